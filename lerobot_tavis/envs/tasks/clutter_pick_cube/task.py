"""clutter_pick_cube in MuJoCo: the red cube and four of the five YCB objects scattered on the table."""

from __future__ import annotations

import numpy as np

from lerobot_tavis.envs import placement
from lerobot_tavis.envs.objects import OBJECT_NAMES, RED_CUBE, add_prop
from lerobot_tavis.envs.tasks.base import YcbTask
from lerobot_tavis.envs.tasks.clutter_pick_cube import INFO, SUCCESS_HEIGHT_M
from lerobot_tavis.envs.tasks.clutter_pick_lift.task import CLUTTER_VARIANTS, scatter


class ClutterPickCube(YcbTask):
    info = INFO
    success_height_m = SUCCESS_HEIGHT_M
    VARIANTS = CLUTTER_VARIANTS

    def __init__(self, variant: str = "id"):
        super().__init__(variant)
        self.target = RED_CUBE.name
        self.absent = OBJECT_NAMES[0]

    def build(self, spec) -> None:
        super().build(spec)
        add_prop(spec, RED_CUBE)

    def props(self) -> tuple[str, ...]:
        return (*OBJECT_NAMES, RED_CUBE.name)

    def initialize_episode(self, model, data, rng: np.random.Generator) -> None:
        # As in the reference, all six are laid out (cube last) and then one YCB object is taken away, so its
        # slot stays empty.
        scatter(model, data, rng, self.variant, (*OBJECT_NAMES, RED_CUBE.name))
        self.absent = OBJECT_NAMES[rng.integers(len(OBJECT_NAMES))]
        placement.hide(model, data, [self.absent])
