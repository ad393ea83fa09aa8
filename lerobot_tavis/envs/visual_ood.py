"""The `ood_visual` split: the `id` episode of the same seed (layout, prompt, physics) with only the look changed.

Five factors, each drawn per episode from its own generator (seeded from the episode's, never drawing from the
task's, so the layout is the `id` one), within these ranges:

- `table`: the top's texture (brushed metal as in `id`, wood, or none), its tint (hue 0-1, saturation 0-0.5,
  value 0.35-0.95) and specular 0.05-0.6.
- `floor`: the tiles' tint (hue 0-1, saturation 0-0.6, value 0.3-1.0).
- `backdrop`: four walls 3 m around the robot (none in `id`), one colour (hue 0-1, saturation 0-0.4, value
  0.4-1.0).
- `lighting`: the key light turned by -60..60 deg of azimuth around the vertical, elevation 25-75 deg, intensity
  0.5-1.5 x the task's, colour temperature 3000-8000 K; the dome (headlight ambient) 0.3-0.7.
- `distractors`: 2-4 shapes (box, cylinder, sphere, capsule) of 2-5 cm, in random colours, on the table behind
  and beside the objects' workspace (on the floor beside the robot for tasks without a table), at least
  MIN_CLEARANCE_M from every task geom. They touch nothing (contype 0), so they never block a grasp, and stand
  behind or beside the task's objects as the cameras see them.

`ood_visual` applies all five; `ood_visual:<factor>` one alone, for ablations (e.g. `ood_visual:lighting`). The
extra materials, walls and shapes exist only in an `ood_visual` model, so the `id` model, its pixels and every
existing dataset stay exactly as they were.
"""

from __future__ import annotations

import colorsys
from dataclasses import dataclass

import mujoco
import numpy as np

from lerobot_tavis.envs import physics, scene
from lerobot_tavis.envs.assets import add_material, add_texture
from lerobot_tavis.envs.tasks.catalog import VISUAL_SPLIT

TABLE_TEXTURES = ("brushed_metal.png", "wood.png", None)
TABLE_SATURATION, TABLE_VALUE, TABLE_SPECULAR = (0.0, 0.5), (0.35, 0.95), (0.05, 0.6)
FLOOR_SATURATION, FLOOR_VALUE = (0.0, 0.6), (0.3, 1.0)
BACKDROP_SATURATION, BACKDROP_VALUE = (0.0, 0.4), (0.4, 1.0)
BACKDROP_DISTANCE_M, BACKDROP_HEIGHT_M = 3.0, 3.0
LIGHT_AZIMUTH_DEG, LIGHT_ELEVATION_DEG = (-60.0, 60.0), (25.0, 75.0)
LIGHT_INTENSITY_SCALE, LIGHT_KELVIN, DOME_AMBIENT = (0.5, 1.5), (3000.0, 8000.0), (0.3, 0.7)
DISTRACTOR_COUNT, DISTRACTOR_SIZE_M = (2, 4), (0.02, 0.05)
DISTRACTOR_SHAPES = ("box", "cylinder", "sphere", "capsule")
MIN_CLEARANCE_M = 0.05
TABLE_BANDS = (((0.74, 0.82), (-0.50, 0.50)),  # behind the workspace: (x range, y range), world frame
               ((0.35, 0.80), (0.45, 0.51)), ((0.35, 0.80), (-0.51, -0.45)))  # beside it
FLOOR_BANDS = (((0.3, 1.0), (0.7, 1.0)), ((0.3, 1.0), (-1.0, -0.7)))
MAX_PLACEMENT_TRIES = 50
PREFIX = f"{VISUAL_SPLIT}/"
TABLE_MATERIAL, FLOOR_MATERIAL, BACKDROP_MATERIAL = (f"{PREFIX}table_top", f"{PREFIX}floor", f"{PREFIX}backdrop")


