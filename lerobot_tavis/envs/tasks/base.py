"""The task interface: scene geometry, episode sampling, prompt and success; no control code.

Life cycle: `build(spec)` adds the task's props and scenery to the world spec; after compilation `bind(model)`
resolves ids; every episode `initialize_episode(model, data, rng)` places things (all randomness from `rng`);
each policy step `after_step(data, step)` updates task state (a light, say) and `is_success(data)` is checked.
"""

from __future__ import annotations

import abc
from typing import ClassVar

import mujoco
import numpy as np

from lerobot_tavis.envs.tasks.catalog import TaskInfo


class Task(abc.ABC):
    info: ClassVar[TaskInfo]
    has_table: ClassVar[bool] = True
    blacked_out_cameras: ClassVar[frozenset[str]] = frozenset()

    def __init__(self, split: str = "id"):
        if split not in self.info.splits:
            raise ValueError(f"split of task {self.info.name!r} must be one of {self.info.splits}, got {split!r}")
        self.split = split
        self._prompt = self.info.prompts[0]

    @abc.abstractmethod
    def build(self, spec: mujoco.MjSpec) -> None:
        """Add props and scenery to the world spec."""

    def bind(self, model: mujoco.MjModel) -> None:
        """Resolve model ids after compilation."""

    @abc.abstractmethod
    def initialize_episode(self, model: mujoco.MjModel, data: mujoco.MjData, rng: np.random.Generator) -> None:
        """Sample and apply this episode's layout and task state."""

    def after_step(self, model: mujoco.MjModel, data: mujoco.MjData, step: int) -> None:
        """Update task state after policy step number `step` (1-based)."""

    @abc.abstractmethod
    def is_success(self, data: mujoco.MjData) -> bool:
        ...

    @property
    def prompt(self) -> str:
        return self._prompt

    def props(self) -> tuple[str, ...]:
        """Names of the free bodies whose motion must die down before the first observation."""
        return ()
