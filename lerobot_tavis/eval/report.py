"""`tavis report <dir>`: success rates with Wilson 95% intervals and the episode metrics, per task x split.

Every `eval_info.json` under the directory (LeRobot's result of one lerobot-eval run) is joined with the
`episodes.jsonl` next to it (`eval.outputs.join`: exactly the episodes LeRobot scored). Every metric of
`lerobot_tavis.metrics.logged_metrics` (GALT, the wrist lead) is summarised per cell from its `<name>_s` and
`<name>_reason` fields, in registry order, and the failed episodes logged with `reach` are counted by how far they
got (`lerobot_tavis.envs.reach.failure_stage`). Writes `results.json`, `results.md`, `success_rates.png` and
`<metric>_<task>.png` (metrics with a histogram, e.g. `galt_<task>.png`) into the directory, and beside each
evaluation's videos a copy with the episode's GALT events drawn on (`videos_annotated/`).
"""

from __future__ import annotations

import json
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from lerobot_tavis.atomic import atomic_path, write_text
from lerobot_tavis.envs.reach import FAILURE_STAGES, HELD_BACK_M, MOVED_M, REACHED_M, failure_stage, held_back
from lerobot_tavis.envs.tasks.catalog import SPLITS, task_sort_key
from lerobot_tavis.errors import InputError
from lerobot_tavis.eval.episode_log import EPISODE_LOG_NAME
from lerobot_tavis.eval.outputs import eval_dirs, join
from lerobot_tavis.eval.run_identity import EPISODE_FIELDS, RUN_FIELD, differences
from lerobot_tavis.metrics.logged_metrics import episode_metrics
from lerobot_tavis.metrics.stats import wilson_interval

DELTA_SPLITS = ("ood_spatial", "ood_visual")  # the report gives id minus each, per task


@dataclass
class LeadTimes:
    """One cell's values of one metric (s, valid episodes only) and how often its detector gave each reason."""

    values_s: list[float] = field(default_factory=list)
    reasons: dict[str, int] = field(default_factory=dict)

    def add(self, value_s: float | None, reason: str | None) -> None:
        if reason:
            self.reasons[reason] = self.reasons.get(reason, 0) + 1
        if value_s is not None:
            self.values_s.append(float(value_s))

    def summary(self, prefix: str) -> dict:
        values = np.array(self.values_s)
        quartiles = np.percentile(values, [25, 50, 75]) if len(values) else [None] * 3
        return {f"{prefix}_n_valid": len(values), f"{prefix}_median_s": _float(quartiles[1]),
                f"{prefix}_q1_s": _float(quartiles[0]), f"{prefix}_q3_s": _float(quartiles[2]),
                f"{prefix}_reasons": dict(sorted(self.reasons.items())), f"{prefix}_values_s": list(self.values_s)}


def _float(value) -> float | None:
    return None if value is None else float(value)


@dataclass
class Cell:
    """One task x split: its episodes' successes and the values of every episode metric, by metric name."""

    task: str
    suite: str
    split: str
    successes: list[bool] = field(default_factory=list)
    metrics: dict[str, LeadTimes] = field(default_factory=lambda: {m.name: LeadTimes() for m in episode_metrics()})
    unstable: int = 0  # episodes ended by a simulator instability (counted as failures)
    failure_stages: Counter = field(default_factory=Counter)  # failed episodes with a `reach`, by stage
    not_reached_held_back: list[bool] = field(default_factory=list)  # per not-reached failure logged with a gap
    first_grasps_xy_m: dict[str, list[float]] = field(default_factory=lambda: {"failure": [], "success": []})

    def add(self, record: dict) -> None:
        """One scored episode record of the episode log."""
        self.successes.append(bool(record["success"]))
        for metric in episode_metrics():
            self.metrics[metric.name].add(record.get(metric.value_field), record.get(metric.reason_field))
        self.unstable += bool(record.get("instability"))
        reach = record.get("reach")
        if reach and not record["success"]:
            stage = failure_stage(reach)
            self.failure_stages[stage] += 1
            held = held_back(reach)
            if stage == "not_reached" and held is not None:
                self.not_reached_held_back.append(held)
        if reach and reach.get("first_grasp_xy_m") is not None:
            self.first_grasps_xy_m["success" if record["success"] else "failure"].append(reach["first_grasp_xy_m"])

    def summary(self) -> dict:
        k, n = sum(self.successes), len(self.successes)
        low, high = wilson_interval(k, n)
        return {
            "task": self.task, "suite": self.suite, "split": self.split, "n": n, "successes": k,
            "success_rate": k / n if n else 0.0, "ci_low": low, "ci_high": high, "unstable": self.unstable,
            "failure_stages": {stage: self.failure_stages[stage] for stage in FAILURE_STAGES} if self.failure_stages
            else {},
            "not_reached_held_back": sum(self.not_reached_held_back) if self.not_reached_held_back else None,
            **{f"first_grasp_xy_median_m_{outcome}": float(np.median(values)) if values else None
               for outcome, values in self.first_grasps_xy_m.items()},
            **{key: value for name, times in self.metrics.items() for key, value in times.summary(name).items()},
        }


