"""Shared by the hand-frame policy tests: made-up episodes and a dataset's data files holding them."""

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from lerobot.utils.constants import OBS_STATE

from lerobot_tavis import canonical


def made_up_episode(rng, length: int) -> tuple[np.ndarray, np.ndarray]:
    """Actions and states (length, 19) of a made-up episode: hands drifting and turning, the state lagging."""
    actions = np.tile(canonical.rest_action(), (length, 1))
    for arm in canonical.ARMS:
        actions[:, arm.position] += np.cumsum(rng.normal(scale=0.01, size=(length, 3)), axis=0)
        turns = rng.normal(scale=0.05, size=(length, 4)) + actions[:, arm.quaternion]
        actions[:, arm.quaternion] = turns / np.linalg.norm(turns, axis=1, keepdims=True)
    states = np.concatenate([actions[:1], actions[:-1]]) + rng.normal(scale=1e-3, size=actions.shape)
    return actions, states


@pytest.fixture
def dataset_root(tmp_path):
    """A dataset's data files as LeRobot writes them (two files, episodes in either order) and its episodes."""
    rng = np.random.default_rng(0)
    episodes = [made_up_episode(rng, length) for length in (9, 3, 6)]
    for name, indices in (("file-000", [2, 0]), ("file-001", [1])):
        rows = [(e, f, episodes[e][0][f], episodes[e][1][f]) for e in indices for f in range(len(episodes[e][0]))]
        vectors = {key: pa.FixedSizeListArray.from_arrays(pa.array(np.concatenate([row[i] for row in rows]),
                                                                   pa.float32()), canonical.ACTION_DIM)
                   for i, key in ((2, "action"), (3, OBS_STATE))}
        table = pa.table({"episode_index": [row[0] for row in rows], "frame_index": [row[1] for row in rows],
                          **vectors})
        (tmp_path / "data/chunk-000").mkdir(parents=True, exist_ok=True)
        pq.write_table(table, tmp_path / f"data/chunk-000/{name}.parquet")
    return tmp_path, [(a.astype(np.float32).astype(float), s.astype(np.float32).astype(float)) for a, s in episodes]
