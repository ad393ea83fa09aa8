"""Policy steps per second of TavisEnv with rendering, per robot x camera mode x image size, and the render cost.

    python benchmarks/env_speed.py [--steps 200] [--robots gr1t2 reachy2] [--configs head_only:240x320 ...]
                                   [--shadows] [--repeats 3] [--peer-python /path/to/python-with-gym-aloha]

Each configuration runs in a fresh process (one GL context, like one vector-env worker): reset, 10 warm-up
steps, then `--steps` timed steps of a scripted head-and-arm motion, then 50 timed renders of the mode's cameras
alone (the render cost per frame, milliseconds per camera image). Configurations render with shadows (the env's
default); `--shadows` measures every configuration without and with them. With `--repeats`, the configurations are
measured round-robin that many times and the medians (and best rates) reported, so a change of machine load hits
all of them alike. Besides wall-clock rates, each step's CPU time (all of the process's threads, Mesa's rendering
threads included) is reported: on a shared machine it moves less with other load than the rate does.

The peer is LeRobot's gym-aloha (`AlohaInsertion-v0`, `pixels_agent_pos`: one 480x640 camera image per step plus
the joint state), measured in the same rounds when it imports in `--peer-python` (default: this interpreter).
Prints Markdown tables. Measure an older checkout with the same script through `PYTHONPATH=<checkout>`.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import time

CONFIGS = [f"{mode}:{size}" for mode in ("head_only", "head_wrist") for size in ("240x320", "480x640")]
WARM_UP_STEPS = 10
RENDER_REPEATS = 50


def measure(robot: str, camera_mode: str, size: tuple[int, int], steps: int, shadows: bool) -> dict:
    """Steps per second, reset time (s) and render cost (ms per camera image) of one configuration."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    import numpy as np

    from lerobot_tavis import canonical
    from lerobot_tavis.envs.env import TavisEnv
    from lerobot_tavis.envs.rendering import CameraRig

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

    for k in range(WARM_UP_STEPS):
        env.step(action(k))
    t0, cpu0 = time.perf_counter(), time.process_time()
    for k in range(steps):
        env.step(action(k))
    steps_per_s = steps / (time.perf_counter() - t0)
    cpu_ms = (time.process_time() - cpu0) * 1000 / steps

    rig = CameraRig(env.model, {name: env.world.cameras[name] for name in env.camera_names}, size)
    rig.render(env.data)
    t0 = time.perf_counter()
    for _ in range(RENDER_REPEATS):
        rig.render(env.data)
    render_ms = (time.perf_counter() - t0) * 1000 / (RENDER_REPEATS * len(env.camera_names))
    rig.close()
    env.close()
    return {"steps_per_s": steps_per_s, "cpu_ms": cpu_ms, "reset_s": reset_s, "render_ms": render_ms}


