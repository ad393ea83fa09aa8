"""`tavis view`: MuJoCo's interactive viewer on one episode, the demonstrator driving or the scene paused; and the
real-time window loop that `tavis teleop` shares.

Keys in the window: SPACE pauses and resumes, N starts the next seed, R restarts the episode; the mouse moves the
free camera; closing the window quits. The viewer needs a display: a desktop session, or a
virtual one (`xvfb-run -a tavis view ...`). The env runs at the 60 Hz control rate, one tick per frame.
"""

from __future__ import annotations

import os
import queue
import time
from dataclasses import dataclass

from lerobot_tavis.errors import TavisError

CONTROL_HZ = 60
DRIVERS = ("demonstrator", "paused")
KEY_SPACE, KEY_N, KEY_R = 32, 78, 82  # GLFW key codes (letters are their upper-case ASCII codes)


class NoDisplayError(TavisError):
    """The interactive viewer was asked for where no display exists."""


def require_display(command: str) -> None:
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        raise NoDisplayError(f"{command} opens a window and needs a display (DISPLAY is not set): run it in a "
                             f"desktop session, or under a virtual one with `xvfb-run -a {command} ...`")


class Window:
    """MuJoCo's passive viewer on a TavisEnv's model and data, paced at CONTROL_HZ; key presses (GLFW codes) queue
    up until `keys()` takes them. `camera` (a camera name of the env's world, e.g. "head") fixes the view to it;
    None leaves the free camera."""

    def __init__(self, env, camera: str | None = None):
        import mujoco
        import mujoco.viewer

        self._pressed: queue.SimpleQueue[int] = queue.SimpleQueue()
        self._handle = mujoco.viewer.launch_passive(env.model, env.data, key_callback=self._pressed.put,
                                                    show_left_ui=False, show_right_ui=False)
        if camera is not None:
            self._handle.cam.type = mujoco.mjtCamera.mjCAMERA_FIXED
            self._handle.cam.fixedcamid = env.world.cameras[camera]
        self._next_frame = time.perf_counter()

    def keys(self) -> list[int]:
        pressed = []
        while not self._pressed.empty():
            pressed.append(self._pressed.get())
        return pressed

    @property
    def running(self) -> bool:
        return self._handle.is_running()

    def show(self) -> None:
        """Draw the current state, then wait for the next 1/CONTROL_HZ s tick of wall time."""
        self._handle.sync()
        self._next_frame += 1.0 / CONTROL_HZ
        delay = self._next_frame - time.perf_counter()
        if delay > 0:
            time.sleep(delay)
        else:  # running late (a slow machine): do not try to catch up
            self._next_frame = time.perf_counter()

    def close(self) -> None:
        self._handle.close()


@dataclass(frozen=True)
class ViewConfig:
    task: str
    robot: str = "gr1t2"
    split: str = "id"
    seed: int = 1000
    driver: str = "demonstrator"
    camera: str | None = None  # None: the free camera
    max_frames: int | None = None  # stop after this many frames (tests, scripted demos); None: until closed


def view(cfg: ViewConfig) -> int:
    """Open the viewer and play episodes until the window closes; returns the number of frames shown."""
    require_display("tavis view")
    os.environ.setdefault("MUJOCO_GL", "egl")
    from lerobot_tavis.envs.env import TavisEnv
    from lerobot_tavis.experts.registry import make_expert

    if cfg.driver not in DRIVERS:
        raise ValueError(f"driver must be one of {DRIVERS}, got {cfg.driver!r}")
    env = TavisEnv(cfg.task, cfg.robot, split=cfg.split, fps=CONTROL_HZ, cameras=())
    seed, paused, frames = cfg.seed, cfg.driver == "paused", 0
    env.reset(seed=seed)
    expert = make_expert(env, seed)
    expert.reset()
    window = Window(env, cfg.camera)
    try:
        while window.running and (cfg.max_frames is None or frames < cfg.max_frames):
            restart = False
            for key in window.keys():
                if key == KEY_SPACE:
                    paused = not paused
                elif key in (KEY_N, KEY_R):
                    seed, restart = seed + (key == KEY_N), True
            if restart:
                env.reset(seed=seed)
                expert = make_expert(env, seed)
                expert.reset()
            elif not paused:
                _, _, terminated, truncated, _ = env.step(expert.act())
                if terminated or truncated:
                    paused = True  # hold the final state on screen; N or R goes on
            window.show()
            frames += 1
    finally:
        window.close()
        env.close()
    return frames
