import numpy as np
import pytest

from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS, VISUAL_FACTORS
from lerobot_tavis.gallery import (OOD_VISUAL_VIEWS, SHEET_VIEWS, GalleryConfig, Stills, capture_stills,
                                   ood_visual_sheet, overview_figure, write_gallery)

pytestmark = pytest.mark.slow  # conftest.py: its file starts first


def test_task_sheet_shows_the_first_observation_and_the_grasp(tmp_path):
    written = write_gallery(GalleryConfig(tmp_path, robots=("gr1t2",), tasks=("conditional_pick",),
                                          image_size=(48, 64)))
    assert [p.relative_to(tmp_path).as_posix() for p in written] == ["gallery/gr1t2/conditional_pick.png",
                                                                     "gallery/gr1t2/ood_visual.png"]
    assert not (tmp_path / "overview.png").exists()  # the figure needs all eight tasks
    assert not list(tmp_path.rglob("*.partial*"))


def test_stills_change_between_first_observation_and_grasp():
    stills = capture_stills("conditional_pick", "gr1t2", image_size=(48, 64))
    assert stills.grasped
    assert set(stills.first) == set(stills.grasp) == set(SHEET_VIEWS)
    for view in SHEET_VIEWS:
        assert stills.first[view].shape == (48, 64, 3)
    moved = [view for view in SHEET_VIEWS if np.abs(stills.first[view].astype(int) - stills.grasp[view]).mean() > 2]
    assert "overview" in moved and "head" in moved


def test_stills_are_deterministic():
    a = capture_stills("peeking_box", "reachy2", image_size=(32, 48), seed=3)
    b = capture_stills("peeking_box", "reachy2", image_size=(32, 48), seed=3)
    for view in SHEET_VIEWS:
        np.testing.assert_array_equal(a.grasp[view], b.grasp[view])


def test_overview_figure_holds_every_task_and_both_robots():
    rng = np.random.default_rng(0)

    def frames():
        return {view: rng.integers(0, 200, (60, 80, 3), dtype=np.uint8) for view in SHEET_VIEWS}

    stills = {task: Stills(task, "gr1t2", frames(), frames(), True) for task in BENCHMARK_TASKS}
    portraits = {"gr1t2": np.zeros((120, 90, 3), np.uint8), "reachy2": np.zeros((120, 90, 3), np.uint8)}
    figure = overview_figure(stills, portraits)
    assert figure.ndim == 3 and figure.dtype == np.uint8
    # the head suite's five columns of 80-px views (two rows) fit in the figure, beside the robots panel
    assert figure.shape[1] > 5 * 80 and figure.shape[0] > 4 * 60


def test_the_ood_visual_sheet_has_a_row_per_look_and_only_the_looks_differ():
    sheet = ood_visual_sheet("conditional_pick", "gr1t2", image_size=(48, 64), seed=2)
    rows = sheet.reshape(len(VISUAL_FACTORS) + 2, 48, len(OOD_VISUAL_VIEWS) * 64, 3)
    below_labels = rows[:, 12:]
    for row in below_labels[1:]:
        assert np.abs(row.astype(int) - below_labels[0]).mean() > 0.5  # every look differs from id
