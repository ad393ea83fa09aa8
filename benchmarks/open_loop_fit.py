"""Does a trained policy reproduce the actions of a dataset's episodes when shown their recorded observations?
A pipeline diagnostic for the trained baselines (docs/results/README.md), beside the closed-loop overfit check.

    python benchmarks/open_loop_fit.py --policy CHECKPOINT/pretrained_model --dataset ROOT [--episodes 8] \
        [--device cuda] [--out DIR]

Each episode's frames go through the policy's own inference path in order (its preprocessor, `select_action` with
its observation history and action queue, its postprocessor), so the chunking and the denoising are those of an
evaluation; only the observations come from the recording instead of the simulator. Prints, per episode, the mean
absolute error of the selected actions against the recorded ones: head angles (rad), hand positions (cm),
grippers (in [-1, 1] units). A policy that fits its training episodes here but fails on their seeds in the
simulator drifts off its data closed loop; one that does not fit them here has not learned them.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from lerobot_tavis import canonical

GROUPS = {
    "head_rad": (canonical.HEAD, 1.0),
    "left_hand_cm": (canonical.LEFT.position, 100.0),
    "right_hand_cm": (canonical.RIGHT.position, 100.0),
    "grippers": (slice(17, 19), 1.0),
}


def episode_errors(predicted: np.ndarray, recorded: np.ndarray) -> dict[str, float]:
    """Mean absolute error per action group, in the group's unit (GROUPS)."""
    return {name: float(np.abs(predicted[:, dims] - recorded[:, dims]).mean() * scale)
            for name, (dims, scale) in GROUPS.items()}


def replay_open_loop(driver, frames: list[dict], device: str) -> np.ndarray:
    """The actions a `viewer.PolicyDriver`'s policy selects, one per frame, when shown the recorded observations
    (already in LeRobot's tensor layout) in order."""
    import torch

    driver.reset()
    actions = []
    for frame in frames:
        batch = {key: value.unsqueeze(0).to(device) for key, value in frame.items()
                 if key.startswith("observation.")}
        batch["task"] = [frame["task"]]
        with torch.inference_mode():
            action = driver.postprocessor(driver.policy.select_action(driver.preprocessor(batch)))
        actions.append(action[0].float().cpu().numpy())
    return np.stack(actions)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--policy", type=Path, required=True, help="a checkpoint's pretrained_model folder")
    parser.add_argument("--dataset", type=Path, required=True, help="root of the LeRobotDataset to replay")
    parser.add_argument("--episodes", type=int, default=8, help="the dataset's first N episodes")
    parser.add_argument("--device", default="cuda")
    parser.add_argument("--out", type=Path, help="writes errors.json and traces.npz (predicted and recorded actions)")
    args = parser.parse_args()

    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    from lerobot_tavis.dataset_tools.quiet import video_backend
    from lerobot_tavis.viewer import PolicyDriver

    driver = PolicyDriver(args.policy, args.device)  # loads the checkpoint as `tavis view` and lerobot-eval do
    dataset = LeRobotDataset(f"local/{args.dataset.name}", root=args.dataset, video_backend=video_backend())
    episode_of_frame = np.array(dataset.hf_dataset["episode_index"])

    results, traces = [], {}
    for episode in sorted(set(episode_of_frame.tolist()))[: args.episodes]:
        frames = [dataset[int(i)] for i in np.flatnonzero(episode_of_frame == episode)]
        recorded = np.stack([frame["action"].numpy() for frame in frames])
        predicted = replay_open_loop(driver, frames, args.device)
        errors = {"episode": episode, "frames": len(frames), **episode_errors(predicted, recorded)}
        results.append(errors)
        traces[f"predicted_{episode}"], traces[f"recorded_{episode}"] = predicted, recorded
        print("  ".join(f"{key} {value:.3f}" if isinstance(value, float) else f"{key} {value}"
                        for key, value in errors.items()), flush=True)
    if args.out:
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / "errors.json").write_text(json.dumps(results, indent=1))
        np.savez_compressed(args.out / "traces.npz", **traces)


if __name__ == "__main__":
    main()
