"""The scripted-demonstrator runtime: a behaviour is a generator of timed segments, played at the env's rate.

An expert's `behaviour()` yields segments one at a time; each starts from the action commanded when it starts, so
a behaviour can look at the (privileged) simulator state between segments to decide what to do next: the public
state of the env (`env.model`, `env.data`, `env.world` with the robot) and the facts its task declares for the
episode (`facts`, an `envs.tasks.base.EpisodeFacts`), never the task object itself. Segments:

- `Move`: arms, grippers and head to a target action; the arms follow a minimum-jerk profile over `duration_s`,
  the head a fast minimum-jerk saccade over `head_s` (starting `head_delay_s` into the move) then holds still, the
  grippers ramp linearly.
- `Hold`: keep the current command for `duration_s`.
- `WaitUntil`: keep the current command until `condition()` is true (or `timeout_s` passes).

Experts act only through the canonical 19-D action.
"""

from __future__ import annotations

import abc
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from lerobot_tavis import canonical
from lerobot_tavis.envs.physics import POLICY_HZ
from lerobot_tavis.experts.motion import interpolate_action, min_jerk

if TYPE_CHECKING:
    from lerobot_tavis.envs.tasks.base import EpisodeFacts

DT_S = 1.0 / POLICY_HZ


@dataclass(frozen=True)
class Move:
    target: np.ndarray
    duration_s: float
    head_s: float | None = None  # default: the head moves with the arms
    head_delay_s: float = 0.0  # the head starts its move this late (a saccade launched during a reach)

    def action_at(self, start: np.ndarray, t: float) -> np.ndarray:
        action = interpolate_action(start, self.target, float(min_jerk(t / self.duration_s)))
        head_s = self.head_s or self.duration_s
        s_head = float(min_jerk((t - self.head_delay_s) / head_s))
        action[canonical.HEAD] = start[canonical.HEAD] + s_head * (self.target[canonical.HEAD] - start[canonical.HEAD])
        s_grip = min(t / self.duration_s, 1.0)
        for arm in canonical.ARMS:
            action[arm.gripper] = start[arm.gripper] + s_grip * (self.target[arm.gripper] - start[arm.gripper])
        return action

    def done(self, t: float) -> bool:
        return t >= max(self.duration_s, self.head_delay_s + (self.head_s or 0.0)) - 1e-9


@dataclass(frozen=True)
class Hold:
    duration_s: float

    def action_at(self, start: np.ndarray, t: float) -> np.ndarray:
        return start.copy()

    def done(self, t: float) -> bool:
        return t >= self.duration_s - 1e-9


@dataclass(frozen=True)
class WaitUntil:
    condition: Callable[[], bool]
    timeout_s: float = 60.0

    def action_at(self, start: np.ndarray, t: float) -> np.ndarray:
        return start.copy()

    def done(self, t: float) -> bool:
        return t >= self.timeout_s or self.condition()


Segment = Move | Hold | WaitUntil


def play(segments: list[Segment], start: np.ndarray) -> list[np.ndarray]:
    """The actions (one per 1/20 s step) of a finite list of Move / Hold segments played from `start`."""
    actions, command = [], np.asarray(start, dtype=float)
    for segment in segments:
        segment_start, t = command.copy(), DT_S
        while True:
            command = segment.action_at(segment_start, t)
            actions.append(command.copy())
            if segment.done(t):
                break
            t += DT_S
    return actions


class Expert(abc.ABC):
    """Plays `behaviour()`; call `reset()` after each env reset, then `act()` once per env step."""

    def __init__(self, env, rng: np.random.Generator):
        self.env = env
        self.rng = rng
        self.dt_s = 1.0 / env.fps
        self.command = canonical.rest_action()

    @abc.abstractmethod
    def behaviour(self) -> Iterator[Segment]:
        ...

    def reset(self) -> None:
        self.command = canonical.rest_action()
        self._segments = self.behaviour()
        self._segment: Segment | None = None
        self._start = self.command
        self._t = 0.0

    def act(self) -> np.ndarray:
        """The action for the next env step (1 / env.fps seconds)."""
        if self._segment is not None and not self._segment.done(self._t):
            self._t += self.dt_s
        else:
            self._segment = self._next_segment()
            self._start, self._t = self.command.copy(), self.dt_s
        self.command = self._segment.action_at(self._start, self._t)
        return self.command.copy()

    def _next_segment(self) -> Segment:
        for segment in self._segments:
            if not segment.done(0.0):  # e.g. a WaitUntil whose condition already holds
                return segment
        return Hold(np.inf)

    @property
    def facts(self) -> EpisodeFacts:
        """What the task declares about the current episode (target, cue, landmarks, body names; see the task's
        `EpisodeFacts` subclass), taken when the env was reset."""
        return self.env.episode_facts

    def uniform(self, low: float, high: float) -> float:
        return float(self.rng.uniform(low, high))
