"""`tavis verify-dataset`: replay a converted dataset's actions and check they reproduce its recorded states.

Each checked episode is replayed open loop in a `TavisEnv` at the dataset's rate, from the seed its conversion log
names: at every frame the env's measured hand positions are compared with the frame's `observation.state`, then
the frame's `action` is applied. A dataset whose actions are shifted against its states, whose states come from
another scene, or whose state or action columns are mislabelled drifts far beyond the tolerance. Demonstrations
end at the frame where success fires, and an open-loop replay that holds each 60 Hz action for a whole frame runs a
few millimetres behind, so the last action is held for `hold_s` more before success is judged.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lerobot_tavis import canonical
from lerobot_tavis.dataset_tools import features as ft
from lerobot_tavis.dataset_tools.convert import CONVERSION_LOG
from lerobot_tavis.dataset_tools.frames import (INFO, check_camera_frames, check_files, column_array, dataset_info,
                                                episode_frames)
from lerobot_tavis.envs.robots import robot_info
from lerobot_tavis.envs.tasks.catalog import parse_split, task_info
from lerobot_tavis.errors import InputError, TavisError
from lerobot_tavis.readers import checked, expect, get, get_integer, read_json

TOLERANCE_M = 0.015  # a faithful 20 Hz replay of a 60 Hz recording keeps its hands this close (docs/datasets.md)
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
    (the check's own test: a shift of one frame must fail). Every metadata and data file is read and every camera
    frame of the chosen episodes decoded first: a damaged file is an InputError naming it (and the frame)."""
    root = Path(root)
    log_path = root / CONVERSION_LOG
    if not log_path.is_file():
        raise TavisError(f"{root}: no {CONVERSION_LOG}; only datasets written by `tavis convert` can be replayed")
    check_files(root)
    info = dataset_info(root)
    robot = checked(robot_info, info.get("robot_type"), root / INFO, "robot_type").name
    log, zero_neck = _conversion_log(log_path)
    chosen = sorted(log) if episodes is None else list(episodes)
    unknown = [index for index in chosen if index not in log]
    if unknown:
        raise TavisError(f"{root}: no episodes {unknown}; it holds 0..{len(log) - 1}")
    frames = episode_frames(root)
    absent = [index for index in chosen if index not in frames]
    if absent:
        raise InputError(f"{root / 'data'}: no frames of episodes {absent}, which {CONVERSION_LOG} lists")
    columns = {index: _episode_columns(frames[index], index) for index in chosen}
    check_camera_frames(root, info, {index: frames[index] for index in chosen})
    return [_replay(robot, info["fps"], log[index], columns[index], zero_neck, hold_s, action_shift)
            for index in chosen]


def _conversion_log(path: Path) -> tuple[dict[int, dict], bool]:
    """The conversion log's episodes by index ({episode_index, task, seed}) and its zero_neck setting."""
    log = read_json(path)
    expect(log, "object", path, "the log")
    entries = {}
    for i, entry in enumerate(get(log, "episodes", "list", path)):
        where = f"episodes[{i}]."
        expect(entry, "object", path, where.rstrip("."))
        index = get_integer(entry, "episode_index", path, where)
        task = checked(task_info, get(entry, "task", "str", path, where), path, f"{where}task").name
        entries[index] = {"episode_index": index, "task": task, "seed": get_integer(entry, "seed", path, where)}
    return entries, bool(get(log, "zero_neck", "bool", path, optional=True))


def _episode_columns(rows, index: int) -> dict[str, np.ndarray | str]:
    """An episode's frames' state and action (frames, 19), finite, and its split."""
    where = f"{rows['data_file'].iloc[0]}: episode {index}"
    columns = {}
    for key in (ft.STATE_KEY, ft.ACTION_KEY):
        try:
            values = column_array(rows, key).astype(np.float64)
        except (KeyError, ValueError, TypeError):
            values = None
        if values is None or values.shape != (len(rows), canonical.ACTION_DIM) or not np.isfinite(values).all():
            raise InputError(f"{where}: {key} must be {canonical.ACTION_DIM} finite numbers per frame")
        columns[key] = values
    split = expect(rows[ft.SPLIT_KEY].iloc[0] if ft.SPLIT_KEY in rows else None, "str", where, ft.SPLIT_KEY)
    checked(parse_split, split, where, ft.SPLIT_KEY)
    return {"state": columns[ft.STATE_KEY], "action": columns[ft.ACTION_KEY], "split": split}


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
