import av
import cv2
import numpy as np

from lerobot_tavis.demo import FPS, look_and_reach_script, run_demo
from lerobot_tavis.envs.env import TavisEnv


def test_demo_writes_one_video_per_camera_and_a_sheet(tmp_path):
    written = run_demo(tmp_path, robots=("reachy2",), image_size=(48, 64))
    names = sorted(p.name for p in written)
    assert names == ["cameras.png", "fixed.mp4", "head.mp4", "left_wrist.mp4", "right_wrist.mp4"]
    with av.open(str(tmp_path / "reachy2" / "head.mp4")) as video:
        frames = [f.to_ndarray(format="rgb24") for f in video.decode(video=0)]
    env = TavisEnv("tabletop", "reachy2", image_size=(48, 64))
    env.reset(seed=0)
    script, _ = look_and_reach_script(env, "soup_can")
    env.close()
    assert len(frames) == int(np.ceil(script.duration_s * FPS)) and frames[0].shape == (48, 64, 3)
    assert cv2.imread(str(tmp_path / "reachy2" / "cameras.png")).shape == (96, 128, 3)
    assert not list(tmp_path.rglob("*.partial*"))
