"""The eight TAVIS tasks: layouts within their split's ranges, success rules, prompts, blocked camera, init pose."""

import itertools
import re
from pathlib import Path

import mujoco
import numpy as np
import pytest

from lerobot_tavis import canonical
from lerobot_tavis.envs import placement
from lerobot_tavis.envs.env import WARM_UP_HEAD_STD_RAD, WARM_UP_POSITION_STD_M, TavisEnv, warm_up_action
from lerobot_tavis.envs.objects import OBJECT_NAMES, PROPS
from lerobot_tavis.envs.robots import make_robot
from lerobot_tavis.envs.tasks import catalog, info, multi_shelf_scan
from lerobot_tavis.envs.tasks.multi_shelf_scan import task as shelf_task
from lerobot_tavis.envs.tasks.peeking_box import task as peeking_box
from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS, SUITES, TASKS, make_task, suite_tasks
from lerobot_tavis.envs.tasks.clutter_pick_lift.task import footprint
from lerobot_tavis.envs.tasks.layout import CONTACT_GAP_M, Pose2D, overlaps
from lerobot_tavis.envs.world import build_world

TAVIS_TASKS = list(BENCHMARK_TASKS)
ROOT = Path(__file__).resolve().parents[2]
VARIANTS = ("id", "ood_spatial")
SEEDS = 200


def _world(task_name, variant):
    task = make_task(task_name, variant)
    world = build_world(make_robot("gr1t2"), task, image_size=(16, 16))
    return task, world.model, mujoco.MjData(world.model)


def _xy(model, data, body):
    return data.qpos[model.jnt_qposadr[model.body(body).jntadr[0]]:][:2].copy()


def _visible(model, data):
    return [n for n in (*OBJECT_NAMES, "red_cube") if n in PROPS and _has(model, n) and _xy(model, data, n)[0] > 0]


def _has(model, body):
    try:
        model.body(body)
        return True
    except KeyError:
        return False


def _table_rows(path: Path) -> list[list[str]]:
    """The cells of every Markdown table row of `path`, header and rule rows included."""
    return [[cell.strip() for cell in line.strip().strip("|").split("|")]
            for line in path.read_text().splitlines() if line.startswith("|")]


def test_suites_hold_the_reference_tasks_and_the_docs_list_the_registry():
    reference_suites = {row[0]: {name.strip() for name in row[1].split(",")}
                        for row in _table_rows(ROOT / "docs" / "reference.md") if row[0].startswith("TAVIS-")}
    assert {suite: set(suite_tasks(suite)) for suite in SUITES} == {
        f"tavis_{name[len('TAVIS-'):].lower()}": tasks for name, tasks in reference_suites.items()}
    for name in TAVIS_TASKS:
        assert TASKS[name].splits == ("id", "ood_spatial", "ood_init_pose", "ood_visual")
    documented = [(row[0], row[1]) for row in _table_rows(ROOT / "docs" / "tasks.md") if row[0] in SUITES]
    assert documented == [(TASKS[name].suite, name) for name in TAVIS_TASKS]
    (readme_list,) = re.findall(r"The eight tasks \(([^)]*)\)", (ROOT / "README.md").read_text())
    assert re.findall(r"`(\w+)`", readme_list) == TAVIS_TASKS


def test_the_docs_state_the_success_thresholds_of_the_code():
    """docs/tasks.md and the demonstrators' comments write each threshold as "`NAME` = value"; every value is the
    constant's, and the shelf's threshold is its front edge less 3 cm."""
    constants = {name: getattr(module, name) for module, names in
                 ((info, ("LIFT_HEIGHT_M", "HIGH_LIFT_HEIGHT_M", "MAX_SUCCESS_SPEED_M_S")),
                  (multi_shelf_scan, ("SHELF_EXIT_X_M",))) for name in names}
    texts = [ROOT / "docs" / "tasks.md", *sorted((ROOT / "lerobot_tavis" / "experts").glob("*.py"))]
    stated = [(name, float(value)) for path in texts
              for name, value in re.findall(r"`([A-Z_]+)` = (\d+(?:\.\d+)?)", path.read_text())]
    assert {name for name, _ in stated} == set(constants)
    for name, value in stated:
        assert value == pytest.approx(constants[name], abs=1e-9), name
    assert multi_shelf_scan.SHELF_EXIT_X_M == multi_shelf_scan.SHELF_X - multi_shelf_scan.SHELF_DEPTH / 2 - 0.03


