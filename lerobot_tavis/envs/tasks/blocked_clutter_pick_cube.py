"""TAVIS-Hands blocked_clutter_pick_cube: clutter_pick_cube with a black head camera (the head still moves)."""

from __future__ import annotations

from lerobot_tavis.envs.tasks.catalog import TASKS
from lerobot_tavis.envs.tasks.clutter_pick_cube import ClutterPickCube


class BlockedClutterPickCube(ClutterPickCube):
    info = TASKS["blocked_clutter_pick_cube"]
    blacked_out_cameras = frozenset({"head"})
