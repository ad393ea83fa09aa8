"""The arena shared by every task: floor, table, lights, backdrop and the scene-fixed workspace camera; and the
materials ("looks") that the arena and the tasks' props are drawn with.

World frame: x forward from the robot, y to its left, z up, floor at z = 0, table top at z = 1.0.

Lighting follows the reference (docs/reference.md §2): a white dome (here the headlight's ambient and a soft camera
fill) plus one distant key light from the front-left, above, which casts the scene's shadows (on by default, as in
the reference). MuJoCo's fixed-function lights have no physical units, so the reference's intensities only set
ratios: `set_key_light` scales the key light by intensity / 2000.

Shadows cost a depth pass from the light and a second lit pass per rendered image, so they are kept cheap: one
shadow-casting light, a SHADOW_MAP_PX map spent on a square SHADOW_HALF_WIDTH_M around SHADOW_CENTRE (the light is
placed on the line through it), and only what can shadow the workspace casts: the robot, the props and the task's
own scenery, not the arena (floor, table, backdrop). `rendering.CameraRig` also leaves out of each image the geoms
that can neither appear in it nor shadow what does.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from lerobot_tavis.envs import physics
from lerobot_tavis.envs.assets import add_material, add_texture
from lerobot_tavis.envs.modes import OVERVIEW_CAMERA
from lerobot_tavis.envs.transforms import camera_quat, vfov_deg

# The reference's packing table as the paper's figure shows it (docs/assets.md): a grey metal top 1.0 m high whose
# front and back edges lie near x 0.22 and 0.90 and whose sides lie beyond every camera's view (2.6 m wide, centred
# on y -0.1 like the reference's table pose), a rounded front lip, and storage bins on a shelf under the front edge.
TABLE_TOP_Z = 1.0
TABLE_X = (0.22, 0.90)
TABLE_Y = (-1.40, 1.20)
TABLE_THICKNESS = 0.05
TABLE_LIP_RADIUS_M = 0.025  # the front edge is a half-round bullnose, flush with the top
TABLE_LEG_HALF_M = 0.03  # square legs, set in from the edges by TABLE_LEG_INSET_M
TABLE_LEG_INSET_M = 0.06
BIN_SHELF_Z = 0.60  # the shelf's top face; bins stand on it just behind the front edge
BIN_SIZE_M = (0.35, 0.42, 0.20)  # depth (x), width (y), height (z)
BIN_GAP_M = 0.04
BIN_FRONT_X = 0.25
TABLE_BODY = "table"
TABLE_SLAB, TABLE_LIP, TABLE_SURFACE = "table/top", "table/lip", "table/surface"
TABLE_TOP_GEOMS = (TABLE_SLAB, TABLE_LIP, TABLE_SURFACE)  # drawn with TABLE_TOP_LOOK (ood_visual varies it)
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
SHADOW_MAP_PX = 512  # the key light's shadow map (texels a side)
# The square (m, across the light's beam) that the shadow map covers, centred where the key light's line meets
# the workspace: the table top in front of the robot, with the robot's shoulders and the arms' reach
SHADOW_CENTRE = (0.5, 0.0, TABLE_TOP_Z)
SHADOW_HALF_WIDTH_M = 1.0
KEY_LIGHT_DISTANCE_M = 3.0  # from SHADOW_CENTRE back along the light: above everything that casts
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
BIN_LOOKS = (Look("bin_blue", (0.13, 0.30, 0.62, 1.0)), Look("bin_yellow", (0.86, 0.70, 0.14, 1.0)),
             Look("bin_cardboard", (0.62, 0.47, 0.30, 1.0)))
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


SKY_RGB = ((0.91, 0.91, 0.92), (0.80, 0.80, 0.82))  # the backdrop's gradient, top to horizon


def add_sky(spec: mujoco.MjSpec) -> None:
    """A plain light-grey backdrop, so cameras looking above the table do not see black; what lies beyond a wrist
    camera's far clip is drawn in its mean colour (`physics.WRIST_FAR_CLIP_M`)."""
    spec.add_texture(name="sky", type=mujoco.mjtTexture.mjTEXTURE_SKYBOX, builtin=mujoco.mjtBuiltin.mjBUILTIN_GRADIENT,
                     rgb1=SKY_RGB[0], rgb2=SKY_RGB[1], width=64, height=64)
    spec.visual.rgba.fog = (*np.mean(SKY_RGB, axis=0), 1.0)


