"""TavisEnv as gymnasium and LeRobot expect it."""

import pickle

import mujoco
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from lerobot_tavis import canonical
from lerobot_tavis.envs.env import TavisEnv
from lerobot_tavis.envs.modes import CAMERA_MODES
from lerobot_tavis.envs.reach import HELD_BACK_M, MOVED_M, REACHED_M, ReachTracker, failure_stage, held_back
from lerobot_tavis.overlay import Caption, compose
from tests.conftest import run_steps


def _wiggle(steps: int = 6) -> list[np.ndarray]:
    actions = []
    for k in range(steps):
        action = canonical.rest_action()
        action[canonical.HEAD_PITCH] = 0.05 * k
        action[canonical.LEFT.position][0] += 0.01 * k
        actions.append(action)
    return actions


def _rollout(env, seed):
    obs, _ = env.reset(seed=seed)
    frames = [obs]
    for action in _wiggle():
        frames.append(env.step(action)[0])
    return frames


@pytest.mark.parametrize("camera_mode", ["head_wrist", "fixed_only"])
def test_same_seed_same_episode_same_pixels(small_env, robot_name, camera_mode):
    env = small_env(robot=robot_name, camera_mode=camera_mode)
    assert env.shadows  # the default: shadow maps and culling must not make pixels vary
    first = _rollout(env, seed=7)
    second = _rollout(small_env(robot=robot_name, camera_mode=camera_mode), seed=7)
    for a, b in zip(first, second):
        for cam in a["pixels"]:
            np.testing.assert_array_equal(a["pixels"][cam], b["pixels"][cam])
        np.testing.assert_array_equal(a["agent_pos"], b["agent_pos"])
        np.testing.assert_array_equal(a["joint_pos"], b["joint_pos"])


def test_reset_with_the_same_seed_reproduces_and_another_seed_differs(small_env):
    env = small_env(robot="gr1t2", camera_mode="fixed_only")
    first = env.reset(seed=3)[0]["pixels"]["fixed"]
    run_steps(env, canonical.rest_action(), 5)
    again = env.reset(seed=3)[0]["pixels"]["fixed"]
    other = env.reset(seed=4)[0]["pixels"]["fixed"]
    np.testing.assert_array_equal(first, again)
    assert not np.array_equal(first, other)


@pytest.mark.parametrize("camera_mode,cameras", [
    ("head_only", {"head"}), ("fixed_only", {"fixed"}),
    ("head_wrist", {"head", "left_wrist", "right_wrist"}), ("fixed_wrist", {"fixed", "left_wrist", "right_wrist"})])
def test_observation_holds_only_the_camera_modes_cameras(small_env, camera_mode, cameras):
    env = small_env(robot="gr1t2", camera_mode=camera_mode, image_size=(24, 32))
    obs, info = env.reset(seed=0)
    assert set(obs["pixels"]) == cameras == set(env.observation_space["pixels"].spaces)
    assert set(env._sim.rig.cameras) == cameras  # nothing else is rendered
    for image in obs["pixels"].values():
        assert image.shape == (24, 32, 3) and image.dtype == np.uint8
    assert obs["agent_pos"].shape == (19,) and obs["joint_pos"].shape == (len(env.world.robot.joint_names()),)
    assert env.observation_space.contains(obs)
    assert info == {"is_success": False}


def test_what_lerobot_reads(small_env):
    env = small_env(robot="reachy2", camera_mode="head_only", episode_length_s=0.5)
    assert env.metadata["render_fps"] == 20
    assert env._max_episode_steps == 10
    assert env.task == "tabletop" and isinstance(env.task_description, str) and env.task_description
    env.reset(seed=0)
    for step in range(10):
        obs, reward, terminated, truncated, info = env.step(canonical.rest_action())
        assert "is_success" in info and not terminated
        assert truncated == (step == 9)


