"""Reusable human-like behaviours for the demonstrators: saccades and fixations, scans, peeks, reach-grasp-lift.

Timing follows people: saccades of 0.15-0.25 s then still fixations; the hand starts toward the target while or
just after the eyes land on it, so the gaze leads the grasp by roughly 0.5-1.2 s; minimum-jerk arm motion; the
gripper closes with a ramp at the end of the approach; lifts at a human pace. Every duration is drawn from the
expert's generator, so a dataset is not one trajectory repeated.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from lerobot_tavis import canonical
from lerobot_tavis.envs.control import ArmIK
from lerobot_tavis.envs.objects import PROPS
from lerobot_tavis.experts.base import Expert, Hold, Move, Segment
from lerobot_tavis.experts.gaze import GazeSolver
from lerobot_tavis.experts.grasping import Grasp, plan_grasp

SLOTS = {"left": canonical.LEFT, "right": canonical.RIGHT}


class SkilledExpert(Expert):
    """An expert with the shared skills; subclasses write `behaviour()` with them."""

    def reset(self) -> None:
        if not hasattr(self, "ik"):
            self.ik = ArmIK(self.env.world.robot)
            self.gaze = GazeSolver(self.env.world)
        super().reset()

    # -- state --------------------------------------------------------------------------------------------
    def body_pose(self, name: str) -> tuple[np.ndarray, float]:
        """World position of a body's origin and its yaw (rad)."""
        model, data = self.env.model, self.env.data
        body = model.body(name).id
        rotation = data.xmat[body].reshape(3, 3)
        return data.xpos[body].copy(), float(np.arctan2(rotation[1, 0], rotation[0, 0]))

    def side_for(self, point) -> str:
        """The arm on the point's side of the body (y >= 0: left)."""
        return "left" if point[1] >= 0 else "right"

    # -- gaze -------------------------------------------------------------------------------------------------
    def looking_at(self, point, base: np.ndarray | None = None) -> np.ndarray:
        action = (self.command if base is None else base).copy()
        action[canonical.HEAD_PITCH], action[canonical.HEAD_YAW] = self.gaze.angles_to(point)
        action[canonical.HEAD_ROLL] = 0.0
        return action

    def saccade_s(self) -> float:
        return self.uniform(0.15, 0.25)

    def fixate(self, point, fixation_s: tuple[float, float] = (0.3, 0.6)) -> Iterator[Segment]:
        """A saccade to `point` (world) followed by a still fixation."""
        head_s = self.saccade_s()
        yield Move(self.looking_at(point), head_s, head_s=head_s)
        yield Hold(self.uniform(*fixation_s))

    def scan(self, points, fixation_s=(0.3, 0.6)) -> Iterator[Segment]:
        for point in points:
            yield from self.fixate(point, fixation_s)

    # -- hands ------------------------------------------------------------------------------------------------
    def at_rest(self, base: np.ndarray | None = None, side: str | None = None) -> np.ndarray:
        """`base` with one arm (or both) back at the rest pose."""
        rest = canonical.rest_action()
        action = (self.command if base is None else base).copy()
        for s, slots in SLOTS.items():
            if side in (None, s):
                action[slots.position], action[slots.quaternion] = rest[slots.position], rest[slots.quaternion]
        return action

    def peek(self, side: str, wrist_at, look_at, duration_s=(0.8, 1.1), dwell_s=(0.4, 0.7),
             base: np.ndarray | None = None) -> Iterator[Segment]:
        """Move one hand so that it points from `wrist_at` toward `look_at` (world, m): its wrist camera then looks
        there; dwell, keeping the gaze still."""
        wrist_at, look_at = np.asarray(wrist_at, dtype=float), np.asarray(look_at, dtype=float)
        delta = look_at - wrist_at
        pitch = float(np.arctan2(-delta[2], np.linalg.norm(delta[:2])))
        view = Grasp(side, look_at, pitch, float(np.arctan2(delta[1], delta[0])), flipped=False)
        offset = float(np.linalg.norm(delta)) - self.ik.robot.gripper.grasp_depth_m
        action = view.action(self.ik, self.command if base is None else base, offset_m=offset)
        action[SLOTS[side].gripper] = canonical.GRIPPER_OPEN
        yield Move(action, self.uniform(*duration_s))
        yield Hold(self.uniform(*dwell_s))

    def plan(self, name: str, side: str, carry_m, **kwargs) -> Grasp:
        """A grasp of prop `name` whose approach avoids the other props near it."""
        center, yaw = self.body_pose(name)
        obstacles = [(pos[:2], PROPS[other].footprint_radius_m, pos[2] + PROPS[other].height_m / 2)
                     for other in self.env.task_object.props()
                     if other != name and abs((pos := self.body_pose(other)[0])[2] - center[2]) < 0.1]
        return plan_grasp(self.ik, side, PROPS[name], center, yaw, carry_m=carry_m, obstacles=obstacles, **kwargs)

    def look_and_pick(self, name: str, carry_m=(0.0, 0.0, 0.24), side: str | None = None,
                      pre_rise_m: tuple[float, float] = (0.05, 0.08),
                      carry_path: list | None = None, attempts: int = 3, **plan_kwargs) -> Iterator[Segment]:
        """Saccade to the object and reach for it (the hand sets off with the saccade or just after the eyes
        land), grasp with a closing ramp at the end of the approach, carry it by `carry_m` (world, m; or through
        the offsets of `carry_path`) and hold. `plan_kwargs` go to `plan_grasp`. A grasp that closes on nothing
        is retried, re-planned from where the object now is, like a person having another go."""
        center, _ = self.body_pose(name)
        side = side or self.side_for(center)
        slots = SLOTS[side]
        for attempt in range(attempts):
            center, _ = self.body_pose(name)
            grasp = self.plan(name, side, (carry_path or [carry_m])[-1], **plan_kwargs)
            head_s = self.saccade_s()
            look = self.looking_at(center)
            pre = grasp.action(self.ik, look, offset_m=self.uniform(0.08, 0.11))
            pre[slots.position][2] += self.uniform(*pre_rise_m)
            if self.rng.random() < 0.5:  # reach together with the saccade
                yield Move(pre, self.uniform(0.6, 0.8), head_s=head_s)
            else:  # a short fixation first
                yield Move(look, head_s, head_s=head_s)
                yield Hold(self.uniform(0.0, 0.15))
                yield Move(pre, self.uniform(0.55, 0.75))
            yield Hold(self.uniform(0.05, 0.15))  # the arm catches up with the pre-grasp pose
            yield Move(grasp.action(self.ik, look), self.uniform(0.55, 0.75))
            # close with a ramp once there (the command crosses 0 halfway), then let the fingers squeeze
            yield Move(grasp.action(self.ik, look, closed=True), self.uniform(0.2, 0.35))
            yield Hold(self.uniform(0.15, 0.3))
            if self.holding(side, name):
                break
            yield Move(pre, self.uniform(0.5, 0.7))  # open and back off, then try again
        for offset in (carry_path or [])[:-1]:
            yield Move(grasp.moved(offset).action(self.ik, look, closed=True), self.uniform(0.9, 1.3))
        yield Move(grasp.carried().action(self.ik, look, closed=True), self.uniform(0.9, 1.3))
        yield Hold(np.inf)

    def holding(self, side: str, name: str) -> bool:
        """Whether prop `name` is between the (not fully closed) fingers of `side`'s hand."""
        arm = self.env.world.arms[side]
        data = self.env.data
        opening = data.qpos[arm.finger_qpos[0]]
        near = np.linalg.norm(data.site_xpos[arm.grasp_site] - self.body_pose(name)[0]) < 0.05
        return bool(opening > 0.004 and near)
