"""The embodiments, by name."""

from lerobot_tavis.envs.robots.base import Robot
from lerobot_tavis.envs.robots.gr1t2 import GR1T2
from lerobot_tavis.envs.robots.reachy2 import Reachy2
from lerobot_tavis.errors import FieldError

ROBOTS: dict[str, type[Robot]] = {"gr1t2": GR1T2, "reachy2": Reachy2}


def make_robot(name: str) -> Robot:
    try:
        return ROBOTS[name]()
    except KeyError:
        raise FieldError("robot", f"must be one of {sorted(ROBOTS)}, got {name!r}") from None
