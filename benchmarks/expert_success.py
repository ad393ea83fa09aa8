"""Success rate and gaze lead (GALT) of the scripted demonstrators per task x robot x split.

    python benchmarks/expert_success.py [--episodes 96] [--robots gr1t2 reachy2] [--splits id ood_spatial]
                                        [--tasks ...] [--workers 2] [--chunk 24]

Seeds 0..episodes-1 per cell, played in chunks of consecutive seeds spread over the worker processes; nothing is
rendered (the demonstrators read the simulator state, not pixels). Prints a Markdown table with Wilson 95%
intervals and a lead time over the successful episodes, computed from the applied actions at 20 Hz: GALT for
TAVIS-Head tasks (as the reference does), the wrist lead of the final grasp for TAVIS-Hands tasks; the share with a
valid positive lead and the median valid lead in seconds.
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import time


def run_chunk(args: tuple[str, str, str, range]) -> tuple[str, str, str, int, int, list]:
    """Play seeds `seeds` of one cell; returns the cell, its successes and episodes, and the successes' leads."""
    task, robot, split, seeds = args
    os.environ.setdefault("MUJOCO_GL", "egl")
    from lerobot_tavis.envs.env import TavisEnv
    from lerobot_tavis.envs.tasks.catalog import task_info
    from lerobot_tavis.experts.rollout import run_episode
    from lerobot_tavis.metrics.galt import compute_galt, wrist_lead_per_grasp

    def lead_s(actions) -> float | None:
        if task_info(task).suite == "tavis_head":
            return compute_galt(actions, fps=20).galt_s
        leads = wrist_lead_per_grasp(actions, fps=20)
        return leads[-1].lead_s if leads else None

    env = TavisEnv(task, robot, camera_mode="head_only", split=split, cameras=())
    successes, leads = 0, []
    for seed in seeds:
        result = run_episode(env, seed)
        if result.success:
            successes += 1
            leads.append(lead_s(result.actions))
    env.close()
    return task, robot, split, successes, len(seeds), leads


def main() -> None:
    from lerobot_tavis.envs.robots import BUILTIN_ROBOTS
    from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS
    from lerobot_tavis.metrics.stats import wilson_interval

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--episodes", type=int, default=96)
    parser.add_argument("--robots", nargs="+", default=list(BUILTIN_ROBOTS))
    parser.add_argument("--splits", nargs="+", default=["id", "ood_spatial"])
    parser.add_argument("--tasks", nargs="+", default=list(BENCHMARK_TASKS))
    parser.add_argument("--workers", type=int, default=os.cpu_count())
    parser.add_argument("--chunk", type=int, default=24, help="consecutive seeds per job")
    args = parser.parse_args()
    chunks = [range(first, min(first + args.chunk, args.episodes)) for first in range(0, args.episodes, args.chunk)]
    jobs = [(t, r, s, seeds) for r in args.robots for t in args.tasks for s in args.splits for seeds in chunks]
    start = time.perf_counter()
    results = {(t, r, s): (0, 0, []) for t, r, s, _ in jobs}
    with multiprocessing.get_context("spawn").Pool(args.workers) as pool:
        for t, r, s, k, n, leads in pool.imap_unordered(run_chunk, jobs):
            done_k, done_n, done_leads = results[(t, r, s)]
            results[(t, r, s)] = (done_k + k, done_n + n, done_leads + leads)
    print(f"{args.episodes} episodes per cell, seeds 0..{args.episodes - 1}; "
          f"{time.perf_counter() - start:.0f} s wall on {args.workers} workers\n")
    print("| task | robot | " + " | ".join(f"{s} success | {s} lead > 0, median" for s in args.splits) + " |")
    print("|---|---|" + "---|---|" * len(args.splits))
    for robot in args.robots:
        for task in args.tasks:
            cells_text = []
            for split in args.splits:
                k, n, leads = results[(task, robot, split)]
                low, high = wilson_interval(k, n)
                cells_text.append(f"{100 * k / n:.1f}% [{100 * low:.1f}, {100 * high:.1f}] ({k}/{n})")
                cells_text.append(_lead_text(leads))
            print(f"| {task} | {robot} | " + " | ".join(cells_text) + " |")


def _lead_text(leads: list) -> str:
    """Share of successful episodes with a valid, positive lead, and the median valid lead (s)."""
    import numpy as np

    valid = [lead for lead in leads if lead is not None]
    if not leads:
        return "-"
    positive = sum(lead > 0 for lead in valid)
    median = f"{np.median(valid):.2f} s" if valid else "-"
    return f"{100 * positive / len(leads):.0f}% ({positive}/{len(leads)}), {median}"


if __name__ == "__main__":
    main()
