"""How far an episode got toward its target, to tell failures apart: a policy that never brought a hand to the
target (searched in vain, or went for another object), one that reached it and never moved it (a missed or
unclosed grasp), and one that moved it without succeeding (dropped, not lifted high enough)."""

from __future__ import annotations

import mujoco
import numpy as np

from lerobot_tavis.envs.tasks.base import MEASURE_DECIMALS

REACHED_M = 0.05  # a hand's grasp site this near the target's origin got to it (the demonstrators' test too)
MOVED_M = 0.02  # the target's origin this far from where the episode found it was moved by the robot
FAILURE_STAGES = ("not_reached", "reached_not_moved", "moved_no_success")


class ReachTracker:
    """Over one episode of a task with a target body: the closest any hand's grasp site came to the target's origin
    (m) and the farthest that origin got from where it was at the first observation (m), world frame."""

    def __init__(self, data: mujoco.MjData, target_body: int, grasp_sites: tuple[int, ...]):
        self._body, self._sites = target_body, grasp_sites
        self._start = data.xpos[target_body].copy()
        self.closest_hand_m, self.target_moved_m = np.inf, 0.0
        self.update(data)

    def update(self, data: mujoco.MjData) -> None:
        """Take the current state into account (after each env step)."""
        target = data.xpos[self._body]
        nearest = min(float(np.linalg.norm(data.site_xpos[site] - target)) for site in self._sites)
        self.closest_hand_m = min(self.closest_hand_m, nearest)
        self.target_moved_m = max(self.target_moved_m, float(np.linalg.norm(target - self._start)))

    def summary(self) -> dict[str, float]:
        """`{"closest_hand_m", "target_moved_m"}`, to the millimetre as the success conditions are."""
        return {"closest_hand_m": round(self.closest_hand_m, MEASURE_DECIMALS),
                "target_moved_m": round(self.target_moved_m, MEASURE_DECIMALS)}


def failure_stage(reach: dict[str, float]) -> str:
    """Where a failed episode stopped (one of FAILURE_STAGES), from its `reach` summary."""
    if reach["closest_hand_m"] > REACHED_M:
        return "not_reached"
    return "reached_not_moved" if reach["target_moved_m"] < MOVED_M else "moved_no_success"
