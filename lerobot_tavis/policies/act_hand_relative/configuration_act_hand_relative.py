"""Configuration of `act_hand_relative`: ACT's, with requirements on its features and an optional time input."""

from __future__ import annotations

from dataclasses import dataclass

from lerobot.configs.policies import PreTrainedConfig
from lerobot.policies.act.configuration_act import ACTConfig
from lerobot.utils.constants import OBS_STATE

from lerobot_tavis.policies.hand_relative import HandRelativeOptions


@PreTrainedConfig.register_subclass("act_hand_relative")
@dataclass
class ACTHandRelativeConfig(HandRelativeOptions, ACTConfig):
    """ACT that predicts each chunk's arm poses relative to the hand pose measured when the chunk is planned.

    The network sees the cameras alone (and the time, with `time_input`: `HandRelativeOptions`):
    `observation.state` is read only as the anchor, so it must not be among `input_features` (the processors then
    pass it through un-normalised). The action is TAVIS's canonical 19-D vector. Every ACT option keeps its meaning,
    temporal ensembling included (chunks are turned back into absolute actions before they are queued or
    ensembled). The ResNet runs under frozen batch norm, hence `amp_dtype` bfloat16 by default.
    """

    def validate_features(self) -> None:
        self._add_time_input()
        super().validate_features()
        if OBS_STATE in self.input_features:
            raise ValueError(f"act_hand_relative reads {OBS_STATE} only to anchor its chunks and does not feed it to "
                             f"the network: remove {OBS_STATE} from policy.input_features")
        self._check_hand_relative_features()
