"""`--env.type=tavis`: the LeRobot EnvConfig of the benchmark, and the factory of its sub-envs.

`task` is a suite (`tavis_head`, `tavis_hands`), a task name, or a comma list of either; `create_envs` returns
`{suite: {task_id: VectorEnv}}` whose sub-envs freeze once their episode ends, as LeRobot's own envs do
(`envs.vector`, whose async workers import neither torch nor LeRobot). Simulators are created in the worker
processes on their first reset. When there is an episode log, each finished episode
appends one JSON line with its seed, success and episode metrics (GALT, wrist lead) to it.

Where the log goes: `--env.episode_log=PATH` when given; else `<output_dir>/episodes.jsonl` when `--output_dir` is
on the command line (read with LeRobot's own `lerobot.configs.parser.parse_arg`), beside lerobot-eval's
`eval_info.json`; else nowhere, with a warning. LeRobot 0.6.1 offers the env no way to learn the run's output
directory: `make_env` calls `create_envs(n_envs, use_async_envs)` with the env config alone, and the default
`outputs/eval/<date>/<time>_<job>` is made later from the clock by the pipeline config.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field, fields
from functools import partial
from pathlib import Path

import gymnasium as gym
from lerobot.configs import parser
from lerobot.configs.types import FeatureType, PolicyFeature
from lerobot.envs.configs import EnvConfig

from lerobot_tavis import canonical, checks
from lerobot_tavis.envs.checkpoint_settings import SETTINGS, match_settings, read_checkpoint_settings
from lerobot_tavis.envs.modes import CAMERA_MODES, DEFAULT_CAMERA_MODE, resolve_camera_mode
from lerobot_tavis.envs.robots import DEFAULT_ROBOT, robot_info
from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS, SUITES, expand_tasks, parse_split, suite_tasks
from lerobot_tavis.envs.vector import Frozen, LazyAsyncVectorEnv
from lerobot_tavis.errors import FieldError
from lerobot_tavis.eval.env_factory import make_tavis_env
from lerobot_tavis.eval.episode_log import EPISODE_LOG_NAME
from lerobot_tavis.process import MAX_NICENESS

# The help of `--env.task`, written from the task registry (draccus reads other fields' help from their comments).
TASK_HELP = f"Suite ({', '.join(SUITES)}), task ({', '.join(BENCHMARK_TASKS)}) or a comma list of them"


@EnvConfig.register_subclass("tavis")
@dataclass
class TavisEnvConfig(EnvConfig):
    """The TAVIS benchmark in MuJoCo (lerobot_tavis): egocentric active vision tasks on a humanoid torso."""

    task: str = field(default="tavis_head", metadata={"custom_args": {"help": TASK_HELP}})
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
    # The key light casts shadows, as in the reference; false renders without them (a little faster, other images)
    shadows: bool = True
    # JSON-lines log of every finished episode (seed, success, GALT); default <output_dir>/episodes.jsonl when
    # --output_dir is on the command line, else none
    episode_log: str | None = None
    # Derived from camera_mode and image_size; not to be set
    features: dict[str, PolicyFeature] = field(default_factory=dict)
    # Derived from camera_mode; not to be set
    features_map: dict[str, str] = field(default_factory=dict)
    # Sub-envs of an async batch that draw video frames (lerobot-eval films at most 10 episodes of a batch, from its
    # first sub-envs); the others skip the overview render that filming costs
    filmed_envs: int = 10
    # Niceness added to each async env worker process (as `nice`, 0-19): a higher value lets the process that runs
    # the policy go first when the cores are contended; 0 keeps the workers at this process's priority
    worker_niceness: int = 0
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
            raise FieldError("fps", f"is fixed by the benchmark at 20, got {self.fps}")
        checks.episode_steps(self.episode_length_s, self.fps)
        checks.integer("filmed_envs", self.filmed_envs, 0)
        checks.integer("worker_niceness", self.worker_niceness, 0, MAX_NICENESS)
        self._derive_features()

    def _derive_features(self) -> None:
        """`features` and `features_map` from `camera_mode` and `image_size`."""
        height, width = checks.image_size(self.image_size)
        self.features = {"action": PolicyFeature(FeatureType.ACTION, (canonical.ACTION_DIM,)),
                         "agent_pos": PolicyFeature(FeatureType.STATE, (canonical.ACTION_DIM,))}
        self.features_map = {"action": "action", "agent_pos": "observation.state"}
        for camera in CAMERA_MODES[self.camera_mode]:
            self.features[f"pixels/{camera}"] = PolicyFeature(FeatureType.VISUAL, (height, width, 3))
            self.features_map[f"pixels/{camera}"] = f"observation.images.{camera}"

    @property
    def gym_kwargs(self) -> dict:
        return {"robot": self.robot, "camera_mode": self.camera_mode, "split": self.split,
                "image_size": tuple(self.image_size), "episode_length_s": self.episode_length_s,
                "shadows": self.shadows}

    def sub_env_factories(self) -> dict[str, dict[int, partial]]:
        """One sub-env factory per task of `task`, by suite and the task's index in its whole suite (so a run of
        some tasks files each one's videos and results under the `<suite>_<index>` of a whole suite's run): what
        `create_envs` batches."""
        log = self.episode_log or command_line_episode_log()
        factories: dict[str, dict[int, partial]] = {}
        for suite, tasks in expand_tasks(self.task).items():
            factories[suite] = {}
            for task in tasks:
                task_id = suite_tasks(suite).index(task)
                factories[suite][task_id] = partial(make_tavis_env, task, episode_log=str(log) if log else None,
                                                    suite=suite, task_id=task_id, **self.gym_kwargs)
        return factories

    def match_command_line_policy(self, args: list[str] | None = None) -> None:
        """Match robot, camera mode and image size to the checkpoint of `--policy.path` on the command line (default:
        sys.argv; lerobot-eval's, or lerobot-train's when it fine-tunes one), as `checkpoint_settings.match_settings`
        does: a setting left at its default and off the command line takes the checkpoint's (logged), a difference
        from one the user gave is logged as a warning, a camera the policy reads and the camera mode does not render
        is refused. LeRobot 0.6.1 passes `create_envs` the env config alone: the command line is where the policy
        can be seen."""
        policy_path = parser.get_path_arg("policy", args)
        if not policy_path:
            return
        checkpoint = read_checkpoint_settings(policy_path, download=True)
        defaults = {item.name: item.default for item in fields(self) if item.name in SETTINGS}
        current = {name: tuple(value) if name == "image_size" else value
                   for name, value in ((name, getattr(self, name)) for name in SETTINGS)}
        given = {name: value for name, value in current.items()
                 if value != defaults[name] or parser.parse_arg(f"env.{name}", args) is not None}
        settings, warnings = match_settings(checkpoint, given, defaults, spell=lambda name: f"--env.{name}")
        log = logging.getLogger(__name__)
        for warning in warnings:
            log.warning("tavis: %s", warning)
        taken = {name: value for name, value in settings.items() if name not in given and value != current[name]}
        if taken:
            log.info("tavis: the env takes the checkpoint's %s",
                     ", ".join(f"{name} {'x'.join(map(str, value)) if name == 'image_size' else value}"
                               for name, value in taken.items()))
        self.robot, self.camera_mode, self.image_size = (settings[name] for name in SETTINGS)
        self._derive_features()

    def create_envs(self, n_envs: int, use_async_envs: bool = False) -> dict[str, dict[int, gym.vector.VectorEnv]]:
        self.match_command_line_policy()
        envs: dict[str, dict[int, gym.vector.VectorEnv]] = {}
        for suite, factories in self.sub_env_factories().items():
            envs[suite] = {}
            for task_id, factory in factories.items():
                if use_async_envs and n_envs > 1:
                    probe = factory(episode_log=None)  # spaces only: builds no simulator, logs nothing
                    envs[suite][task_id] = LazyAsyncVectorEnv([factory] * n_envs, probe.observation_space,
                                                              probe.action_space, probe.metadata,
                                                              filmed_envs=self.filmed_envs,
                                                              worker_niceness=self.worker_niceness)
                else:
                    envs[suite][task_id] = gym.vector.SyncVectorEnv(
                        [Frozen(factory)] * n_envs,
                        autoreset_mode=gym.vector.AutoresetMode.NEXT_STEP)
        return envs


def command_line_episode_log(args: list[str] | None = None) -> Path | None:
    """`<output_dir>/episodes.jsonl` for the `--output_dir` on the command line (default: sys.argv), else None.

    LeRobot passes only the env config to `create_envs`, and no hook of 0.6.1 tells an env its run's output
    directory; an explicit `--output_dir` is the one place it can be read. Without one, LeRobot invents a
    timestamped directory the env cannot see, so no log is written and a warning says how to get one.
    """
    output_dir = parser.parse_arg("output_dir", args)
    if output_dir:
        return Path(output_dir) / EPISODE_LOG_NAME
    logging.getLogger(__name__).warning(
        "tavis: no episode log (no --env.episode_log and no --output_dir on the command line); `tavis report` "
        "needs one beside eval_info.json: pass --output_dir=DIR or --env.episode_log=DIR/%s", EPISODE_LOG_NAME)
    return None
