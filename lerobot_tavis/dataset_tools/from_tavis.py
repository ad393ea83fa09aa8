"""Import a dataset published by the original TAVIS benchmark (e.g. `tavis-benchmark/tavis-head-gr1t2`) into our schema.

The source is a local LeRobotDataset v3.0 recorded by teleoperation at 60 Hz (docs/reference.md §11): cameras
`observation.images.OBS_{HEAD,FIXED,WRIST_LEFT,WRIST_RIGHT}` (videos), `observation.state` = the robot's full
joint vector, `observation.{left,right}_eef_{pos,quat}`, the 19-D canonical `action`, `language_instruction`, and
the task *class* name (e.g. "ConditionalPickTask") as LeRobot's `task`. The result follows
`lerobot_tavis.dataset_tools.features`: cameras `head`/`fixed`/`left_wrist`/`right_wrist`, the canonical 19-D
`observation.state`, `observation.joint_pos`, `action`, `task_name`, `split`, and the prompt as LeRobot's `task`.

Frame alignment. The source pairs, in its frame k, the action sent at step k with the observation measured *after*
step k. With `stride = 60 / fps`, our frame j holds the observation of source frame s = stride * j and the action
of source frame s + stride: the last of the `stride` commands sent after that observation, as the reference's
training reads it (its +1 action shift, docs/reference.md §11) and as `tavis convert` pairs its own recordings.
A source episode of n frames gives floor((n - 1) / stride) frames: the last observations have no complete interval
after them.

Canonical state of source frame s (docs/reference.md §6, §11):

- hand positions: `observation.{left,right}_eef_pos`, already canonical (body minus root minus the canonical offset);
- hand orientations: `observation.{left,right}_eef_quat` (w, x, y, z; world frame, which is the canonical frame's
  orientation because both robots' roots are unrotated), sign-flipped to w >= 0 like our measured state. These
  are the observed links (GR1T2 `*_hand_roll_link`, Reachy2 `*_palm_ik_target`); for GR1T2 that is not the link
  the action's IK drives (`*_hand_pitch_link`); the transform between the two is not published, so none is applied;
- head roll, pitch, yaw: from the joint vector, located by joint name when the source names its joints, else at
  the reference's indices (GR1T2 11, 16, 21; Reachy2 5, 8, 9). The published datasets carry no joint names;
- grippers: the gripper command in force when the observation was taken (the action of source frame s). The
  finger joints' place in the joint vector is undocumented, so the measured opening cannot be read faithfully.
  It differs from our measured state while a grasped object stops the fingers.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from lerobot_tavis import canonical, checks
from lerobot_tavis.dataset_tools import features as ft
from lerobot_tavis.dataset_tools.quiet import quiet_media_libraries
from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS, PROTOCOL_SPLITS
from lerobot_tavis.errors import FieldError, InputError, PathNotFoundError
from lerobot_tavis.staging import staged_directory

SOURCE_CAMERAS = {
    "observation.images.OBS_HEAD": "head",
    "observation.images.OBS_FIXED": "fixed",
    "observation.images.OBS_WRIST_LEFT": "left_wrist",
    "observation.images.OBS_WRIST_RIGHT": "right_wrist",
}
SOURCE_STATE = "observation.state"
SOURCE_POSE = {
    "left": ("observation.left_eef_pos", "observation.left_eef_quat"),
    "right": ("observation.right_eef_pos", "observation.right_eef_quat"),
}
SOURCE_ACTION = "action"
SOURCE_PROMPT = "language_instruction"
# Neck joints (roll, pitch, yaw) by name and, for unnamed joint vectors, by index (docs/reference.md §5).
NECK = {
    "gr1t2": (("head_roll_joint", "head_pitch_joint", "head_yaw_joint"), (11, 16, 21)),
    "reachy2": (("neck_roll", "neck_pitch", "neck_yaw"), (5, 8, 9)),
}


def _class_name(task: str) -> str:
    return "".join(word.capitalize() for word in task.split("_")) + "Task"


# The reference's task class names (its `task` field) -> our task names, for the benchmark suites.
TASK_CLASSES = {_class_name(name): name for name in BENCHMARK_TASKS}


def task_name_for_class(class_name: str) -> str:
    """"ConditionalPickTask" -> "conditional_pick"; ValueError for a class the benchmark does not have."""
    try:
        return TASK_CLASSES[class_name]
    except KeyError:
        raise InputError(f"unknown TAVIS task class {class_name!r}; known: {sorted(TASK_CLASSES)}") from None


def convert_from_tavis(source_root: str | Path, repo_id: str, root: str | Path, *, fps: int = 20,
                       image_size: tuple[int, int] | None = None, overwrite: bool = False, task: str | None = None,
                       split: str = "id", progress: bool = True) -> Path:
    """Convert the original benchmark's dataset at `source_root` into a new dataset `repo_id` at `root`.

    `fps` must divide the source rate (60 Hz); `image_size` (H, W) resizes every camera (INTER_AREA), default the
    source size; `task` (our name, e.g. "conditional_pick") keeps that task's episodes only; `split` is recorded
    in every frame. Nothing is written unless the whole conversion succeeds; an existing `root` is a
    FileExistsError unless `overwrite`. Reads only local files. Returns `root`.
    """
    from lerobot.datasets.dataset_metadata import LeRobotDatasetMetadata
    from lerobot.datasets.lerobot_dataset import LeRobotDataset
    from tqdm import tqdm

    checks.repo_id(repo_id)
    source_root = Path(source_root)
    if not (source_root / "meta" / "info.json").is_file():
        raise PathNotFoundError(f"source_root {source_root} holds no LeRobot dataset (meta/info.json missing)")
    if split not in PROTOCOL_SPLITS:
        raise FieldError("split", f"must be one of {PROTOCOL_SPLITS}, got {split!r}")
    if task is not None and task not in TASK_CLASSES.values():
        raise FieldError("task", f"must be one of {sorted(TASK_CLASSES.values())}, got {task!r}")
    meta = LeRobotDatasetMetadata(f"tavis-benchmark/{source_root.name}", root=source_root)
    stride = ft.frame_stride(meta.fps, fps)
    _check_source_features(meta.features)
    robot = _robot_type(meta.robot_type, source_root.name)
    cameras = {key: name for key, name in SOURCE_CAMERAS.items() if key in meta.features}
    size = _image_size(meta.features, cameras, image_size)
    joint_names = _joint_names(meta.features[SOURCE_STATE], robot)
    neck = _neck_indices(joint_names, robot)
    episodes = [(int(ep["episode_index"]), _episode_task(ep)) for ep in meta.episodes]
    if task is not None:
        episodes = [(index, name) for index, name in episodes if name == task]
        if not episodes:
            raise InputError(f"{source_root} has no episode of task {task!r}")

    quiet_media_libraries()
    with staged_directory(root, overwrite=overwrite) as staging:
        # LeRobot's streaming encoder (threads, every frame kept: queue unbounded, as `convert` uses it): its
        # default encodes each saved episode's cameras in a process pool forked from this multi-threaded process
        dataset = LeRobotDataset.create(repo_id, fps=fps, root=staging, robot_type=robot, use_videos=True,
                                        features=ft.dataset_features(joint_names, cameras.values(), size),
                                        streaming_encoding=True, encoder_queue_maxsize=0)
        try:
            for index, task_name in tqdm(episodes, desc=f"import {source_root.name}", unit="ep",
                                         disable=not progress):
                added = 0
                for frame in _episode_frames(meta, index, stride, cameras, size, neck):
                    dataset.add_frame({**frame, ft.TASK_NAME_KEY: task_name, ft.SPLIT_KEY: split})
                    added += 1
                if added:  # a source episode of fewer than 2 frames gives none
                    dataset.save_episode()
        finally:  # also on failure: an unfinalized dataset writes its buffered metadata when collected
            dataset.finalize()
    return Path(root)


def _check_source_features(features: dict) -> None:
    shapes = {SOURCE_STATE: None, SOURCE_ACTION: (canonical.ACTION_DIM,), SOURCE_PROMPT: None}
    for position, quaternion in SOURCE_POSE.values():
        shapes |= {position: (3,), quaternion: (4,)}
    missing = [key for key in shapes if key not in features]
    if missing:
        raise InputError(f"source dataset lacks the TAVIS features {missing}")
    for key, shape in shapes.items():
        if shape is not None and tuple(features[key]["shape"]) != shape:
            raise InputError(f"source feature {key} must have shape {shape}, got {tuple(features[key]['shape'])}")
    cameras = [key for key in SOURCE_CAMERAS if key in features]
    if not cameras:
        raise InputError(f"source dataset has none of the cameras {list(SOURCE_CAMERAS)}")
    not_video = [key for key in cameras if features[key]["dtype"] != "video"]
    if not_video:
        raise InputError(f"source cameras must be stored as videos: {not_video}")


def _robot_type(robot_type: str | None, dataset_name: str) -> str:
    """Our robot name from the source's `robot_type`, else from its directory name (e.g. `tavis-head-gr1t2`)."""
    for text in (robot_type or "", dataset_name):
        found = [robot for robot in NECK if robot in text.lower()]
        if len(found) == 1:
            return found[0]
    raise InputError(f"cannot tell the robot (one of {sorted(NECK)}) from robot_type {robot_type!r} or the "
                     f"dataset name {dataset_name!r}")


