"""Dataset commands choose a video decoder that loads, and a dataset load prints no traceback."""

import ctypes.util
import os
import subprocess
import sys

import pytest

from lerobot_tavis.dataset_tools.quiet import FALLBACK_LINE, video_backend

SYSTEM_FFMPEG = ctypes.util.find_library("avcodec") is not None


def test_pyav_is_chosen_where_torchcodec_cannot_load(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "torchcodec.decoders", None)  # `import` now fails as a broken install does
    assert video_backend() == "pyav"
    assert capsys.readouterr() == ("", "")


def test_torchcodec_is_chosen_where_it_loads(monkeypatch):
    package, decoders = type(sys)("torchcodec"), type(sys)("torchcodec.decoders")
    package.decoders = decoders
    monkeypatch.setitem(sys.modules, "torchcodec", package)
    monkeypatch.setitem(sys.modules, "torchcodec.decoders", decoders)
    assert video_backend() == "torchcodec"


@pytest.fixture(scope="module")
def tiny_dataset(tmp_path_factory):
    """A LeRobotDataset of one 2-frame episode, state only."""
    import numpy as np
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    root = tmp_path_factory.mktemp("tiny") / "dataset"
    dataset = LeRobotDataset.create("local/tiny", fps=20, root=root, use_videos=False, video_backend="pyav",
                                    features={"observation.state": {"dtype": "float32", "shape": (2,), "names": None}})
    for step in range(2):
        dataset.add_frame({"observation.state": np.full(2, step, np.float32), "task": "t"})
    dataset.save_episode()
    dataset.finalize()
    return root


def _load(root, *, plugin: bool, python_path: str = "") -> tuple[str, str]:
    """(the video backend LeRobot chose, stderr) of a fresh process that loads the dataset at `root`."""
    code = ("import logging, sys; logging.basicConfig(); " + ("import lerobot_env_tavis; " if plugin else "")
            + "from lerobot.datasets.lerobot_dataset import LeRobotDataset; "
            "print(LeRobotDataset('local/tiny', root=sys.argv[1])._video_backend)")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [python_path, os.environ.get("PYTHONPATH")]))}
    done = subprocess.run([sys.executable, "-c", code, str(root)], capture_output=True, text=True, env=env, check=True)
    return done.stdout.strip(), done.stderr


@pytest.mark.skipif(not SYSTEM_FFMPEG, reason="FFmpeg's shared libraries are not installed (`make setup` does)")
def test_a_dataset_loads_without_a_word_where_ffmpeg_is_installed(tiny_dataset):
    assert _load(tiny_dataset, plugin=False) == ("torchcodec", "")


def test_the_plugin_makes_a_torchcodec_that_cannot_load_one_line(tiny_dataset, tmp_path):
    """As on a machine without FFmpeg: torchcodec is installed, and importing it raises its long error, which
    LeRobot's own warning repeats whole and the plugin shortens to one line."""
    broken = tmp_path / "torchcodec"
    broken.mkdir()
    (broken / "__init__.py").write_text("raise RuntimeError('Could not load libtorchcodec.' + '\\n  trace' * 100)\n")
    backend, stderr = _load(tiny_dataset, plugin=True, python_path=str(tmp_path))
    assert backend == "pyav" and stderr.splitlines() == [f"WARNING:lerobot.utils.import_utils:{FALLBACK_LINE}"]
