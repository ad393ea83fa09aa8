"""`tavis demo`: one scripted-demonstrator episode of every task on each robot, filmed by all four cameras.

Writes `<out>/<robot>/<task>.mp4` with the head, fixed and wrist views side by side (the head view is black in
blocked_clutter_pick_cube, as the policy sees it) and prints whether each episode succeeded.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from tqdm import tqdm

from lerobot_tavis import checks
from lerobot_tavis.envs.env import TavisEnv
from lerobot_tavis.envs.modes import CAMERA_NAMES
from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS
from lerobot_tavis.experts.registry import make_expert
from lerobot_tavis.media import side_by_side, write_mp4

FPS = 20
TASKS = BENCHMARK_TASKS


def film_episode(task: str, robot: str, image_size: tuple[int, int], seed: int) -> tuple[list[np.ndarray], bool]:
    """Frames (four labelled views side by side) of one demonstrator episode, and whether it succeeded."""
    env = TavisEnv(task, robot, camera_mode="head_wrist", image_size=image_size, cameras=CAMERA_NAMES)
    obs, _ = env.reset(seed=seed)
    expert = make_expert(env, seed)
    expert.reset()
    frames, success = [side_by_side(obs["pixels"])], False
    for _ in range(env._max_episode_steps):
        obs, _, terminated, truncated, info = env.step(expert.act())
        frames.append(side_by_side(obs["pixels"]))
        success = info["is_success"]
        if terminated or truncated:
            break
    frames += frames[-1:] * FPS  # one more second on the final frame
    env.close()
    return frames, success


def run_demo(out_dir: str | Path, robots=("gr1t2", "reachy2"), tasks=TASKS, image_size=(240, 320),
             seed: int = 0) -> list[Path]:
    checks.integer("seed", seed, 0)
    out_dir = Path(out_dir)
    written = []
    for robot in robots:
        for task in tqdm(tasks, desc=f"demo {robot}", unit="task"):
            frames, success = film_episode(task, robot, image_size, seed)
            written.append(write_mp4(out_dir / robot / f"{task}.mp4", frames, FPS))
            tqdm.write(f"{robot} {task}: {'success' if success else 'failure'} in {len(frames) - 1 - FPS} steps")
    return written
