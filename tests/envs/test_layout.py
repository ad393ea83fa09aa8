"""The clutter layout sampler: the reference's separation rule, footprints that never overlap, the reference's
density."""

import itertools

import numpy as np
import pytest

from lerobot_tavis.envs.objects import OBJECT_NAMES, PROPS
from lerobot_tavis.envs.tasks.clutter_pick_lift.task import CLUTTER_VARIANTS, footprint
from lerobot_tavis.envs.tasks.layout import CONTACT_GAP_M, Box2D, Footprint, Pose2D, overlaps, sample_layout

CIRCLE = Footprint(radius_m=0.03)
BAR = Footprint(half_xy_m=(0.05, 0.01))  # 10 cm long along its x, 2 cm wide


def _overlap(a, pose_a, b, pose_b, gap=0.0) -> bool:
    return bool(overlaps(np.array([pose_a.xy]), np.array([pose_a.yaw]), a, pose_b, b, gap)[0])


@pytest.mark.parametrize("a, pose_a, b, pose_b, expected", [
    (CIRCLE, Pose2D(np.array([0.0, 0.0]), 0.0), CIRCLE, Pose2D(np.array([0.059, 0.0]), 0.0), True),
    (CIRCLE, Pose2D(np.array([0.0, 0.0]), 0.0), CIRCLE, Pose2D(np.array([0.061, 0.0]), 0.0), False),
    (BAR, Pose2D(np.array([0.0, 0.0]), 0.0), CIRCLE, Pose2D(np.array([0.079, 0.0]), 0.0), True),   # along the bar
    (BAR, Pose2D(np.array([0.0, 0.0]), 0.0), CIRCLE, Pose2D(np.array([0.0, 0.041]), 0.0), False),  # beside it
    (CIRCLE, Pose2D(np.array([0.0, 0.041]), 0.0), BAR, Pose2D(np.array([0.0, 0.0]), 0.0), False),  # either order
    (BAR, Pose2D(np.array([0.0, 0.0]), np.pi / 2), CIRCLE, Pose2D(np.array([0.0, 0.079]), 0.0), True),  # turned
    (BAR, Pose2D(np.array([0.0, 0.0]), 0.0), BAR, Pose2D(np.array([0.0, 0.019]), 0.0), True),      # side by side
    (BAR, Pose2D(np.array([0.0, 0.0]), 0.0), BAR, Pose2D(np.array([0.0, 0.021]), 0.0), False),
    (BAR, Pose2D(np.array([0.0, 0.0]), 0.0), BAR, Pose2D(np.array([0.0, 0.04]), np.pi / 2), True),  # a T
    (BAR, Pose2D(np.array([0.0, 0.0]), np.pi / 4), BAR, Pose2D(np.array([0.08, 0.0]), -np.pi / 4), True),  # a V
    (BAR, Pose2D(np.array([0.0, 0.0]), np.pi / 4), BAR, Pose2D(np.array([0.10, 0.0]), -np.pi / 4), False),
])
def test_footprints_overlap_exactly_when_their_outlines_meet(a, pose_a, b, pose_b, expected):
    assert _overlap(a, pose_a, b, pose_b) == expected


def test_a_gap_counts_as_overlap():
    assert not _overlap(CIRCLE, Pose2D(np.array([0.0, 0.0]), 0.0), CIRCLE, Pose2D(np.array([0.065, 0.0]), 0.0))
    assert _overlap(CIRCLE, Pose2D(np.array([0.0, 0.0]), 0.0), CIRCLE, Pose2D(np.array([0.065, 0.0]), 0.0), 0.01)


def test_roomy_layouts_keep_the_separation_and_are_deterministic():
    region = Box2D((0.0, 2.0), (0.0, 2.0))
    first = sample_layout(np.random.default_rng(3), region, [CIRCLE, BAR, BAR, CIRCLE], 0.3)
    again = sample_layout(np.random.default_rng(3), region, [CIRCLE, BAR, BAR, CIRCLE], 0.3)
    assert [p.xy.tolist() for p in first] == [p.xy.tolist() for p in again]
    assert all(np.linalg.norm(a.xy - b.xy) > 0.3 for a, b in itertools.combinations(first, 2))


def test_a_region_too_small_for_the_separation_packs_objects_touching_but_never_inside_each_other():
    region = Box2D((0.0, 0.1), (0.0, 0.1))
    footprints = [BAR] * 4
    for seed in range(20):
        poses = sample_layout(np.random.default_rng(seed), region, footprints, 0.5)
        for (i, a), (j, b) in itertools.combinations(enumerate(poses), 2):
            assert not _overlap(footprints[i], a, footprints[j], b, CONTACT_GAP_M - 1e-6)


@pytest.mark.parametrize("variant, violating", [("id", (0.15, 0.40)), ("ood_spatial", (0.0, 0.05))])
def test_clutter_is_as_dense_as_the_reference(variant, violating):
    """Six objects (clutter_pick_cube): the reference breaks the separation in about 30% of its id layouts (and in
    about 2% of the five-object ones); its median closest pair is about 0.10 m (id) and 0.07 m (ood_spatial)."""
    v = CLUTTER_VARIANTS[variant]
    footprints = [footprint(PROPS[name]) for name in (*OBJECT_NAMES, "red_cube")]
    rng = np.random.default_rng(0)
    closest = []
    for _ in range(200):
        poses = sample_layout(rng, v.region, footprints, v.min_separation_m)
        closest.append(min(np.linalg.norm(a.xy - b.xy) for a, b in itertools.combinations(poses, 2)))
    closest = np.array(closest)
    assert violating[0] <= (closest <= v.min_separation_m).mean() <= violating[1]
    assert np.median(closest) == pytest.approx({"id": 0.101, "ood_spatial": 0.070}[variant], abs=0.008)
