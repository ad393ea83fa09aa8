"""Render the same episodes with an older checkout and with this one, side by side (docs/images/looks_before_after.png).

    git worktree add /tmp/tavis-before b09dd68      # the last commit with the primitive look
    MUJOCO_GL=egl .venv/bin/python tools/looks_before_after.py --before /tmp/tavis-before

Two rows per (task, robot), before and after, at the grasp of seed 0's demonstrator episode (the physics is the same
in both checkouts, so both rows show the same moment): head, fixed and both wrist views.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SCENES = (("clutter_pick_cube", "gr1t2"), ("multi_shelf_scan", "gr1t2"), ("peeking_box", "reachy2"))
VIEWS = ("head", "fixed", "left_wrist", "right_wrist")
IMAGE_SIZE = (240, 320)
GRASP_DELAY_STEPS = 8

# Runs inside either checkout: plays the demonstrator and saves the views at the grasp. It uses only the API that
# both checkouts share (TavisEnv with `cameras=`, make_expert, info["applied_action"]).
_RENDER = """
import json, sys
import numpy as np
from lerobot_tavis.envs.env import TavisEnv
from lerobot_tavis.experts.rollout import make_expert
scenes, views, size, delay, out = json.loads(sys.argv[1])
frames = {}
for task, robot in scenes:
    env = TavisEnv(task, robot, camera_mode="head_wrist", image_size=tuple(size), cameras=tuple(views))
    obs, _ = env.reset(seed=0)
    expert = make_expert(env, 0)
    expert.reset()
    closed_for = -1
    for _ in range(400):
        obs, _, terminated, truncated, info = env.step(expert.act())
        if closed_for >= 0 or max(info["applied_action"][17:19]) > 0:
            closed_for += 1
        if closed_for >= delay or terminated or truncated:
            break
    for view in views:
        frames[f"{task}/{robot}/{view}"] = obs["pixels"][view]
    env.close()
np.savez_compressed(out, **frames)
"""


def render_with(tree: Path, out: Path) -> dict[str, np.ndarray]:
    env = {**os.environ, "PYTHONPATH": str(tree), "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
    args = json.dumps([SCENES, VIEWS, IMAGE_SIZE, GRASP_DELAY_STEPS, str(out)])
    subprocess.run([sys.executable, "-c", _RENDER, args], env=env, check=True, cwd=tree)
    with np.load(out) as saved:
        return dict(saved)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--before", type=Path, required=True, help="a checkout of the older commit")
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "images" / "looks_before_after.png")
    args = parser.parse_args()

    from lerobot_tavis.media import label, write_png

    with tempfile.TemporaryDirectory() as tmp:
        before = render_with(args.before.resolve(), Path(tmp) / "before.npz")
        after = render_with(ROOT, Path(tmp) / "after.npz")
    rows = []
    for task, robot in SCENES:
        for name, frames in (("before", before), ("after", after)):
            rows.append(np.concatenate([label(frames[f"{task}/{robot}/{view}"], f"{name}: {robot} {task}, {view}")
                                        for view in VIEWS], axis=1))
    print(write_png(args.out, np.concatenate(rows, axis=0)))


if __name__ == "__main__":
    main()
