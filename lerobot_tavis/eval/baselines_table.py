"""`tavis table` and `tavis ablation`: the baselines table, laid out as the TAVIS paper lays out its results, and the
wrist-only ablation of its TAVIS-Hands study, both read from `docs/results/baselines.json` (`eval.baselines`).

Per robot, one row per task grouped by suite (TAVIS-Head, TAVIS-Hands); columns: head + wrists on id, fixed +
wrists on id, head + wrists on ood_spatial and on ood_init_pose, each "success% [Wilson 95% interval]", the GALT
median of head + wrists on id, and the paper's published number where it has one. Pooled rows: the four search tasks
and the TAVIS-Hands tasks, their episodes pooled (with the same episodes per task, the pooled rate is the mean of the
task rates, as the paper reports its means); then whether the targets are met. A cell without an entry reads
"not run". The plot: per robot, bars per task for both conditions on id with their Wilson intervals, the paper's
numbers as markers.
"""

from __future__ import annotations

from contextlib import contextmanager, nullcontext
from dataclasses import dataclass
from pathlib import Path

from lerobot_tavis.atomic import write_text
from lerobot_tavis.cli_options import option
from lerobot_tavis.envs.tasks.catalog import suite_tasks
from lerobot_tavis.errors import InputError, PathNotFoundError
from lerobot_tavis.eval.baselines import (BASELINES_PATH, CONDITIONS, Entry, baselines_turn, read_entries,
                                         read_results)
from lerobot_tavis.metrics.stats import wilson_interval

ROBOTS = ("gr1t2", "reachy2")
SUITE_TITLES = {"tavis_head": "TAVIS-Head", "tavis_hands": "TAVIS-Hands"}
SEARCH_TASKS = ("conditional_pick", "clutter_pick_cube", "clutter_pick_lift", "multi_shelf_scan")
# (condition, split) of each column, in the paper's order.
COLUMNS = (("head_wrist", "id"), ("fixed_wrist", "id"), ("head_wrist", "ood_spatial"), ("head_wrist", "ood_init_pose"))
CONDITION_TITLES = {"head_wrist": "head + wrists", "fixed_wrist": "fixed + wrists"}
CONDITION_COLOURS = {"head_wrist": "tab:blue", "fixed_wrist": "tab:orange"}

# The paper's published success rates (fractions): TAVIS-Hands, the multi-task pi0 policy, id split, head camera
# condition, and their mean over the three tasks: the table's targets.
PAPER_SOURCE = "the TAVIS paper's TAVIS-Hands results: one multi-task pi0 policy, id split, head + wrist cameras"
PAPER_HANDS_ID = {
    "gr1t2": {"peeking_box": 0.646, "occluded_reach": 0.875, "blocked_clutter_pick_cube": 0.583},
    "reachy2": {"peeking_box": 0.844, "occluded_reach": 0.781, "blocked_clutter_pick_cube": 0.677},
}
PAPER_HANDS_MEAN = {"gr1t2": 0.701, "reachy2": 0.767}


@dataclass(frozen=True)
class Rate:
    """Successes of n episodes (a cell, or cells pooled)."""

    successes: int
    n: int

    @property
    def rate(self) -> float:
        return self.successes / self.n

    def text(self) -> str:
        """`58.3% [48.3, 67.7]`: the rate and its Wilson 95% interval, percent."""
        low, high = wilson_interval(self.successes, self.n)
        return f"{100 * self.rate:.1f}% [{100 * low:.1f}, {100 * high:.1f}]"


@dataclass(frozen=True)
class Measured:
    """One evaluated cell of the table: its success and its GALT median (s; None without a valid one)."""

    rate: Rate
    galt_median_s: float | None


def measured_cells(entries: list[Entry], root: Path) -> dict[tuple[str, str, str, str], Measured]:
    """(robot, task, condition, split) -> the cell's numbers, from each entry's results.json."""
    cells = {}
    for entry in entries:
        for cell in read_results(entry, root)["cells"]:
            if cell.get("task") == entry.task:
                cells[(entry.robot, entry.task, entry.camera_mode, cell["split"])] = Measured(
                    Rate(cell["successes"], cell["n"]), cell.get("galt_median_s"))
    return cells


