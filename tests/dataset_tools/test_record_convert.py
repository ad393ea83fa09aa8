"""`tavis record` and `tavis convert`: raw episodes that replay exactly, and the LeRobotDataset made from them."""

import json
import os
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from lerobot_tavis import canonical
from lerobot_tavis.cli import main
from lerobot_tavis.dataset_tools import raw as raw_files
from lerobot_tavis.dataset_tools import record as recorder
from lerobot_tavis.dataset_tools.convert import ConvertConfig, ReplayError, convert
from lerobot_tavis.dataset_tools.features import ACTION_KEY, JOINT_POS_KEY, STATE_KEY, image_key
from lerobot_tavis.dataset_tools.frames import check_camera_frames, dataset_info, episode_frames
from lerobot_tavis.envs.robots import make_robot
from lerobot_tavis.envs.tasks.catalog import suite_tasks
from lerobot_tavis.errors import InputError

pytestmark = pytest.mark.slow  # conftest.py: its file starts first

HANDS = suite_tasks("tavis_hands")
IMAGE_SIZE = (48, 64)
FPS = 10  # the module's main dataset: every 6th tick a frame (half the frames of the default 20 Hz to render)
STRIDE = 60 // FPS
SMALL = (24, 32)  # the other conversions (rendering costs the same per frame at any size this small)
TWO_CAMERAS = ("head", "left_wrist")
DATASET_CAMERAS = ("head", "fixed")  # of the main dataset; the wrist cameras are converted in `peeking_box`


@pytest.fixture(scope="module")
def raw_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("raw")
    main(["record", "--robot", "gr1t2", "--suite", "tavis_hands", "--episodes-per-task", "2", "--out", str(out)])
    return out


@pytest.fixture(scope="module")
def dataset(raw_dir, tmp_path_factory):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    root = tmp_path_factory.mktemp("converted") / "hands"
    main(["convert", str(raw_dir), "--repo-id", "local/tavis-hands-gr1t2", "--root", str(root), "--fps", str(FPS),
          "--image-size", "48x64", "--cameras", ",".join(DATASET_CAMERAS)])
    return LeRobotDataset("local/tavis-hands-gr1t2", root=root, video_backend="pyav")


@pytest.fixture(scope="module")
def peeking_box(raw_dir, tmp_path_factory):
    """peeking_box's two episodes, head and left wrist cameras, converted by one worker while LeRobot's video encoder
    lags, as on a loaded machine, as far as it can: each episode's encoder threads start encoding only once the
    episode's last frame is queued (when the episode is finished)."""
    import threading

    from lerobot.datasets import video_utils

    encode = video_utils._CameraEncoderThread.run
    finish = video_utils.StreamingVideoEncoder.finish_episode
    episode_fed = threading.Event()

    def lagging(thread):
        assert episode_fed.wait(timeout=120), "the episode was never finished"
        encode(thread)

    def finish_fed_episode(encoder):
        episode_fed.set()
        try:
            return finish(encoder)  # waits for the episode's encoder threads
        finally:
            episode_fed.clear()

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(video_utils._CameraEncoderThread, "run", lagging)
        patch.setattr(video_utils.StreamingVideoEncoder, "finish_episode", finish_fed_episode)
        return convert(ConvertConfig(raw_dir, "local/peeking_box", tmp_path_factory.mktemp("lagged") / "peeking_box",
                                     image_size=SMALL, task="peeking_box", cameras=TWO_CAMERAS), progress=False)


@pytest.fixture(scope="module")
def occluded_reach(raw_dir, tmp_path_factory):
    """occluded_reach's two episodes converted by the `tavis` console script as a user runs it, with the cameras
    and size of `peeking_box`: (the dataset's root, everything the process printed)."""
    root = tmp_path_factory.mktemp("console") / "occluded_reach"
    tavis = os.path.join(os.path.dirname(sys.executable), "tavis")
    done = subprocess.run([tavis, "convert", str(raw_dir), "--repo-id", "local/occluded_reach", "--root", str(root),
                           "--image-size", "x".join(map(str, SMALL)), "--cameras", ",".join(TWO_CAMERAS),
                           "--task", "occluded_reach"], capture_output=True, text=True, timeout=300, check=True)
    return root, done.stdout + done.stderr


