"""TavisEnv: one TAVIS task on one robot as a gymnasium env, stepped at 20 Hz (or any divisor of 60 Hz: the
demonstrators are recorded at 60 Hz, one control tick per step).

The simulator and renderer are built lazily on the first reset, so the env can be constructed in one process and
used in another (LeRobot's forkserver vector envs). All randomness comes from the generator seeded in
`reset(seed=...)`: the same seed and the same actions give the same observations, pixels included.
"""

from __future__ import annotations

import zlib

import gymnasium as gym
import mujoco
import numpy as np

from lerobot_tavis import canonical, checks
from lerobot_tavis.envs import physics, visual_ood
from lerobot_tavis.envs.control import Controller
from lerobot_tavis.envs.modes import (CAMERA_NAMES, DEFAULT_CAMERA_MODE, OVERVIEW_CAMERA, VIEW_CAMERAS, mode_cameras,
                                      neck_locked, resolve_camera_mode)
from lerobot_tavis.envs.placement import body_speed
from lerobot_tavis.envs.reach import ReachTracker
from lerobot_tavis.envs.rendering import CameraRig
from lerobot_tavis.envs.robots import make_robot
from lerobot_tavis.envs.tasks.base import EpisodeFacts, TargetFacts
from lerobot_tavis.envs.tasks.catalog import VISUAL_SPLIT, make_task, parse_split, task_info
from lerobot_tavis.envs.world import World, build_world
from lerobot_tavis.errors import FieldError

HAND_REACH_M = 1.5  # hand positions of action and state lie within this of the hip, per canonical axis
JOINT_BOUND = 2 * np.pi  # joint_pos bound: every robot joint is a limited hinge (rad) or finger slide (m)
SETTLE_MAX_S = 1.5
SETTLE_MIN_S = 0.1
SETTLE_SPEED_M_S = 0.005
WARM_UP_STEPS = 10
WARM_UP_POSITION_STD_M = 0.10
WARM_UP_HEAD_STD_RAD = 0.175
# MuJoCo's instability warnings (name, index into MjData.warning): it resets the simulation state itself when one
# fires, so the episode cannot go on.
INSTABILITY_WARNINGS = tuple((name, int(getattr(mujoco.mjtWarning, name)))
                             for name in ("mjWARN_BADQPOS", "mjWARN_BADQVEL", "mjWARN_BADQACC"))


class _Sim:
    """Model, data, controller and renderer of one env; exists between the first reset and close()."""

    def __init__(self, world: World, camera_mode: str, camera_names, image_size, blacked_out):
        self.world = world
        self.model = world.model
        self.data = mujoco.MjData(world.model)
        self.controller = Controller(world, neck_locked=neck_locked(camera_mode))
        cameras = {name: world.cameras[name] for name in camera_names}
        self.rig = CameraRig(world.model, cameras, image_size, blacked_out)
        self.id_look = visual_ood.IdLook.of(world.model)

    def advance_tick(self) -> None:
        self.controller.tick(self.data)
        mujoco.mj_step(self.model, self.data, nstep=physics.SUBSTEPS_PER_TICK)

    def instability(self) -> str | None:
        """The first of MuJoCo's instability warnings raised since the last reset, e.g. "mjWARN_BADQVEL"."""
        for name, index in INSTABILITY_WARNINGS:
            if self.data.warning[index].number:
                return name
        return None


