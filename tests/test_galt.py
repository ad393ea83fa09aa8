"""GALT on synthetic episodes with known head and hand timing, one case per reason code."""

import numpy as np
import pytest

from lerobot_tavis import canonical
from lerobot_tavis.metrics.galt import GaltParams, compute_galt, galt_per_grasp, grasp_events, wrist_lead_per_grasp


def episode(fps: float, duration_s: float, head_until_s: float | None, hand=None, grasp_s=None, side="right",
            head_from_s: float = 0.0, head_target: float = 0.8) -> np.ndarray:
    """Rest actions; the head pitch ramps linearly to `head_target` between head_from_s and head_until_s; the
    hand moves linearly 0.2 m forward during `hand` = (start_s, end_s); the gripper closes at grasp_s."""
    t = np.arange(round(duration_s * fps)) / fps
    actions = np.tile(canonical.rest_action(), (len(t), 1))
    if head_until_s is not None:
        ramp = np.clip((t - head_from_s) / (head_until_s - head_from_s), 0.0, 1.0)
        actions[:, canonical.HEAD_PITCH] = head_target * ramp
    arm = canonical.RIGHT if side == "right" else canonical.LEFT
    if hand is not None:
        progress = np.clip((t - hand[0]) / (hand[1] - hand[0]), 0.0, 1.0)
        actions[:, arm.position.start] += 0.2 * progress
    if grasp_s is not None:
        actions[t >= grasp_s, arm.gripper] = 1.0
    return actions


def test_reference_self_test_at_60hz():
    result = compute_galt(episode(60, 5.0, 1.0, hand=(1.4, 2.0), grasp_s=2.0), fps=60)
    assert result.reason == "ok" and result.arm == "right"
    assert result.galt_s == pytest.approx(1.0, abs=0.1)
    assert result.t_hand_arrival_s == pytest.approx(2.0, abs=1 / 60)
    assert result.t_hand_onset_s == pytest.approx(1.4, abs=2 / 60)
    assert result.arm_reach_s == pytest.approx(result.t_hand_arrival_s - result.t_hand_onset_s)


@pytest.mark.parametrize("fps", [20, 60])
@pytest.mark.parametrize("head_until_s,grasp_s,expected", [(1.0, 2.0, 1.0), (1.5, 2.0, 0.5), (0.5, 2.6, 2.1)])
def test_known_lead_times(fps, head_until_s, grasp_s, expected):
    actions = episode(fps, 5.0, head_until_s, hand=(grasp_s - 0.8, grasp_s), grasp_s=grasp_s, side="left")
    result = compute_galt(actions, fps=fps)
    assert result.reason == "ok" and result.arm == "left"
    # the arrival refinement (0.05 rad margin) moves the arrival up to 0.05 rad / 0.8 rad/s earlier
    assert expected <= result.galt_s + 1e-9 and result.galt_s == pytest.approx(expected, abs=0.1)


def test_too_short():
    assert compute_galt(episode(20, 0.45, 0.2), fps=20).reason == "too_short"


def test_no_grasp():
    result = compute_galt(episode(20, 4.0, 1.0, hand=(1.0, 2.0)), fps=20)
    assert result.reason == "no_grasp" and result.galt_s is None


def test_no_hand_onset_when_the_hand_rests_right_before_the_grasp():
    # the reference quirk: a >= 0.3 s rest just before the gripper event hides the onset
    result = compute_galt(episode(20, 4.0, 1.0, hand=(1.0, 1.5), grasp_s=2.0), fps=20)
    assert result.reason == "no_hand_onset"


def test_no_hand_onset_when_the_hand_never_rests():
    actions = episode(20, 3.0, 0.5, grasp_s=2.5)
    actions[:, canonical.RIGHT.position.start] += np.arange(len(actions)) * 0.01  # 0.2 m/s throughout
    assert compute_galt(actions, fps=20).reason == "no_hand_onset"


def test_no_fixation_when_the_head_keeps_moving():
    actions = episode(20, 4.0, None, hand=(1.4, 2.0), grasp_s=2.0)
    actions[:, canonical.HEAD_YAW] = 0.3 * np.arange(len(actions)) / 20  # 0.3 rad/s
    assert compute_galt(actions, fps=20).reason == "no_fixation"


def test_ok_post_anchor_when_the_head_settles_after_the_grasp():
    # the head keeps moving (0.35 rad/s) until 0.3 s after the grasp
    result = compute_galt(episode(20, 4.0, 2.3, hand=(1.4, 2.0), grasp_s=2.0), fps=20)
    assert result.reason == "ok_post_anchor" and result.galt_s == pytest.approx(-0.3, abs=0.1)


def test_outlier_low_when_the_head_settles_long_after_the_grasp():
    params = GaltParams(forward_slack_s=1.0)  # so that the late fixation is inside the window
    result = compute_galt(episode(20, 5.0, 2.8, hand=(1.4, 2.0), grasp_s=2.0, head_target=1.2), fps=20,
                          params=params)
    assert result.reason == "outlier_low"


def test_outlier_high_when_the_fixation_began_long_before():
    params = GaltParams(lookback_s=6.0)
    result = compute_galt(episode(20, 8.0, 0.5, hand=(4.4, 5.0), grasp_s=5.0), fps=20, params=params)
    assert result.reason == "outlier_high"


