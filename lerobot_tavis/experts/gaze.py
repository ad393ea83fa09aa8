"""Where to point the head: neck angles that centre a world point in the head camera.

Uses the simulator's own kinematics on a scratch copy of the state (privileged, like a person's sense of where
their eyes are), so it is exact for both robots whatever their neck geometry.
"""

from __future__ import annotations

import mujoco
import numpy as np

from lerobot_tavis.envs.world import World


class GazeSolver:
    def __init__(self, world: World):
        self.world = world
        self._data = mujoco.MjData(world.model)
        self._camera = world.cameras["head"]
        self._limits = world.robot.neck_range_rad()

    def angles_to(self, target, iterations: int = 6) -> tuple[float, float]:
        """(pitch, yaw) in rad, with roll 0, that put `target` (world, m) on the head camera's optical axis,
        clipped to the neck's range."""
        pitch = yaw = 0.0
        target = np.asarray(target, dtype=float)
        for _ in range(iterations):
            self._data.qpos[self.world.neck_qpos] = (0.0, pitch, yaw)
            mujoco.mj_kinematics(self.world.model, self._data)
            mujoco.mj_comPos(self.world.model, self._data)
            mujoco.mj_camlight(self.world.model, self._data)  # camera poses are not part of mj_kinematics
            rotation = self._data.cam_xmat[self._camera].reshape(3, 3)  # columns: right, up, backward
            local = rotation.T @ (target - self._data.cam_xpos[self._camera])
            yaw += np.arctan2(-local[0], -local[2])
            pitch -= np.arctan2(local[1], -local[2])
            pitch = float(np.clip(pitch, *self._limits[1]))
            yaw = float(np.clip(yaw, *self._limits[2]))
        return pitch, yaw