def add_variation_pieces(spec: mujoco.MjSpec, *, has_table: bool) -> None:
    """The materials, walls and shapes an `ood_visual` episode varies; drawn as in `id` until `apply` runs."""
    for texture in TABLE_TEXTURES:
        if texture is not None and spec.texture(f"look/{texture}") is None:
            add_texture(spec, f"look/{texture}", f"scene/{texture}")
    for material, look in ((TABLE_MATERIAL, scene.TABLE_TOP_LOOK), (FLOOR_MATERIAL, scene.FLOOR_LOOK)):
        repeat = 2.0 / look.period_m  # as scene.use_look draws it
        add_material(spec, material, rgba=look.rgba, texture=f"look/{look.texture}", specular=look.specular,
                     shininess=look.shininess, texrepeat=(repeat, repeat), texuniform=True)
    add_material(spec, BACKDROP_MATERIAL, specular=0.0, shininess=0.0)
    if has_table:
        for name in scene.TABLE_TOP_GEOMS:
            spec.geom(name).material = TABLE_MATERIAL
    spec.geom("floor/tiles").material = FLOOR_MATERIAL
    d, thin = BACKDROP_DISTANCE_M, 0.01
    for index, (x, y, half_x, half_y) in enumerate(((d, 0, thin, d), (-d, 0, thin, d), (0, d, d, thin),
                                                    (0, -d, d, thin))):
        wall = spec.worldbody.add_geom(name=f"{PREFIX}wall{index}", type=mujoco.mjtGeom.mjGEOM_BOX,
                                       pos=(x, y, BACKDROP_HEIGHT_M / 2), size=(half_x, half_y, BACKDROP_HEIGHT_M / 2))
        physics.style_geom(wall, physics.VISUAL, group=physics.GROUP_PARKED)
        wall.castshadow = False
        wall.material = BACKDROP_MATERIAL
    for index in range(DISTRACTOR_COUNT[1]):
        shape = DISTRACTOR_SHAPES[index % len(DISTRACTOR_SHAPES)]
        geom = spec.worldbody.add_geom(name=f"{PREFIX}distractor{index}", type=_geom_type(shape),
                                       pos=(0.0, 0.0, -1.0), size=(0.03, 0.03, 0.03))
        physics.style_geom(geom, physics.VISUAL, rgba=(0.5, 0.5, 0.5, 1.0), group=physics.GROUP_PARKED)


@dataclass(frozen=True)
class VisualDraw:
    """One episode's drawn look (only the applied factors' fields are set), for logs and range checks."""

    table_texture: str | None = None
    table_rgb: tuple[float, float, float] | None = None
    table_specular: float | None = None
    floor_rgb: tuple[float, float, float] | None = None
    backdrop_rgb: tuple[float, float, float] | None = None
    light_azimuth_deg: float | None = None
    light_elevation_deg: float | None = None
    light_intensity_scale: float | None = None
    light_kelvin: float | None = None
    dome_ambient: float | None = None
    distractors: tuple[tuple[str, tuple[float, float, float], float], ...] = ()  # (shape, world position, size)


@dataclass(frozen=True)
class IdLook:
    """What `apply` changes, as the model was compiled (the `id` look, the task's own key light included)."""

    key_light_dir: np.ndarray
    key_light_diffuse: np.ndarray

    @classmethod
    def of(cls, model: mujoco.MjModel) -> IdLook:
        key = model.light(scene.KEY_LIGHT).id
        return cls(model.light_dir[key].copy(), model.light_diffuse[key].copy())


