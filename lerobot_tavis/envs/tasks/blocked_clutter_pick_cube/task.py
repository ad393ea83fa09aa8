"""blocked_clutter_pick_cube in MuJoCo: clutter_pick_cube's scene; the head camera renders black."""

from __future__ import annotations

from lerobot_tavis.envs.tasks.blocked_clutter_pick_cube import INFO
from lerobot_tavis.envs.tasks.clutter_pick_cube.task import ClutterPickCube


class BlockedClutterPickCube(ClutterPickCube):
    info = INFO
    blacked_out_cameras = frozenset({"head"})
