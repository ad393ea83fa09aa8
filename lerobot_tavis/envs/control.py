"""Canonical 19-D action -> actuator targets: mink differential IK for the arms, direct neck and gripper servos.

Every 60 Hz tick the controller reads the measured arm joints, solves one damped-least-squares IK step (a frame
task per hand, a posture task toward the home pose, joint position and velocity limits) on a robot-only copy of the
model, and sends the integrated joint positions to the arm position servos. Neck targets are the commanded angles
clipped to the joint ranges; gripper targets ramp toward the command at the gripper's finger speed. Any finite
command is usable: quaternions of any size are normalised, far hand targets drawn in (`MAX_TARGET_DISTANCE_M`).
"""

from __future__ import annotations

import mink
import mujoco
import numpy as np

from lerobot_tavis import canonical
from lerobot_tavis.envs.physics import CONTROL_HZ
from lerobot_tavis.envs.robots.base import Robot
from lerobot_tavis.envs.transforms import quat_angle_rad
from lerobot_tavis.envs.world import World

POSITION_COST = 1.0
POSTURE_COST = 1e-2
LM_DAMPING = 0.5
SOLVER_DAMPING = 1e-3
ARM_SPEED_LIMIT_RAD_S = 6.0
SOLVER = "daqp"
# Hand targets farther than this from the canonical origin (five times the arms' reach) are moved along their
# direction to this distance, so the IK never sees an error so large that its damped step vanishes; the hand then
# stretches toward them as toward any far target (beyond 3 m the reached pose moves by a few cm at most).
MAX_TARGET_DISTANCE_M = 3.0


