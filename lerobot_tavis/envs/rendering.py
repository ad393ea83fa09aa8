"""Offscreen rendering of a camera subset with one MuJoCo renderer (one GL context per env).

Each image draws only the geoms that can show in it or shadow what does (`out_of_view`): MuJoCo draws every geom in
every pass, and with shadows each image takes three (the lit scene, the shadow map, the shadowed light), so a
camera that sees a part of the scene saves most of its cost. Besides what lies outside the view, what stands under
the table top where the top hides it is left out (`TableCover`): MuJoCo draws a covered geom in every pass too.
The pixels are those of drawing everything.
"""

from __future__ import annotations

import os
from contextlib import contextmanager
from dataclasses import dataclass

import mujoco
import numpy as np

from lerobot_tavis.envs import physics, scene
from lerobot_tavis.envs.modes import WRIST_CAMERAS
from lerobot_tavis.errors import TavisError


class NoOpenGLError(TavisError, RuntimeError):
    """MuJoCo could not create an OpenGL context: the machine's graphics setup, not a bug."""


class CameraRig:
    """Renders the named cameras of a model at one image size; `blacked_out` cameras yield black frames unrendered.
    Wrist cameras (model camera names ending in one of WRIST_CAMERAS) see nothing beyond physics.WRIST_FAR_CLIP_M:
    the model's fog (`physics.set_clip_planes`) paints it over."""

    def __init__(self, model: mujoco.MjModel, cameras: dict[str, int], image_size: tuple[int, int],
                 blacked_out: frozenset[str] = frozenset()):
        self.height, self.width = image_size
        self.cameras = cameras
        self.blacked_out = blacked_out
        self._model = model
        self._renderer = None
        self._table = TableCover.of(model)
        self._wrists = {camera for camera in range(model.ncam) if model.camera(camera).name.endswith(WRIST_CAMERAS)}
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
        wrist = camera_id in self._wrists
        unseen = out_of_view(self._model, data, camera_id, self.width / self.height,
                             far_m=physics.WRIST_FAR_CLIP_M if wrist else None, table=self._table)
        with _left_out(self._model, unseen):
            renderer.update_scene(data, camera=camera_id)
        renderer.scene.flags[mujoco.mjtRndFlag.mjRND_FOG] = wrist
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


def out_of_view(model: mujoco.MjModel, data: mujoco.MjData, camera_id: int, aspect: float,
                far_m: float | None = None, table: TableCover | None = None) -> np.ndarray:
    """(ngeom,) bool: the geoms that can neither appear in the image of camera `camera_id` (`aspect` = width /
    height) nor shadow anything that does, judged by their bounding spheres (`geom_rbound`). With `far_m`, what lies
    farther than `far_m` (m, along the view) counts as unseen too (a wrist camera's fog covers it).

    A shadow-casting geom is kept while the capsule swept by its sphere along a casting directional light, down to
    the floor (z = 0, below which nothing is drawn), reaches into the view: a shadow it casts falls within it.
    With `table`, the geoms under the table top that it hides and that cast no shadow count as unseen too.
    Planes (unbounded) are always kept; so is every geom when the camera is not a plain perspective one, or when a
    light that is not directional casts shadows. The near plane culls; MuJoCo's far plane does not.
    """
    none = np.zeros(model.ngeom, dtype=bool)
    casting = model.light_castshadow.astype(bool) & model.light_active.astype(bool)
    if (model.cam_projection[camera_id] != mujoco.mjtProjection.mjPROJ_PERSPECTIVE
            or model.cam_sensorsize[camera_id].any()
            or (model.light_type[casting] != mujoco.mjtLightType.mjLIGHT_DIRECTIONAL).any()):
        return none
    planes = _frustum_planes(model, data, camera_id, aspect, far_m)
    centres, radii = data.geom_xpos, model.geom_rbound
    outside = _outside(planes, centres, radii)
    hidden = outside.any(axis=1)
    casts = model.geom_castshadow.astype(bool)
    for direction in data.light_xdir[casting]:
        if direction[2] >= 0:  # lit from below the horizon: any geom might shadow the view
            return none
        reach = (np.maximum(centres[:, 2], 0.0) + radii) / -direction[2]
        swept_out = (outside & _outside(planes, centres + reach[:, None] * direction, radii)).any(axis=1)
        hidden &= ~casts | swept_out
    if table is not None:
        hidden |= table.hides(model, data, camera_id) & ~casts
    return hidden & (radii > 0)


