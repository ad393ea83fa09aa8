"""The frame cache (`tavis cache-frames`, `TAVIS_FRAME_CACHE=1`): the samples LeRobot's loader gives, frame by frame
and timestamp by timestamp, without decoding a video; a cache of an earlier state of the dataset is refused; and
lerobot-train trains from it, data-parallel under `accelerate launch` (on CPU here: two processes, gloo)."""

import contextlib
import json
import os
import pickle
import shutil
import signal
import subprocess
import sys
import threading
import time
import warnings

import pytest
import torch

from lerobot_tavis.cli import main
from lerobot_tavis.dataset_tools.convert import ConvertConfig, convert
from lerobot_tavis.dataset_tools.frame_cache import FrameCache, StaleFrameCacheError, cache_dir
from lerobot_tavis.policy_configs import preset_path
from tests.conftest import free_port

pytestmark = pytest.mark.slow  # conftest.py: its file starts first

TINY = (48, 64)
CAMERAS = ("head", "left_wrist", "right_wrist")
CAMERA_KEYS = [f"observation.images.{camera}" for camera in CAMERAS]
FPS = 10  # the dataset's rate: 10 Hz has half the frames of the default 20 Hz to convert and compare
# Two past frames and a chunk of actions: windows that run over both ends of an episode (padding flags, clamped rows).
DELTA_TIMESTAMPS = {**{key: [-2 / FPS, -1 / FPS, 0.0] for key in [*CAMERA_KEYS, "observation.state"]},
                    "action": [step / FPS for step in range(6)]}


@pytest.fixture(scope="module")
def dataset_root(conditional_pick_raw, tmp_path_factory):
    """The run's two conditional_pick demonstrations at 48x64 and FPS with the head and wrist cameras (AV1), and their
    frame cache."""
    root = convert(ConvertConfig(conditional_pick_raw, "local/tiny", tmp_path_factory.mktemp("frame_cache") / "dataset",
                                 fps=FPS, image_size=TINY, cameras=CAMERAS), progress=False)
    main(["cache-frames", str(root)])
    return root


TRAINING_ENDED = "End of training"  # lerobot-train's main process, once the last checkpoint is written
TEARDOWN_GRACE_S = 10  # s; the ranks have passed their last barrier by then and normally exit within a few seconds


def _run_training(command: list[str], env: dict, timeout_s: float) -> tuple[int | None, str]:
    """Runs `command`; returns its exit status and its output (stdout and stderr). Past `timeout_s` every process it
    started (torchrun's ranks run in sessions of their own) prints its Python stacks (faulthandler, SIGABRT) and is
    killed, and the test fails showing them: a hang names the line it hangs on. A run still going TEARDOWN_GRACE_S
    after its main process logged TRAINING_ENDED is stopped the same way and returns None as its status, the stacks
    in its output: on CPU a rank can stay stuck after lerobot-train's `train()` has returned (torch tearing down the
    gloo-backed DDP model; its stack ends in LeRobot's call of `train`), with every file of the run written."""
    import psutil

    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                               env={**env, "PYTHONFAULTHANDLER": "1"})
    lines: list[str] = []
    reader = threading.Thread(target=lambda: lines.extend(iter(process.stdout.readline, "")), daemon=True)
    reader.start()
    started, ended = time.monotonic(), None
    while process.poll() is None:
        time.sleep(0.5)
        now = time.monotonic()
        if ended is None and any(TRAINING_ENDED in line for line in lines):
            ended = now
        if now - started > timeout_s or (ended is not None and now - ended > TEARDOWN_GRACE_S):
            break
    else:
        reader.join()
        return process.returncode, "".join(lines)
    root = psutil.Process(process.pid)
    tree = [root, *root.children(recursive=True)]
    for signal_number in (signal.SIGABRT, signal.SIGKILL):  # the stacks (faulthandler), then the end
        for member in tree:
            with contextlib.suppress(psutil.NoSuchProcess):
                member.send_signal(signal_number)
        tree = psutil.wait_procs(tree, timeout=5)[1]  # those still alive
    process.wait()
    reader.join()
    output = "".join(lines)
    if ended is None:
        pytest.fail(f"{' '.join(command[:6])} ... did not end in {timeout_s} s; its processes' stacks:\n"
                    f"{output[-12000:]}")
    return None, output


def _assert_same_sample(got: dict, want: dict, index: int) -> None:
    assert got.keys() == want.keys()
    assert got["timestamp"] == want["timestamp"] and got["episode_index"] == want["episode_index"]
    for key, value in want.items():
        if isinstance(value, torch.Tensor):
            assert got[key].dtype == value.dtype and torch.equal(got[key], value), (index, key)
        else:
            assert got[key] == value, (index, key)


