"""The demonstrator of a task (declared in `envs.tasks.catalog`), and a helper that plays an episode."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from lerobot_tavis.envs.tasks.catalog import TASKS, demonstrator_class
from lerobot_tavis.errors import InputError
from lerobot_tavis.experts.base import Expert


def make_expert(env, seed: int) -> Expert:
    """The demonstrator of `env.task` (named in the task catalog), with its own generator (timing and path
    variation) derived from `seed`."""
    cls = demonstrator_class(env.task)
    if cls is None:
        with_one = sorted(name for name, info in TASKS.items() if info.demonstrator is not None)
        raise InputError(f"no demonstrator for task {env.task!r}; tasks with one: {with_one}")
    return cls(env, np.random.default_rng([seed, 0x7A715]))


@dataclass(frozen=True)
class EpisodeResult:
    success: bool
    length_steps: int
    actions: np.ndarray  # (T, 19) applied actions


def run_episode(env, seed: int, expert: Expert | None = None,
                on_step: Callable[[], None] | None = None) -> EpisodeResult:
    """Reset `env` (a TavisEnv, possibly wrapped) with `seed` and let its demonstrator act until the episode
    ends. `on_step` is called after the reset and after every step (to record the simulator state, say)."""
    env.reset(seed=seed)
    expert = expert or make_expert(env.unwrapped, seed)
    expert.reset()
    actions, info = [], {"is_success": False}
    if on_step:
        on_step()
    for _ in range(env.unwrapped._max_episode_steps):
        _, _, terminated, truncated, info = env.step(expert.act())
        actions.append(info["applied_action"])
        if on_step:
            on_step()
        if terminated or truncated:
            break
    return EpisodeResult(bool(info["is_success"]), len(actions), np.array(actions))
