"""One sub-env of `--env.type=tavis`: the TavisEnv, wrapped by the episode log when there is one.

LeRobot's async vector envs and `tavis eval --expert` call `make_tavis_env` in worker processes, which import this
module by name: it must import neither LeRobot nor torch (the env config that refers to it does).
"""

from __future__ import annotations

import gymnasium as gym

from lerobot_tavis.eval.episode_log import EpisodeLogger


def make_tavis_env(task: str, robot: str, camera_mode: str, split: str, image_size: tuple[int, int],
                   episode_length_s: float, episode_log: str | None = None, suite: str = "",
                   task_id: int = 0, cameras: tuple[str, ...] | None = None, shadows: bool = True) -> gym.Env:
    """One sub-env (picklable through functools.partial for forkserver workers). In a worker process it also
    binds the worker's life to its parent's, so an env worker never outlives a killed lerobot-eval or tavis eval."""
    from lerobot_tavis.envs.env import TavisEnv  # imports MuJoCo: only in the process that simulates
    from lerobot_tavis.process import bind_worker_to_parent

    bind_worker_to_parent()

    env = TavisEnv(task, robot, camera_mode=camera_mode, split=split, image_size=tuple(image_size),
                   episode_length_s=episode_length_s, cameras=cameras, shadows=shadows)
    if episode_log:
        env = EpisodeLogger(env, episode_log, suite=suite, task_id=task_id)
    return env
