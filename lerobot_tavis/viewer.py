"""`tavis view`: MuJoCo's interactive viewer on one episode, driven by the demonstrator or a policy checkpoint, or
paused; and the real-time window loop that `tavis teleop` shares.

Keys in the window: SPACE pauses and resumes, N starts the next seed, R restarts the episode; the mouse moves the
free camera, which starts where the scene's overview camera looks from (robot, table and objects in view);
closing the window quits. The viewer needs a display: a desktop session, or a virtual one
(`xvfb-run -a tavis view ...`). With the demonstrator the env runs at the 60 Hz control rate, one tick per frame;
with a policy at its 20 Hz step rate, the camera mode and image size it was trained with, one step per frame.
"""

from __future__ import annotations

import os
import queue
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lerobot_tavis import checks
from lerobot_tavis.cli_options import option
from lerobot_tavis.envs.checkpoint_settings import pretrained_model_dir, read_checkpoint_settings
from lerobot_tavis.envs.modes import CAMERA_NAMES, OVERVIEW_CAMERA, VIEW_CAMERAS
from lerobot_tavis.envs.physics import CONTROL_HZ, POLICY_HZ
from lerobot_tavis.envs.robots import DEFAULT_ROBOT, robot_names
from lerobot_tavis.envs.scene import TABLE_TOP_Z
from lerobot_tavis.envs.tasks.catalog import split_names, task_names
from lerobot_tavis.errors import FieldError, InputError, TavisError
from lerobot_tavis.policies import register_policy_types

DRIVERS = ("demonstrator", "policy", "paused")
FREE_CAMERA = "free"  # the window's camera moved with the mouse
WINDOW_CAMERAS = (*CAMERA_NAMES, *VIEW_CAMERAS, FREE_CAMERA)  # what a window may look through
# GLFW key codes, as the viewer's key callback passes them (letters and digits are their ASCII codes)
KEY_SPACE, KEY_ENTER, KEY_TAB, KEY_BACKSPACE = 32, 257, 258, 259
KEY_RIGHT, KEY_LEFT, KEY_DOWN, KEY_UP = 262, 263, 264, 265
KEY_N, KEY_R = ord("N"), ord("R")
CLOSE_TIMEOUT_S = 5.0


class NoDisplayError(TavisError):
    """The interactive viewer was asked for where no display exists."""


def require_display(command: str) -> None:
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        raise NoDisplayError(f"{command} opens a window and needs a display (DISPLAY is not set): run it in a "
                             f"desktop session, or under a virtual one with `xvfb-run -a {command} ...`")


class Window:
    """MuJoCo's passive viewer on a TavisEnv's model and data, paced at CONTROL_HZ; key presses (GLFW codes) queue
    up until `keys()` takes them. `camera` (a camera name of the env's world, e.g. "head") fixes the view to it;
    FREE_CAMERA leaves the free camera. `rate_hz`: frames per second of wall time."""

    def __init__(self, env, camera: str = FREE_CAMERA, rate_hz: float = CONTROL_HZ):
        import mujoco
        import mujoco.viewer

        self._pressed: queue.SimpleQueue[int] = queue.SimpleQueue()
        before = set(threading.enumerate())
        self._handle = mujoco.viewer.launch_passive(env.model, env.data, key_callback=self._pressed.put,
                                                    show_left_ui=False, show_right_ui=False)
        self._ui_threads = set(threading.enumerate()) - before  # the viewer's own, which draws the window
        if camera != FREE_CAMERA:
            self._handle.cam.type = mujoco.mjtCamera.mjCAMERA_FIXED
            self._handle.cam.fixedcamid = env.world.cameras[camera]
        else:
            with self._handle.lock():
                aim_like(self._handle.cam, env.data, env.world.cameras[OVERVIEW_CAMERA])
        self._period_s = 1.0 / rate_hz
        self._next_frame = time.perf_counter()

    def overlay(self, top_left: tuple[str, str], bottom_left: tuple[str, str]) -> None:
        """Text drawn over the scene from the next frame on: two boxes of two columns each (lines split by "\\n")."""
        import mujoco

        self._handle.set_texts([
            (mujoco.mjtFontScale.mjFONTSCALE_150, mujoco.mjtGridPos.mjGRID_TOPLEFT, *top_left),
            (mujoco.mjtFontScale.mjFONTSCALE_150, mujoco.mjtGridPos.mjGRID_BOTTOMLEFT, *bottom_left)])

    def keys(self) -> list[int]:
        pressed = []
        while not self._pressed.empty():
            pressed.append(self._pressed.get())
        return pressed

    @property
    def running(self) -> bool:
        return self._handle.is_running()

    def show(self) -> None:
        """Draw the current state, then wait for the next frame's time."""
        self._handle.sync()
        self._next_frame += self._period_s
        delay = self._next_frame - time.perf_counter()
        if delay > 0:
            time.sleep(delay)
        else:  # running late (a slow machine): do not try to catch up
            self._next_frame = time.perf_counter()

    def close(self) -> None:
        """Close the window and wait (up to CLOSE_TIMEOUT_S) for the viewer's thread to finish: a process that exits
        while that thread still tears the window down crashes in GLFW's exit handler."""
        self._handle.close()
        for thread in self._ui_threads:
            thread.join(timeout=CLOSE_TIMEOUT_S)