def apply(model: mujoco.MjModel, data: mujoco.MjData, factors: tuple[str, ...], rng: np.random.Generator,
          id_look: IdLook, *, has_table: bool, robot_prefix: str) -> VisualDraw:
    """Draw this episode's look for `factors` and set it on `model` (call after the task has placed its objects,
    before the first render); the rest of the look is `id_look`, whatever the previous episode drew."""
    _restore_id_look(model, id_look)
    draw: dict = {}
    if "table" in factors and has_table:
        texture = TABLE_TEXTURES[rng.integers(len(TABLE_TEXTURES))]
        material = model.material(TABLE_MATERIAL).id
        model.mat_texid[material, mujoco.mjtTextureRole.mjTEXROLE_RGB] = (
            -1 if texture is None else model.texture(f"look/{texture}").id)
        rgb = _hsv(rng, TABLE_SATURATION, TABLE_VALUE)
        model.mat_rgba[material, :3] = rgb
        model.mat_specular[material] = rng.uniform(*TABLE_SPECULAR)
        draw |= {"table_texture": texture or "none", "table_rgb": rgb,
                 "table_specular": float(model.mat_specular[material])}
    if "floor" in factors:
        rgb = _hsv(rng, FLOOR_SATURATION, FLOOR_VALUE)
        model.mat_rgba[model.material(FLOOR_MATERIAL).id, :3] = rgb
        draw["floor_rgb"] = rgb
    if "backdrop" in factors:
        rgb = _hsv(rng, BACKDROP_SATURATION, BACKDROP_VALUE)
        model.mat_rgba[model.material(BACKDROP_MATERIAL).id, :3] = rgb
        for index in range(4):
            model.geom_group[model.geom(f"{PREFIX}wall{index}").id] = physics.GROUP_VISIBLE
        draw["backdrop_rgb"] = rgb
    if "lighting" in factors:
        draw |= _light(model, rng, id_look)
    if "distractors" in factors:
        draw["distractors"] = _place_distractors(model, data, rng, has_table, robot_prefix)
    mujoco.mj_camlight(model, data)  # the renderer reads the key light's world direction from `data`, not `model`
    return VisualDraw(**draw)


def task_geoms(model: mujoco.MjModel, robot_prefix: str) -> list[int]:
    """Geoms a distractor must keep clear of: all but the robot's, the arena's and this split's own."""
    arena = ("floor", "table/", PREFIX)
    return [g for g in range(model.ngeom)
            if not (model.geom(g).name.startswith(arena)
                    or model.body(model.geom_bodyid[g]).name.startswith((robot_prefix, "table")))]


def clearance_m(model: mujoco.MjModel, data: mujoco.MjData, geom: int, others: list[int]) -> float:
    """The smallest distance (m) between `geom` and any of `others`, capped at 1 m."""
    fromto = np.zeros(6)
    return min((mujoco.mj_geomDistance(model, data, geom, other, 1.0, fromto) for other in others), default=1.0)


def _restore_id_look(model: mujoco.MjModel, id_look: IdLook) -> None:
    """Undo the previous episode's draw: the `id` look on every piece this split varies."""
    table, floor = model.material(TABLE_MATERIAL).id, model.material(FLOOR_MATERIAL).id
    model.mat_texid[table, mujoco.mjtTextureRole.mjTEXROLE_RGB] = model.texture(
        f"look/{scene.TABLE_TOP_LOOK.texture}").id
    model.mat_rgba[table] = scene.TABLE_TOP_LOOK.rgba
    model.mat_specular[table] = scene.TABLE_TOP_LOOK.specular
    model.mat_rgba[floor] = scene.FLOOR_LOOK.rgba
    for index in range(4):
        model.geom_group[model.geom(f"{PREFIX}wall{index}").id] = physics.GROUP_PARKED
    for index in range(DISTRACTOR_COUNT[1]):
        model.geom_group[model.geom(f"{PREFIX}distractor{index}").id] = physics.GROUP_PARKED
    key = model.light(scene.KEY_LIGHT).id
    model.light_dir[key] = id_look.key_light_dir
    model.light_pos[key] = scene.key_light_pos(id_look.key_light_dir)
    model.light_diffuse[key] = id_look.key_light_diffuse
    model.vis.headlight.ambient[:] = scene.DOME_AMBIENT


