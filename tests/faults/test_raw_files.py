"""Raw recordings that were damaged or lied about: corrupt files, hand-edited manifests, manifests that disagree
with their files. Each is one line naming the file and the field, and nothing is written."""

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
