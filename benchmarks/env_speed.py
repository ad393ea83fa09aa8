"""Policy steps per second of TavisEnv with rendering, per robot x camera mode x image size.

    python benchmarks/env_speed.py [--steps 200] [--robots gr1t2 reachy2] [--shadows]

Each configuration runs in a fresh process (one GL context, like one vector-env worker): reset, 10 warm-up
steps, then `--steps` timed steps of a scripted head-and-arm motion. Prints a Markdown table.
`--shadows` measures every configuration twice, without and with the key light's shadows (TavisEnv(shadows=True)),
in the same run.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time

CONFIGS = [(mode, size) for mode in ("headcam", "head_wrist") for size in ((240, 320), (480, 640))]


def measure(robot: str, camera_mode: str, size: tuple[int, int], steps: int, shadows: bool = False) -> dict:
    os.environ.setdefault("MUJOCO_GL", "egl")
    import numpy as np

    from lerobot_tavis import canonical
    from lerobot_tavis.envs.env import TavisEnv

    env = TavisEnv("tabletop", robot, camera_mode=camera_mode, image_size=size, shadows=shadows)
    t0 = time.perf_counter()
    env.reset(seed=0)
    reset_s = time.perf_counter() - t0

    def action(k: int) -> np.ndarray:
        a = canonical.rest_action()
        a[canonical.HEAD_PITCH] = 0.3 + 0.2 * np.sin(k / 10)
        a[canonical.HEAD_YAW] = 0.4 * np.sin(k / 15)
        a[canonical.LEFT.position] += 0.05 * np.sin(k / 8)
        return a

    for k in range(10):
        env.step(action(k))
    t0 = time.perf_counter()
    for k in range(steps):
        env.step(action(k))
    elapsed = time.perf_counter() - t0
    env.close()
    return {"steps_per_s": steps / elapsed, "reset_s": reset_s}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--steps", type=int, default=200)
    parser.add_argument("--robots", nargs="+", default=["gr1t2", "reachy2"])
    parser.add_argument("--shadows", action="store_true", help="also measure with shadows on")
    parser.add_argument("--one", nargs=5, metavar=("ROBOT", "MODE", "H", "W", "SHADOWS"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one:
        robot, mode, h, w, shadows = args.one
        print(json.dumps(measure(robot, mode, (int(h), int(w)), args.steps, shadows == "on")))
        return
    print(f"machine: {platform.node()} {os.cpu_count()} cores, MUJOCO_GL={os.environ.get('MUJOCO_GL', 'egl')}")
    print("| robot | camera mode | image (HxW) | cameras | shadows | steps/s | reset (s) |")
    print("|---|---|---|---|---|---|---|")
    for robot in args.robots:
        for mode, (h, w) in CONFIGS:
            for shadows in ("off", "on") if args.shadows else ("off",):
                out = subprocess.run([sys.executable, __file__, "--steps", str(args.steps), "--one", robot, mode,
                                      str(h), str(w), shadows], check=True, capture_output=True, text=True).stdout
                result = json.loads(out.strip().splitlines()[-1])
                n_cams = 1 if mode == "headcam" else 3
                print(f"| {robot} | {mode} | {h}x{w} | {n_cams} | {shadows} | {result['steps_per_s']:.1f} "
                      f"| {result['reset_s']:.2f} |", flush=True)


if __name__ == "__main__":
    main()