def aim_like(free_camera, data, camera_id: int, look_at_z_m: float = TABLE_TOP_Z) -> None:
    """Place MuJoCo's free camera (an `mjvCamera`) where camera `camera_id` of `data` is, looking the same way: its
    orbit centre is where that camera's line of sight meets the height `look_at_z_m` (world frame, m; the table top
    by default), or 1 m ahead when it looks up."""
    position = data.cam_xpos[camera_id]
    forward = -data.cam_xmat[camera_id].reshape(3, 3)[:, 2]  # a camera looks along its -z axis
    distance = (look_at_z_m - position[2]) / forward[2] if forward[2] < 0 else 1.0
    free_camera.lookat[:] = position + distance * forward
    free_camera.distance = distance
    free_camera.azimuth = np.degrees(np.arctan2(forward[1], forward[0]))
    free_camera.elevation = np.degrees(np.arcsin(np.clip(forward[2], -1.0, 1.0)))


class PolicyDriver:
    """A LeRobot checkpoint acting on one env's observations the way lerobot-eval runs it: LeRobot's observation
    conversion, the checkpoint's pre- and post-processors, `select_action` with its action queue."""

    def __init__(self, policy_path: str | Path, device: str = "cpu"):
        from lerobot.configs.policies import PreTrainedConfig
        from lerobot.policies.factory import get_policy_class, make_pre_post_processors

        register_policy_types()

        path = pretrained_model_dir(policy_path)
        config = PreTrainedConfig.from_pretrained(path)
        config.device = device
        self.policy = get_policy_class(config.type).from_pretrained(path, config=config).to(device).eval()
        self.preprocessor, self.postprocessor = make_pre_post_processors(
            config, pretrained_path=str(path), preprocessor_overrides={"device_processor": {"device": device}})

    def reset(self) -> None:
        self.policy.reset()

    def act(self, observation: dict, prompt: str) -> np.ndarray:
        import torch
        from lerobot.envs.utils import preprocess_observation

        batch = preprocess_observation({"pixels": {name: image[None] for name, image in observation["pixels"].items()},
                                        "agent_pos": observation["agent_pos"][None]})
        batch["task"] = [prompt]
        with torch.inference_mode():
            action = self.postprocessor(self.policy.select_action(self.preprocessor(batch)))
        return action[0].float().cpu().numpy()


@dataclass(frozen=True)
class ViewConfig:
    """The episode `tavis view` shows and who drives it; also its command-line options. `driver` None: the policy
    when `policy` is given, else the demonstrator."""

    task: str = option(choices=task_names)
    robot: str | None = option(None, f"default: the checkpoint's, else {DEFAULT_ROBOT}", choices=robot_names)
    split: str = option("id", choices=split_names)
    seed: int = 1000
    driver: str | None = option(None, "who acts (default: the policy when --policy is given, else the demonstrator)",
                                choices=DRIVERS)
    policy: str | None = option(None, "a checkpoint's pretrained_model folder; its camera mode and image size apply "
                                "(default: none)")
    device: str = option("cpu", "the policy's device (default cpu)")
    camera: str = option(FREE_CAMERA, "the window's camera (default: the free camera, moved with the mouse, starting "
                         "from the overview camera's viewpoint)", choices=WINDOW_CAMERAS)
    # stop after this many frames (tests, scripted demos); None: until the window closes
    max_frames: int | None = option(None, command_line=False)

    def __post_init__(self):
        checks.integer("seed", self.seed, 0)
        if self.driver is None:
            object.__setattr__(self, "driver", "policy" if self.policy else "demonstrator")


def view(cfg: ViewConfig) -> int:
    """Open the viewer and play episodes until the window closes; returns the number of frames shown."""
    if cfg.driver not in DRIVERS:
        raise FieldError("driver", f"must be one of {DRIVERS}, got {cfg.driver!r}")
    if (cfg.driver == "policy") != (cfg.policy is not None):
        raise InputError("--policy and --driver policy go together")
    require_display("tavis view")
    os.environ.setdefault("MUJOCO_GL", "egl")
    from lerobot_tavis.envs.env import TavisEnv
    from lerobot_tavis.experts.rollout import make_expert

    if cfg.policy is not None:
        settings = read_checkpoint_settings(pretrained_model_dir(cfg.policy)).known()
        driver, fps = PolicyDriver(cfg.policy, cfg.device), POLICY_HZ
        env = TavisEnv(cfg.task, cfg.robot or settings.get("robot", "gr1t2"), split=cfg.split, fps=fps,
                       camera_mode=settings.get("camera_mode", "head_wrist"),
                       image_size=settings.get("image_size", (480, 640)))
    else:
        driver, fps = None, CONTROL_HZ
        env = TavisEnv(cfg.task, cfg.robot or "gr1t2", split=cfg.split, fps=fps, cameras=())
    seed, paused, frames = cfg.seed, cfg.driver == "paused", 0

    def start():
        observation, _ = env.reset(seed=seed)
        if driver is not None:
            driver.reset()
            return observation, None
        expert = make_expert(env, seed)
        expert.reset()
        return observation, expert

    observation, expert = start()
    window = Window(env, cfg.camera, rate_hz=fps)
    try:
        while window.running and (cfg.max_frames is None or frames < cfg.max_frames):
            restart = False
            for key in window.keys():
                if key == KEY_SPACE:
                    paused = not paused
                elif key in (KEY_N, KEY_R):
                    seed, restart = seed + (key == KEY_N), True
            if restart:
                observation, expert = start()
            elif not paused:
                action = driver.act(observation, env.task_description) if driver else expert.act()
                observation, _, terminated, truncated, _ = env.step(action)
                if terminated or truncated:
                    paused = True  # hold the final state on screen; N or R goes on
            window.show()
            frames += 1
    finally:
        window.close()
        env.close()
    return frames
