"""Task classes by name (importing this loads MuJoCo; `catalog` has the metadata without it)."""

from lerobot_tavis.envs.tasks.base import Task
from lerobot_tavis.envs.tasks.blocked_clutter_pick_cube import BlockedClutterPickCube
from lerobot_tavis.envs.tasks.catalog import task_info
from lerobot_tavis.envs.tasks.clutter_pick_cube import ClutterPickCube
from lerobot_tavis.envs.tasks.clutter_pick_lift import ClutterPickLift
from lerobot_tavis.envs.tasks.conditional_pick import ConditionalPick
from lerobot_tavis.envs.tasks.multi_shelf_scan import MultiShelfScan
from lerobot_tavis.envs.tasks.occluded_reach import OccludedReach
from lerobot_tavis.envs.tasks.peeking_box import PeekingBox
from lerobot_tavis.envs.tasks.tabletop import Tabletop
from lerobot_tavis.envs.tasks.wait_then_act import WaitThenAct

TASK_CLASSES: dict[str, type[Task]] = {
    cls.info.name: cls
    for cls in (ConditionalPick, WaitThenAct, ClutterPickCube, ClutterPickLift, MultiShelfScan, PeekingBox,
                OccludedReach, BlockedClutterPickCube, Tabletop)
}


def make_task(name: str, variant: str = "id") -> Task:
    task_info(name)  # a clear error for unknown names
    return TASK_CLASSES[name](variant)