def _copy_raw(raw_dir, tmp_path):
    import shutil

    return shutil.copytree(raw_dir, tmp_path / "raw")


def test_record_keeps_two_replayable_episodes_per_task(raw_dir):
    manifest = raw_files.Manifest.load(raw_dir)
    assert {task: count["kept"] for task, count in manifest.counts().items()} == dict.fromkeys(HANDS, 2)
    assert manifest.fps == 60 and manifest.robot == "gr1t2"
    assert not manifest.damaged(raw_dir)
    entry = manifest.episodes[0]
    episode = raw_files.load_episode(raw_dir / entry.file, entry.sha256)
    assert episode.success and episode.seed >= 100_000 and episode.fps == 60
    assert episode.actions.shape == (entry.n_steps, 19) and len(episode.qpos) == entry.n_steps + 1


def test_record_resumes_without_recording_finished_episodes(raw_dir, monkeypatch):
    def refuse(*args):
        raise AssertionError(f"re-recorded {args}")

    monkeypatch.setattr(recorder, "record_episode", refuse)
    before = (raw_dir / "manifest.json").read_text()
    main(["record", "--robot", "gr1t2", "--suite", "tavis_hands", "--episodes-per-task", "2", "--out", str(raw_dir)])
    assert (raw_dir / "manifest.json").read_text() == before


def test_record_re_records_a_damaged_episode_identically(raw_dir, tmp_path, capsys):
    raw = _copy_raw(raw_dir, tmp_path)
    entry = raw_files.Manifest.load(raw).episodes[0]
    (raw / entry.file).write_bytes(b"truncated")
    main(["record", "--robot", "gr1t2", "--suite", "tavis_hands", "--episodes-per-task", "2", "--out", str(raw)])
    assert f"{entry.file}: checksum mismatch" in capsys.readouterr().err
    assert raw_files.file_sha256(raw / entry.file) == entry.sha256  # same seed, same episode, same bytes


def test_record_refuses_a_directory_of_another_robot(raw_dir):
    with pytest.raises(SystemExit, match="robot/split/seed_start"):
        main(["record", "--robot", "reachy2", "--suite", "tavis_hands", "--episodes-per-task", "2",
              "--out", str(raw_dir)])


