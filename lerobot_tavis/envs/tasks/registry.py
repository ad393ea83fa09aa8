"""Tasks built by name (importing this loads MuJoCo; `catalog`, the registry, declares every task without it)."""

from lerobot_tavis.envs.tasks.base import Task
from lerobot_tavis.envs.tasks.catalog import task_class


def make_task(name: str, variant: str = "id") -> Task:
    """A new task `name` (its class from the catalog) with the variant (split) `variant`."""
    return task_class(name)(variant)
