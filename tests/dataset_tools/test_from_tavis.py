"""Importing the original benchmark's datasets: small sources in its layout (60 Hz, class-name tasks), no network."""

from dataclasses import dataclass, field

import numpy as np
import pytest

from lerobot_tavis import canonical
from lerobot_tavis.dataset_tools import features as ft
from lerobot_tavis.dataset_tools.from_tavis import TASK_CLASSES, convert_from_tavis, task_name_for_class

SIZE = (24, 32)
GR1T2_JOINTS = 33
PROMPTS = {"ConditionalPickTask": "Look at the card, then pick.", "WaitThenActTask": "Wait for green, then pick.",
           "OccludedReachTask": "Reach around the screen.", "MysteryTask": "Do something."}
LEFT_QUAT = np.array([0.6, 0.0, -0.8, 0.0], np.float32)
RIGHT_QUAT = np.array([0.6, 0.0, 0.8, 0.0], np.float32)
BRIGHTNESS = {"OBS_HEAD": lambda k: 10 * k + 5, "OBS_FIXED": lambda k: 250 - 10 * k,
              "OBS_WRIST_LEFT": lambda k: 20 * k + 5}


@dataclass
class Source:
    root: object
    episodes: list = field(default_factory=list)  # per episode: {"action", "joints", "<side>_pos", ...} arrays


def source_frame(episode: int, k: int, joints: int, cameras) -> dict:
    """Source frame k: action[0] = k, action[1] = episode; quaternion signs alternate; image brightness from k."""
    action = canonical.rest_action().astype(np.float32)
    action[0], action[1] = k, episode
    action[17], action[18] = k / 20, -k / 20
    sign = -1 if k % 2 else 1
    frame = {
        "observation.state": (k + np.arange(joints) / 100).astype(np.float32),
        "observation.left_eef_pos": np.array([k / 100, 0.2, 0.3], np.float32),
        "observation.right_eef_pos": np.array([k / 100, -0.2, 0.3], np.float32),
        "observation.left_eef_quat": sign * LEFT_QUAT,
        "observation.right_eef_quat": sign * RIGHT_QUAT,
        "action": action,
    }
    for camera in cameras:
        frame[f"observation.images.{camera}"] = np.full((*SIZE, 3), BRIGHTNESS[camera](k), np.uint8)
    return frame


