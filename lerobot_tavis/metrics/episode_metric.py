"""The interface of an episode metric: one number (seconds) per finished episode, with a reason code.

A metric sees an `Episode` (the applied actions and what the episode was) and returns flat log fields. By
convention every metric named `<name>` writes `<name>_s` (seconds, None when not valid) and `<name>_reason`, plus
any extra fields it lists; the episode log writes them on each episode's line (all None when the metric does
not apply) and `tavis report` summarises `<name>_s` and `<name>_reason` per task x split (median, IQR, valid
count, reason counts), with a table and, when the metric has a `Histogram`, a plot per task.

Adding a metric: one module defining an `EpisodeMetric` subclass instance, plus one line in
`lerobot_tavis.metrics.logged_metrics`.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Episode:
    """One finished episode as a metric sees it."""

    actions: np.ndarray  # (T, 19) canonical actions the env applied, one row per policy step (frames: canonical.py)
    fps: float  # policy steps per second (20 in evaluation): step t happens at t / fps seconds
    success: bool
    suite: str  # tavis_head or tavis_hands
    camera_mode: str


@dataclass(frozen=True)
class Histogram:
    """A per-task histogram of a metric's valid values (seconds), written as `<name>_<task>.png`."""

    start_s: float
    stop_s: float
    step_s: float
    xlabel: str

    def bins(self) -> np.ndarray:
        return np.arange(self.start_s, self.stop_s, self.step_s)


class EpisodeMetric(ABC):
    """A per-episode time in seconds with a reason code, logged as `<name>_*` fields and summarised by the report.

    Subclasses set `name`, `fields` (every log field, in log order: `<name>_s` and `<name>_reason` among them),
    `caption` (the sentence above its table in results.md) and optionally `histogram`.
    """

    name: str
    fields: tuple[str, ...]
    caption: str
    histogram: Histogram | None = None

    @abstractmethod
    def applies(self, episode: Episode) -> bool:
        """Whether the metric is measured on this episode (else all its fields are None)."""

    @abstractmethod
    def measure(self, episode: Episode) -> dict:
        """The fields of an episode it applies to (a subset of `fields`; missing ones are logged as None)."""

    def log_fields(self, episode: Episode) -> dict:
        """Every field in `fields` order: measured when the metric applies, else None."""
        values = self.measure(episode) if self.applies(episode) else {}
        unknown = set(values) - set(self.fields)
        if unknown:
            raise ValueError(f"metric {self.name!r} measured fields it does not list: {sorted(unknown)}")
        return {name: values.get(name) for name in self.fields}

    @property
    def value_field(self) -> str:
        return f"{self.name}_s"

    @property
    def reason_field(self) -> str:
        return f"{self.name}_reason"
