"""What an evaluation wrote, read back: lerobot-eval's `eval_info.json` joined with the episode log beside it.

Per (suite, task_id), a log record belongs to episode `seed - start_seed` (the start seed is the smallest logged seed)
and only episodes below LeRobot's `n_episodes` count, exactly the episodes LeRobot scored. `tavis report`, `tavis
compare` and the video annotation read evaluations through `join`; each record is checked for the fields they read,
and a bad one is an InputError naming the file, the line and the field.
"""

from __future__ import annotations

from pathlib import Path

from lerobot_tavis.errors import InputError, PathNotFoundError
from lerobot_tavis.eval.episode_log import EPISODE_LOG_NAME
from lerobot_tavis.eval.run_identity import RUN_FIELD
from lerobot_tavis.readers import expect, get, read_json, read_json_lines

EVAL_INFO_NAME = "eval_info.json"

# What the report reads from every episode record and what each must be (`readers.KINDS`); the log writes more.
RECORD_FIELDS = {"robot": "str", "suite": "str", "task": "str", "task_id": "int", "split": "str",
                 "camera_mode": "str", "seed": "int", "success": "bool"}
# Fields the report and the video annotation read where present, null allowed; besides them, every `<name>_s` field
# (metric times, seconds) must be a number and every `<name>_reason` a text.
OPTIONAL_RECORD_FIELDS = {"length_steps": "int", "prompt": "str", "instability": "str", "reach": "object"}
# The `reach` fields the report reads (metres): always there, and there or null in older logs.
REACH_FIELDS, OPTIONAL_REACH_FIELDS = ("closest_hand_m", "target_moved_m"), ("closest_hand_other_m",
                                                                             "first_grasp_xy_m", "command_gap_m")


def read_episode_log(path: Path) -> list[dict]:
    """The records of an episode log (`eval.episode_log`), each checked for the fields the report reads; an error
    names the file, the line and the field."""
    records = []
    for number, record in read_json_lines(path):
        where = f"{path}:{number}"
        if not isinstance(record, dict):
            raise InputError(f"{where}: not an episode record (a JSON object), got {type(record).__name__}")
        missing = [name for name in RECORD_FIELDS if name not in record]
        if missing:
            raise InputError(f"{where}: not an episode record (missing {', '.join(missing)})")
        for name, kind in RECORD_FIELDS.items():
            expect(record[name], kind, where, name)
        for name, value in record.items():
            kind = OPTIONAL_RECORD_FIELDS.get(name) or ("number" if name.endswith("_s") else
                                                        "str" if name.endswith("_reason") else None)
            if kind:
                expect(value, kind, where, name, optional=True)
        if record.get("reach"):
            for name in (*REACH_FIELDS, *OPTIONAL_REACH_FIELDS):
                get(record["reach"], name, "number", where, "reach.", optional=name in OPTIONAL_REACH_FIELDS)
        records.append(record)
    return records


def read_eval_info(path: Path) -> dict:
    """A lerobot-eval `eval_info.json`; InputError naming the file when it is not JSON or lacks what is read."""
    info = read_json(path)
    try:
        usable = all(isinstance(task["task_group"], str) and isinstance(task["task_id"], int)
                     and isinstance(task["metrics"]["successes"], list) for task in info["per_task"])
    except (KeyError, TypeError):
        usable = False
    if not usable:
        raise InputError(f"{path}: not a lerobot-eval {EVAL_INFO_NAME} (it needs per_task entries with task_group, "
                         "task_id and metrics.successes)")
    return info


def join(eval_dir: Path) -> tuple[list[dict], dict]:
    """The scored episodes of one lerobot-eval output directory (log records with `episode_ix`), and its meta."""
    info = read_eval_info(eval_dir / EVAL_INFO_NAME)
    log_path = eval_dir / EPISODE_LOG_NAME
    if not log_path.exists():
        raise PathNotFoundError(f"{log_path} is missing: run the evaluation with the tavis env's episode log")
    by_task: dict[tuple[str, int], list[dict]] = {}
    for record in read_episode_log(log_path):
        by_task.setdefault((record["suite"], record["task_id"]), []).append(record)
    episodes, mismatches = [], 0
    for task in info["per_task"]:
        key = (task["task_group"], task["task_id"])
        scored = task["metrics"]["successes"]
        records = by_task.get(key, [])
        if not records:
            raise InputError(f"{log_path} has no episode of {key[0]} task {key[1]}")
        start = min(r["seed"] for r in records)
        latest = {r["seed"] - start: r for r in records}  # a repeated seed: the last record wins
        for ix, success in enumerate(scored):
            if ix not in latest:
                raise InputError(f"{log_path}: episode {ix} of {key[0]} task {key[1]} (seed {start + ix}) "
                                 "was scored by LeRobot but not logged")
            record = {**latest[ix], "episode_ix": ix}
            mismatches += bool(record["success"]) != bool(success)
            episodes.append(record)
    run = {RUN_FIELD: info[RUN_FIELD]} if RUN_FIELD in info else {}  # absent from results before run identities
    return episodes, {"source": str(eval_dir), "success_mismatches": mismatches, **run}


def eval_dirs(root: Path) -> list[Path]:
    """Every lerobot-eval output directory under `root` (those holding an eval_info.json)."""
    # Dot-named folders are staging copies (finished or left by a killed run), never results.
    info_files = sorted(path for path in root.rglob(EVAL_INFO_NAME)
                        if not any(part.startswith(".") for part in path.relative_to(root).parts))
    if not info_files:
        raise PathNotFoundError(f"no {EVAL_INFO_NAME} under {root}")
    return [path.parent for path in info_files]