@pytest.mark.parametrize("task_name", TAVIS_TASKS)
def test_each_tasks_row_in_the_docs_names_the_threshold_its_success_rule_uses(task_name):
    """The success cell of the task's docs/tasks.md row and its row of docs/evaluation.md's conditions table name the
    constant the class's `evaluate` tests, and the declaration's rule text states its value."""
    (row,) = [row for row in _table_rows(ROOT / "docs" / "tasks.md") if row[:2] == [TASKS[task_name].suite, task_name]]
    (conditions_row,) = [row for row in _table_rows(ROOT / "docs" / "evaluation.md")
                         if f"`{task_name}`" in re.findall(r"`\w+`", row[0])]
    cls = catalog.task_class(task_name)
    threshold = multi_shelf_scan.SHELF_EXIT_X_M if task_name == "multi_shelf_scan" else cls.success_height_m
    (named,) = re.findall(r"(?:above|x =) `([A-Z_]+)`", row[3])
    assert getattr(info, named, getattr(multi_shelf_scan, named, None)) == threshold
    assert set(re.findall(r"`([A-Z_]+_M)`", conditions_row[1])) == {named}
    assert f"{threshold:.3f}".rstrip("0") in TASKS[task_name].success_rule
    speed = info.MAX_SUCCESS_SPEED_M_S
    assert "`MAX_SUCCESS_SPEED_M_S`" in row[3] and f"{speed:g} m/s" in TASKS[task_name].success_rule


@pytest.mark.parametrize("variant", VARIANTS)
@pytest.mark.parametrize("task_name", ["clutter_pick_lift", "clutter_pick_cube"])
def test_clutter_layouts_stay_in_range_and_never_overlap(task_name, variant):
    """blocked_clutter_pick_cube lays out clutter_pick_cube's scene (test_blocked_clutter_pick_cube_is_...)."""
    task, model, data = _world(task_name, variant)
    region = task.variant.region
    rng = np.random.default_rng(0)
    for _ in range(SEEDS):
        task.initialize_episode(model, data, rng)
        names = _visible(model, data)
        assert len(names) == 5  # cube tasks: four YCB objects and the cube
        for name in names:
            assert region.contains(_xy(model, data, name))
        poses = {name: Pose2D(_xy(model, data, name), _yaw(model, data, name)) for name in names}
        for a, b in itertools.combinations(names, 2):
            assert not overlaps(poses[a].xy[None], np.array([poses[a].yaw]), footprint(PROPS[a]), poses[b],
                                footprint(PROPS[b]), CONTACT_GAP_M - 1e-6)[0], (a, b)
        assert task.target in names


@pytest.mark.parametrize("variant", VARIANTS)
def test_blocked_clutter_pick_cube_is_clutter_pick_cubes_layout_seed_for_seed(variant):
    layouts = []
    for task_name in ("clutter_pick_cube", "blocked_clutter_pick_cube"):
        task, model, data = _world(task_name, variant)
        rng = np.random.default_rng(0)
        layouts.append([])
        for _ in range(5):
            task.initialize_episode(model, data, rng)
            layouts[-1].append((task.target, {name: _xy(model, data, name).tolist() for name in _visible(model, data)}))
    assert layouts[0] == layouts[1]


def _yaw(model, data, body):
    w, x, y, z = data.qpos[model.jnt_qposadr[model.body(body).jntadr[0]] + 3:][:4]
    return float(np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)))


