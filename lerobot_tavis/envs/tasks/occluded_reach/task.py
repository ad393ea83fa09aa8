"""occluded_reach in MuJoCo: one object on the table behind a fixed portrait monitor."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from lerobot_tavis.envs import physics, placement, scene
from lerobot_tavis.envs.objects import OBJECT_NAMES
from lerobot_tavis.envs.tasks.base import TargetFacts, YcbTask
from lerobot_tavis.envs.tasks.occluded_reach import INFO, SUCCESS_HEIGHT_M
from lerobot_tavis.envs.tasks.layout import Box2D

FRAME_LOOK = scene.Look("screen_frame", (0.18, 0.18, 0.18, 1.0), specular=0.3, shininess=0.3)  # matte plastic
PANEL_LOOK = scene.Look("screen_panel", (0.05, 0.05, 0.05, 1.0), specular=0.8, shininess=0.9)  # glossy glass
SCREEN_X = 0.27
PANEL_HALF_WIDTH = 0.08
# name -> (full size, centre, look)
SCREEN_PARTS = {
    "screen/base": ((0.15, 0.10, 0.02), (SCREEN_X, 0.0, 1.01), FRAME_LOOK),
    "screen/post": ((0.03, 0.03, 0.10), (SCREEN_X, 0.0, 1.07), FRAME_LOOK),
    "screen/panel": ((0.015, 2 * PANEL_HALF_WIDTH, 0.40), (SCREEN_X, 0.0, 1.32), PANEL_LOOK),  # spans z 1.12-1.52
}


@dataclass(frozen=True)
class OccludedVariant:
    object_zone: Box2D


@dataclass(frozen=True)
class OccludedReachFacts(TargetFacts):
    """The screen stands across the table in front of the target, centred on y = 0; its panel spans z 1.12-1.52 m."""

    screen_x_m: float  # world x of the screen's plane
    panel_half_width_m: float  # half the panel's width along y


class OccludedReach(YcbTask):
    info = INFO
    success_height_m = SUCCESS_HEIGHT_M
    VARIANTS = {
        "id": OccludedVariant(Box2D((0.40, 0.50), (-0.20, 0.20))),
        "ood_spatial": OccludedVariant(Box2D((0.36, 0.53), (-0.30, 0.30))),
    }

    def build(self, spec) -> None:
        super().build(spec)
        screen = spec.worldbody.add_body(name="screen")
        for name, (size, centre, look) in SCREEN_PARTS.items():
            geom = screen.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_BOX, pos=centre, size=[s / 2 for s in size])
            physics.style_geom(geom, physics.STATIC)
            scene.use_look(spec, geom, look)

    def initialize_episode(self, model, data, rng: np.random.Generator) -> None:
        self.target = OBJECT_NAMES[rng.integers(len(OBJECT_NAMES))]
        x, y = self.variant.object_zone.sample(rng)
        placement.place_on_table(model, data, self.target, x, y, rng.uniform(-np.pi, np.pi))
        placement.hide(model, data, [n for n in OBJECT_NAMES if n != self.target])

    def episode_facts(self) -> OccludedReachFacts:
        return OccludedReachFacts(props=self.props(), succeeds=self.is_success, target=self.target,
                                  screen_x_m=SCREEN_X, panel_half_width_m=PANEL_HALF_WIDTH)
