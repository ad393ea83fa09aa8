"""The arena shared by every task: floor, table, lights and the scene-fixed workspace camera.

World frame: x forward from the robot, y to its left, z up, floor at z = 0, table top at z = 1.0.
"""

from __future__ import annotations

import mujoco
import numpy as np

from lerobot_tavis.envs import physics
from lerobot_tavis.envs.transforms import camera_quat, vfov_deg

TABLE_TOP_Z = 1.0
TABLE_X = (0.25, 0.85)
TABLE_Y = (-0.55, 0.55)
TABLE_THICKNESS = 0.04
TABLE_RGBA = (0.56, 0.58, 0.61, 1.0)  # neutral brushed-metal grey
FLOOR_RGBA = (0.30, 0.31, 0.33, 1.0)

# Workspace camera (reference §1.5): above and in front of the robot, optical axis forward and 45° down.
FIXED_CAMERA = "fixed"
FIXED_CAMERA_POS = (0.2, 0.0, 1.43)
FIXED_CAMERA_HFOV_DEG = 120.0

# Key light from the front-left, above, travelling toward the robot and down (reference §1.4).
KEY_LIGHT_DIR = (-0.342, -0.321, -0.883)


def add_sky(spec: mujoco.MjSpec) -> None:
    """A plain light-grey backdrop, so cameras looking above the table do not see black."""
    spec.add_texture(name="sky", type=mujoco.mjtTexture.mjTEXTURE_SKYBOX, builtin=mujoco.mjtBuiltin.mjBUILTIN_GRADIENT,
                     rgb1=(0.80, 0.82, 0.85), rgb2=(0.55, 0.57, 0.60), width=64, height=64)


def add_floor(spec: mujoco.MjSpec) -> None:
    floor = spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=(4.0, 4.0, 0.05))
    physics.style_geom(floor, physics.STATIC, FLOOR_RGBA)


def add_table(spec: mujoco.MjSpec) -> None:
    """A static table whose top surface is at TABLE_TOP_Z, on four legs."""
    table = spec.worldbody.add_body(name="table")
    cx, cy = np.mean(TABLE_X), np.mean(TABLE_Y)
    hx, hy = (TABLE_X[1] - TABLE_X[0]) / 2, (TABLE_Y[1] - TABLE_Y[0]) / 2
    top = table.add_geom(name="table/top", type=mujoco.mjtGeom.mjGEOM_BOX)
    top.size = (hx, hy, TABLE_THICKNESS / 2)
    top.pos = (cx, cy, TABLE_TOP_Z - TABLE_THICKNESS / 2)
    physics.style_geom(top, physics.STATIC, TABLE_RGBA)
    leg_half_h = (TABLE_TOP_Z - TABLE_THICKNESS) / 2
    for i, (sx, sy) in enumerate(((1, 1), (1, -1), (-1, 1), (-1, -1))):
        leg = table.add_geom(name=f"table/leg{i}", type=mujoco.mjtGeom.mjGEOM_BOX)
        leg.size = (0.025, 0.025, leg_half_h)
        leg.pos = (cx + sx * (hx - 0.05), cy + sy * (hy - 0.05), leg_half_h)
        physics.style_geom(leg, physics.VISUAL, (0.25, 0.25, 0.27, 1.0))


def add_lights(spec: mujoco.MjSpec, *, shadows: bool) -> None:
    """A directional key light plus a soft fill. Shadows cost 5-10x per frame on a CPU, so they are opt-in."""
    spec.visual.headlight.ambient = (0.25, 0.25, 0.25)
    spec.visual.headlight.diffuse = (0.35, 0.35, 0.35)
    spec.visual.headlight.specular = (0.05, 0.05, 0.05)
    spec.visual.quality.shadowsize = 2048
    key = spec.worldbody.add_light(name="key_light", type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL)
    key.pos = (1.0, 1.0, 3.0)
    key.dir = KEY_LIGHT_DIR
    key.diffuse = (0.6, 0.6, 0.6)
    key.specular = (0.2, 0.2, 0.2)
    key.castshadow = shadows


def add_fixed_camera(spec: mujoco.MjSpec) -> None:
    forward = (np.cos(np.pi / 4), 0.0, -np.sin(np.pi / 4))
    spec.worldbody.add_camera(
        name=FIXED_CAMERA,
        pos=FIXED_CAMERA_POS,
        quat=camera_quat(forward, up=(0.0, 0.0, 1.0)),
        fovy=vfov_deg(FIXED_CAMERA_HFOV_DEG),
    )


# Third-person view for people (gallery, videos), never observed by a policy: front-right, above the table edge.
OVERVIEW_CAMERA = "overview"
OVERVIEW_CAMERA_POS = (1.15, -0.80, 1.70)
OVERVIEW_LOOK_AT = (0.25, 0.0, 1.02)


def add_overview_camera(spec: mujoco.MjSpec) -> None:
    forward = np.subtract(OVERVIEW_LOOK_AT, OVERVIEW_CAMERA_POS)
    spec.worldbody.add_camera(name=OVERVIEW_CAMERA, pos=OVERVIEW_CAMERA_POS,
                              quat=camera_quat(forward, up=(0.0, 0.0, 1.0)), fovy=50.0)


def add_arena(spec: mujoco.MjSpec, *, table: bool = True, shadows: bool = False) -> None:
    add_sky(spec)
    add_floor(spec)
    if table:
        add_table(spec)
    add_lights(spec, shadows=shadows)
    add_fixed_camera(spec)
    add_overview_camera(spec)
