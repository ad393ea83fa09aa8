"""Whether a training dataset holds the camera images a policy config says it reads.

A policy's `input_features` name its cameras (`observation.images.<camera>`) and their shape (3, H, W); LeRobot
trains on the dataset's frames as they are, so a policy that does not resize its images (ACT) learns at the
dataset's size whatever its config says, and its checkpoint then claims a size it never saw. LeRobot 0.6.1 checks
neither the size nor, when the dataset has fewer cameras than the policy, the cameras.
"""

from __future__ import annotations

from lerobot_tavis.envs.checkpoint_settings import IMAGE_PREFIX
from lerobot_tavis.errors import InputError


def check_dataset_images(input_features: dict, dataset_features: dict, resizes: bool) -> None:
    """Raise InputError when the dataset lacks a camera the policy reads or, for a policy that does not resize its
    images (`resizes` False), holds one at another size than the policy's. `input_features`: a policy config's
    (PolicyFeature or its JSON form, shape (3, H, W)); `dataset_features`: a LeRobotDataset's (`meta/info.json`,
    shape (H, W, 3))."""
    wanted = {key.removeprefix(IMAGE_PREFIX): tuple(_shape(feature))[-2:]
              for key, feature in input_features.items() if key.startswith(IMAGE_PREFIX)}
    held = {key.removeprefix(IMAGE_PREFIX): tuple(feature["shape"][:2])
            for key, feature in dataset_features.items() if key.startswith(IMAGE_PREFIX)}
    missing = [camera for camera in wanted if camera not in held]
    if missing:
        raise InputError(f"the policy reads the cameras {', '.join(wanted)}, the dataset has "
                         f"{', '.join(held) or 'none'}: convert the dataset with --cameras {','.join(wanted)}, or "
                         "train a preset of a camera mode it has")
    if resizes:
        return
    for camera, size in wanted.items():
        if held[camera] != size:
            raise InputError(f"the dataset's {camera} images are {_text(held[camera])}, the policy's input_features "
                             f"say {_text(size)} (and evaluation renders that): convert the dataset with --image-size "
                             f"{_text(size)}, or set the policy's input shapes and --env.image_size to "
                             f"{_text(held[camera])}")


def _shape(feature) -> tuple:
    return tuple(feature["shape"] if isinstance(feature, dict) else feature.shape)


def _text(size: tuple[int, int]) -> str:
    return "x".join(str(side) for side in size)
