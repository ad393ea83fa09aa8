"""Whether the robots' arms touch the table while the scripted demonstrators play, per task and robot.

    MUJOCO_GL=egl python benchmarks/table_contacts.py [--episodes 4] [--robots gr1t2 reachy2] [--tasks ...]

Seeds 0..episodes-1 of the `id` split, played by `run_episode` (nothing rendered). After every env step the
contacts between a robot geom and a `table/` geom are read. Prints a Markdown table: successes, the share of steps
with such a contact, the deepest one (mm) and the robot geoms involved.
"""

from __future__ import annotations

import argparse
import os


def table_contacts(task: str, robot: str, seeds: range) -> tuple[int, int, int, float, set[str]]:
    """Successes, steps, steps with a robot-table contact, the deepest contact (m) and the robot geoms touching."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    from lerobot_tavis.envs.env import TavisEnv
    from lerobot_tavis.experts.rollout import run_episode

    env = TavisEnv(task, robot, camera_mode="head_only", split="id", cameras=())
    env.reset(seed=seeds[0])  # builds the model
    model = env.model
    table = {g for g in range(model.ngeom) if model.geom(g).name.startswith("table/")}
    robot_geoms = {g for g in range(model.ngeom) if model.body(model.geom_bodyid[g]).name.startswith(f"{robot}/")}
    counts = {"steps": 0, "touching": 0, "depth": 0.0, "geoms": set()}
    step = env.step

    def step_and_count(action):
        out = step(action)
        touching = False
        for contact in env.data.contact[:env.data.ncon]:
            pair = {contact.geom1, contact.geom2}
            if pair & table and pair & robot_geoms:
                touching = True
                counts["depth"] = max(counts["depth"], -contact.dist)
                counts["geoms"] |= {model.geom(g).name for g in pair & robot_geoms}
        counts["steps"] += 1
        counts["touching"] += touching
        return out

    env.step = step_and_count
    successes = sum(bool(run_episode(env, seed).success) for seed in seeds)
    env.close()
    return successes, counts["steps"], counts["touching"], counts["depth"], counts["geoms"]


def main() -> None:
    from lerobot_tavis.envs.robots import BUILTIN_ROBOTS
    from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS, task_class

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--episodes", type=int, default=4)
    parser.add_argument("--robots", nargs="+", default=list(BUILTIN_ROBOTS))
    parser.add_argument("--tasks", nargs="+", default=list(BENCHMARK_TASKS))
    args = parser.parse_args()
    print("| task | robot | success | steps touching the table | deepest (mm) | robot geoms |")
    print("|---|---|---|---|---|---|")
    for task in args.tasks:
        if not task_class(task).has_table:
            continue
        for robot in args.robots:
            successes, steps, touching, depth, geoms = table_contacts(task, robot, range(args.episodes))
            print(f"| {task} | {robot} | {successes}/{args.episodes} | {touching}/{steps} | {depth * 1000:.1f} | "
                  f"{', '.join(sorted(geoms)) or '-'} |", flush=True)


if __name__ == "__main__":
    main()
