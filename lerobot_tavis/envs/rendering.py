"""Offscreen rendering of a camera subset with one MuJoCo renderer (one GL context per env)."""

from __future__ import annotations

import os

import mujoco
import numpy as np


class CameraRig:
    """Renders the named cameras of a model at one image size; `blacked_out` cameras yield black frames unrendered."""

    def __init__(self, model: mujoco.MjModel, cameras: dict[str, int], image_size: tuple[int, int],
                 blacked_out: frozenset[str] = frozenset()):
        self.height, self.width = image_size
        self.cameras = cameras
        self.blacked_out = blacked_out
        self._renderer = None
        if not set(cameras) - set(blacked_out):
            return  # nothing to draw: no GL context needed
        try:
            self._renderer = mujoco.Renderer(model, height=self.height, width=self.width)
        except mujoco.FatalError as error:
            raise RuntimeError(
                f"MuJoCo could not create an OpenGL context ({error}). MuJoCo picks its backend when it is first "
                "imported: set MUJOCO_GL=egl (or osmesa) in the environment, or import lerobot_tavis.envs before "
                f"mujoco. MUJOCO_GL is {os.environ.get('MUJOCO_GL')!r} now."
            ) from error

    def render(self, data: mujoco.MjData) -> dict[str, np.ndarray]:
        """One fresh (H, W, 3) uint8 image per camera."""
        frames = {}
        for name, camera_id in self.cameras.items():
            if name in self.blacked_out:
                frames[name] = np.zeros((self.height, self.width, 3), dtype=np.uint8)
                continue
            self._renderer.update_scene(data, camera=camera_id)
            frames[name] = self._renderer.render()
        return frames

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
