"""The task registry: every task's declaration (`TaskInfo`: suite, prompts, success rule, splits, task class and
demonstrator) by name, readable without MuJoCo, and the look-ups the CLIs, configs and env use.

A built-in task declares itself once, in its package `envs/tasks/<task>/` (`__init__.py`: its `INFO`, prompts and
success thresholds; `task.py`: the class simulating it); `BUILTIN_DECLARATIONS` below lists them in catalog order.
Task classes and demonstrators are named by import path and imported only when an env or a demonstrator is built,
so CLIs and configs validate names and expand suites without loading a simulator. Tasks from outside the package
join with `register_task` (docs/extending.md).
"""

from __future__ import annotations

import re

from lerobot_tavis import importpath
from lerobot_tavis.envs.tasks import (blocked_clutter_pick_cube, clutter_pick_cube, clutter_pick_lift,
                                      conditional_pick, multi_shelf_scan, occluded_reach, peeking_box, tabletop,
                                      wait_then_act)
from lerobot_tavis.envs.tasks.info import TaskInfo
# The splits a task may offer, named here as well for the registry's users (CLIs, configs, datasets, reports).
from lerobot_tavis.envs.tasks.splits import (PROTOCOL_SPLITS, SPLITS, VISUAL_FACTORS, VISUAL_SPLIT,
                                             parse_split, split_names)
from lerobot_tavis.errors import FieldError

# In catalog order: tables, datasets and plots follow it.
BUILTIN_DECLARATIONS = (conditional_pick, wait_then_act, clutter_pick_cube, clutter_pick_lift, multi_shelf_scan,
                        peeking_box, occluded_reach, blocked_clutter_pick_cube, tabletop)
# The registry, in catalog order; `register_task` adds to it.
TASKS: dict[str, TaskInfo] = {module.INFO.name: module.INFO for module in BUILTIN_DECLARATIONS}
SUITES = ("tavis_head", "tavis_hands")  # the benchmark's suites: closed, `register_task` adds to other suites


def suite_tasks(suite: str) -> tuple[str, ...]:
    """Task names of a suite, in catalog order."""
    names = tuple(name for name, info in TASKS.items() if info.suite == suite)
    if not names:
        suites = sorted({info.suite for info in TASKS.values()})
        raise FieldError("suite", f"must be one of {suites}, got {suite!r}")
    return names


BENCHMARK_TASKS = tuple(name for suite in SUITES for name in suite_tasks(suite))  # the eight TAVIS tasks
BUILTIN_TASKS = tuple(TASKS)  # the benchmark's and `tabletop`
NAME_PATTERN = re.compile(r"[a-z][a-z0-9_]*")


def suite_names() -> tuple[str, ...]:
    """Every suite with a task (the benchmark's, `sandbox` and registered ones), in catalog order."""
    return tuple(dict.fromkeys(info.suite for info in TASKS.values()))


def task_names(suite: str | None = None) -> tuple[str, ...]:
    """Every registered task name, or those of `suite`, in catalog order."""
    return tuple(TASKS) if suite is None else suite_tasks(suite)


def register_task(info: TaskInfo) -> TaskInfo:
    """Add a task from outside the package (docs/extending.md). Its suite must not be one of the benchmark's
    (`SUITES`: the eight TAVIS tasks are fixed); its splits must include `id`. Returns `info`."""
    if not (isinstance(info, TaskInfo) and NAME_PATTERN.fullmatch(info.name)):
        raise ValueError(f"task name must be lower_snake_case (a TaskInfo), got {getattr(info, 'name', info)!r}")
    if info.name in TASKS:
        raise ValueError(f"task {info.name!r} is already registered")
    if info.name in suite_names() or info.suite in TASKS:
        raise ValueError(f"task {info.name!r} of suite {info.suite!r}: a task and a suite may not share a name")
    if not NAME_PATTERN.fullmatch(info.suite) or info.suite in SUITES:
        raise ValueError(f"suite of task {info.name!r} must be lower_snake_case and none of the benchmark's "
                         f"{SUITES}, got {info.suite!r}")
    if not (isinstance(info.prompts, tuple) and info.prompts and all(isinstance(p, str) and p for p in info.prompts)):
        raise ValueError(f"prompts of task {info.name!r} must be a non-empty tuple of texts, got {info.prompts!r}")
    if "id" not in info.splits or not set(info.splits) <= set(SPLITS):
        raise ValueError(f"splits of task {info.name!r} must include 'id' and be among {SPLITS}, got {info.splits!r}")
    importpath.check("task_class", info.task_class)
    importpath.check("demonstrator", info.demonstrator, optional=True)
    TASKS[info.name] = info
    return info


def unregister_task(name: str) -> None:
    """Remove a task added by `register_task` (tests clean up with it); the built-in tasks stay."""
    if name in BUILTIN_TASKS:
        raise ValueError(f"task {name!r} is built in and cannot be unregistered")
    task_info(name)
    del TASKS[name]


def task_class(name: str) -> type:
    """The `Task` subclass of task `name` (importing it loads MuJoCo)."""
    return importpath.resolve(task_info(name).task_class)


def make_task(name: str, variant: str = "id"):
    """A new task `name` (an `envs.tasks.base.Task`; importing its class loads MuJoCo) with the variant (split)
    `variant`."""
    return task_class(name)(variant)


def demonstrator_class(name: str) -> type | None:
    """The scripted demonstrator (`Expert` subclass) of task `name`, or None if it has none."""
    demonstrator = task_info(name).demonstrator
    return None if demonstrator is None else importpath.resolve(demonstrator)


def task_sort_key(name: str) -> tuple[int, str]:
    """Sort key putting task names in catalog order (unknown names last, by name): tables, datasets, plots."""
    order = list(TASKS)
    return (order.index(name) if name in order else len(order), name)


def task_info(name: str, field: str = "task") -> TaskInfo:
    """The declaration of task `name`; an unknown name is a FieldError of `field`."""
    try:
        return TASKS[name]
    except KeyError:
        raise FieldError(field, f"must be one of {sorted(TASKS)}, got {name!r}") from None


def expand_tasks(spec: str, field: str = "task") -> dict[str, list[str]]:
    """`tavis_head`, `peeking_box` or `tavis_head,occluded_reach` -> {suite: [task, ...]}, in the given order; an
    unknown name is a FieldError of `field`."""
    groups: dict[str, list[str]] = {}
    for item in (part.strip() for part in spec.split(",")):
        names = suite_tasks(item) if item in suite_names() else (task_info(item, field).name,)
        for name in names:
            suite = task_info(name).suite
            if name not in groups.setdefault(suite, []):
                groups[suite].append(name)
    return groups