@pytest.mark.parametrize("variant", VARIANTS)
def test_conditional_pick_layout(variant):
    task, model, data = _world("conditional_pick", variant)
    rng = np.random.default_rng(1)
    colours = set()
    for _ in range(SEEDS):
        task.initialize_episode(model, data, rng)
        assert task.variant.left_zone.contains(_xy(model, data, task.left_object))
        assert task.variant.right_zone.contains(_xy(model, data, task.right_object))
        card = data.mocap_pos[model.body("cue_card").mocapid[0]]
        assert task.variant.card_zone.contains(card[:2])
        assert task.target == (task.left_object if task.card_is_red else task.right_object)
        assert len(_visible(model, data)) == 2
        colours.add(task.card_is_red)
    assert colours == {True, False}


@pytest.mark.parametrize("variant,delays", [("id", (2.0, 5.0)), ("ood_spatial", (2.0, 8.0))])
def test_wait_then_act_layout_and_delay(variant, delays):
    task, model, data = _world("wait_then_act", variant)
    rng = np.random.default_rng(2)
    for _ in range(SEEDS):
        task.initialize_episode(model, data, rng)
        assert delays[0] <= task.delay_s <= delays[1] and task.green_at_s == int(task.delay_s * 20) / 20
        assert task.variant.object_zone.contains(_xy(model, data, task.target))
        assert task.variant.light_zone.contains(data.mocap_pos[model.body("signal_light").mocapid[0]][:2])
        assert _visible(model, data) == [task.target] and not task.is_green


@pytest.mark.parametrize("variant", VARIANTS)
def test_multi_shelf_scan_layout(variant):
    task, model, data = _world("multi_shelf_scan", variant)
    rng = np.random.default_rng(3)
    for _ in range(SEEDS):
        task.initialize_episode(model, data, rng)
        assert len(set(task.slots.values())) == 5
        for name, (shelf, slot_y) in task.slots.items():
            x, y = _xy(model, data, name)
            assert shelf_task.SLOT_X_CLAMP[0] - 1e-9 <= x <= shelf_task.SLOT_X_CLAMP[1] + 1e-9
            assert abs(y - slot_y) <= task.variant.jitter_y_m + 1e-9 and abs(y) <= 0.32 + 1e-9
        assert task.prompt in multi_shelf_scan.PROMPTS[task.target]


@pytest.mark.parametrize("variant", VARIANTS)
def test_peeking_box_layout(variant):
    task, model, data = _world("peeking_box", variant)
    rng = np.random.default_rng(4)
    sides = set()
    for _ in range(SEEDS):
        task.initialize_episode(model, data, rng)
        v = task.variant
        assert v.box_x[0] <= task.box_center[0] <= v.box_x[1] and v.box_y[0] <= task.box_center[1] <= v.box_y[1]
        assert v.box_yaw_rad[0] <= task.box_yaw <= v.box_yaw_rad[1]
        local = peeking_box.matrix_from_quat(peeking_box.axis_angle_quat((0, 0, 1), -task.box_yaw))[:2, :2] @ (
            _xy(model, data, task.target) - task.box_center)
        assert v.object_dx[0] - 1e-9 <= local[0] <= v.object_dx[1] + 1e-9
        assert v.object_dy[0] - 1e-9 <= local[1] <= v.object_dy[1] + 1e-9
        open_geom = model.geom(f"box/{task.open_side}").id
        assert model.geom_contype[open_geom] == 0 and model.geom_group[open_geom] == 3
        sides.add(task.open_side)
    assert sides == {"+y", "-y"}


@pytest.mark.parametrize("variant", VARIANTS)
def test_occluded_reach_layout(variant):
    task, model, data = _world("occluded_reach", variant)
    rng = np.random.default_rng(5)
    for _ in range(SEEDS):
        task.initialize_episode(model, data, rng)
        assert task.variant.object_zone.contains(_xy(model, data, task.target))
        assert _visible(model, data) == [task.target]


