"""`act_hand_relative`: ACT trained on, and predicting, chunks whose arm poses are in the hand's frame.

LeRobot's processors normalise absolute actions with the dataset's statistics. Around ACT's own network this policy
turns a training chunk into the hand frame of the chunk's state (`lerobot_tavis.policies.hand_frame`) and normalises
it with statistics of such chunks; a predicted chunk goes the other way, anchored on the state it was planned from,
before ACT queues (or ensembles) it. So the queue holds absolute targets, and each is reached wherever the hand
has moved meanwhile. The four statistics vectors are buffers, saved with the weights.
"""

from __future__ import annotations

from contextlib import nullcontext

import numpy as np
import torch
from torch import Tensor

from lerobot.policies.act.modeling_act import ACTPolicy
from lerobot.utils.constants import ACTION, OBS_ENV_STATE, OBS_STATE

from lerobot_tavis import canonical
from lerobot_tavis.policies.act_hand_relative.configuration_act_hand_relative import ACTHandRelativeConfig
from lerobot_tavis.policies.act_hand_relative.statistics import hand_frame_statistics
from lerobot_tavis.policies.hand_frame import from_hand_frame, to_hand_frame

EPS = 1e-8  # as LeRobot's normaliser: (x - mean) / (std + eps)
TIME_SCALE_S = 10.0  # the time input is elapsed seconds over this, about 0-2 over a TAVIS episode
STATISTICS = ("absolute_mean", "absolute_std", "relative_mean", "relative_std")  # buffers, saved with the weights
MIN_RELATIVE_STD = 1e-4  # m, or quaternion units (0.01 degree): a hand that never moves in the data is not scaled up


class ACTHandRelativePolicy(ACTPolicy):
    config_class = ACTHandRelativeConfig
    name = "act_hand_relative"

    def __init__(self, config: ACTHandRelativeConfig, dataset_stats: dict | None = None, dataset_meta=None,
                 **kwargs):
        """Built for training with the dataset's statistics (`dataset_stats`) and files (`dataset_meta.root`), as
        LeRobot's `make_policy` passes them; `from_pretrained` builds it without and loads the saved buffers."""
        super().__init__(config, **kwargs)
        for buffer in STATISTICS:
            self.register_buffer(buffer, torch.full((canonical.ACTION_DIM,), float("nan")))
        self._statistics_checked = False
        if dataset_meta is not None:
            config.fps = float(dataset_meta.fps)
        if dataset_stats is not None and dataset_meta is not None:
            relative_mean, relative_std = hand_frame_statistics(dataset_meta.root, config.chunk_size)
            relative_std = np.maximum(relative_std, MIN_RELATIVE_STD)
            for buffer, values in (("absolute_mean", dataset_stats[ACTION]["mean"]),
                                   ("absolute_std", dataset_stats[ACTION]["std"]),
                                   ("relative_mean", relative_mean), ("relative_std", relative_std)):
                getattr(self, buffer).copy_(torch.as_tensor(np.asarray(values, dtype=np.float32)))

    def reset(self):
        """Called at the start of every episode: the time input counts from here."""
        super().reset()
        self._elapsed_steps = 0

    def forward(self, batch: dict[str, Tensor]) -> tuple[Tensor, dict]:
        """ACT's loss on the chunk (normalised absolute actions in `batch`) rewritten in the hand frame."""
        self._check_statistics()
        absolute = batch[ACTION].float() * (self.absolute_std + EPS) + self.absolute_mean
        relative = to_hand_frame(absolute, batch[OBS_STATE].float())
        batch = {**batch, ACTION: (relative - self.relative_mean) / (self.relative_std + EPS)}
        if self.config.time_input:
            batch[OBS_ENV_STATE] = self._time_token(batch["timestamp"], batch[ACTION])
        with self._amp_precision(relative.device):
            return super().forward(batch)

    @torch.no_grad()
    def select_action(self, batch: dict[str, Tensor]) -> Tensor:
        action = super().select_action(batch)
        self._elapsed_steps += 1
        return action

    @torch.no_grad()
    def predict_action_chunk(self, batch: dict[str, Tensor]) -> Tensor:
        """A chunk of normalised absolute actions (B, chunk_size, 19), anchored on `batch`'s state; float32 whatever
        precision the network ran in (a half-precision position would be off by a tenth of a millimetre). The time
        input, if any, is the steps `select_action` has taken since `reset()` over `config.fps`."""
        self._check_statistics()
        if self.config.time_input:
            state = batch[OBS_STATE]
            elapsed_s = torch.full(state.shape[:1], self._elapsed_steps / self.config.fps)
            batch = {**batch, OBS_ENV_STATE: self._time_token(elapsed_s, state)}
        with self._amp_precision(batch[OBS_STATE].device):
            relative = super().predict_action_chunk(batch).float()
        relative = relative * (self.relative_std + EPS) + self.relative_mean
        absolute = from_hand_frame(relative, batch[OBS_STATE].float())
        return (absolute - self.absolute_mean) / (self.absolute_std + EPS)

    def _amp_precision(self, device: torch.device):
        """Under AMP (autocast on `device`), autocast in `config.amp_dtype` instead; otherwise nothing changes."""
        if not torch.is_autocast_enabled(device.type):
            return nullcontext()
        return torch.autocast(device.type, dtype=getattr(torch, self.config.amp_dtype))

    @staticmethod
    def _time_token(elapsed_s: Tensor, like: Tensor) -> Tensor:
        """The time input (B, 1) from seconds since the episode began (B,), on `like`'s device, float32."""
        return (elapsed_s.to(device=like.device, dtype=torch.float32) / TIME_SCALE_S).unsqueeze(-1)

    def _check_statistics(self) -> None:
        if self._statistics_checked:
            return
        for buffer in STATISTICS:
            if not torch.isfinite(getattr(self, buffer)).all():
                raise RuntimeError(f"act_hand_relative has no {buffer}: build it for training with the dataset "
                                   "(LeRobot's make_policy(cfg, ds_meta=...)) or load a checkpoint that holds it")
        self._statistics_checked = True
