"""The suite's five YCB objects and the red cube, as coloured primitives.

Sizes are the published YCB dimensions times the benchmark's 0.75 scale, masses the YCB masses times 0.75³
(reference/robots_objects_physics.md §2). Every object stands upright: a box's third size is its height. The
collision shape is one primitive; thin visual-only bands on top give each object its recognisable colour pattern.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco

from lerobot_tavis.envs import physics

YCB_SCALE = 0.75


@dataclass(frozen=True)
class Band:
    """A visual colour band covering the object's side between two heights (fractions of its height, 0 = bottom)."""

    bottom: float
    top: float
    rgba: tuple[float, float, float, float]


@dataclass(frozen=True)
class PropSpec:
    """A graspable object. `size_m` is (diameter, height) for cylinders, (x, y, height) for boxes, in metres."""

    name: str
    label: str
    shape: str  # "cylinder" or "box"
    size_m: tuple[float, ...]
    mass_kg: float
    rgba: tuple[float, float, float, float]
    bands: tuple[Band, ...] = field(default=())

    @property
    def height_m(self) -> float:
        return self.size_m[-1]

    def half_extent_xy(self, yaw_rad: float) -> tuple[float, float]:
        """Half extents (m) along world x and y when standing upright, turned `yaw_rad` about z."""
        if self.shape == "cylinder":
            return self.size_m[0] / 2, self.size_m[0] / 2
        hx, hy = self.size_m[0] / 2, self.size_m[1] / 2
        c, s = abs(math.cos(yaw_rad)), abs(math.sin(yaw_rad))
        return c * hx + s * hy, s * hx + c * hy

    @property
    def footprint_radius_m(self) -> float:
        """Radius of the smallest vertical cylinder around the object, for spacing objects apart."""
        if self.shape == "cylinder":
            return self.size_m[0] / 2
        return 0.5 * (self.size_m[0] ** 2 + self.size_m[1] ** 2) ** 0.5


def _ycb(name, label, shape, size_mm, mass_g, rgba, bands=()) -> PropSpec:
    size = tuple(s / 1000.0 * YCB_SCALE for s in size_mm)
    return PropSpec(name, label, shape, size, mass_g / 1000.0 * YCB_SCALE**3, rgba, tuple(bands))


RED = (0.80, 0.08, 0.07, 1.0)
WHITE = (0.93, 0.92, 0.88, 1.0)
SILVER = (0.72, 0.73, 0.75, 1.0)
BLUE = (0.10, 0.22, 0.62, 1.0)
YELLOW = (0.95, 0.78, 0.10, 1.0)
PINK = (0.96, 0.45, 0.62, 1.0)
BROWN = (0.40, 0.24, 0.12, 1.0)
CREAM = (0.90, 0.82, 0.62, 1.0)

YCB_OBJECTS: dict[str, PropSpec] = {
    spec.name: spec
    for spec in (
        _ycb("soup_can", "tomato soup can", "cylinder", (66, 101), 349, SILVER,
             [Band(0.02, 0.5, WHITE), Band(0.5, 0.97, RED)]),
        _ycb("meat_can", "potted meat can", "box", (50, 97, 82), 370, BLUE, [Band(0.35, 0.65, YELLOW)]),
        _ycb("tuna_fish_can", "tuna fish can", "cylinder", (85, 33), 171, SILVER, [Band(0.08, 0.85, BLUE)]),
        _ycb("gelatin_box", "gelatin box", "box", (28, 85, 73), 97, RED, [Band(0.55, 0.95, PINK)]),
        _ycb("pudding_box", "pudding box", "box", (35, 110, 89), 187, BROWN, [Band(0.60, 0.85, CREAM)]),
    )
}
OBJECT_NAMES: tuple[str, ...] = tuple(YCB_OBJECTS)  # the reference's sampling order

CUBE_EDGE_M = 0.055
RED_CUBE = PropSpec("red_cube", "red cube", "box", (CUBE_EDGE_M,) * 3, 1000.0 * CUBE_EDGE_M**3,
                    (0.9, 0.1, 0.1, 1.0))
PROPS: dict[str, PropSpec] = {**YCB_OBJECTS, RED_CUBE.name: RED_CUBE}

_BAND_INFLATE_M = 0.0006  # bands sit just outside the collision shape so they never z-fight with it


def add_prop(spec: mujoco.MjSpec, prop: PropSpec) -> mujoco.MjsBody:
    """Add `prop` as a free body named after it; its origin is the centre of its collision shape."""
    body = spec.worldbody.add_body(name=prop.name)
    body.add_freejoint(name=prop.name)
    half_h = prop.height_m / 2
    if prop.shape == "cylinder":
        geom_type, half_xy = mujoco.mjtGeom.mjGEOM_CYLINDER, (prop.size_m[0] / 2,)
    else:
        geom_type, half_xy = mujoco.mjtGeom.mjGEOM_BOX, (prop.size_m[0] / 2, prop.size_m[1] / 2)
    collision = body.add_geom(name=prop.name, type=geom_type)
    collision.size = _size(geom_type, half_xy, half_h)
    collision.mass = prop.mass_kg
    collision.friction = physics.OBJECT_FRICTION
    physics.style_geom(collision, physics.PROP, prop.rgba)
    for i, band in enumerate(prop.bands):
        geom = body.add_geom(name=f"{prop.name}/band{i}", type=geom_type)
        band_half = (band.top - band.bottom) * half_h
        geom.size = _size(geom_type, tuple(h + _BAND_INFLATE_M for h in half_xy), band_half)
        geom.pos = (0.0, 0.0, -half_h + (band.bottom + band.top) * half_h)
        physics.style_geom(geom, physics.VISUAL, band.rgba)
    return body


def _size(geom_type, half_xy: tuple[float, ...], half_height: float) -> tuple[float, float, float]:
    if geom_type == mujoco.mjtGeom.mjGEOM_CYLINDER:
        return (half_xy[0], half_height, 0.0)
    return (half_xy[0], half_xy[1], half_height)


def add_marker(spec: mujoco.MjSpec, name: str, geom_type, size, rgba) -> mujoco.MjsBody:
    """A kinematic, visual-only body (cue card, signal light): moved per episode, touches nothing."""
    body = spec.worldbody.add_body(name=name, mocap=True)
    geom = body.add_geom(name=name, type=geom_type, size=size)
    physics.style_geom(geom, physics.VISUAL, rgba)
    return body
