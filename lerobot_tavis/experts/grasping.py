"""Grasp planning for the scripted demonstrators: which hand orientation to grasp an upright prop with.

A grasp is described in the world frame: the grasp point (between the pads), the approach direction (pitched
down from horizontal, turned by an azimuth about z) and whether the hand is rolled by pi about the approach (the
two-finger gripper is symmetric, so both rolls hold the object the same way). Candidates are checked with the
robot's own kinematics (privileged information a human demonstrator also has: a feel for their own arm).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from lerobot_tavis import canonical
from lerobot_tavis.envs.control import ArmIK
from lerobot_tavis.envs.objects import PropSpec
from lerobot_tavis.envs.scene import TABLE_TOP_Z
from lerobot_tavis.envs.transforms import axis_angle_quat, quat_multiply

PITCHES_RAD = np.radians((30.0, 45.0, 15.0, 60.0))
MAX_AZIMUTH_RAD = 1.1
WIDTH_MARGIN_M = 0.012
FLOOR_CLEARANCE_M = 0.006


@dataclass(frozen=True)
class Grasp:
    side: str
    point: np.ndarray  # world position of the point between the pads, m
    pitch_rad: float  # approach angle below horizontal
    azimuth_rad: float  # approach direction about world z (0 = forward)
    flipped: bool

    @property
    def approach(self) -> np.ndarray:
        c = np.cos(self.pitch_rad)
        return np.array([c * np.cos(self.azimuth_rad), c * np.sin(self.azimuth_rad), -np.sin(self.pitch_rad)])

    @property
    def hand_quat(self) -> np.ndarray:
        """Hand-frame orientation: approach along the hand's -z, fingers closing horizontally."""
        quat = quat_multiply(axis_angle_quat((0, 0, 1), self.azimuth_rad),
                             axis_angle_quat((0, 1, 0), self.pitch_rad - np.pi / 2))
        return quat_multiply(quat, axis_angle_quat((0, 0, 1), np.pi)) if self.flipped else quat

    def lifted(self, height_m: float) -> Grasp:
        return replace(self, point=self.point + np.array([0.0, 0.0, height_m]))

    def ee_pose(self, ik: ArmIK, offset_m: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Canonical end-effector position and quaternion that put the pads on the grasp point, backed off
        `offset_m` along the approach."""
        robot = ik.robot
        wrist = self.point - (robot.gripper.grasp_depth_m + offset_m) * self.approach
        return wrist - np.asarray(robot.canonical_origin), robot.ee_quat_for_hand(self.side, self.hand_quat)

    def action(self, ik: ArmIK, base: np.ndarray, offset_m: float = 0.0, gripper: float | None = None) -> np.ndarray:
        """`base` with this arm's pose (and optionally gripper) replaced."""
        slots = canonical.LEFT if self.side == "left" else canonical.RIGHT
        action = base.copy()
        action[slots.position], action[slots.quaternion] = self.ee_pose(ik, offset_m)
        if gripper is not None:
            action[slots.gripper] = gripper
        return action


def _reach_score(ik: ArmIK, grasp: Grasp) -> float:
    position_error, angle_error = ik.reach_error(grasp.action(ik, canonical.rest_action()), grasp.side)
    return position_error + 0.02 * angle_error


def closing_azimuths(prop: PropSpec, yaw_rad: float, stroke_m: float, toward_rad: float) -> list[float]:
    """Approach azimuths (rad) whose closing direction spans a prop side that fits in the gripper.

    Cylinders can be approached from `toward_rad` (the arm's natural direction); a box from across either of its
    horizontal axes (closing along the other). Azimuths are wrapped to [-pi, pi] and sorted by closeness to
    `toward_rad`.
    """
    if prop.shape == "cylinder":
        return [toward_rad]
    options = []
    for closing_axis, width in ((0, prop.size_m[0]), (1, prop.size_m[1])):
        if width > stroke_m - WIDTH_MARGIN_M:
            continue
        closing_dir = yaw_rad + closing_axis * np.pi / 2
        for k in range(4):  # the approach is perpendicular to the closing direction, from either side
            azimuth = np.angle(np.exp(1j * (closing_dir + np.pi / 2 + k * np.pi)))
            if k < 2:
                options.append(float(azimuth))
    return sorted(set(options), key=lambda a: abs(np.angle(np.exp(1j * (a - toward_rad)))))


def plan_grasp(ik: ArmIK, side: str, prop: PropSpec, center: np.ndarray, yaw_rad: float, lift_m: float = 0.2,
               tolerance_m: float = 0.008) -> Grasp:
    """The first grasp whose grasp pose and lifted pose (`lift_m` higher) are both kinematically reachable, in
    order of preference (upright hand, natural azimuth, moderate pitch), else the best-scoring one."""
    shoulder_y = 0.2 if side == "left" else -0.2
    toward = float(np.arctan2(center[1] - shoulder_y, max(center[0], 0.05)))
    bottom = center[2] - prop.height_m / 2
    point = center.copy()
    point[2] = max(center[2], bottom + ik.robot.gripper.pad_length_m / 2 + FLOOR_CLEARANCE_M,
                   TABLE_TOP_Z + ik.robot.gripper.pad_length_m / 2 + FLOOR_CLEARANCE_M)
    best, best_score = None, np.inf
    azimuths = [a for a in closing_azimuths(prop, yaw_rad, ik.robot.gripper.stroke_m, toward)
                if abs(a) <= MAX_AZIMUTH_RAD]
    for flipped in (False, True):
        for azimuth in azimuths:
            for pitch in PITCHES_RAD:
                grasp = Grasp(side, point, float(pitch), azimuth, flipped)
                score = max(_reach_score(ik, grasp), _reach_score(ik, grasp.lifted(lift_m)))
                if score < tolerance_m:
                    return grasp
                if score < best_score:
                    best, best_score = grasp, score
    if best is None:
        raise ValueError(f"no approach direction for {prop.name} at yaw {yaw_rad:.2f} rad")
    return best
