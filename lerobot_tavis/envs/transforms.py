"""Small rotation helpers. Quaternions are w, x, y, z; matrices rotate column vectors. MuJoCo is imported where a
helper uses it, so that metrics and dataset tools can share these without loading the simulator."""

from __future__ import annotations

import numpy as np


def quat_from_matrix(matrix: np.ndarray) -> np.ndarray:
    import mujoco

    quat = np.empty(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(matrix, dtype=float).reshape(9))
    return quat


def matrix_from_quat(quat) -> np.ndarray:
    import mujoco

    matrix = np.empty(9)
    mujoco.mju_quat2Mat(matrix, np.asarray(quat, dtype=float))
    return matrix.reshape(3, 3)


def axis_angle_quat(axis, angle_rad: float) -> np.ndarray:
    axis = np.asarray(axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    return np.concatenate([[np.cos(angle_rad / 2)], np.sin(angle_rad / 2) * axis])


def quat_multiply(a, b) -> np.ndarray:
    import mujoco

    out = np.empty(4)
    mujoco.mju_mulQuat(out, np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    return out


def quat_angle_rad(a, b) -> float:
    """Angle of the rotation between two orientations, in [0, pi]."""
    return float(quat_angles_rad(np.asarray(a, dtype=float), np.asarray(b, dtype=float)))


def quat_angles_rad(q1: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """Row-wise angles (rad, in [0, pi]) of the rotations between orientations q1 and q2 (..., 4; any norm; q and -q
    are the same rotation)."""
    q1 = q1 / np.linalg.norm(q1, axis=-1, keepdims=True)
    q2 = q2 / np.linalg.norm(q2, axis=-1, keepdims=True)
    return 2.0 * np.arccos(np.clip(np.abs(np.sum(q1 * q2, axis=-1)), 0.0, 1.0))


def camera_quat(forward, up) -> np.ndarray:
    """Orientation of a MuJoCo camera (which looks along its -z with +y up) looking along `forward`.

    `up` only needs a component orthogonal to `forward`; it sets which way is up in the image.
    """
    forward = np.asarray(forward, dtype=float)
    forward = forward / np.linalg.norm(forward)
    up = np.asarray(up, dtype=float)
    up = up - np.dot(up, forward) * forward
    up = up / np.linalg.norm(up)
    right = np.cross(forward, up)
    return quat_from_matrix(np.column_stack([right, up, -forward]))


def vfov_deg(hfov_deg: float, width: int = 640, height: int = 480) -> float:
    """Vertical field of view of a pinhole camera with square pixels."""
    return float(np.degrees(2 * np.arctan(np.tan(np.radians(hfov_deg) / 2) * height / width)))
