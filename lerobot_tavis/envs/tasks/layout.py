"""Sampling object layouts on the table as densely as the reference does, without objects inside each other.

The reference's sampler (IsaacLab's, docs/reference.md §4) places objects one after another: for each,
it draws up to 5000 uniform poses and takes the first whose centre is farther than the split's minimum separation
from every centre placed so far; when none is, it takes the 5000th pose, separation or not (about 30% of
clutter_pick_cube `id` resets), which packs the clutter tighter than the separation says. It checks centres only,
so a quarter of its clutter layouts start with two objects inside each other, which its physics then shoves apart
as they drop. `sample_layout` takes the pose that rule takes and, where its footprint (the object's outline seen
from above) overlaps one already placed, slides it straight away from that one until CONTACT_GAP_M separates them,
as the shove would; only if that fails (PUSH_LIMIT_M) does it take the last drawn pose that overlaps nothing.
Objects therefore never start inside each other, and the clutter is as dense as the reference's after its drop
(closest-pair distributions in docs/tasks.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

CONTACT_GAP_M = 0.002
REFERENCE_TRIES = 5000
PUSH_STEP_M = 0.001
PUSH_LIMIT_M = 0.15
MAX_RESTARTS = 100


@dataclass(frozen=True)
class Box2D:
    """An axis-aligned range of positions on the table (world x and y, m)."""

    x: tuple[float, float]
    y: tuple[float, float]

    def sample(self, rng: np.random.Generator) -> np.ndarray:
        return np.array([rng.uniform(*self.x), rng.uniform(*self.y)])

    def contains(self, xy, tol: float = 1e-9) -> bool:
        return self.x[0] - tol <= xy[0] <= self.x[1] + tol and self.y[0] - tol <= xy[1] <= self.y[1] + tol


@dataclass(frozen=True)
class Footprint:
    """An object's outline seen from above: a circle of `radius_m`, or a rectangle of half sizes `half_xy_m` in the
    object's frame (turned by its yaw)."""

    radius_m: float | None = None
    half_xy_m: tuple[float, float] | None = None

    def __post_init__(self):
        if (self.radius_m is None) == (self.half_xy_m is None):
            raise ValueError("a footprint is either a circle (radius_m) or a rectangle (half_xy_m)")


@dataclass(frozen=True)
class Pose2D:
    """Where an object stands: centre (m) and yaw about z (rad)."""

    xy: np.ndarray
    yaw: float


def sample_layout(rng: np.random.Generator, region: Box2D, footprints: list[Footprint], min_separation_m: float,
                  tries: int = REFERENCE_TRIES) -> list[Pose2D]:
    """Poses (centres uniform in `region`, yaw uniform in [-pi, pi)) for `footprints`, in order: see the module."""
    for _ in range(MAX_RESTARTS):
        placed: list[tuple[Pose2D, Footprint]] = []
        for footprint in footprints:
            xy = np.column_stack([rng.uniform(*region.x, size=tries), rng.uniform(*region.y, size=tries)])
            yaw = rng.uniform(-np.pi, np.pi, size=tries)
            separated = np.ones(tries, dtype=bool)
            clear = np.ones(tries, dtype=bool)
            for pose, other in placed:
                separated &= np.linalg.norm(xy - pose.xy, axis=1) > min_separation_m
                clear &= ~overlaps(xy, yaw, footprint, pose, other, CONTACT_GAP_M)
            chosen = np.flatnonzero(separated)
            pose = Pose2D(xy[chosen[0] if len(chosen) else -1], float(yaw[chosen[0] if len(chosen) else -1]))
            pose = _push_clear(pose, footprint, placed, region)
            if pose is None:
                fallback = np.flatnonzero(clear)
                if len(fallback) == 0:
                    break
                pose = Pose2D(xy[fallback[-1]], float(yaw[fallback[-1]]))
            placed.append((pose, footprint))
        if len(placed) == len(footprints):
            return [pose for pose, _ in placed]
    raise RuntimeError(f"no layout of {len(footprints)} objects fits in {region} without overlaps")


