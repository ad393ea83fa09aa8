"""Where an evaluation's policy took its hands: how close they came to the target (the median over episodes, and
how many came within REACHED_M of it), and which object they went for: of the episodes whose closest hand came
within NEAR_M of the target or of another object, how many came nearer another object than the target. On
conditional_pick, whose two objects stand on either side of the robot, those are the episodes that went to the wrong
side; episodes whose hands stayed farther than NEAR_M from every object (a policy that stood still) say nothing about
sides and are left out.

    python benchmarks/reach_sides.py EVAL [EVAL ...]

Each EVAL is a `tavis eval` output folder (or any folder holding `episodes.jsonl` files below it), its episodes
logged with their `reach` (the closest any hand came to the target and to the other props, metres).
"""

from __future__ import annotations

import argparse
import statistics
from pathlib import Path

from lerobot_tavis.envs.reach import REACHED_M
from lerobot_tavis.eval.report import read_episode_log

NEAR_M = 0.10


def count_sides(records: list[dict]) -> tuple[int, int]:
    """(episodes with a hand within NEAR_M of the target or another object, those of them whose closest hand came
    nearer another object than the target); episodes logged without another object's distance count in neither."""
    near = wrong = 0
    for record in records:
        reach = record.get("reach") or {}
        target, other = reach.get("closest_hand_m"), reach.get("closest_hand_other_m")
        if target is None or other is None or min(target, other) > NEAR_M:
            continue
        near += 1
        wrong += other < target
    return near, wrong


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("evals", type=Path, nargs="+", metavar="EVAL")
    args = parser.parse_args()
    for folder in args.evals:
        logs = sorted(folder.rglob("episodes.jsonl"))
        if not logs:
            raise SystemExit(f"{folder}: no episodes.jsonl below it")
        records = [record for log in logs for record in read_episode_log(log)]
        closest = [record["reach"]["closest_hand_m"] for record in records if record.get("reach")]
        if not closest:
            raise SystemExit(f"{folder}: no episode logged with its reach")
        near, wrong = count_sides(records)
        print(f"{folder}: {len(records)} episodes; closest hand to the target {100 * statistics.median(closest):.1f} "
              f"cm at the median, {sum(d <= REACHED_M for d in closest)} within {100 * REACHED_M:.0f} cm; {near} with "
              f"a hand within {100 * NEAR_M:.0f} cm of an object, {wrong} of them nearer another object than the "
              "target")


if __name__ == "__main__":
    main()