def collect(root: Path) -> tuple[dict[tuple[str, str], Cell], list[dict]]:
    cells: dict[tuple[str, str], Cell] = {}
    firsts: dict[tuple[str, str], tuple[dict, Path]] = {}  # per cell: its first record and that record's source
    sources = []
    for eval_dir in eval_dirs(root):
        episodes, meta = join(eval_dir)
        sources.append(meta)
        for record in episodes:
            key = (record["task"], record["split"])
            cell = cells.setdefault(key, Cell(record["task"], record["suite"], record["split"]))
            _check_same_run(key, *firsts.setdefault(key, (record, eval_dir)), record, eval_dir)
            cell.add(record)
            meta.setdefault("robots", set()).add(record["robot"])
            meta.setdefault("camera_modes", set()).add(record["camera_mode"])
    for meta in sources:
        meta["robots"], meta["camera_modes"] = sorted(meta.get("robots", ())), sorted(meta.get("camera_modes", ()))
    return cells, sources


def _check_same_run(cell: tuple[str, str], first: dict, first_source: Path, record: dict, source: Path) -> None:
    """InputError naming the cell and the field when `record` was played otherwise than the cell's `first` record:
    another robot or camera mode, or a run identity differing in a field that decides how episodes play
    (`run_identity.EPISODE_FIELDS`: runs of other seeds pool). Records from before run identities have none and
    are compared by robot and camera mode alone; they do not pool with records that have one."""
    fields = [name for name in ("robot", "camera_mode") if record[name] != first[name]]
    runs = first.get(RUN_FIELD), record.get(RUN_FIELD)
    if not isinstance(runs[1], dict | None):
        raise InputError(f"{source / EPISODE_LOG_NAME}: a record of {cell[0]} {cell[1]} (seed {record['seed']}) has a "
                         f"{RUN_FIELD!r} that is not a run identity (a JSON object)")
    if not fields and (runs[0] is None) != (runs[1] is None):
        fields = [RUN_FIELD]
    elif not fields and runs[0] is not None:
        fields = [f"{RUN_FIELD}.{name}" for name in differences(*runs, EPISODE_FIELDS)]
    if fields:
        def value(which: dict) -> str:
            return json.dumps(_dotted(which, fields[0]))

        place = f"in {source}" if source == first_source else f"in {first_source} and {source}"
        raise InputError(f"{cell[0]} {cell[1]}: its episodes disagree on {fields[0]} ({value(first)} and "
                         f"{value(record)}, {place}): they come from different runs")


def _dotted(record: dict, name: str):
    """record["a"]["b"] for name "a.b" (None where a level is missing)."""
    for part in name.split("."):
        record = record.get(part) if isinstance(record, dict) else None
    return record


def _order(cells) -> tuple[list[str], list[str]]:
    tasks = sorted({task for task, _ in cells}, key=task_sort_key)
    splits = sorted({split for _, split in cells}, key=lambda s: (SPLITS.index(s) if s in SPLITS else 9, s))
    return tasks, splits


def build_report(root: Path) -> dict:
    cells, sources = collect(root)
    tasks, splits = _order(cells)
    average = {}
    for split in splits:
        pooled = [s for (task, sp), cell in cells.items() if sp == split for s in cell.successes]
        low, high = wilson_interval(sum(pooled), len(pooled))
        average[split] = {"n": len(pooled), "successes": sum(pooled), "success_rate": sum(pooled) / len(pooled),
                          "ci_low": low, "ci_high": high}
    deltas = {f"id_minus_{split}": {task: cells[(task, "id")].summary()["success_rate"]
                                    - cells[(task, split)].summary()["success_rate"]
                                    for task in tasks if (task, "id") in cells and (task, split) in cells}
              for split in DELTA_SPLITS}
    return {"cells": [cells[(t, s)].summary() for t in tasks for s in splits if (t, s) in cells],
            "average": average, **deltas, "sources": sources}