@pytest.mark.parametrize(("return_uint8", "episodes"), [(True, None), (False, None), (True, [1])],
                         ids=["uint8 as lerobot-train asks", "float32", "an episode subset"])
def test_cached_samples_are_lerobots_decoded_samples_without_decoding(dataset_root, monkeypatch, return_uint8,
                                                                        episodes):
    from lerobot.datasets import dataset_reader
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    from lerobot_tavis.dataset_tools.cached_dataset import FrameCachedDataset

    decoded = LeRobotDataset("local/tiny", root=dataset_root, video_backend="pyav", delta_timestamps=DELTA_TIMESTAMPS,
                             return_uint8=return_uint8, episodes=episodes)
    expected = [decoded[index] for index in range(len(decoded))]  # LeRobot's decoder's frames
    assert decoded.num_episodes == len(episodes or [0, 1])
    assert any(sample["observation.images.head_is_pad"].any() for sample in expected)
    assert expected[0]["observation.images.head"].dtype == (torch.uint8 if return_uint8 else torch.float32)

    def no_decoding(*args, **kwargs):
        raise AssertionError("the frame cache decoded a video")

    monkeypatch.setattr(dataset_reader, "decode_video_frames", no_decoding)
    cached = FrameCachedDataset("local/tiny", root=dataset_root, video_backend="pyav",
                                delta_timestamps=DELTA_TIMESTAMPS, return_uint8=return_uint8, episodes=episodes)
    assert len(cached) == len(expected)
    cached[0]  # its memory maps are open now; the DataLoader pickles the dataset for its spawned workers, which
    in_worker = pickle.loads(pickle.dumps(cached))  # open them again
    for index, want in enumerate(expected):
        _assert_same_sample((cached if index % 2 else in_worker)[index], want, index)


def test_the_preprocessed_batch_is_the_same_from_uint8_float32_and_decoded_frames(dataset_root):
    """What the policy receives in lerobot-train (its loop turns uint8 camera batches into float32 / 255 after
    Accelerate has put the batch on the device, then runs the policy's preprocessor): the same to the bit on CPU
    whether the frames were decoded, come from the cache as uint8 or as float32 from the loader workers. (On a GPU
    the loop's division may round the last bit differently from the workers' on the CPU.)"""
    from lerobot.configs.types import FeatureType, PolicyFeature
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    from lerobot_tavis.dataset_tools.cached_dataset import FrameCachedDataset, TrainingFloatFrameCachedDataset
    from lerobot_tavis.policies.act_hand_relative.configuration_act_hand_relative import ACTHandRelativeConfig
    from lerobot_tavis.policies.act_hand_relative.processor_act_hand_relative import (
        make_act_hand_relative_pre_post_processors)

    arguments = {"root": dataset_root, "video_backend": "pyav", "delta_timestamps": DELTA_TIMESTAMPS,
                 "return_uint8": True}  # as lerobot-train's dataset factory asks
    datasets = {"decoded": LeRobotDataset("local/tiny", **arguments),
                "cache uint8": FrameCachedDataset("local/tiny", **arguments),
                "cache float32": TrainingFloatFrameCachedDataset("local/tiny", **arguments)}
    config = ACTHandRelativeConfig(device="cpu", input_features={
        key: PolicyFeature(FeatureType.VISUAL, (3, *TINY)) for key in CAMERA_KEYS},
        output_features={"action": PolicyFeature(FeatureType.ACTION, (19,))})
    preprocessor, _ = make_act_hand_relative_pre_post_processors(config, datasets["decoded"].meta.stats)
    batches = {}
    for name, dataset in datasets.items():
        batch = next(iter(torch.utils.data.DataLoader(dataset, batch_size=16, shuffle=False)))
        assert batch[CAMERA_KEYS[0]].dtype == (torch.float32 if name == "cache float32" else torch.uint8)
        for key in dataset.meta.camera_keys:  # lerobot-train's loop
            if batch[key].dtype == torch.uint8:
                batch[key] = batch[key].to(dtype=torch.float32) / 255.0
        batches[name] = preprocessor(batch)
    want = batches.pop("decoded")
    assert want[CAMERA_KEYS[0]].dtype == torch.float32
    for name, got in batches.items():
        assert got.keys() == want.keys(), name
        for key, value in want.items():
            if isinstance(value, torch.Tensor):
                assert got[key].dtype == value.dtype and torch.equal(got[key], value), (name, key)


