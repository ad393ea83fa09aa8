"""The baselines table: docs/results/baselines.json as the repository ships it, the checks of an entry against its
results.json, the writer (`add_entry`), the table (`tavis table`) and the wrist-only ablation (`tavis ablation`)."""

import json
from dataclasses import replace
from pathlib import Path

import pytest

from lerobot_tavis.errors import InputError, PathNotFoundError
from lerobot_tavis.eval.baselines import BASELINES_PATH, Entry, add_entry, read_entries
from lerobot_tavis.eval.baselines_table import (PAPER_HANDS_ID, README_BEGIN, README_END, ablation_markdown, table_body,
                                               table_markdown, table_plot, with_table)

REPO = Path(__file__).resolve().parents[2]


def test_the_repositorys_baselines_file_names_existing_results_of_its_robot_task_and_condition():
    entries = read_entries(REPO / BASELINES_PATH, REPO)  # every check of `check_entry`, and no duplicate cell
    assert len({entry.key for entry in entries}) == len(entries) >= 4
    for entry in entries:
        results = json.loads((REPO / entry.results).read_text())
        assert {(cell["task"], cell["split"]) for cell in results["cells"]} >= {(entry.task, "id")}
        assert entry.policy == f"act_hand_relative_{entry.camera_mode}_compact"


def test_the_results_readme_shows_the_table_of_the_repositorys_baselines_file():
    readme = (REPO / "docs" / "results" / "README.md").read_text()
    table = table_body(read_entries(REPO / BASELINES_PATH, REPO), REPO)
    assert f"{README_BEGIN}\n{table}{README_END}\n" in readme, "run: tavis table --readme docs/results/README.md"


def test_the_table_replaces_only_the_text_between_the_markers_and_refuses_a_file_without_them():
    readme = f"# Results\n\nabove\n{README_BEGIN}\nan old table\n{README_END}\nbelow\n"
    updated = with_table(readme, "the table\n", Path("README.md"))
    assert updated == f"# Results\n\nabove\n{README_BEGIN}\nthe table\n{README_END}\nbelow\n"
    assert with_table(updated, "the table\n", Path("README.md")) == updated
    with pytest.raises(InputError, match="README.md: no table markers"):
        with_table("# Results\n", "the table\n", Path("README.md"))


def _results(root: Path, name: str, robot: str, mode: str, *cells: tuple) -> str:
    """A results.json at root/name/results.json with cells (task, split, successes, n, galt median); its path
    relative to root."""
    path = root / name / "results.json"
    path.parent.mkdir(parents=True)
    path.write_text(json.dumps({
        "cells": [{"task": task, "split": split, "successes": k, "n": n, "galt_median_s": galt}
                  for task, split, k, n, galt in cells],
        "sources": [{"source": "eval", "robots": [robot], "camera_modes": [mode]}]}))
    return f"{name}/results.json"


def _entry(robot, task, mode, results, seed=1000) -> Entry:
    return Entry(robot, task, mode, f"act_hand_relative_{mode}_compact", seed, results)


@pytest.mark.parametrize(("change", "problem"), [
    (dict(camera_mode="fixed_wrist"), "was played with camera_modes ['head_wrist'], the entry says 'fixed_wrist'"),
    (dict(robot="reachy2"), "was played with robots ['gr1t2'], the entry says 'reachy2'"),
    (dict(task="peeking_box"), "holds no id cell of peeking_box"),
    (dict(camera_mode="head_only"), "camera_mode must be one of head_wrist, fixed_wrist, got 'head_only'"),
    (dict(results="/abs/results.json"), "results must be a path inside the repository"),
    (dict(results="cell/../../results.json"), "results must be a path inside the repository"),
])
def test_an_entry_that_disagrees_with_its_results_is_refused_and_the_file_left_as_it_was(tmp_path, change, problem):
    results = _results(tmp_path, "cell", "gr1t2", "head_wrist", ("clutter_pick_cube", "id", 50, 96, 0.5))
    baselines = tmp_path / "baselines.json"
    add_entry(baselines, _entry("gr1t2", "clutter_pick_cube", "head_wrist", results), tmp_path)
    before = baselines.read_text()
    with pytest.raises(InputError, match="the new entry: .*" + problem.replace("[", r"\[").replace("(", r"\(")):
        add_entry(baselines, replace(_entry("gr1t2", "clutter_pick_cube", "head_wrist", results), **change), tmp_path)
    assert baselines.read_text() == before
    assert sorted(path.name for path in tmp_path.iterdir()) == ["baselines.json", "cell"]  # no partial file, no lock


