"""Configuration of `act_hand_relative`: ACT's, with requirements on its features and an optional time input."""

from __future__ import annotations

from dataclasses import dataclass

from lerobot.configs.policies import PreTrainedConfig
from lerobot.configs.types import FeatureType, PolicyFeature
from lerobot.policies.act.configuration_act import ACTConfig
from lerobot.utils.constants import ACTION, OBS_ENV_STATE, OBS_STATE

from lerobot_tavis import canonical
from lerobot_tavis.policies.dataset_fit import check_dataset_images

AMP_DTYPES = ("bfloat16", "float16")


@PreTrainedConfig.register_subclass("act_hand_relative")
@dataclass
class ACTHandRelativeConfig(ACTConfig):
    """ACT that predicts each chunk's arm poses relative to the hand pose measured when the chunk is planned.

    The network sees the cameras alone: `observation.state` is read only as the anchor, so it must not be among
    `input_features` (the processors then pass it through un-normalised). The action is TAVIS's canonical 19-D
    vector. Every ACT option keeps its meaning, temporal ensembling included (chunks are turned back into absolute
    actions before they are queued or ensembled).

    `time_input`: the seconds since the episode began as one more encoder input, ACT's `observation.environment_state`
    (added to `input_features`; the dataset's `timestamp` in training, `fps` steps per second counted since `reset()`
    when acting). It tells apart moments whose images are the same, such as the start of an episode while the
    demonstrator looks at what the policy's cameras do not show.

    `amp_dtype`: the precision the network runs in under AMP (`use_amp`, lerobot-train's and lerobot-eval's autocast,
    which is float16 on CUDA): bfloat16 by default, float32's range, because the ResNet starts from random weights
    (no pretrained weights are reachable) under frozen batch norm and nothing bounds its activations: in float16 they
    can overflow and turn the loss NaN for good. "float16" is LeRobot's ACT's precision.
    """

    time_input: bool = False
    fps: float = 20.0  # policy steps per second when acting (TAVIS's rate, envs.physics.POLICY_HZ); training sets
    # the dataset's
    amp_dtype: str = "bfloat16"

    def __post_init__(self):
        super().__post_init__()
        self._check_amp_dtype()

    def validate_features(self) -> None:
        self._check_amp_dtype()  # again: `tavis eval --policy-option` sets fields after construction
        if self.time_input:
            self.input_features.setdefault(OBS_ENV_STATE, PolicyFeature(FeatureType.ENV, (1,)))
        super().validate_features()
        if OBS_STATE in self.input_features:
            raise ValueError(f"act_hand_relative reads {OBS_STATE} only to anchor its chunks and does not feed it to "
                             f"the network: remove {OBS_STATE} from policy.input_features")
        time = self.input_features.get(OBS_ENV_STATE)
        if time is not None and not (self.time_input and tuple(time.shape) == (1,)):
            raise ValueError(f"act_hand_relative's {OBS_ENV_STATE} is its time input, one value (shape (1,)) with "
                             f"time_input=true; got shape {tuple(time.shape)} with time_input={self.time_input}")
        action = self.output_features.get(ACTION)
        if action is None or tuple(action.shape) != (canonical.ACTION_DIM,):
            raise ValueError(f"act_hand_relative needs TAVIS's {canonical.ACTION_DIM}-D canonical {ACTION}, got "
                             f"{None if action is None else tuple(action.shape)}")

    def set_dataset_feature_metadata(self, dataset_features: dict) -> None:
        """lerobot-train's hook (its `make_policy`, given the training dataset): the dataset must hold the cameras
        the policy reads at the size its input_features say, which evaluation renders."""
        check_dataset_images(self.input_features, dataset_features, resizes=False)

    def _check_amp_dtype(self) -> None:
        if self.amp_dtype not in AMP_DTYPES:
            raise ValueError(f"act_hand_relative's amp_dtype must be one of {', '.join(AMP_DTYPES)}; got "
                             f"{self.amp_dtype!r}")
