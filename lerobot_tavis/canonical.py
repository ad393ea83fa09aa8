"""The canonical 19-D action (and state) shared by both robots.

Layout (docs/reference.md §6), every position in the canonical frame: the robot root's orientation with its origin at
hip level (world z 0.93), x forward, y left, z up; quaternions w, x, y, z.

    [0:3]   left end-effector position, m        [3:7]   left end-effector orientation
    [7:10]  right end-effector position, m       [10:14] right end-effector orientation
    [14:17] head roll, pitch, yaw (absolute joint angles, rad; +pitch looks down, +yaw looks left)
    [17]    left gripper, [18] right gripper, in [-1, 1] with +1 closed and -1 open

The measured state (`agent_pos`) uses the same layout. This module is numpy-only on purpose: metrics, dataset
tools and policy presets use it without importing the simulator.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

ACTION_DIM = 19

HEAD = slice(14, 17)
HEAD_ROLL, HEAD_PITCH, HEAD_YAW = 14, 15, 16
GRIPPER_OPEN, GRIPPER_CLOSED = -1.0, 1.0


@dataclass(frozen=True)
class ArmSlots:
    """Where one arm's quantities sit in the 19-D vector."""

    side: str
    position: slice
    quaternion: slice
    gripper: int


LEFT = ArmSlots("left", slice(0, 3), slice(3, 7), 17)
RIGHT = ArmSlots("right", slice(7, 10), slice(10, 14), 18)
ARMS = (LEFT, RIGHT)

ACTION_NAMES: tuple[str, ...] = (
    *(f"left_ee_{c}" for c in ("x", "y", "z", "qw", "qx", "qy", "qz")),
    *(f"right_ee_{c}" for c in ("x", "y", "z", "qw", "qx", "qy", "qz")),
    "head_roll",
    "head_pitch",
    "head_yaw",
    "left_gripper",
    "right_gripper",
)

# Rest end-effector poses (docs/reference.md §5), canonical frame.
REST_POSITION = {"left": (0.3, 0.2, 0.3), "right": (0.3, -0.2, 0.3)}
REST_QUATERNION = {
    "left": (0.6400948, -0.00045091, -0.7682481, -0.00857063),
    "right": (0.6400948, 0.00045053, -0.76824796, 0.00857048),
}


def rest_action() -> np.ndarray:
    """The rest action: both hands at their rest poses, head straight ahead, grippers open."""
    action = np.zeros(ACTION_DIM)
    for arm in ARMS:
        action[arm.position] = REST_POSITION[arm.side]
        action[arm.quaternion] = REST_QUATERNION[arm.side]
        action[arm.gripper] = GRIPPER_OPEN
    return action


def validate_action(action) -> np.ndarray:
    """Return `action` as a float64 (19,) array, or raise ValueError naming what is wrong.

    Checks that it is real numbers (a complex part is never dropped silently), the shape, that every value is
    finite, and that both quaternions have a usable norm. Range clipping (head, grippers) is robot-specific and done
    by the controller.
    """
    try:
        raw = np.asarray(action)
    except ValueError:  # ragged nesting
        raw = np.asarray(None)
    if raw.dtype.kind == "c" or (raw.dtype.kind == "O" and any(np.iscomplexobj(v) for v in raw.flat)):
        raise ValueError(f"action must be real numbers, got complex values ({type(action).__name__} of {raw.dtype})")
    try:
        numeric = raw.dtype.kind in "biuf" or (raw.dtype.kind == "O" and raw.ndim > 0)
        array = raw.astype(np.float64) if numeric else None
    except (TypeError, ValueError):  # objects that are not numbers
        array = None
    if array is None:
        raise ValueError(f"action must be an array of {ACTION_DIM} numbers, got {type(action).__name__}")
    if array.shape != (ACTION_DIM,):
        raise ValueError(f"action must have shape ({ACTION_DIM},), got {array.shape}")
    bad = np.flatnonzero(~np.isfinite(array))
    if bad.size:
        i = int(bad[0])
        raise ValueError(f"action[{i}] ({ACTION_NAMES[i]}) must be finite, got {array[i]}")
    for arm in ARMS:
        if np.max(np.abs(array[arm.quaternion])) < 1e-6:
            s = arm.quaternion
            raise ValueError(f"action[{s.start}:{s.stop}] ({arm.side} end-effector quaternion) has zero norm")
    return array