def _push_clear(pose: Pose2D, footprint: Footprint, placed: list[tuple[Pose2D, Footprint]],
                region: Box2D) -> Pose2D | None:
    """`pose` slid in PUSH_STEP_M steps straight away from whichever placed object it overlaps, until it overlaps
    none (then it is returned) or it has slid PUSH_LIMIT_M or left `region` (then None)."""
    xy = pose.xy.copy()
    for _ in range(round(PUSH_LIMIT_M / PUSH_STEP_M)):
        hit = next((other_pose for other_pose, other in placed
                    if overlaps(xy[None], np.array([pose.yaw]), footprint, other_pose, other, CONTACT_GAP_M)[0]), None)
        if hit is None:
            return Pose2D(xy, pose.yaw)
        away = xy - hit.xy
        norm = np.linalg.norm(away)
        xy = xy + PUSH_STEP_M * (away / norm if norm > 1e-9 else np.array([0.0, 1.0]))
        if not region.contains(xy):
            return None
    return None


def overlaps(xy: np.ndarray, yaw: np.ndarray, footprint: Footprint, pose: Pose2D, other: Footprint,
             gap_m: float) -> np.ndarray:
    """Whether `footprint` at each of the poses (xy (N, 2), yaw (N,)) comes nearer than `gap_m` to `other` at
    `pose`, as a boolean array (N,)."""
    if footprint.radius_m is not None and other.radius_m is not None:
        return np.linalg.norm(xy - pose.xy, axis=1) < footprint.radius_m + other.radius_m + gap_m
    if footprint.radius_m is not None:  # a circle against the placed rectangle
        return _circle_hits_rectangle(xy, footprint.radius_m + gap_m, pose.xy, pose.yaw, other.half_xy_m)
    if other.radius_m is not None:  # a rectangle against the placed circle
        return _circle_hits_rectangle(np.broadcast_to(pose.xy, xy.shape), other.radius_m + gap_m, xy, yaw,
                                      footprint.half_xy_m)
    return _rectangles_overlap(xy, yaw, footprint.half_xy_m, pose.xy, pose.yaw, other.half_xy_m, gap_m)


def _circle_hits_rectangle(centre, radius, rect_xy, rect_yaw, half_xy) -> np.ndarray:
    """Circles (centre (N, 2), radius) against rectangles centred at rect_xy turned by rect_yaw."""
    offset = centre - rect_xy
    c, s = np.cos(rect_yaw), np.sin(rect_yaw)
    local = np.column_stack([c * offset[:, 0] + s * offset[:, 1], -s * offset[:, 0] + c * offset[:, 1]])
    nearest = np.clip(local, -np.asarray(half_xy), np.asarray(half_xy))
    return np.linalg.norm(local - nearest, axis=1) < radius


def _rectangles_overlap(xy, yaw, half_xy, other_xy, other_yaw, other_half_xy, gap_m) -> np.ndarray:
    """Separating-axis test of rectangles (xy (N, 2), yaw (N,)) against one rectangle, each grown by gap_m / 2. The
    dot products are written out per component (the layouts of every seed depend on these exact sums)."""
    def axes(angle):  # the rectangles' two axes, each as its (x, y) components
        c, s = np.cos(angle), np.sin(angle)
        return (c, s), (-s, c)

    mine = axes(np.asarray(yaw, dtype=float))
    theirs = axes(np.array([other_yaw]))
    half = np.asarray(half_xy) + gap_m / 2
    other_half = np.asarray(other_half_xy) + gap_m / 2
    offset = np.asarray(other_xy) - xy
    separated = np.zeros(len(xy), dtype=bool)
    for ax, ay in (*mine, *theirs):
        reach = (half[0] * np.abs(ax * mine[0][0] + ay * mine[0][1])
                 + half[1] * np.abs(ax * mine[1][0] + ay * mine[1][1]))
        reach += (other_half[0] * np.abs(ax * theirs[0][0] + ay * theirs[0][1])
                  + other_half[1] * np.abs(ax * theirs[1][0] + ay * theirs[1][1]))
        separated |= np.abs(ax * offset[:, 0] + ay * offset[:, 1]) > reach
    return ~separated
