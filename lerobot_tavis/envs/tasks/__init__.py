"""Task classes by name. Metadata without MuJoCo: `lerobot_tavis.envs.tasks.catalog`."""

from lerobot_tavis.envs.tasks.base import Task
from lerobot_tavis.envs.tasks.catalog import task_info
from lerobot_tavis.envs.tasks.tabletop import Tabletop

TASK_CLASSES: dict[str, type[Task]] = {cls.info.name: cls for cls in (Tabletop,)}


def make_task(name: str, split: str = "id") -> Task:
    task_info(name)  # a clear error for unknown names
    return TASK_CLASSES[name](split)
