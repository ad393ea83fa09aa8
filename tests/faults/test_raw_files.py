"""Raw recordings that were damaged or lied about: corrupt files, hand-edited manifests, manifests that disagree
with their files. Each is one line naming the file and the field, and nothing is written."""

import json
import shutil

import numpy as np
import pytest

from lerobot_tavis.cli import main
from lerobot_tavis.dataset_tools import raw as raw_files


def test_a_corrupt_raw_file_gives_a_clear_error_and_writes_nothing(raw_copy, tmp_path, capsys):
    raw = raw_copy
    entry = raw_files.Manifest.load(raw).episodes[1]
    data = bytearray((raw / entry.file).read_bytes())
    data[len(data) // 2] ^= 0xFF
    (raw / entry.file).write_bytes(bytes(data))
    destination = tmp_path / "out" / "dataset"
    with pytest.raises(SystemExit) as error:
        main(["convert", str(raw), "--repo-id", "local/x", "--root", str(destination), "--image-size", "48x64"])
    assert f"{entry.file} (checksum mismatch)" in str(error.value)
    assert not destination.exists() and not list(destination.parent.glob(".*"))
    with pytest.raises(raw_files.RawEpisodeError, match="not a readable raw episode"):
        raw_files.load_episode(raw / entry.file)


def _convert_error(raw, destination) -> str:
    with pytest.raises(SystemExit) as error:
        main(["convert", str(raw), "--repo-id", "local/x", "--root", str(destination), "--image-size", "48x64"])
    assert not destination.exists() and not list(destination.parent.glob(".*"))  # nothing written
    return str(error.value)


def test_a_hand_edited_manifest_is_refused(raw_copy, tmp_path):
    raw = raw_copy
    path = raw / "manifest.json"
    path.write_text(path.read_text().replace('"fps": 60', '"fps": 20', 1))
    assert "manifest.json: changed since `tavis record` wrote it" in _convert_error(raw, tmp_path / "out" / "d")


@pytest.mark.parametrize("lie,field", [
    (lambda manifest: setattr(manifest, "robot", "reachy2"), "robot: the manifest says 'reachy2', the file 'gr1t2'"),
    (lambda manifest: setattr(manifest.episodes[1], "task", "peeking_box"), "task: the manifest says 'peeking_box'"),
    (lambda manifest: setattr(manifest.episodes[1], "seed", manifest.episodes[1].seed + 7), "seed: the manifest says"),
    (lambda manifest: manifest.episodes.append(manifest.episodes[1]), "listed twice"),
])
def test_a_manifest_that_disagrees_with_its_files_is_refused(raw_copy, tmp_path, lie, field):
    """Even a manifest rewritten with a valid checksum: every entry is checked against its file's own record."""
    raw = raw_copy
    manifest = raw_files.Manifest.load(raw)
    lie(manifest)
    manifest.save(raw)
    message = _convert_error(raw, tmp_path / "out" / "d")
    assert "raw episodes that cannot be trusted, nothing converted" in message and field in message
    assert manifest.episodes[1].file in message


def _edit_document(raw, edit) -> None:
    """Edit manifest.json as JSON and drop its checksum (a manifest without one is read, so the edit is what is
    checked)."""
    path = raw / "manifest.json"
    document = json.loads(path.read_text())
    document.pop("sha256")
    path.write_text(json.dumps(edit(document)))


def _edit_entry(**fields):
    """Set `fields` of the manifest's second episode, rewriting the manifest with a valid checksum."""
    def edit(raw):
        manifest = raw_files.Manifest.load(raw)
        for name, value in fields.items():
            setattr(manifest.episodes[1], name, value)
        manifest.save(raw)

    return edit


def _edit_robot(raw) -> None:
    manifest = raw_files.Manifest.load(raw)
    manifest.robot = "r2d2"
    manifest.save(raw)


@pytest.mark.parametrize("damage,problem", [
    (lambda raw: _edit_document(raw, lambda document: [document]), "not a tavis-raw v1 manifest"),
    (lambda raw: (raw / "manifest.json").write_text('{"format": "tavis-raw", "episodes": [{"fi'),
     "not a JSON file (Unterminated string"),
    (lambda raw: (raw / "manifest.json").write_bytes(b"\xff\xfe{}"), "not a JSON file (not UTF-8 text)"),
    (lambda raw: _edit_document(raw, lambda document: document | {"episodes": None}),
     "episodes must be a list, got None"),
    (lambda raw: _edit_document(raw, lambda document: document | {"episodes": [document["episodes"][0], None]}),
     "episodes[1] must be an object, got None"),
    (_edit_entry(seed=None), "episodes[1].seed must be an integer >= 0, got None"),
    (_edit_entry(seed="100001"), "episodes[1].seed must be an integer >= 0, got '100001'"),
    (_edit_entry(success="yes"), "episodes[1].success must be true or false, got 'yes'"),
    (_edit_entry(file=7), "episodes[1].file must be a text, got 7"),
    (_edit_entry(task="no_such_task"), "episodes[1].task must be one of ["),
    (_edit_robot, "robot must be one of ['gr1t2', 'reachy2'], got 'r2d2'"),
])
def test_a_damaged_or_ill_typed_manifest_names_the_file_and_field(raw_copy, tmp_path, refused, damage, problem):
    """Not an option the user never gave: the manifest's path and the field in it."""
    damage(raw_copy)
    message = _convert_error(raw_copy, tmp_path / "out" / "d")
    assert message.startswith(f"tavis convert: error: {raw_copy / 'manifest.json'}: {problem}")
    assert "--" not in message
    # resuming a recording reads the same manifest the same way
    assert refused(["record", "--tasks", "conditional_pick", "--episodes-per-task", "2", "--out", str(raw_copy)]) \
        .startswith(f"tavis record: error: {raw_copy / 'manifest.json'}: {problem}")


@pytest.mark.parametrize("outside", ["../stolen.npz", "ABSOLUTE"])
def test_a_manifest_entry_outside_the_raw_directory_is_refused(raw_copy, tmp_path, outside):
    """The file would be a valid episode (a copy of one, checksum and record matching): it is refused for where it
    is, before anything reads it."""
    raw = raw_copy
    manifest = raw_files.Manifest.load(raw)
    stolen = shutil.copy(raw / manifest.episodes[1].file, tmp_path / "stolen.npz")
    manifest.episodes[1].file = str(stolen) if outside == "ABSOLUTE" else outside
    manifest.save(raw)
    message = _convert_error(raw, tmp_path / "out" / "d")
    assert message == (f"tavis convert: error: {raw / 'manifest.json'}: episodes[1].file must be a path inside the "
                       f"raw directory, got {manifest.episodes[1].file!r}")


def test_a_non_finite_value_in_a_raw_episode_is_refused(raw_copy, tmp_path):
    """A NaN written with a valid checksum (a recorder bug, not a flipped byte): named with its file, array and row."""
    raw = raw_copy
    manifest = raw_files.Manifest.load(raw)
    entry = manifest.episodes[1]
    episode = raw_files.load_episode(raw / entry.file)
    episode.qvel[5, 2] = np.nan
    entry.sha256 = raw_files.save_episode(raw / entry.file, episode)
    manifest.save(raw)
    message = _convert_error(raw, tmp_path / "out" / "d")
    assert message.startswith("tavis convert: error: ")
    assert f"{entry.file} (qvel holds a non-finite value (nan) at row 5)" in message
    with pytest.raises(raw_files.RawEpisodeError, match=f"{entry.file}: qvel holds a non-finite value"):
        raw_files.load_episode(raw / entry.file)