def make_source(root, robot_type, episodes, *, cameras=("OBS_HEAD", "OBS_FIXED"), joint_names=None) -> Source:
    """A LeRobotDataset in the original layout: 60 Hz, bogus vector names unless `joint_names`, class-name tasks."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    bogus = ["height", "width", "channels"]
    joints = len(joint_names) if joint_names else GR1T2_JOINTS
    features = {f"observation.images.{c}": {"dtype": "video", "shape": (*SIZE, 3), "names": bogus} for c in cameras}
    features["observation.state"] = {"dtype": "float32", "shape": (joints,), "names": joint_names or bogus}
    for side in ("left", "right"):
        features[f"observation.{side}_eef_pos"] = {"dtype": "float32", "shape": (3,), "names": bogus}
        features[f"observation.{side}_eef_quat"] = {"dtype": "float32", "shape": (4,), "names": bogus}
    features["action"] = {"dtype": "float32", "shape": (19,), "names": bogus}
    features["language_instruction"] = {"dtype": "string", "shape": (1,), "names": bogus}
    dataset = LeRobotDataset.create(f"tavis-benchmark/{root.name}", fps=60, features=features, root=root,
                                    robot_type=robot_type, use_videos=True)
    source = Source(root)
    for e, (class_name, length) in enumerate(episodes):
        frames = [source_frame(e, k, joints, cameras) for k in range(length)]
        for frame in frames:
            dataset.add_frame({**frame, "language_instruction": PROMPTS[class_name], "task": class_name})
        dataset.save_episode(parallel_encoding=False)  # its pool would fork this multi-threaded process
        source.episodes.append({key: np.stack([f[key] for f in frames]) for key in frames[0]})
    dataset.finalize()
    return source


def load(root, repo_id="local/imported"):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    return LeRobotDataset(repo_id, root=root, video_backend="pyav")


def no_leftovers(destination) -> bool:
    return not [p.name for p in destination.parent.iterdir() if p.name.startswith(f".{destination.name}.")]


@pytest.fixture(scope="module")
def head_source(tmp_path_factory):
    root = tmp_path_factory.mktemp("sources") / "tavis-head-gr1t2"
    return make_source(root, "gr1t2", [("ConditionalPickTask", 13), ("WaitThenActTask", 14)])


@pytest.fixture(scope="module")
def reachy_source(tmp_path_factory):
    """Named joints with the neck first (not at the reference's indices), no robot_type, one wrist camera."""
    root = tmp_path_factory.mktemp("sources") / "tavis-hands-reachy2"
    names = ["neck_roll", "neck_pitch", "neck_yaw", *(f"arm_{i}" for i in range(7))]
    return make_source(root, None, [("OccludedReachTask", 7)], cameras=("OBS_WRIST_LEFT",), joint_names=names)


@pytest.fixture(scope="module")
def imported(head_source, tmp_path_factory):
    root = tmp_path_factory.mktemp("imported") / "head"
    convert_from_tavis(head_source.root, "local/imported", root, fps=20, image_size=SIZE, progress=False)
    return load(root)


def test_the_schema_is_ours(imported):
    meta = imported.meta
    assert meta.fps == 20 and meta.robot_type == "gr1t2" and meta.total_episodes == 2
    expected = ft.dataset_features([f"joint_{i}" for i in range(GR1T2_JOINTS)], ("head", "fixed"), SIZE)
    for key, spec in expected.items():
        assert meta.features[key]["dtype"] == spec["dtype"] and tuple(meta.features[key]["shape"]) == spec["shape"]
    assert meta.features[ft.STATE_KEY]["names"] == meta.features[ft.ACTION_KEY]["names"] == list(canonical.ACTION_NAMES)
    joint_names = meta.features[ft.JOINT_POS_KEY]["names"]
    assert [joint_names[i] for i in (11, 16, 21)] == ["head_roll_joint", "head_pitch_joint", "head_yaw_joint"]
    assert joint_names[0] == "joint_0" and len(set(joint_names)) == GR1T2_JOINTS
    assert not [key for key in meta.features if "OBS_" in key or "eef" in key or key == "language_instruction"]


def test_frames_pair_an_observation_with_the_last_command_of_its_interval(imported, head_source):
    lengths = [int(n) for n in imported.meta.episodes["length"]]
    assert lengths == [4, 4]  # floor((n - 1) / 3) for source episodes of 13 and 14 frames
    index = 0
    for e, (task_name, prompt) in enumerate([("conditional_pick", PROMPTS["ConditionalPickTask"]),
                                             ("wait_then_act", PROMPTS["WaitThenActTask"])]):
        src = head_source.episodes[e]
        for j in range(lengths[e]):
            item, s = imported[index], 3 * j
            index += 1
            assert item["episode_index"].item() == e and item["frame_index"].item() == j
            np.testing.assert_allclose(item["action"].numpy(), src["action"][s + 3])
            assert item["action"][0].item() == s + 3 and item["action"][1].item() == e
            state = item[ft.STATE_KEY].numpy()
            np.testing.assert_allclose(state[0:3], src["observation.left_eef_pos"][s])
            np.testing.assert_allclose(state[7:10], src["observation.right_eef_pos"][s])
            np.testing.assert_allclose(state[3:7], LEFT_QUAT)  # w >= 0 whatever the source's sign
            np.testing.assert_allclose(state[10:14], RIGHT_QUAT)
            np.testing.assert_allclose(state[14:17], src["observation.state"][s, [11, 16, 21]])
            np.testing.assert_allclose(state[17:19], src["action"][s, 17:19])  # the command in force at frame s
            np.testing.assert_allclose(item[ft.JOINT_POS_KEY].numpy(), src["observation.state"][s])
            for camera, source_camera in (("head", "OBS_HEAD"), ("fixed", "OBS_FIXED")):
                image = item[ft.image_key(camera)]
                assert tuple(image.shape) == (3, *SIZE)
                assert abs(image.mean().item() * 255 - BRIGHTNESS[source_camera](s)) < 3
            assert item[ft.TASK_NAME_KEY] == task_name and item[ft.SPLIT_KEY] == "id" and item["task"] == prompt


def test_task_filter_resize_and_split(head_source, tmp_path):
    root = tmp_path / "wait"
    convert_from_tavis(head_source.root, "local/wait", root, fps=30, image_size=(36, 48), task="wait_then_act",
                       split="ood_spatial", progress=False)  # SVT-AV1 cannot encode much smaller than 24 x 32
    dataset = load(root, "local/wait")
    assert dataset.meta.total_episodes == 1 and dataset.meta.fps == 30 and len(dataset) == 6  # (14 - 1) // 2
    assert tuple(dataset.meta.features[ft.image_key("fixed")]["shape"]) == (36, 48, 3)
    item = dataset[3]
    assert tuple(item[ft.image_key("head")].shape) == (3, 36, 48)
    assert abs(item[ft.image_key("head")].mean().item() * 255 - BRIGHTNESS["OBS_HEAD"](6)) < 3
    assert item["action"][0].item() == 8 and item["action"][1].item() == 1
    assert item[ft.TASK_NAME_KEY] == "wait_then_act" and item[ft.SPLIT_KEY] == "ood_spatial"


def test_named_neck_joints_and_robot_from_the_dataset_name(reachy_source, tmp_path):
    root = tmp_path / "reachy"
    convert_from_tavis(reachy_source.root, "local/reachy", root, fps=20, progress=False)
    dataset = load(root, "local/reachy")
    meta, src = dataset.meta, reachy_source.episodes[0]
    assert meta.robot_type == "reachy2" and len(dataset) == 2  # (7 - 1) // 3
    assert list(meta.camera_keys) == [ft.image_key("left_wrist")]
    assert meta.features[ft.JOINT_POS_KEY]["names"][:3] == ["neck_roll", "neck_pitch", "neck_yaw"]
    np.testing.assert_allclose(dataset[1][ft.STATE_KEY][14:17].numpy(), src["observation.state"][3, :3])
    assert dataset[1][ft.TASK_NAME_KEY] == "occluded_reach"


def test_task_class_names_map_to_ours():
    assert task_name_for_class("ConditionalPickTask") == "conditional_pick"
    assert task_name_for_class("BlockedClutterPickCubeTask") == "blocked_clutter_pick_cube"
    assert len(TASK_CLASSES) == 8 and "tabletop" not in TASK_CLASSES.values()


def test_bad_requests_write_nothing(head_source, tmp_path):
    mystery = make_source(tmp_path / "tavis-head-gr1t2", "gr1t2", [("MysteryTask", 4)], cameras=("OBS_HEAD",))
    destination = tmp_path / "out"
    with pytest.raises(ValueError, match="MysteryTask.*ConditionalPickTask"):
        convert_from_tavis(mystery.root, "local/out", destination, progress=False)
    for fps in (25, 7, 0, 120):
        with pytest.raises(ValueError, match="fps must divide the source rate 60 Hz"):
            convert_from_tavis(head_source.root, "local/out", destination, fps=fps, progress=False)
    with pytest.raises(ValueError, match="task must be one of"):
        convert_from_tavis(head_source.root, "local/out", destination, task="tabletop", progress=False)
    with pytest.raises(ValueError, match="split must be one of"):
        convert_from_tavis(head_source.root, "local/out", destination, split="train", progress=False)
    with pytest.raises(FileNotFoundError, match="meta/info.json"):
        convert_from_tavis(tmp_path / "missing", "local/out", destination, progress=False)
    assert not destination.exists() and no_leftovers(destination)


def test_an_existing_destination_needs_overwrite(reachy_source, tmp_path):
    destination = tmp_path / "out"
    destination.mkdir()
    (destination / "keep.txt").write_text("earlier")
    with pytest.raises(FileExistsError):
        convert_from_tavis(reachy_source.root, "local/out", destination, progress=False)
    assert (destination / "keep.txt").exists() and no_leftovers(destination)
    convert_from_tavis(reachy_source.root, "local/out", destination, overwrite=True, progress=False)
    assert not (destination / "keep.txt").exists() and load(destination, "local/out").meta.total_episodes == 1
    assert no_leftovers(destination)


def test_a_failed_conversion_leaves_nothing(head_source, tmp_path, monkeypatch):
    import gc

    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    save_episode = LeRobotDataset.save_episode

    def fail_on_the_second(self, *args, **kwargs):
        if self.meta.total_episodes:
            raise RuntimeError("disk full")
        return save_episode(self, *args, **kwargs)

    monkeypatch.setattr(LeRobotDataset, "save_episode", fail_on_the_second)
    destination = tmp_path / "out"
    with pytest.raises(RuntimeError, match="disk full"):
        convert_from_tavis(head_source.root, "local/out", destination, image_size=SIZE, progress=False)
    gc.collect()  # a dataset object left unfinalized would write its buffered metadata now
    assert not destination.exists() and no_leftovers(destination)
