"""conditional_pick in MuJoCo: two YCB objects in their left and right zones, a red or green cue card between."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from lerobot_tavis.envs import placement
from lerobot_tavis.envs.objects import OBJECT_NAMES, add_marker
from lerobot_tavis.envs.scene import TABLE_TOP_Z, Look, use_look
from lerobot_tavis.envs.tasks.base import TargetFacts, YcbTask
from lerobot_tavis.envs.tasks.conditional_pick import INFO, SUCCESS_HEIGHT_M
from lerobot_tavis.envs.tasks.layout import Box2D

CARD = "cue_card"
CARD_SIZE_M = (0.08, 0.05, 0.003)
RED = (1.0, 0.0, 0.0, 1.0)
GREEN = (0.0, 1.0, 0.0, 1.0)
# matte card stock; its colour is the geom's rgba (RED or GREEN), which overrides the material's
CARD_LOOK = Look("cue_card", specular=0.05, shininess=0.1)


@dataclass(frozen=True)
class ConditionalVariant:
    left_zone: Box2D  # robot's left = +y
    right_zone: Box2D
    card_zone: Box2D


@dataclass(frozen=True)
class ConditionalPickFacts(TargetFacts):
    """`target` is `left_object` if the card is red, `right_object` if green."""

    left_object: str  # body name of the object on the robot's left (+y)
    right_object: str  # body name of the object on the robot's right (-y)
    cue_card: str  # body name of the card lying flat on the table (a mocap body; its origin is its centre)


class ConditionalPick(YcbTask):
    info = INFO
    success_height_m = SUCCESS_HEIGHT_M
    VARIANTS = {
        "id": ConditionalVariant(Box2D((0.35, 0.45), (0.15, 0.25)), Box2D((0.35, 0.45), (-0.25, -0.15)),
                                 Box2D((0.35, 0.45), (-0.05, 0.05))),
        "ood_spatial": ConditionalVariant(Box2D((0.30, 0.50), (0.10, 0.35)), Box2D((0.30, 0.50), (-0.35, -0.10)),
                                          Box2D((0.30, 0.50), (-0.08, 0.08))),
    }

    def __init__(self, variant: str = "id"):
        super().__init__(variant)
        self.left_object, self.right_object = OBJECT_NAMES[:2]
        self.card_is_red = True

    def build(self, spec) -> None:
        super().build(spec)
        add_marker(spec, CARD, mujoco.mjtGeom.mjGEOM_BOX, tuple(s / 2 for s in CARD_SIZE_M), RED)
        use_look(spec, spec.geom(CARD), CARD_LOOK)

    def bind(self, model) -> None:
        super().bind(model)
        self._card_geom = model.geom(CARD).id

    def initialize_episode(self, model, data, rng: np.random.Generator) -> None:
        left, right = rng.choice(len(OBJECT_NAMES), size=2, replace=False)
        self.left_object, self.right_object = OBJECT_NAMES[left], OBJECT_NAMES[right]
        self.card_is_red = bool(rng.integers(2))
        self.target = self.left_object if self.card_is_red else self.right_object
        for name, zone in ((self.left_object, self.variant.left_zone), (self.right_object, self.variant.right_zone)):
            x, y = zone.sample(rng)
            placement.place_on_table(model, data, name, x, y, rng.uniform(-np.pi, np.pi))
        placement.hide(model, data, [n for n in OBJECT_NAMES if n not in (self.left_object, self.right_object)])
        x, y = self.variant.card_zone.sample(rng)
        placement.set_mocap_pose(model, data, CARD, (x, y, TABLE_TOP_Z + CARD_SIZE_M[2] / 2 + 0.0005))
        model.geom_rgba[self._card_geom] = RED if self.card_is_red else GREEN

    def episode_facts(self) -> ConditionalPickFacts:
        return ConditionalPickFacts(props=self.props(), succeeds=self.is_success, target=self.target,
                                    left_object=self.left_object, right_object=self.right_object, cue_card=CARD)