def test_the_switch_picks_the_dataset_class_of_lerobots_factory(monkeypatch):
    """TAVIS_FRAME_CACHE=1 reads frames as lerobot-train asks for them (uint8); float32 converts in the workers."""
    import lerobot.datasets.factory as factory

    from lerobot_tavis.dataset_tools import cached_dataset

    monkeypatch.setattr(factory, "LeRobotDataset", factory.LeRobotDataset)  # restored after the test
    for mode, expected in (("1", cached_dataset.TrainingFrameCachedDataset),
                           ("float32", cached_dataset.TrainingFloatFrameCachedDataset)):
        cached_dataset.use_frame_cache(mode)
        assert factory.LeRobotDataset is expected


def test_a_cache_of_an_earlier_state_of_the_dataset_is_refused_in_one_line(dataset_root, tmp_path, capsys):
    copy = shutil.copytree(dataset_root, tmp_path / "dataset")
    with pytest.raises(StaleFrameCacheError, match="no frame cache for .*; run `tavis cache-frames"):
        FrameCache.open(copy)
    shutil.copytree(cache_dir(dataset_root), cache_dir(copy))  # moved with its dataset: still its cache
    assert FrameCache.open(copy).frame_count == json.loads((cache_dir(copy) / "cache.json").read_text())["frames"]
    main(["cache-frames", str(copy)])
    assert "up to date" in capsys.readouterr().out

    video = sorted((copy / "videos").rglob("*.mp4"))[0]
    with video.open("ab") as file:
        file.write(b"\0")
    with pytest.raises(StaleFrameCacheError) as refusal:
        FrameCache.open(copy)
    message = str(refusal.value)
    assert "\n" not in message and "is stale" in message and video.relative_to(copy).as_posix() in message
    assert f"tavis cache-frames {copy}" in message

    video.write_bytes(video.read_bytes()[:-1])
    (copy / "meta" / "info.json").write_text((copy / "meta" / "info.json").read_text() + " ")
    with pytest.raises(StaleFrameCacheError, match="meta/info.json"):
        FrameCache.open(copy)
    main(["cache-frames", str(copy)])  # rebuilt for the dataset as it is now
    assert FrameCache.open(copy).frame_count == FrameCache.open(dataset_root).frame_count


def test_lerobot_train_reads_the_cache_data_parallel_under_accelerate(dataset_root, tmp_path):
    """The hand-frame compact preset (this package's policy type), shrunk for a CPU, in two processes of
    `accelerate launch` (gloo) reading the cache."""
    preset = json.loads(preset_path("act_hand_relative_head_wrist_compact").read_text())
    for feature in preset["policy"]["input_features"].values():
        feature["shape"] = [3, *TINY]
    (tmp_path / "preset.json").write_text(json.dumps(preset))
    # The ranks meet on the loopback interface at a port no other run on the machine holds (29500 by default).
    env = {**os.environ, "MUJOCO_GL": "egl", "TAVIS_FRAME_CACHE": "1", "GLOO_SOCKET_IFNAME": "lo"}
    train = [sys.executable, "-m", "accelerate.commands.launch", "--multi_gpu", "--num_processes", "2",
             "--num_machines", "1", "--mixed_precision", "no", "--dynamo_backend", "no",
             "--main_process_ip", "127.0.0.1", "--main_process_port", str(free_port()),
             "-m", "lerobot.scripts.lerobot_train", f"--config_path={tmp_path / 'preset.json'}",
             "--dataset.repo_id=local/tiny", f"--dataset.root={dataset_root}", "--env.task=conditional_pick",
             "--policy.device=cpu", "--policy.dim_model=32", "--policy.dim_feedforward=64", "--policy.n_heads=2",
             "--steps=2", "--save_freq=2", "--batch_size=2", "--num_workers=0", "--log_freq=1",
             f"--output_dir={tmp_path / 'train'}"]
    returncode, log = _run_training(train, env, timeout_s=300)
    if returncode is None:
        warnings.warn(f"a rank did not end {TEARDOWN_GRACE_S} s after training; stopped; stacks:\n{log[-6000:]}")
    else:
        assert returncode == 0, log[-3000:]
    assert f"video frames from {cache_dir(dataset_root)}" in log
    assert "Effective batch size: 2 x 2 = 4" in log
    config = json.loads((tmp_path / "train" / "checkpoints" / "last" / "pretrained_model" / "config.json").read_text())
    assert config["type"] == "act_hand_relative"