class TavisEnv(gym.Env):
    """A TAVIS task. Observations: `pixels` (the camera mode's cameras, HxWx3 uint8), `agent_pos` (the measured
    canonical 19-D state) and `joint_pos` (robot joints, see `Robot.joint_names`). Actions: the canonical 19-D
    action (`lerobot_tavis.canonical`); head angles and gripper values outside their ranges are clipped.

    `cameras` overrides which cameras the observations carry (default: the camera mode's), e.g. to add the
    third-person `overview` camera for a video; `()` renders nothing, for recording and replay, which render what
    they need themselves.

    An episode ends early, truncated and unsuccessful, if MuJoCo reports an instability (it then resets the
    simulation state itself); `info["instability"]` names the warning and when it fired. Otherwise every step's
    `info["conditions"]` holds the parts of the task's success rule (`Task.evaluate` less "success", which is
    `info["is_success"]`), e.g. `{"target_lifted": True, "target_slow": False, "target_height_m": 1.31, ...}`, and
    `info["reach"]` how far the episode has got toward a task's target so far (`lerobot_tavis.envs.reach`):
    `{"closest_hand_m": 0.012, "closest_hand_other_m": 0.31, "target_moved_m": 0.25, "first_grasp_xy_m": 0.004,
    "first_grasp_in_hand_m": [0.001, -0.003, 0.012], "command_gap_m": 0.003}`,
    or None for a task without one.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": physics.POLICY_HZ}

    def __init__(self, task: str = "tabletop", robot: str = "gr1t2", camera_mode: str = DEFAULT_CAMERA_MODE,
                 split: str = "id", image_size: tuple[int, int] = (480, 640), episode_length_s: float = 20.0,
                 shadows: bool = True, render_mode: str | None = "rgb_array", fps: int = physics.POLICY_HZ,
                 cameras: tuple[str, ...] | None = None):
        info = task_info(task)
        camera_mode = resolve_camera_mode(camera_mode)
        base_split, self._visual_factors = parse_split(split)
        if base_split not in info.splits:
            raise FieldError("split", f"of task {task!r} must be one of {info.splits}, got {split!r}")
        self.camera_names = mode_cameras(camera_mode) if cameras is None else _check_cameras(cameras)
        make_robot(robot)  # validates the name; the model itself is built on the first reset
        height, width = checks.image_size(image_size)
        if render_mode not in (None, "rgb_array"):
            raise FieldError("render_mode", f"must be 'rgb_array' or None, got {render_mode!r}")
        if not (isinstance(fps, int) and fps > 0 and physics.CONTROL_HZ % fps == 0):
            raise FieldError("fps", f"must divide the {physics.CONTROL_HZ} Hz control rate (20, 30, 60, ...), "
                                    f"got {fps!r}")
        max_episode_steps = checks.episode_steps(episode_length_s, fps)

        self.task = task
        self.task_description = info.prompts[0]
        self.robot_name = robot
        self.camera_mode = camera_mode
        self.split = split
        self.image_size = (height, width)
        self.shadows = shadows
        self.render_mode = render_mode
        self.fps = fps
        self.metadata = {**self.metadata, "render_fps": fps}
        self._ticks_per_step = physics.CONTROL_HZ // fps
        self._max_episode_steps = max_episode_steps
        self._task = make_task(task, "id" if base_split in ("ood_init_pose", VISUAL_SPLIT) else base_split)
        self.visual_draw = None  # ood_visual: the look drawn for the current episode (visual_ood.VisualDraw)
        self._robot = make_robot(robot)
        self._sim: _Sim | None = None
        self._facts: EpisodeFacts | None = None
        self._reach: ReachTracker | None = None  # tasks with a target: how near the hands got, how far it moved,
        # how far off the first grasp of it closed
        self._steps = 0
        self._last_frames: dict[str, np.ndarray] | None = None
        self._success_s: float | None = None  # when the task first reported success in this episode

        n_joints = len(self._robot.joint_names())
        self.observation_space = gym.spaces.Dict({
            "pixels": gym.spaces.Dict({
                name: gym.spaces.Box(0, 255, (height, width, 3), np.uint8) for name in self.camera_names}),
            "agent_pos": _state_space(),
            "joint_pos": gym.spaces.Box(-JOINT_BOUND, JOINT_BOUND, (n_joints,), np.float32),
        })
        self.action_space = _action_space(self._robot.neck_range_rad())

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Start an episode. The scene is drawn from (seed, task), so tasks that get the same seed list (as in
        lerobot-eval) do not share layouts by accident; the same seed always gives the same episode."""
        super().reset(seed=None if seed is None else scene_seed(seed, self.task))
        look_rng = self.np_random.spawn(1)[0]  # ood_visual's draws; spawning leaves the task's stream untouched
        sim = self._ensure_sim()
        mujoco.mj_resetData(sim.model, sim.data)
        sim.controller.reset(sim.data)
        self._task.initialize_episode(sim.model, sim.data, self.np_random)
        self._facts = self._task.episode_facts()
        self.task_description = self._task.prompt
        mujoco.mj_forward(sim.model, sim.data)
        self._settle(sim)
        if self._visual_factors:
            self.visual_draw = visual_ood.apply(sim.model, sim.data, self._visual_factors, look_rng, sim.id_look,
                                                has_table=self._task.has_table, robot_prefix=self._robot.prefix)
        self._steps = 0
        self._success_s = None
        if self.split == "ood_init_pose":
            self._warm_up(sim)
        self._reach = self._track_reach(sim)
        return self._observe(sim), {"is_success": False}

    def step(self, action):
        sim = self._require_sim()
        applied = sim.controller.set_command(action)
        for _ in range(self._ticks_per_step):
            sim.advance_tick()
        self._steps += 1
        unstable = sim.instability()
        if unstable:  # MuJoCo has reset the state: the episode ends, unsuccessful, with the reason
            info = {"is_success": False, "applied_action": applied,
                    "instability": f"{unstable} at step {self._steps} ({self._steps / self.fps:.2f} s)"}
            return self._observe(sim), 0.0, False, True, info
        self._task.after_step(sim.model, sim.data, self._steps / self.fps)
        state = sim.controller.measured_state(sim.data)
        if self._reach is not None:
            self._reach.update(sim.data, applied, state)
        evaluation = self._task.evaluate(sim.data)
        success = bool(evaluation["success"])
        if success and self._success_s is None:
            self._success_s = self._steps / self.fps
        truncated = self._steps >= self._max_episode_steps and not success
        conditions = {name: value for name, value in evaluation.items() if name != "success"}
        info = {"is_success": success, "applied_action": applied, "conditions": conditions,
                "reach": None if self._reach is None else self._reach.summary()}
        return self._observe(sim, state), float(success), success, truncated, info

    def render(self) -> np.ndarray:
        """A frame for people (the videos lerobot-eval writes): the third-person overview camera, rendered now,
        beside the last observation's camera images, with the prompt, the clock and success drawn on
        (`lerobot_tavis.overlay`). The overview is never part of an observation."""
        if self._last_frames is None:
            raise RuntimeError("render() needs an observation: call reset() first")
        if not self.camera_names:
            raise RuntimeError("this env renders no cameras (it was made with cameras=())")
        from lerobot_tavis import overlay  # OpenCV: only in a process that films

        sim = self._require_sim()
        overview = sim.rig.render_camera(sim.data, sim.world.cameras[OVERVIEW_CAMERA])
        events = overlay.EpisodeEvents(success=self._success_s)
        caption = overlay.Caption(self.task_description, self._steps / self.fps, self._max_episode_steps / self.fps,
                                  events)
        return overlay.compose(self._last_frames, overview, caption)

    def close(self) -> None:
        if self._sim is not None:
            self._sim.rig.close()
            self._sim = None
        self._last_frames = None

    @property
    def model(self) -> mujoco.MjModel:
        return self._require_sim().model

    @property
    def data(self) -> mujoco.MjData:
        return self._require_sim().data

    @property
    def world(self) -> World:
        return self._require_sim().world

    @property
    def controller(self) -> Controller:
        return self._require_sim().controller

    @property
    def task_object(self):
        """The simulating task (layout, prompt, success). Demonstrators read `episode_facts` instead."""
        return self._task

    @property
    def episode_facts(self) -> EpisodeFacts:
        """What the task tells its demonstrator about the current episode (`Task.episode_facts`, taken at reset)."""
        if self._facts is None:
            raise RuntimeError("episode facts exist from the first reset(): call reset() first")
        return self._facts

    def _ensure_sim(self) -> _Sim:
        if self._sim is None:
            world = build_world(self._robot, self._task, image_size=self.image_size, shadows=self.shadows,
                                visual_variation=bool(self._visual_factors))
            self._sim = _Sim(world, self.camera_mode, self.camera_names, self.image_size,
                             self._task.blacked_out_cameras)
        return self._sim

    def _require_sim(self) -> _Sim:
        if self._sim is None:
            raise RuntimeError("the simulator starts on the first reset(): call reset() first")
        return self._sim

    def _settle(self, sim: _Sim) -> None:
        """Hold the rest command until the task's props are still (at most SETTLE_MAX_S of simulated time)."""
        props = self._task.props()
        for tick in range(int(SETTLE_MAX_S * physics.CONTROL_HZ)):
            sim.advance_tick()
            if tick + 1 >= SETTLE_MIN_S * physics.CONTROL_HZ and all(
                    body_speed(sim.model, sim.data, p) < SETTLE_SPEED_M_S for p in props):
                break

    def _warm_up(self, sim: _Sim) -> None:
        """ood_init_pose (docs/reference.md §7): hold the rest action perturbed by Gaussian noise (0.10 m per hand
        axis, 0.175 rad on head pitch and yaw, drawn from the episode's generator) for 10 policy steps (0.5 s) before
        the first observation. As in the reference, they count toward the episode (a 20 s episode leaves 390 policy
        steps) and toward the task's clock (wait_then_act's light)."""
        action = warm_up_action(self.np_random)
        sim.controller.set_command(action)
        for _ in range(WARM_UP_STEPS * physics.TICKS_PER_STEP // self._ticks_per_step):
            for _ in range(self._ticks_per_step):
                sim.advance_tick()
            self._steps += 1
            self._task.after_step(sim.model, sim.data, self._steps / self.fps)

    def _track_reach(self, sim: _Sim) -> ReachTracker | None:
        if not isinstance(self._facts, TargetFacts):
            return None
        sites = {side: arm.grasp_site for side, arm in sim.world.arms.items()}
        others = tuple(sim.model.body(name).id for name in self._facts.props if name != self._facts.target)
        return ReachTracker(sim.data, sim.model.body(self._facts.target).id, sites, others)

    def _observe(self, sim: _Sim, state: np.ndarray | None = None) -> dict:
        """The observation of the current state; `state`, its canonical state when the caller has it already."""
        self._last_frames = sim.rig.render(sim.data)
        if state is None:
            state = sim.controller.measured_state(sim.data)
        return {
            "pixels": dict(self._last_frames),
            "agent_pos": state.astype(np.float32),
            "joint_pos": sim.data.qpos[sim.world.robot_joint_qpos].astype(np.float32),
        }


def scene_seed(seed: int, task: str) -> int:
    """The generator seed of episode `seed` (an integer >= 0) of `task`; a fractional, negative or boolean seed is
    refused, never rounded to another episode."""
    seed = checks.integer("seed", seed, 0)
    return int(np.random.SeedSequence([seed, zlib.crc32(task.encode())]).generate_state(1)[0])


def warm_up_action(rng: np.random.Generator) -> np.ndarray:
    """The perturbed rest action of the ood_init_pose warm-up (no clipping, as the reference)."""
    action = canonical.rest_action()
    for arm in canonical.ARMS:
        action[arm.position] += rng.normal(0.0, WARM_UP_POSITION_STD_M, size=3)
    action[[canonical.HEAD_PITCH, canonical.HEAD_YAW]] += rng.normal(0.0, WARM_UP_HEAD_STD_RAD, size=2)
    return action


def _check_cameras(cameras) -> tuple[str, ...]:
    cameras = tuple(cameras)
    known = CAMERA_NAMES + VIEW_CAMERAS
    if not set(cameras) <= set(known) or len(set(cameras)) != len(cameras):
        raise FieldError("cameras", f"must be distinct names among {known}, got {cameras!r}")
    return cameras


def _action_space(neck_range: np.ndarray) -> gym.spaces.Box:
    """Bounds of the canonical action: hand positions within HAND_REACH_M of the hip, unit quaternions, neck joint
    ranges (rad), grippers in [-1, 1]. Values outside are still accepted (see TavisEnv)."""
    return _canonical_box(neck_range[:, 0], neck_range[:, 1])


def _state_space() -> gym.spaces.Box:
    """Bounds of the measured canonical state: the action's, with the head angles within a half turn (rad) instead of
    the neck's ranges, which a joint may overshoot slightly under load."""
    return _canonical_box(-np.pi, np.pi)


def _canonical_box(head_low, head_high) -> gym.spaces.Box:
    low = np.full(canonical.ACTION_DIM, -1.0)
    high = np.full(canonical.ACTION_DIM, 1.0)
    for arm in canonical.ARMS:
        low[arm.position], high[arm.position] = -HAND_REACH_M, HAND_REACH_M
    low[canonical.HEAD], high[canonical.HEAD] = head_low, head_high
    return gym.spaces.Box(low.astype(np.float32), high.astype(np.float32), dtype=np.float32)
