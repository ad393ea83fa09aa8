"""Footprint of a process that only simulates: import time of the env module and peak resident memory.

    MUJOCO_GL=egl python benchmarks/worker_footprint.py [--task wait_then_act] [--robot gr1t2] [--repeats 3]
                                                        [--no-render]

Each measurement is a fresh Python process, as a worker of `tavis record`, `tavis eval --expert` or LeRobot's async
vector envs is: it times `import lerobot_tavis.envs.env`, builds a TavisEnv at 96x128 (head and wrist cameras),
plays one demonstrator episode and reads its peak resident memory (`ru_maxrss`) and, with the env still open, its
resident and proportional memory (`/proc/self/smaps_rollup`: PSS splits shared pages among their sharers).
Prints one line per process, the medians, and whether torch or LeRobot was imported. `--no-render` builds the env
with no cameras, as the workers of `tavis record` and `benchmarks/expert_success.py` do (no GL context).
"""

from __future__ import annotations

import argparse
import json
import resource
import statistics
import subprocess
import sys
import time


def measure(task: str, robot: str, render: bool) -> dict:
    """Runs in the fresh process: nothing but the standard library is imported before the timed import."""
    start = time.perf_counter()
    from lerobot_tavis.envs.env import TavisEnv
    import_s = time.perf_counter() - start
    from lerobot_tavis.experts.rollout import run_episode

    env = TavisEnv(task, robot, camera_mode="head_wrist", image_size=(96, 128), cameras=None if render else ())
    result = run_episode(env, seed=0)
    memory = _smaps_rollup_mib()  # after the episode, the env still open
    env.close()
    return {"import_s": import_s, "peak_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
            "end_rss_mib": memory["Rss"], "end_pss_mib": memory["Pss"],
            "steps": result.length_steps, "success": result.success,
            "heavy": sorted(m for m in ("torch", "lerobot") if m in sys.modules)}


def _smaps_rollup_mib() -> dict[str, float]:
    """This process's memory by kind (Rss, Pss: shared pages split among the processes sharing them), MiB."""
    lines = open("/proc/self/smaps_rollup").read().splitlines()[1:]
    return {line.split(":")[0]: int(line.split()[1]) / 1024 for line in lines if line.endswith("kB")}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--task", default="wait_then_act")
    parser.add_argument("--robot", default="gr1t2")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--no-render", action="store_true", help="no cameras, hence no GL context")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(measure(args.task, args.robot, render=not args.no_render)))
        return
    runs = []
    for _ in range(args.repeats):
        child = subprocess.run([sys.executable, __file__, "--child", *sys.argv[1:]], check=True, capture_output=True,
                               text=True)
        runs.append(json.loads(child.stdout.splitlines()[-1]))
        print(json.dumps(runs[-1]))
    cameras = "no cameras" if args.no_render else "96x128"
    print(f"{args.task} / {args.robot}, {cameras}, {args.repeats} fresh processes: "
          f"import lerobot_tavis.envs.env {statistics.median(r['import_s'] for r in runs):.2f} s, "
          f"peak resident {statistics.median(r['peak_mib'] for r in runs):.0f} MiB, at the end resident "
          f"{statistics.median(r['end_rss_mib'] for r in runs):.0f} MiB and proportional "
          f"{statistics.median(r['end_pss_mib'] for r in runs):.0f} MiB (medians); "
          f"torch/lerobot imported: {runs[0]['heavy'] or 'neither'}")


if __name__ == "__main__":
    main()
