"""CameraRig: each image leaves out the geoms that can neither show in it nor shadow what does, and its pixels are
those of drawing everything; the wrist cameras see nothing beyond their far clip."""

import mujoco
import numpy as np
import pytest

from lerobot_tavis import canonical
from lerobot_tavis.envs import physics, scene
from lerobot_tavis.envs.env import TavisEnv
from lerobot_tavis.envs.rendering import CameraRig, TableCover, out_of_view
from tests.conftest import run_steps

SIZE = (48, 64)
CAMERAS = ("head", "fixed", "left_wrist", "right_wrist", "overview")


def _posed(env: TavisEnv, pitch: float, reach_m: float) -> None:
    action = canonical.rest_action()
    action[canonical.HEAD_PITCH] = pitch
    action[canonical.HEAD_YAW] = -0.5 * pitch
    action[canonical.LEFT.position] += (reach_m, -reach_m, -reach_m)
    run_steps(env, action, 4)


@pytest.mark.parametrize("task,robot,shadows", [("clutter_pick_cube", "gr1t2", True), ("peeking_box", "reachy2", True),
                                                ("multi_shelf_scan", "reachy2", True), ("tabletop", "gr1t2", False)])
def test_leaving_geoms_out_changes_no_pixel(task, robot, shadows):
    env = TavisEnv(task, robot, image_size=SIZE, shadows=shadows, cameras=())
    env.reset(seed=2)
    rig = CameraRig(env.model, {name: env.world.cameras[name] for name in CAMERAS}, SIZE)
    everything = mujoco.Renderer(env.model, *SIZE, max_geom=2 * env.model.ngeom + 100)
    rgba = env.model.geom_rgba.copy()
    left_out = 0
    for pitch, reach_m in ((0.0, 0.0), (0.7, 0.1)):
        _posed(env, pitch, reach_m)
        for name in CAMERAS:
            camera = env.world.cameras[name]
            left_out += out_of_view(env.model, env.data, camera, SIZE[1] / SIZE[0]).sum()
            everything.update_scene(env.data, camera=camera)
            everything.scene.flags[mujoco.mjtRndFlag.mjRND_FOG] = name.endswith("wrist")  # the wrists' far clip
            np.testing.assert_array_equal(rig.render_camera(env.data, camera), everything.render(), err_msg=name)
    np.testing.assert_array_equal(env.model.geom_rgba, rgba)  # the model is left as it was
    assert left_out > 0
    everything.close()
    rig.close()
    env.close()


def test_a_wrist_camera_leaves_out_most_of_the_robot_but_not_what_shadows_its_view():
    env = TavisEnv("tabletop", "gr1t2", image_size=SIZE, cameras=())
    env.reset(seed=0)
    model, data = env.model, env.data
    wrist = out_of_view(model, data, env.world.cameras["left_wrist"], SIZE[1] / SIZE[0])
    robot = np.array([model.geom(g).name.startswith("gr1t2/") and model.geom_group[g] < 3 for g in range(model.ngeom)])
    assert wrist[robot].mean() > 0.5
    assert not wrist[model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE].any()  # unbounded: always drawn
    # a caster far outside the view whose shadow falls into it: a prop in view, lifted 3 m toward the light
    _posed(env, 0.6, 0.0)
    key = model.light("key_light").id
    head_view = env.world.cameras["head"]
    seen = ~out_of_view(model, data, head_view, SIZE[1] / SIZE[0])
    can = model.geom("soup_can/mesh").id
    assert seen[can]
    data.geom_xpos[can] -= 3.0 * data.light_xdir[key]
    assert out_of_view(model, data, head_view, SIZE[1] / SIZE[0])[can] == (not model.geom_castshadow[can])
    model.geom_castshadow[can] = 0
    assert out_of_view(model, data, head_view, SIZE[1] / SIZE[0])[can]
    env.close()


def test_the_table_top_hides_what_stands_under_it_only_from_above():
    env = TavisEnv("tabletop", "gr1t2", image_size=SIZE, cameras=())
    env.reset(seed=0)
    model, data = env.model, env.data
    fixed, table = env.world.cameras[scene.FIXED_CAMERA], TableCover.of(model)
    names = {model.geom(g).name for g in np.flatnonzero(table.hides(model, data, fixed))}
    assert "table/leg4" in names  # the middle back leg, far under the top
    assert not names & set(scene.TABLE_TOP_GEOMS)
    unseen = out_of_view(model, data, fixed, SIZE[1] / SIZE[0], table=table)
    assert names <= {model.geom(g).name for g in np.flatnonzero(unseen)}
    data.cam_xpos[fixed][2] = scene.TABLE_TOP_Z - 0.1  # below the top: it hides nothing
    assert not table.hides(model, data, fixed).any()
    env.close()
    shelves = TavisEnv("multi_shelf_scan", "gr1t2", image_size=SIZE, cameras=())
    shelves.reset(seed=0)
    assert TableCover.of(shelves.model) is None  # a task without the table
    shelves.close()


def test_a_wrist_camera_sees_the_backdrop_colour_beyond_its_far_clip():
    env = TavisEnv("clutter_pick_cube", "reachy2", camera_mode="head_wrist", image_size=SIZE)
    env.reset(seed=0)
    _posed(env, 0.5, 0.1)
    wrist = env.world.cameras["left_wrist"]
    with mujoco.Renderer(env.model, *SIZE) as depth_renderer:
        depth_renderer.enable_depth_rendering()
        depth_renderer.update_scene(env.data, camera=wrist)
        depth = depth_renderer.render()  # distance along the view (m)
    image = env._sim.rig.render_camera(env.data, wrist).astype(int)
    fog = np.round(255 * env.model.vis.rgba.fog[:3])
    beyond, near = depth > physics.WRIST_FAR_CLIP_M + 0.01, depth < physics.WRIST_FAR_CLIP_M - 0.01
    assert beyond.mean() > 0.05 and near.mean() > 0.05
    assert np.abs(image[beyond] - fog).max() <= 1
    assert (np.abs(image[near] - fog).max(axis=1) > 8).mean() > 0.5  # the nearer scene shows as it is
    head = env.world.cameras["head"]  # the head camera has no such clip
    with mujoco.Renderer(env.model, *SIZE) as plain:
        plain.update_scene(env.data, camera=head)
        np.testing.assert_array_equal(env._sim.rig.render_camera(env.data, head), plain.render())
    env.close()
