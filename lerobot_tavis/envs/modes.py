"""Camera modes: which cameras a policy sees, and whether the neck moves. No MuJoCo import.

The paper's two conditions are `head_wrist` (its "headcam": head camera and both wrist cameras) and `fixed_wrist`
(its "fixedcam": fixed workspace camera and both wrists), reference §9; `head_wrist` is the default everywhere.
`head_only` and `fixed_only` (one camera, no wrists) are ablations the paper does not report.
"""

from __future__ import annotations

import warnings

from lerobot_tavis.errors import FieldError

CAMERA_NAMES = ("head", "fixed", "left_wrist", "right_wrist")
# Cameras for people (gallery, videos), never part of a camera mode's observation.
OVERVIEW_CAMERA = "overview"
VIEW_CAMERAS = (OVERVIEW_CAMERA,)

CAMERA_MODES: dict[str, tuple[str, ...]] = {
    "head_wrist": ("head", "left_wrist", "right_wrist"),
    "fixed_wrist": ("fixed", "left_wrist", "right_wrist"),
    "head_only": ("head",),
    "fixed_only": ("fixed",),
}
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