@pytest.mark.parametrize("task_name", TAVIS_TASKS)
def test_episode_facts_name_bodies_of_the_world_and_agree_with_the_episode(task_name):
    """What a demonstrator reads of a task (`episode_facts`): bodies that exist, this episode's draw, frozen."""
    task, model, data = _world(task_name, "ood_spatial")
    rng = np.random.default_rng(6)
    task.initialize_episode(model, data, rng)
    facts = task.episode_facts()
    assert facts.props == task.props() and facts.target == task.target and facts.target in facts.props
    assert facts.succeeds(data) == task.is_success(data)
    names = [v for v in vars(facts).values() if isinstance(v, str) and v not in ("+y", "-y")]
    assert all(_has(model, name) for name in (*facts.props, *names)), names
    with pytest.raises(AttributeError):
        facts.target = "elsewhere"
    if task_name == "conditional_pick":
        assert (facts.left_object, facts.right_object) == (task.left_object, task.right_object)
        assert model.body(facts.cue_card).mocapid[0] >= 0
    if task_name == "wait_then_act":
        assert model.body(facts.light).mocapid[0] >= 0 and not facts.light_is_green()
        task.after_step(model, data, task.green_at_s)
        assert facts.light_is_green()
    if task_name == "peeking_box":
        assert facts.open_side == task.open_side and facts.yaw_rad == task.box_yaw
        np.testing.assert_array_equal(facts.point(0.05, -0.02, 1.1), task.box_point(0.05, -0.02, 1.1))
        np.testing.assert_allclose(facts.to_box(facts.point(0.05, -0.02, 1.1)[:2]), (0.05, -0.02), atol=1e-12)
        assert facts.top_z_m == peeking_box.BOTTOM_Z + peeking_box.HEIGHT
    if task_name == "occluded_reach":
        panel = model.geom("screen/panel").id
        assert model.geom_pos[panel][0] == pytest.approx(facts.screen_x_m)
        assert model.geom_size[panel][1] == pytest.approx(facts.panel_half_width_m)
    assert not any(isinstance(value, np.ndarray) for value in vars(facts).values())  # nothing shared that can change


@pytest.mark.parametrize("task_name", TAVIS_TASKS)
def test_success_fires_above_the_threshold_and_not_below(task_name):
    task, model, data = _world(task_name, "id")
    task.initialize_episode(model, data, np.random.default_rng(0))
    if task_name == "wait_then_act":
        task.after_step(model, data, task.green_at_s)
    if task_name == "multi_shelf_scan":
        inside, outside = (0.50, 0.0, 1.2), (0.40, 0.0, 1.2)
    else:
        threshold = task.success_height_m
        inside, outside = (0.4, 0.0, threshold - 0.01), (0.4, 0.0, threshold + 0.01)
    for where, expected in ((inside, False), (outside, True)):
        placement.set_free_pose(model, data, task.target, where)
        mujoco.mj_forward(model, data)
        assert task.is_success(data) == expected, where
    dof = model.jnt_dofadr[model.body(task.target).jntadr[0]]
    data.qvel[dof] = 1.5  # moving too fast
    mujoco.mj_forward(model, data)
    assert not task.is_success(data)


def _pose_and_speed(model, data, task, where, speed_m_s=0.0):
    placement.set_free_pose(model, data, task.target, where)
    data.qvel[model.jnt_dofadr[model.body(task.target).jntadr[0]]] = speed_m_s
    mujoco.mj_forward(model, data)
    return task.evaluate(data)


def test_evaluate_shows_which_part_of_the_lift_rule_fails():
    task, model, data = _world("conditional_pick", "id")
    task.initialize_episode(model, data, np.random.default_rng(0))
    fast = _pose_and_speed(model, data, task, (0.4, 0.0, 1.3), speed_m_s=1.5)  # lifted but moving fast
    assert fast["success"] is False and fast["target_lifted"] is True and fast["target_slow"] is False
    assert fast["target_height_m"] == pytest.approx(1.3) and fast["target_speed_m_s"] == pytest.approx(1.5)
    low = _pose_and_speed(model, data, task, (0.4, 0.0, 1.1))  # slow but below 1.2 m
    assert low["success"] is False and low["target_lifted"] is False and low["target_slow"] is True
    assert list(low) == ["success", "target_lifted", "target_slow", "target_height_m", "target_speed_m_s"]
    up = _pose_and_speed(model, data, task, (0.4, 0.0, 1.3))
    assert up["success"] is True and up["success"] == task.is_success(data)


