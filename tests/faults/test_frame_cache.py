"""lerobot-train with `TAVIS_FRAME_CACHE=1` on a dataset changed after its frame cache was written: a non-zero exit
with one line naming the problem, before any training; a misspelt switch stops the process in one line too."""

import os
import shutil
import subprocess
import sys

import pytest

from lerobot_tavis.cli import main
from lerobot_tavis.dataset_tools.convert import ConvertConfig, convert
from lerobot_tavis.dataset_tools.frame_cache import cache_dir
from lerobot_tavis.policy_configs import preset_path

pytestmark = pytest.mark.slow  # conftest.py: its file starts first


@pytest.fixture(scope="module")
def dataset_root(conditional_pick_dataset, tmp_path_factory):
    """A copy of the run's conditional_pick dataset (the head camera at 48x64), with its frame cache."""
    root = shutil.copytree(conditional_pick_dataset, tmp_path_factory.mktemp("frame_cache") / "dataset")
    main(["cache-frames", str(root)])
    return root


def _train(dataset_root, tmp_path, switch: str) -> subprocess.CompletedProcess:
    command = [sys.executable, "-m", "lerobot.scripts.lerobot_train",
               f"--config_path={preset_path('diffusion_head_only')}", "--dataset.repo_id=local/tiny",
               f"--dataset.root={dataset_root}", "--policy.device=cpu", "--steps=1", "--num_workers=0",
               f"--output_dir={tmp_path / 'train'}"]
    env = {**os.environ, "MUJOCO_GL": "egl", "TAVIS_FRAME_CACHE": switch}
    return subprocess.run(command, capture_output=True, text=True, env=env, timeout=600)


def test_lerobot_train_refuses_a_stale_frame_cache_in_one_line(dataset_root, tmp_path):
    video = sorted((dataset_root / "videos").rglob("*.mp4"))[0]
    original = video.read_bytes()
    video.write_bytes(original + b"\0")  # a video re-encoded after the cache was written
    try:
        run = _train(dataset_root, tmp_path, "1")
    finally:
        video.write_bytes(original)
    assert run.returncode == 1
    last = run.stderr.strip().splitlines()[-1]
    assert last.startswith(f"lerobot-train: error: the frame cache {cache_dir(dataset_root)} is stale: ")
    assert video.relative_to(dataset_root).as_posix() in last and "tavis cache-frames" in last
    assert "Traceback" not in run.stderr and not (tmp_path / "train" / "checkpoints").exists()


STOPS = object()


@pytest.mark.parametrize(("value", "mode"), [("1", "1"), ("float32", "float32"), ("0", None), (None, None),
                                             ("", None), ("yes", STOPS), ("true", STOPS), ("uint8", STOPS)])
def test_the_switch_is_1_float32_or_0_and_anything_else_stops_in_one_line(monkeypatch, value, mode):
    """The plugin module asks `frame_cache_mode()` in lerobot-train's process (which the stale-cache test runs)."""
    from lerobot_tavis.dataset_tools.cached_dataset import frame_cache_mode

    if value is None:
        monkeypatch.delenv("TAVIS_FRAME_CACHE", raising=False)
    else:
        monkeypatch.setenv("TAVIS_FRAME_CACHE", value)
    if mode is not STOPS:
        assert frame_cache_mode() == mode
        return
    with pytest.raises(SystemExit) as stop:
        frame_cache_mode()
    assert stop.value.code == (f"TAVIS_FRAME_CACHE={value!r}: set it to 1 (read video frames from the frame cache), "
                               "float32 (the same, converted to float32 in the loader workers), 0 (decode them)")


def test_cache_frames_refuses_what_it_cannot_cache_in_one_line_and_writes_nothing(tmp_path):
    """No dataset there, zero workers, a dataset without videos (frames stored as PNG images)."""
    missing = tmp_path / "missing"
    for argv, message in (
        (["cache-frames", str(missing)], f"tavis cache-frames: error: {missing} is not a LeRobotDataset "
                                         "(no meta/info.json)"),
        (["cache-frames", str(missing), "--workers", "0"],
         "tavis cache-frames: error: --workers must be an integer >= 1, got 0"),
    ):
        with pytest.raises(SystemExit) as refusal:
            main(argv)
        assert refusal.value.code == message
    assert not cache_dir(missing).exists()


def test_cache_frames_refuses_a_dataset_without_videos(conditional_pick_raw, tmp_path):
    root = convert(ConvertConfig(conditional_pick_raw, "local/png", tmp_path / "dataset", fps=10, image_size=(24, 32),
                                 cameras=("head",), storage="png", task="conditional_pick"), progress=False)
    with pytest.raises(SystemExit) as refusal:
        main(["cache-frames", str(root)])
    assert refusal.value.code == (f"tavis cache-frames: error: {root.absolute()}: the dataset stores no video "
                                  "cameras; there is nothing to cache")
    assert not cache_dir(root).exists()