def rate_text(summary: dict) -> str:
    """A cell's (or pooled average's) success rate, Wilson interval and episode count as the tables print them:
    ` 50.0% [40.2,  59.8] (96)`."""
    rate, low, high = summary["success_rate"], summary["ci_low"], summary["ci_high"]
    return f"{100 * rate:5.1f}% [{100 * low:4.1f}, {100 * high:5.1f}] ({summary['n']})"


def markdown(report: dict) -> str:
    cells = {(c["task"], c["split"]): c for c in report["cells"]}
    tasks, splits = _order(cells)
    deltas = [split for split in DELTA_SPLITS if report.get(f"id_minus_{split}")]
    robots = sorted({r for s in report["sources"] for r in s["robots"]})
    modes = sorted({m for s in report["sources"] for m in s["camera_modes"]})
    lines = [f"# TAVIS results: {', '.join(robots)}, {', '.join(modes)}", "",
             "Success rate with Wilson 95% interval (n episodes).", "",
             "| task | " + " | ".join([*splits, *(f"id - {split}" for split in deltas)]) + " |",
             "|---|" + "---|" * (len(splits) + len(deltas))]
    for task in tasks:
        row = [rate_text(c) if (c := cells.get((task, s))) else "" for s in splits]
        for split in deltas:
            delta = report[f"id_minus_{split}"].get(task)
            row.append(f"{100 * delta:+.1f} pp" if delta is not None else "")
        lines.append(f"| {task} | " + " | ".join(row) + " |")
    avg = [rate_text(report["average"][s]) for s in splits]
    lines += ["| **AVERAGE** (pooled) | " + " | ".join(avg + [""] * len(deltas)) + " |"]
    for metric in episode_metrics():
        lines += _lead_table(cells, tasks, splits, metric.name, metric.caption)
    lines += _failure_table(cells, tasks, splits)
    unstable = [f"{c['task']} {c['split']}: {c['unstable']} of {c['n']}" for c in report["cells"] if c["unstable"]]
    if unstable:
        lines += ["", "Episodes ended by a simulator instability (counted as failures; the episode log names the "
                  "warning): " + "; ".join(unstable) + "."]
    return "\n".join(lines) + "\n"


def _lead_table(cells: dict, tasks: list[str], splits: list[str], prefix: str, caption: str) -> list[str]:
    """Median, IQR, n valid and reason counts (s) of the metric named `prefix` per task x split."""
    rows = []
    for task, split in ((t, s) for t in tasks for s in splits):
        cell = cells.get((task, split))
        if cell is None or not cell[f"{prefix}_reasons"]:
            continue
        median, q1, q3 = (cell[f"{prefix}_{key}_s"] for key in ("median", "q1", "q3"))
        reasons = ", ".join(f"{k} {v}" for k, v in cell[f"{prefix}_reasons"].items())
        rows.append(f"| {task} | {split} | {_seconds(median)} | {_seconds(q1)} - {_seconds(q3)} "
                    f"| {cell[f'{prefix}_n_valid']} | {reasons} |")
    if not rows:
        return []
    return ["", caption, "", "| task | split | median | IQR | n valid | reasons |", "|---|---|---|---|---|---|", *rows]


