"""benchmarks/grasp_tolerance.py: a demonstration replayed with its grasping arm shifted succeeds unshifted and
after a moment's hold, and fails when the hand is sent far below the grasp or turned round."""

import numpy as np

from lerobot_tavis import canonical
from lerobot_tavis.dataset_tools.raw import Manifest, load_episode
from lerobot_tavis.envs.transforms import axis_angle_quat, quat_multiply


def test_the_grasping_arm_is_found_and_a_hand_sent_far_below_the_grasp_fails(benchmark_script, conditional_pick_raw):
    probe = benchmark_script("grasp_tolerance")
    entry = next(e for e in Manifest.load(conditional_pick_raw).episodes if e.file)
    path = str(conditional_pick_raw / entry.file)
    actions = load_episode(path).actions
    arm = probe.grasping_arm(actions)
    idle = next(a for a in canonical.ARMS if a is not arm)
    assert np.ptp(actions[:, arm.position], axis=0).max() > np.ptp(actions[:, idle.position], axis=0).max()

    (unshifted, far_below, no_turn, half_turn), moved_m, margin_m = probe.replay_shifted(
        path, [np.zeros(3), np.array([0.0, 0.0, -0.08])], hold_s=1.0,
        rotations=[axis_angle_quat((0, 0, 1), 0.0), axis_angle_quat((0, 0, 1), np.pi)])
    assert unshifted[0] and not far_below[0] and unshifted[1] < 0.05
    assert no_turn == unshifted and not half_turn[0]  # a hand turned round cannot grasp

    side, quaternion = probe.grasp_orientation(actions)
    assert side == arm.side and np.isclose(np.linalg.norm(quaternion), 1.0)
    turned = quat_multiply(axis_angle_quat((1, 0, 0), np.radians(30.0)), quaternion)
    assert np.allclose(probe.orientation_spread_deg([quaternion, quaternion, turned]), [0.0, 0.0, 30.0], atol=1e-4)
    assert 0.0 <= moved_m < 0.1 and 0.0 < margin_m < 0.05  # recordings end the moment the object is past the line