def test_render_adds_the_overview_to_the_last_frames_without_rendering_them_again(small_env, monkeypatch):
    env = small_env(robot="gr1t2", camera_mode="head_wrist")
    obs, _ = env.reset(seed=0)
    observed, overview = [], []
    monkeypatch.setattr(env._sim.rig, "render", lambda data: observed.append(1))
    original = env._sim.rig.render_camera
    monkeypatch.setattr(env._sim.rig, "render_camera",
                        lambda data, camera_id: overview.append(camera_id) or original(data, camera_id))
    frame = env.render()
    assert not observed and overview == [env.world.cameras["overview"]]
    expected = compose(obs["pixels"], original(env.data, overview[0]),
                       Caption(env.task_description, 0.0, env._max_episode_steps / env.fps))
    np.testing.assert_array_equal(frame, expected)
    assert "overview" not in obs["pixels"]


def test_simulator_is_built_lazily_and_released_by_close():
    env = TavisEnv(robot="gr1t2", camera_mode="fixed_only", image_size=(24, 32))
    assert env._sim is None
    clone = pickle.loads(pickle.dumps(env))  # what a forkserver worker receives
    clone.reset(seed=0)
    clone.close()
    assert clone._sim is None
    with pytest.raises(RuntimeError, match="reset"):
        env.step(canonical.rest_action())
    with pytest.raises(RuntimeError, match="reset"):
        env.render()


@pytest.mark.parametrize("camera_mode", ["fixed_only", "fixed_wrist"])
def test_fixed_camera_modes_hold_the_neck_at_zero(small_env, camera_mode):
    env = small_env(robot="gr1t2", camera_mode=camera_mode)
    env.reset(seed=0)
    action = canonical.rest_action()
    action[canonical.HEAD] = (0.1, 0.6, -0.8)
    state = run_steps(env, action, 15)["agent_pos"]
    np.testing.assert_array_equal(state[canonical.HEAD], 0.0)
    np.testing.assert_allclose(env.data.qpos[env.world.neck_qpos], 0.0, atol=1e-3)


@pytest.mark.parametrize("kwargs,message", [
    ({"robot": "atlas"}, "robot must be one of"),
    ({"camera_mode": "eyes"}, "camera_mode must be one of"),
    ({"task": "fly"}, "task must be one of"),
    ({"split": "ood_spatial"}, "split of task 'tabletop' must be one of"),
    ({"image_size": (480,)}, "image_size must be"),
    ({"image_size": (4, 4)}, "image_size must be within"),
    ({"episode_length_s": 0}, "episode_length_s must be a finite number of seconds, at least one step at 20 fps"),
    ({"fps": 25}, "fps must divide the 60 Hz control rate"),
    ({"cameras": ("head", "belly")}, "cameras must be distinct names among"),
])
def test_bad_arguments_raise_clear_errors(kwargs, message):
    with pytest.raises(ValueError, match=message):
        TavisEnv(**kwargs)


def test_gymnasium_env_checker(small_env, recwarn):
    check_env(small_env(robot="gr1t2", camera_mode="fixed_only", image_size=(24, 32)), skip_render_check=True)
    # its one remark: the action is in metres and radians (the canonical action), not normalised to [-1, 1] as it
    # advises for reinforcement learning; LeRobot's policies normalise actions themselves
    assert [str(warning.message) for warning in recwarn] == [
        "\x1b[33mWARN: For Box action spaces, we recommend using a symmetric and normalized space (range=[-1, 1] or "
        "[0, 1]). See https://stable-baselines3.readthedocs.io/en/master/guide/rl_tips.html for more "
        "information.\x1b[0m"]
    recwarn.clear()


def test_a_60hz_env_steps_one_control_tick_and_counts_time_in_seconds(small_env):
    env = small_env(task="wait_then_act", fps=60, episode_length_s=1.0)
    env.reset(seed=3)
    assert env._max_episode_steps == 60 and env.metadata["render_fps"] == 60
    before = env.data.time
    env.step(canonical.rest_action())
    assert env.data.time - before == pytest.approx(1 / 60)
    green_at = env.task_object.green_at_s
    steps = round(green_at * 60)
    for _ in range(steps - 2):
        env.step(canonical.rest_action())
    assert not env.task_object.is_green  # after steps - 1 steps of 1/60 s
    env.step(canonical.rest_action())
    assert env.task_object.is_green


