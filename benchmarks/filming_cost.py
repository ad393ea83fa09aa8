"""What filming costs a policy evaluation: one protocol cell timed once per number of filmed episodes.

    MUJOCO_GL=egl python benchmarks/filming_cost.py --work /tmp/filming [--films 0 2 8] [--episodes 8]
        [--batch-size 8] [--episode-length-s 5]

The policy is a small ACT with random weights (no checkpoint to download; it never succeeds, so every episode
runs its full length), evaluated on the CPU with `tavis eval`'s own path (`eval.protocol.run_protocol`: TAVIS-Head,
id split, head + both wrists at 120x160, async envs). Each timing is a fresh cell; a wall clock per line.
"""

from __future__ import annotations

import argparse
import shutil
import time
from pathlib import Path

IMAGE_SIZE = (120, 160)


def small_act_checkpoint(path: Path) -> None:
    from lerobot.policies.act.configuration_act import ACTConfig
    from lerobot.policies.factory import make_policy, make_pre_post_processors

    from lerobot_tavis.eval.env_config import TavisEnvConfig

    config = ACTConfig(pretrained_backbone_weights=None, device="cpu", push_to_hub=False, dim_model=64,
                       n_encoder_layers=1, n_decoder_layers=1, dim_feedforward=128, chunk_size=20, n_action_steps=10)
    make_policy(config, env_cfg=TavisEnvConfig(image_size=IMAGE_SIZE, camera_mode="head_wrist")).save_pretrained(path)
    for processor in make_pre_post_processors(config, dataset_stats=None):
        processor.save_pretrained(path)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--work", type=Path, required=True, help="scratch directory (cells are written anew)")
    parser.add_argument("--films", type=int, nargs="+", default=[0, 2, 8], help="filmed episodes per task")
    parser.add_argument("--episodes", type=int, default=8, help="episodes per task")
    parser.add_argument("--batch-size", type=int, default=8, help="async envs per task")
    parser.add_argument("--episode-length-s", type=float, default=5.0)
    args = parser.parse_args()

    from lerobot_tavis.eval.protocol import ProtocolConfig, run_protocol

    checkpoint = args.work / "checkpoint"
    if not checkpoint.exists():
        small_act_checkpoint(checkpoint)
    for film in args.films:
        out = args.work / f"film_{film}"
        shutil.rmtree(out, ignore_errors=True)
        start = time.perf_counter()
        run_protocol(ProtocolConfig(out_dir=out, suites=("tavis_head",), splits=("id",), n_episodes=args.episodes,
                                    batch_size=args.batch_size, image_size=IMAGE_SIZE, camera_mode="head_wrist",
                                    policy_path=str(checkpoint), film_episodes=film,
                                    episode_length_s=args.episode_length_s))
        print(f"filmed episodes per task {film}: {time.perf_counter() - start:.1f} s", flush=True)


if __name__ == "__main__":
    main()
