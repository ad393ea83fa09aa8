"""Grasp planning for the scripted demonstrators: which hand orientation to grasp an upright prop with.

A grasp is described in the world frame: the grasp point (between the pads), the approach direction (pitched
down from horizontal, turned by an azimuth about z) and whether the hand is rolled by pi about the approach (the
two-finger gripper is symmetric, so both rolls hold the object the same way). Candidates are checked with the
robot's own kinematics (privileged information a human demonstrator also has: a feel for their own arm).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, replace

import numpy as np

from lerobot_tavis import canonical
from lerobot_tavis.envs.control import ArmIK
from lerobot_tavis.envs.objects import PropSpec
from lerobot_tavis.envs.transforms import axis_angle_quat, quat_multiply

PITCHES_RAD = np.radians((45.0, 60.0, 30.0, 75.0, 90.0, 15.0))
STEEP_PITCHES_RAD = np.radians((75.0, 90.0, 60.0, 45.0, 30.0))
TIGHT_CLEARANCE_M = 0.015  # per side, below which the steep pitches are tried first
CARRY_TOLERANCE_M = 0.04
CARRY_PULL_M = 0.08  # the carried pose only has to get the object past the success line
CARRY_RAISED_PITCH_RAD = -0.35  # fingertips up: brings a held object nearer a stretched arm
NATURAL_AZIMUTH_RAD = np.pi / 4  # wider azimuths are tried only after every pitch of the natural ones
MAX_AZIMUTH_RAD = np.pi / 2
MIN_FINGER_CLEARANCE_M = 0.002  # total; a wide side is still tried, after the narrow one
FLOOR_CLEARANCE_M = 0.006
PAD_ABOVE_TOP_M = 0.004  # pad tips may stick out above the object's top by this much
CORRIDOR_MARGIN_M = 0.005
PRESHAPE_MARGIN_M = 0.03  # open this much wider than the object
FOREARM_CLEARANCE_M = 0.08
CYLINDER_AZIMUTH_OFFSETS_RAD = (0.0, -0.35, 0.35, -0.7, 0.7)
BOX_AZIMUTH_OFFSETS_RAD = (0.0, -0.2, 0.2)  # a slightly skewed grip still holds a box


@dataclass(frozen=True)
class Grasp:
    side: str
    point: np.ndarray  # world position of the point between the pads, m
    pitch_rad: float  # approach angle below horizontal
    azimuth_rad: float  # approach direction about world z (0 = forward)
    flipped: bool
    opening_m: float = 1.0  # pre-grasp opening (pre-shaped to the object; clipped to the stroke)
    carry_offset_m: tuple[float, float, float] = (0.0, 0.0, 0.2)  # where the object goes once held (world, m)
    carry_pitch_rad: float | None = None  # approach pitch while carrying (None: unchanged)

    @property
    def approach(self) -> np.ndarray:
        c = np.cos(self.pitch_rad)
        return np.array([c * np.cos(self.azimuth_rad), c * np.sin(self.azimuth_rad), -np.sin(self.pitch_rad)])

    @property
    def closing_direction(self) -> np.ndarray:
        """Horizontal unit vector along which the fingers close."""
        return np.array([-np.sin(self.azimuth_rad), np.cos(self.azimuth_rad), 0.0])

    @property
    def hand_quat(self) -> np.ndarray:
        """Hand-frame orientation: approach along the hand's -z, fingers closing horizontally."""
        quat = quat_multiply(axis_angle_quat((0, 0, 1), self.azimuth_rad),
                             axis_angle_quat((0, 1, 0), self.pitch_rad - np.pi / 2))
        return quat_multiply(quat, axis_angle_quat((0, 0, 1), np.pi)) if self.flipped else quat

    def moved(self, offset_m) -> Grasp:
        """The same hand orientation with the grasp point shifted by `offset_m` (world, m): carrying."""
        return replace(self, point=self.point + np.asarray(offset_m, dtype=float))

    def carried(self) -> Grasp:
        """The hand pose holding the object at its carry position (the carry offset and pitch chosen by the
        planner)."""
        pitch = self.pitch_rad if self.carry_pitch_rad is None else self.carry_pitch_rad
        return replace(self.moved(self.carry_offset_m), pitch_rad=pitch)

    def ee_pose(self, ik: ArmIK, offset_m: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Canonical end-effector position and quaternion that put the pads on the grasp point, backed off
        `offset_m` along the approach."""
        robot = ik.robot
        wrist = self.point - (robot.gripper.grasp_depth_m + offset_m) * self.approach
        return wrist - np.asarray(robot.canonical_origin), robot.ee_quat_for_hand(self.side, self.hand_quat)

    def action(self, ik: ArmIK, base: np.ndarray, offset_m: float = 0.0, closed: bool = False) -> np.ndarray:
        """`base` with this arm's pose replaced and its gripper pre-shaped open, or closed."""
        slots = canonical.LEFT if self.side == "left" else canonical.RIGHT
        action = base.copy()
        action[slots.position], action[slots.quaternion] = self.ee_pose(ik, offset_m)
        stroke = ik.robot.gripper.stroke_m
        action[slots.gripper] = canonical.GRIPPER_CLOSED if closed else 1.0 - 2.0 * min(self.opening_m, stroke) / stroke
        return action


def _reach_score(ik: ArmIK, grasp: Grasp) -> float:
    """How far (m) the pads would end from the grasp point: wrist error plus the tilt error's lever arm."""
    position_error, angle_error = ik.reach_error(grasp.action(ik, canonical.rest_action()), grasp.side)
    return position_error + ik.robot.gripper.grasp_depth_m * angle_error


def closing_azimuths(prop: PropSpec, yaw_rad: float, stroke_m: float, toward_rad: float) -> list[float]:
    """Approach azimuths (rad) whose closing direction spans a prop side that fits in the gripper.

    Cylinders are approached from around `toward_rad` (the arm's natural direction); a box from across either of its
    horizontal axes (closing along the other, give or take 0.2 rad), from whichever side faces `toward_rad`.
    Sorted by closeness to
    `toward_rad`, wrapped to [-pi, pi].
    """
    if prop.shape == "cylinder":
        return [toward_rad + offset for offset in CYLINDER_AZIMUTH_OFFSETS_RAD]
    options = []
    for closing_axis, width in ((0, prop.size_m[0]), (1, prop.size_m[1])):
        if width > stroke_m - MIN_FINGER_CLEARANCE_M:
            continue
        approach = yaw_rad + closing_axis * np.pi / 2 + np.pi / 2  # perpendicular to the closing direction
        if np.cos(approach - toward_rad) < 0:
            approach += np.pi  # the side facing the hand
        options += [float(np.angle(np.exp(1j * (approach + offset)))) for offset in BOX_AZIMUTH_OFFSETS_RAD]
    return sorted(options, key=lambda a: abs(np.angle(np.exp(1j * (a - toward_rad)))))


def width_across(prop: PropSpec, yaw_rad: float, direction: np.ndarray) -> float:
    """Extent (m) of an upright prop along a horizontal direction."""
    if prop.shape == "cylinder":
        return prop.size_m[0]
    axes = np.array([[np.cos(yaw_rad), np.sin(yaw_rad)], [-np.sin(yaw_rad), np.cos(yaw_rad)]])
    return float(np.abs(axes @ direction[:2]) @ prop.size_m[:2])


def hand_clearance(grasp: Grasp, obstacles, reach_m: float, finger_thickness_m: float,
                   hand_half_height_m: float = 0.025) -> tuple[float, float]:
    """Gaps (m) between obstacles ((xy centre, footprint radius, top z) triples) and (1) the hand's path, the
    segment from the grasp point back along the approach, `reach_m` long, seen from above, counting only obstacles
    taller than the hand where it passes them; (2) the open fingers at the grasp point."""
    start = grasp.point[:2]
    back = -grasp.approach[:2] * reach_m
    rise_per_m = np.tan(grasp.pitch_rad)
    fingers = [start + sign * (grasp.opening_m / 2 + finger_thickness_m) * grasp.closing_direction[:2]
               for sign in (1.0, -1.0)]
    path_gap = finger_gap = np.inf
    for centre, radius, top_z in obstacles:
        centre = np.asarray(centre)
        t = np.clip(np.dot(centre - start, back) / max(np.dot(back, back), 1e-12), 0.0, 1.0)
        hand_bottom_z = grasp.point[2] + t * reach_m * rise_per_m - hand_half_height_m
        if hand_bottom_z < top_z:
            path_gap = min(path_gap, float(np.linalg.norm(centre - (start + t * back))) - radius)
        finger_gap = min(finger_gap, *(float(np.linalg.norm(centre - f)) - radius for f in fingers))
    return path_gap, finger_gap


def palm_clearances(grasp: Grasp, gripper, top_z: float, center: np.ndarray, half_extent_xy) -> tuple[float, float]:
    """How far (m) the palm's leading edge stays above the object's top, and behind its near side."""
    behind = gripper.grasp_depth_m - gripper.mount_offset_m - gripper.palm_length_m  # pads' middle to palm face
    half_thickness = gripper.palm_half_thickness_m
    above = behind * np.sin(grasp.pitch_rad) - half_thickness * np.cos(grasp.pitch_rad) + grasp.point[2] - top_z
    direction = grasp.approach[:2] / max(np.linalg.norm(grasp.approach[:2]), 1e-9)
    near_side = abs(direction[0]) * half_extent_xy[0] + abs(direction[1]) * half_extent_xy[1] - np.dot(
        center[:2] - grasp.point[:2], direction)
    beyond = behind * np.cos(grasp.pitch_rad) - half_thickness * np.sin(grasp.pitch_rad) - near_side
    return float(above), float(beyond)


def clear_the_palm(grasp: Grasp, gripper, top_z: float, center: np.ndarray, half_extent_xy) -> Grasp | None:
    """`grasp`, moved back along the approach (by at most a third of the pads' length) if that keeps the palm
    clear of a long object's near side; None if the palm would hit the object."""
    above, beyond = palm_clearances(grasp, gripper, top_z, center, half_extent_xy)
    if max(above, beyond) > CORRIDOR_MARGIN_M:
        return grasp
    shift = CORRIDOR_MARGIN_M - beyond + 1e-4
    if shift > gripper.pad_length_m / 3:
        return None
    direction = np.array([*(grasp.approach[:2] / max(np.linalg.norm(grasp.approach[:2]), 1e-9)), 0.0])
    return replace(grasp, point=grasp.point - shift * direction)


def carry_options(grasp: Grasp, carry_m) -> list[Grasp]:
    """Ways to hold the object at its carry position: as grasped, with a flatter hand, or a little closer to
    the body (all get it past the success line)."""
    carry = np.asarray(carry_m, dtype=float)
    nearer = carry + (-CARRY_PULL_M, 0.0, 0.0) if carry[2] > 0.1 else carry
    pitches = (None, max(grasp.pitch_rad - 0.5, 0.0), 0.0, CARRY_RAISED_PITCH_RAD)
    return [replace(grasp, carry_offset_m=tuple(offset), carry_pitch_rad=pitch)
            for offset in (carry, nearer) for pitch in pitches]


def plan_grasp(ik: ArmIK, side: str, prop: PropSpec, center: np.ndarray, yaw_rad: float, **kwargs) -> Grasp:
    """The most preferred grasp of `grasp_candidates` (see there)."""
    return next(grasp_candidates(ik, side, prop, center, yaw_rad, **kwargs))


def grasp_candidates(ik: ArmIK, side: str, prop: PropSpec, center: np.ndarray, yaw_rad: float,
                     carry_m=(0.0, 0.0, 0.2), pitches_rad=PITCHES_RAD, max_azimuth_rad: float = MAX_AZIMUTH_RAD,
                     toward_rad: float | None = None, obstacles=(), tolerance_m: float = 0.008,
                     carry_tolerance_m: float = CARRY_TOLERANCE_M) -> Iterator[Grasp]:
    """Grasps that (1) keep the hand's path clear of `obstacles` ((xy, radius, top z) of the other props) and the
    palm clear of the object, (2) whose grasp pose is kinematically reachable within `tolerance_m` and (3) whose
    carried pose (grasp point + `carry_m`) is reachable within `carry_tolerance_m`, in order of preference:
    upright hand; azimuth within 45° of `toward_rad` (default: from the robot's shoulder, at world y
    `Robot.shoulder_y(side)`, to the object); the given pitch order; azimuth nearest `toward_rad`. Then the others,
    best-scoring first. Azimuths farther than `max_azimuth_rad` from `toward_rad` are considered only when there is
    no other."""
    if toward_rad is None:
        shoulder_y = ik.robot.shoulder_y(side)
        toward_rad = float(np.arctan2(center[1] - shoulder_y, max(center[0], 0.05)))
    bottom, top = center[2] - prop.height_m / 2, center[2] + prop.height_m / 2
    gripper = ik.robot.gripper
    point = center.copy()
    # pads on the upper part of the object (the palm then stays clear of its top), never touching the surface below
    point[2] = max(top - gripper.pad_length_m / 2 + PAD_ABOVE_TOP_M,
                   bottom + gripper.pad_length_m / 2 + FLOOR_CLEARANCE_M)
    options = closing_azimuths(prop, yaw_rad, gripper.stroke_m, toward_rad)
    azimuths = [a for a in options if abs(np.angle(np.exp(1j * (a - toward_rad)))) <= max_azimuth_rad] or options[:1]
    if pitches_rad is PITCHES_RAD and min(width_across(prop, yaw_rad, Grasp(side, point, 0.0, a, False)
                                                           .closing_direction) for a in azimuths) > \
            gripper.stroke_m - 2 * TIGHT_CLEARANCE_M:
        pitches_rad = STEEP_PITCHES_RAD  # little room beside the object: come down from above
    reach = gripper.grasp_depth_m + FOREARM_CLEARANCE_M

    def preference(candidate):
        flipped, azimuth, pitch_index = candidate
        deviation = abs(np.angle(np.exp(1j * (azimuth - toward_rad))))
        return flipped, deviation > NATURAL_AZIMUTH_RAD, pitch_index, deviation

    candidates = sorted(((f, a, i) for f in (False, True) for a in azimuths for i in range(len(pitches_rad))),
                        key=preference)
    rejected: list[tuple[float, int, Grasp]] = []
    for flipped, azimuth, pitch_index in candidates:
        pitch = float(pitches_rad[pitch_index])
        closing = Grasp(side, point, pitch, azimuth, flipped).closing_direction
        opening = min(gripper.stroke_m, width_across(prop, yaw_rad, closing) + PRESHAPE_MARGIN_M)
        nominal = Grasp(side, point, pitch, azimuth, flipped, opening, tuple(np.asarray(carry_m, dtype=float)))
        grasp = clear_the_palm(nominal, gripper, top, center, prop.half_extent_xy(yaw_rad))
        palm_hits = grasp is None
        grasp = grasp or nominal
        path_gap, finger_gap = hand_clearance(grasp, obstacles, reach * np.cos(pitch),
                                              gripper.finger_thickness_m + gripper.pad_thickness_m)
        blocked = (palm_hits or path_gap < gripper.palm_half_width_m + CORRIDOR_MARGIN_M
                   or finger_gap < CORRIDOR_MARGIN_M)
        grasp_error = _reach_score(ik, grasp)
        if blocked or grasp_error > tolerance_m:
            score = grasp_error + 0.05 * blocked + 0.05
        else:
            carry_error, grasp = min(((_reach_score(ik, option.carried()), option)
                                      for option in carry_options(grasp, carry_m)), key=lambda pair: pair[0])
            if carry_error < carry_tolerance_m:
                yield grasp
                continue
            score = grasp_error + carry_error
        rejected.append((score, len(rejected), grasp))
    for _, _, grasp in sorted(rejected, key=lambda item: item[:2]):
        yield grasp
