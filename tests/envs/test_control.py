"""The canonical action drives both robots: rest pose, reach grid, head tracking, clipping, bad input."""

import mujoco
import numpy as np
import pytest

from lerobot_tavis import canonical
from lerobot_tavis.envs import physics
from lerobot_tavis.envs.control import ArmIK, Controller
from lerobot_tavis.envs.robots import make_robot
from lerobot_tavis.envs.tasks.base import Task
from lerobot_tavis.envs.tasks.catalog import TaskInfo
from lerobot_tavis.envs.transforms import quat_angle_rad
from lerobot_tavis.envs.world import build_world
from tests.conftest import run_steps


class EmptyRoom(Task):
    """No table, no props: reach targets at table height must not collide with anything."""

    info = TaskInfo("empty_room", "test", ("",), "never")
    VARIANTS = {"id": None}
    has_table = False

    def build(self, spec):
        pass

    def initialize_episode(self, model, data, rng):
        pass

    def evaluate(self, data):
        return {"success": False}


def _settle(controller, model, data, action, seconds):
    controller.set_command(action)
    for _ in range(int(seconds * physics.CONTROL_HZ)):
        controller.tick(data)
        mujoco.mj_step(model, data, nstep=physics.SUBSTEPS_PER_TICK)
    return controller.measured_state(data)


def test_rest_action_settles_each_hand_within_1cm_and_3deg(small_env, robot_name):
    env = small_env(task="tabletop", robot=robot_name, camera_mode="fixed_only", cameras=())
    rest = canonical.rest_action()
    perturbed = rest.copy()
    perturbed[0:3] += (0.05, 0.05, -0.05)
    perturbed[7:10] += (0.05, -0.05, 0.05)
    env.reset(seed=0)
    run_steps(env, perturbed, 20)  # move away first, so settling is really exercised
    state = run_steps(env, rest, 40)["agent_pos"]
    for arm in canonical.ARMS:
        assert np.linalg.norm(state[arm.position] - rest[arm.position]) < 0.01
        assert np.degrees(quat_angle_rad(state[arm.quaternion], rest[arm.quaternion])) < 3.0


def test_reach_grid_is_tracked_within_1cm_wherever_reachable(robot_name):
    """Grid over x 0.25-0.55, y -0.35-0.35, z 0.07-0.40 (canonical), rest orientation, arm on the target's side.

    'Reachable' = the same IK iterated kinematically to convergence gets within 5 mm; the simulated robot
    must then be within 1 cm after 2.5 s.
    """
    robot = make_robot(robot_name)
    world = build_world(robot, EmptyRoom("id"), image_size=(48, 64))
    data = mujoco.MjData(world.model)
    controller = Controller(world)
    oracle = ArmIK(robot)
    reachable, errors = 0, []
    for x in np.linspace(0.25, 0.55, 4):
        for y in np.linspace(-0.35, 0.35, 5):
            for z in np.linspace(0.07, 0.40, 4):
                arm = canonical.LEFT if y >= 0 else canonical.RIGHT
                action = canonical.rest_action()
                action[arm.position] = (x, y, z)
                if oracle.reach_error(action, arm.side, iterations=300)[0] > 0.005:
                    continue
                reachable += 1
                mujoco.mj_resetData(world.model, data)
                controller.reset(data)
                state = _settle(controller, world.model, data, action, 2.5)
                errors.append(np.linalg.norm(state[arm.position] - action[arm.position]))
    assert reachable >= 25, f"only {reachable}/80 grid points reachable: the test would prove little"
    assert max(errors) < 0.01, f"worst tracking error {max(errors):.4f} m"


def test_head_pitch_and_yaw_are_tracked_within_002_rad(small_env, robot_name):
    env = small_env(task="tabletop", robot=robot_name, camera_mode="head_only", cameras=())
    env.reset(seed=0)
    limits = env.world.robot.neck_range_rad()
    for pitch_frac, yaw_frac in [(0.8, 0.0), (-0.5, 0.6), (0.3, -0.9), (0.0, 0.2)]:
        action = canonical.rest_action()
        action[canonical.HEAD_PITCH] = pitch_frac * limits[1, 1 if pitch_frac > 0 else 0] * np.sign(pitch_frac)
        action[canonical.HEAD_YAW] = yaw_frac * limits[2, 1 if yaw_frac > 0 else 0] * np.sign(yaw_frac)
        state = run_steps(env, action, 20)["agent_pos"]
        np.testing.assert_allclose(state[canonical.HEAD], action[canonical.HEAD], atol=0.02)


def test_head_and_gripper_commands_are_clipped_to_their_ranges(small_env, robot_name):
    env = small_env(task="tabletop", robot=robot_name, camera_mode="head_only", cameras=())
    env.reset(seed=0)
    action = canonical.rest_action()
    action[canonical.HEAD] = (5.0, -5.0, 5.0)
    action[canonical.LEFT.gripper] = 3.0
    action[canonical.RIGHT.gripper] = -7.0
    _, _, _, _, info = env.step(action)
    limits = env.world.robot.neck_range_rad()
    np.testing.assert_allclose(info["applied_action"][canonical.HEAD], (limits[0, 1], limits[1, 0], limits[2, 1]))
    np.testing.assert_allclose(info["applied_action"][17:], (1.0, -1.0))
    state = run_steps(env, action, 30)["agent_pos"]
    assert np.all(state[canonical.HEAD] >= limits[:, 0] - 0.02) and np.all(state[canonical.HEAD] <= limits[:, 1] + 0.02)
    assert state[canonical.LEFT.gripper] == pytest.approx(1.0, abs=0.05)


def test_unreachable_target_gives_the_closest_pose_never_nan(small_env, robot_name):
    env = small_env(task="tabletop", robot=robot_name, camera_mode="fixed_only", cameras=())
    env.reset(seed=0)
    action = canonical.rest_action()
    action[canonical.LEFT.position] = (3.0, 2.0, 1.5)  # 3.7 m away
    action[canonical.RIGHT.position] = (-1.0, -3.0, -2.0)
    start = env.step(canonical.rest_action())[0]["agent_pos"]
    state = run_steps(env, action, 40)["agent_pos"]
    assert np.all(np.isfinite(state))
    for arm in canonical.ARMS:
        before = np.linalg.norm(start[arm.position] - action[arm.position])
        after = np.linalg.norm(state[arm.position] - action[arm.position])
        assert after < before - 0.1  # the hand stretched toward the target


def test_bad_actions_raise_naming_the_problem(small_env):
    env = small_env(task="tabletop", robot="gr1t2", camera_mode="fixed_only", cameras=())
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"shape \(19,\)"):
        env.step(np.zeros(18))
    action = canonical.rest_action()
    action[9] = np.nan
    with pytest.raises(ValueError, match=r"action\[9\] \(right_ee_z\)"):
        env.step(action)


def test_ik_joint_ranges_narrow_only_the_ik_model():
    robot = make_robot("reachy2")
    world = build_world(robot, EmptyRoom("id"), image_size=(48, 64))
    ik = ArmIK(robot)
    for joint, joint_range in robot.ik_joint_ranges.items():
        np.testing.assert_allclose(ik.model.jnt_range[ik.model.joint(joint).id], joint_range)
        servo_range = world.model.jnt_range[world.model.joint(robot.prefix + joint).id]
        assert servo_range[1] > joint_range[1]  # the simulated joint keeps its full range