@dataclass(frozen=True)
class TableCover:
    """The table's drawn top surface (`scene.TABLE_SURFACE`, an axis-aligned plane: `centre` (m, world) and
    `half` sizes (m) along x and y) and the table's geoms that stand wholly under it (legs, shelf, bins): `geoms`
    and the world corners of their bounding boxes, `corners` (n, 8, 3). The table is static, so this holds for the
    model's lifetime."""

    centre: np.ndarray
    half: np.ndarray
    geoms: np.ndarray
    corners: np.ndarray

    @classmethod
    def of(cls, model: mujoco.MjModel) -> TableCover | None:
        """The model's table cover; None when the model has no table."""
        surface = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, scene.TABLE_SURFACE)
        if surface < 0:
            return None
        data = mujoco.MjData(model)
        mujoco.mj_kinematics(model, data)
        centre, half = data.geom_xpos[surface].copy(), model.geom_size[surface][:2].copy()
        table = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, scene.TABLE_BODY)
        top = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name) for name in scene.TABLE_TOP_GEOMS]
        geoms = np.setdiff1d(np.flatnonzero(model.geom_bodyid == table), top)
        signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
        local = model.geom_aabb[geoms, None, :3] + signs * model.geom_aabb[geoms, None, 3:]  # in each geom's frame
        rotations = data.geom_xmat[geoms].reshape(-1, 3, 3)
        corners = data.geom_xpos[geoms, None, :] + local @ rotations.transpose(0, 2, 1)
        below = (corners[..., 2] < centre[2]).all(axis=1)
        return cls(centre, half, geoms[below], corners[below])

    def hides(self, model: mujoco.MjModel, data: mujoco.MjData, camera_id: int) -> np.ndarray:
        """(ngeom,) bool: the geoms under the top that it hides from camera `camera_id`: the camera is above the
        surface and every line of sight to the geom's bounding box crosses the surface beyond the near clip plane
        (the box's corners seen through the surface's plane all fall within the surface, which is convex)."""
        hidden = np.zeros(model.ngeom, dtype=bool)
        eye = data.cam_xpos[camera_id]
        if eye[2] <= self.centre[2]:
            return hidden
        drop = eye[2] - self.corners[..., 2:3]
        through = eye + (eye[2] - self.centre[2]) / drop * (self.corners - eye)  # on the surface's plane
        forward = -data.cam_xmat[camera_id].reshape(3, 3)[:, 2]
        within = (np.abs(through[..., :2] - self.centre[:2]) < self.half).all(axis=-1)
        beyond_near = (through - eye) @ forward > model.vis.map.znear * model.stat.extent
        hidden[self.geoms] = (within & beyond_near).all(axis=1)
        return hidden


def _frustum_planes(model: mujoco.MjModel, data: mujoco.MjData, camera_id: int, aspect: float,
                    far_m: float | None) -> np.ndarray:
    """(5 or 6, 4) planes (unit outward normal, offset) of the camera's view: left, right, bottom, top, near and,
    with `far_m`, far."""
    position = data.cam_xpos[camera_id]
    right, up, back = data.cam_xmat[camera_id].reshape(3, 3).T  # MuJoCo cameras look along their -z
    tan_y = np.tan(np.radians(model.cam_fovy[camera_id]) / 2)
    tan_x = tan_y * aspect
    normals = np.array([-right + tan_x * back, right + tan_x * back, -up + tan_y * back, up + tan_y * back, back])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    offsets = -normals @ position
    offsets[4] += model.vis.map.znear * model.stat.extent  # the near plane lies znear in front of the camera
    planes = np.column_stack([normals, offsets])
    if far_m is None:
        return planes
    return np.vstack([planes, [*-back, back @ position - far_m]])


def _outside(planes: np.ndarray, centres: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """(n, planes) bool: whether each sphere lies wholly outside each plane."""
    return centres @ planes[:, :3].T + planes[:, 3] > radii[:, None]


@contextmanager
def _left_out(model: mujoco.MjModel, geoms: np.ndarray):
    """While open, MuJoCo's scene update skips `geoms` ((ngeom,) bool): it leaves out geoms of alpha 0."""
    alpha = model.geom_rgba[geoms, 3].copy()
    model.geom_rgba[geoms, 3] = 0.0
    try:
        yield
    finally:
        model.geom_rgba[geoms, 3] = alpha
