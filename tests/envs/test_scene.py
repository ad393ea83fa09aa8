"""The arena's look: textured materials on the table and floor, per-task key light, cue colours that still switch,
procedural textures that their script reproduces, and physics untouched by the drawn-only geoms."""

from pathlib import Path

import cv2
import mujoco
import numpy as np
import pytest

from lerobot_tavis import canonical
from lerobot_tavis.envs import physics, scene
from lerobot_tavis.envs.assets import ASSET_DIR
from lerobot_tavis.envs.env import TavisEnv
from lerobot_tavis.envs.robots import make_robot
from lerobot_tavis.envs.tasks.catalog import BUILTIN_TASKS, make_task, task_class
from lerobot_tavis.envs.tasks.conditional_pick.task import CARD
from lerobot_tavis.envs.tasks.multi_shelf_scan import task as shelf_task
from lerobot_tavis.envs.tasks.wait_then_act.task import LIGHT
from lerobot_tavis.envs.world import build_world

ROOT = Path(__file__).resolve().parents[2]


def _model(task_name: str) -> mujoco.MjModel:
    return build_world(make_robot("gr1t2"), make_task(task_name), image_size=(16, 16)).model


def _texture_of(model: mujoco.MjModel, geom: str) -> int:
    material = model.geom_matid[model.geom(geom).id]
    assert material >= 0, f"{geom} has no material"
    return model.mat_texid[material, mujoco.mjtTextureRole.mjTEXROLE_RGB]


def _texture_pixels(model: mujoco.MjModel, texture: int) -> np.ndarray:
    start, (h, w, c) = model.tex_adr[texture], (model.tex_height[texture], model.tex_width[texture],
                                                model.tex_nchannel[texture])
    return model.tex_data[start:start + h * w * c].reshape(h, w, c)


def _top_down(model, data, lookat, distance_m: float, size: int = 48) -> np.ndarray:
    """An image looking straight down at `lookat` (world, m) from `distance_m` above it."""
    camera = mujoco.MjvCamera()
    camera.type = mujoco.mjtCamera.mjCAMERA_FREE
    camera.lookat[:] = lookat
    camera.distance, camera.elevation, camera.azimuth = distance_m, -90.0, 0.0
    with mujoco.Renderer(model, size, size) as renderer:
        renderer.update_scene(data, camera=camera)
        return renderer.render().astype(float)


@pytest.mark.parametrize("task_name", sorted(BUILTIN_TASKS))
def test_every_task_compiles_with_textured_floor_and_key_light(task_name):
    model = _model(task_name)
    floor_texture = _texture_of(model, "floor/tiles")
    assert floor_texture >= 0
    assert model.light(scene.KEY_LIGHT).type == mujoco.mjtLightType.mjLIGHT_DIRECTIONAL
    if task_class(task_name).has_table:
        for geom in ("table/top", "table/surface"):
            assert _texture_of(model, geom) >= 0


def test_table_top_is_brushed_metal_texture_and_floor_tiles_repeat_every_half_metre():
    model = _model("conditional_pick")
    metal = _texture_pixels(model, _texture_of(model, "table/surface"))
    assert metal.std() > 1.0  # streaks and smudges, not a flat colour
    floor_material = model.geom_matid[model.geom("floor/tiles").id]
    assert model.mat_texuniform[floor_material]
    # MuJoCo repeats a texuniform texture `texrepeat` times per 2 m
    np.testing.assert_allclose(model.mat_texrepeat[floor_material], 2.0 / scene.FLOOR_LOOK.period_m)


def test_floor_renders_dark_tiles_with_light_grout():
    env = TavisEnv("conditional_pick", "gr1t2", cameras=())
    env.reset(seed=0)
    image = _top_down(env.model, env.data, (-1.5, 1.5, 0.0), 2.0, size=96).mean(axis=2)
    env.close()
    tile = np.median(image)
    bright = image > tile + 20
    assert tile < 60
    assert 0.01 < bright.mean() < 0.3  # thin grout lines cross the view
    assert bright.any(axis=0).sum() > 5 and bright.any(axis=1).sum() > 5  # ... in both directions


