"""Checks of user-given values shared by the configs, the env and the Hub tools. Each raises a FieldError naming
the field; the `tavis` command turns it into one line naming the option. Imports neither numpy nor MuJoCo.
"""

from __future__ import annotations

import math
import numbers
import os
import re

from lerobot_tavis.errors import FieldError

IMAGE_SIDE_PX = (16, 4096)  # smallest and largest camera side the renderer is asked for
# A Hugging Face Hub repository id, as huggingface_hub validates it, with the owner required: each part ASCII
# letters, digits, "-", "_" and ".", starting and ending with a letter, digit or "_", at most 96 characters.
_HUB_PART = r"[A-Za-z0-9_](?:[A-Za-z0-9_.-]{0,94}[A-Za-z0-9_])?"
_REPO_ID = re.compile(rf"{_HUB_PART}/{_HUB_PART}")


def _is_real(value) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def integer(field: str, value, minimum: int, maximum: int | None = None) -> int:
    """`value` as an int, refused unless it is a whole number >= `minimum` (and <= `maximum`, if given)."""
    if not (_is_real(value) and math.isfinite(value) and float(value).is_integer() and value >= minimum
            and (maximum is None or value <= maximum)):
        bounds = f">= {minimum}" if maximum is None else f"from {minimum} to {maximum}"
        raise FieldError(field, f"must be an integer {bounds}, got {value!r}")
    return int(value)


def image_size(value, field: str = "image_size") -> tuple[int, int]:
    """(height, width) in whole pixels within IMAGE_SIDE_PX; a fractional size is refused, not truncated."""
    low, high = IMAGE_SIDE_PX
    try:
        sides = () if isinstance(value, (str, bytes)) else tuple(value)
    except TypeError:
        sides = ()
    if len(sides) != 2 or not all(_is_real(s) and math.isfinite(s) and float(s).is_integer() for s in sides):
        raise FieldError(field, f"must be (height, width), two positive integers (pixels), got {value!r}")
    height, width = (int(s) for s in sides)
    if not (low <= height <= high and low <= width <= high):
        raise FieldError(field, f"must be within {low}..{high} pixels per side, got {value!r}")
    return height, width


def image_size_text(text: str, field: str = "image_size") -> tuple[int, int]:
    """`480x640` (height x width, pixels) -> (480, 640), as the command line writes a size; `image_size` checks
    the range."""
    match = re.fullmatch(r"\s*([0-9]+)\s*[xX]\s*([0-9]+)\s*", text)
    if not match or not all(int(side) > 0 for side in match.groups()):
        raise FieldError(field, f"must be HxW in pixels, e.g. 480x640 (height x width), got {text!r}")
    return int(match[1]), int(match[2])


def episode_steps(episode_length_s, fps: int, field: str = "episode_length_s") -> int:
    """Steps of an episode of `episode_length_s` seconds at `fps`; refused unless finite and at least one step."""
    if _is_real(episode_length_s) and math.isfinite(episode_length_s * fps) and round(episode_length_s * fps) >= 1:
        return int(round(episode_length_s * fps))
    raise FieldError(field, f"must be a finite number of seconds, at least one step at {fps} fps ({1 / fps:g} s), "
                            f"got {episode_length_s!r}")


def repo_id(value, field: str = "repo_id") -> str:
    """A Hub repository id `<owner>/<name>`."""
    if not (isinstance(value, str) and _REPO_ID.fullmatch(value) and "--" not in value and ".." not in value):
        raise FieldError(field, f"must be <owner>/<name> on the Hugging Face Hub: one '/', each part letters, "
                                f"digits, '-', '_' or '.' (not '--' or '..', nor '-' or '.' at either end), "
                                f"got {value!r}")
    return value


def utf8(field: str, value: str | os.PathLike) -> str | os.PathLike:
    """`value` if its text is UTF-8. Python hands over command-line bytes of another encoding (a file name written
    in Latin-1, say) as lone surrogates, which LeRobot's datasets, JSON files and video writers cannot store."""
    try:
        os.fspath(value).encode("utf-8")
    except UnicodeEncodeError:
        raise FieldError(field, f"must be UTF-8 text, got {os.fsencode(value)!r} (datasets and reports store "
                                "names as UTF-8: rename it)") from None
    return value


def choice(field: str, value, allowed: tuple) -> object:
    """`value` if it is one of `allowed`."""
    if value not in allowed:
        raise FieldError(field, f"must be one of {', '.join(map(str, allowed))}, got {value!r}")
    return value
