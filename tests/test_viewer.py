"""`tavis view` opens MuJoCo's viewer on a virtual display (Xvfb) and plays the episode; without a display it
says how to get one. The window runs in a child process: GLFW keeps its X connection for the life of a process,
and the display must outlive it."""

import json
import os
import shutil
import subprocess
import sys
import time

import numpy as np
import pytest

from lerobot_tavis.viewer import NoDisplayError, ViewConfig, view

pytestmark = pytest.mark.slow  # conftest.py: its file starts first

PLAY = """
import json, time
from lerobot_tavis.viewer import ViewConfig, view

started = time.perf_counter()
frames = view(ViewConfig(task="conditional_pick", max_frames=30))
print(json.dumps({"frames": frames, "elapsed": time.perf_counter() - started}))
"""
FOLLOW = """
import json
from lerobot_tavis.envs.env import TavisEnv
from lerobot_tavis.viewer import Window

env = TavisEnv("conditional_pick", "gr1t2", fps=60, cameras=())
env.reset(seed=0)
window = Window(env, camera="head")
following = window._handle.cam.fixedcamid == env.world.cameras["head"]
window._pressed.put(32)  # what the viewer's key callback does on SPACE
keys = [window.keys(), window.keys()]
window.overlay(("W / S", "hand forward / back"), ("seed", "200000"))  # what teleop draws over the scene
window.show()
window.close()
print(json.dumps({"following": bool(following), "keys": keys}))
"""


def in_a_window(code: str, display: str) -> dict:
    """Run `code` in a child process on `display` (one window per process) and read the JSON it prints last."""
    env = {**os.environ, "DISPLAY": display, "MUJOCO_GL": "egl"}
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300)
    assert result.returncode == 0, result.stderr[-2000:]
    return json.loads(result.stdout.strip().splitlines()[-1])


@pytest.fixture
def virtual_display():
    if shutil.which("Xvfb") is None:
        pytest.skip("Xvfb is not installed (make setup installs it where apt-get can run)")
    display = f":{90 + os.getpid() % 900}"
    server = subprocess.Popen(["Xvfb", display, "-screen", "0", "1024x768x24", "-nolisten", "tcp"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(1.0)
    if server.poll() is not None:
        pytest.skip(f"Xvfb could not start on display {display}")
    yield display
    server.terminate()
    server.wait(timeout=10)


def test_the_viewer_plays_the_demonstrator_in_a_window(virtual_display):
    shown = in_a_window(PLAY, virtual_display)
    assert shown["frames"] == 30
    assert shown["elapsed"] >= 30 / 60  # paced at the 60 Hz control rate, not as fast as it can


def test_the_window_follows_a_camera_and_queues_key_presses(virtual_display):
    shown = in_a_window(FOLLOW, virtual_display)
    assert shown["following"] and shown["keys"] == [[32], []]


POLICY_IMAGE_SIZE = (48, 64)


@pytest.fixture(scope="module")
def act_checkpoint(tmp_path_factory):
    """A small ACT checkpoint (random weights; what it acts on, not how well, is tested here) that reads the head
    and wrist cameras at POLICY_IMAGE_SIZE, saved as lerobot-train saves one."""
    from lerobot.policies.act.configuration_act import ACTConfig
    from lerobot.policies.factory import make_policy, make_pre_post_processors

    from lerobot_tavis.eval.env_config import TavisEnvConfig

    path = tmp_path_factory.mktemp("view_policy") / "pretrained_model"
    config = ACTConfig(pretrained_backbone_weights=None, device="cpu", push_to_hub=False, dim_model=32,
                       dim_feedforward=64, n_heads=2, chunk_size=20, n_action_steps=10)
    policy = make_policy(config, env_cfg=TavisEnvConfig(camera_mode="head_wrist", image_size=POLICY_IMAGE_SIZE))
    policy.save_pretrained(path)
    for processor in make_pre_post_processors(config, dataset_stats=None):
        processor.save_pretrained(path)
    return path


def test_a_policy_checkpoint_drives_the_viewer(virtual_display, act_checkpoint):
    script = ("import json\nfrom lerobot_tavis.viewer import ViewConfig, view\n"
              f"frames = view(ViewConfig(task='conditional_pick', driver='policy', policy={str(act_checkpoint)!r}, "
              "max_frames=12))\nprint(json.dumps({'frames': frames}))")
    assert in_a_window(script, virtual_display) == {"frames": 12}


def test_a_policy_acts_on_the_env_observations(act_checkpoint):
    from lerobot_tavis.envs.env import TavisEnv
    from lerobot_tavis.viewer import PolicyDriver

    driver = PolicyDriver(act_checkpoint)
    env = TavisEnv("conditional_pick", "gr1t2", camera_mode="head_wrist", image_size=POLICY_IMAGE_SIZE)
    observation, _ = env.reset(seed=0)
    driver.reset()
    action = driver.act(observation, env.task_description)
    env.close()
    assert action.shape == (19,) and np.all(np.isfinite(action))
    with pytest.raises(FileNotFoundError, match="no config.json"):
        PolicyDriver(act_checkpoint.parent)


def test_policy_and_driver_go_together():
    with pytest.raises(ValueError, match="go together"):
        view(ViewConfig(task="conditional_pick", driver="policy"))


def test_without_a_display_view_says_how_to_get_one(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    with pytest.raises(NoDisplayError, match="xvfb-run -a tavis view"):
        view(ViewConfig(task="conditional_pick"))


def test_the_free_camera_starts_where_the_overview_camera_looks_from():
    """`tavis view` opens on the scene's overview (robot, table and objects), not on the robot's legs."""
    import mujoco

    from lerobot_tavis.envs.env import TavisEnv
    from lerobot_tavis.viewer import aim_like

    env = TavisEnv("conditional_pick", "gr1t2", fps=60, cameras=())
    env.reset(seed=0)
    overview = env.world.cameras["overview"]
    camera = mujoco.MjvCamera()
    aim_like(camera, env.data, overview)
    azimuth, elevation = np.radians(camera.azimuth), np.radians(camera.elevation)
    looking = np.array([np.cos(elevation) * np.cos(azimuth), np.cos(elevation) * np.sin(azimuth), np.sin(elevation)])
    eye = camera.lookat - camera.distance * looking  # where MuJoCo puts a free camera
    np.testing.assert_allclose(eye, env.data.cam_xpos[overview], atol=1e-9)
    np.testing.assert_allclose(looking, -env.data.cam_xmat[overview].reshape(3, 3)[:, 2], atol=1e-9)
    assert camera.lookat[2] == pytest.approx(1.0) and camera.elevation < 0  # aimed down at the table top
    env.close()
