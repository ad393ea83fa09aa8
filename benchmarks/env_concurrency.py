"""Env steps per second of many env processes at once on one machine: the ceiling a policy evaluation's env
workers can reach, with the camera mode's cameras rendered or with none.

    python benchmarks/env_concurrency.py [--seconds 12] [--render 1 16 48 96] [--no-render 96]
                                         [--camera-mode head_wrist] [--image-size 240x320]

Each count starts that many processes (spawned, one GL context each, like lerobot-eval's async env workers); each
builds a conditional_pick env (GR1T2, seed 1000), resets it, then, once all are ready, steps it for `--seconds`
holding its measured pose. Prints one Markdown row per count: env steps per second over all processes and the CPU
cores they kept busy. With MUJOCO_GL=egl the renders go to the GPU where there is one.
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import time

os.environ.setdefault("MUJOCO_GL", "egl")


def _step_for(seconds: float, render: bool, camera_mode: str, size: tuple[int, int], ready, results) -> None:
    from lerobot_tavis.envs.env import TavisEnv

    env = TavisEnv("conditional_pick", "gr1t2", camera_mode=camera_mode, split="id", image_size=size,
                   episode_length_s=1e6, cameras=None if render else ())
    observation, _ = env.reset(seed=1000)
    hold = observation["agent_pos"].copy()
    env.step(hold)  # the first step builds what is built lazily (the GL context among it)
    ready.wait()
    end, steps, cpu_start = time.perf_counter() + seconds, 0, time.process_time()
    while time.perf_counter() < end:
        env.step(hold)
        steps += 1
    results.put((steps, time.process_time() - cpu_start))
    env.close()


def measure(processes: int, render: bool, seconds: float, camera_mode: str, size: tuple[int, int]) -> dict:
    """Steps per second over `processes` concurrent envs and the CPU cores they used."""
    ctx = mp.get_context("spawn")
    ready, results = ctx.Barrier(processes + 1), ctx.Queue()
    workers = [ctx.Process(target=_step_for, args=(seconds, render, camera_mode, size, ready, results))
               for _ in range(processes)]
    for worker in workers:
        worker.start()
    ready.wait()
    totals = [results.get() for _ in workers]
    for worker in workers:
        worker.join()
    return {"processes": processes, "render": render, "steps_per_s": sum(t[0] for t in totals) / seconds,
            "cpu_cores": sum(t[1] for t in totals) / seconds}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=12.0)
    parser.add_argument("--render", type=int, nargs="*", default=[1, 16, 48, 96], help="process counts, rendering")
    parser.add_argument("--no-render", type=int, nargs="*", default=[96], help="process counts, no camera")
    parser.add_argument("--camera-mode", default="head_wrist")
    parser.add_argument("--image-size", default="240x320", help="HxW of each camera image")
    args = parser.parse_args()
    size = tuple(int(v) for v in args.image_size.split("x"))
    print(f"{args.camera_mode} at {args.image_size}, {os.cpu_count()} CPUs, MUJOCO_GL={os.environ['MUJOCO_GL']}")
    print("\n| processes | cameras rendered | env steps/s (all processes) | CPU cores busy |\n|---|---|---|---|")
    for processes, render in [(n, True) for n in args.render] + [(n, False) for n in args.no_render]:
        row = measure(processes, render, args.seconds, args.camera_mode, size)
        print(f"| {processes} | {'yes' if render else 'none'} | {row['steps_per_s']:,.0f} | {row['cpu_cores']:.1f} |",
              flush=True)


if __name__ == "__main__":
    main()
