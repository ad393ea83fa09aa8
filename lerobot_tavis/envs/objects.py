"""The suite's five YCB objects and the red cube: sizes, masses, and how each is added to a model.

Sizes are the published YCB dimensions times the benchmark's 0.75 scale, masses the YCB masses times 0.75³
(docs/reference.md §13). Every object stands upright (a box's third size is its height) on one
collision primitive whose centre is the body's origin. Dressed, a YCB object is drawn as its scanned, textured mesh
(`lerobot_tavis/assets/ycb/`, fitted onto the primitive's extents by `tools/assets/ycb.py`) and the primitive is
hidden; undressed, the primitive itself is drawn in the object's colour. Physics is the same either way. The red
cube is always its primitive.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco

from lerobot_tavis.envs import assets, physics

YCB_SCALE = 0.75


@dataclass(frozen=True)
class Surface:
    """How a scanned object's material answers the scene light (MuJoCo material terms, 0-1; no reflections)."""

    specular: float
    shininess: float


METAL = Surface(specular=0.4, shininess=0.5)  # printed tinplate: a soft highlight
CARDBOARD = Surface(specular=0.08, shininess=0.1)  # printed board: nearly matte


@dataclass(frozen=True)
class PropSpec:
    """A graspable object. `size_m` is (diameter, height) for cylinders, (x, y, height) for boxes, in metres."""

    name: str
    label: str
    shape: str  # "cylinder" or "box"
    size_m: tuple[float, ...]
    mass_kg: float
    rgba: tuple[float, float, float, float]  # the primitive's colour when it is drawn
    surface: Surface | None = None  # a scanned mesh `assets/ycb/<name>.obj` + `.png` exists when set

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


def _ycb(name, label, shape, size_mm, mass_g, rgba, surface) -> PropSpec:
    size = tuple(s / 1000.0 * YCB_SCALE for s in size_mm)
    return PropSpec(name, label, shape, size, mass_g / 1000.0 * YCB_SCALE**3, rgba, surface)


YCB_OBJECTS: dict[str, PropSpec] = {
    spec.name: spec
    for spec in (
        _ycb("soup_can", "tomato soup can", "cylinder", (66, 101), 349, (0.78, 0.12, 0.10, 1.0), METAL),
        _ycb("meat_can", "potted meat can", "box", (50, 97, 82), 370, (0.12, 0.22, 0.60, 1.0), METAL),
        _ycb("tuna_fish_can", "tuna fish can", "cylinder", (85, 33), 171, (0.20, 0.35, 0.70, 1.0), METAL),
        _ycb("gelatin_box", "gelatin box", "box", (28, 85, 73), 97, (0.85, 0.15, 0.15, 1.0), CARDBOARD),
        _ycb("pudding_box", "pudding box", "box", (35, 110, 89), 187, (0.40, 0.24, 0.14, 1.0), CARDBOARD),
    )
}
OBJECT_NAMES: tuple[str, ...] = tuple(YCB_OBJECTS)  # the reference's sampling order

CUBE_EDGE_M = 0.055
RED_CUBE = PropSpec("red_cube", "red cube", "box", (CUBE_EDGE_M,) * 3, 1000.0 * CUBE_EDGE_M**3,
                    (0.9, 0.1, 0.1, 1.0))
PROPS: dict[str, PropSpec] = {**YCB_OBJECTS, RED_CUBE.name: RED_CUBE}


def add_prop(spec: mujoco.MjSpec, prop: PropSpec, *, dressed: bool = True) -> mujoco.MjsBody:
    """Add `prop` as a free body named after it; its origin is the centre of its collision shape.

    `dressed`: draw a scanned object as its textured mesh (geom `<name>/mesh`) and hide the collision primitive;
    otherwise the primitive is drawn in `prop.rgba`. Objects without a scan are always drawn as their primitive.
    """
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
    scanned = dressed and prop.surface is not None
    physics.style_geom(collision, physics.PROP, prop.rgba,
                       group=physics.GROUP_HIDDEN if scanned else physics.GROUP_VISIBLE)
    if scanned:
        _add_scan(spec, body, prop)
    return body


def _add_scan(spec: mujoco.MjSpec, body: mujoco.MjsBody, prop: PropSpec) -> None:
    """The scanned mesh, texture and material of `prop` (all named `ycb/<name>`) and its visual geom."""
    asset = f"ycb/{prop.name}"
    assets.add_mesh(spec, asset, f"{asset}.obj")
    assets.add_texture(spec, asset, f"{asset}.png")
    assets.add_material(spec, asset, texture=asset, specular=prop.surface.specular,
                        shininess=prop.surface.shininess)
    assets.add_visual_mesh(body, f"{prop.name}/mesh", asset, asset)


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