def pooled(cells: dict, robot: str, tasks: tuple[str, ...], condition: str) -> tuple[Rate | None, int]:
    """The id episodes of `tasks` pooled for one robot and condition, and how many of the tasks were measured."""
    found = [cells[key].rate for task in tasks if (key := (robot, task, condition, "id")) in cells]
    if not found:
        return None, 0
    return Rate(sum(r.successes for r in found), sum(r.n for r in found)), len(found)


def _percent(value: float) -> str:
    return f"{100 * value:.1f}%"


def robot_table(cells: dict, robot: str) -> list[str]:
    """The Markdown lines of one robot's table, its pooled rows and its targets."""
    header = ["suite", "task", *(f"{CONDITION_TITLES[c]}, {s}" for c, s in COLUMNS),
              "GALT median, head + wrists id", "paper (head, id)"]
    lines = [f"### {robot}", "", "| " + " | ".join(header) + " |", "|---|---|" + "---|" * (len(header) - 2)]
    for suite, title in SUITE_TITLES.items():
        for task in suite_tasks(suite):
            row = [cells[key].rate.text() if (key := (robot, task, c, s)) in cells else "not run" for c, s in COLUMNS]
            galt = cells.get((robot, task, "head_wrist", "id"))
            row.append("not run" if galt is None else "-" if galt.galt_median_s is None
                       else f"{galt.galt_median_s:.2f} s")
            paper = PAPER_HANDS_ID.get(robot, {}).get(task)
            row.append("-" if paper is None else _percent(paper))
            lines.append(f"| {title} | {task} | " + " | ".join(row) + " |")
    for name, tasks, paper in (("search tasks pooled", SEARCH_TASKS, None),
                               ("TAVIS-Hands mean", suite_tasks("tavis_hands"), PAPER_HANDS_MEAN.get(robot))):
        row = []
        for condition, split in COLUMNS:
            rate, count = pooled(cells, robot, tasks, condition) if split == "id" else (None, 0)
            row.append("-" if split != "id" else "not run" if rate is None
                       else f"{rate.text()} ({count} of {len(tasks)} tasks)")
        lines.append(f"| | **{name}** | " + " | ".join(row) + " | | " + ("-" if paper is None else _percent(paper))
                     + " |")
    return lines + [""] + targets(cells, robot)


def targets(cells: dict, robot: str) -> list[str]:
    """The table's two targets for one robot, each met, missed or not yet measurable."""
    hands = suite_tasks("tavis_hands")
    head, count = pooled(cells, robot, hands, "head_wrist")
    goal = PAPER_HANDS_MEAN[robot]
    if count < len(hands):
        hands_line = f"not measured ({count} of {len(hands)} tasks run)"
    else:
        hands_line = f"{_percent(head.rate)}: {'met' if head.rate >= goal else 'not met'}"
    lines = [f"- Target, TAVIS-Hands mean with head + wrists >= {_percent(goal)} (the paper's): {hands_line}."]
    with_head, count_head = pooled(cells, robot, SEARCH_TASKS, "head_wrist")
    without, count_fixed = pooled(cells, robot, SEARCH_TASKS, "fixed_wrist")
    if min(count_head, count_fixed) < len(SEARCH_TASKS):
        search_line = f"not measured ({min(count_head, count_fixed)} of {len(SEARCH_TASKS)} tasks run in both)"
    else:
        search_line = (f"{_percent(with_head.rate)} against {_percent(without.rate)}: "
                       f"{'met' if with_head.rate > without.rate else 'not met'}")
    return lines + [f"- Target, the four search tasks pooled, head + wrists ahead of fixed + wrists: {search_line}."]


def table_body(entries: list[Entry], root: Path) -> str:
    """The table below its title: what a cell holds, then each robot's table and targets."""
    cells = measured_cells(entries, root)
    lines = ["Success on 96 episodes per cell unless the entry's evaluation says otherwise, with Wilson 95% "
             "intervals; GALT: median gaze-action lead time of the successful episodes. One single-task policy "
             "per robot, task and condition (docs/results/baselines.json). Paper: " + PAPER_SOURCE + ".", ""]
    for robot in ROBOTS:
        lines += robot_table(cells, robot) + [""]
    return "\n".join(lines)


