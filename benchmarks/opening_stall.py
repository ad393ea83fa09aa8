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
from dataclasses import dataclass
from pathlib import Path

import numpy as np

STATE_TOLERANCE = 1e-3
IMAGE_TOLERANCE = 2 / 255
ARM_ACTION_TOLERANCE = 5e-3


def first_change(values: list[np.ndarray], tolerance: float, reduce=np.max) -> int | None:
    """Index of the first of `values` whose absolute difference from values[0], reduced, exceeds `tolerance`."""
    return next((index for index, value in enumerate(values) if reduce(np.abs(value - values[0])) > tolerance), None)


@dataclass(frozen=True)
class OpeningStall:
    """One episode's opening, in frames from its first: where the state, each camera and the arms' action change
    (None: not within the frames read)."""

    episode: int
    state: int | None
    images: dict[str, int | None]
    arm_action: int | None
    frames_read: int

    @property
    def frames(self) -> int:
        """Frames from the first during which no input changes."""
        changes = [index for index in (self.state, *self.images.values()) if index is not None]
        return min(changes, default=self.frames_read)


def opening_stalls(root: Path, frames: int = 80) -> tuple[list[OpeningStall], float]:
    """Every episode's opening stall in the LeRobotDataset at `root`, reading its first `frames` frames; and the
    dataset's fps."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    from lerobot_tavis import canonical

    if not (root / "meta" / "info.json").is_file():
        raise SystemExit(f"{root} is not a LeRobotDataset folder (no meta/info.json)")
    dataset = LeRobotDataset(f"local/{root.name}", root=root, video_backend="pyav")
    arms = np.r_[canonical.LEFT.position, canonical.LEFT.quaternion, canonical.RIGHT.position,
                 canonical.RIGHT.quaternion]
    episode_of_frame = np.asarray(dataset.hf_dataset["episode_index"])
    stalls = []
    for episode in np.unique(episode_of_frame):
        items = [dataset[int(index)] for index in np.flatnonzero(episode_of_frame == episode)[:frames]]
        stalls.append(OpeningStall(
            episode=int(episode),
            state=first_change([item["observation.state"].numpy() for item in items], STATE_TOLERANCE),
            images={camera.rsplit(".", 1)[-1]: first_change([item[camera].numpy() for item in items],
                                                            IMAGE_TOLERANCE, np.mean)
                    for camera in dataset.meta.camera_keys},
            arm_action=first_change([item["action"].numpy()[arms] for item in items], ARM_ACTION_TOLERANCE),
            frames_read=len(items)))
    return stalls, dataset.fps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("root", type=Path, help="a LeRobotDataset folder written by `tavis convert`")
    parser.add_argument("--frames", type=int, default=80, help="frames read from the start of each episode")
    args = parser.parse_args()
    stalls, fps = opening_stalls(args.root, args.frames)
    print(f"{args.root}: {len(stalls)} episodes at {fps} fps")
    for stall in stalls:
        images = ", ".join(f"{camera} {index}" for camera, index in stall.images.items())
        print(f"episode {stall.episode}: inputs unchanged for {stall.frames} frames (state changes at {stall.state}; "
              f"images: {images}); arm action moves at {stall.arm_action}")
    seconds = [stall.frames / fps for stall in stalls]
    print(f"opening stall: {min(seconds):.2f}-{max(seconds):.2f} s, median {statistics.median(seconds):.2f} s "
          f"over {len(seconds)} episodes (None: no change within {args.frames} frames)")


if __name__ == "__main__":
    main()