def _image_size(features: dict, cameras: dict[str, str], image_size: tuple[int, int] | None) -> tuple[int, int]:
    if image_size is not None:
        height, width = image_size
        if height < 1 or width < 1:
            raise FieldError("image_size", f"must be (height, width) with both >= 1, got {image_size!r}")
        return int(height), int(width)
    sizes = {tuple(features[key]["shape"][:2]) for key in cameras}
    if len(sizes) != 1:
        raise InputError(f"source cameras differ in size {sorted(sizes)}: pass image_size")
    return sizes.pop()


def _joint_names(feature: dict, robot: str) -> list[str]:
    """The source's joint names, or `joint_<i>` with the neck joints named at the reference's indices where it
    carries none (the published datasets name every vector ["height", "width", "channels"])."""
    count = int(feature["shape"][0])
    names = feature.get("names")
    if isinstance(names, list) and len(names) == count and len(set(names)) == count and names != ft.IMAGE_NAMES:
        return [str(name) for name in names]
    generated = [f"joint_{i}" for i in range(count)]
    for name, i in zip(NECK[robot][0], _reference_neck(robot, count), strict=True):
        generated[i] = name
    return generated


def _neck_indices(joint_names: list[str], robot: str) -> list[int]:
    """Indices of head roll, pitch, yaw in the joint vector: by name, else the reference's."""
    neck_names = NECK[robot][0]
    if all(name in joint_names for name in neck_names):
        return [joint_names.index(name) for name in neck_names]
    return _reference_neck(robot, len(joint_names))


