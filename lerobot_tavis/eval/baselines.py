"""The baselines table's index, `docs/results/baselines.json`: which evaluation is the table's cell.

The file is a JSON list of entries, one per (robot, task, camera_mode), each
`{"robot", "task", "camera_mode", "policy", "training_seed", "results"}`: `policy` names the recipe (the preset the
policy was trained with), `training_seed` lerobot-train's seed, and `results` the path, relative to the repository
root, of the `results.json` that `tavis eval` / `tavis report` wrote for that policy. That file must have been played
by that robot in that camera mode (its `sources` say so) and hold the task's `id` cell. `tavis table-add` adds or
replaces one entry (`add_entry`: checked, under a lock, written whole); `tavis table` (under the same lock, so that
cells finishing together write their tables in turn) and `tavis ablation` read them.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from pathlib import Path

from lerobot_tavis.atomic import write_text
from lerobot_tavis.cli_options import option
from lerobot_tavis.envs.robots import robot_names
from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS, task_sort_key
from lerobot_tavis.errors import InputError, PathNotFoundError
from lerobot_tavis.locking import exclusive_output
from lerobot_tavis.readers import expect, read_json

BASELINES_PATH = Path("docs/results/baselines.json")  # relative to the repository root
CONDITIONS = ("head_wrist", "fixed_wrist")  # the paper's two conditions: its headcam and fixedcam
# Another process holds the file's lock for milliseconds (an entry) or a few seconds (a table and its plot): wait
# up to a minute (s) for it.
TURN_WAIT_S = 60.0


@dataclass(frozen=True)
class Entry:
    """One cell of the table: the evaluation of the policy trained for (robot, task, camera_mode)."""

    robot: str
    task: str
    camera_mode: str
    policy: str  # the recipe: the preset the policy was trained with
    training_seed: int  # lerobot-train's --seed
    results: str  # path of the evaluation's results.json, relative to the repository root

    @property
    def key(self) -> tuple[str, str, str]:
        return self.robot, self.task, self.camera_mode


ENTRY_KINDS = {"robot": "str", "task": "str", "camera_mode": "str", "policy": "str", "training_seed": "int",
               "results": "str"}


def entry_from_json(value, where: str) -> Entry:
    """An entry parsed from its JSON object; InputError naming `where` and the field at fault."""
    if not isinstance(value, dict):
        raise InputError(f"{where}: must be an object with {', '.join(ENTRY_KINDS)}, got {type(value).__name__}")
    if sorted(value) != sorted(ENTRY_KINDS):
        missing, extra = sorted(set(ENTRY_KINDS) - set(value)), sorted(set(value) - set(ENTRY_KINDS))
        raise InputError(f"{where}: must have exactly the fields {', '.join(ENTRY_KINDS)}"
                         + (f"; missing {', '.join(missing)}" if missing else "")
                         + (f"; unknown {', '.join(extra)}" if extra else ""))
    for name, kind in ENTRY_KINDS.items():
        expect(value[name], kind, where, name)
    return Entry(**value)


def check_entry(entry: Entry, root: Path, where: str) -> dict:
    """The entry's results.json, parsed, after checking the entry against it and the catalog: a known robot, task
    and condition, a relative path that exists under `root`, a results file played by that robot in that camera
    mode holding the task's id cell. InputError (PathNotFoundError for a missing file) naming `where`."""
    for name, allowed in (("robot", robot_names()), ("task", BENCHMARK_TASKS), ("camera_mode", CONDITIONS)):
        if getattr(entry, name) not in allowed:
            raise InputError(f"{where}: {name} must be one of {', '.join(allowed)}, got {getattr(entry, name)!r}")
    if Path(entry.results).is_absolute() or ".." in Path(entry.results).parts:
        raise InputError(f"{where}: results must be a path inside the repository, relative to its root, got "
                         f"{entry.results!r}")
    path = root / entry.results
    if not path.is_file():
        raise PathNotFoundError(f"{where}: results {entry.results} is not a file under {root.absolute()}")
    report = read_json(path)
    sources = report.get("sources") if isinstance(report, dict) else None
    if not (isinstance(sources, list) and sources and isinstance(report.get("cells"), list)):
        raise InputError(f"{where}: {entry.results} is not a `tavis eval` / `tavis report` results.json (it needs "
                         "cells and sources)")
    for field, wanted in (("robots", entry.robot), ("camera_modes", entry.camera_mode)):
        played = sorted({value for source in sources for value in source.get(field) or ()})
        if played != [wanted]:
            raise InputError(f"{where}: {entry.results} was played with {field} {played}, the entry says {wanted!r}")
    if not any(cell.get("task") == entry.task and cell.get("split") == "id" for cell in report["cells"]):
        raise InputError(f"{where}: {entry.results} holds no id cell of {entry.task}")
    return report


