"""Success rate and gaze lead (GALT) of the scripted demonstrators per task x robot x split.

    python benchmarks/expert_success.py [--episodes 96] [--robots gr1t2 reachy2] [--splits id ood_spatial]
                                        [--tasks ...] [--workers 2] [--chunk 24] [--results DIR] [--out TABLE.md]

Seeds 0..episodes-1 per cell, played in chunks of consecutive seeds spread over the worker processes; nothing is
rendered (the demonstrators read the simulator state, not pixels). Prints a Markdown table with Wilson 95%
intervals and a lead time over the successful episodes, computed from the applied actions at 20 Hz: GALT for
TAVIS-Head tasks (as the reference does), the wrist lead of the final grasp for TAVIS-Hands tasks; the share with a
valid positive lead and the median valid lead in seconds.

With `--results DIR`, each finished chunk is kept as DIR/<task>-<robot>-<split>-<first seed>-<end>.json, and a
rerun with the same DIR plays only the chunks not there yet (an interrupted run resumes; keep `--chunk` as it was).
With `--out`, the table is also written to that file (whole or not at all).
"""

from __future__ import annotations

import argparse
import json
import os
import time
from concurrent.futures import as_completed
from pathlib import Path


def run_chunk(args: tuple[str, str, str, range]) -> tuple[str, str, str, range, int, list]:
    """Play seeds `seeds` of one cell; returns the cell, the seeds, their successes, and the successes' leads."""
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
    return task, robot, split, seeds, successes, leads


def main() -> None:
    from lerobot_tavis import atomic
    from lerobot_tavis.envs.robots import BUILTIN_ROBOTS
    from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS
    from lerobot_tavis.metrics.stats import wilson_interval
    from lerobot_tavis.workers import executor

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--episodes", type=int, default=96)
    parser.add_argument("--robots", nargs="+", default=list(BUILTIN_ROBOTS))
    parser.add_argument("--splits", nargs="+", default=["id", "ood_spatial"])
    parser.add_argument("--tasks", nargs="+", default=list(BENCHMARK_TASKS))
    parser.add_argument("--workers", type=int, default=os.cpu_count())
    parser.add_argument("--chunk", type=int, default=24, help="consecutive seeds per job")
    parser.add_argument("--results", type=Path, help="folder keeping each finished chunk; a rerun resumes from it")
    parser.add_argument("--out", type=Path, help="also write the table to this file")
    args = parser.parse_args()
    chunks = [range(first, min(first + args.chunk, args.episodes)) for first in range(0, args.episodes, args.chunk)]
    jobs = [(t, r, s, seeds) for r in args.robots for t in args.tasks for s in args.splits for seeds in chunks]
    start = time.perf_counter()
    results = {(t, r, s): (0, 0, []) for t, r, s, _ in jobs}

    def add(task: str, robot: str, split: str, seeds: range, successes: int, leads: list) -> None:
        done_k, done_n, done_leads = results[(task, robot, split)]
        results[(task, robot, split)] = (done_k + successes, done_n + len(seeds), done_leads + leads)

    if args.results is not None:
        args.results.mkdir(parents=True, exist_ok=True)
        for job in [job for job in jobs if _chunk_file(args.results, *job).exists()]:
            successes, leads = json.loads(_chunk_file(args.results, *job).read_text())
            add(*job, successes, leads)
            jobs.remove(job)
    with executor(args.workers, share_cpus=True) as pool:  # each worker on its own share of the CPUs
        for done in as_completed([pool.submit(run_chunk, job) for job in jobs]):
            task, robot, split, seeds, successes, leads = done.result()
            add(task, robot, split, seeds, successes, leads)
            if args.results is not None:
                atomic.write_text(_chunk_file(args.results, task, robot, split, seeds), json.dumps([successes, leads]))
    lines = [(f"{args.episodes} episodes per cell, seeds 0..{args.episodes - 1}; "
              f"{time.perf_counter() - start:.0f} s wall on {args.workers} workers"), ""]
    lines.append("| task | robot | " + " | ".join(f"{s} success | {s} lead > 0, median" for s in args.splits) + " |")
    lines.append("|---|---|" + "---|---|" * len(args.splits))
    for robot in args.robots:
        for task in args.tasks:
            cells_text = []
            for split in args.splits:
                k, n, leads = results[(task, robot, split)]
                low, high = wilson_interval(k, n)
                cells_text.append(f"{100 * k / n:.1f}% [{100 * low:.1f}, {100 * high:.1f}] ({k}/{n})")
                cells_text.append(_lead_text(leads))
            lines.append(f"| {task} | {robot} | " + " | ".join(cells_text) + " |")
    print("\n".join(lines))
    if args.out is not None:
        atomic.write_text(args.out, "\n".join(lines[2:]) + "\n")


def _chunk_file(folder: Path, task: str, robot: str, split: str, seeds: range) -> Path:
    return folder / f"{task}-{robot}-{split}-{seeds.start}-{seeds.stop}.json"


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
