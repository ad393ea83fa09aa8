"""Configuration of `act_hand_relative`: ACT's, with requirements on its features and optional time and prompt
inputs."""

from __future__ import annotations

from dataclasses import dataclass

from lerobot.configs.policies import PreTrainedConfig
from lerobot.policies.act.configuration_act import ACTConfig
from lerobot.utils.constants import OBS_STATE

from lerobot_tavis.policies.hand_relative import HandRelativeOptions

BACKBONE_NORMS = ("frozen_batch_norm", "group_norm")
GROUP_NORM_CHANNELS = 16  # channels per group of "group_norm" (Diffusion Policy's)


@PreTrainedConfig.register_subclass("act_hand_relative")
@dataclass
class ACTHandRelativeConfig(HandRelativeOptions, ACTConfig):
    """ACT that predicts each chunk's arm poses relative to the hand pose measured when the chunk is planned.

    The network sees the cameras alone (and the time and the prompt, with `time_input` and `prompt_input`:
    `HandRelativeOptions`):
    `observation.state` is read only as the anchor, so it must not be among `input_features` (the processors then
    pass it through un-normalised). The action is TAVIS's canonical 19-D vector. Every ACT option keeps its meaning,
    temporal ensembling included (chunks are turned back into absolute actions before they are queued or
    ensembled). ACT's ResNet keeps ImageNet's batch-norm statistics frozen (`backbone_norm` "frozen_batch_norm"):
    trained from random weights it then has no normalisation at all, hence `amp_dtype` bfloat16 by default;
    "group_norm" puts group normalisation (16 channels a group) in place of each batch norm, as Diffusion Policy's
    `use_group_norm` does, for a ResNet trained from scratch (`pretrained_backbone_weights` None).
    """

    backbone_norm: str = "frozen_batch_norm"

    def __post_init__(self):
        super().__post_init__()
        self._check_backbone_norm()

    def validate_features(self) -> None:
        self._check_backbone_norm()  # again: `tavis eval --policy-option` sets fields after construction
        self._add_env_state_input()
        super().validate_features()
        if OBS_STATE in self.input_features:
            raise ValueError(f"act_hand_relative reads {OBS_STATE} only to anchor its chunks and does not feed it to "
                             f"the network: remove {OBS_STATE} from policy.input_features")
        self._check_hand_relative_features()

    def _check_backbone_norm(self) -> None:
        if self.backbone_norm not in BACKBONE_NORMS:
            raise ValueError(f"act_hand_relative's backbone_norm must be one of {', '.join(BACKBONE_NORMS)}; got "
                             f"{self.backbone_norm!r}")
        if self.backbone_norm == "group_norm" and self.pretrained_backbone_weights is not None:
            raise ValueError(f"act_hand_relative's backbone_norm group_norm trains the ResNet from scratch; "
                             f"pretrained_backbone_weights must be None, got {self.pretrained_backbone_weights!r}")
