"""Can the policy's image encoder, trained from scratch, tell conditional_pick's card colour while the head fixates
the card? A pipeline diagnostic for the trained baselines (docs/results/README.md).

    MUJOCO_GL=egl python benchmarks/cue_perception.py --work /tmp/perc [--episodes 40] [--steps 150]

Records `--episodes` demonstrations, converts them with the head camera at 120x160, and keeps the frames of each
episode's first fixation on the card (head pitch past 0.8 rad, head yaw within 0.02 rad of its value on arrival),
labelled by the card's colour (red when the left hand grasps). Two classifiers learn the colour from those frames
for `--steps` Adam steps (lr 1e-4, batch 32, ImageNet normalisation as lerobot-train applies it) and are scored
on the last 8 episodes, never trained on: Diffusion Policy's own encoder (ResNet-18 with batch norm and spatial
softmax keypoints, `DiffusionRgbEncoder`) and a ResNet-18 with average pooling.
"""

from __future__ import annotations

import argparse
import os
import subprocess
from pathlib import Path

import numpy as np

FIXATION_PITCH_RAD = 0.8
FIXATION_YAW_TOLERANCE_RAD = 0.02
HELD_OUT_EPISODES = 8


def make_dataset(work: Path, episodes: int) -> Path:
    root = work / "dataset"
    if not (root / "meta" / "info.json").exists():
        subprocess.run(["tavis", "record", "--robot", "gr1t2", "--tasks", "conditional_pick", "--episodes-per-task",
                        str(episodes), "--workers", str(os.cpu_count()), "--out", str(work / "raw")], check=True)
        subprocess.run(["tavis", "convert", str(work / "raw"), "--repo-id", "local/cue", "--root", str(root),
                        "--fps", "20", "--image-size", "120x160", "--cameras", "head", "--workers",
                        str(os.cpu_count()), "--overwrite"], check=True)
    return root


def fixation_frames(root: Path):
    """(normalised head images, colour labels 1 = red, episode of each frame) of every first card fixation."""
    import torch
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    dataset = LeRobotDataset("local/cue", root=root, video_backend="pyav")
    episode = np.array(dataset.hf_dataset["episode_index"])
    actions = np.stack(dataset.hf_dataset["action"])
    states = np.stack(dataset.hf_dataset["observation.state"])
    frames, labels, episodes = [], [], []
    for index in np.unique(episode):
        rows = np.where(episode == index)[0]
        action, state = actions[rows], states[rows]
        red = np.abs(action[-1, 0:3] - action[0, 0:3]).sum() > np.abs(action[-1, 7:10] - action[0, 7:10]).sum()
        arrival = int(np.argmax(state[:, 15] > FIXATION_PITCH_RAD))
        for k in range(arrival, len(rows)):
            if abs(state[k, 16] - state[arrival, 16]) > FIXATION_YAW_TOLERANCE_RAD:
                break
            frames.append(rows[k])
            labels.append(int(red))
            episodes.append(index)
    images = torch.stack([dataset[int(i)]["observation.images.head"] for i in frames])
    mean = torch.tensor([0.485, 0.456, 0.406]).view(1, 3, 1, 1)
    std = torch.tensor([0.229, 0.224, 0.225]).view(1, 3, 1, 1)
    return (images - mean) / std, torch.tensor(labels), np.array(episodes)


def classifiers():
    import torch.nn as nn
    import torchvision
    from lerobot.configs.types import FeatureType, PolicyFeature
    from lerobot.policies.diffusion.configuration_diffusion import DiffusionConfig
    from lerobot.policies.diffusion.modeling_diffusion import DiffusionRgbEncoder

    def spatial_softmax():
        config = DiffusionConfig(
            pretrained_backbone_weights=None, use_group_norm=False, resize_shape=None, crop_shape=None,
            input_features={"observation.images.head": PolicyFeature(FeatureType.VISUAL, (3, 120, 160)),
                            "observation.state": PolicyFeature(FeatureType.STATE, (19,))},
            output_features={"action": PolicyFeature(FeatureType.ACTION, (19,))})
        encoder = DiffusionRgbEncoder(config)
        return nn.Sequential(encoder, nn.Linear(encoder.feature_dim, 2))

    def average_pooling():
        network = torchvision.models.resnet18(weights=None)
        network.fc = nn.Linear(512, 2)
        return network

    return {"DiffusionRgbEncoder (spatial softmax)": spatial_softmax, "ResNet-18 (average pooling)": average_pooling}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--work", type=Path, required=True)
    parser.add_argument("--episodes", type=int, default=40)
    parser.add_argument("--steps", type=int, default=150)
    args = parser.parse_args()
    import torch
    import torch.nn.functional as F

    images, labels, episodes = fixation_frames(make_dataset(args.work, args.episodes))
    held_out = episodes >= np.sort(np.unique(episodes))[-HELD_OUT_EPISODES]
    train = np.where(~held_out)[0]
    print(f"{len(labels)} fixation frames from {len(np.unique(episodes))} episodes, {labels.float().mean():.0%} red")
    for name, build in classifiers().items():
        torch.manual_seed(0)
        model = build()
        optimiser = torch.optim.Adam(model.parameters(), lr=1e-4)
        for step in range(args.steps):
            batch = np.random.default_rng(step).choice(train, 32)
            loss = F.cross_entropy(model(images[batch]), labels[batch])
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
        model.eval()
        with torch.no_grad():
            def accuracy(mask):
                return (model(images[mask]).argmax(1) == labels[mask]).float().mean().item()
            print(f"{name}: {args.steps} steps, accuracy {accuracy(~held_out):.2f} on training episodes, "
                  f"{accuracy(held_out):.2f} on {HELD_OUT_EPISODES} held-out episodes")


if __name__ == "__main__":
    main()
