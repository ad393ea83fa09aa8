"""Success across a training run's checkpoints: the `tavis eval` reports of `step_<N>/` folders under one directory
(as `benchmarks/train_baseline.sh` writes them, one per checkpoint) gathered into one table and one plot of success
rate, with its Wilson 95% interval, against the training step."""

from __future__ import annotations

import re
from pathlib import Path

from lerobot_tavis.atomic import write_text
from lerobot_tavis.errors import PathNotFoundError
from lerobot_tavis.eval.report import rate_text, save_figure
from lerobot_tavis.readers import expect, get, read_json

STEP_FOLDER = re.compile(r"step_(\d+)")
TABLE_NAME, PLOT_NAME = "checkpoints.md", "checkpoints.png"
# What the curve reads from every cell of a results.json (`eval.report`) and what each must be (`readers.KINDS`).
CELL_FIELDS = {"task": "str", "split": "str", "n": "int", "success_rate": "number", "ci_low": "number",
               "ci_high": "number"}


def read_results(path: Path) -> dict:
    """A `tavis report` results.json, checked for what the curve reads; an error names the file and the field."""
    report = read_json(path)
    expect(report, "object", path, "the report")
    for i, cell in enumerate(get(report, "cells", "list", path)):
        expect(cell, "object", path, f"cells[{i}]")
        for name, kind in CELL_FIELDS.items():
            get(cell, name, kind, path, f"cells[{i}].")
        get(cell, "galt_median_s", "number", path, f"cells[{i}].", optional=True)
    return report


def checkpoint_reports(root: Path) -> list[tuple[int, dict]]:
    """(training step, `results.json` report) of every finished evaluation `root/step_<N>/`, by step; folders still
    being evaluated (no results.json yet) are left out."""
    root = Path(root)
    if not root.is_dir():
        raise PathNotFoundError(f"{root}: no such directory")
    reports = []
    for folder in root.iterdir():
        match = STEP_FOLDER.fullmatch(folder.name)
        if match is None or not (folder / "results.json").is_file():
            continue
        reports.append((int(match[1]), read_results(folder / "results.json")))
    if not reports:
        raise PathNotFoundError(f"{root}: no step_<N>/results.json below it (one `tavis eval` output per checkpoint)")
    return sorted(reports, key=lambda item: item[0])


def curve_markdown(reports: list[tuple[int, dict]]) -> str:
    """One row per checkpoint and task x split: success with Wilson interval (n episodes), GALT median of the
    successes (s) where the task has one."""
    lines = ["# Success by training step", "", "Success rate with Wilson 95% interval (n episodes); GALT: median of "
             "the successful episodes' gaze-action lead time (s).", "",
             "| step | task | split | success | GALT median (s) |", "|---|---|---|---|---|"]
    for step, report in reports:
        for cell in report["cells"]:
            galt = cell.get("galt_median_s")
            lines.append(f"| {step} | {cell['task']} | {cell['split']} | {rate_text(cell)} | "
                         f"{'-' if galt is None else f'{galt:.2f}'} |")
    return "\n".join(lines) + "\n"


def plot_curve(reports: list[tuple[int, dict]], path: Path) -> Path:
    """Success rate (%) against training step, one line per task x split with its Wilson interval as a band."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    lines: dict[tuple[str, str], list[tuple[int, dict]]] = {}
    for step, report in reports:
        for cell in report["cells"]:
            lines.setdefault((cell["task"], cell["split"]), []).append((step, cell))
    fig, ax = plt.subplots(figsize=(6.0, 3.6))
    for (task, split), points in lines.items():
        steps = [step for step, _ in points]
        ax.plot(steps, [100 * c["success_rate"] for _, c in points], marker="o", label=f"{task} ({split})")
        ax.fill_between(steps, [100 * c["ci_low"] for _, c in points], [100 * c["ci_high"] for _, c in points],
                        alpha=0.2)
    ax.set_xlabel("training step")
    ax.set_ylabel("success rate (%), Wilson 95% CI")
    ax.set_ylim(0, 100)
    ax.legend()
    fig.tight_layout()
    written = save_figure(fig, path)
    plt.close(fig)
    return written


def write_curve(root: str | Path) -> list[Path]:
    """Write `checkpoints.md` and `checkpoints.png` into `root` from its `step_<N>/` evaluations; returns them."""
    root = Path(root)
    reports = checkpoint_reports(root)
    return [write_text(root / TABLE_NAME, curve_markdown(reports)), plot_curve(reports, root / PLOT_NAME)]
