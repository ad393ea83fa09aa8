"""What every embodiment provides: a standalone MjSpec of the robot plus the facts the controller needs.

A robot spec holds only the robot, its base already at its world pose, with unprefixed names
(`left_shoulder_pitch`, `left_ee`, `head`, ...). The world attaches it under the prefix `<robot name>/`; the IK
controller compiles it alone, so both models share world coordinates.
"""

from __future__ import annotations

import abc
from typing import ClassVar

import mujoco
import numpy as np

from lerobot_tavis.envs import physics
from lerobot_tavis.envs.robots import visuals
from lerobot_tavis.envs.robots.calibration import RestCalibration, calibrate
from lerobot_tavis.envs.robots.parts import GripperGeometry, JointDef
from lerobot_tavis.envs.transforms import quat_multiply


class Robot(abc.ABC):
    """A fixed-base humanoid torso with two 7-DoF arms, a 3-DoF neck, two parallel grippers and three cameras."""

    name: ClassVar[str]
    visual_assets: ClassVar[str | None] = None  # `assets/<group>/visuals.json` to dress it in; None: primitives only
    canonical_origin: ClassVar[tuple[float, float, float]]  # world position of the canonical (hip) frame
    rest_posture_seed: ClassVar[dict[str, tuple[float, ...]]]  # seeds the rest calibration (calibration.py)
    gripper: ClassVar[GripperGeometry]
    # lateral distance (m, world y) of the left shoulder from the body's mid-plane (the right one mirrors it); the
    # demonstrators aim a hand's approach from (0, ±shoulder_y_m) to the object
    shoulder_y_m: ClassVar[float]
    # joint ranges (rad) the IK keeps to, narrower than the servos' own, by joint name
    ik_joint_ranges: ClassVar[dict[str, tuple[float, float]]] = {}
    ik_orientation_cost: ClassVar[float] = 0.3  # weight of 1 rad of hand tilt against 1 m of position error
    SIDES: ClassVar[tuple[str, str]] = ("left", "right")
    CAMERAS: ClassVar[tuple[str, ...]] = ("head", "left_wrist", "right_wrist")

    @abc.abstractmethod
    def arm_joints(self, side: str) -> tuple[JointDef, ...]:
        """The arm's seven joints from shoulder to wrist, in the robot's official order."""

    @abc.abstractmethod
    def neck_joints(self) -> tuple[JointDef, JointDef, JointDef]:
        """Neck roll, pitch and yaw, in that order."""

    @abc.abstractmethod
    def _build(self, spec: mujoco.MjSpec) -> None:
        """Add the robot's bodies, joints, actuators, sites (`<side>_ee` at the wrist centre with the hand frame's
        orientation, `<side>_grasp`) and cameras to `spec`. What hangs in an optional frame `<side>_ee_mount` of
        the hand (identity here) turns with the end-effector frame once calibrated (`build_spec`)."""

    def raw_spec(self) -> mujoco.MjSpec:
        """The robot with its end-effector sites still aligned with the hand frames (input of the calibration)."""
        spec = mujoco.MjSpec()
        spec.modelname = self.name
        physics.configure_compiler(spec)
        self._build(spec)
        return spec

    def build_spec(self, *, dressed: bool = False) -> mujoco.MjSpec:
        """The robot with calibrated end-effector frames: the rest quaternion is the relaxed rest orientation.

        `dressed` draws the robot with its real visual meshes (`visuals.dress`, from `visual_assets`) instead of its
        primitives; the physics is the same either way, so the IK controller compiles the cheaper undressed model.
        """
        spec = self.raw_spec()
        for side, quat in self.calibration().ee_quat_in_hand.items():
            spec.site(self.ee_site(side)).quat = quat
            mount = spec.frame(self.ee_mount(side))
            if mount is not None:
                mount.quat = quat
        if dressed and self.visual_assets:
            visuals.dress(spec, self.visual_assets)
        return spec

    def calibration(self) -> RestCalibration:
        return calibrate(type(self))

    def ee_quat_for_hand(self, side: str, hand_quat) -> np.ndarray:
        """End-effector quaternion to command for a desired hand-frame orientation (both world frame, w, x, y, z).

        Example: `hand_quat = (1, 0, 0, 0)` points the gripper straight down with the fingers closing along y.
        """
        return quat_multiply(hand_quat, self.calibration().ee_quat_in_hand[side])

    @property
    def prefix(self) -> str:
        return f"{self.name}/"

    def arm_joint_names(self, side: str) -> tuple[str, ...]:
        return tuple(j.name for j in self.arm_joints(side))

    def neck_joint_names(self) -> tuple[str, str, str]:
        return tuple(j.name for j in self.neck_joints())

    def neck_range_rad(self) -> np.ndarray:
        """(3, 2) array of neck roll/pitch/yaw limits."""
        return np.array([j.range_rad for j in self.neck_joints()])

    def shoulder_y(self, side: str) -> float:
        """World y (m) of `side`'s shoulder: +`shoulder_y_m` on the left, -`shoulder_y_m` on the right."""
        return self.shoulder_y_m if side == "left" else -self.shoulder_y_m

    def ee_site(self, side: str) -> str:
        return f"{side}_ee"

    def ee_mount(self, side: str) -> str:
        """Name of the hand's frame that `build_spec` turns into the end-effector frame (at the wrist centre)."""
        return f"{side}_ee_mount"

    def grasp_site(self, side: str) -> str:
        return f"{side}_grasp"

    def joint_names(self) -> tuple[str, ...]:
        """The joints reported in `joint_pos`: left arm, right arm, neck, then one opening per gripper."""
        return (*self.arm_joint_names("left"), *self.arm_joint_names("right"), *self.neck_joint_names(),
                "left_finger_a", "right_finger_a")