def test_drawn_only_geoms_leave_physics_alone():
    model = _model("conditional_pick")
    floor = model.geom("floor").id
    assert model.geom_group[floor] == physics.GROUP_HIDDEN
    assert (model.geom_contype[floor], model.geom_conaffinity[floor]) == (1, 3)
    for name in ("floor/tiles", "table/surface"):
        geom = model.geom(name).id
        assert model.geom_contype[geom] == model.geom_conaffinity[geom] == 0
        assert model.geom_group[geom] == physics.GROUP_VISIBLE
    surface, top = model.geom("table/surface").id, model.geom("table/top").id
    np.testing.assert_allclose(model.geom_size[surface][:2], model.geom_size[top][:2])
    assert 0 < model.geom_pos[surface][2] - scene.TABLE_TOP_Z < 0.001


def test_key_light_direction_and_strength_per_task():
    default, shelf = _model("conditional_pick"), _model("multi_shelf_scan")
    key = default.light(scene.KEY_LIGHT)
    np.testing.assert_allclose(key.dir, np.divide(scene.KEY_LIGHT_DIR, np.linalg.norm(scene.KEY_LIGHT_DIR)),
                               atol=1e-6)
    shelf_key = shelf.light(scene.KEY_LIGHT)
    expected = np.divide(shelf_task.KEY_LIGHT_DIR, np.linalg.norm(shelf_task.KEY_LIGHT_DIR))
    np.testing.assert_allclose(shelf_key.dir, expected, atol=1e-6)
    np.testing.assert_allclose(shelf_key.diffuse, key.diffuse * shelf_task.KEY_LIGHT_INTENSITY
                               / scene.KEY_LIGHT_INTENSITY, atol=1e-6)
    assert shelf.nlight == default.nlight == 1


def test_the_key_light_casts_shadows_by_default_and_the_arena_casts_none():
    robot, task = make_robot("gr1t2"), make_task("tabletop")
    shadowed = build_world(robot, task, image_size=(16, 16)).model
    plain = build_world(robot, task, image_size=(16, 16), shadows=False).model
    assert not plain.light_castshadow.any()
    key = shadowed.light(scene.KEY_LIGHT).id
    assert shadowed.light_castshadow.nonzero()[0].tolist() == [key]
    assert shadowed.vis.quality.shadowsize == scene.SHADOW_MAP_PX
    assert shadowed.vis.quality.offsamples == 0
    casts = {shadowed.geom(g).name: bool(shadowed.geom_castshadow[g]) for g in range(shadowed.ngeom)}
    assert not any(cast for name, cast in casts.items() if name.startswith(("floor", "table")))
    assert casts["soup_can/mesh"] and casts["gr1t2/left_finger_a/visual39"]


@pytest.mark.parametrize("task_name", ["tabletop", "multi_shelf_scan"])
def test_the_shadow_map_covers_the_workspace_along_the_key_light(task_name):
    model = _model(task_name)
    key = model.light(scene.KEY_LIGHT).id
    np.testing.assert_allclose(model.vis.map.shadowclip * model.stat.extent, scene.SHADOW_HALF_WIDTH_M, rtol=1e-6)
    # MuJoCo centres a directional light's shadow map on the line through its position along its direction
    to_centre = np.subtract(scene.SHADOW_CENTRE, model.light_pos[key])
    np.testing.assert_allclose(to_centre, scene.KEY_LIGHT_DISTANCE_M * model.light_dir[key], atol=1e-6)


def test_the_arms_shadow_darkens_the_table_under_the_key_light():
    env = TavisEnv("tabletop", "gr1t2", camera_mode="fixed_only", image_size=(48, 64))
    flat = TavisEnv("tabletop", "gr1t2", camera_mode="fixed_only", image_size=(48, 64), shadows=False)
    shadowed, plain = (e.reset(seed=0)[0]["pixels"]["fixed"].astype(float) for e in (env, flat))
    env.close()
    flat.close()
    darker = plain.mean(axis=2) - shadowed.mean(axis=2)
    assert (darker > 20).mean() > 0.01  # the shadows of the arms and objects
    assert (abs(darker) < 8).mean() > 0.5  # the lit rest looks as without shadows


def _is(colour: str, patch: np.ndarray) -> bool:
    r, g, _ = patch.reshape(-1, 3).mean(axis=0)
    return r > 2 * g + 40 if colour == "red" else g > 2 * r + 40


