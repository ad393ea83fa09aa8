"""What declares a task, readable without MuJoCo: `TaskInfo`, and the success thresholds several tasks share.

Each built-in task declares itself in its package's `__init__.py` (`envs/tasks/<task>/`: its `INFO`, prompts and
thresholds) beside the class that simulates it (`<task>/task.py`); `catalog.py` collects the declarations. The
thresholds are named constants that the task's `evaluate`, its success-rule text and docs/tasks.md all use (a test
checks the docs' numbers against them).
"""

from __future__ import annotations

from dataclasses import dataclass

from lerobot_tavis.envs.tasks.splits import SPLITS

# Success thresholds shared by several tasks (world frame; docs/reference.md §4). The target's origin must be:
LIFT_HEIGHT_M = 1.2  # above this z: the Head tasks that lift, and blocked_clutter_pick_cube
HIGH_LIFT_HEIGHT_M = 1.25  # above this z: peeking_box and occluded_reach
MAX_SUCCESS_SPEED_M_S = 1.0  # and slower than this (m/s), in every task
SPEED_RULE = f"moving slower than {MAX_SUCCESS_SPEED_M_S:g} m/s"

HEAD_EXPERTS, HANDS_EXPERTS = "lerobot_tavis.experts.head_tasks", "lerobot_tavis.experts.hands_tasks"


def lift_rule(what: str, height_m: float) -> str:
    """The text of the lift rule for `what` (the target's description) and the threshold `height_m` (world z, m)."""
    return f"the {what}'s origin is above {height_m} m and {SPEED_RULE}"


@dataclass(frozen=True)
class TaskInfo:
    """One task. `task_class` (an `envs.tasks.base.Task` subclass) and `demonstrator` (an `experts.base.Expert`
    subclass; None: the task has none) are import paths "package.module:Class", imported on first use, or the
    classes themselves."""

    name: str
    suite: str
    prompts: tuple[str, ...]
    success_rule: str
    splits: tuple[str, ...] = SPLITS
    task_class: str | type = ""
    demonstrator: str | type | None = None
