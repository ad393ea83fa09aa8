"""The arena shared by every task: floor, table, lights, backdrop and the scene-fixed workspace camera; and the
materials ("looks") that the arena and the tasks' props are drawn with.

World frame: x forward from the robot, y to its left, z up, floor at z = 0, table top at z = 1.0.

Lighting follows the reference (docs/reference.md §2): a white dome (here the headlight's ambient and a soft camera
fill) plus one distant key light from the front-left, above. MuJoCo's fixed-function lights have no physical units,
so the reference's intensities only set ratios: `set_key_light` scales the key light by intensity / 2000.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from lerobot_tavis.envs import physics
from lerobot_tavis.envs.assets import add_material, add_texture
from lerobot_tavis.envs.modes import OVERVIEW_CAMERA
from lerobot_tavis.envs.transforms import camera_quat, vfov_deg

TABLE_TOP_Z = 1.0
TABLE_X = (0.25, 0.85)
TABLE_Y = (-0.55, 0.55)
TABLE_THICKNESS = 0.04
TABLE_SURFACE_GRID_M = 0.05  # tessellation of the drawn table top (m)
TABLE_SURFACE_LIFT_M = 0.0005  # the drawn top lies this far above the collision box's top face
FLOOR_GRID_M = 0.5  # tessellation of the drawn floor (m)

# Workspace camera (docs/reference.md §3): above and in front of the robot, optical axis forward and 45° down.
FIXED_CAMERA = "fixed"
FIXED_CAMERA_POS = (0.2, 0.0, 1.43)
FIXED_CAMERA_HFOV_DEG = 120.0

# Key light (docs/reference.md §2): travelling toward the robot and down, intensity 2000 beside a dome of 800.
KEY_LIGHT = "key_light"
KEY_LIGHT_DIR = (-0.342, -0.321, -0.883)
KEY_LIGHT_INTENSITY = 2000.0
KEY_DIFFUSE_AT_REFERENCE = 0.5  # diffuse gain that gives the reference's lit/shadowed contrast at intensity 2000
KEY_SPECULAR_AT_REFERENCE = 0.6
SHADOW_MAP_PX = 1024  # the key light's shadow map, when shadows are on
DOME_AMBIENT = 0.5  # the headlight's ambient, grey


@dataclass(frozen=True)
class Look:
    """How a surface is drawn: a MuJoCo material.

    `rgba` tints the texture (or is the colour, without one); a geom's own rgba replaces it when the geom's rgba
    is not MuJoCo's default (0.5, 0.5, 0.5, 1), which is how tasks switch a cue's colour at run time.
    `texture` is a PNG under `lerobot_tavis/assets/scene/`, repeated every `period_m` metres on every face.
    `emission` (0-1) makes the surface glow in its own colour, whatever the lighting.
    """

    name: str
    rgba: tuple[float, float, float, float] = (1.0, 1.0, 1.0, 1.0)
    texture: str | None = None
    period_m: float = 1.0
    specular: float = 0.2
    shininess: float = 0.2
    emission: float = 0.0


TABLE_TOP_LOOK = Look("table_top", (0.76, 0.77, 0.79, 1.0), "brushed_metal.png", period_m=1.0, specular=0.5,
                      shininess=0.12)
TABLE_LEG_LOOK = Look("table_leg", (0.30, 0.30, 0.32, 1.0), "brushed_metal.png", period_m=1.0, specular=0.4,
                      shininess=0.3)
FLOOR_LOOK = Look("floor", texture="floor_tile.png", period_m=0.5, specular=0.15, shininess=0.1)


def use_look(spec: mujoco.MjSpec, geom: mujoco.MjsGeom, look: Look) -> None:
    """Draw `geom` with `look`, adding its material (and texture) to `spec` the first time it is used."""
    material = f"look/{look.name}"
    if spec.material(material) is None:
        texture = None
        if look.texture is not None:
            texture = f"look/{look.texture}"
            if spec.texture(texture) is None:
                add_texture(spec, texture, f"scene/{look.texture}")
        # with texuniform, MuJoCo repeats a texture `texrepeat` times per 2 m of geom surface
        repeat = 2.0 / look.period_m
        add_material(spec, material, rgba=look.rgba, texture=texture, specular=look.specular,
                     shininess=look.shininess, texrepeat=(repeat, repeat), texuniform=True)
        spec.material(material).emission = look.emission
    geom.material = material


def add_sky(spec: mujoco.MjSpec) -> None:
    """A plain light-grey backdrop, so cameras looking above the table do not see black."""
    spec.add_texture(name="sky", type=mujoco.mjtTexture.mjTEXTURE_SKYBOX, builtin=mujoco.mjtBuiltin.mjBUILTIN_GRADIENT,
                     rgb1=(0.91, 0.91, 0.92), rgb2=(0.80, 0.80, 0.82), width=64, height=64)


def add_floor(spec: mujoco.MjSpec) -> None:
    """The ground plane (collision only) and, drawn in its place, a dark tiled floor (0.5 m tiles).

    The drawn plane is a separate visual geom because MuJoCo tessellates a plane by its third size: the collision
    plane's 5 cm grid costs about 1 ms per 240x320 frame on a CPU, a 0.5 m grid almost nothing.
    """
    floor = spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=(4.0, 4.0, 0.05))
    physics.style_geom(floor, physics.STATIC, group=physics.GROUP_HIDDEN)
    tiles = spec.worldbody.add_geom(name="floor/tiles", type=mujoco.mjtGeom.mjGEOM_PLANE,
                                    size=(4.0, 4.0, FLOOR_GRID_M))
    physics.style_geom(tiles, physics.VISUAL)
    tiles.castshadow = False  # nothing lies under it
    use_look(spec, tiles, FLOOR_LOOK)


def add_table(spec: mujoco.MjSpec) -> None:
    """A static table whose brushed-metal top surface is at TABLE_TOP_Z, on four legs."""
    table = spec.worldbody.add_body(name="table")
    cx, cy = np.mean(TABLE_X), np.mean(TABLE_Y)
    hx, hy = (TABLE_X[1] - TABLE_X[0]) / 2, (TABLE_Y[1] - TABLE_Y[0]) / 2
    top = table.add_geom(name="table/top", type=mujoco.mjtGeom.mjGEOM_BOX)
    top.size = (hx, hy, TABLE_THICKNESS / 2)
    top.pos = (cx, cy, TABLE_TOP_Z - TABLE_THICKNESS / 2)
    physics.style_geom(top, physics.STATIC)
    use_look(spec, top, TABLE_TOP_LOOK)
    # The top face drawn again as a finely tessellated plane just above it: MuJoCo lights per vertex, and a box
    # face's few vertices would turn the key light's soft highlight into blotches.
    surface = table.add_geom(name="table/surface", type=mujoco.mjtGeom.mjGEOM_PLANE)
    surface.size = (hx, hy, TABLE_SURFACE_GRID_M)
    surface.pos = (cx, cy, TABLE_TOP_Z + TABLE_SURFACE_LIFT_M)
    physics.style_geom(surface, physics.VISUAL)
    surface.castshadow = False  # the box below casts the table's shadow
    use_look(spec, surface, TABLE_TOP_LOOK)
    leg_half_h = (TABLE_TOP_Z - TABLE_THICKNESS) / 2
    for i, (sx, sy) in enumerate(((1, 1), (1, -1), (-1, 1), (-1, -1))):
        leg = table.add_geom(name=f"table/leg{i}", type=mujoco.mjtGeom.mjGEOM_BOX)
        leg.size = (0.025, 0.025, leg_half_h)
        leg.pos = (cx + sx * (hx - 0.05), cy + sy * (hy - 0.05), leg_half_h)
        physics.style_geom(leg, physics.VISUAL)
        use_look(spec, leg, TABLE_LEG_LOOK)


def add_lights(spec: mujoco.MjSpec, *, shadows: bool) -> None:
    """The dome (headlight ambient plus a weak fill from the camera) and the distant key light.

    Only the key light can cast shadows, and they are opt-in: on a 2-core CPU (llvmpipe) they cut head_only 240x320
    from about 140 to about 30 policy steps/s (`benchmarks/env_speed.py --shadows`); a 512 px shadow map is no
    cheaper than 1024, the cost being MuJoCo's extra lit pass over the frame.
    """
    spec.visual.headlight.ambient = (DOME_AMBIENT,) * 3
    spec.visual.headlight.diffuse = (0.15, 0.15, 0.15)
    spec.visual.headlight.specular = (0.0, 0.0, 0.0)
    spec.visual.quality.shadowsize = SHADOW_MAP_PX
    key = spec.worldbody.add_light(name=KEY_LIGHT, type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL)
    key.pos = (1.0, 1.0, 3.0)
    key.castshadow = shadows
    set_key_light(spec, KEY_LIGHT_DIR, KEY_LIGHT_INTENSITY)


def set_key_light(spec: mujoco.MjSpec, direction, intensity: float) -> None:
    """Point the key light along `direction` (world, the way the light travels) with the reference's `intensity`
    (2000 in most tasks). Tasks with their own lighting call this from `build`."""
    if intensity < 0:
        raise ValueError(f"key light intensity must be >= 0, got {intensity}")
    key = spec.light(KEY_LIGHT)
    if key is None:
        raise ValueError(f"the spec has no {KEY_LIGHT!r}: call add_arena first")
    key.dir = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    gain = intensity / KEY_LIGHT_INTENSITY
    key.diffuse = (KEY_DIFFUSE_AT_REFERENCE * gain,) * 3
    key.specular = (KEY_SPECULAR_AT_REFERENCE * gain,) * 3


def add_fixed_camera(spec: mujoco.MjSpec) -> None:
    forward = (np.cos(np.pi / 4), 0.0, -np.sin(np.pi / 4))
    spec.worldbody.add_camera(
        name=FIXED_CAMERA,
        pos=FIXED_CAMERA_POS,
        quat=camera_quat(forward, up=(0.0, 0.0, 1.0)),
        fovy=vfov_deg(FIXED_CAMERA_HFOV_DEG),
    )


# Third-person view for people (gallery, videos), never observed by a policy: front-right, above the table edge.
OVERVIEW_CAMERA_POS = (1.20, -0.90, 1.90)
OVERVIEW_LOOK_AT = (0.15, 0.0, 1.15)


def add_overview_camera(spec: mujoco.MjSpec) -> None:
    forward = np.subtract(OVERVIEW_LOOK_AT, OVERVIEW_CAMERA_POS)
    spec.worldbody.add_camera(name=OVERVIEW_CAMERA, pos=OVERVIEW_CAMERA_POS,
                              quat=camera_quat(forward, up=(0.0, 0.0, 1.0)), fovy=42.0)


def add_arena(spec: mujoco.MjSpec, *, table: bool = True, shadows: bool = False) -> None:
    add_sky(spec)
    add_floor(spec)
    if table:
        add_table(spec)
    add_lights(spec, shadows=shadows)
    add_fixed_camera(spec)
    add_overview_camera(spec)
