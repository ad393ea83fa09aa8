"""What a policy checkpoint expects of the env (robot, camera mode, cameras, image size), and the env's settings
matched to it.

A LeRobot checkpoint (a `pretrained_model` folder, or a Hub repository of one) names the camera images its network
reads, and their size, in `config.json` (`input_features`: `observation.images.<camera>` of shape (3, H, W)); when
lerobot-train made it with `--env.type=tavis`, `train_config.json` beside it holds that env's robot, camera mode and
image size. `match_settings` settles an evaluation's env: a setting the user gave is kept (with a warning where it
differs from the checkpoint's), one left out takes the checkpoint's; a camera the policy reads that the camera mode
does not render is refused, naming the camera mode that renders the policy's cameras, and so is an image size other
than the checkpoint's for a policy that does not resize its images (UNRESIZED_POLICIES: its network would see images
of a size it never trained on). Only JSON is read here: no torch, no LeRobot.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from lerobot_tavis import checks
from lerobot_tavis.envs.modes import CAMERA_MODES, RENAMED_MODES, mode_cameras
from lerobot_tavis.errors import FieldError, InputError, PathNotFoundError

POLICY_CONFIG_NAME = "config.json"
TRAIN_CONFIG_NAME = "train_config.json"
IMAGE_PREFIX = "observation.images."
SETTINGS = ("robot", "camera_mode", "image_size")  # the env settings a checkpoint fixes
UNRESIZED_POLICIES = ("act", "act_hand_relative")  # policy types whose network reads the frames at their size


@dataclass(frozen=True)
class CheckpointSettings:
    """What a checkpoint says of its env; None where it says nothing. `cameras`: those its network reads, in the
    order of its `input_features`; `image_size`: their common (height, width), pixels; `policy_type`: its config's
    `type` (e.g. act, diffusion)."""

    robot: str | None = None
    camera_mode: str | None = None
    cameras: tuple[str, ...] | None = None
    image_size: tuple[int, int] | None = None
    policy_type: str | None = None

    def known(self) -> dict:
        """The env settings (robot, camera_mode, image_size) the checkpoint fixes."""
        return {name: getattr(self, name) for name in SETTINGS if getattr(self, name) is not None}


def settings_from_configs(policy: dict | None, train: dict | None) -> CheckpointSettings:
    """The settings in a checkpoint's `config.json` (`policy`) and `train_config.json` (`train`), as parsed JSON."""
    policy = policy or (train or {}).get("policy") or {}
    features = policy.get("input_features") or ((train or {}).get("policy") or {}).get("input_features") or {}
    images = {key.removeprefix(IMAGE_PREFIX): tuple(feature.get("shape", ()))
              for key, feature in features.items() if key.startswith(IMAGE_PREFIX)}
    env = (train or {}).get("env") or {}
    env = env if env.get("type") == "tavis" else {}
    sizes = {shape[-2:] for shape in images.values() if len(shape) == 3}
    image_size = next(iter(sizes)) if len(sizes) == 1 else (tuple(env["image_size"]) if "image_size" in env else None)
    cameras = tuple(images) or None
    camera_mode = RENAMED_MODES.get(env.get("camera_mode"), env.get("camera_mode"))
    camera_mode = camera_mode if camera_mode in CAMERA_MODES else _mode_of(cameras)
    return CheckpointSettings(env.get("robot"), camera_mode, cameras, image_size, policy.get("type"))


def read_checkpoint_settings(policy_path: str | Path, download: bool = False) -> CheckpointSettings:
    """The settings of the checkpoint at `policy_path`: a local folder, else a Hub repo id whose two config files
    are read from the Hugging Face cache, or downloaded when `download` (any failure: nothing is known, and
    LeRobot's own loading reports it)."""
    path = Path(policy_path)
    if path.is_dir():
        return settings_from_configs(_read_json(path / POLICY_CONFIG_NAME), _read_json(path / TRAIN_CONFIG_NAME))
    try:
        checks.repo_id(str(policy_path))
    except FieldError:
        return CheckpointSettings()
    return settings_from_configs(_hub_json(str(policy_path), POLICY_CONFIG_NAME, download),
                                 _hub_json(str(policy_path), TRAIN_CONFIG_NAME, download))


