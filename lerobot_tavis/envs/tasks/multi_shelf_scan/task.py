"""multi_shelf_scan in MuJoCo: a three-shelf unit (no table), five objects in six slots, its own key light."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from lerobot_tavis.envs import physics, placement, scene
from lerobot_tavis.envs.objects import OBJECT_NAMES, PROPS
from lerobot_tavis.envs.placement import body_speed
from lerobot_tavis.envs.tasks.base import MEASURE_DECIMALS, YcbTask
from lerobot_tavis.envs.tasks.info import MAX_SUCCESS_SPEED_M_S
from lerobot_tavis.envs.tasks.multi_shelf_scan import INFO, PROMPTS, SHELF_DEPTH, SHELF_EXIT_X_M, SHELF_X

SHELF_WIDTH = 0.70
BOARD_THICKNESS = 0.02
BOARD_Z = (0.97, 1.10, 1.27)  # centres of the three shelf boards; the top board is at 1.52
TOP_BOARD_Z = 1.52
SLOT_Y = (0.15, -0.15)
SLOTS = tuple((shelf, y) for shelf in range(3) for y in SLOT_Y)  # 6 slots: the reference removed the middle ones
SLOT_X_CLAMP = (0.485, 0.555)
SLOT_Y_CLAMP = (-0.32, 0.32)
INNER_X = (SHELF_X - SHELF_DEPTH / 2, SHELF_X + SHELF_DEPTH / 2 - 0.005)  # open front .. back panel
INNER_Y = (-SHELF_WIDTH / 2, SHELF_WIDTH / 2)
# This task's own key light (docs/reference.md §4): from behind-left of the robot into the shelf's open front.
KEY_LIGHT_DIR = (0.643, -0.236, -0.728)
KEY_LIGHT_INTENSITY = 1000.0
# Light wood, as the shelf appears in the reference's renders (its base colour (0.55, 0.35, 0.20) is lit there far
# more strongly than MuJoCo's clamped lighting allows). The back panel is a shade darker, so that the boards stand
# out against it also with shadows off.
SHELF_LOOK = scene.Look("shelf_wood", (0.94, 0.79, 0.58, 1.0), "wood.png", period_m=0.5, specular=0.1, shininess=0.1)
SHELF_BACK_LOOK = scene.Look("shelf_back", (0.78, 0.64, 0.46, 1.0), "wood.png", period_m=0.5, specular=0.1,
                             shininess=0.1)


@dataclass(frozen=True)
class ShelfVariant:
    jitter_x_m: float
    jitter_y_m: float


class MultiShelfScan(YcbTask):
    info = INFO
    VARIANTS = {"id": ShelfVariant(0.03, 0.03), "ood_spatial": ShelfVariant(0.03, 0.10)}
    has_table = False

    def __init__(self, variant: str = "id"):
        super().__init__(variant)
        self.slots: dict[str, tuple[int, float]] = {}

    def build(self, spec) -> None:
        super().build(spec)
        shelf = spec.worldbody.add_body(name="shelf")
        height = TOP_BOARD_Z - BOARD_Z[0] + BOARD_THICKNESS
        mid_z = (BOARD_Z[0] + TOP_BOARD_Z) / 2
        boxes = [(f"shelf/board{i}", (SHELF_X, 0.0, z), (SHELF_DEPTH, SHELF_WIDTH, BOARD_THICKNESS))
                 for i, z in enumerate((*BOARD_Z, TOP_BOARD_Z))]
        boxes += [(f"shelf/side{i}", (SHELF_X, s * (SHELF_WIDTH / 2 + 0.01), mid_z), (SHELF_DEPTH, 0.02, height))
                  for i, s in enumerate((1, -1))]
        boxes.append(("shelf/back", (SHELF_X + SHELF_DEPTH / 2 + 0.005, 0.0, mid_z), (0.01, SHELF_WIDTH, height)))
        for name, pos, size in boxes:
            geom = shelf.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_BOX, pos=pos, size=[s / 2 for s in size])
            physics.style_geom(geom, physics.STATIC)
            scene.use_look(spec, geom, SHELF_BACK_LOOK if name == "shelf/back" else SHELF_LOOK)
        scene.set_key_light(spec, KEY_LIGHT_DIR, KEY_LIGHT_INTENSITY)

    def initialize_episode(self, model, data, rng: np.random.Generator) -> None:
        chosen = rng.choice(len(SLOTS), size=len(OBJECT_NAMES), replace=False)
        self.slots = {name: SLOTS[i] for name, i in zip(OBJECT_NAMES, chosen)}
        self.target = OBJECT_NAMES[rng.integers(len(OBJECT_NAMES))]
        self.prompt = PROMPTS[self.target][rng.integers(3)]
        for name, (shelf, slot_y) in self.slots.items():
            jitter = rng.uniform(-1.0, 1.0, size=2) * (self.variant.jitter_x_m, self.variant.jitter_y_m)
            yaw = rng.uniform(-np.pi, np.pi)
            hx, hy = PROPS[name].half_extent_xy(yaw)
            # the reference's clamps, tightened so an object never sticks into the back panel or a side wall
            x = np.clip(SHELF_X + jitter[0], max(SLOT_X_CLAMP[0], INNER_X[0] + hx),
                        min(SLOT_X_CLAMP[1], INNER_X[1] - hx))
            y = np.clip(slot_y + jitter[1], max(SLOT_Y_CLAMP[0], INNER_Y[0] + hy),
                        min(SLOT_Y_CLAMP[1], INNER_Y[1] - hy))
            surface = BOARD_Z[shelf] + BOARD_THICKNESS / 2
            placement.set_free_pose(model, data, name, (x, y, placement.standing_z(name, surface)), yaw)

    def evaluate(self, data) -> dict[str, bool | float]:
        """`target_out_of_shelf`: the origin nearer than x = `SHELF_EXIT_X_M` (`target_x_m`); `target_slow`:
        slower than `MAX_SUCCESS_SPEED_M_S` (`target_speed_m_s`); measures to `MEASURE_DECIMALS`."""
        x = float(data.xpos[self._model.body(self.target).id][0])
        speed = body_speed(self._model, data, self.target)
        out, slow = x < SHELF_EXIT_X_M, speed < MAX_SUCCESS_SPEED_M_S
        return {"success": out and slow, "target_out_of_shelf": out, "target_slow": slow,
                "target_x_m": round(x, MEASURE_DECIMALS), "target_speed_m_s": round(speed, MEASURE_DECIMALS)}
