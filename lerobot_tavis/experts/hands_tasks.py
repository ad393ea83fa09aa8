"""Demonstrators for the TAVIS-Hands tasks: a wrist camera goes to look before the arm commits to an approach."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from lerobot_tavis.envs.scene import TABLE_TOP_Z
from lerobot_tavis.experts.base import Hold, Move, Segment
from lerobot_tavis.experts.grasping import PITCHES_RAD
from lerobot_tavis.experts.head_tasks import LIFT, ClutterExpert
from lerobot_tavis.experts.skills import SkilledExpert

HIGH_LIFT = (0.0, 0.0, 0.29)  # success needs the origin above `HIGH_LIFT_HEIGHT_M` = 1.25 m
SIDE_OF = {"+y": "left", "-y": "right"}
# where a hand may peek into the box from (box frame, m): back toward the robot from the nominal spot, out from
# the open side, height of the wrist; the first reachable one is used
PEEK_BACK_M = (0.0, 0.06, 0.12, 0.18)
PEEK_OUT_M = (0.24, 0.20, 0.16, 0.12)
PEEK_Z_M = (1.12, 1.17)
FINGERTIP_BEYOND_GRASP_M = 0.03
BOX_CLEARANCE_M = 0.01
UNDER_PANEL_PITCHES_RAD = np.radians((15.0, 5.0, 30.0, 45.0, 60.0))


class PeekingBoxExpert(SkilledExpert):
    """Look at the box, peek into both sides with the wrist cameras, then reach in through the open side."""

    def behaviour(self) -> Iterator[Segment]:
        box = self.facts  # PeekingBoxFacts
        box_point = box.point
        yield Hold(self.uniform(0.2, 0.4))
        yield from self.fixate(box_point(0.0, 0.0, box.top_z_m), (0.3, 0.5))
        for opening in self.rng.permutation(["+y", "-y"]):
            sign = 1.0 if opening == "+y" else -1.0
            side = SIDE_OF[opening]
            along = self.uniform(-0.05, 0.0)
            inside = box_point(self.uniform(-0.02, 0.04), 0.0, TABLE_TOP_Z + 0.05)
            # beside the opening, far enough out that the fingertips stay outside the box while the wrist camera
            # looks in; nearer the body where the arm cannot reach that far
            options = sorted(((along - back, out, z) for back in PEEK_BACK_M for out in PEEK_OUT_M for z in PEEK_Z_M),
                             key=lambda o: abs(o[0] - along) + PEEK_OUT_M[0] - o[1] + o[2] - PEEK_Z_M[0])
            wrists = [box_point(dx, sign * (box.half_width_m + out), z) for dx, out, z in options]
            outside = self.reachable_view(side, [w for w in wrists if self._fingertips_outside(w, inside)], inside)
            yield from self.fixate(outside, (0.1, 0.2))
            yield from self.peek(side, outside, inside)
            if opening == box.open_side:
                break
            yield Move(self.at_rest(side=side), self.uniform(0.6, 0.9))
        side = SIDE_OF[box.open_side]
        sign = 1.0 if box.open_side == "+y" else -1.0
        into_box = box.yaw_rad - sign * np.pi / 2  # approach direction through the opening
        out = np.array([*(box.rotation @ (0.0, sign * 0.22)), 0.0])  # back out through the opening
        yield from self.look_and_pick(box.target, side=side, pre_rise_m=(0.0, 0.01),
                                      carry_path=[out, out + HIGH_LIFT], toward_rad=float(into_box),
                                      max_azimuth_rad=0.9, pitches_rad=np.radians((15.0, 25.0, 5.0, 35.0)))

    def _fingertips_outside(self, wrist, look_at) -> bool:
        """Whether the fingertips of a hand at `wrist` (world, m) pointing at `look_at` stay clear of the box."""
        box = self.facts  # PeekingBoxFacts
        direction = (look_at - wrist) / np.linalg.norm(look_at - wrist)
        tip = wrist + (self.ik.robot.gripper.grasp_depth_m + FINGERTIP_BEYOND_GRASP_M) * direction
        x, y = box.to_box(tip[:2])
        wall = box.wall_m + BOX_CLEARANCE_M
        return bool(abs(y) > box.half_width_m + wall or x < -box.half_depth_m - wall or tip[2] > box.top_z_m + wall)


class OccludedReachExpert(SkilledExpert):
    """Look at the screen, bring a hand to its edge so the wrist camera sees behind it, then reach around."""

    def behaviour(self) -> Iterator[Segment]:
        facts = self.facts  # OccludedReachFacts
        target, _ = self.body_pose(facts.target)
        yield Hold(self.uniform(0.2, 0.4))
        yield from self.fixate((facts.screen_x_m, 0.0, 1.2), (0.3, 0.5))
        side = self.side_for(target) if abs(target[1]) > 0.05 else ("left", "right")[self.rng.integers(2)]
        sign = 1.0 if side == "left" else -1.0
        order = [side] if self.rng.random() < 0.6 else [("right" if side == "left" else "left"), side]
        for peeking in order:
            s = 1.0 if peeking == "left" else -1.0
            edge = np.array([facts.screen_x_m - 0.03, s * self.uniform(0.17, 0.21), self.uniform(1.18, 1.24)])
            behind = np.array([self.uniform(0.42, 0.48), s * self.uniform(-0.02, 0.06), TABLE_TOP_Z + 0.03])
            yield from self.fixate(edge, (0.1, 0.2))
            yield from self.peek(peeking, edge, behind)
            if peeking != side:
                yield Move(self.at_rest(side=peeking), self.uniform(0.6, 0.9))
        toward = float(np.arctan2(target[1] - sign * 0.18, target[0] - facts.screen_x_m))
        # right behind the panel, a flat hand passes under it (beside the post) more easily than around its edge
        under = abs(target[1]) < facts.panel_half_width_m
        yield from self.look_and_pick(facts.target, HIGH_LIFT, side=side, toward_rad=toward, max_azimuth_rad=0.8,
                                      pitches_rad=UNDER_PANEL_PITCHES_RAD if under else PITCHES_RAD,
                                      pre_rise_m=(0.0, 0.01) if under else (0.05, 0.08))


class BlockedClutterExpert(ClutterExpert):
    """The head camera is black: sweep a hand over the table with its wrist camera looking down, then pick."""

    def behaviour(self) -> Iterator[Segment]:
        facts = self.facts  # TargetFacts
        cube, _ = self.body_pose(facts.target)
        yield Hold(self.uniform(0.2, 0.4))
        side = self.side_for(cube)
        sign = 1.0 if side == "left" else -1.0
        stops = sorted(self.rng.uniform(-0.05, 0.25, size=int(self.rng.integers(2, 4))) * sign, reverse=sign > 0)
        for y in [*stops, cube[1]]:
            x = self.uniform(0.36, 0.44) if y != cube[1] else cube[0]
            over = np.array([x - 0.12, y, TABLE_TOP_Z + 0.30])
            yield from self.peek(side, over, (x, y, TABLE_TOP_Z), duration_s=(0.5, 0.8), dwell_s=(0.3, 0.5),
                                 base=self.looking_at((x, y, TABLE_TOP_Z)))
        yield from self.look_and_pick(facts.target, LIFT, side=side)
