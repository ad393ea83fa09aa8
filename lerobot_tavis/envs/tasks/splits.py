"""The splits (episode distributions) a task may offer, and the parsing of a split's name; no MuJoCo."""

from __future__ import annotations

from lerobot_tavis.errors import FieldError, InputError

SPLITS = ("id", "ood_spatial", "ood_init_pose", "ood_visual")
# ood_visual (envs/visual_ood.py) changes only the look; `ood_visual:<factor>` applies one factor alone.
VISUAL_SPLIT = "ood_visual"
VISUAL_FACTORS = ("table", "floor", "backdrop", "lighting", "distractors")
PROTOCOL_SPLITS = ("id", "ood_spatial", "ood_init_pose")  # the reference's three, the default of `tavis eval`


def parse_split(split: str) -> tuple[str, tuple[str, ...]]:
    """`ood_visual` -> ("ood_visual", VISUAL_FACTORS); `ood_visual:lighting` -> ("ood_visual", ("lighting",));
    another split -> (split, ()). Raises ValueError for an unknown split or factor."""
    name, _, factor = split.partition(":")
    if name not in SPLITS:
        raise FieldError("split", f"must be one of {split_names()}, got {split!r}")
    if name != VISUAL_SPLIT:
        if factor:
            raise InputError(f"only {VISUAL_SPLIT} takes a factor (e.g. {VISUAL_SPLIT}:lighting), got {split!r}")
        return name, ()
    if not factor:
        return name, VISUAL_FACTORS
    if factor not in VISUAL_FACTORS:
        raise InputError(f"the factor of {VISUAL_SPLIT} must be one of {VISUAL_FACTORS}, got {factor!r}")
    return name, (factor,)


def split_names() -> tuple[str, ...]:
    """Every accepted split name: the splits, and `ood_visual:<factor>` per factor."""
    return (*SPLITS, *(f"{VISUAL_SPLIT}:{factor}" for factor in VISUAL_FACTORS))
