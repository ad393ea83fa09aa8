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
from lerobot_tavis.envs.reach import REACHED_M
from lerobot_tavis.experts.base import Expert, Hold, Move, Segment, play
from lerobot_tavis.experts.gaze import GazeSolver
from lerobot_tavis.experts.grasping import Grasp, carry_options, grasp_candidates
from lerobot_tavis.experts.imagination import Imagination

SLOTS = {"left": canonical.LEFT, "right": canonical.RIGHT}
IMAGINED_ROLLOUTS = 24  # picks tried in imagination before settling for the best of them
VIEW_POSITION_TOLERANCE_M = 0.015  # how closely a looking pose must be reachable
VIEW_ANGLE_TOLERANCE_RAD = 0.1


class SkilledExpert(Expert):
    """An expert with the shared skills; subclasses write `behaviour()` with them."""

    def reset(self) -> None:
        if not hasattr(self, "ik"):
            self.ik = ArmIK(self.env.world.robot)
            self.gaze = GazeSolver(self.env.world)
            self.imagination = Imagination(self.env.world)
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

    def view_action(self, side: str, wrist_at, look_at, base: np.ndarray | None = None) -> np.ndarray:
        """`base` (default: the current command) with `side`'s hand at `wrist_at` pointing toward `look_at` (world,
        m), so that its wrist camera looks there, gripper open."""
        wrist_at, look_at = np.asarray(wrist_at, dtype=float), np.asarray(look_at, dtype=float)
        delta = look_at - wrist_at
        pitch = float(np.arctan2(-delta[2], np.linalg.norm(delta[:2])))
        view = Grasp(side, look_at, pitch, float(np.arctan2(delta[1], delta[0])), flipped=False)
        offset = float(np.linalg.norm(delta)) - self.ik.robot.gripper.grasp_depth_m
        action = view.action(self.ik, self.command if base is None else base, offset_m=offset)
        action[SLOTS[side].gripper] = canonical.GRIPPER_OPEN
        return action

    def reachable_view(self, side: str, wrist_options, look_at) -> np.ndarray:
        """The first of `wrist_options` (world, m; in order of preference) from which `side`'s hand can point at
        `look_at`, by the arm's kinematics; the nearest miss if none can."""
        misses = []
        for wrist_at in wrist_options:
            position_error, angle_error = self.ik.reach_error(
                self.view_action(side, wrist_at, look_at, canonical.rest_action()), side)
            if position_error < VIEW_POSITION_TOLERANCE_M and angle_error < VIEW_ANGLE_TOLERANCE_RAD:
                return np.asarray(wrist_at, dtype=float)
            misses.append((position_error + self.ik.robot.gripper.grasp_depth_m * angle_error, len(misses), wrist_at))
        return np.asarray(min(misses)[2], dtype=float)

    def peek(self, side: str, wrist_at, look_at, duration_s=(0.8, 1.1), dwell_s=(0.4, 0.7),
             base: np.ndarray | None = None) -> Iterator[Segment]:
        """Move one hand so that it points from `wrist_at` toward `look_at` (world, m): its wrist camera then looks
        there; dwell, keeping the gaze still."""
        yield Move(self.view_action(side, wrist_at, look_at, base), self.uniform(*duration_s))
        yield Hold(self.uniform(*dwell_s))

    def candidates(self, name: str, side: str, carry_m, **kwargs):
        """Grasps of prop `name` (see `grasp_candidates`) whose approach avoids the other props near it."""
        center, yaw = self.body_pose(name)
        obstacles = [(pos[:2], PROPS[other].footprint_radius_m, pos[2] + PROPS[other].height_m / 2)
                     for other in self.facts.props
                     if other != name and abs((pos := self.body_pose(other)[0])[2] - center[2]) < 0.1]
        return grasp_candidates(self.ik, side, PROPS[name], center, yaw, carry_m=carry_m, obstacles=obstacles,
                                **kwargs)

    def look_and_pick(self, name: str, carry_m=(0.0, 0.0, 0.24), side: str | None = None,
                      pre_rise_m: tuple[float, float] = (0.05, 0.08),
                      carry_path: list | None = None, attempts: int = 3, **plan_kwargs) -> Iterator[Segment]:
        """Saccade to the object and reach for it (the eyes land during the reach or just before it), grasp
        with a closing ramp at the end of the approach, carry it by `carry_m` (world, m; or through the offsets of
        `carry_path`) and hold. `plan_kwargs` go to `grasp_candidates`; candidates are tried in
        imagination first and the first that works is executed. A grasp that closes on nothing is retried,
        re-planned from where the object now is, like a person having another go."""
        side = side or self.side_for(self.body_pose(name)[0])
        carry = np.asarray((carry_path or [carry_m])[-1], dtype=float)
        for _ in range(attempts):
            reach, hold = self._imagine_pick(name, side, carry, pre_rise_m, carry_path, plan_kwargs)
            yield from reach
            if self.holding(self.env.data, side, name):
                yield from hold
                return
            yield Move(reach[-4].target, self.uniform(0.5, 0.7))  # open and back off to the pre-grasp, try again
        yield Hold(np.inf)

    def _imagine_pick(self, name, side, carry, pre_rise_m, carry_path, plan_kwargs) -> tuple[list, list]:
        """Segments of the first pick that succeeds in imagination (grasp candidates in order of preference; for
        a grasp that holds, its ways of carrying), else of the one that got the object nearest to success."""
        best, best_progress, rollouts = None, -np.inf, 0
        for grasp in self.candidates(name, side, carry, **plan_kwargs):
            reach, hold = self._pick_segments(name, side, grasp, pre_rise_m, carry_path)
            options = [hold] + [self._carry_segments(option, name, carry_path)
                                for option in carry_options(grasp, grasp.carry_offset_m)[1:]]
            for hold in options:
                progress = self._imagined_progress(reach, hold, side, name, carry)
                rollouts += 1
                if progress >= 1.0:
                    return reach, hold
                if progress > best_progress:
                    best, best_progress = (reach, hold), progress
                if progress < 0 or rollouts >= IMAGINED_ROLLOUTS:
                    break  # not even grasped: other ways of carrying will not help
            if rollouts >= IMAGINED_ROLLOUTS:
                break
        return best

    def _pick_segments(self, name, side, grasp: Grasp, pre_rise_m, carry_path) -> tuple[list, list]:
        """The segments of one pick: reaching and closing, then carrying and holding."""
        look = self.looking_at(self.body_pose(name)[0])
        head_s = self.saccade_s()
        pre = grasp.action(self.ik, look, offset_m=self.uniform(0.08, 0.11))
        pre[SLOTS[side].position][2] += self.uniform(*pre_rise_m)
        if self.rng.random() < 0.5:  # the hand sets off first; the eyes jump to the object during the reach
            reach = [Move(pre, self.uniform(0.6, 0.8), head_s=head_s, head_delay_s=self.uniform(0.3, 0.55))]
        else:  # the eyes land first, a short fixation, then the reach
            reach = [Move(look, head_s, head_s=head_s), Hold(self.uniform(0.0, 0.1)),
                     Move(pre, self.uniform(0.4, 0.55))]
        reach += [
            Move(pre, self.uniform(0.05, 0.1)),  # the arm catches up with the pre-grasp pose
            Move(grasp.action(self.ik, look), self.uniform(0.45, 0.6)),
            # close with a quick ramp once there (the command crosses 0 halfway; the fingers follow at their own
            # speed), then let them squeeze
            Move(grasp.action(self.ik, look, closed=True), self.uniform(0.12, 0.2)),
            Hold(self.uniform(0.15, 0.3)),
        ]
        return reach, self._carry_segments(grasp, name, carry_path)

    def _carry_segments(self, grasp: Grasp, name: str, carry_path) -> list[Segment]:
        look = self.looking_at(self.body_pose(name)[0])
        hold = [Move(grasp.moved(offset).action(self.ik, look, closed=True), self.uniform(0.9, 1.3))
                for offset in (carry_path or [])[:-1]]
        hold.append(Move(grasp.carried().action(self.ik, look, closed=True), self.uniform(0.9, 1.3)))
        return hold

    def _imagined_progress(self, reach: list[Segment], hold: list[Segment], side: str, name: str,
                           carry: np.ndarray) -> float:
        """Play a pick in imagination: 1.0 if the task succeeds with the object in hand, else the fraction of the
        carry the object followed; -1 if it was not grasped."""
        body = self.env.model.body(name).id
        start = self.env.data.xpos[body].copy()
        data = self.imagination.rollout(self.env.data, self.env.controller, play(reach + hold, self.command))
        if not self.holding(data, side, name):
            return -1.0
        if self.facts.succeeds(data):
            return 1.0
        return float(np.dot(data.xpos[body] - start, carry) / max(np.dot(carry, carry), 1e-9))

    def holding(self, data, side: str, name: str) -> bool:
        """Whether prop `name` is between the (not fully closed) fingers of `side`'s hand in `data`."""
        arm = self.env.world.arms[side]
        opening = data.qpos[arm.finger_qpos[0]]
        near = np.linalg.norm(data.site_xpos[arm.grasp_site] - data.xpos[self.env.model.body(name).id]) < REACHED_M
        return bool(opening > 0.004 and near)
