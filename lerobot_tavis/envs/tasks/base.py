"""The task interface: scene geometry, variants (splits), episode sampling, prompt and success; no control code.

Life cycle: `build(spec)` adds the task's props and scenery to the world spec; after compilation `bind(model)`
resolves ids; every episode `initialize_episode(model, data, rng)` places things (all randomness from `rng`) and
picks the prompt; after each env step `after_step(model, data, elapsed_s)` updates task state (a light, say) and
`evaluate(data)` is checked: `{"success": bool, <sub-condition>: bool or float, ...}`, the parts the task's success
rule combines (and the quantities they test), plain Python values that go into `info` and the episode log.

What a scripted demonstrator may know of the task is declared here too: `episode_facts()`, an `EpisodeFacts`
(a frozen dataclass; each task subclasses it with its own facts) that the env takes right after
`initialize_episode`. Demonstrators read those facts and the public simulator state (model, data, the robot), never
the task's attributes or body names of their own.
"""

from __future__ import annotations

import abc
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar

import mujoco
import numpy as np

from lerobot_tavis.envs.objects import OBJECT_NAMES, YCB_OBJECTS, add_prop
from lerobot_tavis.envs.placement import body_speed
from lerobot_tavis.envs.tasks.info import LIFT_HEIGHT_M, MAX_SUCCESS_SPEED_M_S, TaskInfo

# `evaluate` reports measured quantities to the millimetre (mm/s): bit-level differences between runs of the same
# episode (a policy's arithmetic in another process, say) stay out of the episode log. Decisions use exact values.
MEASURE_DECIMALS = 3


@dataclass(frozen=True)
class EpisodeFacts:
    """What a task tells its scripted demonstrator about the current episode, taken right after
    `initialize_episode` and fixed until the next one (privileged knowledge, as a person who set up the scene has).

    Body names are the world model's (`model.body(name)`); their poses come from the simulator state. Positions are
    in the world frame (x forward, y left, z up; table top at z = 1.0), in m; angles in rad. Subclasses add the
    facts of one task.
    """

    props: tuple[str, ...]  # the free bodies of the scene (`Task.props`, off-stage ones included), in that order
    succeeds: Callable[[mujoco.MjData], bool]  # the task's success rule on any state of this world (imagined ones)


@dataclass(frozen=True)
class TargetFacts(EpisodeFacts):
    """The facts of a task with one prop to pick."""

    target: str  # body name of the prop to pick (a free body; its origin is its centre)


class Task(abc.ABC):
    info: ClassVar[TaskInfo]
    VARIANTS: ClassVar[dict[str, Any]]  # "id" and "ood_spatial" presets (docs/reference.md §4)
    has_table: ClassVar[bool] = True
    blacked_out_cameras: ClassVar[frozenset[str]] = frozenset()

    def __init__(self, variant: str = "id"):
        if variant not in self.VARIANTS:
            raise ValueError(f"variant of task {self.info.name!r} must be one of {sorted(self.VARIANTS)}, "
                             f"got {variant!r}")
        self.variant_name = variant
        self.variant = self.VARIANTS[variant]
        self.prompt = self.info.prompts[0]

    @abc.abstractmethod
    def build(self, spec: mujoco.MjSpec) -> None:
        """Add props and scenery to the world spec."""

    def bind(self, model: mujoco.MjModel) -> None:
        """Resolve model ids after compilation."""

    @abc.abstractmethod
    def initialize_episode(self, model: mujoco.MjModel, data: mujoco.MjData, rng: np.random.Generator) -> None:
        """Sample and apply this episode's layout, task state and prompt."""

    def after_step(self, model: mujoco.MjModel, data: mujoco.MjData, elapsed_s: float) -> None:
        """Update task state after an env step; `elapsed_s` is the episode time since the first observation."""

    def task_state(self) -> np.ndarray:
        """Task state that lives outside the simulator state (a light's colour, say), for recordings."""
        return np.zeros(0)

    @abc.abstractmethod
    def evaluate(self, data: mujoco.MjData) -> dict[str, bool | float]:
        """`{"success": bool, <sub-condition>: bool or float, ...}` for the current state: "success" first, then the
        conditions the success rule combines and the measured quantities they test (SI units, world frame)."""

    def is_success(self, data: mujoco.MjData) -> bool:
        return bool(self.evaluate(data)["success"])

    def props(self) -> tuple[str, ...]:
        """Names of the free bodies whose motion must die down before the first observation."""
        return ()

    def episode_facts(self) -> EpisodeFacts:
        """What the demonstrator may know of this episode (see `EpisodeFacts`); called once after each
        `initialize_episode`. Tasks with a demonstrator return their own subclass."""
        return EpisodeFacts(props=self.props(), succeeds=self.is_success)


class YcbTask(Task, abc.ABC):
    """A task with the five YCB objects (those not used in an episode wait off-stage) and one target prop; its
    `evaluate` is the lift rule at `success_height_m` (world z, m; the built-in tasks set their declaration's)."""

    success_height_m: ClassVar[float] = LIFT_HEIGHT_M

    def __init__(self, variant: str = "id"):
        super().__init__(variant)
        self.target = OBJECT_NAMES[0]

    def build(self, spec: mujoco.MjSpec) -> None:
        for name in OBJECT_NAMES:
            add_prop(spec, YCB_OBJECTS[name])

    def bind(self, model: mujoco.MjModel) -> None:
        self._model = model

    def props(self) -> tuple[str, ...]:
        return OBJECT_NAMES

    def episode_facts(self) -> TargetFacts:
        return TargetFacts(props=self.props(), succeeds=self.is_success, target=self.target)

    def evaluate(self, data: mujoco.MjData) -> dict[str, bool | float]:
        return lift_conditions(self._model, data, self.target, self.success_height_m)


def lift_conditions(model: mujoco.MjModel, data: mujoco.MjData, body: str,
                    height_m: float) -> dict[str, bool | float]:
    """The reference's lift rule, part by part: the body's origin above `height_m` (world z; `target_lifted`) and
    slower than `MAX_SUCCESS_SPEED_M_S` (`target_slow`), with the measured height (m) and speed (m/s), to
    `MEASURE_DECIMALS`."""
    height = float(data.xpos[model.body(body).id][2])
    speed = body_speed(model, data, body)
    lifted, slow = height > height_m, speed < MAX_SUCCESS_SPEED_M_S
    return {"success": lifted and slow, "target_lifted": lifted, "target_slow": slow,
            "target_height_m": round(height, MEASURE_DECIMALS), "target_speed_m_s": round(speed, MEASURE_DECIMALS)}

