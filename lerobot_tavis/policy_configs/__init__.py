"""Training presets for `lerobot-train --config_path=<preset>`: pi0 and Diffusion Policy x camera modes, and compact
presets for the paper's two camera conditions.

Each preset is a partial LeRobot `TrainPipelineConfig` (JSON, shipped with the package) following the reference's
hyper-parameters (docs/reference.md §10) in LeRobot 0.6 fields: an action chunk of 16 of which 8 are executed at 20 Hz,
batch 16; diffusion with 2 observation steps, lr 1e-4 and images resized to 240x320; pi0 fine-tuned from
`lerobot/pi0_base` with lr 2.5e-5. The policy sees only its camera mode's images plus the canonical state
(`input_features`), and `env.type=tavis` with the same camera mode makes lerobot-train's periodic evaluation run on
TAVIS. Override anything on the command line (`--dataset.repo_id=... --dataset.root=... --steps=...`).

- Diffusion presets train offline: the ResNet-18 encoder starts from random weights with group norm. For the
  reference's ImageNet start (downloaded from download.pytorch.org) add
  `--policy.pretrained_backbone_weights=ResNet18_Weights.IMAGENET1K_V1 --policy.use_group_norm=false`.
- Fixed-camera presets (`fixed_wrist`, `fixed_only`) train on a dataset converted with `tavis convert --zero-neck`:
  the neck dimensions of state and action are 0 in training, as the env reports and applies them in evaluation.
- pi0 presets need `lerobot/pi0_base` and its tokenizer from the Hub or the local cache; `tavis train` checks that
  first and says what is missing.
- Compact presets (`act_head_wrist_compact`, `act_fixed_wrist_compact`: the paper's two camera conditions) are not
  the reference's: ACT sized to train a baseline in minutes on one GPU (120x160 frames, a ResNet-18 from
  random weights, a chunk of 20 of which 10 are executed, batch 64, 6000 steps, AdamW at lr 1e-4 annealed along a
  cosine to 0 at the last of `--steps`, so a run's last checkpoint is its settled one: set `--steps` to the budget,
  not past it; `--optimizer.lr` changes the peak). A compact Diffusion Policy of the same budget did not reproduce
  even its own training episodes (docs/results/history.md), ACT does.
- Hand-frame compact presets (`act_hand_relative_head_wrist_compact`, `act_hand_relative_fixed_wrist_compact`): the
  same ACT as `act_hand_relative` (lerobot_tavis.policies), its arm actions in the frame of the hand measured when a
  chunk is planned, the cameras its only network input, and the seconds since the episode began as one more
  (`time_input`: without it a fixed + wrists policy never starts its reach); batch 128, 3200 steps, a checkpoint
  every 800: the recipe of the trained baselines (docs/results/README.md); `--policy.time_input=false` suits a head +
  wrists policy alone better.

- Hand-frame Diffusion Policy compact presets (`diffusion_hand_relative_head_wrist_compact`,
  `diffusion_hand_relative_fixed_wrist_compact`): `diffusion_hand_relative` (lerobot_tavis.policies) on the hand-frame
  ACT presets' cameras, time input, optimiser, schedule and budget; 2 observation steps, a horizon of 16 of which 8
  are executed, UNet 256-512-1024, 10 DDIM steps when acting, `observation.state` read as the anchor alone.

`tavis train` checks a local dataset against the preset first (`check_training_dataset`): the cameras the policy
reads must be there and, for ACT (which does not resize its images), at the preset's size. A plain
`lerobot-train --config_path=<preset>` makes the same check when it imports the plugin
(`refuse_unfit_training_dataset`).

The JSON files are generated from `build_preset` (`python -m lerobot_tavis.policy_configs` rewrites them); a test
keeps the two in step.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

from lerobot_tavis import canonical
from lerobot_tavis.envs.checkpoint_settings import UNRESIZED_POLICIES
from lerobot_tavis.envs.modes import (BUILTIN_CAMERA_MODES, RENAMED_MODES, mode_cameras, neck_locked,
                                      resolve_camera_mode)
from lerobot_tavis.errors import InputError
from lerobot_tavis.policies.dataset_fit import check_dataset_images
from lerobot_tavis.readers import read_json

PRESET_DIR = Path(__file__).parent
POLICIES = ("diffusion", "pi0")
COMPACT_POLICIES = ("act", "act_hand_relative", "diffusion_hand_relative")
PI0_BASE = "lerobot/pi0_base"
PI0_TOKENIZER = "google/paligemma-3b-pt-224"
DIFFUSION_IMAGE_SIZE = (240, 320)
COMPACT_IMAGE_SIZE = (120, 160)
COMPACT_MODES = ("head_wrist", "fixed_wrist")  # the paper's headcam and fixedcam conditions (docs/reference.md §1)
PI0_IMAGE_SIZE = (480, 640)  # pi0 resizes and pads every camera to 224x224 itself
CHUNK, EXECUTED = 16, 8
COMPACT_CHUNK, COMPACT_EXECUTED = 20, 10
COMPACT_LR = 1e-4  # ACT's default peak, for the backbone as for the transformer
COMPACT_DOWN_DIMS = [256, 512, 1024]  # the UNet of the earlier compact Diffusion Policy (docs/training.md)
HAND_RELATIVE_BUDGET = {"batch_size": 128, "steps": 3200, "save_freq": 800}


def presets() -> dict[str, tuple[str, str, bool]]:
    """Every shipped preset's name -> (policy, camera mode, compact); registered camera modes have none (their
    presets come from `build_preset`)."""
    table = {f"{policy}_{mode}": (policy, mode, False) for policy in POLICIES for mode in BUILTIN_CAMERA_MODES}
    return table | {f"{policy}_{mode}_compact": (policy, mode, True)
                    for policy in COMPACT_POLICIES for mode in COMPACT_MODES}


def preset_names() -> list[str]:
    return list(presets())


def preset_path(name: str) -> Path:
    """The JSON file of preset `name` (e.g. `diffusion_head_wrist`); old camera-mode names work, with a warning."""
    policy, _, mode = name.partition("_")
    if mode in RENAMED_MODES:
        name = f"{policy}_{resolve_camera_mode(mode)}"
    if name not in presets():
        raise InputError(f"unknown preset {name!r}; presets: {', '.join(preset_names())}")
    return PRESET_DIR / f"{name}.json"


def build_preset(policy: str, camera_mode: str, compact: bool = False) -> dict:
    """The partial TrainPipelineConfig of one preset (`compact`: the fast baselines, not the reference's)."""
    if compact:
        builders = {"act": _compact_act, "act_hand_relative": _compact_act_hand_relative,
                    "diffusion_hand_relative": _compact_diffusion_hand_relative}
        if policy not in builders:
            raise ValueError(f"compact presets are of {', '.join(COMPACT_POLICIES)}, got policy {policy!r}")
        return builders[policy](camera_mode)
    image_size = DIFFUSION_IMAGE_SIZE if policy == "diffusion" else PI0_IMAGE_SIZE
    inputs = {f"observation.images.{camera}": {"type": "VISUAL", "shape": [3, *image_size]}
              for camera in mode_cameras(camera_mode)}
    inputs["observation.state"] = {"type": "STATE", "shape": [canonical.ACTION_DIM]}
    common_policy = {"input_features": inputs, "n_action_steps": EXECUTED, "push_to_hub": False}
    if policy == "diffusion":
        policy_cfg = {"type": "diffusion", **common_policy, "n_obs_steps": 2, "horizon": CHUNK,
                      "drop_n_last_frames": CHUNK - EXECUTED - 2 + 1, "resize_shape": list(image_size),
                      "crop_shape": None, "down_dims": [512, 1024, 2048], "pretrained_backbone_weights": None,
                      "use_group_norm": True, "optimizer_lr": 1e-4}
    elif policy == "pi0":
        policy_cfg = {"type": "pi0", **common_policy, "pretrained_path": PI0_BASE, "chunk_size": CHUNK,
                      "optimizer_lr": 2.5e-5, "dtype": "bfloat16", "gradient_checkpointing": True}
    else:
        raise ValueError(f"policy must be one of {POLICIES}, got {policy!r}")
    suffix = "-zero-neck" if neck_locked(camera_mode) else ""
    return {
        "dataset": {"repo_id": f"local/tavis-head-gr1t2{suffix}", "video_backend": "pyav"},
        "env": {"type": "tavis", "task": "tavis_head", "robot": "gr1t2", "camera_mode": camera_mode,
                "image_size": list(image_size)},
        "policy": policy_cfg,
        "batch_size": 16,
        "steps": 200_000 if policy == "diffusion" else 30_000,
        "env_eval_freq": 20_000,
        "save_freq": 20_000,
        "eval": {"n_episodes": 8, "batch_size": 8, "use_async_envs": True},
    }


def _compact_act(camera_mode: str) -> dict:
    """ACT on the reference-faithful preset's cameras and state at 120x160, sized to train in minutes on one GPU
    (docs/training.md)."""
    if camera_mode not in COMPACT_MODES:
        raise ValueError(f"compact presets exist for {COMPACT_MODES}, got {camera_mode!r}")
    preset = build_preset("diffusion", camera_mode)
    size = list(COMPACT_IMAGE_SIZE)
    inputs = preset["policy"]["input_features"]
    for feature in inputs.values():
        if feature["type"] == "VISUAL":
            feature["shape"] = [3, *size]
    preset["policy"] = {"type": "act", "input_features": inputs, "chunk_size": COMPACT_CHUNK,
                        "n_action_steps": COMPACT_EXECUTED, "pretrained_backbone_weights": None,
                        "optimizer_lr": COMPACT_LR, "optimizer_lr_backbone": COMPACT_LR, "push_to_hub": False}
    preset["env"]["image_size"] = size
    # ACT's own optimizer (AdamW, weight decay 1e-4, gradients clipped at norm 10) with a schedule added: the lr
    # falls along a cosine from COMPACT_LR to 0 at the last step
    schedule = {"use_policy_training_preset": False,
                "optimizer": {"type": "adamw", "lr": COMPACT_LR, "weight_decay": 1e-4, "grad_clip_norm": 10.0},
                "scheduler": {"type": "cosine_annealing_with_warmup", "num_warmup_steps": 0}}
    return preset | schedule | {"batch_size": 64, "steps": 6000, "save_freq": 2000, "env_eval_freq": 0}


def _compact_act_hand_relative(camera_mode: str) -> dict:
    """The compact ACT preset as `act_hand_relative` with its time input and without the state input (which that
    policy reads only as its chunks' anchor), on the hand-frame budget (`HAND_RELATIVE_BUDGET`)."""
    preset = _compact_act(camera_mode)
    del preset["policy"]["input_features"]["observation.state"]
    preset["policy"] |= {"type": "act_hand_relative", "time_input": True}
    return preset | HAND_RELATIVE_BUDGET


def _compact_diffusion_hand_relative(camera_mode: str) -> dict:
    """`diffusion_hand_relative` on the hand-frame ACT preset's cameras at 120x160 (resized to that size, not
    cropped), time input, optimiser, schedule and budget: 2 observation steps, a horizon of 16 actions of which 8 are
    executed, a UNet of `COMPACT_DOWN_DIMS` channels, a ResNet-18 from random weights with group norm, 10 DDIM steps
    when acting. `observation.state` stays an input, as Diffusion Policy needs, and is read as the anchor; the network
    sees none of it (`state_input` none, as the hand-frame ACT)."""
    preset = _compact_act(camera_mode)
    preset["policy"] = {"type": "diffusion_hand_relative", "input_features": preset["policy"]["input_features"],
                        "n_obs_steps": 2, "horizon": CHUNK, "n_action_steps": EXECUTED,
                        "drop_n_last_frames": CHUNK - EXECUTED - 2 + 1, "resize_shape": list(COMPACT_IMAGE_SIZE),
                        "crop_shape": None, "down_dims": COMPACT_DOWN_DIMS, "pretrained_backbone_weights": None,
                        "use_group_norm": True, "noise_scheduler_type": "DDIM", "num_inference_steps": 10,
                        "optimizer_lr": COMPACT_LR, "push_to_hub": False, "time_input": True, "state_input": "none"}
    return preset | HAND_RELATIVE_BUDGET


def write_presets() -> list[Path]:
    written = []
    for name, (policy, mode, compact) in presets().items():
        path = preset_path(name)
        path.write_text(json.dumps(build_preset(policy, mode, compact), indent=2) + "\n")
        written.append(path)
    return written


def check_training_dataset(preset: Path, lerobot_args: Sequence[str]) -> None:
    """Refuse (InputError, `policies.dataset_fit`) a training dataset that lacks a camera the preset's policy reads
    or, for a policy that does not resize its images (ACT), holds them at another size than the preset's. The
    dataset is `--dataset.root` of `lerobot_args`, else the preset's, else LeRobot's local copy of
    `--dataset.repo_id`; a dataset not on this machine is not checked (lerobot-train downloads it)."""
    from lerobot.configs.parser import parse_arg
    from lerobot.utils.constants import HF_LEROBOT_HOME

    config = json.loads(preset.read_text())
    dataset = config.get("dataset", {})
    root = parse_arg("dataset.root", lerobot_args) or dataset.get("root")
    repo_id = parse_arg("dataset.repo_id", lerobot_args) or dataset.get("repo_id")
    info = Path(root) / "meta" / "info.json" if root else HF_LEROBOT_HOME / str(repo_id) / "meta" / "info.json"
    if not info.is_file():
        return
    content = read_json(info)
    features = content.get("features") if isinstance(content, dict) else None
    if not isinstance(features, dict):
        raise InputError(f"{info}: not a LeRobotDataset's info.json (no features object)")
    policy = config.get("policy") or {}
    policy_type = parse_arg("policy.type", lerobot_args) or policy.get("type")
    check_dataset_images(policy.get("input_features") or {}, features, resizes=policy_type not in UNRESIZED_POLICIES)


def refuse_unfit_training_dataset(args: Sequence[str]) -> None:
    """`check_training_dataset` for lerobot-train's own command line `args` when its `--config_path` is a TAVIS
    training config (a preset, or a train_config.json whose env is `tavis`): an unfit dataset ends the process with
    one line (SystemExit) before LeRobot loads anything. LeRobot 0.6.1 hands no plugin its dataset's metadata
    before training (a policy config gets it through `set_dataset_feature_metadata`, which its own ACT and
    Diffusion configs lack), so the plugin reads the command line as lerobot-train will. A config that is not a
    readable JSON file is left to LeRobot to report."""
    from lerobot.configs.parser import parse_arg

    config_path = parse_arg("config_path", args)
    if not config_path or not Path(config_path).is_file():
        return
    try:
        config = json.loads(Path(config_path).read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return
    if not isinstance(config, dict):
        return
    if (parse_arg("env.type", args) or (config.get("env") or {}).get("type")) != "tavis":
        return
    try:
        check_training_dataset(Path(config_path), args)
    except InputError as error:
        raise SystemExit(f"lerobot-train: error: {error}") from None


def missing_pi0_downloads() -> list[str]:
    """Hub repos a pi0 preset needs that are neither cached nor reachable (empty when all is well)."""
    from huggingface_hub import HfApi, snapshot_download
    from huggingface_hub.errors import LocalEntryNotFoundError

    missing = []
    for repo_id in (PI0_BASE, PI0_TOKENIZER):
        try:
            snapshot_download(repo_id, local_files_only=True)
            continue
        except LocalEntryNotFoundError:  # not cached: is the Hub there?
            pass
        try:
            HfApi().model_info(repo_id, timeout=10)
        except Exception as error:  # offline, gated, no token...: any failure means it cannot be loaded
            missing.append(f"{repo_id} ({type(error).__name__})")
    return missing