def test_converted_dataset_features_names_and_counts(dataset, raw_dir):
    manifest = raw_files.Manifest.load(raw_dir)
    assert dataset.fps == FPS and dataset.num_episodes == len(manifest.episodes) == 6
    features = dataset.meta.features
    for camera in DATASET_CAMERAS:
        assert features[image_key(camera)]["dtype"] == "video"
        assert tuple(features[image_key(camera)]["shape"]) == (*IMAGE_SIZE, 3)
    assert image_key("left_wrist") not in features and image_key("right_wrist") not in features  # not asked for
    assert features[STATE_KEY]["names"] == list(canonical.ACTION_NAMES)
    assert features[ACTION_KEY]["names"] == list(canonical.ACTION_NAMES)
    assert features[JOINT_POS_KEY]["names"] == list(make_robot("gr1t2").joint_names())
    lengths = {row["episode_index"]: row["length"] for row in dataset.meta.episodes}
    episodes = _episodes_in_dataset_order(manifest)
    assert [lengths[i] for i in range(6)] == [-(-e.n_steps // STRIDE) for e in episodes]  # ceil(T / STRIDE)


def _episodes_in_dataset_order(manifest):
    return sorted(manifest.episodes, key=lambda e: (HANDS.index(e.task), e.seed))


def test_frames_pair_each_observation_with_the_last_command_of_its_interval(dataset, raw_dir):
    episodes = _episodes_in_dataset_order(raw_files.Manifest.load(raw_dir))
    start = 0
    for index, entry in enumerate(episodes):
        episode = raw_files.load_episode(raw_dir / entry.file)
        n_frames = -(-entry.n_steps // STRIDE)
        for j in (0, 7, n_frames - 1):
            frame = dataset[start + j]
            assert int(frame["episode_index"]) == index and int(frame["frame_index"]) == j
            last_tick = min(STRIDE * (j + 1), entry.n_steps) - 1  # frame j observes tick STRIDE * j, the rest follow
            np.testing.assert_array_equal(frame[ACTION_KEY].numpy(), episode.actions[last_tick].astype(np.float32))
            assert frame["task"] == episode.prompt and frame["task_name"] == entry.task and frame["split"] == "id"
        start += n_frames
    first = dataset[0]
    assert first[image_key("head")].shape == (3, *IMAGE_SIZE)
    blocked = HANDS.index("blocked_clutter_pick_cube") * 2
    blocked_start = sum(-(-e.n_steps // STRIDE) for e in episodes[:blocked])
    assert float(dataset[blocked_start][image_key("head")].max()) < 0.05  # the head camera is black there
    log = json.loads((dataset.root / "meta" / "tavis_conversion.json").read_text())
    assert [e["max_qpos_deviation"] for e in log["episodes"]] == [0.0] * 6  # exact replay
    assert log["shadows"] is True  # rendered as evaluation renders by default


def test_convert_prints_its_progress_and_no_encoder_chatter(occluded_reach):
    """No SVT-AV1 banner, FFmpeg muxer line, per-episode `datasets` bar or traceback: only tavis's own output."""
    root, output = occluded_reach
    for chatter in ("Svt[", "[mp4 @", "Map:", "Traceback", "moov atom"):
        assert chatter not in output, f"{chatter!r} in:\n{output}"
    assert "convert local/occluded_reach" in output and str(root) in output


def test_converting_twice_gives_identical_data_whatever_the_workers(raw_dir, peeking_box, tmp_path):
    """Two workers and an encoder on time against `peeking_box` (one worker, its encoder late)."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    again = convert(ConvertConfig(raw_dir, "local/again", tmp_path / "again", image_size=SMALL, task="peeking_box",
                                  cameras=TWO_CAMERAS, workers=2), progress=False)
    pd.testing.assert_frame_equal(*(pd.read_parquet(root / "data") for root in (peeking_box, again)))
    first = LeRobotDataset("local/peeking_box", root=peeking_box, video_backend="pyav")
    second = LeRobotDataset("local/again", root=again, video_backend="pyav")
    for index in (0, len(first) - 1):
        for camera in TWO_CAMERAS:
            assert np.array_equal(first[index][image_key(camera)].numpy(), second[index][image_key(camera)].numpy())


def test_no_frame_is_lost_when_the_video_encoder_lags(peeking_box):
    """LeRobot's streaming encoder drops frames that find its queue full; conversion must not lose any."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    dataset = LeRobotDataset("local/peeking_box", root=peeking_box, video_backend="pyav")
    assert dataset.num_frames > 60  # more than LeRobot's default queue of 30 frames per episode
    for index in range(len(dataset)):  # every frame of every camera decodes at its own timestamp
        frame = dataset[index]
        for camera in TWO_CAMERAS:
            assert frame[image_key(camera)].shape == (3, *SMALL)


def test_a_replay_that_ends_differently_is_an_error(raw_dir, tmp_path):
    raw = _copy_raw(raw_dir, tmp_path)
    manifest = raw_files.Manifest.load(raw)
    entry = max((e for e in manifest.episodes if e.task == "occluded_reach"), key=lambda e: e.seed)  # the 2nd
    episode = raw_files.load_episode(raw / entry.file)
    episode.actions[:, canonical.RIGHT.gripper] = -1.0  # never grasps: the replay cannot succeed
    episode.actions[:, canonical.LEFT.gripper] = -1.0
    entry.sha256 = raw_files.save_episode(raw / entry.file, episode)
    manifest.save(raw)
    with pytest.raises(ReplayError, match=f"occluded_reach seed {entry.seed}: the replay ended with success=False"):
        convert(ConvertConfig(raw, "local/x", tmp_path / "x", image_size=IMAGE_SIZE, task="occluded_reach",
                              cameras=("head",)), progress=False)
    assert not (tmp_path / "x").exists() and not list(tmp_path.glob(".x*"))


def test_an_existing_destination_needs_overwrite(raw_dir, tmp_path):
    (tmp_path / "taken").mkdir()
    cfg = ConvertConfig(raw_dir, "local/x", tmp_path / "taken", image_size=IMAGE_SIZE, task="peeking_box")
    with pytest.raises(FileExistsError, match="--overwrite"):
        convert(cfg, progress=False)


def test_lerobot_merges_converted_datasets(peeking_box, occluded_reach, tmp_path, monkeypatch):
    """LeRobot's lerobot-edit-dataset (its entry point, in this process) merges two converted datasets."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset
    from lerobot.scripts import lerobot_edit_dataset

    roots = [peeking_box, occluded_reach[0]]
    merged = tmp_path / "merged"
    monkeypatch.setattr("sys.argv", [
        "lerobot-edit-dataset", "--new_repo_id", "local/merged", "--new_root", str(merged), "--operation.type", "merge",
        "--operation.repo_ids", "['local/peeking_box', 'local/occluded_reach']",
        "--operation.roots", str([str(r) for r in roots])])
    lerobot_edit_dataset.main()
    dataset = LeRobotDataset("local/merged", root=merged, video_backend="pyav")
    assert dataset.num_episodes == 4
    assert {dataset[0]["task_name"], dataset[len(dataset) - 1]["task_name"]} == {"peeking_box", "occluded_reach"}


@pytest.mark.parametrize("storage", ["h264", "png"])
def test_other_frame_storages_hold_the_same_frames(raw_dir, dataset, tmp_path, storage):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    root = tmp_path / storage
    main(["convert", str(raw_dir), "--repo-id", f"local/{storage}", "--root", str(root), "--image-size", "48x64",
          "--fps", str(FPS), "--cameras", "fixed", "--task", "peeking_box", "--storage", storage])
    other = LeRobotDataset(f"local/{storage}", root=root, video_backend="pyav")
    key = image_key("fixed")
    assert other.meta.features[key]["dtype"] == ("image" if storage == "png" else "video")
    assert json.loads((root / "meta" / "tavis_conversion.json").read_text())["storage"] == storage
    task_names = pd.read_parquet(dataset.root / "data", columns=["task_name"])["task_name"]
    reference = [i for i, name in enumerate(task_names) if name == "peeking_box"]
    assert len(other) == len(reference)
    for i in (0, len(other) // 2, len(other) - 1):
        frame, expected = other[i], dataset[reference[i]]
        np.testing.assert_array_equal(frame[ACTION_KEY].numpy(), expected[ACTION_KEY].numpy())
        # lossless PNG and near-lossless H.264 against AV1 at crf 30: the same picture up to compression noise
        assert np.abs(frame[key].numpy() - expected[key].numpy()).mean() < 0.03
    check_camera_frames(root, dataset_info(root), episode_frames(root))  # what verify-dataset decodes: every frame
    if storage == "png":  # an image cut short inside its data file is named with its frame and episode
        _cut_image(next((root / "data").rglob("*.parquet")), key, row=5)
        with pytest.raises(InputError, match=f"file-000.parquet: {key} of frame 5 of episode 0 cannot be decoded"):
            check_camera_frames(root, dataset_info(root), episode_frames(root))


def _cut_image(path, key: str, row: int) -> None:
    """Rewrite the data file `path` with the PNG of image column `key` in `row` cut to its first 100 bytes."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pq.read_table(path)
    images = table.column(key).to_pylist()
    images[row] = {**images[row], "bytes": images[row]["bytes"][:100]}
    field = table.schema.field(key)
    pq.write_table(table.set_column(table.schema.get_field_index(key), field, pa.array(images, type=field.type)), path)


def test_storage_is_checked(raw_dir, tmp_path):
    with pytest.raises(ValueError, match="storage must be one of"):
        convert(ConvertConfig(raw_dir=raw_dir, repo_id="local/x", root=tmp_path / "x", storage="mpeg2"))
    assert not (tmp_path / "x").exists()
