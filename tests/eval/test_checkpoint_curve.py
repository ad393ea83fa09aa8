"""`tavis curve`: the evaluations of a run's checkpoints (step_<N>/ folders) as one table and plot, by step."""

import pytest

from lerobot_tavis.cli import main
from lerobot_tavis.errors import InputError, PathNotFoundError
from lerobot_tavis.eval.checkpoint_curve import checkpoint_reports, curve_markdown, write_curve
from lerobot_tavis.eval.report import write_report

from .test_report import _eval_dir


def _checkpoint(root, step, successes):
    _eval_dir(root / f"step_{step}" / "tavis_head__id", "id", {"conditional_pick": successes})
    write_report(root / f"step_{step}", workers=1)


def test_the_finished_checkpoints_in_step_order_as_a_table_and_a_plot(tmp_path, capsys):
    _checkpoint(tmp_path, 1600, [True] * 48 + [False] * 48)
    _checkpoint(tmp_path, 800, [False] * 96)
    (tmp_path / "step_2400.running").mkdir()  # another evaluation still at work
    (tmp_path / "step_2400").mkdir()  # ...whose folder has no results.json yet
    assert [step for step, _ in checkpoint_reports(tmp_path)] == [800, 1600]
    main(["curve", str(tmp_path)])
    assert capsys.readouterr().out.split() == [str(tmp_path / "checkpoints.md"), str(tmp_path / "checkpoints.png")]
    table = (tmp_path / "checkpoints.md").read_text()
    rows = [line for line in table.splitlines() if line.startswith("| 800 ") or line.startswith("| 1600 ")]
    assert rows == ["| 800 | conditional_pick | id |   0.0% [ 0.0,   3.8] (96) | - |",
                    "| 1600 | conditional_pick | id |  50.0% [40.2,  59.8] (96) | 2.85 |"]  # GALT 0.5-5.2 s
    assert (tmp_path / "checkpoints.png").read_bytes().startswith(b"\x89PNG")
    assert not list(tmp_path.glob(".*partial*"))


def test_a_folder_without_finished_checkpoints_or_with_a_broken_report_is_refused(tmp_path):
    (tmp_path / "step_800").mkdir()
    with pytest.raises(PathNotFoundError, match="no step_<N>/results.json below it"):
        write_curve(tmp_path)
    with pytest.raises(PathNotFoundError, match="no such directory"):
        checkpoint_reports(tmp_path / "missing")
    (tmp_path / "step_800" / "results.json").write_text("{")
    with pytest.raises(InputError, match="step_800/results.json: not a JSON file"):
        checkpoint_reports(tmp_path)
    assert not (tmp_path / "checkpoints.md").exists()


def test_every_task_and_split_of_a_checkpoint_gets_its_row():
    cell = {"success_rate": 0.25, "ci_low": 0.1, "ci_high": 0.5, "n": 8, "galt_median_s": None}
    report = {"cells": [{**cell, "task": "wait_then_act", "split": "id"},
                        {**cell, "task": "wait_then_act", "split": "ood_spatial"}]}
    rows = [line for line in curve_markdown([(3200, report)]).splitlines() if line.startswith("| 3200")]
    assert [row.split(" | ")[2] for row in rows] == ["id", "ood_spatial"]
