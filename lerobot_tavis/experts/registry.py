"""One demonstrator per task, and a helper that plays an episode."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from lerobot_tavis.errors import InputError
from lerobot_tavis.experts.base import Expert
from lerobot_tavis.experts.hands_tasks import BlockedClutterExpert, OccludedReachExpert, PeekingBoxExpert
from lerobot_tavis.experts.head_tasks import ClutterExpert, ConditionalPickExpert, ShelfExpert, WaitThenActExpert

EXPERTS: dict[str, type[Expert]] = {
    "conditional_pick": ConditionalPickExpert,
    "wait_then_act": WaitThenActExpert,
    "clutter_pick_cube": ClutterExpert,
    "clutter_pick_lift": ClutterExpert,
    "multi_shelf_scan": ShelfExpert,
    "peeking_box": PeekingBoxExpert,
    "occluded_reach": OccludedReachExpert,
    "blocked_clutter_pick_cube": BlockedClutterExpert,
}


def make_expert(env, seed: int) -> Expert:
    """The demonstrator of `env.task`, with its own generator (timing and path variation) derived from `seed`."""
    try:
        cls = EXPERTS[env.task]
    except KeyError:
        raise InputError(f"no demonstrator for task {env.task!r}; tasks with one: {sorted(EXPERTS)}") from None
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