class ArmIK:
    """Differential IK for both arms on a robot-only model that shares the world's coordinates."""

    def __init__(self, robot: Robot):
        self.robot = robot
        self.model = robot.build_spec().compile()
        for joint, joint_range in robot.ik_joint_ranges.items():
            self.model.jnt_range[self.model.joint(joint).id] = joint_range
        self.configuration = mink.Configuration(self.model)
        self.arm_qpos = {s: np.array([self.model.joint(j).qposadr[0] for j in robot.arm_joint_names(s)])
                         for s in robot.SIDES}
        arm_joints = [j for s in robot.SIDES for j in robot.arm_joint_names(s)]
        arm_dofs = {int(self.model.joint(j).dofadr[0]) for j in arm_joints}
        self.frame_tasks = {
            side: mink.FrameTask(robot.ee_site(side), "site", position_cost=POSITION_COST,
                                 orientation_cost=robot.ik_orientation_cost, lm_damping=LM_DAMPING)
            for side in robot.SIDES
        }
        self.posture_task = mink.PostureTask(self.model, cost=POSTURE_COST)
        self.limits = [mink.ConfigurationLimit(self.model),
                       mink.VelocityLimit(self.model, {j: ARM_SPEED_LIMIT_RAD_S for j in arm_joints})]
        frozen = [d for d in range(self.model.nv) if d not in arm_dofs]  # neck and fingers are not IK's business
        self.constraints = [mink.DofFreezingTask(self.model, dof_indices=frozen)]
        self.lower = self.model.jnt_range[:, 0][self.model.dof_jntid]
        self.upper = self.model.jnt_range[:, 1][self.model.dof_jntid]
        self.home_q = np.zeros(self.model.nq)
        for side, rest in robot.calibration().arm_qpos.items():
            self.home_q[self.arm_qpos[side]] = rest
        self.posture_task.set_target(self.home_q)

    def set_targets(self, targets: dict[str, tuple[np.ndarray, np.ndarray]]) -> None:
        """Hand targets per side: (world position (3,), orientation quaternion wxyz (4,))."""
        for side, (pos, quat) in targets.items():
            self.frame_tasks[side].set_target(
                mink.SE3.from_rotation_and_translation(mink.SO3(quat / np.linalg.norm(quat)), pos))

    def step(self, q: np.ndarray, dt: float) -> np.ndarray:
        """One IK step from joint configuration `q` (IK-model qpos); returns the integrated configuration."""
        self.configuration.update(np.clip(q, self.lower, self.upper))
        velocity = mink.solve_ik(self.configuration, [*self.frame_tasks.values(), self.posture_task], dt, SOLVER,
                                 damping=SOLVER_DAMPING, limits=self.limits, constraints=self.constraints)
        return self.configuration.integrate(velocity, dt)

    def reach_error(self, action: np.ndarray, side: str, iterations: int = 200) -> tuple[float, float]:
        """Kinematic check of a canonical action: iterate IK from the home pose and return the remaining position
        (m) and orientation (rad) error of `side`'s hand. Cheap enough for planners to compare options."""
        self.set_targets(hand_targets(self.robot, action))
        q = self.home_q.copy()
        for _ in range(iterations):
            q = self.step(q, 0.05)
        position, quat = self.ee_pose(side, q)
        slots = canonical.LEFT if side == "left" else canonical.RIGHT
        target = action[slots.position] + np.asarray(self.robot.canonical_origin)
        return float(np.linalg.norm(position - target)), quat_angle_rad(quat, action[slots.quaternion])

    def ee_pose(self, side: str, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Forward kinematics: world position and quaternion of the hand at configuration `q`."""
        self.configuration.update(q)
        pose = self.configuration.get_transform_frame_to_world(self.robot.ee_site(side), "site")
        return pose.translation(), pose.rotation().wxyz


def _unit(quat: np.ndarray) -> np.ndarray:
    """`quat` normalised without overflow for any finite size; an already normalised one is returned unchanged
    (so that applying an applied command again changes nothing, not a bit)."""
    with np.errstate(over="ignore"):
        if abs(np.linalg.norm(quat) - 1.0) <= 1e-12:
            return quat
    scaled = quat / np.max(np.abs(quat))
    return scaled / np.linalg.norm(scaled)


def _within(offset: np.ndarray, radius: float) -> np.ndarray:
    """`offset` (m, canonical frame) moved along its direction to at most `radius` from the canonical origin."""
    scale = np.max(np.abs(offset))
    if scale <= radius / 2:  # certainly inside, and its norm cannot overflow
        return offset
    direction = offset / scale
    norm = np.linalg.norm(direction)
    return offset if scale * norm <= radius else direction / norm * radius


def hand_targets(robot: Robot, action: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """World-frame hand targets of a canonical action."""
    origin = np.asarray(robot.canonical_origin)
    return {arm.side: (action[arm.position] + origin, action[arm.quaternion]) for arm in canonical.ARMS}


class Controller:
    """Turns the current 19-D command into actuator targets of the simulated robot, one 60 Hz tick at a time."""

    def __init__(self, world: World, *, neck_locked: bool = False):
        self.world = world
        self.robot = world.robot
        self.ik = ArmIK(self.robot)
        self.neck_range = self.robot.neck_range_rad()
        self.neck_locked = neck_locked
        self.half_stroke = self.robot.gripper.stroke_m / 2
        self.finger_step = self.robot.gripper.speed_m_s / CONTROL_HZ
        self._ik_q = self.ik.home_q.copy()
        self.command = canonical.rest_action()
        self._finger_setpoint = {side: self.half_stroke for side in self.robot.SIDES}

    def reset(self, data: mujoco.MjData) -> None:
        """Put the robot at its home pose, at rest, with the rest action commanded and the grippers open."""
        home = self.ik.home_q
        for side, arm in self.world.arms.items():
            data.qpos[arm.qpos] = home[self.ik.arm_qpos[side]]
            data.ctrl[arm.actuators] = home[self.ik.arm_qpos[side]]
            data.qpos[arm.finger_qpos] = self.half_stroke
            data.ctrl[arm.gripper_actuator] = self.half_stroke
            self._finger_setpoint[side] = self.half_stroke
        data.qpos[self.world.neck_qpos] = 0.0
        data.ctrl[self.world.neck_actuators] = 0.0
        self.set_command(canonical.rest_action())

    def copy_setpoints(self, other: Controller) -> None:
        """Take over another controller's command and gripper ramps (same world), e.g. to simulate ahead."""
        self.set_command(other.command)
        self._finger_setpoint = dict(other._finger_setpoint)

    def set_command(self, action: np.ndarray) -> np.ndarray:
        """Validate a canonical action, clip head and gripper values to their ranges, and make it the command.

        Returns the command actually applied (after clipping and, when the neck is locked, zeroing the head).
        """
        command = canonical.validate_action(action).copy()
        command[canonical.HEAD] = np.clip(command[canonical.HEAD], self.neck_range[:, 0], self.neck_range[:, 1])
        if self.neck_locked:
            command[canonical.HEAD] = 0.0
        for arm in canonical.ARMS:
            command[arm.gripper] = np.clip(command[arm.gripper], -1.0, 1.0)
            command[arm.quaternion] = _unit(command[arm.quaternion])
            command[arm.position] = _within(command[arm.position], MAX_TARGET_DISTANCE_M)
        self.command = command
        self.ik.set_targets(hand_targets(self.robot, command))
        return command

    def tick(self, data: mujoco.MjData) -> None:
        """Refresh all actuator targets from the measured state and the current command (call at 60 Hz)."""
        for side, arm in self.world.arms.items():
            self._ik_q[self.ik.arm_qpos[side]] = data.qpos[arm.qpos]
        q = self.ik.step(self._ik_q, 1.0 / CONTROL_HZ)
        for side, arm in self.world.arms.items():
            data.ctrl[arm.actuators] = q[self.ik.arm_qpos[side]]
        data.ctrl[self.world.neck_actuators] = self.command[canonical.HEAD]
        for arm_slots in canonical.ARMS:
            side = arm_slots.side
            target = self.half_stroke * (1.0 - self.command[arm_slots.gripper]) / 2
            current = self._finger_setpoint[side]
            self._finger_setpoint[side] = current + np.clip(target - current, -self.finger_step, self.finger_step)
            data.ctrl[self.world.arms[side].gripper_actuator] = self._finger_setpoint[side]

    def measured_state(self, data: mujoco.MjData) -> np.ndarray:
        """The canonical 19-D state: hand poses in the canonical frame, neck angles, gripper openness in [-1, 1]."""
        state = np.zeros(canonical.ACTION_DIM)
        origin = np.asarray(self.robot.canonical_origin)
        for slots in canonical.ARMS:
            arm = self.world.arms[slots.side]
            state[slots.position] = data.site_xpos[arm.ee_site] - origin
            quat = np.empty(4)
            mujoco.mju_mat2Quat(quat, data.site_xmat[arm.ee_site])
            state[slots.quaternion] = quat if quat[0] >= 0 else -quat
            opening = data.qpos[arm.finger_qpos[0]] / self.half_stroke
            state[slots.gripper] = np.clip(1.0 - 2.0 * opening, -1.0, 1.0)
        state[canonical.HEAD] = 0.0 if self.neck_locked else data.qpos[self.world.neck_qpos]
        return state
