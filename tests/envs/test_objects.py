"""Props: the YCB objects are drawn as scanned meshes fitted onto their collision primitives; physics is unchanged."""

import mujoco
import numpy as np
import pytest

from lerobot_tavis.envs import physics, placement
from lerobot_tavis.envs.objects import PROPS, RED_CUBE, YCB_OBJECTS, add_prop
from lerobot_tavis.envs.robots import make_robot
from lerobot_tavis.envs.tasks.catalog import make_task
from lerobot_tavis.envs.world import build_world

FIT_TOLERANCE_M = 0.002


@pytest.fixture(scope="module")
def task_model():
    """clutter_pick_cube holds all five YCB objects and the red cube."""
    return build_world(make_robot("gr1t2"), make_task("clutter_pick_cube"), image_size=(16, 16)).model


def _props_model(dressed: bool) -> mujoco.MjModel:
    spec = mujoco.MjSpec()
    physics.configure_compiler(spec)
    for prop in PROPS.values():
        add_prop(spec, prop, dressed=dressed)
    return spec.compile()


def _drawn(model, geom_id) -> bool:
    return model.geom_group[geom_id] < physics.GROUP_HIDDEN and model.geom_rgba[geom_id][3] > 0


def _world_vertices(model, data, geom_id) -> np.ndarray:
    mesh = model.geom_dataid[geom_id]
    start, count = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
    return model.mesh_vert[start:start + count] @ data.geom_xmat[geom_id].reshape(3, 3).T + data.geom_xpos[geom_id]


def _collision_half_extents(model, data, geom_id) -> np.ndarray:
    """World-frame half extents of an upright box or cylinder geom's bounding box."""
    size = model.geom_size[geom_id]
    if model.geom_type[geom_id] == mujoco.mjtGeom.mjGEOM_CYLINDER:
        return np.array([size[0], size[0], size[1]])
    return np.abs(data.geom_xmat[geom_id].reshape(3, 3)) @ size


@pytest.mark.parametrize("name", YCB_OBJECTS)
def test_ycb_prop_is_a_visible_textured_mesh_that_fits_its_collision_shape(task_model, name):
    model, data = task_model, mujoco.MjData(task_model)
    mesh = model.geom(f"{name}/mesh")
    assert mesh.type[0] == mujoco.mjtGeom.mjGEOM_MESH and _drawn(model, mesh.id)
    assert mesh.contype[0] == 0 and mesh.conaffinity[0] == 0
    assert model.mesh_texcoordnum[mesh.dataid[0]] > 0
    texture = model.mat_texid[mesh.matid[0], mujoco.mjtTextureRole.mjTEXROLE_RGB]
    assert texture >= 0 and max(model.tex_width[texture], model.tex_height[texture]) <= 1024
    assert model.mesh_facenum[mesh.dataid[0]] <= 2000
    collision = model.geom(name).id
    for yaw in np.random.default_rng(7).uniform(-np.pi, np.pi, size=4):
        placement.place_on_table(model, data, name, 0.4, 0.1, yaw)
        mujoco.mj_forward(model, data)
        vertices = _world_vertices(model, data, mesh.id)
        half = _collision_half_extents(model, data, collision)
        centre = data.geom_xpos[collision]
        np.testing.assert_allclose(vertices.min(axis=0), centre - half, atol=FIT_TOLERANCE_M)
        np.testing.assert_allclose(vertices.max(axis=0), centre + half, atol=FIT_TOLERANCE_M)


@pytest.mark.parametrize("name", YCB_OBJECTS)
def test_dressed_collision_primitive_is_hidden_and_unchanged(task_model, name):
    model, prop = task_model, YCB_OBJECTS[name]
    collision = model.geom(name)
    assert collision.group[0] == physics.GROUP_HIDDEN and not _drawn(model, collision.id)
    assert (collision.contype[0], collision.conaffinity[0]) == (physics.PROP["contype"], physics.PROP["conaffinity"])
    if prop.shape == "cylinder":
        expected = (prop.size_m[0] / 2, prop.height_m / 2, 0.0)
    else:
        expected = (prop.size_m[0] / 2, prop.size_m[1] / 2, prop.height_m / 2)
    np.testing.assert_allclose(collision.size, expected)
    np.testing.assert_array_equal(model.body(name).ipos, 0.0)


def test_dressing_leaves_masses_inertias_and_collision_geoms_bit_identical():
    dressed, plain = _props_model(True), _props_model(False)
    for name in PROPS:
        a, b = dressed.body(name), plain.body(name)
        for field in ("mass", "inertia", "ipos", "iquat"):
            np.testing.assert_array_equal(getattr(a, field), getattr(b, field), err_msg=f"{name}.{field}")
        ga, gb = dressed.geom(name), plain.geom(name)
        for field in ("type", "size", "pos", "quat", "friction", "contype", "conaffinity", "solref", "solimp"):
            np.testing.assert_array_equal(getattr(ga, field), getattr(gb, field), err_msg=f"{name} geom {field}")


def test_undressed_props_draw_their_primitive_in_their_colour():
    model = _props_model(False)
    assert model.nmesh == 0
    for name, prop in PROPS.items():
        assert model.body(name).geomnum[0] == 1
        assert _drawn(model, model.geom(name).id)
        np.testing.assert_allclose(model.geom(name).rgba, prop.rgba, rtol=1e-6)


def test_red_cube_has_no_mesh(task_model):
    body = task_model.body(RED_CUBE.name)
    assert body.geomnum[0] == 1
    cube = task_model.geom(RED_CUBE.name)
    assert cube.type[0] == mujoco.mjtGeom.mjGEOM_BOX and _drawn(task_model, cube.id)
