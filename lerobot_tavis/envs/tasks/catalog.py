"""Task metadata: suite, prompts, success rule and splits, readable without MuJoCo.

The simulating task classes live in one module each next to this file; `TASKS` below is the single list of what
exists, so CLIs and configs can validate names and expand suites without building a simulator.
"""

from __future__ import annotations

from dataclasses import dataclass

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
    name: str
    suite: str
    prompts: tuple[str, ...]
    success_rule: str
    splits: tuple[str, ...] = SPLITS


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
LIFT_RULE = "the {what}'s origin is above {z} m and moving slower than 1 m/s"

TASKS: dict[str, TaskInfo] = {
    info.name: info
    for info in (
        TaskInfo("conditional_pick", "tavis_head",
                 ("Look at the card. If it is red, pick the object on the left. If it is green, pick the object on "
                  "the right.",),
                 LIFT_RULE.format(what="target (left object if the card is red, right if green)", z=1.2)),
        TaskInfo("wait_then_act", "tavis_head",
                 ("Watch the red light. When it turns green, pick up the object.",),
                 "once the light is green: " + LIFT_RULE.format(what="object", z=1.2)),
        TaskInfo("clutter_pick_cube", "tavis_head", (CUBE_PROMPT,), LIFT_RULE.format(what="red cube", z=1.2)),
        TaskInfo("clutter_pick_lift", "tavis_head", tuple(p for ps in LIFT_PROMPTS.values() for p in ps),
                 LIFT_RULE.format(what="named object", z=1.2)),
        TaskInfo("multi_shelf_scan", "tavis_head", tuple(p for ps in SHELF_PROMPTS.values() for p in ps),
                 "the named object's origin is closer than x = 0.435 m (out of the shelf) and moving slower than "
                 "1 m/s"),
        TaskInfo("peeking_box", "tavis_hands", ("Retrieve the object from inside the box.",),
                 LIFT_RULE.format(what="object", z=1.25)),
        TaskInfo("occluded_reach", "tavis_hands", ("Reach around the screen and pick up the object behind it.",),
                 LIFT_RULE.format(what="object", z=1.25)),
        TaskInfo("blocked_clutter_pick_cube", "tavis_hands", (CUBE_PROMPT,),
                 LIFT_RULE.format(what="red cube", z=1.2) + "; the head camera image is black"),
        TaskInfo("tabletop", "sandbox", ("Look at the objects on the table.",),
                 "never succeeds: a free scene (the five YCB objects on the table) for trying the robots",
                 splits=("id",)),
    )
}
SUITES = ("tavis_head", "tavis_hands")


def suite_tasks(suite: str) -> tuple[str, ...]:
    """Task names of a suite, in catalog order."""
    names = tuple(name for name, info in TASKS.items() if info.suite == suite)
    if not names:
        suites = sorted({info.suite for info in TASKS.values()})
        raise FieldError("suite", f"must be one of {suites}, got {suite!r}")
    return names


BENCHMARK_TASKS = tuple(name for suite in SUITES for name in suite_tasks(suite))  # the eight TAVIS tasks


def task_sort_key(name: str) -> tuple[int, str]:
    """Sort key putting task names in catalog order (unknown names last, by name): tables, datasets, plots."""
    order = list(TASKS)
    return (order.index(name) if name in order else len(order), name)


def task_info(name: str) -> TaskInfo:
    try:
        return TASKS[name]
    except KeyError:
        raise FieldError("task", f"must be one of {sorted(TASKS)}, got {name!r}") from None


def expand_tasks(spec: str) -> dict[str, list[str]]:
    """`tavis_head`, `peeking_box` or `tavis_head,occluded_reach` -> {suite: [task, ...]}, in the given order."""
    groups: dict[str, list[str]] = {}
    for item in (part.strip() for part in spec.split(",")):
        names = suite_tasks(item) if item in SUITES else (task_info(item).name,)
        for name in names:
            suite = task_info(name).suite
            if name not in groups.setdefault(suite, []):
                groups[suite].append(name)
    return groups
