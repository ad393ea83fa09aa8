"""Fourier GR1T2 upper body with two Robotiq-2F-85-like grippers, built from primitives.

Kinematics from the official URDF (docs/reference.md §12): pelvis (the canonical origin) at
world z 0.93, waist locked, arms in the official joint order with the 24.8° roll of the shoulder-pitch frame, neck
roll -> pitch -> yaw. Link frames coincide with the pelvis frame at the zero pose (arms hanging down), which makes
the hand frame follow the package convention (approach along -z) with no extra mount rotation.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from lerobot_tavis.envs import physics
from lerobot_tavis.envs.robots import parts
from lerobot_tavis.envs.robots.base import Robot
from lerobot_tavis.envs.robots.parts import CameraMount, GripperGeometry, JointDef, Servo
from lerobot_tavis.envs.transforms import axis_angle_quat

SHELL = (0.86, 0.87, 0.89, 1.0)
JOINT_RGBA = (0.22, 0.23, 0.26, 1.0)

PELVIS_HEIGHT_M = 0.93
TORSO_IN_PELVIS = (0.003, 0.0, 0.328)
SHOULDER_FRAME_ROLL_RAD = 0.43275  # 24.8°: the shoulder-pitch axis points up and out

SHOULDER = Servo(kp=600.0, force_limit=80.0, armature=0.1, damping=1.0)
ELBOW = Servo(kp=450.0, force_limit=60.0, armature=0.08, damping=1.0)
WRIST = Servo(kp=150.0, force_limit=20.0, armature=0.03, damping=0.3)
NECK = Servo(kp=60.0, force_limit=20.0, armature=0.03, damping=0.5)

HEAD_HFOV_DEG = math.degrees(2 * math.atan(20.955 / 2 / 15.0))  # 15 mm lens on a 20.955 mm aperture: 69.9°
WRIST_HFOV_DEG = math.degrees(2 * math.atan(20.955 / 2 / 21.0))  # 21 mm lens: 53.0°


def _mirror(lo: float, hi: float, sign: float) -> tuple[float, float]:
    """Joint range for the arm on side `sign` (+1 left, -1 right) of a roll or yaw range given for the left arm."""
    return (lo, hi) if sign > 0 else (-hi, -lo)


class GR1T2(Robot):
    name = "gr1t2"
    visual_assets = "gr1t2"
    canonical_origin = (0.0, 0.0, PELVIS_HEIGHT_M)
    # The reference's rest joints (docs/reference.md §5); they already hold the hands at the rest position.
    rest_posture_seed = {
        "left": (-0.335, -0.008, 0.046, -1.778, 0.0, 0.0, 0.0),
        "right": (-0.335, 0.008, -0.047, -1.778, 0.0, 0.0, 0.0),
    }
    gripper = GripperGeometry(stroke_m=0.085, palm_length_m=0.07, palm_half_width_m=0.062,
                              finger_length_m=0.055, pad_length_m=0.035, mount_offset_m=0.023)
    # The shoulder's three axes pass through y = 0.10 (pitch), 0.19 (roll) and 0.23 m (yaw) at the zero pose; 0.2 m is
    # the value the demonstrators were tuned with on both robots (one constant served both before), as Reachy2's.
    shoulder_y_m = 0.2
    head_camera = CameraMount(pos=(0.10, 0.0, 0.0), look_at=(1.10, 0.0, 0.0), up=(0.0, 0.0, 1.0),
                              hfov_deg=HEAD_HFOV_DEG)
    # Reference mount: 15 cm above and 5 cm behind the wrist centre, looking 35° down past the fingertips. The
    # reference mounts it on the link its IK drives to the commanded quaternion, which here is the end-effector
    # frame (`<side>_ee_mount`, see Robot.build_spec): a command points the camera as it points the reference's.
    wrist_camera = parts.wrist_camera_mount(height_m=0.15, back_m=0.05, look_depth_m=0.164, hfov_deg=WRIST_HFOV_DEG)

    def arm_joints(self, side: str) -> tuple[JointDef, ...]:
        s = 1.0 if side == "left" else -1.0
        return (
            JointDef(f"{side}_shoulder_pitch_joint", (0, 1, 0), (-2.79, 1.92), SHOULDER),
            JointDef(f"{side}_shoulder_roll_joint", (1, 0, 0), _mirror(-0.57, 2.53, s), SHOULDER),
            JointDef(f"{side}_shoulder_yaw_joint", (0, 0, 1), (-2.97, 2.97), SHOULDER),
            JointDef(f"{side}_elbow_pitch_joint", (0, 1, 0), (-2.27, 2.27), ELBOW),
            JointDef(f"{side}_wrist_yaw_joint", (0, 0, 1), (-2.97, 2.97), WRIST),
            JointDef(f"{side}_wrist_roll_joint", (1, 0, 0), _mirror(-0.87, 0.96, s), WRIST),
            JointDef(f"{side}_wrist_pitch_joint", (0, 1, 0), (-0.61, 0.61), WRIST),
        )

    def neck_joints(self) -> tuple[JointDef, JointDef, JointDef]:
        return (
            JointDef("head_roll_joint", (1, 0, 0), (-0.35, 0.35), NECK),
            JointDef("head_pitch_joint", (0, 1, 0), (-0.87, 0.87), NECK),
            JointDef("head_yaw_joint", (0, 0, 1), (-2.71, 2.71), NECK),
        )

    def _build(self, spec: mujoco.MjSpec) -> None:
        pelvis = spec.worldbody.add_body(name="pelvis", pos=self.canonical_origin)
        parts.add_box(pelvis, "pelvis", (0.0, 0.0, 0.0), (0.09, 0.13, 0.07), JOINT_RGBA)
        for s in (1.0, -1.0):  # legs, for looks only
            parts.add_limb(pelvis, f"leg{int(s)}", (0.0, s * 0.09, -0.05), (0.0, s * 0.09, -0.86), 0.055, SHELL,
                           role=physics.VISUAL)
        torso = pelvis.add_body(name="torso_link", pos=TORSO_IN_PELVIS)
        parts.add_box(torso, "torso", (-0.02, 0.0, -0.08), (0.10, 0.14, 0.16), SHELL)
        parts.add_box(torso, "chest", (-0.02, 0.0, 0.06), (0.09, 0.10, 0.05), JOINT_RGBA)
        self._build_neck(spec, torso)
        for side in self.SIDES:
            self._build_arm(spec, torso, side)

    def _build_neck(self, spec: mujoco.MjSpec, torso: mujoco.MjsBody) -> None:
        roll, pitch, yaw = self.neck_joints()
        roll_link = parts.add_link(spec, torso, "head_roll_link", roll, pos=(0.002, 0.0005, 0.14465))
        parts.add_limb(roll_link, "neck", (0.0, 0.0, -0.05), (0.0, 0.0, 0.03), 0.035, JOINT_RGBA,
                       role=physics.VISUAL)
        pitch_link = parts.add_link(spec, roll_link, "head_pitch_link", pitch, pos=(0.0, 0.0, 0.0))
        head = parts.add_link(spec, pitch_link, "head_yaw_link", yaw, pos=(0.0, 0.0, 0.0513))
        head_geom = head.add_geom(name="head", type=parts.SPHERE, pos=(0.0, 0.0, 0.094), size=(0.11, 0.0, 0.0))
        physics.style_geom(head_geom, physics.VISUAL, SHELL)
        parts.add_box(head, "visor", (0.06, 0.0, 0.11), (0.06, 0.085, 0.035), JOINT_RGBA, role=physics.VISUAL)
        parts.add_camera(head, "head", self.head_camera)

    def _build_arm(self, spec: mujoco.MjSpec, torso: mujoco.MjsBody, side: str) -> None:
        s = 1.0 if side == "left" else -1.0
        sp, sr, sy, el, wy, wr, wp = self.arm_joints(side)
        body = parts.add_link(spec, torso, f"{side}_shoulder_pitch_link", sp, pos=(0.0, s * 0.10128, 0.046651),
                              quat=axis_angle_quat((1, 0, 0), s * SHOULDER_FRAME_ROLL_RAD))
        parts.add_limb(body, f"{side}_shoulder", (0, 0, 0), (0, s * 0.09515, 0), 0.045, JOINT_RGBA)
        body = parts.add_link(spec, body, f"{side}_shoulder_roll_link", sr, pos=(0.0, s * 0.09515, 0.0),
                              quat=axis_angle_quat((1, 0, 0), -s * SHOULDER_FRAME_ROLL_RAD))
        parts.add_limb(body, f"{side}_shoulder_roll", (0, 0, 0), (0, s * 0.04, -0.0709), 0.042, JOINT_RGBA)
        body = parts.add_link(spec, body, f"{side}_shoulder_yaw_link", sy, pos=(0.0, s * 0.04, -0.0709))
        parts.add_limb(body, f"{side}_upper_arm", (0, 0, -0.02), (0, s * 0.00105, -0.1786), 0.038, SHELL)
        body = parts.add_link(spec, body, f"{side}_elbow_pitch_link", el, pos=(0.0, s * 0.00105, -0.1786))
        parts.add_limb(body, f"{side}_elbow", (0, 0, 0), (0, 0, -0.05945), 0.036, JOINT_RGBA)
        body = parts.add_link(spec, body, f"{side}_wrist_yaw_link", wy, pos=(0.0, 0.0, -0.05945))
        parts.add_limb(body, f"{side}_forearm", (0, 0, -0.01), (0, 0, -0.165), 0.034, SHELL)
        body = parts.add_link(spec, body, f"{side}_wrist_roll_link", wr, pos=(0.0, 0.0, -0.19115))
        hand = parts.add_link(spec, body, f"{side}_hand_pitch_link", wp, pos=(0.0, 0.0, 0.0))
        wrist = hand.add_geom(name=f"{side}_wrist", type=parts.SPHERE, size=(0.03, 0.0, 0.0))
        physics.style_geom(wrist, physics.ROBOT, JOINT_RGBA)
        hand.add_site(name=self.ee_site(side), size=(0.008, 0.0, 0.0), group=4)
        parts.add_gripper(spec, hand, side, self.gripper, JOINT_RGBA)
        mount = hand.add_frame(name=self.ee_mount(side))
        cam = np.asarray(self.wrist_camera.pos)
        parts.add_limb(mount, f"{side}_camera_post", (0.03, 0.0, -0.03), cam - (0.012, 0.0, 0.0), 0.008,
                       JOINT_RGBA, role=physics.VISUAL)
        parts.add_camera(mount, f"{side}_wrist", self.wrist_camera)