def match_settings(checkpoint: CheckpointSettings, given: dict, defaults: dict,
                   spell: Callable[[str], str]) -> tuple[dict, list[str]]:
    """The env settings for evaluating `checkpoint`, and warnings for the user.

    `given`: the settings the user chose (name -> value); `defaults`: the value of each of SETTINGS when neither the
    user nor the checkpoint gives one; `spell(name)`: how the user writes the option (e.g. `--env.image_size`).
    Raises InputError when the camera mode does not render every camera the policy reads, or when the image size
    differs from the checkpoint's and its policy does not resize its images."""
    settings = {name: given.get(name, checkpoint.known().get(name, defaults[name])) for name in SETTINGS}
    settings["image_size"] = tuple(settings["image_size"])
    trained, asked = checkpoint.image_size, settings["image_size"]
    if checkpoint.policy_type in UNRESIZED_POLICIES and trained is not None and asked != tuple(trained):
        raise InputError(f"the policy ({checkpoint.policy_type}, which does not resize its images) was trained on "
                         f"{_size(trained)} images, {spell('image_size')} asks for {_size(asked)}: leave "
                         f"{spell('image_size')} out to use the checkpoint's")
    rendered = mode_cameras(settings["camera_mode"])
    policy_cameras = checkpoint.cameras
    if policy_cameras and not set(policy_cameras) <= set(rendered):
        suggestion = _mode_of(policy_cameras)
        fix = f"{spell('camera_mode')} {suggestion}" if suggestion else "a camera mode that renders them"
        raise InputError(f"the policy reads the cameras {', '.join(policy_cameras)}, camera mode "
                         f"{settings['camera_mode']} renders {', '.join(rendered)}: use {fix}")
    warnings = []
    if policy_cameras and set(rendered) - set(policy_cameras):
        warnings.append(f"camera mode {settings['camera_mode']} renders {', '.join(rendered)}; the policy reads only "
                        f"{', '.join(policy_cameras)}")
    for name, told in (("robot", "was trained on the robot {}"), ("camera_mode", "was trained with camera mode {}"),
                       ("image_size", "was trained on {} images")):
        trained = checkpoint.known().get(name)
        if trained is not None and settings[name] != trained:
            shown, asked = (_size(trained), _size(settings[name])) if name == "image_size" else (
                trained, settings[name])
            warnings.append(f"the policy {told.format(shown)}; {spell(name)} asks for {asked} (leave "
                            f"{spell(name)} out to use the checkpoint's)")
    return settings, warnings


def pretrained_model_dir(policy_path: str | Path) -> Path:
    """`policy_path` if it holds a policy's config.json; else a PathNotFoundError naming the checkpoint folder
    below it (`checkpoints/last/pretrained_model` of a lerobot-train output, `pretrained_model` of one checkpoint)
    when there is one."""
    path = Path(policy_path)
    if (path / POLICY_CONFIG_NAME).is_file():
        return path
    if not path.exists():
        raise PathNotFoundError(f"{path}: no such checkpoint directory")
    candidates = (path / "checkpoints" / "last" / "pretrained_model", path / "pretrained_model",
                  *sorted(path.glob("checkpoints/*/pretrained_model"), reverse=True))  # steps are zero-padded
    found = next((candidate for candidate in candidates if (candidate / POLICY_CONFIG_NAME).is_file()), None)
    hint = found or "a checkpoint's pretrained_model folder (<train output>/checkpoints/<step>/pretrained_model)"
    raise PathNotFoundError(f"{path} holds no {POLICY_CONFIG_NAME}: pass {hint}")


def _mode_of(cameras: tuple[str, ...] | None) -> str | None:
    """The camera mode that renders exactly `cameras`, if any."""
    if not cameras:
        return None
    return next((mode for mode, rendered in CAMERA_MODES.items() if set(rendered) == set(cameras)), None)


def _size(size) -> str:
    return "x".join(str(side) for side in size)


def _read_json(path: Path) -> dict | None:
    if not path.is_file():
        return None
    try:
        return json.loads(path.read_text())
    except json.JSONDecodeError as error:
        raise InputError(f"{path}: not a JSON file ({error.msg})") from None


def _hub_json(repo_id: str, name: str, download: bool) -> dict | None:
    from huggingface_hub import hf_hub_download, try_to_load_from_cache

    try:
        path = hf_hub_download(repo_id, name) if download else try_to_load_from_cache(repo_id, name)
    except Exception:  # offline, not found, gated...: LeRobot's own loading reports it
        return None
    return _read_json(Path(path)) if isinstance(path, str) else None