def measure_aloha(steps: int) -> dict:
    """Steps per second of gym-aloha's insertion task with pixel observations (random actions)."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    import gym_aloha  # noqa: F401  (registers the gym ids)
    import gymnasium as gym

    env = gym.make("gym_aloha/AlohaInsertion-v0", obs_type="pixels_agent_pos")
    env.reset(seed=0)
    env.action_space.seed(0)
    for _ in range(WARM_UP_STEPS):
        env.step(env.action_space.sample())
    t0, cpu0 = time.perf_counter(), time.process_time()
    for _ in range(steps):
        env.step(env.action_space.sample())
    steps_per_s = steps / (time.perf_counter() - t0)
    cpu_ms = (time.process_time() - cpu0) * 1000 / steps
    env.close()
    return {"steps_per_s": steps_per_s, "cpu_ms": cpu_ms}


def _run(python: str, steps: int, *one: str) -> dict | None:
    """One measurement in a fresh process; None when it fails (the peer is not installed there)."""
    result = subprocess.run([python, __file__, "--steps", str(steps), "--one", *one], capture_output=True, text=True)
    if result.returncode != 0:
        return None
    return json.loads(result.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--steps", type=int, default=200)
    parser.add_argument("--robots", nargs="+", help="default: every built-in robot")
    parser.add_argument("--configs", nargs="+", default=CONFIGS, help="camera mode:HxW (default: %(default)s)")
    parser.add_argument("--shadows", action="store_true", help="also measure without shadows")
    parser.add_argument("--repeats", type=int, default=1, help="round-robin rounds; medians are reported")
    parser.add_argument("--peer-python", default=sys.executable, help="interpreter in which gym_aloha imports")
    parser.add_argument("--one", nargs="+", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one:  # a measurement process; the peer's (`aloha`) may run where lerobot_tavis is not installed
        if args.one[0] == "aloha":
            print(json.dumps(measure_aloha(args.steps)))
        else:
            robot, mode, h, w, shadows = args.one
            print(json.dumps(measure(robot, mode, (int(h), int(w)), args.steps, shadows == "on")))
        return
    from lerobot_tavis.envs.robots import BUILTIN_ROBOTS  # not before: the peer's interpreter lacks the package

    sizes = {}
    for config in args.configs:
        mode, _, size = config.partition(":")
        h, _, w = size.partition("x")
        if not (mode in ("head_only", "head_wrist") and h.isdigit() and w.isdigit()):
            parser.error(f"--configs: {config!r} is not head_only:HxW or head_wrist:HxW")
        sizes[config] = (mode, (int(h), int(w)))
    configs = [(robot, mode, size, shadows) for robot in args.robots or BUILTIN_ROBOTS for mode, size in sizes.values()
               for shadows in (("off", "on") if args.shadows else ("on",))]
    results = {config: [] for config in configs}
    peer = []
    for _ in range(args.repeats):
        for config in configs:
            robot, mode, (h, w), shadows = config
            measured = _run(sys.executable, args.steps, robot, mode, str(h), str(w), shadows)
            if measured is None:
                raise SystemExit(f"measuring {config} failed: run it alone with --one {robot} {mode} {h} {w} {shadows}")
            results[config].append(measured)
        if (measured := _run(args.peer_python, args.steps, "aloha")) is not None:
            peer.append(measured)

    def median(config, key):
        return statistics.median(r[key] for r in results[config])

    load = os.getloadavg()[0]
    print(f"machine: {platform.node()} {os.cpu_count()} cores, MUJOCO_GL={os.environ.get('MUJOCO_GL', 'egl')}, "
          f"{args.repeats} round(s), medians (best rate in brackets), load average {load:.1f} at the end")
    print("| robot | camera mode | image (HxW) | cameras | shadows | steps/s | CPU ms per step "
          "| render (ms per image) | reset (s) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for config in configs:
        robot, mode, (h, w), shadows = config
        best = max(r["steps_per_s"] for r in results[config])
        print(f"| {robot} | {mode} | {h}x{w} | {1 if mode == 'head_only' else 3} | {shadows} "
              f"| {median(config, 'steps_per_s'):.1f} ({best:.1f}) | {median(config, 'cpu_ms'):.1f} "
              f"| {median(config, 'render_ms'):.2f} | {median(config, 'reset_s'):.2f} |")
    if not peer:
        print(f"\npeer: gym_aloha does not import in {args.peer_python}; not measured")
        return
    aloha = statistics.median(p["steps_per_s"] for p in peer)
    aloha_cpu = statistics.median(p["cpu_ms"] for p in peer)
    print(f"\npeer: gym-aloha AlohaInsertion-v0 (pixels_agent_pos) {aloha:.1f} steps/s "
          f"(best {max(p['steps_per_s'] for p in peer):.1f}), {aloha_cpu:.0f} CPU ms per step")
    for config in configs:
        robot, mode, (h, w), shadows = config
        if mode == "head_wrist" and (h, w) == (480, 640):
            ratio = median(config, "steps_per_s") / aloha
            cpu_ratio = aloha_cpu / median(config, "cpu_ms")
            print(f"{robot} head_wrist 480x640 shadows {shadows}: {ratio:.1f}x the peer's rate, "
                  f"{cpu_ratio:.1f}x by CPU time")


if __name__ == "__main__":
    main()
