"""The ordered episode metrics that the episode log writes and `tavis report` summarises, in that order.

A new metric: its module (see `episode_metric.py`) plus one entry in `_METRICS` below, so that worker
processes, which import this module afresh, know it too. `register` adds one at run time in this process only
(tests, notebooks).
"""

from __future__ import annotations

from lerobot_tavis.metrics.episode_metric import EpisodeMetric
from lerobot_tavis.metrics.galt_metric import GALT
from lerobot_tavis.metrics.wrist_lead_metric import WRIST_LEAD

_METRICS: list[EpisodeMetric] = [GALT, WRIST_LEAD]


def episode_metrics() -> tuple[EpisodeMetric, ...]:
    """Every registered metric, in registration order (the order of log fields, report keys and tables)."""
    return tuple(_METRICS)


def register(metric: EpisodeMetric) -> EpisodeMetric:
    """Append a metric to the registry of this process; ValueError when its name or a field is taken."""
    taken = {field for known in _METRICS for field in known.fields}
    if any(known.name == metric.name for known in _METRICS) or taken & set(metric.fields):
        raise ValueError(f"an episode metric named {metric.name!r} or with one of its fields is already registered")
    for field in (metric.value_field, metric.reason_field):
        if field not in metric.fields:
            raise ValueError(f"metric {metric.name!r} must list {field!r} in its fields")
    _METRICS.append(metric)
    return metric
