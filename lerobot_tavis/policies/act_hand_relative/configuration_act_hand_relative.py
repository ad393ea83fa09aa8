"""Configuration of `act_hand_relative`: ACT's, with two more requirements on its features."""

from __future__ import annotations

from dataclasses import dataclass

from lerobot.configs.policies import PreTrainedConfig
from lerobot.policies.act.configuration_act import ACTConfig
from lerobot.utils.constants import ACTION, OBS_STATE

from lerobot_tavis import canonical


@PreTrainedConfig.register_subclass("act_hand_relative")
@dataclass
class ACTHandRelativeConfig(ACTConfig):
    """ACT that predicts each chunk's arm poses relative to the hand pose measured when the chunk is planned.

    The network sees the cameras alone: `observation.state` is read only as the anchor, so it must not be among
    `input_features` (the processors then pass it through un-normalised). The action is TAVIS's canonical 19-D
    vector. Every ACT option keeps its meaning, temporal ensembling included (chunks are turned back into absolute
    actions before they are queued or ensembled).
    """

    def validate_features(self) -> None:
        super().validate_features()
        if OBS_STATE in self.input_features:
            raise ValueError(f"act_hand_relative reads {OBS_STATE} only to anchor its chunks and does not feed it to "
                             f"the network: remove {OBS_STATE} from policy.input_features")
        action = self.output_features.get(ACTION)
        if action is None or tuple(action.shape) != (canonical.ACTION_DIM,):
            raise ValueError(f"act_hand_relative needs TAVIS's {canonical.ACTION_DIM}-D canonical {ACTION}, got "
                             f"{None if action is None else tuple(action.shape)}")
