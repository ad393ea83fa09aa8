import av
import numpy as np
import pytest

from lerobot_tavis.demo import DemoConfig, run_demo
from lerobot_tavis.overlay import EVENT_COLOURS, PANEL_HEIGHT, band_height

pytestmark = pytest.mark.slow  # conftest.py: its file starts first


def test_demo_writes_an_annotated_video_per_task(tmp_path):
    """One task (every task is filmed by the same code): its video where its name says, the head view dark where
    the task blocks it, and SUCCESS in the band."""
    written = run_demo(DemoConfig(tmp_path, robots=("gr1t2",), tasks=("blocked_clutter_pick_cube",),
                                  image_size=(32, 48)))
    assert written == [tmp_path / "gr1t2" / "blocked_clutter_pick_cube.mp4"]
    with av.open(str(tmp_path / "gr1t2" / "blocked_clutter_pick_cube.mp4")) as video:
        frames = [f.to_ndarray(format="rgb24") for f in video.decode(video=0)]
    panel_h, panel_w = PANEL_HEIGHT, 2 * 540  # the 32x48 overview at 360x540, then the views at half size, 2 per row
    assert frames[0].shape == (panel_h + band_height(panel_w), panel_w, 3)
    head_cell = frames[-1][panel_h // 8:panel_h // 2, panel_w // 2:3 * panel_w // 4]  # below its label
    assert head_cell.max() < 40  # the blocked head view stays dark
    band = frames[-1][panel_h:]
    assert np.any(np.all(np.abs(band.astype(int) - EVENT_COLOURS["success"]) < 30, axis=-1))  # SUCCESS shown
    assert len(frames) > 40
    assert not list(tmp_path.rglob("*.partial*"))
