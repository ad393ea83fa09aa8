"""`diffusion_hand_relative`: Diffusion Policy trained on, and denoising, horizons whose arm poses are in the hand's
frame.

Tensors and their frames. In training, a batch holds `n_obs_steps` observations t-(n_obs_steps-1)..t (images,
`observation.state` raw canonical states (B, n_obs_steps, 19)) and a horizon of actions from t-(n_obs_steps-1)
on, normalised absolute (B, horizon, 19) as the processors give them; the whole horizon is rewritten in the hand
frame of the state at t, the current step (`hand_relative`), which the network learns to denoise. Acting, the
network's horizon is turned back into absolute actions anchored on the raw state of the step it is planned from,
and Diffusion Policy queues the `n_action_steps` of them from that step on. What the network sees of the states:
`config.state_input`.
"""

from __future__ import annotations

from collections import deque

import torch
from torch import Tensor

from lerobot.policies.diffusion.modeling_diffusion import DiffusionPolicy
from lerobot.utils.constants import ACTION, OBS_ENV_STATE, OBS_STATE

from lerobot_tavis import canonical
from lerobot_tavis.policies.diffusion_hand_relative.configuration_diffusion_hand_relative import (
    DiffusionHandRelativeConfig,
)
from lerobot_tavis.policies.hand_relative import HandRelativeChunks

ANCHOR = "hand_frame_anchor"  # queue of the raw state (B, 19) of the latest step: the next chunk's anchor
ARM_POSES = [i for arm in canonical.ARMS for i in range(arm.position.start, arm.quaternion.stop)]


class DiffusionHandRelativePolicy(HandRelativeChunks, DiffusionPolicy):
    config_class = DiffusionHandRelativeConfig
    name = "diffusion_hand_relative"

    def __init__(self, config: DiffusionHandRelativeConfig, dataset_stats: dict | None = None, dataset_meta=None,
                 **kwargs):
        """Built for training with the dataset's statistics (`dataset_stats`) and files (`dataset_meta.root`), as
        LeRobot's `make_policy` passes them; `from_pretrained` builds it without and loads the saved buffers."""
        super().__init__(config, **kwargs)
        self._register_statistics(dataset_stats, dataset_meta, config.action_delta_indices, state_statistics=True)

    def reset(self):
        super().reset()
        self._queues[ANCHOR] = deque(maxlen=1)

    def forward(self, batch: dict[str, Tensor]) -> tuple[Tensor, None]:
        """Diffusion Policy's loss on the horizon rewritten in the hand frame of the current (last observed)
        state; with the time input, `batch["timestamp"]` (B,) is the current step's."""
        anchor = batch[OBS_STATE][:, -1]
        batch = {**self._network_observations(batch), ACTION: self._to_network_chunk(batch[ACTION], anchor)}
        with self._amp_precision(anchor.device):
            return super().forward(batch)

    @torch.no_grad()
    def select_action(self, batch: dict[str, Tensor], noise: Tensor | None = None) -> Tensor:
        """One step's observation (raw state (B, 19)) -> a normalised absolute action (B, 19)."""
        state = batch[OBS_STATE]
        batch = {**batch, ANCHOR: state, OBS_STATE: self._network_state(state)}
        if self.config.env_state_size():
            batch[OBS_ENV_STATE] = self._acting_env_state(batch, state)
        action = super().select_action(batch, noise=noise)
        self._elapsed_steps += 1
        return action

    @torch.no_grad()
    def predict_action_chunk(self, batch: dict[str, Tensor], noise: Tensor | None = None) -> Tensor:
        """Normalised absolute actions (B, n_action_steps, 19) from the current step on, anchored on its raw state.
        Acting (`select_action`), the observations come from the queues; given a dataset batch instead (raw state
        (B, n_obs_steps, 19), and `timestamp` with the time input), from it."""
        self._check_statistics()
        if ANCHOR in batch:
            anchor = self._queues[ANCHOR][-1]
        else:
            anchor = batch[OBS_STATE][:, -1]
            batch = self._network_observations(batch)
        with self._amp_precision(anchor.device):
            relative = super().predict_action_chunk(batch, noise=noise)
        return self._from_network_chunk(relative, anchor)

    def _network_observations(self, batch: dict[str, Tensor]) -> dict[str, Tensor]:
        """A dataset batch's observations as the network reads them: the state by `config.state_input` and, with
        the time input, each observation's seconds since the episode began, from the current step's `timestamp`
        back by 1/fps a step and held at 0 before the episode (where LeRobot repeats its first frame), and with the
        prompt input the one-hot of `batch["task"]` at every step."""
        state = batch[OBS_STATE]
        batch = {**batch, OBS_STATE: self._network_state(state)}
        if self.config.env_state_size():
            time = None
            if self.config.time_input:
                steps_back = torch.arange(self.config.n_obs_steps - 1, -1, -1, device=state.device)
                elapsed_s = batch["timestamp"].to(state.device).unsqueeze(-1) - steps_back / self.config.fps
                time = self._time_token(elapsed_s.clamp_min(0.0), state)
            batch[OBS_ENV_STATE] = self._env_state(time, batch.get("task"), state, steps=self.config.n_obs_steps)
        return batch

    def _network_state(self, state: Tensor) -> Tensor:
        """Raw canonical states (..., 19) -> what the network sees of them (`DiffusionHandRelativeConfig`)."""
        if self.config.state_input == "none":
            return torch.zeros_like(state, dtype=torch.float32)
        self._check_statistics()
        normalised = self._normalise(state.float(), "state")
        if self.config.state_input == "invariant":
            normalised[..., ARM_POSES] = 0.0
        return normalised

