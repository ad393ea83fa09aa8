"""Human-like motion primitives for scripted actions: minimum-jerk profiles and interpolation of 19-D actions.

Everything here works on canonical actions (numpy only, no simulator): positions in the canonical frame (m),
quaternions w, x, y, z, head angles (rad), grippers in [-1, 1].
"""

from __future__ import annotations

import numpy as np

from lerobot_tavis import canonical


def min_jerk(s: float | np.ndarray) -> float | np.ndarray:
    """Minimum-jerk progress 10s³ - 15s⁴ + 6s⁵ for normalised time s in [0, 1] (clipped outside)."""
    s = np.clip(s, 0.0, 1.0)
    return s**3 * (10.0 + s * (-15.0 + 6.0 * s))


def slerp(q0, q1, s: float) -> np.ndarray:
    """Spherical interpolation between unit quaternions along the shorter arc."""
    q0, q1 = np.asarray(q0, dtype=float), np.asarray(q1, dtype=float)
    dot = float(np.dot(q0, q1))
    if dot < 0.0:
        q1, dot = -q1, -dot
    if dot > 0.9995:
        q = q0 + s * (q1 - q0)
        return q / np.linalg.norm(q)
    theta = np.arccos(dot)
    return (np.sin((1 - s) * theta) * q0 + np.sin(s * theta) * q1) / np.sin(theta)


def interpolate_action(start: np.ndarray, end: np.ndarray, s: float) -> np.ndarray:
    """Action at progress s in [0, 1] between two actions: linear in position, head and grippers, slerp in
    orientation (apply a profile such as `min_jerk` to s first)."""
    action = start + s * (end - start)
    for arm in canonical.ARMS:
        action[arm.quaternion] = slerp(start[arm.quaternion], end[arm.quaternion], s)
    return action
