"""Human-like motion primitives for scripted actions: minimum-jerk profiles and keyframed 19-D action scripts.

Everything here works on canonical actions (numpy only, no simulator): positions in the canonical frame (m),
quaternions w, x, y, z, head angles (rad), grippers in [-1, 1].
"""

from __future__ import annotations

from dataclasses import dataclass

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


def top_down_hand_quat(yaw_rad: float) -> np.ndarray:
    """Hand orientation pointing the gripper straight down, turned `yaw_rad` about the world z axis.

    At yaw 0 the fingers close along the world y axis (hand-frame convention of `envs.robots.parts`).
    """
    return np.array([np.cos(yaw_rad / 2), 0.0, 0.0, np.sin(yaw_rad / 2)])


def interpolate_action(start: np.ndarray, end: np.ndarray, s: float) -> np.ndarray:
    """Action at progress s in [0, 1] between two actions: linear in position, head and grippers, slerp in
    orientation (apply a profile such as `min_jerk` to s first)."""
    action = start + s * (end - start)
    for arm in canonical.ARMS:
        action[arm.quaternion] = slerp(start[arm.quaternion], end[arm.quaternion], s)
    return action


@dataclass(frozen=True)
class Keyframe:
    """Move to `action` over `duration_s` with a minimum-jerk profile, then continue with the next keyframe."""

    action: np.ndarray
    duration_s: float


class ActionScript:
    """A sequence of keyframes played from a start action; `action_at(t)` gives the commanded action at t (s)."""

    def __init__(self, start: np.ndarray, keyframes: list[Keyframe]):
        self.start = np.asarray(start, dtype=float)
        self.keyframes = keyframes
        self.ends = np.cumsum([k.duration_s for k in keyframes])

    @property
    def duration_s(self) -> float:
        return float(self.ends[-1]) if len(self.ends) else 0.0

    def action_at(self, t: float) -> np.ndarray:
        previous, t0 = self.start, 0.0
        for keyframe, t1 in zip(self.keyframes, self.ends):
            if t < t1:
                return interpolate_action(previous, keyframe.action, float(min_jerk((t - t0) / keyframe.duration_s)))
            previous, t0 = keyframe.action, t1
        return previous.copy()
