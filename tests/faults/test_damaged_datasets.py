"""Converted datasets with a damaged, missing or ill-typed file: `tavis verify-dataset`, `noise-state`, `pull` (its
local copy) and `push` exit with one line naming the file (and the field or the video frame), and write nothing."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

DATA = "data/chunk-000/file-000.parquet"
EPISODES = "meta/episodes/chunk-000/file-000.parquet"
VIDEO = "videos/observation.images.head/chunk-000/file-000.mp4"


def _truncate(path) -> None:
    data = path.read_bytes()
    path.write_bytes(data[:len(data) // 2])


def _garble(path) -> None:
    """2000 random bytes over the middle of the file."""
    data = bytearray(path.read_bytes())
    middle = len(data) // 2
    data[middle:middle + 2000] = np.random.default_rng(0).integers(0, 256, 2000, dtype=np.uint8).tobytes()
    path.write_bytes(bytes(data))


def _edit_json(path, edit) -> None:
    document = json.loads(path.read_text())
    edit(document)
    path.write_text(json.dumps(document))


def _files(root) -> dict:
    return {path: path.stat().st_mtime_ns for path in root.rglob("*")}


# (what is damaged, how, the file the message names, what it says of it)
DAMAGES = {
    "data file truncated": (DATA, _truncate, DATA, "not a readable Parquet file (Parquet magic bytes not found"),
    "data file garbled": (DATA, _garble, DATA, "not a readable Parquet file"),
    "data file missing": (DATA, os.remove, "data", "holds no data files (Parquet)"),
    "info.json truncated": ("meta/info.json", _truncate, "meta/info.json", "not a JSON file (Unterminated string"),
    "info.json missing": ("meta/info.json", os.remove, "meta/info.json", "missing"),
    "info.json ill-typed": ("meta/info.json", lambda p: _edit_json(p, lambda info: info.update(fps="20")),
                            "meta/info.json", "fps must be an integer >= 1, got '20'"),
    "info.json robot": ("meta/info.json", lambda p: _edit_json(p, lambda info: info.update(robot_type=None)),
                        "meta/info.json", "robot_type must be one of ['gr1t2', 'reachy2'], got None"),
    "conversion log truncated": ("meta/tavis_conversion.json", _truncate, "meta/tavis_conversion.json",
                                 "not a JSON file"),
    "conversion log null seed": ("meta/tavis_conversion.json",
                                 lambda p: _edit_json(p, lambda log: log["episodes"][1].update(seed=None)),
                                 "meta/tavis_conversion.json", "episodes[1].seed must be an integer >= 0, got None"),
    "episode metadata truncated": (EPISODES, _truncate, EPISODES, "not a readable Parquet file"),
    "episode metadata missing": (EPISODES, os.remove, "meta/episodes", "no episode metadata (Parquet files)"),
    "tasks truncated": ("meta/tasks.parquet", _truncate, "meta/tasks.parquet", "not a readable Parquet file"),
    "stats.json garbled": ("meta/stats.json", lambda p: p.write_bytes(b"\x00" * 64), "meta/stats.json",
                           "not a JSON file"),
    "video truncated": (VIDEO, _truncate, VIDEO, "frame 7 of episode 1 (3.85 s) cannot be decoded: decoding stops"),
    "video garbled": (VIDEO, _garble, VIDEO, "of episode 1 ("),
    "video missing": (VIDEO, os.remove, VIDEO, "missing"),
}


@pytest.mark.parametrize("case", DAMAGES)
def test_verify_dataset_names_the_damaged_file(dataset_copy, refused, case):
    """Every metadata and data file is read, every camera frame of the checked episodes decoded, before a replay."""
    damaged, damage, named, problem = DAMAGES[case]
    damage(dataset_copy / damaged)
    before = _files(dataset_copy)
    message = refused(["verify-dataset", str(dataset_copy)])
    assert message.startswith(f"tavis verify-dataset: error: {dataset_copy / named}: ")
    assert problem in message
    assert _files(dataset_copy) == before


def test_verify_dataset_decodes_only_the_episodes_it_checks(dataset_copy, capsys):
    """Episode 0 lies before the cut of a truncated video: checking it alone replays it."""
    from lerobot_tavis.cli import main

    _truncate(dataset_copy / VIDEO)
    main(["verify-dataset", str(dataset_copy), "--episodes", "0"])
    assert "1 episodes replay as recorded" in capsys.readouterr().out


def test_a_damaged_video_is_one_line_from_the_command(dataset_copy):
    """The real command in its own process: exit status 1, one line on stderr, no traceback."""
    _garble(dataset_copy / VIDEO)
    result = subprocess.run([sys.executable, "-m", "lerobot_tavis.cli", "verify-dataset", str(dataset_copy)],
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 1
    (line,) = result.stderr.splitlines()
    assert line.startswith(f"tavis verify-dataset: error: {dataset_copy / VIDEO}: frame ")


@pytest.mark.parametrize("damaged", [DATA, EPISODES, "meta/info.json"])
def test_noise_state_names_the_damaged_file_and_writes_nothing(dataset_copy, tmp_path, refused, damaged):
    _truncate(dataset_copy / damaged)
    out = tmp_path / "noisy"
    message = refused(["noise-state", str(dataset_copy), "--out", str(out), "--position-m", "0.01",
                       "--rotation-deg", "2"])
    assert message.startswith(f"tavis noise-state: error: {dataset_copy / damaged}: not a ")
    assert not out.exists() and sorted(path.name for path in tmp_path.iterdir()) == ["dataset"]


@pytest.mark.parametrize("damaged", [DATA, EPISODES, "meta/tasks.parquet", "meta/info.json"])
def test_pull_names_a_damaged_local_file(dataset_copy, refused, monkeypatch, damaged):
    """A copy in --root (e.g. a download cut short) is read before LeRobot loads it; offline, so no Hub is asked."""
    monkeypatch.setenv("HF_HUB_OFFLINE", "1")
    _truncate(dataset_copy / damaged)
    before = _files(dataset_copy)
    message = refused(["pull", "local/faults", "--root", str(dataset_copy)])
    assert message.startswith(f"tavis pull: error: {dataset_copy / damaged}: not a ")
    assert message.endswith("; remove it to download it again")
    assert _files(dataset_copy) == before


def test_push_names_a_damaged_file_before_uploading(dataset_copy, refused, monkeypatch):
    monkeypatch.setenv("HF_HUB_OFFLINE", "1")
    _truncate(dataset_copy / DATA)
    assert refused(["push", str(dataset_copy), "--repo-id", "local/faults"]).startswith(
        f"tavis push: error: {dataset_copy / DATA}: not a readable Parquet file")
