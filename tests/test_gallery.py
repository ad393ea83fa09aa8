import numpy as np
import pytest

from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS, VISUAL_FACTORS
from lerobot_tavis.gallery import (OOD_VISUAL_VIEWS, SHEET_VIEWS, GalleryConfig, Stills, capture_stills,
                                   overview_figure, task_sheet, write_gallery)

pytestmark = pytest.mark.slow  # conftest.py: its file starts first


SIZE = (48, 64)


@pytest.fixture(scope="module")
def gallery(tmp_path_factory):
    """`tavis gallery` of conditional_pick on GR1T2 at SIZE: (its output directory, the files it wrote)."""
    out = tmp_path_factory.mktemp("gallery")
    return out, write_gallery(GalleryConfig(out, robots=("gr1t2",), tasks=("conditional_pick",), image_size=SIZE))


@pytest.fixture(scope="module")
def stills():
    """The gallery's stills of conditional_pick on GR1T2 (seed 0), captured again in this process."""
    return capture_stills("conditional_pick", "gr1t2", image_size=SIZE)


def _read_png(path) -> np.ndarray:
    import cv2

    return cv2.cvtColor(cv2.imread(str(path)), cv2.COLOR_BGR2RGB)


def test_task_sheet_shows_the_first_observation_and_the_grasp_the_same_every_time(gallery, stills):
    out, written = gallery
    assert [p.relative_to(out).as_posix() for p in written] == ["gallery/gr1t2/conditional_pick.png",
                                                                "gallery/gr1t2/ood_visual.png"]
    assert not (out / "overview.png").exists()  # the figure needs all eight tasks
    assert not list(out.rglob("*.partial*"))
    np.testing.assert_array_equal(_read_png(written[0]), task_sheet(stills))  # the same seed, the same pixels


def test_stills_change_between_first_observation_and_grasp(stills):
    assert stills.grasped
    assert set(stills.first) == set(stills.grasp) == set(SHEET_VIEWS)
    for view in SHEET_VIEWS:
        assert stills.first[view].shape == (*SIZE, 3)
    moved = [view for view in SHEET_VIEWS if np.abs(stills.first[view].astype(int) - stills.grasp[view]).mean() > 2]
    assert "overview" in moved and "head" in moved


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


def test_the_ood_visual_sheet_has_a_row_per_look_and_only_the_looks_differ(gallery):
    out, _ = gallery
    sheet = _read_png(out / "gallery" / "gr1t2" / "ood_visual.png")  # OOD_VISUAL_TASK, conditional_pick
    rows = sheet.reshape(len(VISUAL_FACTORS) + 2, SIZE[0], len(OOD_VISUAL_VIEWS) * SIZE[1], 3)
    below_labels = rows[:, 12:]
    for row in below_labels[1:]:
        assert np.abs(row.astype(int) - below_labels[0]).mean() > 0.5  # every look differs from id