def _reference_neck(robot: str, count: int) -> list[int]:
    indices = list(NECK[robot][1])
    if max(indices) >= count:
        raise InputError(f"{robot} joint vector has {count} joints, too few for the reference neck indices {indices}")
    return indices


def _episode_task(episode: dict) -> str:
    tasks = list(episode["tasks"])
    if len(tasks) != 1:
        raise InputError(f"source episode {episode['episode_index']} must have one task, got {tasks}")
    return task_name_for_class(tasks[0])


def _episode_frames(meta, index: int, stride: int, cameras: dict[str, str], size: tuple[int, int],
                    neck: list[int]) -> Iterator[dict]:
    """Our frames of source episode `index`: observation of source frame s, action of frame s + stride (module doc)."""
    import cv2
    import pyarrow.parquet as pq

    vectors = [SOURCE_STATE, SOURCE_ACTION, *(key for pose in SOURCE_POSE.values() for key in pose)]
    table = pq.read_table(meta.root / meta.get_data_file_path(index),
                          columns=["frame_index", "timestamp", SOURCE_PROMPT, *vectors],
                          filters=[("episode_index", "==", index)]).sort_by("frame_index")
    observed = np.arange(0, table.num_rows - stride, stride)
    if observed.size == 0:
        return
    table = table.take(np.concatenate([observed, observed + stride]))
    count = observed.size
    data = {key: _vectors(table, key) for key in vectors}
    prompts = table.column(SOURCE_PROMPT).to_pylist()[:count]
    times = table.column("timestamp").to_numpy()[:count].astype(np.float64)
    videos = {key: _decode(meta.root / meta.get_video_file_path(index, key),
                           meta.episodes[index][f"videos/{key}/from_timestamp"] + times, meta.fps)
              for key in cameras}
    for j in range(count):
        state = np.zeros(canonical.ACTION_DIM, np.float32)
        for slots in canonical.ARMS:
            position, quaternion = SOURCE_POSE[slots.side]
            quat = data[quaternion][j]
            state[slots.position] = data[position][j]
            state[slots.quaternion] = quat if quat[0] >= 0 else -quat
            state[slots.gripper] = data[SOURCE_ACTION][j, slots.gripper]
        state[canonical.HEAD] = data[SOURCE_STATE][j, neck]
        frame = {ft.STATE_KEY: state, ft.JOINT_POS_KEY: data[SOURCE_STATE][j],
                 ft.ACTION_KEY: data[SOURCE_ACTION][count + j], "task": prompts[j]}
        for key, camera in cameras.items():
            image = next(videos[key])
            if image.shape[:2] != size:
                image = cv2.resize(image, (size[1], size[0]), interpolation=cv2.INTER_AREA)
            frame[ft.image_key(camera)] = image
        yield frame


def _vectors(table, key: str) -> np.ndarray:
    """A list column of `table` as a float32 (rows, D) array."""
    flat = table.column(key).combine_chunks().flatten().to_numpy(zero_copy_only=False)
    return flat.reshape(table.num_rows, -1).astype(np.float32)


def _decode(path: Path, timestamps_s: np.ndarray, fps: int) -> Iterator[np.ndarray]:
    """RGB frames (H, W, 3 uint8) of the video at `path` at the increasing `timestamps_s`, decoded in one pass.

    Each timestamp takes the frame within half a frame period of it; a missing frame is a ValueError."""
    import av

    half_period = 0.5 / fps
    pending = iter(timestamps_s.tolist())
    target = next(pending, None)
    with av.open(str(path)) as container:
        stream = container.streams.video[0]
        container.seek(max(0, math.floor(target / stream.time_base) - 1), backward=True, any_frame=False,
                       stream=stream)
        for frame in container.decode(stream):
            if target is None:
                break
            if frame.pts is None:
                continue
            time_s = float(frame.pts * stream.time_base)
            if time_s < target - half_period:
                continue
            if time_s > target + half_period:
                break
            yield frame.to_ndarray(format="rgb24")
            target = next(pending, None)
    if target is not None:
        raise InputError(f"{path}: no video frame at {target:.4f} s")
