"""Model pieces shared by the robots: jointed links, capsule limbs, position servos, a parallel gripper and cameras.

Hand-frame convention (both robots): the hand body's origin is the wrist centre, the gripper extends along the
hand's -z (the approach direction), the fingers close along the hand's y, and +x is the top of the hand, where the
wrist camera sits. With this convention the canonical quaternion (1, 0, 0, 0) points the gripper straight down.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from lerobot_tavis.envs import physics
from lerobot_tavis.envs.transforms import camera_quat, vfov_deg

HINGE = mujoco.mjtJoint.mjJNT_HINGE
SLIDE = mujoco.mjtJoint.mjJNT_SLIDE
CAPSULE = mujoco.mjtGeom.mjGEOM_CAPSULE
BOX = mujoco.mjtGeom.mjGEOM_BOX
SPHERE = mujoco.mjtGeom.mjGEOM_SPHERE
CYLINDER = mujoco.mjtGeom.mjGEOM_CYLINDER
ELLIPSOID = mujoco.mjtGeom.mjGEOM_ELLIPSOID

DARK = (0.16, 0.17, 0.19, 1.0)
CAMERA_RGBA = (0.05, 0.05, 0.06, 1.0)


@dataclass(frozen=True)
class Servo:
    """Position-servo gains for one joint: stiffness (N·m/rad or N/m) and force limit (N·m or N)."""

    kp: float
    force_limit: float
    armature: float = 0.05
    damping: float = 0.5


@dataclass(frozen=True)
class JointDef:
    """One actuated hinge: name, axis in its body frame, range (rad) and servo gains."""

    name: str
    axis: tuple[float, float, float]
    range_rad: tuple[float, float]
    servo: Servo


def add_link(spec: mujoco.MjSpec, parent: mujoco.MjsBody, body_name: str, joint: JointDef, *, pos,
             quat=(1.0, 0.0, 0.0, 0.0)) -> mujoco.MjsBody:
    """A gravity-compensated child body turning about `joint`, plus the joint's position servo."""
    body = parent.add_body(name=body_name, pos=pos, quat=quat)
    body.gravcomp = 1.0
    body.add_joint(name=joint.name, type=HINGE, axis=joint.axis, range=joint.range_rad,
                   armature=joint.servo.armature, damping=joint.servo.damping)
    add_servo(spec, joint.name, joint.range_rad, joint.servo)
    return body


def add_servo(spec: mujoco.MjSpec, joint: str, range_rad, servo: Servo) -> None:
    """A critically damped position actuator on `joint`, named like it, with control range = joint range."""
    actuator = spec.add_actuator(name=joint, target=joint, trntype=mujoco.mjtTrn.mjTRN_JOINT)
    actuator.set_to_position(kp=servo.kp, dampratio=1.0)
    actuator.ctrlrange = range_rad
    actuator.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
    actuator.forcerange = (-servo.force_limit, servo.force_limit)
    actuator.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE


def add_limb(body: mujoco.MjsBody | mujoco.MjsFrame, name: str, start, end, radius: float, rgba,
             role=physics.ROBOT) -> None:
    """A capsule from `start` to `end` (body frame, m)."""
    geom = body.add_geom(name=name, type=CAPSULE, fromto=(*start, *end), size=(radius, 0.0, 0.0))
    physics.style_geom(geom, role, rgba)


def add_box(body: mujoco.MjsBody, name: str, pos, half_size, rgba, role=physics.ROBOT, quat=(1, 0, 0, 0)) -> None:
    geom = body.add_geom(name=name, type=BOX, pos=pos, size=half_size, quat=quat)
    physics.style_geom(geom, role, rgba)


@dataclass(frozen=True)
class GripperGeometry:
    """A two-finger parallel gripper. Lengths in m, along the approach direction unless stated."""

    stroke_m: float  # full opening between the pads
    palm_length_m: float
    palm_half_width_m: float  # along y, must exceed stroke/2 + finger thickness
    finger_length_m: float
    pad_length_m: float
    mount_offset_m: float  # wrist centre to the palm's back face
    squeeze_force_n: float = 40.0
    servo_kp: float = 2000.0
    speed_m_s: float = 0.12  # setpoint ramp per finger: a commanded jump closes over ~0.2-0.4 s
    palm_half_thickness_m: float = 0.02  # along the hand's x
    finger_half_x_m: float = 0.011
    finger_thickness_m: float = 0.010
    pad_thickness_m: float = 0.004

    @property
    def grasp_depth_m(self) -> float:
        """Distance from the wrist centre to the middle of the pads, along the approach direction."""
        return self.mount_offset_m + self.palm_length_m + self.finger_length_m - self.pad_length_m / 2

    @property
    def tip_depth_m(self) -> float:
        return self.mount_offset_m + self.palm_length_m + self.finger_length_m


