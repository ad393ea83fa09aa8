"""`tavis report`: the join with eval_info.json, Wilson intervals, pooled average, deltas, GALT, plots."""

import json

import pytest

from lerobot_tavis.eval.outputs import join
from lerobot_tavis.eval.report import build_report, markdown, write_report


def _record(task, task_id, seed, success, split="id", galt=None):
    return {"robot": "gr1t2", "suite": "tavis_head", "task": task, "task_id": task_id, "split": split,
            "camera_mode": "head_only", "seed": seed, "success": success, "length_steps": 100,
            "galt_s": galt, "galt_reason": ("ok" if galt is not None else None) if success else None}


def _eval_dir(path, split, outcomes: dict[str, list[bool]], extra=1):
    """A lerobot-eval output: eval_info.json scores len(outcomes) episodes per task; the log has `extra` more."""
    path.mkdir(parents=True)
    per_task, lines = [], []
    for task_id, (task, successes) in enumerate(outcomes.items()):
        per_task.append({"task_group": "tavis_head", "task_id": task_id, "metrics": {"successes": successes}})
        for ix, success in enumerate(successes + [True] * extra):  # the last batch's surplus episodes
            lines.append(_record(task, task_id, 1000 + ix, success, split, galt=0.5 + 0.1 * ix if success else None))
    (path / "eval_info.json").write_text(json.dumps({"per_task": per_task}))
    (path / "episodes.jsonl").write_text("".join(json.dumps(line) + "\n" for line in reversed(lines)))


def test_join_keeps_exactly_the_episodes_lerobot_scored(tmp_path):
    _eval_dir(tmp_path / "a", "id", {"conditional_pick": [True, False, True]}, extra=2)
    episodes, meta = join(tmp_path / "a")
    assert sorted(e["episode_ix"] for e in episodes) == [0, 1, 2] and meta["success_mismatches"] == 0


def test_report_rates_intervals_average_and_deltas(tmp_path):
    _eval_dir(tmp_path / "id", "id", {"conditional_pick": [True] * 48 + [False] * 48,
                                      "wait_then_act": [True] * 96})
    _eval_dir(tmp_path / "ood", "ood_spatial", {"conditional_pick": [False] * 96, "wait_then_act": [True] * 96})
    report = build_report(tmp_path)
    cells = {(c["task"], c["split"]): c for c in report["cells"]}
    half = cells[("conditional_pick", "id")]
    assert (half["n"], half["successes"], round(100 * half["ci_low"], 1), round(100 * half["ci_high"], 1)) == (
        96, 48, 40.2, 59.8)
    assert round(100 * cells[("conditional_pick", "ood_spatial")]["ci_high"], 1) == 3.8
    assert report["average"]["id"]["successes"] == 144 and report["average"]["id"]["n"] == 192
    assert report["id_minus_ood_spatial"]["conditional_pick"] == pytest.approx(0.5)
    assert cells[("wait_then_act", "id")]["galt_n_valid"] == 96
    assert cells[("wait_then_act", "id")]["galt_median_s"] == pytest.approx(0.5 + 0.1 * 47.5)
    text = markdown(report)
    assert "| conditional_pick |  50.0% [40.2,  59.8] (96) |   0.0% [ 0.0,   3.8] (96) | +50.0 pp |" in text
    assert "**AVERAGE**" in text


def test_write_report_writes_tables_and_plots_atomically(tmp_path):
    _eval_dir(tmp_path / "id", "id", {"clutter_pick_lift": [True, True, False]})
    written = {p.name for p in write_report(tmp_path)}
    assert {"results.json", "results.md", "success_rates.png", "galt_clutter_pick_lift.png"} <= written
    assert json.loads((tmp_path / "results.json").read_text())["cells"][0]["n"] == 3
    assert not list(tmp_path.glob(".*partial*"))


