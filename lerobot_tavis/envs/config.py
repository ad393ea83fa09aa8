"""`--env.type=tavis`: the LeRobot EnvConfig of the benchmark, and the factory of its sub-envs.

`task` is a suite (`tavis_head`, `tavis_hands`), a task name, or a comma list of either; `create_envs` returns
`{suite: {task_id: VectorEnv}}` with every sub-env wrapped by LeRobot's `freeze_after_episode_end`. Simulators
are created in the worker processes on their first reset. When an episode log is configured (by default
`episodes.jsonl` in the output directory of the running lerobot-eval / lerobot-train), each finished episode
appends one JSON line with its seed, success and GALT.
"""

from __future__ import annotations

import inspect
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path

import gymnasium as gym
from lerobot.configs.types import FeatureType, PolicyFeature
from lerobot.envs.configs import EnvConfig
from lerobot.envs.utils import _LazyAsyncVectorEnv, freeze_after_episode_end

from lerobot_tavis import canonical, checks
from lerobot_tavis.envs.factory import make_tavis_env
from lerobot_tavis.envs.modes import CAMERA_MODES, DEFAULT_CAMERA_MODE, resolve_camera_mode
from lerobot_tavis.envs.robots import DEFAULT_ROBOT, robot_info
from lerobot_tavis.envs.tasks.catalog import expand_tasks, parse_split
from lerobot_tavis.eval.episode_log import EPISODE_LOG_NAME


@EnvConfig.register_subclass("tavis")
@dataclass
class TavisEnvConfig(EnvConfig):
    """The TAVIS benchmark in MuJoCo (lerobot_tavis): egocentric active vision tasks on a humanoid torso."""

    # Suite (tavis_head, tavis_hands), task (conditional_pick, wait_then_act, clutter_pick_cube, clutter_pick_lift,
    # multi_shelf_scan, peeking_box, occluded_reach, blocked_clutter_pick_cube) or a comma list of them
    task: str = "tavis_head"
    # Policy steps per second; fixed by the benchmark at 20
    fps: int = 20
    # Robot: gr1t2 or reachy2
    robot: str = DEFAULT_ROBOT
    # Cameras the policy sees: head_wrist (the paper's "headcam": head and both wrists), fixed_wrist (its
    # "fixedcam": fixed workspace camera and both wrists), head_only, fixed_only
    camera_mode: str = DEFAULT_CAMERA_MODE
    # Episode distribution: id, ood_spatial (wider zones, closer objects), ood_init_pose (the id scene from a
    # perturbed hand and head start) or ood_visual (the id scene with another table, floor, backdrop, lighting and
    # distractors; ood_visual:table, :floor, :backdrop, :lighting or :distractors for one factor alone)
    split: str = "id"
    # Camera images as height width, pixels (16-4096 each); the cameras' native size is 480 640
    image_size: tuple[int, int] = (480, 640)
    # Episode length in seconds (400 steps at 20 Hz by default)
    episode_length_s: float = 20.0
    # JSON-lines log of every finished episode (seed, success, GALT); default <output_dir>/episodes.jsonl
    episode_log: str | None = None
    # Derived from camera_mode and image_size; not to be set
    features: dict[str, PolicyFeature] = field(default_factory=dict)
    # Derived from camera_mode; not to be set
    features_map: dict[str, str] = field(default_factory=dict)
    # Tasks of a suite that lerobot-eval runs at once (threads)
    max_parallel_tasks: int = 1
    # Skip gymnasium's env checker
    disable_env_checker: bool = True

    def __post_init__(self):
        expand_tasks(self.task)  # raises a clear error for an unknown task or suite
        robot_info(self.robot)  # raises a clear error for an unknown robot
        self.camera_mode = resolve_camera_mode(self.camera_mode)
        parse_split(self.split)  # raises a clear error for an unknown split or ood_visual factor
        if self.fps != 20:
            raise ValueError(f"fps is fixed by the benchmark at 20, got {self.fps}")
        height, width = checks.image_size(self.image_size)
        checks.episode_steps(self.episode_length_s, self.fps)
        self.features = {"action": PolicyFeature(FeatureType.ACTION, (canonical.ACTION_DIM,)),
                         "agent_pos": PolicyFeature(FeatureType.STATE, (canonical.ACTION_DIM,))}
        self.features_map = {"action": "action", "agent_pos": "observation.state"}
        for camera in CAMERA_MODES[self.camera_mode]:
            self.features[f"pixels/{camera}"] = PolicyFeature(FeatureType.VISUAL, (height, width, 3))
            self.features_map[f"pixels/{camera}"] = f"observation.images.{camera}"

    @property
    def gym_kwargs(self) -> dict:
        return {"robot": self.robot, "camera_mode": self.camera_mode, "split": self.split,
                "image_size": tuple(self.image_size), "episode_length_s": self.episode_length_s}

    def create_envs(self, n_envs: int, use_async_envs: bool = False) -> dict[str, dict[int, gym.vector.VectorEnv]]:
        log = self.episode_log or _pipeline_episode_log()
        envs: dict[str, dict[int, gym.vector.VectorEnv]] = {}
        for suite, tasks in expand_tasks(self.task).items():
            envs[suite] = {}
            for task_id, task in enumerate(tasks):
                factory = partial(make_tavis_env, task, episode_log=str(log) if log else None, suite=suite,
                                  task_id=task_id, **self.gym_kwargs)
                if use_async_envs and n_envs > 1:
                    probe = factory.func(task, **self.gym_kwargs)  # spaces only: builds no simulator
                    envs[suite][task_id] = _LazyAsyncVectorEnv([factory] * n_envs, probe.observation_space,
                                                               probe.action_space, probe.metadata)
                else:
                    envs[suite][task_id] = gym.vector.SyncVectorEnv(
                        [freeze_after_episode_end(factory)] * n_envs,
                        autoreset_mode=gym.vector.AutoresetMode.NEXT_STEP)
        return envs


def _pipeline_episode_log() -> Path | None:
    """`<output_dir>/episodes.jsonl` of the lerobot-eval or lerobot-train run that is creating the envs.

    LeRobot passes only the env config to `create_envs`, so the pipeline config (`cfg`, with its resolved
    `output_dir`) is looked up in the calling frames.
    """
    frame = inspect.currentframe()
    while frame is not None:
        output_dir = getattr(frame.f_locals.get("cfg"), "output_dir", None)
        if output_dir:
            return Path(output_dir) / EPISODE_LOG_NAME
        frame = frame.f_back
    return None
