"""Offscreen rendering of a camera subset with one MuJoCo renderer (one GL context per env)."""

from __future__ import annotations

import os

import mujoco
import numpy as np

from lerobot_tavis.errors import TavisError


class NoOpenGLError(TavisError, RuntimeError):
    """MuJoCo could not create an OpenGL context: the machine's graphics setup, not a bug."""


class CameraRig:
    """Renders the named cameras of a model at one image size; `blacked_out` cameras yield black frames unrendered."""

    def __init__(self, model: mujoco.MjModel, cameras: dict[str, int], image_size: tuple[int, int],
                 blacked_out: frozenset[str] = frozenset()):
        self.height, self.width = image_size
        self.cameras = cameras
        self.blacked_out = blacked_out
        self._model = model
        self._renderer = None
        if set(cameras) - set(blacked_out):
            self._ensure_renderer()  # else nothing to draw: no GL context until `render_camera` needs one

    def render(self, data: mujoco.MjData) -> dict[str, np.ndarray]:
        """One fresh (H, W, 3) uint8 image per camera."""
        frames = {}
        for name, camera_id in self.cameras.items():
            if name in self.blacked_out:
                frames[name] = np.zeros((self.height, self.width, 3), dtype=np.uint8)
                continue
            frames[name] = self.render_camera(data, camera_id)
        return frames

    def render_camera(self, data: mujoco.MjData, camera_id: int) -> np.ndarray:
        """One (H, W, 3) uint8 image from any camera of the model, e.g. one outside the rig for a video."""
        renderer = self._ensure_renderer()
        renderer.update_scene(data, camera=camera_id)
        return renderer.render()

    def _ensure_renderer(self) -> mujoco.Renderer:
        if self._renderer is None:
            try:
                self._renderer = mujoco.Renderer(self._model, height=self.height, width=self.width,
                                                 max_geom=2 * self._model.ngeom + 100)
            except mujoco.FatalError as error:
                raise NoOpenGLError(
                    f"MuJoCo could not create an OpenGL context ({error}). MuJoCo picks its backend when it is "
                    "first imported: set MUJOCO_GL=egl (or osmesa) in the environment, or import "
                    f"lerobot_tavis.envs before mujoco. MUJOCO_GL is {os.environ.get('MUJOCO_GL')!r} now."
                ) from error
        return self._renderer

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