def test_cameras_override_the_mode_and_none_renders_nothing(small_env):
    env = small_env(camera_mode="head_only", cameras=("fixed", "left_wrist"))
    obs, _ = env.reset(seed=0)
    assert list(obs["pixels"]) == ["fixed", "left_wrist"]
    blind = small_env(cameras=())
    obs, _ = blind.reset(seed=0)
    assert obs["pixels"] == {} and obs["agent_pos"].shape == (19,)
    with pytest.raises(RuntimeError, match="renders no cameras"):
        blind.render()


def test_the_overview_camera_is_for_people_only(small_env):
    for camera_mode in CAMERA_MODES:
        assert "overview" not in small_env(camera_mode=camera_mode).camera_names
    env = small_env(cameras=("overview", "head"))
    obs, _ = env.reset(seed=0)
    overview, head = obs["pixels"]["overview"], obs["pixels"]["head"]
    assert overview.shape == head.shape and overview.std() > 10 and not np.array_equal(overview, head)
    with pytest.raises(ValueError, match="overview"):
        small_env(cameras=("topdown",))


def test_reach_tells_a_hand_that_never_got_to_the_target(small_env):
    env = small_env(task="conditional_pick")
    env.reset(seed=1000)
    closing = canonical.rest_action()
    closing[[canonical.LEFT.gripper, canonical.RIGHT.gripper]] = canonical.GRIPPER_CLOSED
    for action in (canonical.rest_action(), closing):  # grippers closed far from the target: no grasp of it
        *_, info = env.step(action)
    reach = info["reach"]
    assert reach["closest_hand_m"] > REACHED_M and reach["target_moved_m"] < MOVED_M
    assert REACHED_M < reach["closest_hand_other_m"] < 1.0  # the other object on the table, not an off-stage one
    assert reach["first_grasp_xy_m"] is None and reach["first_grasp_in_hand_m"] is None
    assert failure_stage(reach) == "not_reached"
    assert failure_stage({**reach, "closest_hand_other_m": 0.03}) == "reached_other"
    assert failure_stage({"closest_hand_m": 0.2, "target_moved_m": 0.0}) == "not_reached"  # logged before "other"
    assert failure_stage({"closest_hand_m": 0.01, "closest_hand_other_m": 0.03, "target_moved_m": 0.0}) == \
        "reached_not_moved"
    assert failure_stage({"closest_hand_m": 0.01, "target_moved_m": 0.1}) == "moved_no_success"


def test_reach_gives_the_first_grasp_in_the_closing_hand_s_frame():
    # the left hand's grasp site turned 90 degrees about z (its x along world y), the target 1 cm ahead of it
    model = mujoco.MjModel.from_xml_string("""<mujoco><worldbody>
      <site name="left" pos="0 0 1" euler="0 0 90"/><site name="right" pos="0 -1 1"/>
      <body name="target" pos="0.01 0 1"><freejoint/><geom size="0.01"/></body></worldbody></mujoco>""")
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    tracker = ReachTracker(data, model.body("target").id, {"left": 0, "right": 1})
    closing = canonical.rest_action()
    closing[canonical.LEFT.gripper] = canonical.GRIPPER_CLOSED
    tracker.update(data, closing, closing)
    reach = tracker.summary()
    assert reach["first_grasp_xy_m"] == 0.01
    assert reach["first_grasp_in_hand_m"] == [0.0, -0.01, 0.0]  # the target along the hand's -y


def test_reach_tells_a_hand_held_back_from_one_that_stopped_where_commanded(small_env):
    env = small_env(task="conditional_pick")
    env.reset(seed=1000)
    *_, info = env.step(canonical.rest_action())
    assert held_back(info["reach"]) is False and info["reach"]["command_gap_m"] < HELD_BACK_M
    out_of_reach = canonical.rest_action()
    out_of_reach[canonical.LEFT.position] = (0.3, 1.2, 0.3)  # a metre to the robot's left
    for _ in range(10):
        *_, info = env.step(out_of_reach)
    assert held_back(info["reach"]) is True and info["reach"]["command_gap_m"] > 0.3
    assert held_back({"closest_hand_m": 0.2, "target_moved_m": 0.0}) is None  # a log from before the gap
