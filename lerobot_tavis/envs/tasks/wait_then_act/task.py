"""wait_then_act in MuJoCo: one object, and a signal light that turns from red to green after a drawn delay."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import mujoco
import numpy as np

from lerobot_tavis.envs import placement
from lerobot_tavis.envs.objects import OBJECT_NAMES, add_marker
from lerobot_tavis.envs.physics import POLICY_HZ
from lerobot_tavis.envs.scene import TABLE_TOP_Z, Look, use_look
from lerobot_tavis.envs.tasks.base import TargetFacts, YcbTask
from lerobot_tavis.envs.tasks.wait_then_act import INFO, SUCCESS_HEIGHT_M
from lerobot_tavis.envs.tasks.layout import Box2D

LIGHT = "signal_light"
LIGHT_RADIUS_M = 0.03
RED = (1.0, 0.0, 0.0, 1.0)
GREEN = (0.0, 1.0, 0.0, 1.0)
# a plain diffuse ball, as the reference's (no glow, no highlight); its colour is the geom's rgba (RED or GREEN),
# which overrides the material's
LIGHT_LOOK = Look("signal_lamp", specular=0.0)


@dataclass(frozen=True)
class WaitVariant:
    object_zone: Box2D
    light_zone: Box2D
    delay_range_s: tuple[float, float]


@dataclass(frozen=True)
class WaitThenActFacts(TargetFacts):
    """The light starts red and turns green after a drawn delay; lifting the target counts only once it is green."""

    light: str  # body name of the signal light standing on the table (a mocap body; its origin is the lamp's centre)
    # whether the light shows green now (what someone watching it sees); the one fact that changes in an episode
    light_is_green: Callable[[], bool]


class WaitThenAct(YcbTask):
    info = INFO
    success_height_m = SUCCESS_HEIGHT_M
    VARIANTS = {
        "id": WaitVariant(Box2D((0.35, 0.45), (-0.12, 0.12)), Box2D((0.60, 0.70), (-0.10, 0.10)), (2.0, 5.0)),
        "ood_spatial": WaitVariant(Box2D((0.30, 0.50), (-0.20, 0.20)), Box2D((0.55, 0.75), (-0.15, 0.15)),
                                   (2.0, 8.0)),
    }

    def __init__(self, variant: str = "id"):
        super().__init__(variant)
        self.delay_s = 0.0
        self.green_at_s = 0.0
        self.is_green = False

    def build(self, spec) -> None:
        super().build(spec)
        add_marker(spec, LIGHT, mujoco.mjtGeom.mjGEOM_SPHERE, (LIGHT_RADIUS_M, 0.0, 0.0), RED)
        use_look(spec, spec.geom(LIGHT), LIGHT_LOOK)

    def bind(self, model) -> None:
        super().bind(model)
        self._light_geom = model.geom(LIGHT).id

    def initialize_episode(self, model, data, rng: np.random.Generator) -> None:
        self.target = OBJECT_NAMES[rng.integers(len(OBJECT_NAMES))]
        self.delay_s = float(rng.uniform(*self.variant.delay_range_s))
        self.green_at_s = int(self.delay_s * POLICY_HZ) / POLICY_HZ  # truncated to a 20 Hz step, as the reference
        x, y = self.variant.object_zone.sample(rng)
        placement.place_on_table(model, data, self.target, x, y, rng.uniform(-np.pi, np.pi))
        placement.hide(model, data, [n for n in OBJECT_NAMES if n != self.target])
        x, y = self.variant.light_zone.sample(rng)
        placement.set_mocap_pose(model, data, LIGHT, (x, y, TABLE_TOP_Z + LIGHT_RADIUS_M))
        self._set_green(model, False)

    def after_step(self, model, data, elapsed_s: float) -> None:
        if not self.is_green and elapsed_s >= self.green_at_s - 1e-9:
            self._set_green(model, True)

    def episode_facts(self) -> WaitThenActFacts:
        return WaitThenActFacts(props=self.props(), succeeds=self.is_success, target=self.target, light=LIGHT,
                                light_is_green=lambda: self.is_green)

    def task_state(self) -> np.ndarray:
        return np.array([float(self.is_green)])

    def evaluate(self, data) -> dict[str, bool | float]:
        """The lift rule's conditions and `light_green`; success needs all three."""
        lift = super().evaluate(data)
        return {"success": self.is_green and lift["success"], "light_green": self.is_green,
                **{name: value for name, value in lift.items() if name != "success"}}

    def _set_green(self, model, green: bool) -> None:
        self.is_green = green
        model.geom_rgba[self._light_geom] = GREEN if green else RED
