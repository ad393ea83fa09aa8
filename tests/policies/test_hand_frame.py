"""Arm poses rewritten in the hand's frame and back, checked against MuJoCo's quaternion routines."""

import numpy as np
import torch

from lerobot_tavis import canonical
from lerobot_tavis.envs.transforms import matrix_from_quat, quat_multiply
from lerobot_tavis.policies.hand_frame import from_hand_frame, to_hand_frame


def _random_vectors(rng, *shape) -> np.ndarray:
    """Random 19-D vectors whose quaternion slots hold unit quaternions of either sign."""
    vectors = rng.normal(size=(*shape, canonical.ACTION_DIM))
    for arm in canonical.ARMS:
        quaternions = rng.normal(size=(*shape, 4))
        vectors[..., arm.quaternion] = quaternions / np.linalg.norm(quaternions, axis=-1, keepdims=True)
    return vectors


def test_a_chunk_is_expressed_in_the_hand_frame_of_its_state():
    rng = np.random.default_rng(0)
    actions, state = _random_vectors(rng, 2, 5), _random_vectors(rng, 2)
    relative = to_hand_frame(torch.from_numpy(actions), torch.from_numpy(state)).numpy()
    for b in range(2):
        for t in range(5):
            for arm in canonical.ARMS:
                rotation = matrix_from_quat(state[b, arm.quaternion])
                np.testing.assert_allclose(relative[b, t, arm.position],
                                           rotation.T @ (actions[b, t, arm.position] - state[b, arm.position]),
                                           atol=1e-12)
                turn = quat_multiply(state[b, arm.quaternion] * [1, -1, -1, -1], actions[b, t, arm.quaternion])
                np.testing.assert_allclose(relative[b, t, arm.quaternion], turn * np.sign(turn[0]), atol=1e-12)
            np.testing.assert_array_equal(relative[b, t, 14:], actions[b, t, 14:])  # head and grippers


def test_from_hand_frame_gives_back_the_absolute_poses():
    rng = np.random.default_rng(1)
    actions, state = torch.from_numpy(_random_vectors(rng, 3, 4)), torch.from_numpy(_random_vectors(rng, 3))
    back = from_hand_frame(to_hand_frame(actions, state), state)
    for arm in canonical.ARMS:
        torch.testing.assert_close(back[..., arm.position], actions[..., arm.position])
        same_turn = (back[..., arm.quaternion] * actions[..., arm.quaternion]).sum(-1).abs()
        torch.testing.assert_close(same_turn, torch.ones_like(same_turn))  # q and -q: one orientation
    torch.testing.assert_close(back[..., 14:], actions[..., 14:])


def test_the_hand_pose_itself_is_the_identity_and_a_scaled_turn_is_normalised():
    rng = np.random.default_rng(2)
    state = torch.from_numpy(_random_vectors(rng, 1))
    relative = to_hand_frame(state.unsqueeze(1), state)
    for arm in canonical.ARMS:
        torch.testing.assert_close(relative[0, 0, arm.position], torch.zeros(3, dtype=torch.float64))
        torch.testing.assert_close(relative[0, 0, arm.quaternion], torch.tensor([1.0, 0, 0, 0], dtype=torch.float64))
    relative[..., canonical.LEFT.quaternion] *= 3.0  # a network's turn is not unit
    back = from_hand_frame(relative, state)
    torch.testing.assert_close(back[0, 0, canonical.LEFT.quaternion], state[0, canonical.LEFT.quaternion])
