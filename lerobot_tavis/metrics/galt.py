"""GALT, the Gaze-Action Lead Time: how long the head settles on its final fixation before the hand grasps.

Computed from the commanded action trajectory alone, exactly as the reference detector (docs/reference.md §9), quirks
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

Two extensions, kept apart from the reference result: `galt_per_grasp` measures every grasp (each closing of
a gripper) the way the reference measures the final gripper event, and `wrist_lead_per_grasp` is the wrist-camera
analogue for TAVIS-Hands: how long before a grasp the camera on the grasping hand settled for its last look.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from lerobot_tavis.envs.transforms import quat_angles_rad

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
    wrist_arrival_margin_m: float = 0.01  # extension only: the wrist analogue's settle refinement

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
    left_orientation: tuple[int, ...] = (3, 4, 5, 6)  # quaternion w, x, y, z (wrist analogue only)
    right_orientation: tuple[int, ...] = (10, 11, 12, 13)

    def arms(self) -> dict[str, tuple[tuple[int, ...], int]]:
        return {"left": (self.left_hand, self.left_gripper), "right": (self.right_hand, self.right_gripper)}

    def orientation(self, side: str) -> tuple[int, ...]:
        return self.left_orientation if side == "left" else self.right_orientation


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
    return _galt_at(int(events[-1]), channel_speed(actions[:, list(hand)], fps), fps, params, steps, neck,
                    neck_speed)


def _galt_at(anchor, hand_speed, fps, params, steps, neck, neck_speed) -> ArmGalt:
    """Steps 3b-e of the reference for one gripper event at step `anchor`."""
    onset = hand_onset(hand_speed, anchor, params.v_hand_thresh, steps["m"])
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
    actions = _checked(actions)
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


# --- Extensions (not part of the reference detector) ---------------------------------------------------------


@dataclass(frozen=True)
class GraspGalt:
    """GALT of one grasp: `arm` closed its gripper at step `anchor` (t_grasp_s = anchor / fps)."""

    arm: str
    t_grasp_s: float
    galt: ArmGalt


@dataclass(frozen=True)
class WristLead:
    """How long before one grasp the grasping hand's wrist camera settled for its last look.

    reason: `ok`, `no_hand_onset` (as the reference), `no_fixation` (the camera still turns when the hand starts
    its reach) or `outlier_high` (settled more than 4.0 s before the grasp: a rest, not a look).
    """

    arm: str
    t_grasp_s: float
    reason: str
    lead_s: float | None = None
    t_settle_s: float | None = None
    t_hand_onset_s: float | None = None


def grasp_events(actions: np.ndarray, layout: ActionLayout = ActionLayout()) -> list[tuple[str, int]]:
    """Every closing of a gripper (binarised open -> closed) as (arm, step), in time order, left first on ties."""
    events = []
    for side, (_, gripper) in layout.arms().items():
        closed = actions[:, gripper] >= 0
        events += [(side, int(t)) for t in binarised_events(actions[:, gripper]) if closed[t]]
    return sorted(events, key=lambda event: (event[1], event[0] != "left"))


def galt_per_grasp(actions, fps: float, params: GaltParams = GaltParams(),
                   layout: ActionLayout = ActionLayout()) -> list[GraspGalt]:
    """GALT for every grasp of an episode, each measured as the reference measures its final gripper event.

    Unlike the reference, openings are not grasps; episodes shorter than 10 steps have none.
    """
    actions = _checked(actions)
    if len(actions) < MIN_STEPS:
        return []
    steps = params.steps(fps)
    neck = actions[:, list(layout.neck)]
    neck_speed = channel_speed(neck, fps)
    hand_speed = {side: channel_speed(actions[:, list(hand)], fps) for side, (hand, _) in layout.arms().items()}
    return [GraspGalt(side, anchor / fps, _galt_at(anchor, hand_speed[side], fps, params, steps, neck, neck_speed))
            for side, anchor in grasp_events(actions, layout)]


def wrist_lead_per_grasp(actions, fps: float, params: GaltParams = GaltParams(),
                         layout: ActionLayout = ActionLayout()) -> list[WristLead]:
    """The wrist-camera analogue of GALT for every grasp (TAVIS-Hands).

    The camera rides on the hand, so its last look before a grasp is the still pose the hand leaves at its
    reach onset (found as in the reference). The look is the run of steps before the onset where the hand moves
    slower than 0.05 m/s and turns slower than 0.10 rad/s; its start is refined backwards to where the hand was
    last more than 0.01 m or 0.05 rad from its pose there. lead_s = (grasp - settle) / fps.
    """
    actions = _checked(actions)
    if len(actions) < MIN_STEPS:
        return []
    steps = params.steps(fps)
    leads = []
    for side, anchor in grasp_events(actions, layout):
        position = actions[:, list(layout.arms()[side][0])]
        quaternion = actions[:, list(layout.orientation(side))]
        leads.append(_wrist_lead(side, anchor, position, quaternion, fps, params, steps))
    return leads


def _wrist_lead(side, anchor, position, quaternion, fps, params, steps) -> WristLead:
    t_grasp = anchor / fps
    move_speed = channel_speed(position, fps)
    onset = hand_onset(move_speed, anchor, params.v_hand_thresh, steps["m"])
    if onset is None:
        return WristLead(side, t_grasp, "no_hand_onset")
    turn = quat_angles_rad(quaternion[:-1], quaternion[1:]) * fps
    turn_speed = np.append(turn, turn[-1])  # as channel_speed: forward differences, last value repeated
    still = (move_speed < params.v_hand_thresh) & (turn_speed < params.v_sac_thresh)
    start = onset
    while start > 0 and still[start - 1]:
        start -= 1
    if onset - start < steps["k"]:
        return WristLead(side, t_grasp, "no_fixation", t_hand_onset_s=onset / fps)
    settle = start
    while settle > 0 and (np.max(np.abs(position[settle - 1] - position[start])) < params.wrist_arrival_margin_m
                          and quat_angles_rad(quaternion[settle - 1], quaternion[start]) < params.arrival_margin_rad):
        settle -= 1
    lead = (anchor - settle) / fps
    reason = "outlier_high" if lead > params.outlier_max_s else "ok"
    return WristLead(side, t_grasp, reason, lead if reason == "ok" else None, settle / fps, onset / fps)


def _checked(actions) -> np.ndarray:
    actions = np.asarray(actions, dtype=float)
    if actions.ndim != 2:
        raise ValueError(f"actions must be a (T, D) array, got shape {actions.shape}")
    return actions
