"""Sandbox scene: the five YCB objects standing in a row on the table; there is nothing to succeed at."""

from __future__ import annotations

import numpy as np

from lerobot_tavis.envs import placement
from lerobot_tavis.envs.objects import OBJECT_NAMES
from lerobot_tavis.envs.tasks.base import YcbTask
from lerobot_tavis.envs.tasks.catalog import TASKS

ROW_X = 0.42
ROW_Y = np.linspace(0.24, -0.24, len(OBJECT_NAMES))
JITTER_M = 0.02


class Tabletop(YcbTask):
    info = TASKS["tabletop"]
    VARIANTS = {"id": None}

    def initialize_episode(self, model, data, rng: np.random.Generator) -> None:
        for name, y in zip(OBJECT_NAMES, ROW_Y):
            dx, dy = rng.uniform(-JITTER_M, JITTER_M, size=2)
            placement.place_on_table(model, data, name, ROW_X + dx, y + dy, rng.uniform(-np.pi, np.pi))

    def evaluate(self, data) -> dict[str, bool | float]:
        return {"success": False}
