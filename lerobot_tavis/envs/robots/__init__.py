"""The robot registry: every embodiment by name, readable without MuJoCo.

`ROBOTS` below is the one place a robot is declared; its class (a `base.Robot` subclass, one module each next to
this file) is named by import path and imported only when a robot is built. Robots from outside the package join
with `register_robot` (docs/extending.md).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING

from lerobot_tavis import importpath
from lerobot_tavis.errors import FieldError

if TYPE_CHECKING:
    from lerobot_tavis.envs.robots.base import Robot


@dataclass(frozen=True)
class RobotInfo:
    """One robot: `name` (the class's `name` too: it prefixes the robot's bodies in the world), `robot_class`
    ("package.module:Class", or the class) and `title` (how figures and tables write it)."""

    name: str
    robot_class: str | type
    title: str


ROBOTS: dict[str, RobotInfo] = {
    info.name: info
    for info in (
        RobotInfo("gr1t2", "lerobot_tavis.envs.robots.gr1t2:GR1T2", "GR1T2"),
        RobotInfo("reachy2", "lerobot_tavis.envs.robots.reachy2:Reachy2", "Reachy2"),
    )
}
BUILTIN_ROBOTS = tuple(ROBOTS)
DEFAULT_ROBOT = "gr1t2"
NAME_PATTERN = re.compile(r"[a-z][a-z0-9_]*")


def robot_names() -> tuple[str, ...]:
    """Every registered robot, built-in ones first."""
    return tuple(ROBOTS)


def robot_info(name: str) -> RobotInfo:
    try:
        return ROBOTS[name]
    except KeyError:
        raise FieldError("robot", f"must be one of {sorted(ROBOTS)}, got {name!r}") from None


def register_robot(info: RobotInfo) -> RobotInfo:
    """Add a robot from outside the package (docs/extending.md). Returns `info`."""
    if not (isinstance(info, RobotInfo) and NAME_PATTERN.fullmatch(info.name)):
        raise ValueError(f"robot name must be lower_snake_case (a RobotInfo), got {getattr(info, 'name', info)!r}")
    if info.name in ROBOTS:
        raise ValueError(f"robot {info.name!r} is already registered")
    importpath.check("robot_class", info.robot_class)
    ROBOTS[info.name] = info
    return info


def unregister_robot(name: str) -> None:
    """Remove a robot added by `register_robot` (tests clean up with it); the built-in robots stay."""
    if name in BUILTIN_ROBOTS:
        raise ValueError(f"robot {name!r} is built in and cannot be unregistered")
    robot_info(name)
    del ROBOTS[name]


def make_robot(name: str) -> Robot:
    """A new robot `name` (importing its class loads MuJoCo)."""
    robot = importpath.resolve(robot_info(name).robot_class)()
    if robot.name != name:
        raise ValueError(f"robot {name!r} is registered with a class whose name is {robot.name!r}; they must agree")
    return robot
