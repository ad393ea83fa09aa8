"""Task classes by name (importing this loads MuJoCo; `catalog` has the metadata without it)."""

from lerobot_tavis.envs.tasks.base import Task
from lerobot_tavis.envs.tasks.catalog import task_info
from lerobot_tavis.envs.tasks.tabletop import Tabletop

TASK_CLASSES: dict[str, type[Task]] = {cls.info.name: cls for cls in (Tabletop,)}


def make_task(name: str, split: str = "id") -> Task:
    task_info(name)  # a clear error for unknown names
    return TASK_CLASSES[name](split)