def add_gripper(spec: mujoco.MjSpec, hand: mujoco.MjsBody, side: str, g: GripperGeometry, rgba) -> None:
    """Palm, two sliding fingers with friction pads, and one servo that drives both fingers symmetrically.

    Finger joints `<side>_finger_a/b` measure each pad's distance from the centre line (0 = closed, stroke/2 =
    open). A fixed tendon averages them, an equality keeps them equal, and the actuator `<side>_gripper` servos the
    tendon with its squeeze force capped at `squeeze_force_n`. Sites: `<side>_grasp` between the pads.
    """
    z_palm = -g.mount_offset_m
    add_box(hand, f"{side}_palm", (0.0, 0.0, z_palm - g.palm_length_m / 2),
            (g.palm_half_thickness_m, g.palm_half_width_m, g.palm_length_m / 2), rgba)
    z_root = z_palm - g.palm_length_m
    finger_mid = z_root - g.finger_length_m / 2
    pad_mid = z_root - g.finger_length_m + g.pad_length_m / 2
    half_stroke = g.stroke_m / 2
    for suffix, sign in (("a", 1.0), ("b", -1.0)):
        name = f"{side}_finger_{suffix}"
        finger = hand.add_body(name=name, pos=(0.0, 0.0, 0.0))
        finger.gravcomp = 1.0
        finger.add_joint(name=name, type=SLIDE, axis=(0.0, sign, 0.0), range=(0.0, half_stroke), armature=0.01,
                         damping=2.0)
        y_finger = sign * (g.pad_thickness_m + g.finger_thickness_m / 2)
        add_box(finger, name, (0.0, y_finger, finger_mid),
                (g.finger_half_x_m, g.finger_thickness_m / 2, g.finger_length_m / 2), DARK)
        pad = finger.add_geom(name=f"{name}_pad", type=BOX, pos=(0.0, sign * g.pad_thickness_m / 2, pad_mid),
                              size=(g.finger_half_x_m, g.pad_thickness_m / 2, g.pad_length_m / 2))
        physics.style_geom(pad, physics.ROBOT, (0.08, 0.08, 0.08, 1.0))
        pad.condim = 4
        pad.priority = 1
        pad.friction = physics.PAD_FRICTION
    hand.add_site(name=f"{side}_grasp", pos=(0.0, 0.0, pad_mid), size=(0.006, 0.0, 0.0), group=4)

    tendon = spec.add_tendon(name=f"{side}_gripper")
    for suffix in ("a", "b"):
        tendon.wrap_joint(f"{side}_finger_{suffix}", 0.5)
    spec.add_equality(type=mujoco.mjtEq.mjEQ_JOINT, name1=f"{side}_finger_a", name2=f"{side}_finger_b",
                      objtype=mujoco.mjtObj.mjOBJ_JOINT, solref=(0.005, 1.0))
    actuator = spec.add_actuator(name=f"{side}_gripper", target=f"{side}_gripper",
                                 trntype=mujoco.mjtTrn.mjTRN_TENDON)
    actuator.set_to_position(kp=g.servo_kp, dampratio=1.0)
    actuator.ctrlrange = (0.0, half_stroke)
    actuator.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
    actuator.forcerange = (-2 * g.squeeze_force_n, 2 * g.squeeze_force_n)  # tendon force splits over two fingers
    actuator.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE


@dataclass(frozen=True)
class CameraMount:
    """A camera on a link: position in the link frame (m), the point it looks at, and the image-up direction."""

    pos: tuple[float, float, float]
    look_at: tuple[float, float, float]
    up: tuple[float, float, float]
    hfov_deg: float

    @property
    def quat(self) -> np.ndarray:
        return camera_quat(np.subtract(self.look_at, self.pos), self.up)


def add_camera(body: mujoco.MjsBody | mujoco.MjsFrame, name: str, mount: CameraMount, *,
               housing: bool = True) -> None:
    body.add_camera(name=name, pos=mount.pos, quat=mount.quat, fovy=vfov_deg(mount.hfov_deg))
    if housing:
        direction = np.subtract(mount.look_at, mount.pos)
        direction = direction / np.linalg.norm(direction)
        centre = np.asarray(mount.pos) - 0.012 * direction  # just behind the lens, so it never blocks the view
        geom = body.add_geom(name=f"{name}_housing", type=SPHERE, pos=centre, size=(0.01, 0.0, 0.0))
        physics.style_geom(geom, physics.VISUAL, CAMERA_RGBA)


def wrist_camera_mount(*, height_m: float, back_m: float, look_depth_m: float, hfov_deg: float = 53.0) -> CameraMount:
    """A wrist camera on top of the hand (+x) that looks at the point `look_depth_m` ahead of the wrist centre."""
    return CameraMount(pos=(height_m, 0.0, back_m), look_at=(0.0, 0.0, -look_depth_m), up=(1.0, 0.0, 0.0),
                       hfov_deg=hfov_deg)
