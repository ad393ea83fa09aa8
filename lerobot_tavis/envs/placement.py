"""Putting free bodies where a task wants them, at rest."""

from __future__ import annotations

import mujoco
import numpy as np

from lerobot_tavis.envs import physics
from lerobot_tavis.envs.objects import PROPS
from lerobot_tavis.envs.scene import TABLE_TOP_Z
from lerobot_tavis.envs.transforms import axis_angle_quat

HIDDEN_XY = (-2.0, -0.6)  # unused props wait on the floor behind the robot, out of every camera's view


def set_free_pose(model: mujoco.MjModel, data: mujoco.MjData, body: str, pos, yaw_rad: float = 0.0) -> None:
    """Place free body `body` at world position `pos` (its origin), upright, rotated `yaw_rad` about z, at rest."""
    joint = model.body(body).jntadr[0]
    qpos, qvel = model.jnt_qposadr[joint], model.jnt_dofadr[joint]
    data.qpos[qpos:qpos + 3] = pos
    data.qpos[qpos + 3:qpos + 7] = axis_angle_quat((0.0, 0.0, 1.0), yaw_rad)
    data.qvel[qvel:qvel + 6] = 0.0
    _set_drawn(model, body, True)


def standing_z(prop: str, surface_z: float = TABLE_TOP_Z) -> float:
    """Height of an upright prop's origin when it stands on a surface at `surface_z`."""
    return surface_z + PROPS[prop].height_m / 2


def place_on_table(model, data, prop: str, x: float, y: float, yaw_rad: float) -> None:
    set_free_pose(model, data, prop, (x, y, standing_z(prop)), yaw_rad)


def hide(model, data, props: list[str] | tuple[str, ...]) -> None:
    """Park `props` on the floor behind the robot, each on its own spot, and stop drawing them (the overview camera,
    or a head turned right round, would see them there). Placing a prop again draws it again."""
    for prop in props:
        slot = list(PROPS).index(prop)
        set_free_pose(model, data, prop, (HIDDEN_XY[0], HIDDEN_XY[1] + 0.25 * slot, standing_z(prop, 0.0)))
        _set_drawn(model, prop, False)


def _set_drawn(model: mujoco.MjModel, body: str, drawn: bool) -> None:
    """Move the drawn geoms of `body` between the visible group and the parked (undrawn) one; rendering only."""
    body_id = model.body(body).id
    start = model.body_geomadr[body_id]
    for geom in range(start, start + model.body_geomnum[body_id]):
        if drawn and model.geom_group[geom] == physics.GROUP_PARKED:
            model.geom_group[geom] = physics.GROUP_VISIBLE
        elif not drawn and model.geom_group[geom] == physics.GROUP_VISIBLE:
            model.geom_group[geom] = physics.GROUP_PARKED


def set_mocap_pose(model: mujoco.MjModel, data: mujoco.MjData, body: str, pos, yaw_rad: float = 0.0) -> None:
    """Move a kinematic (mocap) body to world position `pos`, rotated `yaw_rad` about z."""
    mocap = model.body(body).mocapid[0]
    data.mocap_pos[mocap] = pos
    data.mocap_quat[mocap] = axis_angle_quat((0.0, 0.0, 1.0), yaw_rad)


def body_speed(model: mujoco.MjModel, data: mujoco.MjData, body: str) -> float:
    """Linear speed (m/s) of a free body's origin."""
    dof = model.jnt_dofadr[model.body(body).jntadr[0]]
    return float(np.linalg.norm(data.qvel[dof:dof + 3]))
