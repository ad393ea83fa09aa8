"""Shared by the hand-frame policy tests: made-up episodes and a dataset's data files holding them; a recorded
demonstration and its replay by a checkpoint on the env."""

import json
from types import SimpleNamespace

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
import torch
from lerobot.utils.constants import ACTION, OBS_STATE

from lerobot_tavis import canonical
from tests.conftest import built_once_per_run


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


@pytest.fixture(scope="session")
def demonstration(conditional_pick_demonstration, tmp_path_factory):
    """The run's one recorded conditional_pick demonstration (GR1T2) converted once per run with the head camera at
    32x32: the dataset's `root`, the episode's `seed`, its `actions` and `states` (T, 19, float32 tensors) in frame
    order."""
    import pandas as pd

    from lerobot_tavis.dataset_tools.convert import CONVERSION_LOG, ConvertConfig, convert
    def build(path):
        convert(ConvertConfig(conditional_pick_demonstration, "local/tiny", path, image_size=(32, 32),
                              cameras=("head",)), progress=False)

    root = built_once_per_run(tmp_path_factory, "hand_frame_demonstration", build)
    (entry,) = json.loads((root / CONVERSION_LOG).read_text())["episodes"]
    frames = pd.read_parquet(next((root / "data").rglob("*.parquet"))).sort_values("frame_index")
    actions, states = (torch.tensor(np.stack(frames[key].to_numpy()), dtype=torch.float32)
                       for key in (ACTION, OBS_STATE))
    return SimpleNamespace(root=root, seed=entry["seed"], actions=actions, states=states)


def replay(checkpoint, demonstration) -> tuple[bool, float]:
    """The checkpoint acting on the env from the demonstration's seed through `PolicyDriver` (as lerobot-eval runs
    it), the last recorded action held for one second more: whether it succeeded, and the largest distance (m) of
    an executed arm position target from the recorded one of the same step."""
    from lerobot_tavis.envs.env import TavisEnv
    from lerobot_tavis.viewer import PolicyDriver

    actions = demonstration.actions
    driver = PolicyDriver(checkpoint)
    env = TavisEnv("conditional_pick", "gr1t2", camera_mode="head_only", image_size=(32, 32))
    observation, _ = env.reset(seed=demonstration.seed)
    driver.reset()
    errors_m, success = [], False
    for step in range(len(actions) + 20):
        action = driver.act(observation, env.task_description)
        recorded = actions[min(step, len(actions) - 1)].numpy()
        errors_m.append(max(np.linalg.norm(action[arm.position] - recorded[arm.position]) for arm in canonical.ARMS))
        observation, _, success, _, _ = env.step(action)
        if success:
            break
    env.close()
    return success, max(errors_m)
