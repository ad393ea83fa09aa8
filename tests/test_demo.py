import av

from lerobot_tavis.demo import run_demo


def test_demo_writes_a_side_by_side_video_per_task(tmp_path):
    written = run_demo(tmp_path, robots=("gr1t2",), tasks=("wait_then_act", "blocked_clutter_pick_cube"),
                       image_size=(32, 48))
    assert [p.name for p in written] == ["wait_then_act.mp4", "blocked_clutter_pick_cube.mp4"]
    with av.open(str(tmp_path / "gr1t2" / "blocked_clutter_pick_cube.mp4")) as video:
        frames = [f.to_ndarray(format="rgb24") for f in video.decode(video=0)]
    assert frames[0].shape == (32, 4 * 48, 3)  # head, fixed, left and right wrist views in one row
    assert frames[-1][12:, :40].max() < 40  # the blocked head view stays dark (its label is above row 12)
    assert len(frames) > 40
    assert not list(tmp_path.rglob("*.partial*"))
