"""Normalisation statistics of hand-frame action chunks, computed from a LeRobotDataset's data files."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from lerobot_tavis import canonical
from lerobot_tavis.dataset_tools.features import STATE_KEY
from lerobot_tavis.errors import InputError
from lerobot_tavis.policies.hand_frame import to_hand_frame


def hand_frame_statistics(root: str | Path, chunk_size: int) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard deviation (19,) of every action a training chunk holds, in the hand frame of the chunk's
    first state: for each frame t of each episode, actions t..t+chunk_size-1 that lie inside the episode (those past
    its end are padding, which ACT's loss ignores)."""
    episodes = _episodes(Path(root))
    total = np.zeros(canonical.ACTION_DIM)
    total_squares = np.zeros(canonical.ACTION_DIM)
    count = 0
    for actions, states in episodes:
        actions, states = torch.from_numpy(actions), torch.from_numpy(states)
        for offset in range(min(chunk_size, len(actions))):
            relative = to_hand_frame(actions[offset:].unsqueeze(-2), states[:len(actions) - offset])[:, 0].numpy()
            total += relative.sum(axis=0)
            total_squares += np.square(relative).sum(axis=0)
            count += len(relative)
    mean = total / count
    return mean, np.sqrt(np.maximum(total_squares / count - np.square(mean), 0.0))


def _episodes(root: Path) -> list[tuple[np.ndarray, np.ndarray]]:
    """Each episode's actions and states (T, 19) in frame order, float64."""
    import pyarrow.parquet as pq

    paths = sorted((root / "data").rglob("*.parquet"))
    if not paths:
        raise InputError(f"{root}: no data files under data/ to compute act_hand_relative's statistics from")
    columns = ("episode_index", "frame_index", "action", STATE_KEY)
    tables = [pq.read_table(path, columns=list(columns)) for path in paths]
    episode = np.concatenate([table.column("episode_index").to_numpy() for table in tables])
    frame = np.concatenate([table.column("frame_index").to_numpy() for table in tables])
    vectors = {key: np.concatenate([_vectors(table, key) for table in tables]) for key in ("action", STATE_KEY)}
    order = np.lexsort((frame, episode))
    starts = np.flatnonzero(np.diff(episode[order])) + 1
    return list(zip(np.split(vectors["action"][order], starts), np.split(vectors[STATE_KEY][order], starts)))


def _vectors(table, key: str) -> np.ndarray:
    return table.column(key).combine_chunks().flatten().to_numpy().reshape(-1, canonical.ACTION_DIM).astype(np.float64)