def test_cue_card_renders_red_or_green_as_its_state_says():
    seen = set()
    env = TavisEnv("conditional_pick", "gr1t2", cameras=())
    for seed in range(20):
        env.reset(seed=seed)
        colour = "red" if env.task_object.card_is_red else "green"
        card = env.data.mocap_pos[env.model.body(CARD).mocapid[0]]
        image = _top_down(env.model, env.data, card, 0.2)
        assert _is(colour, image[20:28, 20:28]), f"seed {seed}: the card should look {colour}"
        seen.add(colour)
        if len(seen) == 2:
            break
    env.close()
    assert seen == {"red", "green"}


def test_signal_light_renders_red_then_green():
    env = TavisEnv("wait_then_act", "gr1t2", cameras=())
    env.reset(seed=0)
    lamp = env.data.mocap_pos[env.model.body(LIGHT).mocapid[0]]
    assert _is("red", _top_down(env.model, env.data, lamp, 0.2)[20:28, 20:28])
    while not env.task_object.is_green:
        env.step(canonical.rest_action())
    assert _is("green", _top_down(env.model, env.data, lamp, 0.2)[20:28, 20:28])
    env.close()


def test_texture_script_reproduces_the_packaged_textures(monkeypatch):
    monkeypatch.syspath_prepend(str(ROOT / "tools" / "assets"))
    import textures

    for name, (make, _) in textures.TEXTURES.items():
        packaged = cv2.cvtColor(cv2.imread(str(ASSET_DIR / "scene" / name)), cv2.COLOR_BGR2RGB)
        regenerated = make()
        assert regenerated.shape == packaged.shape
        assert np.abs(regenerated.astype(int) - packaged).max() <= 1, name  # float noise may round differently


def test_cameras_clip_at_a_tenth_of_a_metre_like_the_reference():
    model = _model("tabletop")
    assert model.vis.map.znear * model.stat.extent == pytest.approx(physics.NEAR_CLIP_M)
    assert model.vis.map.zfar * model.stat.extent == pytest.approx(physics.FAR_CLIP_M)


def test_a_head_pitched_fully_down_does_not_blind_the_fixed_camera():
    env = TavisEnv("tabletop", "gr1t2", camera_mode="head_wrist", image_size=(48, 64), cameras=("fixed",))
    env.reset(seed=0)
    action = canonical.rest_action()
    action[canonical.HEAD_PITCH] = 0.87  # the neck's limit: the head leans over the fixed camera
    for _ in range(30):
        obs, *_ = env.step(action)
    dark = (obs["pixels"]["fixed"].max(axis=2) < 30).mean()
    env.close()
    assert dark < 0.1  # the head (within 0.1 m of the lens) is clipped; the table and arms stay in view


def test_the_table_fills_the_fixed_camera_s_view_from_side_to_side():
    """As in the reference's figure: below the table's far edge the fixed camera sees table top, not floor, at both
    sides of its image; the top is flush with its rounded front lip at TABLE_TOP_Z."""
    env = TavisEnv("clutter_pick_cube", "gr1t2", image_size=(48, 64), cameras=())
    env.reset(seed=0)
    model, data = env.model, env.data
    with mujoco.Renderer(model, 48, 64) as renderer:
        renderer.enable_segmentation_rendering()
        renderer.update_scene(data, camera=env.world.cameras[scene.FIXED_CAMERA])
        segmentation = renderer.render()
    env.close()
    geoms = np.where(segmentation[..., 1] == mujoco.mjtObj.mjOBJ_GEOM, segmentation[..., 0], -1)
    table = [g for g in range(model.ngeom) if model.geom(g).name.startswith("table/")]
    for row in (26, 32, 38):  # between the far edge (row ~19) and the front lip (row ~41)
        assert np.isin(geoms[row, [0, -1]], table).all(), row
    lip, top = model.geom("table/lip").id, model.geom("table/top").id
    assert model.geom_pos[lip][2] + model.geom_size[lip][0] == pytest.approx(scene.TABLE_TOP_Z)
    assert model.geom_pos[top][2] + model.geom_size[top][2] == pytest.approx(scene.TABLE_TOP_Z)
