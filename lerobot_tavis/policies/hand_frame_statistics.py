"""Normalisation statistics of hand-frame action chunks, computed from a LeRobotDataset's data files."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import numpy as np
import torch

from lerobot_tavis import canonical
from lerobot_tavis.dataset_tools.features import ACTION_KEY, STATE_KEY
from lerobot_tavis.dataset_tools.frames import column_array, episode_frames
from lerobot_tavis.policies.hand_frame import to_hand_frame


def hand_frame_statistics(root: str | Path, offsets: Iterable[int]) -> dict[str, np.ndarray]:
    """Mean, std, min and max (19,) (LeRobot's statistics keys) of every action a training chunk holds, in the hand
    frame of the state the chunk is anchored on: for each frame t of each episode, the actions t+k for k in `offsets`
    (ACT: 0..chunk_size-1; Diffusion Policy: 1-n_obs_steps..horizon-n_obs_steps) that lie inside the episode. Those
    outside are padding: ACT's loss ignores it, and LeRobot pads with the episode's first or last action, whose
    hand-frame value is one of the counted ones (same action, same anchor), so min and max hold it too."""
    total = np.zeros(canonical.ACTION_DIM)
    total_squares = np.zeros(canonical.ACTION_DIM)
    low = np.full(canonical.ACTION_DIM, np.inf)
    high = np.full(canonical.ACTION_DIM, -np.inf)
    count = 0
    offsets = tuple(offsets)
    for rows in episode_frames(root, columns=(ACTION_KEY, STATE_KEY)).values():
        actions, states = (torch.from_numpy(column_array(rows, key).astype(np.float64))
                           for key in (ACTION_KEY, STATE_KEY))
        length = len(actions)
        for offset in offsets:
            anchors = range(max(0, -offset), min(length, length - offset))  # t with t + offset in the episode
            if not anchors:
                continue
            chunk_actions = actions[anchors.start + offset:anchors.stop + offset].unsqueeze(-2)
            relative = to_hand_frame(chunk_actions, states[anchors.start:anchors.stop])[:, 0].numpy()
            total += relative.sum(axis=0)
            total_squares += np.square(relative).sum(axis=0)
            low = np.minimum(low, relative.min(axis=0))
            high = np.maximum(high, relative.max(axis=0))
            count += len(relative)
    mean = total / count
    return {"mean": mean, "std": np.sqrt(np.maximum(total_squares / count - np.square(mean), 0.0)),
            "min": low, "max": high}
