"""What every hand-frame policy variant (`act_hand_relative`, `diffusion_hand_relative`) shares: its config options
(time and prompt inputs, AMP precision) and, on the policy, the statistics buffers, those inputs and the conversion
of action chunks between the absolute actions LeRobot's processors normalise and the hand-frame ones the network
learns and predicts.

Around a LeRobot policy's own network: a training chunk of normalised absolute actions is un-normalised with the
dataset's action statistics, rewritten in the hand frame of the chunk's anchor state (`hand_frame`) and normalised
with the statistics of such chunks (`hand_frame_statistics`), in the mode the config's `normalization_mapping`
gives actions (ACT: mean/std; Diffusion Policy: min/max to [-1, 1]); a predicted chunk goes the other way. So what
the policy hands back, and queues, are absolute targets, each reached wherever the hand has moved meanwhile. The
statistics are buffers, saved with the weights.
"""

from __future__ import annotations

from collections.abc import Iterable
from contextlib import nullcontext
from dataclasses import dataclass, field

import numpy as np
import torch
from torch import Tensor

from lerobot.configs.types import FeatureType, NormalizationMode, PolicyFeature
from lerobot.utils.constants import ACTION, OBS_ENV_STATE, OBS_STATE

from lerobot_tavis import canonical
from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS, task_info
from lerobot_tavis.errors import InputError
from lerobot_tavis.policies.dataset_fit import check_dataset_images
from lerobot_tavis.policies.hand_frame import from_hand_frame, to_hand_frame
from lerobot_tavis.policies.hand_frame_statistics import hand_frame_statistics

AMP_DTYPES = ("bfloat16", "float16")
EPS = 1e-8  # as LeRobot's normaliser: (x - mean) / (std + eps); a min/max span of 0 becomes eps
TIME_SCALE_S = 10.0  # the time input is elapsed seconds over this, about 0-2 over a TAVIS episode
MIN_RELATIVE_SPREAD = 1e-4  # m, or quaternion units (0.01 degree): a hand that never moves in the data is not
# scaled up (the floor of a standard deviation, half the floor of a min-max span)
STATISTICS_KEYS = {NormalizationMode.MEAN_STD: ("mean", "std"), NormalizationMode.MIN_MAX: ("min", "max")}


@dataclass
class HandRelativeOptions:
    """Config options of a hand-frame policy (a base before the LeRobot config class).

    `time_input`: the seconds since the episode began as one more network input, `observation.environment_state`
    (added to `input_features`; the dataset's `timestamp` in training, `fps` steps per second counted since `reset()`
    when acting). It tells apart moments whose images are the same, such as the start of an episode while the
    demonstrator looks at what the policy's cameras do not show.

    `prompt_input`: the episode's prompt as one more network input, a one-hot vector over `prompts` in the same
    `observation.environment_state` (after the time, with both): the prompt LeRobot hands every sample and every
    step (`task`: the dataset's and the env's `task_description`). clutter_pick_lift and multi_shelf_scan name the
    object to lift in their prompt alone, and one policy trained on several tasks tells them apart by it.
    `prompts` is the vocabulary, saved with the checkpoint: every distinct prompt of the eight TAVIS tasks unless
    given (clutter_pick_cube and blocked_clutter_pick_cube share theirs). A prompt outside it is refused, naming it.

    `amp_dtype`: the precision the network runs in under AMP (`use_amp`, lerobot-train's and lerobot-eval's autocast,
    which is float16 on CUDA): bfloat16 by default, float32's range, because the ResNet starts from random weights
    (no pretrained weights are reachable) and nothing bounds its activations: in float16 they can overflow and turn
    the loss NaN for good. "float16" is LeRobot's own precision.
    """

    time_input: bool = False
    prompt_input: bool = False
    prompts: list[str] = field(default_factory=list)
    fps: float = 20.0  # policy steps per second when acting (TAVIS's rate, envs.physics.POLICY_HZ); training sets
    # the dataset's
    amp_dtype: str = "bfloat16"

    def __post_init__(self):
        super().__post_init__()
        self._check_amp_dtype()

    def set_dataset_feature_metadata(self, dataset_features: dict) -> None:
        """lerobot-train's hook (its `make_policy`, given the training dataset): the dataset must hold the cameras
        the policy reads and, unless the policy resizes them (`resize_shape`), at the size its input_features say,
        which evaluation renders."""
        check_dataset_images(self.input_features, dataset_features,
                             resizes=getattr(self, "resize_shape", None) is not None)

    def _add_env_state_input(self) -> None:
        """Before the LeRobot config's own `validate_features`: the time and prompt inputs join `input_features` as
        one `observation.environment_state` vector."""
        self._check_amp_dtype()  # again: `tavis eval --policy-option` sets fields after construction
        if self.prompt_input and not self.prompts:
            every_prompt = (prompt for task in BENCHMARK_TASKS for prompt in task_info(task).prompts)
            self.prompts = list(dict.fromkeys(every_prompt))  # in catalog order, each once
        if size := self.env_state_size():
            self.input_features.setdefault(OBS_ENV_STATE, PolicyFeature(FeatureType.ENV, (size,)))

    def env_state_size(self) -> int:
        """Values of `observation.environment_state`: 1 for the time input, one per prompt for the prompt input."""
        return int(self.time_input) + (len(self.prompts) if self.prompt_input else 0)

    def _check_hand_relative_features(self) -> None:
        env_state = self.input_features.get(OBS_ENV_STATE)
        size = self.env_state_size()
        if (env_state is None and size) or (env_state is not None and tuple(env_state.shape) != (size,)):
            raise ValueError(f"{self.type}'s {OBS_ENV_STATE} holds its time input (1 value, time_input="
                             f"{self.time_input}) and prompt input ({len(self.prompts)} values, prompt_input="
                             f"{self.prompt_input}): shape ({size},) expected, got "
                             f"{None if env_state is None else tuple(env_state.shape)}")
        if len(set(self.prompts)) != len(self.prompts):
            raise ValueError(f"{self.type}'s prompts must be distinct")
        action = self.output_features.get(ACTION)
        if action is None or tuple(action.shape) != (canonical.ACTION_DIM,):
            raise ValueError(f"{self.type} needs TAVIS's {canonical.ACTION_DIM}-D canonical {ACTION}, got "
                             f"{None if action is None else tuple(action.shape)}")
        mode = self.normalization_mapping.get(FeatureType.ACTION.value)
        if mode not in STATISTICS_KEYS:
            raise ValueError(f"{self.type} normalises its hand-frame actions as the processors do the absolute ones, "
                             f"with {' or '.join(m.value for m in STATISTICS_KEYS)}; normalization_mapping.ACTION is "
                             f"{getattr(mode, 'value', mode)}")

    def _check_amp_dtype(self) -> None:
        if self.amp_dtype not in AMP_DTYPES:
            raise ValueError(f"{self.type}'s amp_dtype must be one of {', '.join(AMP_DTYPES)}; got "
                             f"{self.amp_dtype!r}")


