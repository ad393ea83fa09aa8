"""How far off a hand may be and still grasp: each recorded demonstration replayed with the grasping arm's
end-effector position commands shifted by a constant offset (or its orientation commands turned by a constant
angle), and whether the task still succeeds.

    python benchmarks/grasp_tolerance.py --raw RAW_DIR [--offsets-cm 0.25 0.5 1 1.5 2] [--rotations-deg 5 10 20]
                                         [--episodes 8] [--hold-s 2] [--workers N]

RAW_DIR is a `tavis record` directory (e.g. `tavis record --robot gr1t2 --tasks conditional_pick
--episodes-per-task 8 --out RAW_DIR`). The grasping arm is the one whose commanded position travels farthest in
the episode; its commanded position (canonical hip frame: x forward, y to the robot's left, z up) is shifted for
the whole episode by `offset` along +x, -x, +y, -y, +z and -z, the other
commands replayed as recorded, then the last command held for `--hold-s` (a recording ends the moment the task
succeeds, so a shifted lift may need a moment more). The demonstrators plan the grasp from the simulator state,
so offset 0 must succeed; the offset at which success falls off is the precision a policy's hand needs. With
`--rotations-deg`, the grasping arm's commanded orientation is also turned, for the whole episode, by each angle
about +x, -x, +y, -y, +z and -z of the same frame (the other commands as recorded). Prints Markdown tables: success
per offset (or rotation) and direction over the episodes, and for rotations also how many replays never brought a
hand within 5 cm of the target's centre (the report's "not reached"). Also prints how much the grasping arm's
commanded orientation at the grasp varies over the demonstrations: what a policy has to read off its images.
Nothing is rendered.
"""

from __future__ import annotations

import argparse
import os

import numpy as np
from tqdm import tqdm

os.environ.setdefault("MUJOCO_GL", "egl")

NOT_REACHED_M = 0.05  # the episode report's "not reached": no hand within 5 cm of the target's centre
DIRECTIONS = {"+x": (1, 0, 0), "-x": (-1, 0, 0), "+y": (0, 1, 0), "-y": (0, -1, 0), "+z": (0, 0, 1), "-z": (0, 0, -1)}


def grasping_arm(actions: np.ndarray):
    """The canonical arm slots whose commanded position travels farthest over `actions` (T, 19)."""
    from lerobot_tavis import canonical

    def travel(arm) -> float:
        return float(np.sum(np.linalg.norm(np.diff(actions[:, arm.position], axis=0), axis=1)))

    return max(canonical.ARMS, key=travel)


def grasp_orientation(actions: np.ndarray) -> tuple[str, np.ndarray]:
    """The grasping arm's side and its commanded orientation (unit quaternion w, x, y, z) at the first step whose
    gripper command is closed (> 0), from `actions` (T, 19)."""
    arm = grasping_arm(actions)
    quaternion = actions[int(np.argmax(actions[:, arm.gripper] > 0.0)), arm.quaternion].astype(float)
    return arm.side, quaternion / np.linalg.norm(quaternion)


def orientation_spread_deg(quaternions: list[np.ndarray]) -> np.ndarray:
    """Angles (degrees) from each of `quaternions` to the most central one (the least median angle to the rest)."""
    from lerobot_tavis.envs.transforms import quat_angle_rad

    angles = np.degrees([[quat_angle_rad(a, b) for b in quaternions] for a in quaternions])
    return angles[int(np.argmin(np.median(angles, axis=1)))]


def replay_shifted(path: str, shifts_m: list[np.ndarray], hold_s: float,
                   rotations: list[np.ndarray] = ()) -> tuple[list[tuple[bool, float]], float, float | None]:
    """(success, closest hand to the target's centre in m) of the raw episode at `path` replayed once per shift
    (m, canonical frame) of the grasping arm's position commands, then once per rotation (a quaternion w, x, y, z
    applied in the canonical frame) of its orientation commands, its last command held `hold_s` seconds more;
    and, from the replay as recorded (no shift, no hold), how far the target had moved (m) when the grasping arm's
    gripper command first turned closed, and how far above the task's success height its centre was at the
    recording's last step (m; None for a task without a height rule)."""
    from lerobot_tavis.dataset_tools.raw import load_episode
    from lerobot_tavis.envs.env import TavisEnv
    from lerobot_tavis.envs.transforms import quat_multiply

    episode = load_episode(path)
    env = TavisEnv(episode.task, episode.robot, split=episode.split, fps=episode.fps, cameras=())
    arm = grasping_arm(episode.actions)
    held = np.concatenate([episode.actions, np.repeat(episode.actions[-1:], round(hold_s * episode.fps), 0)])
    variants = []
    for shift_m in shifts_m:
        actions = held.copy()
        actions[:, arm.position] += shift_m
        variants.append(actions)
    for rotation in rotations:
        actions = held.copy()
        for action in actions:
            action[arm.quaternion] = quat_multiply(rotation, action[arm.quaternion])
        variants.append(actions)
    results = []
    for actions in variants:
        env.reset(seed=episode.seed)
        success = False
        for action in actions:
            _, _, terminated, truncated, info = env.step(action)
            success = success or bool(info["is_success"])
            if terminated or truncated:
                break
        results.append((success, float(info["reach"]["closest_hand_m"])))
    env.reset(seed=episode.seed)
    moved_at_close_m = None
    for action in episode.actions:
        *_, info = env.step(action)
        if moved_at_close_m is None and action[arm.gripper] > 0.0:
            moved_at_close_m = info["reach"]["target_moved_m"]
    height = info["conditions"].get("target_height_m")
    margin_m = None if height is None else height - env.task_object.success_height_m
    env.close()
    return results, moved_at_close_m or 0.0, margin_m


