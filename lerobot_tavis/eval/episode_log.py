"""One JSON line per finished episode: who, what, which seed, success, length and GALT.

The wrapper sits inside LeRobot's `FreezeAfterEpisodeEnd`, so it sees each genuine episode once. It records the
actions the env actually applied (after clipping, and with the neck zeroed in fixed-camera modes) and, when an
episode ends, computes GALT from them at the env's rate (20 Hz in evaluation) for successful episodes of
head-camera modes, as the reference does; the GALT fields are also added to that step's `info`. Successful
TAVIS-Hands episodes also get the wrist analogue of their final grasp (`wrist_lead_*`, any camera mode: it is
read from the hand's motion).
"""

from __future__ import annotations

import json
from pathlib import Path

import gymnasium as gym
import numpy as np

from lerobot_tavis.envs.modes import neck_locked
from lerobot_tavis.metrics.galt import compute_galt, wrist_lead_per_grasp

EPISODE_LOG_NAME = "episodes.jsonl"  # in the output directory of a lerobot-eval or lerobot-train run
GALT_FIELDS = ("galt_s", "galt_reason", "galt_arm", "galt_t_head_arrival_s", "galt_t_hand_arrival_s",
               "galt_t_hand_onset_s", "galt_arm_reach_s")
WRIST_FIELDS = ("wrist_lead_s", "wrist_lead_reason", "wrist_lead_arm")


def galt_fields(actions: np.ndarray | None, fps: float) -> dict:
    """GALT of an episode's applied actions as flat log fields (all None when not computed)."""
    if actions is None:
        return dict.fromkeys(GALT_FIELDS)
    result = compute_galt(actions, fps=fps)
    return {"galt_s": result.galt_s, "galt_reason": result.reason, "galt_arm": result.arm,
            "galt_t_head_arrival_s": result.t_head_arrival_s, "galt_t_hand_arrival_s": result.t_hand_arrival_s,
            "galt_t_hand_onset_s": result.t_hand_onset_s, "galt_arm_reach_s": result.arm_reach_s}


def wrist_fields(actions: np.ndarray | None, fps: float) -> dict:
    """The wrist analogue of an episode's final grasp as flat log fields (all None when not computed)."""
    leads = wrist_lead_per_grasp(actions, fps=fps) if actions is not None else []
    if not leads:
        return dict.fromkeys(WRIST_FIELDS)
    final = leads[-1]
    return {"wrist_lead_s": final.lead_s, "wrist_lead_reason": final.reason, "wrist_lead_arm": final.arm}


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
            record = self._record(bool(info["is_success"])) | {"instability": info.get("instability")}
            info = {**info, **{k: v for k, v in record.items() if k in GALT_FIELDS}}
            self._append(record)
        return obs, reward, terminated, truncated, info

    def _record(self, success: bool) -> dict:
        env = self.env.unwrapped
        actions = np.array(self._actions)
        with_galt = success and not neck_locked(env.camera_mode)
        with_wrist = success and self.suite == "tavis_hands"
        return {
            "robot": env.robot_name, "suite": self.suite, "task": env.task, "task_id": self.task_id,
            "split": env.split, "camera_mode": env.camera_mode, "seed": self._seed, "success": success,
            "length_steps": len(self._actions), "prompt": env.task_description,
            **galt_fields(actions if with_galt else None, env.fps),
            **wrist_fields(actions if with_wrist else None, env.fps),
        }

    def _append(self, record: dict) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        line = json.dumps(record) + "\n"
        with open(self.path, "a") as log:  # one small write per episode: workers may share the file
            log.write(line)