def add_floor(spec: mujoco.MjSpec) -> None:
    """The ground plane (collision only) and, drawn in its place, a dark tiled floor (0.5 m tiles).

    The drawn plane is a separate visual geom because MuJoCo tessellates a plane by its third size: the collision
    plane's 5 cm grid would draw a hundred times the triangles of a 0.5 m one, which a CPU renderer pays for.
    """
    floor = spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=(4.0, 4.0, 0.05))
    physics.style_geom(floor, physics.STATIC, group=physics.GROUP_HIDDEN)
    tiles = spec.worldbody.add_geom(name="floor/tiles", type=mujoco.mjtGeom.mjGEOM_PLANE,
                                    size=(4.0, 4.0, FLOOR_GRID_M))
    physics.style_geom(tiles, physics.VISUAL)
    tiles.castshadow = False  # nothing lies under it
    use_look(spec, tiles, FLOOR_LOOK)


def add_table(spec: mujoco.MjSpec) -> None:
    """The static packing table: a brushed-metal top whose surface is at TABLE_TOP_Z over TABLE_X x TABLE_Y, with a
    rounded front lip, on six legs, and a shelf of coloured bins under its front edge.

    The top and the lip collide; legs, shelf and bins are drawn only (nothing reaches under the table) and cast no
    shadow (they stand in the top's shadow).
    """
    table = spec.worldbody.add_body(name=TABLE_BODY)
    lip = TABLE_LIP_RADIUS_M
    x0, x1 = TABLE_X[0] + lip, TABLE_X[1]  # the flat top; the lip rounds off its front
    y0, y1 = TABLE_Y
    cx, cy, hx, hy = (x0 + x1) / 2, (y0 + y1) / 2, (x1 - x0) / 2, (y1 - y0) / 2
    top = table.add_geom(name=TABLE_SLAB, type=mujoco.mjtGeom.mjGEOM_BOX)
    top.size = (hx, hy, TABLE_THICKNESS / 2)
    top.pos = (cx, cy, TABLE_TOP_Z - TABLE_THICKNESS / 2)
    physics.style_geom(top, physics.STATIC)
    use_look(spec, top, TABLE_TOP_LOOK)
    front = table.add_geom(name=TABLE_LIP, type=mujoco.mjtGeom.mjGEOM_CAPSULE,
                           fromto=(x0, y0 + lip, TABLE_TOP_Z - lip, x0, y1 - lip, TABLE_TOP_Z - lip), size=(lip, 0, 0))
    physics.style_geom(front, physics.STATIC)
    use_look(spec, front, TABLE_TOP_LOOK)
    # The top face drawn again as a finely tessellated plane just above it: MuJoCo lights per vertex, and a box
    # face's few vertices would turn the key light's soft highlight into blotches.
    surface = table.add_geom(name=TABLE_SURFACE, type=mujoco.mjtGeom.mjGEOM_PLANE)
    surface.size = (hx, hy, TABLE_SURFACE_GRID_M)
    surface.pos = (cx, cy, TABLE_TOP_Z + TABLE_SURFACE_LIFT_M)
    physics.style_geom(surface, physics.VISUAL)
    surface.castshadow = False  # the box below casts the table's shadow
    use_look(spec, surface, TABLE_TOP_LOOK)

    def drawn_box(name: str, centre, half_size, look: Look) -> None:
        geom = table.add_geom(name=f"table/{name}", type=mujoco.mjtGeom.mjGEOM_BOX, pos=centre, size=half_size)
        physics.style_geom(geom, physics.VISUAL)
        geom.castshadow = False
        use_look(spec, geom, look)

    leg_half_h = (TABLE_TOP_Z - TABLE_THICKNESS) / 2
    leg_x = (TABLE_X[0] + TABLE_LEG_INSET_M, TABLE_X[1] - TABLE_LEG_INSET_M)
    leg_y = (y0 + TABLE_LEG_INSET_M, y1 - TABLE_LEG_INSET_M)
    legs = [(x, y) for x in leg_x for y in leg_y] + [(leg_x[1], cy)]  # no middle front leg: the robot stands there
    for i, (x, y) in enumerate(legs):
        drawn_box(f"leg{i}", (x, y, leg_half_h), (TABLE_LEG_HALF_M, TABLE_LEG_HALF_M, leg_half_h), TABLE_LEG_LOOK)
    shelf_half_z = 0.01
    drawn_box("shelf", (cx, cy, BIN_SHELF_Z - shelf_half_z), (hx, hy, shelf_half_z), TABLE_LEG_LOOK)
    depth, width, height = BIN_SIZE_M
    count = int((y1 - y0 - 2 * TABLE_LEG_INSET_M) // (width + BIN_GAP_M))
    for i in range(count):
        y = cy + (i - (count - 1) / 2) * (width + BIN_GAP_M)
        drawn_box(f"bin{i}", (BIN_FRONT_X + depth / 2, y, BIN_SHELF_Z + height / 2), (depth / 2, width / 2, height / 2),
                  BIN_LOOKS[i % len(BIN_LOOKS)])


def add_lights(spec: mujoco.MjSpec, *, shadows: bool) -> None:
    """The dome (headlight ambient plus a weak fill from the camera) and the distant key light, the one light that
    casts shadows (when `shadows`)."""
    spec.visual.headlight.ambient = (DOME_AMBIENT,) * 3
    spec.visual.headlight.diffuse = (0.15, 0.15, 0.15)
    spec.visual.headlight.specular = (0.0, 0.0, 0.0)
    spec.visual.quality.shadowsize = SHADOW_MAP_PX
    key = spec.worldbody.add_light(name=KEY_LIGHT, type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL)
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
    key.pos = key_light_pos(key.dir)
    gain = intensity / KEY_LIGHT_INTENSITY
    key.diffuse = (KEY_DIFFUSE_AT_REFERENCE * gain,) * 3
    key.specular = (KEY_SPECULAR_AT_REFERENCE * gain,) * 3


def key_light_pos(direction) -> np.ndarray:
    """Where a directional key light travelling along `direction` (world, unit) sits: KEY_LIGHT_DISTANCE_M back from
    SHADOW_CENTRE. A directional light's position only places its shadow map, which MuJoCo centres on this line."""
    return np.asarray(SHADOW_CENTRE) - KEY_LIGHT_DISTANCE_M * np.asarray(direction, dtype=float)


def fit_shadow_map(model: mujoco.MjModel) -> None:
    """Spend the shadow map on SHADOW_HALF_WIDTH_M around SHADOW_CENTRE (MuJoCo stores the half-width relative to
    the compiled model's extent, so this runs after compiling)."""
    model.vis.map.shadowclip = SHADOW_HALF_WIDTH_M / model.stat.extent


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


def add_arena(spec: mujoco.MjSpec, *, table: bool = True, shadows: bool = True) -> None:
    """The arena on an empty `spec`; with `shadows`, the key light casts them. The arena's own geoms cast none:
    their shadows would fall on the floor under the table, and the table's area would fill the shadow map."""
    add_sky(spec)
    add_floor(spec)
    if table:
        add_table(spec)
    for geom in spec.geoms:
        geom.castshadow = False
    add_lights(spec, shadows=shadows)
    add_fixed_camera(spec)
    add_overview_camera(spec)
