"""An episode seed is an integer >= 0: a fractional one is refused rather than played as its integer part, and a
negative or boolean one is refused in the project's words, by the env and by every command's seed option."""

import subprocess
import sys

import numpy as np
import pytest

from lerobot_tavis.envs.env import TavisEnv
from lerobot_tavis.errors import FieldError


@pytest.fixture(scope="module")
def env():
    env = TavisEnv("conditional_pick", "gr1t2", image_size=(16, 16), cameras=())
    yield env
    env.close()


@pytest.mark.parametrize("seed", [1.5, -1, True, False, "3", float("nan"), float("inf"), 10**20 * -1])
def test_reset_refuses_a_seed_that_is_not_an_integer_from_zero(env, seed):
    with pytest.raises(ValueError) as error:
        env.reset(seed=seed)
    assert isinstance(error.value, FieldError) and error.value.field == "seed"
    assert str(error.value) == f"seed must be an integer >= 0, got {seed!r}"


def test_whole_seeds_of_any_integer_type_play_the_same_episode(env):
    reference = env.reset(seed=1)[0]["agent_pos"]
    for seed in (np.int64(1), np.uint8(1), 1.0):
        np.testing.assert_array_equal(env.reset(seed=seed)[0]["agent_pos"], reference)


@pytest.mark.parametrize("argv,line", [
    (["view", "--task", "conditional_pick", "--seed", "-3"],
     "tavis view: error: --seed must be an integer >= 0, got -3"),
    (["noise-state", "in", "--out", "out", "--position-m", "0", "--rotation-deg", "0", "--seed", "-2"],
     "tavis noise-state: error: --seed must be an integer >= 0, got -2"),
])
def test_negative_seed_options_are_one_line(tmp_path, argv, line):
    result = subprocess.run([sys.executable, "-m", "lerobot_tavis.cli", *argv], capture_output=True, text=True,
                            cwd=tmp_path, timeout=120)
    assert (result.returncode, result.stderr) == (1, line + "\n")
