"""Pollen Reachy 2 upper body on a fixed base, with parallel grippers, built from primitives.

Kinematics from Pollen's public model (docs/reference.md §12): base on the floor, torso at
z 0.996, shoulders at ±0.20 m with frames tilted 15° from horizontal and yawed 10°, Orbita joints whose axes meet
in one point (upper arm 0.28 m, forearm 0.28 m), neck roll/pitch/yaw through one point pitched 10° forward. The
hand frame is the wrist's shoulder-aligned frame, which hangs along -z at the zero pose like the package convention.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from lerobot_tavis.envs import physics
from lerobot_tavis.envs.robots import parts
from lerobot_tavis.envs.robots.base import Robot
from lerobot_tavis.envs.robots.parts import CameraMount, GripperGeometry, JointDef, Servo
from lerobot_tavis.envs.transforms import axis_angle_quat, quat_multiply

SHELL = (0.95, 0.95, 0.96, 1.0)
JOINT_RGBA = (0.12, 0.13, 0.15, 1.0)

TORSO_POS = (-0.01, 0.0, 0.996)
SHOULDER_HALF_SPAN_M = 0.20
UPPER_ARM_M = 0.28
FOREARM_M = 0.28
NECK_ABOVE_TORSO_M = 0.115
NECK_FORWARD_PITCH_RAD = math.radians(10.0)
IK_MIN_ELBOW_BEND_RAD = 0.15  # costs the straight arm 2 mm of reach

SHOULDER = Servo(kp=500.0, force_limit=80.0, armature=0.1, damping=1.0)
ELBOW = Servo(kp=400.0, force_limit=60.0, armature=0.08, damping=1.0)
WRIST = Servo(kp=150.0, force_limit=20.0, armature=0.03, damping=0.3)
NECK = Servo(kp=60.0, force_limit=20.0, armature=0.03, damping=0.5)

HEAD_HFOV_DEG = math.degrees(2 * math.atan(20.955 / 2 / 15.0))
WRIST_HFOV_DEG = math.degrees(2 * math.atan(20.955 / 2 / 21.0))


def shoulder_frame_quat(sign: float) -> np.ndarray:
    """Right shoulder (sign -1): yawed +10° after tilting the pitch axis 15° down; the left one mirrors it."""
    yaw = axis_angle_quat((0, 0, 1), -sign * math.radians(10.0))
    tilt = axis_angle_quat((1, 0, 0), sign * math.radians(15.0))
    return quat_multiply(yaw, tilt)


class Reachy2(Robot):
    name = "reachy2"
    visual_assets = "reachy2"
    canonical_origin = (-0.01, 0.0, 0.93)
    # The reference's rest joints (-0.3 shoulder pitch, -1.7 elbow) put the hands below the table top; seed the
    # calibration with the elbows raised and out, so the upper arms stay clear of the table's front edge.
    rest_posture_seed = {
        "left": (-1.5, 1.1, -0.6, -1.65, 0.0, 0.0, 0.0),
        "right": (-1.5, -1.1, 0.6, -1.65, 0.0, 0.0, 0.0),
    }
    # The elbow servo allows 0.10 rad of hyperextension; an IK step that takes a stretched arm across straight
    # cannot bend it back (the hand then stays stuck at full reach), so the IK keeps the elbow slightly bent.
    ik_joint_ranges = {f"{p}_elbow_pitch": (-2.25, -IK_MIN_ELBOW_BEND_RAD) for p in "lr"}
    # The wrist tilts only ±0.35 rad, so many commanded hand orientations are out of reach: the hand then keeps to
    # its commanded position rather than stopping short to turn toward an orientation it cannot take.
    ik_orientation_cost = 0.2
    gripper = GripperGeometry(stroke_m=0.105, palm_length_m=0.05, palm_half_width_m=0.072,
                              finger_length_m=0.06, pad_length_m=0.035, mount_offset_m=0.02)
    shoulder_y_m = SHOULDER_HALF_SPAN_M  # 0.20 m, where the shoulder pitch and roll axes meet (GR1T2 states 0.2 too)
    # The reference's mount, inside the real head's shell: the face plate 37 mm ahead lies within the cameras'
    # near clip (physics.NEAR_CLIP_M), so the camera sees through it, as the reference's (0.15 m clip) does.
    head_camera = CameraMount(pos=(0.02, 0.0, 0.05), look_at=(1.02, 0.0, 0.05), up=(0.0, 0.0, 1.0),
                              hfov_deg=HEAD_HFOV_DEG)
    wrist_camera = parts.wrist_camera_mount(height_m=0.10, back_m=0.01, look_depth_m=0.146, hfov_deg=WRIST_HFOV_DEG)

    def arm_joints(self, side: str) -> tuple[JointDef, ...]:
        p = side[0]
        right = side == "right"
        return (
            JointDef(f"{p}_shoulder_pitch", (0, 1, 0), (-math.pi, math.pi), SHOULDER),
            JointDef(f"{p}_shoulder_roll", (1, 0, 0), (-math.pi, 0.0) if right else (0.0, math.pi), SHOULDER),
            JointDef(f"{p}_elbow_yaw", (0, 0, 1), (-math.pi, math.pi), ELBOW),
            JointDef(f"{p}_elbow_pitch", (0, 1, 0), (-2.25, 0.10), ELBOW),
            JointDef(f"{p}_wrist_roll", (1, 0, 0), (-0.35, 0.35), WRIST),
            JointDef(f"{p}_wrist_pitch", (0, 1, 0), (-0.35, 0.35), WRIST),
            JointDef(f"{p}_wrist_yaw", (0, 0, 1), (-1.57, 1.57), WRIST),
        )

    def neck_joints(self) -> tuple[JointDef, JointDef, JointDef]:
        return (
            JointDef("neck_roll", (1, 0, 0), (-0.35, 0.35), NECK),
            JointDef("neck_pitch", (0, 1, 0), (-0.35, 0.35), NECK),
            JointDef("neck_yaw", (0, 0, 1), (-1.57, 1.57), NECK),
        )

    def _build(self, spec: mujoco.MjSpec) -> None:
        base = spec.worldbody.add_body(name="base", pos=(0.0, 0.0, 0.0))
        base_geom = base.add_geom(name="base", type=parts.CYLINDER, pos=(-0.05, 0.0, 0.13), size=(0.27, 0.13, 0.0))
        physics.style_geom(base_geom, physics.ROBOT, JOINT_RGBA)
        parts.add_box(base, "column", (-0.03, 0.0, 0.55), (0.05, 0.07, 0.30), SHELL, role=physics.VISUAL)
        torso = spec.worldbody.add_body(name="torso", pos=TORSO_POS)
        parts.add_box(torso, "torso", (-0.03, 0.0, -0.04), (0.08, 0.14, 0.11), SHELL)
        parts.add_limb(torso, "shoulder_bar", (0.0, -0.16, 0.0), (0.0, 0.16, 0.0), 0.045, JOINT_RGBA)
        self._build_head(spec, torso)
        for side in self.SIDES:
            self._build_arm(spec, torso, side)

    def _build_head(self, spec: mujoco.MjSpec, torso: mujoco.MjsBody) -> None:
        roll, pitch, yaw = self.neck_joints()
        neck_base = torso.add_body(name="neck_base", pos=(0.0, 0.0, NECK_ABOVE_TORSO_M),
                                   quat=axis_angle_quat((0, 1, 0), NECK_FORWARD_PITCH_RAD))
        parts.add_limb(neck_base, "neck", (0.0, 0.0, -0.08), (0.0, 0.0, 0.0), 0.03, JOINT_RGBA, role=physics.VISUAL)
        body = parts.add_link(spec, neck_base, "neck_roll_link", roll, pos=(0.0, 0.0, 0.0))
        body = parts.add_link(spec, body, "neck_pitch_link", pitch, pos=(0.0, 0.0, 0.0))
        head = parts.add_link(spec, body, "head", yaw, pos=(0.0, 0.0, 0.0))
        shell = head.add_geom(name="head", type=parts.ELLIPSOID, pos=(0.0, 0.0, 0.06), size=(0.06, 0.09, 0.055))
        physics.style_geom(shell, physics.VISUAL, SHELL)
        for s in (1.0, -1.0):
            parts.add_limb(head, f"antenna{int(s)}", (-0.01, s * 0.05, 0.10), (-0.02, s * 0.07, 0.17), 0.006,
                           JOINT_RGBA, role=physics.VISUAL)
        parts.add_camera(head, "head", self.head_camera)

    def _build_arm(self, spec: mujoco.MjSpec, torso: mujoco.MjsBody, side: str) -> None:
        s = 1.0 if side == "left" else -1.0
        sp, sr, ey, ep, wr, wp, wy = self.arm_joints(side)
        p = side[0]
        frame = torso.add_body(name=f"{p}_shoulder_frame", pos=(0.0, s * SHOULDER_HALF_SPAN_M, 0.0),
                               quat=shoulder_frame_quat(s))
        body = parts.add_link(spec, frame, f"{p}_shoulder_pitch_link", sp, pos=(0.0, 0.0, 0.0))
        ball = body.add_geom(name=f"{p}_shoulder", type=parts.SPHERE, size=(0.055, 0.0, 0.0))
        physics.style_geom(ball, physics.ROBOT, JOINT_RGBA)
        body = parts.add_link(spec, body, f"{p}_shoulder_roll_link", sr, pos=(0.0, 0.0, 0.0))
        parts.add_limb(body, f"{p}_upper_arm", (0, 0, -0.05), (0, 0, -UPPER_ARM_M + 0.04), 0.045, SHELL)
        body = parts.add_link(spec, body, f"{p}_elbow_yaw_link", ey, pos=(0.0, 0.0, -UPPER_ARM_M))
        elbow = body.add_geom(name=f"{p}_elbow", type=parts.SPHERE, size=(0.045, 0.0, 0.0))
        physics.style_geom(elbow, physics.ROBOT, JOINT_RGBA)
        body = parts.add_link(spec, body, f"{p}_elbow_pitch_link", ep, pos=(0.0, 0.0, 0.0))
        parts.add_limb(body, f"{p}_forearm", (0, 0, -0.04), (0, 0, -FOREARM_M + 0.035), 0.04, SHELL)
        body = parts.add_link(spec, body, f"{p}_wrist_roll_link", wr, pos=(0.0, 0.0, -FOREARM_M))
        body = parts.add_link(spec, body, f"{p}_wrist_pitch_link", wp, pos=(0.0, 0.0, 0.0))
        # The hand's top (+x, where the wrist camera sits) faces the body's inside at the zero pose: with the
        # shoulders at table height, that is the side facing up in Reachy2's reachable grasps.
        hand = parts.add_link(spec, body, f"{p}_hand", wy, pos=(0.0, 0.0, 0.0), quat=(0.0, 0.0, 0.0, 1.0))
        wrist = hand.add_geom(name=f"{side}_wrist", type=parts.SPHERE, size=(0.035, 0.0, 0.0))
        physics.style_geom(wrist, physics.ROBOT, JOINT_RGBA)
        hand.add_site(name=self.ee_site(side), size=(0.008, 0.0, 0.0), group=4)
        parts.add_gripper(spec, hand, side, self.gripper, JOINT_RGBA)
        cam = np.asarray(self.wrist_camera.pos)
        parts.add_limb(hand, f"{side}_camera_post", (0.03, 0.0, -0.02), cam - (0.012, 0.0, 0.0), 0.008,
                       JOINT_RGBA, role=physics.VISUAL)
        parts.add_camera(hand, f"{side}_wrist", self.wrist_camera)
