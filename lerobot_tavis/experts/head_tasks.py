"""Demonstrators for the TAVIS-Head tasks: the head finds what matters, then the hand follows."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from lerobot_tavis.envs.scene import TABLE_TOP_Z
from lerobot_tavis.experts.base import Hold, Segment, WaitUntil
from lerobot_tavis.experts.skills import SkilledExpert

LIFT = (0.0, 0.0, 0.24)  # object origins start near 1.01-1.05 m; success needs > `LIFT_HEIGHT_M` = 1.2 m
PULL_OUT = (-0.18, 0.0, 0.02)  # out of the shelf: success needs x < `SHELF_EXIT_X_M` = 0.435 m


class ConditionalPickExpert(SkilledExpert):
    """Look at the card, sometimes glance at both objects, then pick the one the colour points to."""

    def behaviour(self) -> Iterator[Segment]:
        facts = self.facts  # ConditionalPickFacts
        yield Hold(self.uniform(0.2, 0.5))
        card, _ = self.body_pose(facts.cue_card)
        yield from self.fixate(card, (0.4, 0.8))
        if self.rng.random() < 0.4:
            first, second = self.rng.permutation([facts.left_object, facts.right_object])
            yield from self.scan([self.body_pose(first)[0], self.body_pose(second)[0]], (0.25, 0.45))
        yield from self.look_and_pick(facts.target, LIFT)


class WaitThenActExpert(SkilledExpert):
    """Glance at the object, watch the light until it turns green, react, then pick the object."""

    def behaviour(self) -> Iterator[Segment]:
        facts = self.facts  # WaitThenActFacts
        yield Hold(self.uniform(0.2, 0.5))
        if self.rng.random() < 0.5:
            yield from self.fixate(self.body_pose(facts.target)[0], (0.3, 0.6))
        yield from self.fixate(self.body_pose(facts.light)[0], (0.1, 0.2))
        yield WaitUntil(facts.light_is_green)
        yield Hold(self.uniform(0.2, 0.4))  # reaction time
        yield from self.look_and_pick(facts.target, LIFT)


class ClutterExpert(SkilledExpert):
    """Scan the clutter with a few fixations (left to right or right to left), then pick the target."""

    def behaviour(self) -> Iterator[Segment]:
        facts = self.facts  # TargetFacts
        yield Hold(self.uniform(0.2, 0.5))
        present = [n for n in facts.props if self._on_table(n)]  # the props taken away are parked on the floor
        others = [n for n in present if n != facts.target]
        looked = list(self.rng.choice(others, size=min(len(others), int(self.rng.integers(2, 4))), replace=False))
        points = sorted((self.body_pose(n)[0] for n in looked), key=lambda p: p[1], reverse=bool(self.rng.integers(2)))
        yield from self.scan(points, (0.25, 0.5))
        yield from self.look_and_pick(facts.target, LIFT)

    def _on_table(self, name: str) -> bool:
        return self.body_pose(name)[0][2] > TABLE_TOP_Z


class ShelfExpert(SkilledExpert):
    """Scan the shelves (several slots, top to bottom or bottom to top), then take the target out."""

    def behaviour(self) -> Iterator[Segment]:
        facts = self.facts  # TargetFacts
        yield Hold(self.uniform(0.2, 0.5))
        others = [n for n in facts.props if n != facts.target]
        looked = self.rng.choice(others, size=int(self.rng.integers(2, 4)), replace=False)
        points = sorted((self.body_pose(n)[0] for n in looked), key=lambda p: p[2], reverse=bool(self.rng.integers(2)))
        yield from self.scan(points, (0.25, 0.5))
        center, _ = self.body_pose(facts.target)
        side = self.side_for(center)
        yield from self.look_and_pick(facts.target, PULL_OUT, side=side, pre_rise_m=(0.0, 0.01),
                                      pitches_rad=np.radians((10.0, 0.0, 20.0, 30.0)), max_azimuth_rad=0.9,
                                      toward_rad=0.0)
