"""Physics and rendering defaults shared by every model piece: one place for timing, contacts and colours.

Grasp-stable settings follow docs/reference.md §14: implicitfast integrator, elliptic friction
cones with impratio 10, solref 0.01 (>= 2 timesteps), condim 4 on gripper pads.
"""

from __future__ import annotations

import mujoco

TIMESTEP_S = 1.0 / 480.0
CONTROL_HZ = 60  # IK and actuator targets are refreshed at this rate
POLICY_HZ = 20  # one env step
SUBSTEPS_PER_TICK = round(1.0 / (CONTROL_HZ * TIMESTEP_S))  # 8 physics steps per 60 Hz tick
TICKS_PER_STEP = CONTROL_HZ // POLICY_HZ  # 3 ticks per 20 Hz policy step

# Clip planes of every camera (m). The reference clips its fixed and wrist cameras at 0.1 m (its head camera at
# 0.15 m), so a head pitched down in front of the fixed camera is cut away instead of filling its view.
NEAR_CLIP_M, FAR_CLIP_M = 0.10, 20.0
# The reference's wrist cameras see nothing beyond 1 m. MuJoCo's clip planes are global, and a wrist camera's own far
# plane would also cut its shadow map (drawn between the same planes), so the wrist cameras draw what lies beyond
# in the backdrop's colour instead: a fog that starts and ends there (`rendering.CameraRig`).
WRIST_FAR_CLIP_M = 1.0

CONTACT_SOLREF = (0.01, 1.0)
CONTACT_SOLIMP = (0.95, 0.99, 0.001, 0.5, 2.0)
OBJECT_FRICTION = (1.0, 0.005, 0.0001)
PAD_FRICTION = (1.2, 0.02, 0.0001)

# Collision filtering (MuJoCo collides a pair when contype of one & conaffinity of the other is non-zero):
# robots touch props and static scenery but never themselves; visual-only geoms touch nothing.
STATIC = {"contype": 1, "conaffinity": 3}
PROP = {"contype": 1, "conaffinity": 3}
ROBOT = {"contype": 2, "conaffinity": 0}
VISUAL = {"contype": 0, "conaffinity": 0}

# Geom groups: 0-2 are drawn by the renderer, 3 is hidden (collision-only shapes), 4 is hidden too (the drawn geoms
# of props parked out of the episode; placement.py moves them between 0 and 4).
GROUP_VISIBLE, GROUP_HIDDEN, GROUP_PARKED = 0, 3, 4


def configure_compiler(spec: mujoco.MjSpec) -> None:
    """Angles in radians; massless links (joint frames with only visual geoms) get a small mass and inertia."""
    spec.compiler.degree = False
    spec.compiler.boundmass = 0.05
    spec.compiler.boundinertia = 1e-4


def configure(spec: mujoco.MjSpec, *, image_size: tuple[int, int]) -> None:
    """Set solver options and the offscreen buffer (at least `image_size` = (height, width) pixels)."""
    configure_compiler(spec)
    spec.option.timestep = TIMESTEP_S
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.impratio = 10.0
    spec.option.solver = mujoco.mjtSolver.mjSOL_NEWTON
    spec.option.gravity = (0.0, 0.0, -9.81)
    height, width = image_size
    spec.visual.global_.offwidth = max(640, width)
    spec.visual.global_.offheight = max(480, height)
    spec.visual.quality.offsamples = 0  # MSAA costs ~2.5x per frame on a CPU


def set_clip_planes(model: mujoco.MjModel) -> None:
    """Clip every camera's view to NEAR_CLIP_M..FAR_CLIP_M metres, and set the fog that ends the wrist cameras' view
    at WRIST_FAR_CLIP_M (MuJoCo stores both relative to the compiled model's extent, so this runs after
    compiling). The fog's colour is the model's `visual.rgba.fog`."""
    model.vis.map.znear = NEAR_CLIP_M / model.stat.extent
    model.vis.map.zfar = FAR_CLIP_M / model.stat.extent
    model.vis.map.fogstart = WRIST_FAR_CLIP_M / model.stat.extent
    model.vis.map.fogend = (WRIST_FAR_CLIP_M + 0.001) / model.stat.extent  # a 1 mm step: all or nothing


def style_geom(geom: mujoco.MjsGeom, role: dict[str, int], rgba=None, *, group: int = GROUP_VISIBLE) -> None:
    """Apply a collision role (STATIC, PROP, ROBOT or VISUAL), the shared contact parameters and a colour."""
    geom.contype = role["contype"]
    geom.conaffinity = role["conaffinity"]
    geom.group = group
    geom.solref = CONTACT_SOLREF
    geom.solimp = CONTACT_SOLIMP
    if role is VISUAL:
        geom.mass = 0.0
    if rgba is not None:
        geom.rgba = rgba