def test_evaluate_shows_an_object_still_in_the_shelf():
    task, model, data = _world("multi_shelf_scan", "id")
    task.initialize_episode(model, data, np.random.default_rng(0))
    inside = _pose_and_speed(model, data, task, (0.50, 0.0, 1.2))
    assert inside["success"] is False and inside["target_out_of_shelf"] is False and inside["target_slow"] is True
    assert inside["target_x_m"] == pytest.approx(0.50)
    out = _pose_and_speed(model, data, task, (0.40, 0.0, 1.2))
    assert out["success"] is True and out["target_out_of_shelf"] is True


def test_evaluate_shows_a_lift_before_the_light_is_green():
    task, model, data = _world("wait_then_act", "id")
    task.initialize_episode(model, data, np.random.default_rng(0))
    task.after_step(model, data, 0.0)
    early = _pose_and_speed(model, data, task, (0.4, 0.0, 1.3))
    assert early["success"] is False and early["light_green"] is False
    assert early["target_lifted"] is True and early["target_slow"] is True
    task.after_step(model, data, task.green_at_s)
    assert task.evaluate(data)["success"] is True and task.evaluate(data)["light_green"] is True


@pytest.mark.parametrize("task_name", [*TAVIS_TASKS, "tabletop"])
def test_evaluate_gives_plain_json_values(task_name):
    task, model, data = _world(task_name, "id")
    task.initialize_episode(model, data, np.random.default_rng(0))
    mujoco.mj_forward(model, data)
    evaluation = task.evaluate(data)
    assert next(iter(evaluation)) == "success" and evaluation["success"] is False
    assert all(type(value) in (bool, float) for value in evaluation.values()), evaluation


def test_wait_then_act_counts_success_only_once_green():
    task, model, data = _world("wait_then_act", "id")
    task.initialize_episode(model, data, np.random.default_rng(0))
    placement.set_free_pose(model, data, task.target, (0.4, 0.0, 1.3))
    mujoco.mj_forward(model, data)
    task.after_step(model, data, task.green_at_s - 1 / 60)
    assert not task.is_green and not task.is_success(data) and task.task_state().tolist() == [0.0]
    task.after_step(model, data, task.green_at_s)
    assert task.is_green and task.is_success(data) and task.task_state().tolist() == [1.0]


def test_blocked_head_camera_is_black_and_the_head_still_moves(small_env):
    env = small_env(task="blocked_clutter_pick_cube", camera_mode="head_wrist")
    obs, _ = env.reset(seed=0)
    assert not obs["pixels"]["head"].any()
    assert obs["pixels"]["left_wrist"].any()
    action = canonical.rest_action()
    action[canonical.HEAD_YAW] = 0.5
    for _ in range(15):
        obs, *_ = env.step(action)
    assert not obs["pixels"]["head"].any() and obs["agent_pos"][canonical.HEAD_YAW] == pytest.approx(0.5, abs=0.02)
    open_env = small_env(task="clutter_pick_cube", camera_mode="head_only")
    assert open_env.reset(seed=0)[0]["pixels"]["head"].any()


@pytest.mark.parametrize("task_name", TAVIS_TASKS)
def test_seed_reproduces_layout_and_prompt_and_objects_are_still(small_env, task_name):
    first, second = (small_env(task=task_name, camera_mode="fixed_only", cameras=()) for _ in range(2))
    first.reset(seed=11)
    second.reset(seed=11)
    np.testing.assert_array_equal(first.data.qpos, second.data.qpos)
    assert first.task_description == second.task_description
    for prop in first.task_object.props():
        assert placement.body_speed(first.model, first.data, prop) < 0.01


@pytest.mark.parametrize("task_name", ["clutter_pick_lift", "multi_shelf_scan"])
def test_prompts_vary_with_the_seed(small_env, task_name):
    env = small_env(task=task_name, camera_mode="fixed_only", cameras=())
    prompts = {env.reset(seed=seed)[0] and env.task_description for seed in range(30)}
    assert len(prompts) >= 8 and prompts <= set(TASKS[task_name].prompts)