def test_add_entry_replaces_the_cells_entry_keeps_table_order_and_the_reader_refuses_a_duplicate(tmp_path):
    head = _results(tmp_path, "head", "gr1t2", "head_wrist", ("clutter_pick_cube", "id", 50, 96, 0.5))
    fixed = _results(tmp_path, "fixed", "gr1t2", "fixed_wrist", ("clutter_pick_cube", "id", 20, 96, None))
    again = _results(tmp_path, "again", "gr1t2", "head_wrist", ("clutter_pick_cube", "id", 60, 96, 0.4))
    baselines = tmp_path / "baselines.json"
    for entry in (_entry("gr1t2", "clutter_pick_cube", "fixed_wrist", fixed),
                  _entry("gr1t2", "clutter_pick_cube", "head_wrist", head),
                  _entry("gr1t2", "clutter_pick_cube", "head_wrist", again, seed=2000)):
        add_entry(baselines, entry, tmp_path)
    written = json.loads(baselines.read_text())
    assert [(e["camera_mode"], e["results"], e["training_seed"]) for e in written] == [
        ("head_wrist", "again/results.json", 2000), ("fixed_wrist", "fixed/results.json", 1000)]
    baselines.write_text(json.dumps(written + [written[1]]))
    with pytest.raises(InputError, match=r"entry 2: gr1t2 clutter_pick_cube fixed_wrist is entry 1 already"):
        read_entries(baselines, tmp_path)
    (tmp_path / "fixed" / "results.json").unlink()
    baselines.write_text(json.dumps(written))
    with pytest.raises(PathNotFoundError, match="entry 1: results fixed/results.json is not a file under"):
        read_entries(baselines, tmp_path)
    baselines.write_text(json.dumps([{**written[0], "seed": 1}]))
    with pytest.raises(InputError, match="entry 0: must have exactly the fields .*; unknown seed"):
        read_entries(baselines, tmp_path)


def test_the_table_shows_each_cell_pooled_rows_the_papers_numbers_and_the_targets(tmp_path):
    entries = []
    for task, k in (("peeking_box", 72), ("occluded_reach", 80), ("blocked_clutter_pick_cube", 60)):
        entries.append(_entry("gr1t2", task, "head_wrist", _results(
            tmp_path, task, "gr1t2", "head_wrist", (task, "id", k, 96, 0.7), (task, "ood_spatial", 10, 96, 0.6))))
    for task, mode, k in (("conditional_pick", "head_wrist", 39), ("conditional_pick", "fixed_wrist", 34),
                          ("clutter_pick_cube", "head_wrist", 56), ("clutter_pick_cube", "fixed_wrist", 20),
                          ("clutter_pick_lift", "head_wrist", 30), ("clutter_pick_lift", "fixed_wrist", 31),
                          ("multi_shelf_scan", "head_wrist", 10), ("multi_shelf_scan", "fixed_wrist", 0)):
        galt = 0.5 if mode == "head_wrist" else None
        entries.append(_entry("gr1t2", task, mode, _results(tmp_path, f"{task}_{mode}", "gr1t2", mode,
                                                            (task, "id", k, 96, galt))))
    text = table_markdown(entries, tmp_path)
    assert ("| TAVIS-Hands | peeking_box | 75.0% [65.5, 82.6] | not run | 10.4% [5.8, 18.1] | not run | 0.70 s "
            "| 64.6% |") in text
    assert ("| TAVIS-Head | conditional_pick | 40.6% [31.3, 50.6] | 35.4% [26.6, 45.4] | not run | not run | 0.50 s "
            "| - |") in text
    assert "| TAVIS-Head | wait_then_act | not run | not run | not run | not run | not run | - |" in text
    # 212 of 288 = 73.6%, the mean of 75.0, 83.3 and 62.5%: above GR1T2's 70.1%.
    assert "| | **TAVIS-Hands mean** | 73.6% [68.2, 78.4] (3 of 3 tasks) | not run | - | - | | 70.1% |" in text
    # head + wrists 39 + 56 + 30 + 10 = 135 of 384; fixed + wrists 34 + 20 + 31 + 0 = 85 of 384.
    assert "| | **search tasks pooled** | 35.2% [30.5, 40.1] (4 of 4 tasks) | 22.1% [18.3, 26.6] (4 of 4 tasks)" in text
    assert "TAVIS-Hands mean with head + wrists >= 70.1% (the paper's): 73.6%: met." in text
    assert "head + wrists ahead of fixed + wrists: 35.2% against 22.1%: met." in text
    assert "TAVIS-Hands mean with head + wrists >= 76.7% (the paper's): not measured (0 of 3 tasks run)." in text
    assert text.count("### ") == 2
    assert table_plot(entries, tmp_path, tmp_path / "table.png").read_bytes().startswith(b"\x89PNG")
    assert PAPER_HANDS_ID["reachy2"]["peeking_box"] == 0.844