def _light(model: mujoco.MjModel, rng: np.random.Generator, id_look: IdLook) -> dict:
    azimuth = rng.uniform(*LIGHT_AZIMUTH_DEG)
    elevation = rng.uniform(*LIGHT_ELEVATION_DEG)
    scale = rng.uniform(*LIGHT_INTENSITY_SCALE)
    kelvin = rng.uniform(*LIGHT_KELVIN)
    ambient = rng.uniform(*DOME_AMBIENT)
    base = id_look.key_light_dir
    heading = np.arctan2(base[1], base[0]) + np.radians(azimuth)
    down = np.radians(elevation)  # the light travels downward at this angle below the horizon
    direction = np.array([np.cos(down) * np.cos(heading), np.cos(down) * np.sin(heading), -np.sin(down)])
    key = model.light(scene.KEY_LIGHT).id
    model.light_dir[key] = direction
    model.light_pos[key] = scene.key_light_pos(direction)  # keeps the shadow map on the workspace
    model.light_diffuse[key] = np.clip(id_look.key_light_diffuse * scale * kelvin_rgb(kelvin), 0.0, 1.0)
    model.vis.headlight.ambient[:] = ambient
    return {"light_azimuth_deg": float(azimuth), "light_elevation_deg": float(elevation),
            "light_intensity_scale": float(scale), "light_kelvin": float(kelvin), "dome_ambient": float(ambient)}


def kelvin_rgb(kelvin: float) -> np.ndarray:
    """The colour of a black body at `kelvin` (1000-40000 K), scaled to a maximum of 1 (Tanner Helland's fit)."""
    t = kelvin / 100.0
    red = 255.0 if t <= 66 else 329.698727446 * (t - 60) ** -0.1332047592
    green = 99.4708025861 * np.log(t) - 161.1195681661 if t <= 66 else 288.1221695283 * (t - 60) ** -0.0755148492
    blue = 255.0 if t >= 66 else (0.0 if t <= 19 else 138.5177312231 * np.log(t - 10) - 305.0447927307)
    rgb = np.clip([red, green, blue], 0.0, 255.0)
    return rgb / rgb.max()


def _place_distractors(model, data, rng, has_table: bool, robot_prefix: str) -> tuple:
    others = task_geoms(model, robot_prefix)
    count = int(rng.integers(DISTRACTOR_COUNT[0], DISTRACTOR_COUNT[1] + 1))
    bands = TABLE_BANDS if has_table else FLOOR_BANDS
    base_z = scene.TABLE_TOP_Z if has_table else 0.0
    placed = []
    for index in range(count):
        geom = model.geom(f"{PREFIX}distractor{index}").id
        size = float(rng.uniform(*DISTRACTOR_SIZE_M))
        model.geom_size[geom] = (size, size, size)
        model.geom_rgba[geom, :3] = _hsv(rng, (0.4, 1.0), (0.3, 1.0))
        half_height = size * (2.0 if model.geom_type[geom] == mujoco.mjtGeom.mjGEOM_CAPSULE else 1.0)
        for _ in range(MAX_PLACEMENT_TRIES):
            (x_range, y_range) = bands[rng.integers(len(bands))]
            model.geom_pos[geom] = (rng.uniform(*x_range), rng.uniform(*y_range), base_z + half_height)
            mujoco.mj_kinematics(model, data)
            if clearance_m(model, data, geom, others + [d for d, *_ in placed]) >= MIN_CLEARANCE_M:
                model.geom_group[geom] = physics.GROUP_VISIBLE
                placed.append((geom, DISTRACTOR_SHAPES[index % len(DISTRACTOR_SHAPES)], size))
                break
        else:  # no free spot in this episode's bands: leave it out
            model.geom_pos[geom] = (0.0, 0.0, -1.0)
    mujoco.mj_kinematics(model, data)
    return tuple((shape, tuple(float(v) for v in data.geom_xpos[geom]), size) for geom, shape, size in placed)


def _hsv(rng: np.random.Generator, saturation: tuple[float, float], value: tuple[float, float]):
    rgb = colorsys.hsv_to_rgb(rng.uniform(0.0, 1.0), rng.uniform(*saturation), rng.uniform(*value))
    return tuple(float(c) for c in rgb)


def _geom_type(shape: str) -> mujoco.mjtGeom:
    return {"box": mujoco.mjtGeom.mjGEOM_BOX, "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
            "sphere": mujoco.mjtGeom.mjGEOM_SPHERE, "capsule": mujoco.mjtGeom.mjGEOM_CAPSULE}[shape]
