"""The tabletop sandbox in MuJoCo: the five YCB objects in a row, each jittered and turned."""

from __future__ import annotations

import numpy as np

from lerobot_tavis.envs import placement
from lerobot_tavis.envs.objects import OBJECT_NAMES
from lerobot_tavis.envs.tasks.base import YcbTask
from lerobot_tavis.envs.tasks.tabletop import INFO

ROW_X = 0.42
ROW_Y = np.linspace(0.24, -0.24, len(OBJECT_NAMES))
JITTER_M = 0.02


class Tabletop(YcbTask):
    info = INFO
    VARIANTS = {"id": None}

    def initialize_episode(self, model, data, rng: np.random.Generator) -> None:
        for name, y in zip(OBJECT_NAMES, ROW_Y):
            dx, dy = rng.uniform(-JITTER_M, JITTER_M, size=2)
            placement.place_on_table(model, data, name, ROW_X + dx, y + dy, rng.uniform(-np.pi, np.pi))

    def evaluate(self, data) -> dict[str, bool | float]:
        return {"success": False}
