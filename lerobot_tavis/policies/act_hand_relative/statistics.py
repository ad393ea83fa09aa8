"""Normalisation statistics of hand-frame action chunks, computed from a LeRobotDataset's data files."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from lerobot_tavis import canonical
from lerobot_tavis.dataset_tools.features import ACTION_KEY, STATE_KEY
from lerobot_tavis.dataset_tools.frames import column_array, episode_frames
from lerobot_tavis.policies.hand_frame import to_hand_frame


def hand_frame_statistics(root: str | Path, chunk_size: int) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard deviation (19,) of every action a training chunk holds, in the hand frame of the chunk's
    first state: for each frame t of each episode, actions t..t+chunk_size-1 that lie inside the episode (those past
    its end are padding, which ACT's loss ignores)."""
    total = np.zeros(canonical.ACTION_DIM)
    total_squares = np.zeros(canonical.ACTION_DIM)
    count = 0
    for rows in episode_frames(root, columns=(ACTION_KEY, STATE_KEY)).values():
        actions, states = (torch.from_numpy(column_array(rows, key).astype(np.float64))
                           for key in (ACTION_KEY, STATE_KEY))
        for offset in range(min(chunk_size, len(actions))):
            relative = to_hand_frame(actions[offset:].unsqueeze(-2), states[:len(actions) - offset])[:, 0].numpy()
            total += relative.sum(axis=0)
            total_squares += np.square(relative).sum(axis=0)
            count += len(relative)
    mean = total / count
    return mean, np.sqrt(np.maximum(total_squares / count - np.square(mean), 0.0))
