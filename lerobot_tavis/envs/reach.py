"""How far an episode got toward its target, to tell failures apart: a policy that brought a hand to another
object and never to the target (it chose wrong), one that brought a hand to neither (searched in vain, or kept
still), one that reached the target and never moved it (a missed or unclosed grasp), and one that moved it without
succeeding (dropped, not lifted high enough); how well placed its first grasp of the target was; and whether the
hands ended where they were commanded (a policy that stops short) or held back from it (blocked by an object, or
commanded out of reach)."""

from __future__ import annotations

import mujoco
import numpy as np

from lerobot_tavis import canonical
from lerobot_tavis.envs.tasks.base import MEASURE_DECIMALS

REACHED_M = 0.05  # a hand's grasp site this near the target's origin got to it (the demonstrators' test too)
MOVED_M = 0.02  # the target's origin this far from where the episode found it was moved by the robot
HELD_BACK_M = 0.02  # an end effector this far from its commanded position at the last step is held back from it
FAILURE_STAGES = ("reached_other", "not_reached", "reached_not_moved", "moved_no_success")


class ReachTracker:
    """Over one episode of a task with a target body, world frame: the closest any hand's grasp site came to the
    target's origin (m) and to the origin of any of the `other_bodies` (the scene's other props, m; None without
    any), the farthest the target's origin got from where it was at the first observation (m), and the
    horizontal distance (m) from the target's origin to the grasp site of the first hand that closed its gripper
    within REACHED_M of it (None until one does; the demonstrators centre their pads on the object, so this is
    how far off a grasp was placed) and, at that moment, the target's origin in that hand's frame (m: x along the
    fingers' width, y across the jaws, z along the fingers toward the wrist); and after the latest step, the larger
    of the two arms' distances between the commanded and the measured end-effector position (m)."""

    def __init__(self, data: mujoco.MjData, target_body: int, grasp_sites: dict[str, int],
                 other_bodies: tuple[int, ...] = ()):
        self._body, self._sites = target_body, grasp_sites
        self._hand_ids, self._others = np.array(list(grasp_sites.values())), np.array(other_bodies, dtype=int)
        self._start = data.xpos[target_body].copy()
        self._closed = dict.fromkeys(grasp_sites, False)
        self.closest_hand_m, self.target_moved_m = np.inf, 0.0
        self.closest_hand_other_m = np.inf
        self.first_grasp_xy_m: float | None = None
        self.first_grasp_in_hand_m: np.ndarray | None = None
        self.command_gap_m = 0.0
        self._measure(data)

    def update(self, data: mujoco.MjData, command: np.ndarray, measured: np.ndarray) -> None:
        """Take the state after an env step into account: the canonical `command` that step applied and the
        canonical state `measured` after it."""
        self._measure(data)
        self.command_gap_m = max(float(np.linalg.norm(command[arm.position] - measured[arm.position]))
                                 for arm in canonical.ARMS)
        target = data.xpos[self._body]
        for arm in canonical.ARMS:
            closed = command[arm.gripper] > 0.0
            if closed and not self._closed[arm.side] and self.first_grasp_xy_m is None:
                site = self._sites[arm.side]
                offset = data.site_xpos[site] - target
                if np.linalg.norm(offset) <= REACHED_M:
                    self.first_grasp_xy_m = float(np.linalg.norm(offset[:2]))
                    self.first_grasp_in_hand_m = data.site_xmat[site].reshape(3, 3).T @ -offset
            self._closed[arm.side] = closed

    def summary(self) -> dict[str, float | list[float] | None]:
        """`{"closest_hand_m", "closest_hand_other_m", "target_moved_m", "first_grasp_xy_m",
        "first_grasp_in_hand_m", "command_gap_m"}`, to the millimetre as the success conditions are."""
        return {"closest_hand_m": _millimetre(self.closest_hand_m),
                "closest_hand_other_m": _millimetre(self.closest_hand_other_m) if self._others.size else None,
                "target_moved_m": _millimetre(self.target_moved_m),
                "first_grasp_xy_m": None if self.first_grasp_xy_m is None else _millimetre(self.first_grasp_xy_m),
                "first_grasp_in_hand_m": None if self.first_grasp_in_hand_m is None
                else [_millimetre(value) for value in self.first_grasp_in_hand_m],
                "command_gap_m": _millimetre(self.command_gap_m)}

    def _measure(self, data: mujoco.MjData) -> None:
        hands = data.site_xpos[self._hand_ids]
        target = data.xpos[self._body]
        self.closest_hand_m = min(self.closest_hand_m, _nearest(hands, target[None]))
        if self._others.size:
            self.closest_hand_other_m = min(self.closest_hand_other_m, _nearest(hands, data.xpos[self._others]))
        self.target_moved_m = max(self.target_moved_m, float(np.linalg.norm(target - self._start)))


def _nearest(hands: np.ndarray, bodies: np.ndarray) -> float:
    """The smallest distance between any of the points `hands` (n, 3) and any of `bodies` (m, 3), m."""
    return float(np.linalg.norm(hands[:, None] - bodies[None], axis=-1).min())


def _millimetre(value_m: float) -> float:
    return round(float(value_m), MEASURE_DECIMALS)


def failure_stage(reach: dict[str, float]) -> str:
    """Where a failed episode stopped (one of FAILURE_STAGES), from its `reach` summary. Logs written before the
    other props were measured (no `closest_hand_other_m`) count a target never reached as `not_reached`."""
    if reach["closest_hand_m"] > REACHED_M:
        other = reach.get("closest_hand_other_m")
        return "reached_other" if other is not None and other <= REACHED_M else "not_reached"
    return "reached_not_moved" if reach["target_moved_m"] < MOVED_M else "moved_no_success"


def held_back(reach: dict[str, float]) -> bool | None:
    """Whether an episode ended with a hand held back from its commanded position (by more than HELD_BACK_M); None
    for logs written before this was measured."""
    gap = reach.get("command_gap_m")
    return None if gap is None else gap > HELD_BACK_M
