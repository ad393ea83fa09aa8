"""`act_hand_relative`: ACT trained on, and predicting, chunks whose arm poses are in the hand's frame.

Around ACT's own network (`lerobot_tavis.policies.hand_relative`): a training chunk (actions t..t+chunk_size-1) is
rewritten in the hand frame of its state at t, a predicted chunk turned back into absolute actions anchored on the
state it was planned from, before ACT queues (or ensembles) it. The processors are ACT's (mean/std).
"""

from __future__ import annotations

import torch
from torch import Tensor, nn
from torchvision.ops.misc import FrozenBatchNorm2d

from lerobot.policies.act.modeling_act import ACTPolicy
from lerobot.utils.constants import ACTION, OBS_ENV_STATE, OBS_STATE

from lerobot_tavis.policies.act_hand_relative.configuration_act_hand_relative import (GROUP_NORM_CHANNELS,
                                                                                      ACTHandRelativeConfig)
from lerobot_tavis.policies.hand_relative import HandRelativeChunks


class ACTHandRelativePolicy(HandRelativeChunks, ACTPolicy):
    config_class = ACTHandRelativeConfig
    name = "act_hand_relative"

    def __init__(self, config: ACTHandRelativeConfig, dataset_stats: dict | None = None, dataset_meta=None,
                 **kwargs):
        """Built for training with the dataset's statistics (`dataset_stats`) and files (`dataset_meta.root`), as
        LeRobot's `make_policy` passes them; `from_pretrained` builds it without and loads the saved buffers."""
        super().__init__(config, **kwargs)
        if config.backbone_norm == "group_norm" and config.image_features:
            _group_normalise(self.model.backbone)
        self._register_statistics(dataset_stats, dataset_meta, range(config.chunk_size))

    def forward(self, batch: dict[str, Tensor]) -> tuple[Tensor, dict]:
        """ACT's loss on the chunk (normalised absolute actions in `batch`, state (B, 19) raw) rewritten in the hand
        frame of the state; with the time and prompt inputs, from `batch["timestamp"]` (B,) and `batch["task"]`."""
        batch = {**batch, ACTION: self._to_network_chunk(batch[ACTION], batch[OBS_STATE])}
        if self.config.env_state_size():
            time = self._time_token(batch["timestamp"], batch[ACTION]) if self.config.time_input else None
            batch[OBS_ENV_STATE] = self._env_state(time, batch.get("task"), batch[ACTION])
        with self._amp_precision(batch[ACTION].device):
            return super().forward(batch)

    @torch.no_grad()
    def select_action(self, batch: dict[str, Tensor]) -> Tensor:
        action = super().select_action(batch)
        self._elapsed_steps += 1
        return action

    @torch.no_grad()
    def predict_action_chunk(self, batch: dict[str, Tensor]) -> Tensor:
        """A chunk of normalised absolute actions (B, chunk_size, 19), anchored on `batch`'s raw state (B, 19)."""
        self._check_statistics()
        state = batch[OBS_STATE]
        if self.config.env_state_size():
            batch = {**batch, OBS_ENV_STATE: self._acting_env_state(batch, state)}
        with self._amp_precision(state.device):
            relative = super().predict_action_chunk(batch)
        return self._from_network_chunk(relative, state)


def _group_normalise(module: nn.Module) -> None:
    """Puts a GroupNorm (GROUP_NORM_CHANNELS channels a group, unit scale, zero shift) in place of every frozen
    batch norm under `module`."""
    for name, child in module.named_children():
        if isinstance(child, FrozenBatchNorm2d):
            channels = child.weight.shape[0]
            setattr(module, name, nn.GroupNorm(channels // GROUP_NORM_CHANNELS, channels))
        else:
            _group_normalise(child)
