"""The Robotiq 2F-85 gripper's visual parts, posed at any opening, from MuJoCo Menagerie's `robotiq_2f85` model.

The model is read at a pinned commit of a git clone of huggingface/lerobot, which vendors an unmodified copy of the
Menagerie model (2f85.xml and its STL meshes, BSD-2-Clause). It is compiled with MuJoCo to pose its parts; nothing
is simulated.

Frame of every returned vertex (the "gripper frame"): the model's root, i.e. the centre of the coupling plate's
mounting face, with +z the approach direction (towards the fingertips) and +y the side of the `right_*` finger;
the fingers close along y. Metres.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from common import read_git_file

REPOSITORY = "huggingface/lerobot"
COMMIT = "7d12e746c0c0f1c0fa4a3e76d56e239e2411d329"
SOURCE_DIR = "lerobot/franka_sim/franka_sim/envs/xmls/robotiq_2f85"
MESHES = ("base_mount", "base", "driver", "coupler", "spring_link", "follower", "pad", "silicone_pad")
LICENSE = "BSD-2-Clause"
# One side's chain, from the base outwards; the other side is the same parts turned 180° about z.
FINGER_PARTS = ("driver", "coupler", "spring_link", "follower", "pad", "silicone_pad")
MAX_OPENING_RAD = 0.8  # driver joint range: 0 = open, 0.8 = closed


@dataclass(frozen=True)
class Part:
    """One visual mesh of the gripper, posed: vertices (V, 3) in the gripper frame, faces (F, 3)."""

    body: str  # e.g. "base", "right_follower"
    mesh: str  # e.g. "follower"
    vertices: np.ndarray
    faces: np.ndarray


def source_path(name: str) -> str:
    """Repository path of a source file, e.g. `source_path("assets/base.stl")`."""
    return f"{SOURCE_DIR}/{name}"


def load(mirror: Path) -> mujoco.MjModel:
    """Compile the 2F-85 model from the git clone `mirror` at `COMMIT` (meshes passed in memory)."""
    xml = read_git_file(mirror, COMMIT, source_path("2f85.xml")).decode()
    assets = {f"{mesh}.stl": read_git_file(mirror, COMMIT, source_path(f"assets/{mesh}.stl")) for mesh in MESHES}
    spec = mujoco.MjSpec.from_string(xml, assets=assets)
    spec.meshdir = ""
    return spec.compile()


def linkage_qpos(model: mujoco.MjModel, closing_rad: float) -> np.ndarray:
    """Joint positions of the unloaded linkage at driver angle `closing_rad` (0 open .. 0.8 closed).

    Free of contact, the 2F-85 moves as a parallelogram: the spring link turns with the driver, the coupler stays
    straight and the follower counter-rotates so that the pads stay parallel.
    """
    if not 0.0 <= closing_rad <= MAX_OPENING_RAD:
        raise ValueError(f"closing_rad must be in [0, {MAX_OPENING_RAD}], got {closing_rad}")
    qpos = model.qpos0.copy()
    for side in ("left", "right"):
        for joint, value in (("driver", closing_rad), ("spring_link", closing_rad), ("coupler", 0.0),
                             ("follower", -closing_rad)):
            qpos[model.jnt_qposadr[model.joint(f"{side}_{joint}_joint").id]] = value
    return qpos


def posed_parts(model: mujoco.MjModel, closing_rad: float) -> list[Part]:
    """Every visual mesh of the gripper (group 2 geoms) at driver angle `closing_rad`, in the gripper frame."""
    data = mujoco.MjData(model)
    data.qpos[:] = linkage_qpos(model, closing_rad)
    mujoco.mj_kinematics(model, data)
    parts = []
    for geom in range(model.ngeom):
        if model.geom_type[geom] != mujoco.mjtGeom.mjGEOM_MESH or model.geom_group[geom] != 2:
            continue
        mesh = model.geom_dataid[geom]
        start, count = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
        local = model.mesh_vert[start:start + count].astype(float)
        vertices = local @ data.geom_xmat[geom].reshape(3, 3).T + data.geom_xpos[geom]
        face_start, face_count = model.mesh_faceadr[mesh], model.mesh_facenum[mesh]
        faces = model.mesh_face[face_start:face_start + face_count].copy()
        parts.append(Part(model.body(model.geom_bodyid[geom]).name, model.mesh(mesh).name, vertices, faces))
    return parts


def inner_pad_face_y(model: mujoco.MjModel, closing_rad: float) -> float:
    """Gripper-frame y of the right silicone pad's gripping face at driver angle `closing_rad` (m)."""
    (pad,) = [p for p in posed_parts(model, closing_rad) if p.body == "right_silicone_pad"]
    return float(pad.vertices[:, 1].min())


def closing_for_gap(model: mujoco.MjModel, half_gap_m: float) -> float:
    """Driver angle at which each pad's gripping face is `half_gap_m` from the centre line (bisection)."""
    lo, hi = 0.0, MAX_OPENING_RAD
    if not inner_pad_face_y(model, hi) <= half_gap_m <= inner_pad_face_y(model, lo):
        raise ValueError(f"half_gap_m {half_gap_m} is outside the 2F-85 stroke")
    for _ in range(40):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if inner_pad_face_y(model, mid) > half_gap_m else (lo, mid)
    return (lo + hi) / 2
