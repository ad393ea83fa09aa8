"""GALT, the Gaze-Action Lead Time: how long the head settles on its final fixation before the hand grasps.

Computed from the commanded action trajectory alone, exactly as the reference detector (reference §8), quirks
included, so numbers compare with published ones:

1. Fewer than 10 steps: `too_short`.
2. Speeds are forward differences (L2 over a channel group, times fps), the last value repeated.
3. Per arm, left first: the grasp anchor is the last change of the binarised gripper (value >= 0); none:
   `no_grasp`. Hand onset: walking back from the anchor, the first block of m quiet steps (hand speed < 0.05 m/s)
   puts the onset just after it; no block, or one ending at the anchor: `no_hand_onset`. Head arrival: in the
   window [anchor - 3 s, anchor + 0.5 s], runs of k still steps (neck speed < 0.10 rad/s) give candidate starts;
   the latest one not after the anchor (else the earliest after it) is refined backwards to where the neck was
   last more than 0.05 rad (any channel) from its value there; none: `no_fixation`. GALT = (anchor - arrival) /
   fps: below -0.5 s `outlier_low`, above 4.0 s `outlier_high`, else `ok` (arrival not after the anchor) or
   `ok_post_anchor`.
4. One valid arm gives the result; two give `ambiguous_arms`; none give the most severe per-arm reason
   (no_fixation = outlier_low = outlier_high > no_hand_onset > no_grasp, ties to the left arm).

Step counts use Python's round (half to even) like the reference.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

REASON_PRIORITY = {"no_grasp": 1, "no_hand_onset": 2, "no_fixation": 3, "outlier_low": 3, "outlier_high": 3}
MIN_STEPS = 10


@dataclass(frozen=True)
class GaltParams:
    v_hand_thresh: float = 0.05  # m/s
    v_sac_thresh: float = 0.10  # rad/s
    k_fix_s: float = 0.080
    min_stable_for_onset_s: float = 0.300
    lookback_s: float = 3.0
    forward_slack_s: float = 0.5
    outlier_min_s: float = -0.5
    outlier_max_s: float = 4.0
    arrival_margin_rad: float = 0.05

    def steps(self, fps: float) -> dict[str, int]:
        return {
            "k": max(1, round(self.k_fix_s * fps)),
            "m": max(1, round(self.min_stable_for_onset_s * fps)),
            "lookback": round(self.lookback_s * fps),
            "slack": round(self.forward_slack_s * fps),
        }


@dataclass(frozen=True)
class ActionLayout:
    """Channels of the (T, D) action array that GALT reads (defaults: the canonical 19-D action)."""

    left_hand: tuple[int, ...] = (0, 1, 2)
    right_hand: tuple[int, ...] = (7, 8, 9)
    neck: tuple[int, ...] = (14, 15, 16)
    left_gripper: int = 17
    right_gripper: int = 18

    def arms(self) -> dict[str, tuple[tuple[int, ...], int]]:
        return {"left": (self.left_hand, self.left_gripper), "right": (self.right_hand, self.right_gripper)}


@dataclass(frozen=True)
class ArmGalt:
    reason: str
    galt_s: float | None = None
    anchor: int | None = None
    onset: int | None = None
    head_arrival: int | None = None

    @property
    def valid(self) -> bool:
        return self.galt_s is not None


@dataclass(frozen=True)
class GaltResult:
    galt_s: float | None
    reason: str
    arm: str | None = None
    t_head_arrival_s: float | None = None
    t_hand_arrival_s: float | None = None
    t_hand_onset_s: float | None = None
    arm_reach_s: float | None = None
    per_arm: dict[str, ArmGalt] = field(default_factory=dict)


def channel_speed(values: np.ndarray, fps: float) -> np.ndarray:
    """Per-step speed of a (T, d) channel group: forward difference norm x fps, last value repeated (length T)."""
    speed = np.linalg.norm(np.diff(values, axis=0), axis=1) * fps
    return np.append(speed, speed[-1])


def binarised_events(gripper: np.ndarray) -> np.ndarray:
    """Indices t where the binarised gripper (value >= 0) differs from t - 1."""
    closed = gripper >= 0
    return np.flatnonzero(closed[1:] != closed[:-1]) + 1


def hand_onset(hand_speed: np.ndarray, anchor: int, v_thresh: float, m: int) -> int | None:
    quiet = 0
    for t in range(anchor - 1, -1, -1):
        quiet = quiet + 1 if hand_speed[t] < v_thresh else 0
        if quiet == m:
            onset = t + m
            return None if onset >= anchor else onset
    return None


def head_arrival(neck: np.ndarray, neck_speed: np.ndarray, anchor: int, params: GaltParams, steps: dict) -> int | None:
    """Refined start of the fixation that the gaze settles on around the anchor, or None."""
    first, last = max(0, anchor - steps["lookback"]), min(len(neck) - 1, anchor + steps["slack"])
    starts, run = [], 0
    for t in range(first, last + 1):
        run = run + 1 if neck_speed[t] < params.v_sac_thresh else 0
        if run == steps["k"]:
            starts.append(t - steps["k"] + 1)
    if not starts:
        return None
    before = [s for s in starts if s <= anchor]
    chosen = max(before) if before else min(starts)
    settled = neck[chosen]
    for t in range(chosen - 1, -1, -1):
        if np.max(np.abs(neck[t] - settled)) >= params.arrival_margin_rad:
            return t + 1
    return 0


def _arm_galt(actions, fps, params, steps, hand, gripper, neck, neck_speed) -> ArmGalt:
    events = binarised_events(actions[:, gripper])
    if not len(events):
        return ArmGalt("no_grasp")
    anchor = int(events[-1])
    onset = hand_onset(channel_speed(actions[:, list(hand)], fps), anchor, params.v_hand_thresh, steps["m"])
    if onset is None:
        return ArmGalt("no_hand_onset", anchor=anchor)
    arrival = head_arrival(neck, neck_speed, anchor, params, steps)
    if arrival is None:
        return ArmGalt("no_fixation", anchor=anchor, onset=onset)
    galt = (anchor - arrival) / fps
    if galt < params.outlier_min_s:
        return ArmGalt("outlier_low", anchor=anchor, onset=onset, head_arrival=arrival)
    if galt > params.outlier_max_s:
        return ArmGalt("outlier_high", anchor=anchor, onset=onset, head_arrival=arrival)
    return ArmGalt("ok" if arrival <= anchor else "ok_post_anchor", galt, anchor, onset, arrival)


def compute_galt(actions, fps: float, params: GaltParams = GaltParams(),
                 layout: ActionLayout = ActionLayout()) -> GaltResult:
    """GALT of one episode from its (T, D) commanded actions sampled at `fps` (see the module docstring)."""
    actions = np.asarray(actions, dtype=float)
    if actions.ndim != 2:
        raise ValueError(f"actions must be a (T, D) array, got shape {actions.shape}")
    if len(actions) < MIN_STEPS:
        return GaltResult(None, "too_short")
    steps = params.steps(fps)
    gaze = actions[:, list(layout.neck)]
    gaze_speed = channel_speed(gaze, fps)
    per_arm = {side: _arm_galt(actions, fps, params, steps, hand, gripper, gaze, gaze_speed)
               for side, (hand, gripper) in layout.arms().items()}
    return _combine(per_arm, fps)


def _combine(per_arm: dict[str, ArmGalt], fps: float) -> GaltResult:
    valid = [side for side, arm in per_arm.items() if arm.valid]
    if len(valid) == 2:
        return GaltResult(None, "ambiguous_arms", per_arm=per_arm)
    if not valid:
        worst = max(per_arm.values(), key=lambda arm: REASON_PRIORITY[arm.reason])  # max keeps the first on ties
        return GaltResult(None, worst.reason, per_arm=per_arm)
    side = valid[0]
    arm = per_arm[side]
    return GaltResult(arm.galt_s, arm.reason, side, arm.head_arrival / fps, arm.anchor / fps, arm.onset / fps,
                      (arm.anchor - arm.onset) / fps, per_arm)
