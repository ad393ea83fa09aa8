"""Evaluation outputs with a damaged or ill-typed file: `tavis report` (episodes.jsonl, eval_info.json, an episode
video) and `tavis curve` (results.json) exit with one line naming the file and the line or field, and write
nothing."""

import json
import shutil

import numpy as np
import pytest

from lerobot_tavis.media import write_mp4

CELL = "step_100/tavis_head__id"


def _files(root) -> dict:
    return {path: path.stat().st_mtime_ns for path in root.rglob("*")}


def _edit_record(edit):
    """Rewrite the first record of the episode log with `edit` applied."""
    def damage(log):
        records = [json.loads(line) for line in log.read_text().splitlines()]
        edit(records[0])
        log.write_text("".join(json.dumps(record) + "\n" for record in records))

    return damage


@pytest.mark.parametrize("damage,problem", [
    (lambda log: log.write_text(log.read_text()[:100]), ":1: not a JSON line (Unterminated string"),
    (lambda log: log.write_bytes(b"\xff" + log.read_bytes()), ":1: not a JSON line (not UTF-8 text)"),
    (lambda log: log.write_text("null\n"), ":1: not an episode record (a JSON object), got NoneType"),
    (_edit_record(lambda record: record.update(seed="1000")), ":1: seed must be an integer, got '1000'"),
    (_edit_record(lambda record: record.update(success=None)), ":1: success must be true or false, got None"),
    (_edit_record(lambda record: record.update(task_id=None)), ":1: task_id must be an integer, got None"),
    (_edit_record(lambda record: record.update(galt_s="1.0")), ":1: galt_s must be a finite number or null, got"),
    (_edit_record(lambda record: record["reach"].update(closest_hand_m=None)),
     ":1: reach.closest_hand_m must be a finite number, got None"),
    (_edit_record(lambda record: record.update(reach=[1])), ":1: reach must be an object or null, got [1]"),
])
def test_report_names_the_damaged_episode_log_line(eval_root, tmp_path, refused, damage, problem):
    root = shutil.copytree(eval_root, tmp_path / "evals")
    log = root / CELL / "episodes.jsonl"
    damage(log)
    before = _files(root)
    message = refused(["report", str(root / "step_100")])
    assert message.startswith(f"tavis report: error: {log}{problem}")
    assert _files(root) == before


def test_report_names_a_truncated_eval_info(eval_root, tmp_path, refused):
    root = shutil.copytree(eval_root, tmp_path / "evals")
    info = root / CELL / "eval_info.json"
    info.write_text(info.read_text()[:40])
    before = _files(root)
    assert refused(["report", str(root / "step_100")]).startswith(
        f"tavis report: error: {info}: not a JSON file (")
    assert _files(root) == before


def test_report_names_a_damaged_episode_video_before_writing_its_results(eval_root, tmp_path, refused):
    """A filmed episode's video cut short: named with the frame where decoding stops; results.json stays as it
    was."""
    root = shutil.copytree(eval_root, tmp_path / "evals")
    video = root / CELL / "videos" / "tavis_head_0" / "eval_episode_0.mp4"
    write_mp4(video, [np.full((48, 64, 3), value, np.uint8) for value in range(0, 250, 10)], fps=20)
    video.write_bytes(video.read_bytes()[:-400])
    before = _files(root)
    message = refused(["report", str(root / "step_100"), "--workers", "1"])
    assert message.startswith(f"tavis report: error: {video}: frame ") and "cannot be decoded" in message
    assert _files(root) == before


@pytest.mark.parametrize("damage,problem", [
    (lambda results: results.write_text(results.read_text()[:50]), "not a JSON file (Unterminated string"),
    (lambda results: results.write_text("[]"), "the report must be an object, got []"),
    (lambda results: results.write_text('{"cells": null}'), "cells must be a list, got None"),
    (lambda results: results.write_text('{"cells": [null]}'), "cells[0] must be an object, got None"),
    (lambda results: results.write_text(results.read_text().replace('"n": 1,', '"n": "1",', 1)),
     "cells[0].n must be an integer, got '1'"),
    (lambda results: results.write_text(results.read_text().replace('"ci_low"', '"ci_lo"', 1)),
     "cells[0].ci_low is missing"),
])
def test_curve_names_the_damaged_results_file(eval_root, tmp_path, refused, damage, problem):
    root = shutil.copytree(eval_root, tmp_path / "evals")
    results = root / "step_100" / "results.json"
    damage(results)
    before = _files(root)
    assert refused(["curve", str(root)]).startswith(f"tavis curve: error: {results}: {problem}")
    assert _files(root) == before