def test_report_summarises_the_wrist_lead_of_hands_tasks(tmp_path):
    path = tmp_path / "hands"
    path.mkdir()
    records = [{**_record("peeking_box", 0, 1000 + ix, True), "suite": "tavis_hands", "wrist_lead_s": lead,
                "wrist_lead_reason": "ok" if lead is not None else "no_fixation"}
               for ix, lead in enumerate([1.0, 2.0, 3.0, None])]
    (path / "eval_info.json").write_text(json.dumps(
        {"per_task": [{"task_group": "tavis_hands", "task_id": 0, "metrics": {"successes": [True] * 4}}]}))
    (path / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in records))
    (cell,) = build_report(tmp_path)["cells"]
    assert cell["wrist_lead_n_valid"] == 3 and cell["wrist_lead_median_s"] == 2.0
    assert cell["wrist_lead_reasons"] == {"no_fixation": 1, "ok": 3}
    assert "| peeking_box | id | 2.00 | 1.50 - 2.50 | 3 | no_fixation 1, ok 3 |" in markdown(build_report(tmp_path))


def test_report_counts_failed_episodes_by_how_far_they_got(tmp_path):
    path = tmp_path / "run"
    path.mkdir()
    # closest hand, target moved, first grasp off centre, closest hand to another object, command gap at the end
    reaches = [(0.20, 0.0, None, 0.3, 0.15), (0.30, 0.01, None, None, None), (0.01, 0.005, 0.012, 0.2, 0.001),
               (0.02, 0.30, 0.02, 0.2, 0.0), (0.01, 0.40, 0.003, 0.2, 0.0), (0.25, 0.0, None, 0.04, 0.2),
               (0.07, 0.0, None, 0.3, 0.004),
               None]  # the second was logged before `closest_hand_other_m` existed, the last before `reach`
    successes = [False, False, False, False, True, False, False, False]
    records = [{**_record("conditional_pick", 0, 1000 + ix, success),
                "reach": reach and {"closest_hand_m": reach[0], "target_moved_m": reach[1],
                                    "first_grasp_xy_m": reach[2],
                                    **({} if reach[3] is None else {"closest_hand_other_m": reach[3]}),
                                    **({} if reach[4] is None else {"command_gap_m": reach[4]})}}
               for ix, (reach, success) in enumerate(zip(reaches, successes))]
    (path / "eval_info.json").write_text(json.dumps(
        {"per_task": [{"task_group": "tavis_head", "task_id": 0, "metrics": {"successes": successes}}]}))
    (path / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in records))
    (cell,) = build_report(tmp_path)["cells"]
    assert cell["failure_stages"] == {"reached_other": 1, "not_reached": 3, "reached_not_moved": 1,
                                      "moved_no_success": 1}
    assert cell["not_reached_held_back"] == 1  # of the two not-reached episodes logged with a gap
    assert cell["first_grasp_xy_median_m_failure"] == 0.016 and cell["first_grasp_xy_median_m_success"] == 0.003
    assert "| conditional_pick | id | 6 | 1 | 3 | 1 | 1 | 1 | 16 / 3 |" in markdown(build_report(tmp_path))


def test_no_failure_table_without_reach_records(tmp_path):
    _eval_dir(tmp_path / "id", "id", {"conditional_pick": [True, False]})
    (cell,) = build_report(tmp_path)["cells"]
    assert cell["failure_stages"] == {} and "how far they got" not in markdown(build_report(tmp_path))


def test_missing_or_corrupt_logs_give_clear_errors(tmp_path):
    _eval_dir(tmp_path / "a", "id", {"conditional_pick": [True]})
    (tmp_path / "a" / "episodes.jsonl").write_text('{"suite": "tavis_head"\n')
    with pytest.raises(ValueError, match=r"episodes.jsonl:1: not a JSON line"):
        join(tmp_path / "a")
    (tmp_path / "a" / "episodes.jsonl").unlink()
    with pytest.raises(FileNotFoundError, match="episodes.jsonl is missing"):
        join(tmp_path / "a")
    with pytest.raises(FileNotFoundError, match="no eval_info.json"):
        build_report(tmp_path / "a" / "nothing")


def test_the_report_gives_the_drop_to_ood_visual_too(tmp_path):
    _eval_dir(tmp_path / "id", "id", {"conditional_pick": [True] * 8})
    _eval_dir(tmp_path / "visual", "ood_visual", {"conditional_pick": [True] * 2 + [False] * 6})
    report = build_report(tmp_path)
    assert report["id_minus_ood_visual"]["conditional_pick"] == pytest.approx(0.75)
    assert report["id_minus_ood_spatial"] == {}
    text = markdown(report)
    assert "| task | id | ood_visual | id - ood_visual |" in text and "+75.0 pp" in text
