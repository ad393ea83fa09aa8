"""Arm actions expressed in the hand's own frame at the time they are planned (torch, batched).

An absolute arm target (position p_a and quaternion q_a in the canonical hip frame; layout:
`lerobot_tavis.canonical`) is rewritten relative to the measured hand pose (p_s, q_s) of `observation.state`:

    p_rel = R(q_s)^T (p_a - p_s)        metres, along the hand's own axes
    q_rel = q_s^-1 * q_a                 the turn from the hand's orientation to the target's, sign w >= 0

and back: p_a = p_s + R(q_s) p_rel, q_a = q_s * q_rel / |q_rel|. A whole chunk of actions is anchored on the one
state it was planned from. Head angles and grippers stay absolute. Quaternions are w, x, y, z.
"""

from __future__ import annotations

import torch
from torch import Tensor

from lerobot_tavis import canonical


def to_hand_frame(actions: Tensor, state: Tensor) -> Tensor:
    """Absolute actions (..., T, 19) -> the same with both arms' poses relative to `state` (..., 19)."""
    relative = actions.clone()
    for arm in canonical.ARMS:
        position, quaternion = _hand_pose(state, arm)
        relative[..., arm.position] = _rotate(_conjugate(quaternion), actions[..., arm.position] - position)
        relative[..., arm.quaternion] = _positive_w(_multiply(_conjugate(quaternion), actions[..., arm.quaternion]))
    return relative


def from_hand_frame(relative: Tensor, state: Tensor) -> Tensor:
    """Inverse of `to_hand_frame`: actions (..., T, 19) relative to `state` (..., 19) -> absolute actions."""
    actions = relative.clone()
    for arm in canonical.ARMS:
        position, quaternion = _hand_pose(state, arm)
        turn = relative[..., arm.quaternion]
        turn = turn / turn.norm(dim=-1, keepdim=True).clamp_min(1e-12)
        actions[..., arm.position] = position + _rotate(quaternion, relative[..., arm.position])
        actions[..., arm.quaternion] = _multiply(quaternion, turn)
    return actions


def _hand_pose(state: Tensor, arm: canonical.ArmSlots) -> tuple[Tensor, Tensor]:
    """One arm's measured position (..., 1, 3) and unit quaternion (..., 1, 4), shaped to broadcast over a chunk."""
    quaternion = state[..., arm.quaternion]
    quaternion = quaternion / quaternion.norm(dim=-1, keepdim=True).clamp_min(1e-12)
    return state[..., arm.position].unsqueeze(-2), quaternion.unsqueeze(-2)


def _conjugate(quaternion: Tensor) -> Tensor:
    return torch.cat([quaternion[..., :1], -quaternion[..., 1:]], dim=-1)


def _multiply(a: Tensor, b: Tensor) -> Tensor:
    """Hamilton products a * b (broadcast): rotate by b, then by a."""
    aw, av, bw, bv = a[..., :1], a[..., 1:], b[..., :1], b[..., 1:]
    av, bv = torch.broadcast_tensors(av, bv)
    w = aw * bw - (av * bv).sum(dim=-1, keepdim=True)
    return torch.cat([w, aw * bv + bw * av + torch.linalg.cross(av, bv, dim=-1)], dim=-1)


def _rotate(quaternion: Tensor, vector: Tensor) -> Tensor:
    """Vectors (..., 3) rotated by unit quaternions (..., 4), broadcast."""
    w, u = quaternion[..., :1], quaternion[..., 1:]
    u, vector = torch.broadcast_tensors(u, vector)
    twice_cross = 2.0 * torch.linalg.cross(u, vector, dim=-1)
    return vector + w * twice_cross + torch.linalg.cross(u, twice_cross, dim=-1)


def _positive_w(quaternion: Tensor) -> Tensor:
    return torch.where(quaternion[..., :1] < 0, -quaternion, quaternion)