def test_ambiguous_arms():
    actions = episode(20, 4.0, 1.0, hand=(1.4, 2.0), grasp_s=2.0, side="right")
    left = episode(20, 4.0, None, hand=(1.5, 2.1), grasp_s=2.1, side="left")
    actions[:, 0:7], actions[:, 17] = left[:, 0:7], left[:, 17]
    assert compute_galt(actions, fps=20).reason == "ambiguous_arms"


def test_reason_priority_prefers_the_more_severe_arm_reason():
    # right arm: no_hand_onset; left arm: never grasps (no_grasp, lower priority)
    result = compute_galt(episode(20, 4.0, 1.0, hand=(1.0, 1.5), grasp_s=2.0, side="right"), fps=20)
    assert result.per_arm["left"].reason == "no_grasp" and result.reason == "no_hand_onset"


def test_bad_input_shape():
    with pytest.raises(ValueError, match=r"\(T, D\)"):
        compute_galt(np.zeros(19), fps=20)


def two_grasps(fps: float) -> np.ndarray:
    """Right hand grasps at 2.0 s (head settled at 1.0 s), releases at 3.0 s; the head turns again from 3.0 to
    3.5 s; the left hand reaches 4.2-5.0 s and grasps at 5.0 s."""
    actions = episode(fps, 7.0, 1.0, hand=(1.4, 2.0), grasp_s=2.0, side="right")
    t = np.arange(len(actions)) / fps
    actions[t >= 3.0, canonical.RIGHT.gripper] = -1.0
    actions[:, canonical.HEAD_YAW] = 0.6 * np.clip((t - 3.0) / 0.5, 0.0, 1.0)
    left = episode(fps, 7.0, None, hand=(4.2, 5.0), grasp_s=5.0, side="left")
    actions[:, canonical.LEFT.position], actions[:, canonical.LEFT.gripper] = (
        left[:, canonical.LEFT.position], left[:, canonical.LEFT.gripper])
    return actions


@pytest.mark.parametrize("fps", [20, 60])
def test_galt_per_grasp_measures_every_closing(fps):
    actions = two_grasps(fps)
    assert grasp_events(actions) == [("right", round(2.0 * fps)), ("left", round(5.0 * fps))]
    first, second = galt_per_grasp(actions, fps=fps)
    assert (first.arm, second.arm) == ("right", "left")
    assert first.t_grasp_s == pytest.approx(2.0) and second.t_grasp_s == pytest.approx(5.0)
    assert first.galt.reason == "ok" and first.galt.galt_s == pytest.approx(1.0, abs=0.1)
    assert second.galt.reason == "ok" and second.galt.galt_s == pytest.approx(1.5, abs=0.1)
    # the reference looks only at each arm's last gripper change: the right one is the release
    reference = compute_galt(actions, fps=fps)
    assert reference.arm == "left" and reference.per_arm["right"].anchor == round(3.0 * fps)


def test_galt_per_grasp_of_a_single_grasp_equals_the_reference():
    actions = episode(20, 5.0, 1.0, hand=(1.4, 2.0), grasp_s=2.0)
    (grasp,) = galt_per_grasp(actions, fps=20)
    assert grasp.galt == compute_galt(actions, fps=20).per_arm["right"]
    assert galt_per_grasp(actions[:9], fps=20) == []


def peek_then_grasp(fps: float, look_from_s: float = 1.0) -> np.ndarray:
    """The right hand moves to a peek pose (done at `look_from_s`, wrist turned 0.5 rad), looks until 2.0 s,
    reaches 2.0-2.6 s and grasps at 2.6 s; the head is still from the start."""
    actions = episode(fps, 5.0, None, hand=(2.0, 2.6), grasp_s=2.6)
    t = np.arange(len(actions)) / fps
    turn = 0.5 * np.clip(t / look_from_s, 0.0, 1.0)  # about the x axis, reaching look_from_s
    actions[:, canonical.RIGHT.quaternion] = np.stack(
        [np.cos(turn / 2), np.sin(turn / 2), np.zeros_like(t), np.zeros_like(t)], axis=1)
    return actions


@pytest.mark.parametrize("fps", [20, 60])
def test_wrist_lead_is_the_time_from_the_last_look_to_the_grasp(fps):
    (lead,) = wrist_lead_per_grasp(peek_then_grasp(fps), fps=fps)
    assert lead.arm == "right" and lead.reason == "ok"
    assert lead.t_hand_onset_s == pytest.approx(2.0, abs=2 / fps)
    # settled at 1.0 s (refined by up to 0.05 rad / 0.5 rad/s earlier), grasp at 2.6 s
    assert lead.lead_s == pytest.approx(1.6, abs=0.1) and lead.t_settle_s <= 1.0 + 1e-9


def test_wrist_lead_needs_a_still_camera_before_the_reach():
    actions = peek_then_grasp(20, look_from_s=2.0)  # still turning when the reach starts
    assert wrist_lead_per_grasp(actions, fps=20)[0].reason == "no_fixation"


def test_wrist_lead_of_a_hand_resting_since_the_start_is_an_outlier():
    actions = episode(20, 8.0, 0.5, hand=(5.4, 6.0), grasp_s=6.0)
    assert wrist_lead_per_grasp(actions, fps=20)[0].reason == "outlier_high"


def test_wrist_lead_without_hand_onset():
    actions = episode(20, 4.0, 1.0, hand=(1.0, 1.5), grasp_s=2.0)
    assert wrist_lead_per_grasp(actions, fps=20)[0].reason == "no_hand_onset"