def table_markdown(entries: list[Entry], root: Path) -> str:
    return "# The baselines table\n\n" + table_body(entries, root)


README_BEGIN = "<!-- the baselines table: written by `tavis table --readme`, do not edit -->"
README_END = "<!-- end of the baselines table -->"


def with_table(readme: str, body: str, path: Path) -> str:
    """`readme` with the text between its two marker lines replaced by `body`."""
    head, begin, rest = readme.partition(README_BEGIN + "\n")
    _, end, tail = rest.partition(README_END + "\n")
    if not begin or not end:
        raise InputError(f"{path}: no table markers: put the line '{README_BEGIN}' and, below it, the line "
                         f"'{README_END}' where the table goes")
    return f"{head}{begin}{body}{end}{tail}"


def table_plot(entries: list[Entry], root: Path, path: Path) -> Path:
    """Per robot, success on id for both conditions per task (Wilson 95% error bars), the paper's numbers as
    markers; written to `path` (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch

    from lerobot_tavis.eval.report import save_figure

    cells = measured_cells(entries, root)
    tasks = [task for suite in SUITE_TITLES for task in suite_tasks(suite)]
    fig, axes = plt.subplots(len(ROBOTS), 1, figsize=(10.0, 3.6 * len(ROBOTS)), sharex=True)
    width = 0.38
    for ax, robot in zip(axes, ROBOTS):
        for offset, condition in zip((-width / 2, width / 2), CONDITIONS):
            xs, rates, errors = [], [], [[], []]
            for x, task in enumerate(tasks):
                if (key := (robot, task, condition, "id")) not in cells:
                    continue
                rate = cells[key].rate
                low, high = wilson_interval(rate.successes, rate.n)
                xs.append(x + offset)
                rates.append(100 * rate.rate)
                errors[0].append(100 * (rate.rate - low))
                errors[1].append(100 * (high - rate.rate))
            ax.bar(xs, rates, width, yerr=errors, capsize=3, color=CONDITION_COLOURS[condition],
                   label=f"{CONDITION_TITLES[condition]}, id")
        for x, task in enumerate(tasks):
            if not any((robot, task, condition, "id") in cells for condition in CONDITIONS):
                ax.text(x, 2, "not run", ha="center", fontsize=8, color="grey")
        paper = PAPER_HANDS_ID.get(robot, {})
        markers = ax.scatter([tasks.index(task) - width / 2 for task in paper], [100 * v for v in paper.values()],
                             marker="D", color="black", zorder=3, label="paper (head, id)")
        ax.set_title(robot)
        ax.set_ylabel("success (%), Wilson 95%")
        ax.set_ylim(0, 105)
        ax.legend(handles=[*(Patch(color=CONDITION_COLOURS[c], label=f"{CONDITION_TITLES[c]}, id") for c in CONDITIONS),
                           markers], loc="upper left", fontsize=8)  # a robot without bars still names both
    axes[-1].set_xticks(range(len(tasks)), tasks, rotation=30, ha="right")
    fig.tight_layout()
    written = save_figure(fig, path)
    plt.close(fig)
    return written


@dataclass(frozen=True, kw_only=True)
class TableConfig:
    """`tavis table`: the table from the baselines file."""

    baselines: Path = option(BASELINES_PATH, "the baselines file")
    root: Path = option(Path("."), "the repository root, which results paths are relative to (default: the current "
                        "directory)")
    out_dir: Path | None = option(None, "also write baselines.md and baselines.png into this folder (default: print "
                                  "the table only)", flag="--out")
    readme: Path | None = option(None, "also put the table into this Markdown file, between its two marker lines "
                                 f"('{README_BEGIN}' and '{README_END}') (default: none)")


@contextmanager
def _existing_baselines_turn(baselines: Path):
    """The baselines file's lock (`baselines_turn`) once the file is known to exist (the lock would make its folder):
    tables and ablations written at once would write the same files at once, each from the entries it read."""
    if not Path(baselines).is_file():
        raise PathNotFoundError(f"{baselines}: missing")
    with baselines_turn(baselines):
        yield


def run_table(cfg: TableConfig) -> list[str]:
    """The table of the baselines file's entries, written where `cfg` asks (else returned), holding the file's
    lock."""
    if cfg.readme is not None and not cfg.readme.is_file():
        raise PathNotFoundError(f"--readme {cfg.readme}: no such file")
    with _existing_baselines_turn(cfg.baselines):
        entries = read_entries(cfg.baselines, cfg.root)
        text = table_markdown(entries, cfg.root)
        written = []
        if cfg.readme is not None:
            readme = with_table(cfg.readme.read_text(), table_body(entries, cfg.root), cfg.readme)
            written.append(str(write_text(cfg.readme, readme)))
        if cfg.out_dir is not None:
            written += [str(write_text(cfg.out_dir / "baselines.md", text)),
                        str(table_plot(entries, cfg.root, cfg.out_dir / "baselines.png"))]
    return written or [text]


# The wrist-only ablation of the paper's TAVIS-Hands study: a TAVIS-Head policy with and without active vision
# against a TAVIS-Hands policy whose head camera is black (blocked_clutter_pick_cube renders it black, the head still
# moving), each (task, condition) a cell of the table.
ABLATION_ROWS = (("clutter_pick_cube", "head_wrist", "Head policy with active vision (head + wrists)"),
                 ("clutter_pick_cube", "fixed_wrist", "Head policy without active vision (fixed + wrists)"),
                 ("blocked_clutter_pick_cube", "head_wrist", "Hands policy, head camera black (wrists alone)"))


@dataclass(frozen=True, kw_only=True)
class AblationConfig:
    """`tavis ablation`: the wrist-only ablation's three cells for one robot."""

    robot: str = option(help="the robot whose cells are compared", choices=ROBOTS)
    baselines: Path = option(BASELINES_PATH, "the baselines file")
    root: Path = option(Path("."), "the repository root, which results paths are relative to (default: the current "
                        "directory)")
    out: Path | None = option(None, "also write the table (Markdown) to this file (default: print it only)")


