"""Configuration of `diffusion_hand_relative`: Diffusion Policy's, with the state left raw by the processors, a
choice of what the network sees of it, and optional time and prompt inputs."""

from __future__ import annotations

from dataclasses import dataclass, field

from lerobot.configs.policies import PreTrainedConfig
from lerobot.configs.types import FeatureType, NormalizationMode
from lerobot.policies.diffusion.configuration_diffusion import DiffusionConfig
from lerobot.utils.constants import OBS_STATE

from lerobot_tavis import canonical
from lerobot_tavis.policies.hand_relative import HandRelativeOptions

STATE_INPUTS = ("none", "invariant", "absolute")


@PreTrainedConfig.register_subclass("diffusion_hand_relative")
@dataclass
class DiffusionHandRelativeConfig(HandRelativeOptions, DiffusionConfig):
    """Diffusion Policy that denoises each horizon's arm poses relative to the hand pose measured at the step the
    chunk is planned from (the last of its `n_obs_steps` observations).

    `observation.state` (TAVIS's canonical 19-D state) must be among `input_features`: Diffusion Policy's network
    always reads one, and the policy anchors its chunks on it. The processors leave it raw (`normalization_mapping`
    STATE: IDENTITY), so the anchor is the measured pose itself, not one un-normalised back from [-1, 1]; the policy
    then builds what the network sees of each observation's state (`state_input`):

    - "none" (default): nothing (zeros), as `act_hand_relative`, whose network sees no state: a policy that reads
      where its hands are copies that more than it looks.
    - "invariant": the head angles and grippers, which stay absolute in the hand-frame action, normalised to
      [-1, 1] with the dataset's min and max; both arms' poses zero.
    - "absolute": the whole state so normalised, as Diffusion Policy's processors would.

    Actions are normalised with min and max (to [-1, 1], which `clip_sample` keeps denoised samples in), the
    hand-frame ones with the min and max of every training horizon's actions in their anchor's frame.
    `time_input`, `prompt_input`, `prompts`, `fps`, `amp_dtype`: `HandRelativeOptions`.
    """

    state_input: str = "none"
    normalization_mapping: dict[str, NormalizationMode] = field(
        default_factory=lambda: {
            "VISUAL": NormalizationMode.MEAN_STD,
            "STATE": NormalizationMode.IDENTITY,
            "ACTION": NormalizationMode.MIN_MAX,
        }
    )

    def __post_init__(self):
        super().__post_init__()
        self._check_state_input()

    def validate_features(self) -> None:
        self._add_env_state_input()
        self._check_state_input()  # again: `tavis eval --policy-option` sets fields after construction
        super().validate_features()
        state = self.input_features.get(OBS_STATE)
        if state is None or tuple(state.shape) != (canonical.ACTION_DIM,):
            raise ValueError(f"diffusion_hand_relative anchors its chunks on TAVIS's {canonical.ACTION_DIM}-D "
                             f"{OBS_STATE}, which policy.input_features must hold; got "
                             f"{None if state is None else tuple(state.shape)}")
        if self.normalization_mapping.get(FeatureType.STATE.value) != NormalizationMode.IDENTITY:
            raise ValueError(f"diffusion_hand_relative anchors its chunks on the raw {OBS_STATE}: "
                             "normalization_mapping.STATE must be IDENTITY (state_input chooses what the network "
                             "sees of it)")
        self._check_hand_relative_features()

    def _check_state_input(self) -> None:
        if self.state_input not in STATE_INPUTS:
            raise ValueError(f"diffusion_hand_relative's state_input must be one of {', '.join(STATE_INPUTS)}; got "
                             f"{self.state_input!r}")