class HandRelativeChunks:
    """Policy side (a base before the LeRobot policy class): statistics buffers, chunk conversion, time input, AMP
    precision. The subclass calls `_register_statistics` in its `__init__` after the LeRobot policy's."""

    def _register_statistics(self, dataset_stats: dict | None, dataset_meta, chunk_offsets: Iterable[int],
                             state_statistics: bool = False) -> None:
        """Buffers `absolute_<a>`, `absolute_<b>`, `relative_<a>`, `relative_<b>` (<a>, <b>: mean, std or min, max,
        as actions are normalised), and with `state_statistics` `state_min`, `state_max`: NaN until filled from the
        dataset (`dataset_stats`, and `dataset_meta.root`'s data files for the hand-frame chunks of `chunk_offsets`,
        the actions a training chunk holds relative to its anchor's frame) or loaded from a checkpoint."""
        keys = STATISTICS_KEYS[self._mode("absolute")]
        names = [f"{kind}_{key}" for kind in ("absolute", "relative") for key in keys]
        names += ["state_min", "state_max"] if state_statistics else []
        self._statistics = tuple(names)
        for buffer in self._statistics:
            self.register_buffer(buffer, torch.full((canonical.ACTION_DIM,), float("nan")))
        self._statistics_checked = False
        if dataset_meta is not None:
            self.config.fps = float(dataset_meta.fps)
        if dataset_stats is None or dataset_meta is None:
            return
        relative = hand_frame_statistics(dataset_meta.root, chunk_offsets)
        if "std" in keys:
            relative["std"] = np.maximum(relative["std"], MIN_RELATIVE_SPREAD)
        else:
            middle = (relative["min"] + relative["max"]) / 2
            half = np.maximum((relative["max"] - relative["min"]) / 2, MIN_RELATIVE_SPREAD)
            relative["min"], relative["max"] = middle - half, middle + half
        values = {f"absolute_{key}": dataset_stats[ACTION][key] for key in keys}
        values |= {f"relative_{key}": relative[key] for key in keys}
        if state_statistics:
            values |= {f"state_{key}": dataset_stats[OBS_STATE][key] for key in ("min", "max")}
        for buffer, value in values.items():
            getattr(self, buffer).copy_(torch.as_tensor(np.asarray(value, dtype=np.float32)))

    def reset(self):
        """Called at the start of every episode: the time input counts from here."""
        super().reset()
        self._elapsed_steps = 0

    def _to_network_chunk(self, actions: Tensor, anchor: Tensor) -> Tensor:
        """Normalised absolute actions (B, T, 19), as the processors give them, -> the network's target: the same
        chunk in the hand frame of `anchor` (B, 19, raw canonical state), normalised with the relative statistics."""
        self._check_statistics()
        absolute = self._unnormalise(actions.float(), "absolute")
        return self._normalise(to_hand_frame(absolute, anchor.float()), "relative")

    def _from_network_chunk(self, relative: Tensor, anchor: Tensor) -> Tensor:
        """Inverse of `_to_network_chunk`: the network's chunk (B, T, 19) -> normalised absolute actions, float32
        whatever precision the network ran in (a half-precision position would be off by a tenth of a millimetre)."""
        absolute = from_hand_frame(self._unnormalise(relative.float(), "relative"), anchor.float())
        return self._normalise(absolute, "absolute")

    def _normalise(self, values: Tensor, kind: str) -> Tensor:
        """LeRobot's normalisation of `values` with the `kind` (absolute, relative, state) statistics buffers."""
        first, second = self._statistics_of(kind)
        if self._mode(kind) == NormalizationMode.MIN_MAX:
            return 2 * (values - first) / self._span(first, second) - 1
        return (values - first) / (second + EPS)

    def _unnormalise(self, values: Tensor, kind: str) -> Tensor:
        first, second = self._statistics_of(kind)
        if self._mode(kind) == NormalizationMode.MIN_MAX:
            return (values + 1) / 2 * self._span(first, second) + first
        return values * (second + EPS) + first

    def _mode(self, kind: str) -> NormalizationMode:
        """States are normalised as Diffusion Policy's processors would (min/max), actions as the config says."""
        if kind == "state":
            return NormalizationMode.MIN_MAX
        return NormalizationMode(self.config.normalization_mapping[FeatureType.ACTION.value])

    def _statistics_of(self, kind: str) -> tuple[Tensor, Tensor]:
        return tuple(getattr(self, f"{kind}_{key}") for key in STATISTICS_KEYS[self._mode(kind)])

    @staticmethod
    def _span(low: Tensor, high: Tensor) -> Tensor:
        span = high - low
        return torch.where(span == 0, torch.full_like(span, EPS), span)

    def _elapsed_time(self, batch_size: int, like: Tensor) -> Tensor:
        """The time input (B, 1) when acting: the steps `select_action` has taken since `reset()` over `config.fps`."""
        return self._time_token(torch.full((batch_size,), self._elapsed_steps / self.config.fps), like)

    def _acting_env_state(self, batch: dict, state: Tensor) -> Tensor:
        """`observation.environment_state` (B, E) when acting on `batch`, whose raw state is `state` (B, 19): the
        steps since `reset()` and the batch's prompts (`task`), as the config asks."""
        time = self._elapsed_time(state.shape[0], state) if self.config.time_input else None
        return self._env_state(time, batch.get("task"), state)

    def _env_state(self, time: Tensor | None, prompts: list[str] | None, like: Tensor,
                   steps: int | None = None) -> Tensor:
        """`observation.environment_state`, (B, E), or (B, steps, E) for Diffusion Policy's observation steps: the
        time input (B, 1) or (B, steps, 1) as given (None without it), then the prompt input, one-hot over
        `config.prompts`, the same at every step."""
        parts = [] if time is None else [time]
        if self.config.prompt_input:
            if prompts is None:
                raise InputError(f"{self.name} reads the episode's prompt (prompt_input): the batch holds no `task`")
            row_of = {prompt: row for row, prompt in enumerate(self.config.prompts)}
            unknown = sorted(set(prompts) - set(row_of))
            if unknown:
                raise InputError(f"{self.name} was trained on {len(self.config.prompts)} prompts; {unknown[0]!r} is "
                                 "not one of them")
            rows = torch.tensor([row_of[prompt] for prompt in prompts], device=like.device)
            one_hot = torch.nn.functional.one_hot(rows, len(self.config.prompts)).to(torch.float32)
            parts.append(one_hot if steps is None else one_hot.unsqueeze(1).expand(-1, steps, -1))
        return torch.cat(parts, dim=-1)

    @staticmethod
    def _time_token(elapsed_s: Tensor, like: Tensor) -> Tensor:
        """The time input (..., 1) from seconds since the episode began (...), on `like`'s device, float32."""
        return (elapsed_s.to(device=like.device, dtype=torch.float32) / TIME_SCALE_S).unsqueeze(-1)

    def _amp_precision(self, device: torch.device):
        """Under AMP (autocast on `device`), autocast in `config.amp_dtype` instead; otherwise nothing changes."""
        if not torch.is_autocast_enabled(device.type):
            return nullcontext()
        return torch.autocast(device.type, dtype=getattr(torch, self.config.amp_dtype))

    def _check_statistics(self) -> None:
        if self._statistics_checked:
            return
        for buffer in self._statistics:
            if not torch.isfinite(getattr(self, buffer)).all():
                raise RuntimeError(f"{self.name} has no {buffer}: build it for training with the dataset "
                                   "(LeRobot's make_policy(cfg, ds_meta=...)) or load a checkpoint that holds it")
        self._statistics_checked = True
