"""peeking_box in MuJoCo: one object inside a box (a mocap body) whose +y or -y wall is taken away."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from lerobot_tavis.envs import physics, placement, scene
from lerobot_tavis.envs.objects import OBJECT_NAMES, PROPS
from lerobot_tavis.envs.tasks.base import TargetFacts, YcbTask
from lerobot_tavis.envs.tasks.peeking_box import INFO, SUCCESS_HEIGHT_M
from lerobot_tavis.envs.transforms import axis_angle_quat, matrix_from_quat

BOX = "box"
# light beige board, as the box appears in the reference's renders
BOX_LOOK = scene.Look("box_board", (0.92, 0.87, 0.77, 1.0), "cardboard.png", period_m=0.25, specular=0.1,
                      shininess=0.1)
HALF_DEPTH, HALF_WIDTH, HEIGHT, WALL = 0.20, 0.07, 0.20, 0.008
BOTTOM_Z = 0.995  # sunk 5 mm into the table
WALL_Z = BOTTOM_Z + HEIGHT / 2
# name -> (full size x, y, z; centre in the box frame)
WALLS = {
    "back": ((WALL, 2 * (HALF_WIDTH + WALL), HEIGHT), (HALF_DEPTH + WALL / 2, 0.0, WALL_Z)),
    "front": ((WALL, 2 * (HALF_WIDTH + WALL), HEIGHT), (-HALF_DEPTH - WALL / 2, 0.0, WALL_Z)),
    "top": ((2 * (HALF_DEPTH + WALL), 2 * (HALF_WIDTH + WALL), WALL), (0.0, 0.0, BOTTOM_Z + HEIGHT + WALL / 2)),
    "+y": ((2 * HALF_DEPTH, WALL, HEIGHT), (0.0, HALF_WIDTH + WALL / 2, WALL_Z)),
    "-y": ((2 * HALF_DEPTH, WALL, HEIGHT), (0.0, -HALF_WIDTH - WALL / 2, WALL_Z)),
}


@dataclass(frozen=True)
class BoxVariant:
    box_x: tuple[float, float]
    box_y: tuple[float, float]
    box_yaw_rad: tuple[float, float]
    object_dx: tuple[float, float]
    object_dy: tuple[float, float]


def box_rotation(yaw_rad: float) -> np.ndarray:
    """2x2 rotation (about z) from the frame of a box turned by `yaw_rad` to the world frame."""
    return matrix_from_quat(axis_angle_quat((0, 0, 1), yaw_rad))[:2, :2]


def box_point(center_xy, yaw_rad: float, dx: float, dy: float, z: float) -> np.ndarray:
    """World point (m) at offset (dx, dy) from the box centre `center_xy` along the box's axes, at height z."""
    return np.array([*(np.asarray(center_xy) + box_rotation(yaw_rad) @ (dx, dy)), z])


@dataclass(frozen=True)
class PeekingBoxFacts(TargetFacts):
    """The box and its opening. Box frame: origin at the box's centre on the table, x from its front wall (facing
    the robot) to its back wall, y toward its +y side, turned by `yaw_rad` about world z. Sizes are of the inside."""

    open_side: str  # "+y" or "-y": the side without a wall, in the box frame
    center_xy: tuple[float, float]  # world x, y of the box's centre, m
    yaw_rad: float  # the box frame's turn about world z
    half_depth_m: float  # half the inside along the box's x
    half_width_m: float  # half the inside along the box's y
    height_m: float  # inside height
    wall_m: float  # wall thickness
    bottom_z_m: float  # world z of the inside's bottom (sunk a little into the table)

    @property
    def top_z_m(self) -> float:
        """World z of the inside's top (the lid's underside)."""
        return self.bottom_z_m + self.height_m

    @property
    def rotation(self) -> np.ndarray:
        """2x2 rotation (about z) from the box frame to the world frame."""
        return box_rotation(self.yaw_rad)

    def point(self, dx: float, dy: float, z: float) -> np.ndarray:
        """World point (m) at offset (dx, dy) from the box centre along the box's axes, at height z."""
        return box_point(self.center_xy, self.yaw_rad, dx, dy, z)

    def to_box(self, xy) -> np.ndarray:
        """A world point's x, y (m) in the box frame."""
        return self.rotation.T @ (np.asarray(xy) - np.asarray(self.center_xy))


