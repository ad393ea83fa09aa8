"""Episode metrics: the registry's order and checks, and a toy metric reaching the log and the report unaided."""

import json

import numpy as np
import pytest

from lerobot_tavis.eval.episode_log import EpisodeLogger, metric_fields
from lerobot_tavis.eval.report import build_report, markdown, write_report
from lerobot_tavis.metrics import logged_metrics
from lerobot_tavis.metrics.episode_metric import Episode, EpisodeMetric, Histogram
from lerobot_tavis.metrics.galt_metric import GALT
from lerobot_tavis.metrics.wrist_lead_metric import WRIST_LEAD
from tests.eval.test_episode_log import ScriptedEnv, _run
from tests.test_galt import episode


class Duration(EpisodeMetric):
    """A toy metric: the episode's duration in seconds, for successful episodes only."""

    name = "duration"
    fields = ("duration_s", "duration_reason", "duration_steps")
    caption = "Duration (s) of successful episodes."
    histogram = Histogram(0.0, 10.0, 0.5, "duration (s)")

    def applies(self, episode: Episode) -> bool:
        return episode.success

    def measure(self, episode: Episode) -> dict:
        return {"duration_s": len(episode.actions) / episode.fps, "duration_reason": "ok",
                "duration_steps": len(episode.actions)}


@pytest.fixture
def toy_registered(monkeypatch):
    monkeypatch.setattr(logged_metrics, "_METRICS", list(logged_metrics._METRICS))  # undone after the test
    return logged_metrics.register(Duration())


def test_the_registry_holds_galt_then_the_wrist_lead():
    assert logged_metrics.episode_metrics() == (GALT, WRIST_LEAD)
    assert (GALT.value_field, GALT.reason_field) == ("galt_s", "galt_reason")


def test_register_refuses_a_taken_name_or_field_and_a_metric_without_its_value_field(monkeypatch):
    monkeypatch.setattr(logged_metrics, "_METRICS", list(logged_metrics._METRICS))
    with pytest.raises(ValueError, match="already registered"):
        logged_metrics.register(type("Again", (Duration,), {"name": "galt"})())
    with pytest.raises(ValueError, match="must list 'duration_s'"):
        logged_metrics.register(type("Partial", (Duration,), {"fields": ("duration_reason",)})())
    assert logged_metrics.episode_metrics() == (GALT, WRIST_LEAD)


def test_a_metric_that_does_not_apply_logs_none_and_unlisted_fields_are_refused():
    failed = Episode(np.zeros((30, 19)), 20.0, False, "tavis_head", "head_wrist")
    assert Duration().log_fields(failed) == {"duration_s": None, "duration_reason": None, "duration_steps": None}
    leaky = type("Leaky", (Duration,), {"fields": ("duration_s", "duration_reason")})()
    with pytest.raises(ValueError, match="does not list"):
        leaky.log_fields(Episode(np.zeros((30, 19)), 20.0, True, "tavis_head", "head_wrist"))


def test_a_registered_toy_metric_reaches_the_episode_log_and_the_report(tmp_path, toy_registered):
    actions = episode(20, 3.0, 1.0, hand=(1.4, 2.0), grasp_s=2.0)
    run = tmp_path / "eval"
    log = run / "episodes.jsonl"
    for seed in (1000, 1001):
        _run(EpisodeLogger(ScriptedEnv(actions), log, "tavis_head", 0), seed, len(actions))
    records = [json.loads(line) for line in log.read_text().splitlines()]
    assert [r["duration_s"] for r in records] == [3.0, 3.0] and records[0]["duration_steps"] == 60
    assert list(records[0])[-4:] == ["duration_s", "duration_reason", "duration_steps", "instability"]
    (run / "eval_info.json").write_text(json.dumps(
        {"per_task": [{"task_group": "tavis_head", "task_id": 0, "metrics": {"successes": [True, True]}}]}))
    (cell,) = build_report(tmp_path)["cells"]
    assert cell["duration_n_valid"] == 2 and cell["duration_median_s"] == 3.0
    assert cell["duration_reasons"] == {"ok": 2} and cell["galt_n_valid"] == 2
    text = markdown(build_report(tmp_path))
    assert "Duration (s) of successful episodes." in text and "| clutter_pick_lift | id | 3.00 |" in text
    written = {path.name for path in write_report(tmp_path)}
    assert {"galt_clutter_pick_lift.png", "duration_clutter_pick_lift.png"} <= written


def test_metric_fields_concatenate_every_metric_in_order(toy_registered):
    fields = metric_fields(Episode(episode(20, 3.0, 1.0, hand=(1.4, 2.0), grasp_s=2.0), 20.0, True,
                                   "tavis_head", "head_wrist"))
    assert list(fields) == [*GALT.fields, *WRIST_LEAD.fields, *Duration.fields]
