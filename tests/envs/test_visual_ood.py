"""The ood_visual split: the id episode of the same seed with only the look changed, each factor within its
documented range, distractors clear of the task's objects."""

import numpy as np
import pytest

from lerobot_tavis.envs import visual_ood
from lerobot_tavis.envs.env import TavisEnv
from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS, VISUAL_FACTORS, parse_split, split_names
from lerobot_tavis.experts.rollout import make_expert

SIZE = (48, 64)


def play(task, split, seed, robot="gr1t2", steps=15):
    """States and pixels of the first `steps` demonstrator steps of one episode."""
    env = TavisEnv(task, robot, camera_mode="head_wrist", split=split, image_size=SIZE, cameras=("head", "fixed"))
    obs, _ = env.reset(seed=seed)
    expert = make_expert(env, seed)
    expert.reset()
    states, pixels = [env.data.qpos.copy()], [obs["pixels"]]
    for _ in range(steps):
        obs, *_ = env.step(expert.act())
        states.append(env.data.qpos.copy())
        pixels.append(obs["pixels"])
    draw, prompt = env.visual_draw, env.task_description
    env.close()
    return np.array(states), pixels, draw, prompt


@pytest.mark.parametrize("task,robot", [(task, "gr1t2") for task in BENCHMARK_TASKS] + [("peeking_box", "reachy2")])
def test_same_states_and_prompt_as_id_different_pixels(task, robot):
    id_states, id_pixels, _, id_prompt = play(task, "id", 7, robot)
    states, pixels, draw, prompt = play(task, "ood_visual", 7, robot)
    np.testing.assert_array_equal(states, id_states)
    assert prompt == id_prompt and draw is not None
    assert any(np.abs(pixels[0][c].astype(int) - id_pixels[0][c]).mean() > 2 for c in ("head", "fixed"))


def test_same_seed_same_look_and_pixels():
    first, second = play("conditional_pick", "ood_visual", 3, steps=2), play("conditional_pick", "ood_visual", 3,
                                                                             steps=2)
    assert first[2] == second[2]
    for a, b in zip(first[1], second[1]):
        for camera in a:
            np.testing.assert_array_equal(a[camera], b[camera])
    assert play("conditional_pick", "ood_visual", 4, steps=0)[2] != first[2]


@pytest.fixture(scope="module")
def id_pixels_seed_5():
    """The first observation's pixels of conditional_pick seed 5 in the id split, which every factor changes."""
    return play("conditional_pick", "id", 5, steps=0)[1]


@pytest.mark.parametrize("factor", VISUAL_FACTORS)
def test_one_factor_alone_changes_only_its_part(factor, id_pixels_seed_5):
    id_pixels = id_pixels_seed_5
    _, pixels, draw, _ = play("conditional_pick", f"ood_visual:{factor}", 5, steps=0)
    drawn = {name for name, value in vars(draw).items() if value not in (None, ())}
    expected = {"table": {"table_texture", "table_rgb", "table_specular"}, "floor": {"floor_rgb"},
                "backdrop": {"backdrop_rgb"}, "distractors": {"distractors"},
                "lighting": {"light_azimuth_deg", "light_elevation_deg", "light_intensity_scale", "light_kelvin",
                             "dome_ambient"}}[factor]
    assert drawn == expected
    assert any(np.any(pixels[0][c] != id_pixels[0][c]) for c in ("head", "fixed"))


def test_every_factor_stays_in_its_range_and_distractors_stay_clear_over_200_seeds():
    env = TavisEnv("clutter_pick_cube", "gr1t2", split="ood_visual", cameras=())
    shelf = TavisEnv("multi_shelf_scan", "gr1t2", split="ood_visual", cameras=())
    prefix = env.unwrapped._robot.prefix
    for seed in range(200):
        for world in (env, shelf) if seed % 10 == 0 else (env,):
            world.reset(seed=seed)
            draw = world.visual_draw
            if world is env:
                assert draw.table_texture in ("brushed_metal.png", "wood.png", "none")
                assert visual_ood.TABLE_SPECULAR[0] <= draw.table_specular <= visual_ood.TABLE_SPECULAR[1]
                _check_hsv(draw.table_rgb, visual_ood.TABLE_SATURATION, visual_ood.TABLE_VALUE)
            _check_hsv(draw.floor_rgb, visual_ood.FLOOR_SATURATION, visual_ood.FLOOR_VALUE)
            _check_hsv(draw.backdrop_rgb, visual_ood.BACKDROP_SATURATION, visual_ood.BACKDROP_VALUE)
            for name in ("light_azimuth_deg", "light_elevation_deg", "light_intensity_scale", "light_kelvin",
                         "dome_ambient"):
                low, high = {"light_azimuth_deg": visual_ood.LIGHT_AZIMUTH_DEG,
                             "light_elevation_deg": visual_ood.LIGHT_ELEVATION_DEG,
                             "light_intensity_scale": visual_ood.LIGHT_INTENSITY_SCALE,
                             "light_kelvin": visual_ood.LIGHT_KELVIN, "dome_ambient": visual_ood.DOME_AMBIENT}[name]
                assert low <= getattr(draw, name) <= high, name
            assert len(draw.distractors) <= visual_ood.DISTRACTOR_COUNT[1]
            others = visual_ood.task_geoms(world.model, prefix)
            for index, (_, position, size) in enumerate(draw.distractors):
                geom = world.model.geom(f"ood_visual/distractor{index}").id
                assert visual_ood.DISTRACTOR_SIZE_M[0] <= size <= visual_ood.DISTRACTOR_SIZE_M[1]
                assert visual_ood.clearance_m(world.model, world.data, geom, others) >= visual_ood.MIN_CLEARANCE_M
                bands = visual_ood.TABLE_BANDS if world is env else visual_ood.FLOOR_BANDS
                assert any(x[0] <= position[0] <= x[1] and y[0] <= position[1] <= y[1] for x, y in bands)
        assert len(env.visual_draw.distractors) >= visual_ood.DISTRACTOR_COUNT[0]
    env.close()
    shelf.close()


def _check_hsv(rgb, saturation, value):
    import colorsys

    _, s, v = colorsys.rgb_to_hsv(*rgb)
    assert saturation[0] - 1e-9 <= s <= saturation[1] + 1e-9 and value[0] - 1e-9 <= v <= value[1] + 1e-9


def test_the_id_model_has_none_of_the_split_pieces():
    env = TavisEnv("conditional_pick", "gr1t2", cameras=())
    env.reset(seed=0)
    names = {env.model.geom(g).name for g in range(env.model.ngeom)}
    assert not any(name.startswith("ood_visual/") for name in names)
    env.close()


def test_split_names_and_errors():
    assert parse_split("ood_visual") == ("ood_visual", VISUAL_FACTORS)
    assert parse_split("ood_visual:lighting") == ("ood_visual", ("lighting",))
    assert parse_split("id") == ("id", ())
    assert "ood_visual:distractors" in split_names()
    with pytest.raises(ValueError, match="factor of ood_visual must be one of"):
        parse_split("ood_visual:weather")
    with pytest.raises(ValueError, match="only ood_visual takes a factor"):
        parse_split("id:lighting")
    with pytest.raises(ValueError, match="split must be one of"):
        TavisEnv("conditional_pick", split="ood_style")
