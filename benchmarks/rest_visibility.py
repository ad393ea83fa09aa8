"""How often the head camera sees the task's target at the first observation (robot at rest), per task and robot.

    python benchmarks/rest_visibility.py [--episodes 20] [--split id] [--min-pixels 20]

For seeds 0..episodes-1 the env is reset (nothing else) and the head camera's view is rendered as a segmentation
image at 240x320: the target counts as visible when at least `--min-pixels` pixels show it (any of its geoms). A
blacked-out head camera (blocked_clutter_pick_cube) sees nothing by design. Prints a Markdown table: the share of
episodes with the target visible, and the median visible pixel count over the episodes.
"""

from __future__ import annotations

import argparse
import os
import statistics

IMAGE_SIZE = (240, 320)


def visible_pixels(task: str, robot: str, split: str, seeds: range) -> list[int]:
    """Pixels of the target in the head camera's first observation, per seed (0 where the camera is blacked out)."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    import mujoco

    from lerobot_tavis.envs.env import TavisEnv

    env = TavisEnv(task, robot, split=split, image_size=IMAGE_SIZE, cameras=())
    env.reset(seed=seeds[0])  # builds the model
    counts = []
    with mujoco.Renderer(env.model, *IMAGE_SIZE) as renderer:
        renderer.enable_segmentation_rendering()
        for seed in seeds:
            env.reset(seed=seed)
            if "head" in env.task_object.blacked_out_cameras:
                counts.append(0)
                continue
            renderer.update_scene(env.data, camera=env.world.cameras["head"])
            segmentation = renderer.render()
            target = env.model.body(env.task_object.target).id
            geoms = segmentation[..., 0][segmentation[..., 1] == mujoco.mjtObj.mjOBJ_GEOM]
            counts.append(int((env.model.geom_bodyid[geoms] == target).sum()))
    env.close()
    return counts


def main() -> None:
    from lerobot_tavis.envs.robots import BUILTIN_ROBOTS
    from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--episodes", type=int, default=20)
    parser.add_argument("--split", default="id")
    parser.add_argument("--min-pixels", type=int, default=20)
    parser.add_argument("--robots", nargs="+", default=list(BUILTIN_ROBOTS))
    args = parser.parse_args()
    print(f"| task | {' | '.join(f'{r}: target visible (median pixels)' for r in args.robots)} |")
    print(f"|---|{'---|' * len(args.robots)}")
    for task in BENCHMARK_TASKS:
        cells = []
        for robot in args.robots:
            counts = visible_pixels(task, robot, args.split, range(args.episodes))
            seen = sum(c >= args.min_pixels for c in counts)
            cells.append(f"{seen}/{len(counts)} ({statistics.median(counts):.0f})")
        print(f"| {task} | {' | '.join(cells)} |", flush=True)


if __name__ == "__main__":
    main()