def _failure_table(cells: dict, tasks: list[str], splits: list[str]) -> list[str]:
    """Failed episodes per task x split by how far they got toward the target (episodes logged with `reach`)."""
    rows = []
    for task, split in ((t, s) for t in tasks for s in splits):
        cell = cells.get((task, split)) or {}
        stages = cell.get("failure_stages")
        if stages:
            counts = " | ".join(str(stages[stage]) for stage in FAILURE_STAGES)
            held = cell.get("not_reached_held_back")
            offsets = " / ".join(_millimetres(cell.get(f"first_grasp_xy_median_m_{outcome}"))
                                 for outcome in ("failure", "success"))
            rows.append(f"| {task} | {split} | {sum(stages.values())} | {counts} | {'-' if held is None else held} "
                        f"| {offsets} |")
    if not rows:
        return []
    caption = (f"Failed episodes by how far they got: a hand within {100 * REACHED_M:.0f} cm of another object's "
               "centre, never of the target's (episodes logged before this was measured count as not reached); "
               f"no hand within {100 * REACHED_M:.0f} cm of either; a hand at the target but the target moved less "
               f"than {100 * MOVED_M:.0f} cm; the target moved, no success. Then how many not-reached episodes ended "
               f"with a hand over {100 * HELD_BACK_M:.0f} cm from its commanded position (held back by an object or "
               "its reach; the others stopped short where commanded; - for logs without it), and the median "
               "horizontal distance from the target's centre at which the first grasp of it closed, in failed and "
               "in successful episodes.")
    header = ("| task | split | failed | reached another object | not reached | reached, not moved | moved, no success "
              "| not reached, held back | first grasp off centre (mm), failed / succeeded |")
    return ["", caption, "", header, "|---|---|---|---|---|---|---|---|---|", *rows]


def _millimetres(value_m: float | None) -> str:
    return "-" if value_m is None else f"{1000 * value_m:.0f}"


def _seconds(value: float | None) -> str:
    return "-" if value is None else f"{value:.2f}"


def plot(report: dict, out_dir: Path) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cells = {(c["task"], c["split"]): c for c in report["cells"]}
    tasks, splits = _order(cells)
    written = []
    fig, ax = plt.subplots(figsize=(max(6.0, 1.3 * len(tasks) * max(1, len(splits)) / 2), 4.0))
    width = 0.8 / len(splits)
    for i, split in enumerate(splits):
        xs, rates, errors = [], [], [[], []]
        for j, task in enumerate(tasks):
            if (c := cells.get((task, split))) is None:
                continue
            xs.append(j + (i - (len(splits) - 1) / 2) * width)
            rates.append(100 * c["success_rate"])
            errors[0].append(100 * (c["success_rate"] - c["ci_low"]))
            errors[1].append(100 * (c["ci_high"] - c["success_rate"]))
        ax.bar(xs, rates, width, yerr=errors, capsize=3, label=split)
    ax.set_xticks(range(len(tasks)), tasks, rotation=30, ha="right")
    ax.set_ylabel("success rate (%), Wilson 95% CI")
    ax.set_ylim(0, 105)
    ax.legend()
    fig.tight_layout()
    written.append(save_figure(fig, out_dir / "success_rates.png"))
    for metric in (m for m in episode_metrics() if m.histogram is not None):
        for task in tasks:
            values = {s: c[f"{metric.name}_values_s"] for s in splits if (c := cells.get((task, s))) is not None}
            if not any(values.values()):
                continue
            fig, ax = plt.subplots(figsize=(5.0, 3.2))
            ax.hist(list(values.values()), bins=metric.histogram.bins(), label=list(values), stacked=True)
            ax.set_xlabel(metric.histogram.xlabel)
            ax.set_ylabel("episodes")
            ax.set_title(task)
            ax.legend()
            fig.tight_layout()
            written.append(save_figure(fig, out_dir / f"{metric.name}_{task}.png"))
            plt.close("all")
    return written


def save_figure(fig, path: Path) -> Path:
    """Write `fig` to `path` as a 120-dpi PNG, complete or not at all."""
    with atomic_path(path, suffix=".png") as partial:  # matplotlib picks the format from the extension
        fig.savefig(partial, dpi=120)
    return path


def write_report(root: str | Path, workers: int | None = None) -> list[Path]:
    """Build the report of every evaluation under `root` and write it there, with an annotated copy of each
    episode video (`lerobot_tavis.eval.annotate`, `workers` processes: default every core this process may use);
    returns the written files."""
    from lerobot_tavis.eval.annotate import annotate_videos
    from lerobot_tavis.workers import usable_cores

    root = Path(root)
    report = build_report(root)
    # The videos first: a damaged one stops the report before any of its files is written.
    annotated = annotate_videos(eval_dirs(root), usable_cores() if workers is None else workers)
    written = plot(report, root)
    written.append(write_text(root / "results.json", json.dumps(report, indent=2) + "\n"))
    written.append(write_text(root / "results.md", markdown(report)))
    return written + annotated
