"""`tavis verify-dataset`: replay a converted dataset's actions and check they reproduce its recorded states.

Each checked episode is replayed open loop in a `TavisEnv` at the dataset's rate, from the seed its conversion log
names: at every frame the env's measured hand positions are compared with the frame's `observation.state`, then
the frame's `action` is applied. A dataset whose actions are shifted against its states, whose states come from
another scene, or whose state or action columns are mislabelled drifts far beyond the tolerance. Demonstrations
end at the frame where success fires, and an open-loop replay that holds each 60 Hz action for a whole frame runs a
few millimetres behind, so the last action is held for `hold_s` more before success is judged.
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lerobot_tavis import canonical
from lerobot_tavis.dataset_tools import features as ft
from lerobot_tavis.dataset_tools.convert import CONVERSION_LOG
from lerobot_tavis.dataset_tools.frames import column_array, episode_frames
from lerobot_tavis.errors import TavisError

TOLERANCE_M = 0.015  # replayed hands stay within 1.3 cm of a 60 Hz recording at 20 Hz (measured, 20 episodes)
HOLD_S = 1.0


@dataclass(frozen=True)
class EpisodeCheck:
    episode_index: int
    task: str
    seed: int
    max_hand_error_m: float  # largest distance between a replayed and a recorded hand position
    success: bool  # the replay succeeded, the last action held HOLD_S past the last frame

    @property
    def passed(self) -> bool:
        return self.max_hand_error_m <= TOLERANCE_M and self.success


def verify_dataset(root: Path, episodes: Sequence[int] | None = None, hold_s: float = HOLD_S,
                   action_shift: int = 0) -> list[EpisodeCheck]:
    """Replay `episodes` (default: all) of the dataset at `root`; `action_shift` frames misalign actions on purpose
    (the check's own test: a shift of one frame must fail)."""
    from lerobot.datasets.lerobot_dataset import LeRobotDatasetMetadata

    log_path = Path(root) / CONVERSION_LOG
    if not log_path.is_file():
        raise TavisError(f"{root}: no {CONVERSION_LOG}; only datasets written by `tavis convert` can be replayed")
    conversion = json.loads(log_path.read_text())
    log = {entry["episode_index"]: entry for entry in conversion["episodes"]}
    meta = LeRobotDatasetMetadata("local/verify", root=root)
    chosen = sorted(log) if episodes is None else list(episodes)
    unknown = [index for index in chosen if index not in log]
    if unknown:
        raise TavisError(f"{root}: no episodes {unknown}; it holds 0..{len(log) - 1}")
    zero_neck = conversion.get("zero_neck", False)
    columns = _episode_columns(root)
    return [_replay(meta.robot_type, meta.fps, log[index], columns[index], zero_neck, hold_s, action_shift)
            for index in chosen]


def _episode_columns(root: Path) -> dict[int, dict[str, np.ndarray]]:
    """Per episode index: its frames' state, action and split, in frame order."""
    return {index: {"state": column_array(rows, ft.STATE_KEY), "action": column_array(rows, ft.ACTION_KEY),
                    "split": str(rows[ft.SPLIT_KEY].iloc[0])}
            for index, rows in episode_frames(root).items()}


def _replay(robot: str, fps: int, entry: dict, columns: dict, zero_neck: bool, hold_s: float,
            action_shift: int) -> EpisodeCheck:
    os.environ.setdefault("MUJOCO_GL", "egl")
    from lerobot_tavis.envs.env import TavisEnv

    states, actions = columns["state"], np.roll(columns["action"], action_shift, axis=0)
    env = TavisEnv(entry["task"], robot, camera_mode="fixed_only" if zero_neck else "head_only",
                   split=columns["split"], fps=fps, cameras=(), episode_length_s=len(actions) / fps + hold_s + 1)
    try:
        obs, _ = env.reset(seed=entry["seed"])
        error, success = 0.0, False
        for state, action in zip(states, actions):
            error = max(error, _hand_error(obs["agent_pos"], state))
            obs, _, success, _, _ = env.step(action)  # terminated == succeeded
            if success:
                break
        else:
            for _ in range(int(round(hold_s * fps))):
                _, _, success, _, _ = env.step(actions[-1])
                if success:
                    break
    finally:
        env.close()
    return EpisodeCheck(entry["episode_index"], entry["task"], entry["seed"], error, bool(success))


def _hand_error(measured: np.ndarray, recorded: np.ndarray) -> float:
    """Largest distance (m) between the measured and the recorded hand positions, over both hands."""
    return max(float(np.linalg.norm(measured[arm.position] - recorded[arm.position])) for arm in canonical.ARMS)