def main() -> None:
    from lerobot_tavis.dataset_tools.raw import Manifest, load_episode
    from lerobot_tavis.envs.transforms import axis_angle_quat
    from lerobot_tavis.workers import executor

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--raw", required=True, help="a `tavis record` directory")
    parser.add_argument("--offsets-cm", type=float, nargs="+", default=[0.25, 0.5, 1, 1.5, 2],
                        help="shifts besides none (cm, > 0)")
    parser.add_argument("--rotations-deg", type=float, nargs="*", default=[],
                        help="turns of the grasping arm's orientation commands (degrees, > 0)")
    parser.add_argument("--episodes", type=int, default=8, help="the first kept episodes of the recording")
    parser.add_argument("--hold-s", type=float, default=2.0, help="the last command held this long after the end")
    parser.add_argument("--workers", type=int, default=os.cpu_count())
    args = parser.parse_args()
    if args.episodes < 1 or args.workers < 1 or args.hold_s < 0 or min(args.offsets_cm + args.rotations_deg) <= 0:
        parser.error("--episodes and --workers must be >= 1, --hold-s >= 0 and every offset and rotation > 0")
    manifest = Manifest.load(args.raw)
    kept = [entry for entry in manifest.episodes if entry.file][: args.episodes]
    if not kept:
        raise SystemExit(f"{args.raw} holds no kept episode")
    shifts_m = [np.zeros(3)] + [cm / 100 * np.asarray(unit, dtype=float)
                                for cm in args.offsets_cm for unit in DIRECTIONS.values()]
    rotations = [axis_angle_quat(axis, np.radians(degrees)) for degrees in args.rotations_deg
                 for axis in DIRECTIONS.values()]
    with executor(args.workers) as pool:  # the project's: spawned workers that die with this process
        replays = [pool.submit(replay_shifted, os.path.join(args.raw, e.file), shifts_m, args.hold_s, rotations)
                   for e in kept]
        outcomes = [replay.result() for replay in tqdm(replays, desc="replays", unit="demonstration")]
    results = np.array([results for results, _, _ in outcomes])  # (episodes, variants, (success, closest hand m))
    successes = results[:, :, 0].sum(axis=0).astype(int)  # per variant, over the episodes
    not_reached = (results[:, :, 1] > NOT_REACHED_M).sum(axis=0)
    moved_cm = [100 * moved for _, moved, _ in outcomes]
    margins_mm = [1000 * margin for _, _, margin in outcomes if margin is not None]
    tasks = sorted({entry.task for entry in kept})
    print(f"{len(kept)} demonstrations of {', '.join(tasks)} ({manifest.robot}, {manifest.split}), "
          "grasping arm's commanded position shifted\n")
    print("| offset (cm) | " + " | ".join(DIRECTIONS) + " |\n|---|" + "---|" * len(DIRECTIONS))
    print(f"| 0 | {successes[0]}/{len(kept)} (unshifted) |" + " |" * (len(DIRECTIONS) - 1))
    for i, cm in enumerate(args.offsets_cm):
        row = successes[1 + i * len(DIRECTIONS): 1 + (i + 1) * len(DIRECTIONS)]
        print(f"| {cm:g} | " + " | ".join(f"{n}/{len(kept)}" for n in row) + " |")
    if args.rotations_deg:
        print("\nGrasping arm's commanded orientation turned about each axis: successes (never within 5 cm of the "
              "target)\n")
        print("| rotation (deg) | " + " | ".join(DIRECTIONS) + " |\n|---|" + "---|" * len(DIRECTIONS))
        first = len(shifts_m)
        for i, degrees in enumerate(args.rotations_deg):
            columns = range(first + i * len(DIRECTIONS), first + (i + 1) * len(DIRECTIONS))
            print(f"| {degrees:g} | " + " | ".join(f"{successes[c]}/{len(kept)} ({not_reached[c]})" for c in columns)
                  + " |")
    grasps = [grasp_orientation(load_episode(os.path.join(args.raw, entry.file)).actions) for entry in kept]
    for side in sorted({side for side, _ in grasps}):
        spread = orientation_spread_deg([quaternion for hand, quaternion in grasps if hand == side])
        print(f"\nGrasp orientation ({side} hand, {len(spread)} demonstrations): {np.median(spread):.0f} degrees from "
              f"the most central one at the median, {np.percentile(spread, 90):.0f} at the 90th percentile, "
              f"{spread.max():.0f} at most (commanded when the gripper closes)", end="")
    print()
    brushed = [moved for moved in moved_cm if moved > 0]
    print(f"\nAs recorded: the target had moved before the gripper command closed in {len(brushed)} of {len(kept)} "
          f"(by {max(brushed, default=0):.1f} cm at most, {sum(moved >= 2 for moved in moved_cm)} by 2 cm or more)"
          + (f"; at the last step its centre was {min(margins_mm):.0f}-{max(margins_mm):.0f} mm above the success "
             "height" if margins_mm else ""))


if __name__ == "__main__":
    main()
