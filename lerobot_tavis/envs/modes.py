"""The camera-mode registry: which cameras a policy sees, and whether the neck moves. No MuJoCo import.

`CAMERA_MODES` below is the one place a camera mode is declared; modes from outside the package join with
`register_camera_mode` (docs/extending.md).

The paper's two conditions are `head_wrist` (its "headcam": head camera and both wrist cameras) and `fixed_wrist`
(its "fixedcam": fixed workspace camera and both wrists), docs/reference.md §1; `head_wrist` is the default everywhere.
`head_only` and `fixed_only` (one camera, no wrists) are ablations the paper does not report.
"""

from __future__ import annotations

import re
import warnings

from lerobot_tavis.errors import FieldError

CAMERA_NAMES = ("head", "fixed", "left_wrist", "right_wrist")
WRIST_CAMERAS = ("left_wrist", "right_wrist")  # the cameras on the hands
# Cameras for people (gallery, videos), never part of a camera mode's observation.
OVERVIEW_CAMERA = "overview"
VIEW_CAMERAS = (OVERVIEW_CAMERA,)

CAMERA_MODES: dict[str, tuple[str, ...]] = {
    "head_wrist": ("head", "left_wrist", "right_wrist"),
    "fixed_wrist": ("fixed", "left_wrist", "right_wrist"),
    "head_only": ("head",),
    "fixed_only": ("fixed",),
}
BUILTIN_CAMERA_MODES = tuple(CAMERA_MODES)
DEFAULT_CAMERA_MODE = "head_wrist"
PAPER_CONDITIONS = {"headcam": "head_wrist", "fixedcam": "fixed_wrist"}  # the paper's name -> our camera mode
# Names this package used before the paper's conditions became the default; they meant one camera alone.
RENAMED_MODES = {"headcam": "head_only", "fixedcam": "fixed_only"}


def resolve_camera_mode(camera_mode: str) -> str:
    """The camera mode's current name: old names still work, with a one-line deprecation warning."""
    if camera_mode in RENAMED_MODES:
        new = RENAMED_MODES[camera_mode]
        warnings.warn(f"camera mode {camera_mode!r} is now called {new!r} (one camera, no wrists); the paper's "
                      f"{camera_mode} condition is {PAPER_CONDITIONS[camera_mode]!r}", FutureWarning, stacklevel=2)
        return new
    mode_cameras(camera_mode)
    return camera_mode


def mode_cameras(camera_mode: str) -> tuple[str, ...]:
    try:
        return CAMERA_MODES[camera_mode]
    except KeyError:
        raise FieldError("camera_mode", f"must be one of {list(CAMERA_MODES)}, got {camera_mode!r}") from None


def neck_locked(camera_mode: str) -> bool:
    """Fixed-camera modes hold the neck at 0 and report it as 0, as in the reference protocol."""
    return mode_cameras(camera_mode)[0] == "fixed"


def camera_mode_names() -> tuple[str, ...]:
    """Every registered camera mode, built-in ones first (old names in `RENAMED_MODES` are accepted too)."""
    return tuple(CAMERA_MODES)


def register_camera_mode(name: str, cameras: tuple[str, ...]) -> tuple[str, ...]:
    """Add a camera mode from outside the package (docs/extending.md): the cameras a policy sees, from
    `CAMERA_NAMES`. A mode whose first camera is `fixed` holds the neck (`neck_locked`). Returns the cameras."""
    if not (isinstance(name, str) and re.fullmatch(r"[a-z][a-z0-9_]*", name)):
        raise ValueError(f"camera mode name must be lower_snake_case, got {name!r}")
    if name in CAMERA_MODES or name in RENAMED_MODES:
        raise ValueError(f"camera mode {name!r} is already registered")
    cameras = tuple(cameras) if isinstance(cameras, (tuple, list)) else (cameras,)
    if not cameras or len(set(cameras)) != len(cameras) or not set(cameras) <= set(CAMERA_NAMES):
        raise ValueError(f"cameras of camera mode {name!r} must be distinct names among {CAMERA_NAMES}, "
                         f"got {cameras!r}")
    CAMERA_MODES[name] = cameras
    return cameras


def unregister_camera_mode(name: str) -> None:
    """Remove a camera mode added by `register_camera_mode` (tests clean up with it); built-in modes stay."""
    if name in BUILTIN_CAMERA_MODES:
        raise ValueError(f"camera mode {name!r} is built in and cannot be unregistered")
    mode_cameras(name)
    del CAMERA_MODES[name]
