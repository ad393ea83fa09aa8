"""Clutter density: closest-pair distances of our layouts against the reference sampler's, per task and split.

    python benchmarks/layout_density.py [--layouts 2000] [--plot docs/images/layout_density.png]

The reference sampler is simulated as described in docs/reference.md §4 (centres uniform in the
zone, each object takes its first draw farther than the minimum separation from every placed centre, else its
5000th draw), with a uniform yaw per object so that interpenetrating pairs can be counted with the objects' real
outlines. Ours is `lerobot_tavis.envs.tasks.layout.sample_layout`. Prints a Markdown table and saves histograms.
"""

from __future__ import annotations

import argparse
import itertools
from pathlib import Path

import numpy as np

from lerobot_tavis.envs.objects import OBJECT_NAMES, PROPS, RED_CUBE
from lerobot_tavis.envs.tasks.clutter_pick_lift.task import CLUTTER_VARIANTS, ClutterVariant, footprint
from lerobot_tavis.envs.tasks.layout import REFERENCE_TRIES, Pose2D, overlaps, sample_layout

TASKS = {"clutter_pick_cube": (*OBJECT_NAMES, RED_CUBE.name), "clutter_pick_lift": OBJECT_NAMES}
CLOSE_M = 0.07


def reference_layout(rng: np.random.Generator, variant: ClutterVariant, count: int) -> list[Pose2D]:
    placed: list[Pose2D] = []
    for _ in range(count):
        for attempt in range(REFERENCE_TRIES):
            xy = variant.region.sample(rng)
            if attempt == REFERENCE_TRIES - 1 or all(np.linalg.norm(xy - p.xy) > variant.min_separation_m
                                                     for p in placed):
                placed.append(Pose2D(xy, float(rng.uniform(-np.pi, np.pi))))
                break
    return placed


def closest_pair_m(poses: list[Pose2D]) -> float:
    return min(float(np.linalg.norm(a.xy - b.xy)) for a, b in itertools.combinations(poses, 2))


def interpenetrating(poses: list[Pose2D], names) -> bool:
    return any(overlaps(a.xy[None], np.array([a.yaw]), footprint(PROPS[m]), b, footprint(PROPS[n]), 0.0)[0]
               for (a, m), (b, n) in itertools.combinations(zip(poses, names), 2))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--layouts", type=int, default=2000)
    parser.add_argument("--plot", type=Path, help="save the histograms here (PNG)")
    args = parser.parse_args()
    rows, histograms = [], {}
    for task, names in TASKS.items():
        footprints = [footprint(PROPS[n]) for n in names]
        for split, variant in CLUTTER_VARIANTS.items():
            rng = np.random.default_rng(0)
            reference = [reference_layout(rng, variant, len(names)) for _ in range(args.layouts)]
            ours = [sample_layout(rng, variant.region, footprints, variant.min_separation_m)
                    for _ in range(args.layouts)]
            for sampler, layouts in (("reference", reference), ("ours", ours)):
                closest = np.array([closest_pair_m(p) for p in layouts])
                inside = np.mean([interpenetrating(p, names) for p in layouts])
                histograms[(task, split, sampler)] = closest
                rows.append(f"| {task} | {split} | {sampler} | {np.median(closest):.3f} | "
                            f"{(closest < CLOSE_M).mean():.0%} | {(closest <= variant.min_separation_m).mean():.0%} | "
                            f"{inside:.0%} |")
    print(f"{args.layouts} layouts per row")
    print("| task | split | sampler | median closest pair (m) | closest pair < 7 cm | separation broken | "
          "objects inside each other |")
    print("|---|---|---|---|---|---|---|")
    print("\n".join(rows))
    if args.plot:
        plot(histograms, args.plot)


def plot(histograms: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(1, 4, figsize=(16, 3.4), sharey=False)
    bins = np.linspace(0.0, 0.25, 51)
    for axis, (task, split) in zip(axes, itertools.product(TASKS, CLUTTER_VARIANTS)):
        for sampler, colour in (("reference", "tab:gray"), ("ours", "tab:blue")):
            axis.hist(histograms[(task, split, sampler)], bins=bins, histtype="step", linewidth=1.6, color=colour,
                      label=sampler, density=True)
        axis.axvline(CLUTTER_VARIANTS[split].min_separation_m, color="tab:red", linestyle=":", linewidth=1)
        axis.set_title(f"{task}, {split}", fontsize=10)
        axis.set_xlabel("closest pair of centres (m)")
    axes[0].legend()
    figure.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
