"""Where the wrist cameras look with the arms at rest: pitch, position and what fills the image, per robot and side.

    MUJOCO_GL=egl python benchmarks/wrist_view.py [--robots gr1t2 reachy2] [--before CHECKOUT --image PNG]
                                                  [--demo-episodes N]

clutter_pick_cube, seed 0: reset, then the rest action (canonical.rest_action) for REST_STEPS steps. For each wrist
camera, the pitch of its optical axis below the horizon (deg), its world position (m), and the share of its
180x240 image showing the table, the floor and nothing (the backdrop). The reference's GR1T2 wrist camera looks
24.6 deg below the horizon at rest (its mount turned by the rest quaternion).

With `--before`, the same measurement also runs on that checkout (an older commit), and `--image` writes GR1T2's
left wrist view at rest before and after, side by side.

With `--demo-episodes N` (this checkout only), also the wrist cameras through N demonstrator episodes of the same
task (seeds 0..N-1, at most DEMO_STEPS steps each, every DEMO_EVERY-th step, both wrists): the pitch below the
horizon (median, 10th and 90th percentiles; negative = above) and the share of frames whose image is more than
10% table.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
TASK, SEED, REST_STEPS = "clutter_pick_cube", 0, 30
IMAGE_SIZE = (180, 240)
SIDES = ("left", "right")
DEMO_STEPS, DEMO_EVERY = 400, 10

# Runs inside either checkout; uses only the API both share (TavisEnv with `cameras=`, canonical.rest_action).
_MEASURE = """
import json, sys
import mujoco
import numpy as np
from lerobot_tavis import canonical
from lerobot_tavis.envs.env import TavisEnv
robots, task, seed, steps, size, image_out = json.loads(sys.argv[1])
rows, images = [], {}
for robot in robots:
    cameras = tuple(f"{side}_wrist" for side in ("left", "right"))
    env = TavisEnv(task, robot, image_size=tuple(size), cameras=cameras)
    obs, _ = env.reset(seed=seed)
    for _ in range(steps):
        obs, *_ = env.step(canonical.rest_action())
    model, data = env.model, env.data
    with mujoco.Renderer(model, *size) as renderer:
        renderer.enable_segmentation_rendering()
        for camera in cameras:
            cam = env.world.cameras[camera]
            forward = -data.cam_xmat[cam].reshape(3, 3)[:, 2]
            renderer.update_scene(data, camera=cam)
            seg = renderer.render()
            geom = np.where(seg[..., 1] == mujoco.mjtObj.mjOBJ_GEOM, seg[..., 0], -1)
            names = [model.geom(g).name if g >= 0 else "" for g in range(model.ngeom)]
            def share(prefix):
                hits = np.isin(geom, [g for g, n in enumerate(names) if n.startswith(prefix)])
                return float(hits.mean())
            rows.append({"robot": robot, "camera": camera, "pitch_deg": float(np.degrees(-np.arcsin(forward[2]))),
                         "pos": [float(v) for v in data.cam_xpos[cam]], "table": share("table"),
                         "floor": share("floor"), "backdrop": float((geom < 0).mean())})
            images[f"{robot}/{camera}"] = obs["pixels"][camera]
    env.close()
if image_out:
    np.savez_compressed(image_out, **images)
print(json.dumps(rows))
"""


def measure(tree: Path, robots: list[str], image_out: Path | None) -> list[dict]:
    env = {**os.environ, "PYTHONPATH": str(tree), "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
    args = json.dumps([robots, TASK, SEED, REST_STEPS, IMAGE_SIZE, str(image_out) if image_out else ""])
    done = subprocess.run([sys.executable, "-c", _MEASURE, args], env=env, check=True, cwd=tree,
                          capture_output=True, text=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def demo_views(robot: str, episodes: int) -> tuple[np.ndarray, np.ndarray]:
    """Pitch below the horizon (deg) and table share of each sampled wrist frame through the demonstrations."""
    import mujoco

    from lerobot_tavis.envs.env import TavisEnv
    from lerobot_tavis.experts.rollout import make_expert

    cameras = tuple(f"{side}_wrist" for side in SIDES)
    env = TavisEnv(TASK, robot, image_size=IMAGE_SIZE, cameras=cameras)
    pitches, shares = [], []
    for seed in range(episodes):
        env.reset(seed=seed)
        expert = make_expert(env, seed)
        expert.reset()
        model, data = env.model, env.data
        table = [g for g in range(model.ngeom) if model.geom(g).name.startswith("table/")]
        with mujoco.Renderer(model, *IMAGE_SIZE) as renderer:
            renderer.enable_segmentation_rendering()
            for step in range(DEMO_STEPS):
                _, _, terminated, truncated, _ = env.step(expert.act())
                if step % DEMO_EVERY == 0:
                    for camera in cameras:
                        cam = env.world.cameras[camera]
                        forward = -data.cam_xmat[cam].reshape(3, 3)[:, 2]
                        renderer.update_scene(data, camera=cam)
                        seg = renderer.render()
                        geom = np.where(seg[..., 1] == mujoco.mjtObj.mjOBJ_GEOM, seg[..., 0], -1)
                        pitches.append(np.degrees(-np.arcsin(forward[2])))
                        shares.append(np.isin(geom, table).mean())
                if terminated or truncated:
                    break
    env.close()
    return np.array(pitches), np.array(shares)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--robots", nargs="+", default=["gr1t2", "reachy2"])
    parser.add_argument("--before", type=Path, help="a checkout of an older commit, measured too")
    parser.add_argument("--image", type=Path, help="with --before: write GR1T2's left wrist view before | after")
    parser.add_argument("--demo-episodes", type=int, default=0, help="also measure through N demonstrations")
    args = parser.parse_args()
    if args.image and not args.before:
        parser.error("--image needs --before")

    import tempfile

    from lerobot_tavis.media import label, write_png

    trees = ([("before", args.before.resolve())] if args.before else []) + [("after", ROOT)]
    print("| code | robot | camera | pitch below horizon (deg) | position (m) | table | floor | backdrop |")
    print("|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        views = {}
        for name, tree in trees:
            out = Path(tmp) / f"{len(views)}.npz" if args.image else None
            for row in measure(tree, args.robots, out):
                pos = ", ".join(f"{v:.3f}" for v in row["pos"])
                print(f"| {name} | {row['robot']} | {row['camera']} | {row['pitch_deg']:.1f} | ({pos}) | "
                      f"{row['table']:.0%} | {row['floor']:.0%} | {row['backdrop']:.0%} |")
            if out is not None:
                with np.load(out) as saved:
                    views[name] = saved["gr1t2/left_wrist"]
    if args.image:
        panels = [label(views[name], f"{name}: GR1T2 left wrist at rest") for name, _ in trees]
        print(write_png(args.image, np.concatenate(panels, axis=1)))
    if args.demo_episodes:
        print(f"\n{TASK}, {args.demo_episodes} demonstrations, both wrists every {DEMO_EVERY} steps:\n")
        print("| robot | frames | pitch below horizon (deg): median [p10, p90] | frames > 10% table |")
        print("|---|---|---|---|")
        for robot in args.robots:
            pitch, share = demo_views(robot, args.demo_episodes)
            print(f"| {robot} | {len(pitch)} | {np.median(pitch):.1f} [{np.percentile(pitch, 10):.1f}, "
                  f"{np.percentile(pitch, 90):.1f}] | {(share > 0.1).mean():.0%} |")


if __name__ == "__main__":
    main()
