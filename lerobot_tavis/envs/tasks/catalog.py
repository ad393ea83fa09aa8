"""The task registry: each task's suite, prompts, success rule, splits, task class and demonstrator, readable
without MuJoCo.

`TASKS` below is the one place a task is declared, with the thresholds of its success rule as named constants
that the task class's `evaluate`, the rule's text here and docs/tasks.md all use. Its task class (one module each
next to this file) and its demonstrator (`lerobot_tavis.experts`) are named by import path and imported only when an
env or a demonstrator is built, so CLIs and configs validate names and expand suites without loading a simulator.
Tasks from outside the package join with `register_task` (docs/extending.md).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from lerobot_tavis import importpath
from lerobot_tavis.errors import FieldError, InputError

SPLITS = ("id", "ood_spatial", "ood_init_pose", "ood_visual")
# ood_visual (envs/visual_ood.py) changes only the look; `ood_visual:<factor>` applies one factor alone.
VISUAL_SPLIT = "ood_visual"
VISUAL_FACTORS = ("table", "floor", "backdrop", "lighting", "distractors")
PROTOCOL_SPLITS = ("id", "ood_spatial", "ood_init_pose")  # the reference's three, the default of `tavis eval`


def parse_split(split: str) -> tuple[str, tuple[str, ...]]:
    """`ood_visual` -> ("ood_visual", VISUAL_FACTORS); `ood_visual:lighting` -> ("ood_visual", ("lighting",));
    another split -> (split, ()). Raises ValueError for an unknown split or factor."""
    name, _, factor = split.partition(":")
    if name not in SPLITS:
        raise FieldError("split", f"must be one of {split_names()}, got {split!r}")
    if name != VISUAL_SPLIT:
        if factor:
            raise InputError(f"only {VISUAL_SPLIT} takes a factor (e.g. {VISUAL_SPLIT}:lighting), got {split!r}")
        return name, ()
    if not factor:
        return name, VISUAL_FACTORS
    if factor not in VISUAL_FACTORS:
        raise InputError(f"the factor of {VISUAL_SPLIT} must be one of {VISUAL_FACTORS}, got {factor!r}")
    return name, (factor,)


def split_names() -> tuple[str, ...]:
    """Every accepted split name: the splits, and `ood_visual:<factor>` per factor."""
    return (*SPLITS, *(f"{VISUAL_SPLIT}:{factor}" for factor in VISUAL_FACTORS))


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


LIFT_PROMPTS = {
    "soup_can": ("Pick up the tomato soup can and lift it.", "Grasp the soup can and hold it up.",
                 "Lift the red soup can off the table."),
    "meat_can": ("Pick up the potted meat can and lift it.", "Grasp the can of spam and hold it up.",
                 "Lift the meat can off the table."),
    "tuna_fish_can": ("Pick up the tuna fish can and lift it.", "Grasp the tuna can and hold it up.",
                      "Lift the tuna fish can off the table."),
    "gelatin_box": ("Pick up the gelatin box and lift it.", "Grasp the gelatin box and hold it up.",
                    "Lift the gelatin box off the table."),
    "pudding_box": ("Pick up the pudding box and lift it.", "Grasp the pudding box and hold it up.",
                    "Lift the pudding box off the table."),
}
SHELF_PROMPTS = {
    "soup_can": ("Find the tomato soup can on the shelf and bring it to me.",
                 "Retrieve the soup can from the shelves.",
                 "Look through the shelves, find the red soup can, and take it."),
    "meat_can": ("Find the potted meat can on the shelf and bring it to me.",
                 "Retrieve the spam can from the shelves.",
                 "Look through the shelves, find the meat can, and take it."),
    "tuna_fish_can": ("Find the tuna fish can on the shelf and bring it to me.",
                      "Retrieve the tuna can from the shelves.",
                      "Look through the shelves, find the tuna can, and take it."),
    "gelatin_box": ("Find the gelatin box on the shelf and bring it to me.",
                    "Retrieve the gelatin box from the shelves.",
                    "Look through the shelves, find the gelatin box, and take it."),
    "pudding_box": ("Find the pudding box on the shelf and bring it to me.",
                    "Retrieve the pudding box from the shelves.",
                    "Look through the shelves, find the pudding box, and take it."),
}
CUBE_PROMPT = "Find the red cube and pick it up."

# Success thresholds (world frame; docs/reference.md §4). The target's origin must be:
LIFT_HEIGHT_M = 1.2  # above this z: the Head tasks that lift, and blocked_clutter_pick_cube
HIGH_LIFT_HEIGHT_M = 1.25  # above this z: peeking_box and occluded_reach
SHELF_EXIT_X_M = 0.52 - 0.11 / 2 - 0.03  # 0.435, nearer than this x: the shelf's front edge (x 0.52, depth 0.11) - 3 cm
MAX_SUCCESS_SPEED_M_S = 1.0  # and slower than this (m/s), in every task
SPEED_RULE = f"moving slower than {MAX_SUCCESS_SPEED_M_S:g} m/s"
LIFT_RULE = "the {what}'s origin is above {z} m and " + SPEED_RULE

TASKS_PKG, HEAD_EXPERTS, HANDS_EXPERTS = ("lerobot_tavis.envs.tasks", "lerobot_tavis.experts.head_tasks",
                                          "lerobot_tavis.experts.hands_tasks")
# The registry, in catalog order (tables, datasets, plots follow it). `register_task` adds to it.
TASKS: dict[str, TaskInfo] = {
    info.name: info
    for info in (
        TaskInfo("conditional_pick", "tavis_head",
                 ("Look at the card. If it is red, pick the object on the left. If it is green, pick the object on "
                  "the right.",),
                 LIFT_RULE.format(what="target (left object if the card is red, right if green)", z=LIFT_HEIGHT_M),
                 task_class=f"{TASKS_PKG}.conditional_pick:ConditionalPick",
                 demonstrator=f"{HEAD_EXPERTS}:ConditionalPickExpert"),
        TaskInfo("wait_then_act", "tavis_head",
                 ("Watch the red light. When it turns green, pick up the object.",),
                 "once the light is green: " + LIFT_RULE.format(what="object", z=LIFT_HEIGHT_M),
                 task_class=f"{TASKS_PKG}.wait_then_act:WaitThenAct", demonstrator=f"{HEAD_EXPERTS}:WaitThenActExpert"),
        TaskInfo("clutter_pick_cube", "tavis_head", (CUBE_PROMPT,), LIFT_RULE.format(what="red cube", z=LIFT_HEIGHT_M),
                 task_class=f"{TASKS_PKG}.clutter_pick_cube:ClutterPickCube",
                 demonstrator=f"{HEAD_EXPERTS}:ClutterExpert"),
        TaskInfo("clutter_pick_lift", "tavis_head", tuple(p for ps in LIFT_PROMPTS.values() for p in ps),
                 LIFT_RULE.format(what="named object", z=LIFT_HEIGHT_M),
                 task_class=f"{TASKS_PKG}.clutter_pick_lift:ClutterPickLift",
                 demonstrator=f"{HEAD_EXPERTS}:ClutterExpert"),
        TaskInfo("multi_shelf_scan", "tavis_head", tuple(p for ps in SHELF_PROMPTS.values() for p in ps),
                 f"the named object's origin is closer than x = {SHELF_EXIT_X_M:.3f} m (out of the shelf) and "
                 + SPEED_RULE,
                 task_class=f"{TASKS_PKG}.multi_shelf_scan:MultiShelfScan", demonstrator=f"{HEAD_EXPERTS}:ShelfExpert"),
        TaskInfo("peeking_box", "tavis_hands", ("Retrieve the object from inside the box.",),
                 LIFT_RULE.format(what="object", z=HIGH_LIFT_HEIGHT_M),
                 task_class=f"{TASKS_PKG}.peeking_box:PeekingBox", demonstrator=f"{HANDS_EXPERTS}:PeekingBoxExpert"),
        TaskInfo("occluded_reach", "tavis_hands", ("Reach around the screen and pick up the object behind it.",),
                 LIFT_RULE.format(what="object", z=HIGH_LIFT_HEIGHT_M),
                 task_class=f"{TASKS_PKG}.occluded_reach:OccludedReach",
                 demonstrator=f"{HANDS_EXPERTS}:OccludedReachExpert"),
        TaskInfo("blocked_clutter_pick_cube", "tavis_hands", (CUBE_PROMPT,),
                 LIFT_RULE.format(what="red cube", z=LIFT_HEIGHT_M) + "; the head camera image is black",
                 task_class=f"{TASKS_PKG}.blocked_clutter_pick_cube:BlockedClutterPickCube",
                 demonstrator=f"{HANDS_EXPERTS}:BlockedClutterExpert"),
        TaskInfo("tabletop", "sandbox", ("Look at the objects on the table.",),
                 "never succeeds: a free scene (the five YCB objects on the table) for trying the robots",
                 splits=("id",), task_class=f"{TASKS_PKG}.tabletop:Tabletop"),
    )
}
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
