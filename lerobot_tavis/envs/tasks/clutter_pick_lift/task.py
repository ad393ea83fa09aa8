"""clutter_pick_lift in MuJoCo: the five YCB objects scattered on the table, and the clutter sampler the cube
tasks share."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lerobot_tavis.envs import placement
from lerobot_tavis.envs.objects import OBJECT_NAMES, PROPS, PropSpec
from lerobot_tavis.envs.tasks.base import YcbTask
from lerobot_tavis.envs.tasks.clutter_pick_lift import INFO, PROMPTS, SUCCESS_HEIGHT_M
from lerobot_tavis.envs.tasks.layout import Box2D, Footprint, sample_layout


@dataclass(frozen=True)
class ClutterVariant:
    region: Box2D
    min_separation_m: float


CLUTTER_VARIANTS = {
    "id": ClutterVariant(Box2D(x=(0.35, 0.45), y=(-0.25, 0.25)), 0.10),
    "ood_spatial": ClutterVariant(Box2D(x=(0.30, 0.50), y=(-0.35, 0.35)), 0.05),
}


def footprint(prop: PropSpec) -> Footprint:
    """The outline of an upright prop seen from above."""
    if prop.shape == "cylinder":
        return Footprint(radius_m=prop.size_m[0] / 2)
    return Footprint(half_xy_m=(prop.size_m[0] / 2, prop.size_m[1] / 2))


def scatter(model, data, rng: np.random.Generator, variant: ClutterVariant, names: tuple[str, ...]) -> None:
    """Place `names` upright, in the given order, as the reference's sampler does (`layout.sample_layout`)."""
    poses = sample_layout(rng, variant.region, [footprint(PROPS[n]) for n in names], variant.min_separation_m)
    for name, pose in zip(names, poses):
        placement.place_on_table(model, data, name, *pose.xy, pose.yaw)


class ClutterPickLift(YcbTask):
    info = INFO
    success_height_m = SUCCESS_HEIGHT_M
    VARIANTS = CLUTTER_VARIANTS

    def initialize_episode(self, model, data, rng: np.random.Generator) -> None:
        self.target = OBJECT_NAMES[rng.integers(len(OBJECT_NAMES))]
        self.prompt = PROMPTS[self.target][rng.integers(3)]
        scatter(model, data, rng, self.variant, OBJECT_NAMES)
