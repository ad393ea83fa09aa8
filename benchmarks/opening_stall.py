"""How long each episode of a converted dataset opens with policy inputs that do not change.

    python benchmarks/opening_stall.py DATASET_ROOT [--frames 80]

A policy that sees only the current frame cannot tell the first frame of such a stall from its last, so it cannot
learn when the arms start: if the demonstrations keep the arms still for longer than the actions it executes
before looking again, a deterministic policy (ACT's L1-regressed chunk) returns to the same inputs and stays
there. With the fixed camera and the neck state held at 0 (`tavis convert --zero-neck`), the demonstrator's
opening look at the cue moves nothing the policy sees; with the head camera it does.

For each episode, from its first `--frames` frames: the first frame at which the state differs from the first
frame's by more than 1e-3 (metres, radians or quaternion components), at which each camera's image differs by more
than 2/255 on average, and at which an arm's action (end-effector poses) moves by more than 5e-3. Prints one row
per episode and the stall's range in seconds.
"""

from __future__ import annotations

import argparse
import statistics
from pathlib import Path

import numpy as np

STATE_TOLERANCE = 1e-3
IMAGE_TOLERANCE = 2 / 255
ARM_ACTION_TOLERANCE = 5e-3


def first_change(values: list[np.ndarray], tolerance: float, reduce=np.max) -> int | None:
    """Index of the first of `values` whose absolute difference from values[0], reduced, exceeds `tolerance`."""
    return next((index for index, value in enumerate(values) if reduce(np.abs(value - values[0])) > tolerance), None)


def main() -> None:
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    from lerobot_tavis import canonical

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("root", type=Path, help="a LeRobotDataset folder written by `tavis convert`")
    parser.add_argument("--frames", type=int, default=80, help="frames read from the start of each episode")
    args = parser.parse_args()
    if not (args.root / "meta" / "info.json").is_file():
        parser.error(f"{args.root} is not a LeRobotDataset folder (no meta/info.json)")

    dataset = LeRobotDataset(f"local/{args.root.name}", root=args.root, video_backend="pyav")
    cameras = list(dataset.meta.camera_keys)
    arms = np.r_[canonical.LEFT.position, canonical.LEFT.quaternion, canonical.RIGHT.position,
                 canonical.RIGHT.quaternion]
    episode_of_frame = np.asarray(dataset.hf_dataset["episode_index"])
    stalls_s = []
    print(f"{args.root}: {dataset.meta.total_episodes} episodes at {dataset.fps} fps, cameras {cameras}")
    for episode in np.unique(episode_of_frame):
        frames = [dataset[int(index)] for index in np.flatnonzero(episode_of_frame == episode)[:args.frames]]
        state = first_change([frame["observation.state"].numpy() for frame in frames], STATE_TOLERANCE)
        images = {camera: first_change([frame[camera].numpy() for frame in frames], IMAGE_TOLERANCE, np.mean)
                  for camera in cameras}
        arm = first_change([frame["action"].numpy()[arms] for frame in frames], ARM_ACTION_TOLERANCE)
        changes = [index for index in (state, *images.values()) if index is not None]
        stall = min(changes, default=len(frames))
        stalls_s.append(stall / dataset.fps)
        shown = ", ".join(f"{camera.rsplit('.', 1)[-1]} {index}" for camera, index in images.items())
        print(f"episode {episode}: inputs unchanged for {stall} frames (state changes at {state}; images: {shown});"
              f" arm action moves at {arm}")
    print(f"opening stall: {min(stalls_s):.2f}-{max(stalls_s):.2f} s, median {statistics.median(stalls_s):.2f} s "
          f"over {len(stalls_s)} episodes (None: no change within {args.frames} frames)")


if __name__ == "__main__":
    main()
