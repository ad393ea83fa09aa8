"""The LeRobotDataset v3.0 schema of TAVIS datasets: keys, names and shapes. No MuJoCo import.

Per frame (20 Hz by default):

- `observation.images.<camera>`: video, (H, W, 3), cameras `head`, `fixed`, `left_wrist`, `right_wrist`
- `observation.state`: float32 (19,), the measured canonical state (`lerobot_tavis.canonical`, same layout as action)
- `observation.joint_pos`: float32 (J,), the robot's joints (names from the robot)
- `action`: float32 (19,), the canonical action taken from this frame's observation
- `task_name`, `split`: string (1,), the TAVIS task and split of the episode
- LeRobot's `task`: the episode's prompt
"""

from __future__ import annotations

from collections.abc import Sequence

from lerobot_tavis import canonical
from lerobot_tavis.envs.modes import CAMERA_NAMES as CAMERAS
STATE_KEY = "observation.state"
JOINT_POS_KEY = "observation.joint_pos"
ACTION_KEY = "action"
TASK_NAME_KEY = "task_name"
SPLIT_KEY = "split"
IMAGE_NAMES = ["height", "width", "channels"]


def image_key(camera: str) -> str:
    return f"observation.images.{camera}"


def parse_cameras(text: str | Sequence[str]) -> tuple[str, ...]:
    """`head,fixed` or ["head", "fixed"] -> ("head", "fixed"), checked against CAMERAS."""
    cameras = tuple(c.strip() for c in (text.split(",") if isinstance(text, str) else text) if c.strip())
    unknown = [c for c in cameras if c not in CAMERAS]
    if unknown or not cameras or len(set(cameras)) != len(cameras):
        raise ValueError(f"cameras must be distinct names among {CAMERAS}, got {text!r}")
    return cameras


def frame_stride(source_fps: int, fps: int) -> int:
    """Source frames per dataset frame when a `source_fps` recording becomes an `fps` dataset (fps must divide it)."""
    if not (isinstance(fps, int) and 0 < fps <= source_fps and source_fps % fps == 0):
        divisors = [d for d in range(1, source_fps + 1) if source_fps % d == 0]
        raise ValueError(f"fps must divide the source rate {source_fps} Hz, one of {divisors}; got {fps!r}")
    return source_fps // fps


def dataset_features(joint_names: Sequence[str], cameras: Sequence[str],
                     image_size: tuple[int, int]) -> dict[str, dict]:
    """The `features` argument of `LeRobotDataset.create` for a TAVIS dataset."""
    height, width = image_size
    features = {image_key(camera): {"dtype": "video", "shape": (height, width, 3), "names": IMAGE_NAMES}
                for camera in parse_cameras(cameras)}
    features[STATE_KEY] = {"dtype": "float32", "shape": (canonical.ACTION_DIM,), "names": list(canonical.ACTION_NAMES)}
    features[JOINT_POS_KEY] = {"dtype": "float32", "shape": (len(joint_names),), "names": list(joint_names)}
    features[ACTION_KEY] = {"dtype": "float32", "shape": (canonical.ACTION_DIM,), "names": list(canonical.ACTION_NAMES)}
    features[TASK_NAME_KEY] = {"dtype": "string", "shape": (1,), "names": None}
    features[SPLIT_KEY] = {"dtype": "string", "shape": (1,), "names": None}
    return features
