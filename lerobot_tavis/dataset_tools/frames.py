"""A LeRobotDataset's frames per episode, read from its data files (which hold no images) in frame order."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from lerobot_tavis.errors import InputError


def episode_frames(root: str | Path) -> dict:
    """Per episode index, its rows of the data files under `root` (a pandas DataFrame) sorted by `frame_index`."""
    import pandas as pd

    paths = sorted((Path(root) / "data").rglob("*.parquet"))
    if not paths:
        raise InputError(f"{root}: no data files under data/")
    table = pd.concat([pd.read_parquet(path) for path in paths]).sort_values(["episode_index", "frame_index"])
    return {int(index): rows for index, rows in table.groupby("episode_index")}


def column_array(rows, key: str) -> np.ndarray:
    """A vector column (e.g. `action`) of an episode's rows as one (frames, size) array."""
    return np.stack(rows[key].to_numpy())
