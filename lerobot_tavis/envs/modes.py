"""Camera modes: which cameras a policy sees, and whether the neck moves. No MuJoCo import."""

from __future__ import annotations

CAMERA_NAMES = ("head", "fixed", "left_wrist", "right_wrist")
# Cameras for people (gallery, videos), never part of a camera mode's observation.
VIEW_CAMERAS = ("overview",)

CAMERA_MODES: dict[str, tuple[str, ...]] = {
    "headcam": ("head",),
    "fixedcam": ("fixed",),
    "head_wrist": ("head", "left_wrist", "right_wrist"),
    "fixed_wrist": ("fixed", "left_wrist", "right_wrist"),
}


def mode_cameras(camera_mode: str) -> tuple[str, ...]:
    try:
        return CAMERA_MODES[camera_mode]
    except KeyError:
        raise ValueError(f"camera_mode must be one of {sorted(CAMERA_MODES)}, got {camera_mode!r}") from None


def neck_locked(camera_mode: str) -> bool:
    """Fixed-camera modes hold the neck at 0 and report it as 0, as in the reference protocol."""
    return mode_cameras(camera_mode)[0] == "fixed"