class PeekingBox(YcbTask):
    info = INFO
    success_height_m = SUCCESS_HEIGHT_M
    VARIANTS = {
        "id": BoxVariant((0.41, 0.45), (-0.04, 0.04), tuple(np.radians((-5.0, 5.0))), (-0.04, 0.04), (-0.02, 0.02)),
        "ood_spatial": BoxVariant((0.39, 0.47), (-0.04, 0.04), tuple(np.radians((-10.0, 10.0))), (-0.04, 0.04),
                                  (-0.04, 0.04)),
    }

    def __init__(self, variant: str = "id"):
        super().__init__(variant)
        self.open_side = "+y"
        self.box_center = np.array([0.43, 0.0])
        self.box_yaw = 0.0

    @property
    def box_rotation(self) -> np.ndarray:
        """2x2 rotation (about z) from the box frame to the world frame."""
        return box_rotation(self.box_yaw)

    def box_point(self, dx: float, dy: float, z: float) -> np.ndarray:
        """World point (m) at offset (dx, dy) from the box centre along the box's axes, at height z."""
        return box_point(self.box_center, self.box_yaw, dx, dy, z)

    def build(self, spec) -> None:
        super().build(spec)
        box = spec.worldbody.add_body(name=BOX, mocap=True)
        for wall, (size, centre) in WALLS.items():
            geom = box.add_geom(name=f"box/{wall}", type=mujoco.mjtGeom.mjGEOM_BOX, pos=centre,
                                size=[s / 2 for s in size])
            physics.style_geom(geom, physics.STATIC)
            scene.use_look(spec, geom, BOX_LOOK)

    def bind(self, model) -> None:
        super().bind(model)
        self._side_geoms = {side: model.geom(f"box/{side}").id for side in ("+y", "-y")}
        self._wall_style = {side: (model.geom_contype[g], model.geom_conaffinity[g], model.geom_group[g])
                            for side, g in self._side_geoms.items()}

    def initialize_episode(self, model, data, rng: np.random.Generator) -> None:
        v = self.variant
        self.box_center = np.array([rng.uniform(*v.box_x), rng.uniform(*v.box_y)])
        self.box_yaw = float(rng.uniform(*v.box_yaw_rad))
        self.open_side = ("+y", "-y")[rng.integers(2)]
        self.target = OBJECT_NAMES[rng.integers(len(OBJECT_NAMES))]
        placement.set_mocap_pose(model, data, BOX, (*self.box_center, 0.0), self.box_yaw)
        for side, geom in self._side_geoms.items():
            contype, conaffinity, group = self._wall_style[side] if side != self.open_side else (0, 0, 3)
            model.geom_contype[geom], model.geom_conaffinity[geom], model.geom_group[geom] = contype, conaffinity, group
        yaw = rng.uniform(-np.pi, np.pi)
        # keep the object inside the walls whatever its yaw (the reference's offsets can push a long box into one)
        hx, hy = PROPS[self.target].half_extent_xy(yaw)
        dx = np.clip(rng.uniform(*v.object_dx), -HALF_DEPTH + hx, HALF_DEPTH - hx)
        dy = np.clip(rng.uniform(*v.object_dy), -HALF_WIDTH + hy + 0.003, HALF_WIDTH - hy - 0.003)
        x, y, _ = self.box_point(dx, dy, 0.0)
        placement.place_on_table(model, data, self.target, x, y, self.box_yaw + yaw)
        placement.hide(model, data, [n for n in OBJECT_NAMES if n != self.target])

    def episode_facts(self) -> PeekingBoxFacts:
        return PeekingBoxFacts(props=self.props(), succeeds=self.is_success, target=self.target,
                               open_side=self.open_side, center_xy=tuple(self.box_center.tolist()),
                               yaw_rad=self.box_yaw, half_depth_m=HALF_DEPTH, half_width_m=HALF_WIDTH, height_m=HEIGHT,
                               wall_m=WALL, bottom_z_m=BOTTOM_Z)
