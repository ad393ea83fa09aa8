"""Rest calibration: the arm posture that holds each hand at the rest position, and the end-effector frame.

Each robot names a rest-posture seed (GR1T2: the reference's rest joints; Reachy2: elbows out, because the
reference's rest joints put its hands below the table top). A position-only IK solve from that seed gives the
rest posture; the end-effector frame is then the hand frame rotated so that its orientation at the rest posture is
exactly the canonical rest quaternion. So the rest action is reached with a relaxed wrist on both robots, and the
controller's posture task pulls toward a pose it can actually hold.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import mink
import numpy as np

from lerobot_tavis import canonical
from lerobot_tavis.envs.transforms import quat_multiply

ITERATIONS = 600
STEP_S = 0.05


@dataclass(frozen=True)
class RestCalibration:
    arm_qpos: dict[str, np.ndarray]  # side -> (7,) rest posture, rad
    ee_quat_in_hand: dict[str, np.ndarray]  # side -> orientation of the end-effector frame in the hand frame


@functools.cache
def calibrate(robot_cls) -> RestCalibration:
    """Solve once per robot class (deterministic)."""
    robot = robot_cls()
    model = robot.raw_spec().compile()
    configuration = mink.Configuration(model)
    q = np.zeros(model.nq)
    arm_qpos = {s: np.array([model.joint(j).qposadr[0] for j in robot.arm_joint_names(s)]) for s in robot.SIDES}
    for side in robot.SIDES:
        q[arm_qpos[side]] = robot.rest_posture_seed[side]
    posture = mink.PostureTask(model, cost=1e-2)
    posture.set_target(q.copy())
    origin = np.asarray(robot.canonical_origin)
    tasks = [posture]
    for side in robot.SIDES:
        task = mink.FrameTask(robot.ee_site(side), "site", position_cost=1.0, orientation_cost=0.0)
        position = np.asarray(canonical.REST_POSITION[side]) + origin
        task.set_target(mink.SE3.from_rotation_and_translation(mink.SO3.identity(), position))
        tasks.append(task)
    limits = [mink.ConfigurationLimit(model)]
    for _ in range(ITERATIONS):
        configuration.update(q)
        q = configuration.integrate(mink.solve_ik(configuration, tasks, STEP_S, "daqp", damping=1e-3,
                                                  limits=limits), STEP_S)
    configuration.update(q)
    ee_quat_in_hand = {}
    for side in robot.SIDES:
        hand_quat = configuration.get_transform_frame_to_world(robot.ee_site(side), "site").rotation().wxyz
        hand_inverse = hand_quat * np.array([1.0, -1.0, -1.0, -1.0])
        ee_quat_in_hand[side] = quat_multiply(hand_inverse, canonical.REST_QUATERNION[side])
    return RestCalibration({s: q[arm_qpos[s]].copy() for s in robot.SIDES}, ee_quat_in_hand)