def test_warm_up_noise_has_the_reference_spread():
    rng = np.random.default_rng(0)
    samples = np.array([warm_up_action(rng) for _ in range(4000)]) - canonical.rest_action()
    positions = samples[:, [0, 1, 2, 7, 8, 9]]
    assert positions.std(axis=0) == pytest.approx(np.full(6, WARM_UP_POSITION_STD_M), rel=0.06)
    assert samples[:, [15, 16]].std(axis=0) == pytest.approx(np.full(2, WARM_UP_HEAD_STD_RAD), rel=0.06)
    np.testing.assert_array_equal(samples[:, 14], 0.0)
    np.testing.assert_array_equal(samples[:, [3, 4, 5, 6, 10, 11, 12, 13, 17, 18]], 0.0)


def test_ood_init_pose_starts_from_the_id_scene_with_a_perturbed_robot(small_env):
    nominal = small_env(task="clutter_pick_lift", split="id", camera_mode="fixed_only", cameras=())
    perturbed = small_env(task="clutter_pick_lift", split="ood_init_pose", camera_mode="fixed_only", cameras=())
    id_obs, _ = nominal.reset(seed=5)
    ood_obs, _ = perturbed.reset(seed=5)
    for name in OBJECT_NAMES:
        np.testing.assert_allclose(_xy(nominal.model, nominal.data, name),
                                   _xy(perturbed.model, perturbed.data, name), atol=2e-3)
    assert nominal.task_description == perturbed.task_description
    hands = [0, 1, 2, 7, 8, 9]
    moved = np.abs(ood_obs["agent_pos"][hands] - id_obs["agent_pos"][hands])
    assert moved.max() > 0.02


def _steps_until(env, seed, done) -> int:
    env.reset(seed=seed)
    for step in range(1, 1000):
        _, _, terminated, truncated, _ = env.step(canonical.rest_action())
        if done(env, truncated):
            return step
    raise AssertionError("never done")


@pytest.mark.parametrize("fps", [20, 60])
def test_ood_init_pose_warm_up_counts_toward_the_episode_and_the_task_clock(small_env, fps):
    def truncated(env, truncated):
        return truncated

    def green(env, truncated):
        return env.task_object.is_green

    warm_up_steps = fps // 2  # 10 policy steps at 20 Hz: 0.5 s
    lengths = {split: _steps_until(small_env(task="clutter_pick_lift", split=split, episode_length_s=2.0, fps=fps,
                                             camera_mode="fixed_only", cameras=()), 3, truncated)
               for split in ("id", "ood_init_pose")}
    assert lengths == {"id": 2 * fps, "ood_init_pose": 2 * fps - warm_up_steps}
    greens = {split: _steps_until(small_env(task="wait_then_act", split=split, fps=fps, camera_mode="fixed_only",
                                            cameras=()), 4, green)
              for split in ("id", "ood_init_pose")}
    assert greens["id"] - greens["ood_init_pose"] == warm_up_steps


def test_task_metadata_is_readable_without_a_simulator():
    info = TASKS["multi_shelf_scan"]
    assert info.suite == "tavis_head" and len(info.prompts) == 15 and "0.435" in info.success_rule
    assert TASKS["peeking_box"].prompts == ("Retrieve the object from inside the box.",)
    assert TavisEnv(task="peeking_box")._sim is None


def _drawn(model, body):
    """Whether any geom of `body` is in a group the renderer draws (0-2)."""
    start = model.body(body).geomadr[0]
    return bool((model.geom_group[start:start + model.body(body).geomnum[0]] <= 2).any())


def test_parked_props_are_not_drawn_and_placed_props_are():
    task, model, data = _world("conditional_pick", "id")
    rng = np.random.default_rng(4)
    drawn_once = set()
    for _ in range(20):
        task.initialize_episode(model, data, rng)
        placed = {task.left_object, task.right_object}
        for name in OBJECT_NAMES:
            assert _drawn(model, name) == (name in placed), name
        drawn_once |= placed
    assert drawn_once == set(OBJECT_NAMES)  # every prop was parked, then placed and drawn again
