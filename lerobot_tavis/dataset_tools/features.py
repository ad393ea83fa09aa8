"""The LeRobotDataset v3.0 schema of TAVIS datasets: keys, names and shapes. No MuJoCo import.

Per frame (20 Hz by default):

- `observation.images.<camera>`: video (or PNG images, see STORAGES), (H, W, 3), cameras `head`, `fixed`,
  `left_wrist`, `right_wrist`
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
from lerobot_tavis.errors import FieldError
STATE_KEY = "observation.state"
JOINT_POS_KEY = "observation.joint_pos"
ACTION_KEY = "action"
TASK_NAME_KEY = "task_name"
SPLIT_KEY = "split"
IMAGE_NAMES = ["height", "width", "channels"]

# How camera frames are stored. Training reads frames at random: an AV1 frame is decoded from its keyframe (every
# second frame) with a slow software decoder; all-intra H.264 decodes each frame alone and fast; PNG images need no
# video decoder at all but take several times the disk.
STORAGES = ("av1", "h264", "png")


def image_key(camera: str) -> str:
    return f"observation.images.{camera}"


def parse_cameras(text: str | Sequence[str]) -> tuple[str, ...]:
    """`head,fixed` or ["head", "fixed"] -> ("head", "fixed"), checked against CAMERAS."""
    cameras = tuple(c.strip() for c in (text.split(",") if isinstance(text, str) else text) if c.strip())
    unknown = [c for c in cameras if c not in CAMERAS]
    if unknown or not cameras or len(set(cameras)) != len(cameras):
        raise FieldError("cameras", f"must be distinct names among {CAMERAS}, got {text!r}")
    return cameras


def check_storage(storage: str) -> str:
    if storage not in STORAGES:
        raise FieldError("storage", f"must be one of {STORAGES}, got {storage!r}")
    return storage


def video_encoder(storage: str):
    """LeRobot's RGB encoder settings for a video storage (None: LeRobot's default, AV1 with a keyframe every 2)."""
    from lerobot.configs.video import RGBEncoderConfig

    if check_storage(storage) == "h264":
        return RGBEncoderConfig(vcodec="h264", g=1, crf=18, preset="veryfast", fast_decode=1)
    return None


def frame_stride(source_fps: int, fps: int) -> int:
    """Source frames per dataset frame when a `source_fps` recording becomes an `fps` dataset (fps must divide it)."""
    if not (isinstance(fps, int) and 0 < fps <= source_fps and source_fps % fps == 0):
        divisors = [d for d in range(1, source_fps + 1) if source_fps % d == 0]
        raise FieldError("fps", f"must divide the source rate {source_fps} Hz, one of {divisors}; got {fps!r}")
    return source_fps // fps


def dataset_features(joint_names: Sequence[str], cameras: Sequence[str],
                     image_size: tuple[int, int], storage: str = "av1") -> dict[str, dict]:
    """The `features` argument of `LeRobotDataset.create` for a TAVIS dataset."""
    height, width = image_size
    dtype = "image" if check_storage(storage) == "png" else "video"
    features = {image_key(camera): {"dtype": dtype, "shape": (height, width, 3), "names": IMAGE_NAMES}
                for camera in parse_cameras(cameras)}
    features[STATE_KEY] = {"dtype": "float32", "shape": (canonical.ACTION_DIM,), "names": list(canonical.ACTION_NAMES)}
    features[JOINT_POS_KEY] = {"dtype": "float32", "shape": (len(joint_names),), "names": list(joint_names)}
    features[ACTION_KEY] = {"dtype": "float32", "shape": (canonical.ACTION_DIM,), "names": list(canonical.ACTION_NAMES)}
    features[TASK_NAME_KEY] = {"dtype": "string", "shape": (1,), "names": None}
    features[SPLIT_KEY] = {"dtype": "string", "shape": (1,), "names": None}
    return features
