"""`tavis demo`: one scripted-demonstrator episode of every task on each robot, filmed by all four cameras.

Writes `<out>/<robot>/<task>.mp4`: the overview camera beside the head, fixed and wrist views (the head view is
black in blocked_clutter_pick_cube, as the policy sees it), with the prompt, the clock, success and the gaze and
hand events GALT finds in the episode (`lerobot_tavis.overlay`), and prints whether each episode succeeded.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from lerobot_tavis import checks
from lerobot_tavis.cli_options import option
from lerobot_tavis.envs.env import TavisEnv
from lerobot_tavis.envs.modes import CAMERA_NAMES
from lerobot_tavis.envs.robots import robot_names
from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS, task_info
from lerobot_tavis.experts.rollout import make_expert
from lerobot_tavis.media import write_mp4
from lerobot_tavis.metrics.galt import compute_galt
from lerobot_tavis.overlay import Caption, EpisodeEvents, redraw_caption

FPS = 20


def film_episode(task: str, robot: str, image_size: tuple[int, int], seed: int) -> tuple[list[np.ndarray], bool]:
    """Annotated frames of one demonstrator episode, and whether it succeeded."""
    env = TavisEnv(task, robot, camera_mode="head_wrist", image_size=image_size, cameras=CAMERA_NAMES)
    env.reset(seed=seed)
    expert = make_expert(env, seed)
    expert.reset()
    frames, actions, success = [env.render()], [], False
    for _ in range(env._max_episode_steps):
        _, _, terminated, truncated, info = env.step(expert.act())
        frames.append(env.render())
        actions.append(info["applied_action"])
        success = info["is_success"]
        if terminated or truncated:
            break
    duration_s = len(actions) / env.fps
    galt = compute_galt(np.array(actions), fps=env.fps)
    events = EpisodeEvents(gaze=galt.t_head_arrival_s, reach=galt.t_hand_onset_s, grasp=galt.t_hand_arrival_s,
                           success=duration_s if success else None)
    frames = [redraw_caption(frame, Caption(env.task_description, step / env.fps, duration_s, events))
              for step, frame in enumerate(frames)]
    frames += frames[-1:] * FPS  # one more second on the final frame
    env.close()
    return frames, success


@dataclass(frozen=True)
class DemoConfig:
    """What `tavis demo` films, and where; also its command-line options."""

    out_dir: Path = option(Path("outputs/demo"), "output directory (default: outputs/demo)", flag="--out")
    robots: tuple[str, ...] = option(default_factory=lambda: tuple(robot_names()), choices=robot_names)
    tasks: tuple[str, ...] = option(BENCHMARK_TASKS, "task names (default: the eight TAVIS tasks)")
    image_size: tuple[int, int] = option((240, 320), "HxW of every camera (default 240x320)",
                                         parse=checks.image_size_text)
    seed: int = 0

    def __post_init__(self):
        checks.integer("seed", self.seed, 0)
        for task in self.tasks:
            task_info(task, "tasks")


def run_demo(cfg: DemoConfig) -> list[Path]:
    """Film every task of `cfg.tasks` on every robot of `cfg.robots`."""
    written = []
    for robot in cfg.robots:
        for task in tqdm(cfg.tasks, desc=f"demo {robot}", unit="task"):
            frames, success = film_episode(task, robot, cfg.image_size, cfg.seed)
            written.append(write_mp4(Path(cfg.out_dir) / robot / f"{task}.mp4", frames, FPS))
            tqdm.write(f"{robot} {task}: {'success' if success else 'failure'} in {len(frames) - 1 - FPS} steps")
    return written