def test_the_ablation_reads_its_three_cells_and_pairs_only_the_same_tasks_episodes():
    entries = read_entries(REPO / BASELINES_PATH, REPO)
    text = ablation_markdown(entries, REPO, "gr1t2")
    # The oracle: each clutter_pick_cube cell's own episode log, read here without the package's readers.
    outcomes = {}
    for entry in entries:
        if (entry.robot, entry.task) == ("gr1t2", "clutter_pick_cube"):
            log = REPO / Path(entry.results).parent / "tavis_head__id" / "episodes.jsonl"
            outcomes[entry.camera_mode] = {episode["seed"]: episode["success"]
                                           for episode in map(json.loads, log.read_text().splitlines())}
    head, fixed = outcomes["head_wrist"], outcomes["fixed_wrist"]
    for label, mode, outcome in (("with active vision (head + wrists)", "head_wrist", head),
                                 ("without active vision (fixed + wrists)", "fixed_wrist", fixed)):
        rate = 100 * sum(outcome.values()) / len(outcome)
        assert f"| Head policy {label} | clutter_pick_cube | {mode} | {rate:.1f}% [" in text
    seeds = head.keys() & fixed.keys()
    both = sum(head[s] and fixed[s] for s in seeds)
    only_head, only_fixed = (sum(a[s] and not b[s] for s in seeds) for a, b in ((head, fixed), (fixed, head)))
    assert (f"{len(seeds)} paired episodes: A {both + only_head} successes, B {both + only_fixed}; both {both}, "
            f"only A {only_head}, only B {only_fixed}; exact McNemar p") in text
    assert "| Hands policy, head camera black (wrists alone) | blocked_clutter_pick_cube | head_wrist |" in text


def test_add_entry_waits_for_another_writer_of_the_file(tmp_path):
    import threading
    import time

    from lerobot_tavis.locking import exclusive_output

    results = _results(tmp_path, "cell", "gr1t2", "head_wrist", ("clutter_pick_cube", "id", 50, 96, 0.5))
    baselines = tmp_path / "baselines.json"
    held, release = threading.Event(), threading.Event()

    def other_writer():
        with exclusive_output(baselines):
            held.set()
            release.wait(5)

    writer = threading.Thread(target=other_writer)
    writer.start()
    held.wait(5)
    threading.Timer(0.3, release.set).start()
    started = time.monotonic()
    add_entry(baselines, _entry("gr1t2", "clutter_pick_cube", "head_wrist", results), tmp_path)
    writer.join()
    assert time.monotonic() - started >= 0.3  # it waited for the lock instead of failing
    assert [e["results"] for e in json.loads(baselines.read_text())] == ["cell/results.json"]


def test_a_table_waits_for_another_writer_of_the_baselines_file(tmp_path):
    """Cells that finish together each rewrite the table (benchmarks/baselines.sh): one at a time, else both write
    the same partial files and one rename finds its file gone."""
    import threading

    from lerobot_tavis.eval.baselines_table import TableConfig, run_table
    from lerobot_tavis.locking import exclusive_output

    results = _results(tmp_path, "cell", "gr1t2", "head_wrist", ("clutter_pick_cube", "id", 50, 96, 0.5))
    baselines = tmp_path / "baselines.json"
    add_entry(baselines, _entry("gr1t2", "clutter_pick_cube", "head_wrist", results), tmp_path)
    table = threading.Thread(target=run_table, args=(TableConfig(baselines=baselines, root=tmp_path, out_dir=tmp_path / "out"),))
    with exclusive_output(baselines):  # another cell adding its entry or writing its table
        table.start()
        table.join(1.0)
        assert table.is_alive() and not (tmp_path / "out").exists()
    table.join(60)
    assert (tmp_path / "out" / "baselines.md").is_file() and (tmp_path / "out" / "baselines.png").is_file()
    with pytest.raises(PathNotFoundError, match="missing"):
        run_table(TableConfig(baselines=tmp_path / "none" / "baselines.json", root=tmp_path))
    assert not (tmp_path / "none").exists()


def test_the_ablation_pairs_the_head_policies_and_shows_the_hands_policy_beside_them(tmp_path):
    import shutil

    entries = [entry for entry in read_entries(REPO / BASELINES_PATH, REPO) if entry.task == "clutter_pick_cube"]
    for entry in entries:
        shutil.copytree((REPO / entry.results).parent, (tmp_path / entry.results).parent)
    blocked = _results(tmp_path, "blocked", "gr1t2", "head_wrist", ("blocked_clutter_pick_cube", "id", 48, 96, 0.4))
    entries.append(_entry("gr1t2", "blocked_clutter_pick_cube", "head_wrist", blocked))
    text = ablation_markdown(entries, tmp_path, "gr1t2")
    assert ("| Hands policy, head camera black (wrists alone) | blocked_clutter_pick_cube | head_wrist "
            "| 50.0% [40.2, 59.8] |") in text
    assert text.count("not paired: the tasks' episodes differ") == 2
    assert "not run" not in text
    assert ablation_markdown(entries, tmp_path, "reachy2").count("not run") == 6  # 3 cells, 3 pairs
