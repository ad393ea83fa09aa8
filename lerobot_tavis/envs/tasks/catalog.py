"""Task metadata: suite, prompts, success rule and splits, readable without MuJoCo.

The simulating task classes live in one module each next to this file; `TASKS` below is the single list of what
exists, so CLIs and configs can validate names and expand suites without building a simulator.
"""

from __future__ import annotations

from dataclasses import dataclass

SPLITS = ("id", "ood_spatial", "ood_init_pose")


@dataclass(frozen=True)
class TaskInfo:
    name: str
    suite: str
    prompts: tuple[str, ...]
    success_rule: str
    splits: tuple[str, ...] = SPLITS


TASKS: dict[str, TaskInfo] = {
    info.name: info
    for info in (
        TaskInfo(
            name="tabletop",
            suite="sandbox",
            prompts=("Look at the objects on the table.",),
            success_rule="never succeeds: a free scene (the five YCB objects on the table) for trying the robots",
            splits=("id",),
        ),
    )
}


def suite_tasks(suite: str) -> tuple[str, ...]:
    """Task names of a suite, in catalog order."""
    names = tuple(name for name, info in TASKS.items() if info.suite == suite)
    if not names:
        suites = sorted({info.suite for info in TASKS.values()})
        raise ValueError(f"suite must be one of {suites}, got {suite!r}")
    return names


def task_info(name: str) -> TaskInfo:
    try:
        return TASKS[name]
    except KeyError:
        raise ValueError(f"task must be one of {sorted(TASKS)}, got {name!r}") from None
