"""One JSON line per finished episode: who, what, which seed, success, length, success conditions and every episode
metric.

The wrapper sits inside `envs.vector.FreezeAfterEpisodeEnd`, so it sees each genuine episode once. It records the
actions the env actually applied (after clipping, and with the neck zeroed in fixed-camera modes) and, when an
episode ends, writes the fields of every metric of `lerobot_tavis.metrics.logged_metrics`, in its order, computed from
them at the env's rate (20 Hz in evaluation): GALT for successful episodes of head-camera modes, as the reference
does, and the wrist lead of the final grasp for successful TAVIS-Hands episodes. The metric fields are also added
to that step's `info`. Before them, `conditions` holds the final step's `info["conditions"]`: the parts of the
task's success rule (`Task.evaluate`), and `reach` its `info["reach"]`: how near a hand came to the task's target
and how far the target moved over the episode, and how far off its centre the first grasp of it closed
(`lerobot_tavis.envs.reach`); each is null when the env gave none
(an episode ended by an instability; `reach` also for a task without a target).
"""

from __future__ import annotations

import json
from pathlib import Path

import gymnasium as gym
import numpy as np

from lerobot_tavis.metrics.episode_metric import Episode
from lerobot_tavis.metrics.logged_metrics import episode_metrics

EPISODE_LOG_NAME = "episodes.jsonl"  # the episode log's file name in an evaluation's output directory


def metric_fields(episode: Episode) -> dict:
    """The log fields of every registered metric for one episode, in registry order."""
    return {name: value for metric in episode_metrics() for name, value in metric.log_fields(episode).items()}


class EpisodeLogger(gym.Wrapper):
    def __init__(self, env: gym.Env, path: str | Path, suite: str, task_id: int):
        super().__init__(env)
        self.path = Path(path)
        self.suite = suite
        self.task_id = task_id
        self._actions: list[np.ndarray] = []
        self._seed: int | None = None

    def reset(self, *, seed=None, options=None):
        self._actions, self._seed = [], seed
        return self.env.reset(seed=seed, options=options)

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        self._actions.append(info["applied_action"])
        if terminated or truncated:
            success = bool(info["is_success"])
            metrics = self._metrics(success)
            outcome = {"conditions": info.get("conditions"), "reach": info.get("reach")}
            self._append(self._record(success) | outcome | metrics | {"instability": info.get("instability")})
            info = {**info, **metrics}
        return obs, reward, terminated, truncated, info

    def _record(self, success: bool) -> dict:
        env = self.env.unwrapped
        return {
            "robot": env.robot_name, "suite": self.suite, "task": env.task, "task_id": self.task_id,
            "split": env.split, "camera_mode": env.camera_mode, "shadows": env.shadows, "seed": self._seed,
            "success": success,
            "length_steps": len(self._actions), "prompt": env.task_description,
        }

    def _metrics(self, success: bool) -> dict:
        env = self.env.unwrapped
        return metric_fields(Episode(np.array(self._actions), env.fps, success, self.suite, env.camera_mode))

    def _append(self, record: dict) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        line = json.dumps(record) + "\n"
        with open(self.path, "a") as log:  # one small write per episode: workers may share the file
            log.write(line)
