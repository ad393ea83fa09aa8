"""Both robots' vendored visual meshes (assets/<robot>, made by tools/assets/) change what is drawn only."""

import json

import mujoco
import numpy as np
import pytest

from lerobot_tavis.envs import physics
from lerobot_tavis.envs.assets import ASSET_DIR
from lerobot_tavis.envs.robots import BUILTIN_ROBOTS, make_robot

ROBOTS = BUILTIN_ROBOTS
MESH = mujoco.mjtGeom.mjGEOM_MESH
PHYSICS_FIELDS = ("body_mass", "body_inertia", "body_pos", "body_quat", "body_ipos", "body_iquat", "jnt_range",
                  "jnt_axis", "dof_armature", "dof_damping", "actuator_gainprm", "actuator_biasprm",
                  "actuator_ctrlrange", "actuator_forcerange", "site_pos", "site_quat", "cam_pos", "cam_quat")
COLLISION_FIELDS = ("geom_type", "geom_size", "geom_pos", "geom_quat", "geom_contype", "geom_conaffinity",
                    "geom_condim", "geom_priority", "geom_friction", "geom_solref", "geom_solimp", "geom_bodyid")


@pytest.fixture(scope="module", params=ROBOTS)
def robot(request):
    """(name, plain model, dressed model, manifest)."""
    spec = make_robot(request.param)
    manifest = json.loads((ASSET_DIR / request.param / "visuals.json").read_text())
    return request.param, spec.build_spec().compile(), spec.build_spec(dressed=True).compile(), manifest


def _collision_geoms(model):
    return {model.geom(g).name: g for g in range(model.ngeom) if model.geom_contype[g] or model.geom_conaffinity[g]}


def _mesh_geoms(model):
    return [g for g in range(model.ngeom) if model.geom_type[g] == MESH]


def test_dressing_keeps_the_physics_bit_identical(robot):
    _, plain, dressed, _ = robot
    for count in ("nbody", "njnt", "nq", "nv", "nu", "neq", "ntendon", "nsite", "ncam"):
        assert getattr(dressed, count) == getattr(plain, count), count
    for field in PHYSICS_FIELDS:
        np.testing.assert_array_equal(getattr(dressed, field), getattr(plain, field), err_msg=field)
    plain_geoms, dressed_geoms = _collision_geoms(plain), _collision_geoms(dressed)
    assert plain_geoms.keys() == dressed_geoms.keys()
    for name, g in plain_geoms.items():
        h = dressed_geoms[name]
        for field in COLLISION_FIELDS:
            np.testing.assert_array_equal(getattr(dressed, field)[h], getattr(plain, field)[g],
                                          err_msg=f"{name} {field}")
        assert dressed.geom_group[h] == physics.GROUP_HIDDEN, name


def test_only_the_massless_meshes_are_drawn_and_they_touch_nothing(robot):
    name, _, dressed, manifest = robot
    meshes = _mesh_geoms(dressed)
    assert len(meshes) == len(manifest["meshes"])
    assert all(dressed.geom_contype[g] == 0 and dressed.geom_conaffinity[g] == 0 for g in meshes)
    assert [g for g in range(dressed.ngeom) if dressed.geom_group[g] < physics.GROUP_HIDDEN] == meshes
    spec = make_robot(name).build_spec(dressed=True)
    assert all(geom.mass == 0 for geom in spec.geoms if geom.type == MESH)


def test_manifest_names_existing_bodies_files_materials_and_notice_rows(robot):
    name, _, _, manifest = robot
    spec = make_robot(name).build_spec()
    notice = (ASSET_DIR / name / "NOTICE.md").read_text()
    for entry in manifest["meshes"]:
        assert spec.body(entry["body"]) is not None, entry["body"]
        assert (ASSET_DIR / name / entry["file"]).is_file(), entry["file"]
        assert f"`{entry['file']}`" in notice, entry["file"]
        assert entry["material"] in manifest["materials"], entry["material"]


def test_robot_stays_within_its_triangle_and_size_budgets(robot):
    name, _, dressed, _ = robot
    assert sum(int(dressed.mesh_facenum[dressed.geom_dataid[g]]) for g in _mesh_geoms(dressed)) <= 25_000
    assert sum(p.stat().st_size for p in (ASSET_DIR / name).iterdir()) <= 3_000_000