def ablation_markdown(entries: list[Entry], root: Path, robot: str) -> str:
    """The three cells' success with Wilson intervals on id, and the exact McNemar test between each two that were
    played on the same episodes (task, split and seed: `eval.compare`)."""
    from lerobot_tavis.eval.compare import compare_evaluations

    by_key = {entry.key: entry for entry in entries}
    cells = measured_cells(entries, root)
    lines = [f"# Wrist-only ablation, {robot}", "",
             "| policy | task | condition | success on id, Wilson 95% |", "|---|---|---|---|"]
    for task, condition, title in ABLATION_ROWS:
        cell = cells.get((robot, task, condition, "id"))
        lines.append(f"| {title} | {task} | {condition} | {'not run' if cell is None else cell.rate.text()} |")
    lines += ["", "| pair | exact McNemar on the shared episodes |", "|---|---|"]
    for i, (task_a, condition_a, title_a) in enumerate(ABLATION_ROWS):
        for task_b, condition_b, title_b in ABLATION_ROWS[i + 1:]:
            a, b = by_key.get((robot, task_a, condition_a)), by_key.get((robot, task_b, condition_b))
            if a is None or b is None:
                result = "not run"
            elif task_a != task_b:
                result = "not paired: the tasks' episodes differ (compare the intervals)"
            else:
                result = compare_evaluations(root / Path(a.results).parent, root / Path(b.results).parent).summary()
            lines.append(f"| {title_a} / {title_b} | {result} |")
    return "\n".join(lines) + "\n"


def run_ablation(cfg: AblationConfig) -> list[str]:
    """The ablation's Markdown, also written to `cfg.out` if set (holding the baselines file's lock)."""
    with nullcontext() if cfg.out is None else _existing_baselines_turn(cfg.baselines):
        text = ablation_markdown(read_entries(cfg.baselines, cfg.root), cfg.root, cfg.robot)
        return [text] if cfg.out is None else [text, str(write_text(cfg.out, text))]