def read_entries(path: str | Path, root: str | Path = ".") -> list[Entry]:
    """The entries of a baselines.json, each checked (`check_entry`, paths relative to `root`) and no two of one
    (robot, task, camera_mode)."""
    path = Path(path)
    entries = _parsed_entries(path)
    for index, entry in enumerate(entries):
        check_entry(entry, Path(root), f"{path}: entry {index}")
    return entries


def _parsed_entries(path: Path) -> list[Entry]:
    """The entries of a baselines.json as written, no two of one (robot, task, camera_mode); their results files
    are not read."""
    document = read_json(path)
    if not isinstance(document, list):
        raise InputError(f"{path}: must be a list of entries, got {type(document).__name__}")
    entries, seen = [], {}
    for index, value in enumerate(document):
        entry = entry_from_json(value, f"{path}: entry {index}")
        if entry.key in seen:
            raise InputError(f"{path}: entry {index}: {' '.join(entry.key)} is entry {seen[entry.key]} already; one "
                             "entry per robot, task and camera mode")
        seen[entry.key] = index
        entries.append(entry)
    return entries


def read_results(entry: Entry, root: str | Path = ".") -> dict:
    """The parsed results.json of an entry read by `read_entries`."""
    return read_json(Path(root) / entry.results)


def add_entry(path: str | Path, entry: Entry, root: str | Path = ".") -> Path:
    """Add `entry` to the baselines.json at `path` (made if missing), replacing the one of the same robot, task and
    camera mode, after checking it (the others are kept as they are: a cell being made again may have lost its
    folder); the file is rewritten whole, in table order, one writer at a time."""
    path = Path(path)
    check_entry(entry, Path(root), "the new entry")
    with baselines_turn(path):
        entries = _parsed_entries(path) if path.exists() else []
        kept = [old for old in entries if old.key != entry.key] + [entry]
        kept.sort(key=lambda e: (e.robot, task_sort_key(e.task), CONDITIONS.index(e.camera_mode)))
        return write_text(path, json.dumps([asdict(e) for e in kept], indent=2) + "\n")


def baselines_turn(path: str | Path):
    """The lock of the baselines file at `path`, waited for up to TURN_WAIT_S while another process holds it: cells
    that finish together add their entries and rewrite the table one after the other."""
    return exclusive_output(path, wait_s=TURN_WAIT_S)


@dataclass(frozen=True, kw_only=True)
class TableAddConfig:
    """`tavis table-add`: one entry of the table, added or replaced."""

    robot: str = option(help="the robot the policy was trained and evaluated on", choices=robot_names)
    task: str = option(help="the task of the single-task policy", choices=BENCHMARK_TASKS)
    camera_mode: str = option(help="the paper's condition the policy was trained in", choices=CONDITIONS)
    policy: str = option(help="the recipe: the preset the policy was trained with")
    training_seed: int = option(help="lerobot-train's --seed")
    results: Path = option(help="the evaluation's results.json (`tavis eval` / `tavis report`), relative to --root")
    baselines: Path = option(BASELINES_PATH, "the baselines file, made if missing")
    root: Path = option(Path("."), "the repository root, which results paths are relative to (default: the current "
                        "directory)")


def run_table_add(cfg: TableAddConfig) -> list[str]:
    entry = Entry(cfg.robot, cfg.task, cfg.camera_mode, cfg.policy, cfg.training_seed, cfg.results.as_posix())
    path = add_entry(cfg.baselines, entry, cfg.root)
    return [f"{path}: {' '.join(entry.key)} -> {entry.results}"]
