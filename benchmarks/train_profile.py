"""What bounds lerobot-train on TAVIS data: the loader's ceiling and the GPU update's ceiling, measured apart.

    python benchmarks/train_profile.py loader --work /tmp/tp --storage av1 --image-size 240x320
        [--backend pyav torchcodec] [--workers 16] [--batch 64] [--batches 60] [-- <lerobot-train arguments>]
    python benchmarks/train_profile.py update --work /tmp/tp --storage av1 --image-size 240x320
        [--batch 64] [--steps 40] [-- <lerobot-train arguments>]

Both build the run exactly as lerobot-train does, from the preset (`--preset`, default diffusion_head_wrist) plus
the extra arguments, on a dataset made by `train_throughput.py data`:

- `loader` iterates LeRobot's DataLoader (LeRobot's `make_dataset`, its worker settings) and also does what
  lerobot-train's main process does with each batch before the update: the copy to the device that Accelerate's
  prepared DataLoader makes (`send_to_device`), uint8 frames to float there, the policy's preprocessor. It prints
  samples/s of the workers alone and of the whole data path, after `--skip` warm-up batches.
- `update` runs the policy's forward, backward and optimiser step (Accelerate, mixed precision as lerobot-train
  sets it) on one batch held on the GPU, so no loading at all: samples/s of the GPU work alone.

The end-to-end rate cannot exceed the smaller of the two; `train_throughput.py train` measures it.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import torch

from train_throughput import dataset_root


def train_config(args: argparse.Namespace, extra: list[str]):
    """LeRobot's TrainPipelineConfig of the preset with the extra arguments, validated as lerobot-train does."""
    from lerobot.configs.train import TrainPipelineConfig

    import lerobot_env_tavis  # noqa: F401  (registers --env.type=tavis, as LeRobot's CLIs do)
    from lerobot_tavis.policy_configs import preset_path

    root = dataset_root(args.work, args.storage, args.image_size)
    cli = [f"--dataset.repo_id=local/tp-{args.storage}", f"--dataset.root={root}", f"--policy.device={args.device}",
           "--policy.use_amp=true", f"--batch_size={args.batch}", f"--num_workers={args.workers}",
           f"--output_dir={args.work / 'profile_out'}", *extra]
    cfg = TrainPipelineConfig.from_pretrained(str(preset_path(args.preset)), cli_args=cli)
    cfg.validate()
    return cfg


def synchronize(device: str) -> None:
    if device == "cuda":
        torch.cuda.synchronize()


def endless(loader):
    """The loader's batches, epoch after epoch (persistent workers carry over)."""
    while True:
        yield from loader


def profile_loader(args: argparse.Namespace, extra: list[str]) -> None:
    from accelerate.utils import send_to_device
    from lerobot.datasets.factory import make_dataset
    from lerobot.policies.factory import make_pre_post_processors

    for backend in args.backend:
        cfg = train_config(args, [*extra, f"--dataset.video_backend={backend}"])
        dataset = make_dataset(cfg)
        preprocessor, _ = make_pre_post_processors(cfg.policy, dataset_stats=dataset.meta.stats)
        loader = torch.utils.data.DataLoader(
            dataset, batch_size=cfg.batch_size, shuffle=True, num_workers=cfg.num_workers, pin_memory=True,
            drop_last=True, prefetch_factor=cfg.prefetch_factor, persistent_workers=True,
            multiprocessing_context=cfg.dataloader_multiprocessing_context)
        batches = endless(loader)
        worker_s, path_s = [], []
        for index in range(args.skip + args.batches):
            start = time.perf_counter()
            batch = next(batches)
            fetched = time.perf_counter()
            batch = send_to_device(batch, torch.device(args.device))
            for key in dataset.meta.camera_keys:
                if key in batch and batch[key].dtype == torch.uint8:
                    batch[key] = batch[key].to(dtype=torch.float32) / 255.0
            batch = preprocessor(batch)
            synchronize(args.device)
            if index >= args.skip:
                worker_s.append(fetched - start)
                path_s.append(time.perf_counter() - start)
        mean_fetch, mean_path = statistics.fmean(worker_s), statistics.fmean(path_s)
        print(f"| loader | {args.storage} | {args.image_size} | {backend} | {cfg.num_workers} | {cfg.batch_size} "
              f"| {' '.join(extra)} | {cfg.batch_size / mean_fetch:.0f} | {cfg.batch_size / mean_path:.0f} "
              f"| {mean_fetch:.3f} | {mean_path - mean_fetch:.3f} |", flush=True)


def profile_update(args: argparse.Namespace, extra: list[str]) -> None:
    from accelerate import Accelerator
    from lerobot.datasets.factory import make_dataset
    from lerobot.optim.factory import make_optimizer_and_scheduler
    from lerobot.policies.factory import make_policy, make_pre_post_processors

    cfg = train_config(args, [*extra, "--num_workers=0"])
    dataset = make_dataset(cfg)
    policy = make_policy(cfg=cfg.policy, ds_meta=dataset.meta)
    preprocessor, _ = make_pre_post_processors(cfg.policy, dataset_stats=dataset.meta.stats)
    optimizer, _ = make_optimizer_and_scheduler(cfg, policy)
    torch.backends.cudnn.benchmark = True  # as lerobot-train sets them
    torch.backends.cuda.matmul.allow_tf32 = True
    accelerator = Accelerator(mixed_precision="fp16" if cfg.policy.use_amp else "no")
    policy, optimizer = accelerator.prepare(policy, optimizer)
    batch = torch.utils.data.default_collate([dataset[i] for i in range(cfg.batch_size)])
    for key in dataset.meta.camera_keys:
        batch[key] = batch[key].to(dtype=torch.float32) / 255.0
    batch = preprocessor(batch)
    policy.train()
    times = []
    for step in range(args.skip + args.steps):
        synchronize(args.device)
        start = time.perf_counter()
        with accelerator.autocast():
            loss, _ = policy.forward(batch)
        accelerator.backward(loss)
        accelerator.clip_grad_norm_(policy.parameters(), cfg.optimizer.grad_clip_norm)
        optimizer.step()
        optimizer.zero_grad()
        loss.item()
        if step >= args.skip:
            times.append(time.perf_counter() - start)
    parameters = sum(p.numel() for p in policy.parameters()) / 1e6
    mean_s = statistics.fmean(times)
    peak_gb = torch.cuda.max_memory_allocated() / 2**30 if args.device == "cuda" else 0.0
    print(f"| update | {args.image_size} | {cfg.batch_size} | {' '.join(extra)} | {parameters:.0f} M "
          f"| {cfg.batch_size / mean_s:.0f} | {mean_s:.3f} | {peak_gb:.1f} |",
          flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("stage", choices=["loader", "update"])
    parser.add_argument("--work", type=Path, required=True)
    parser.add_argument("--storage", default="av1")
    parser.add_argument("--image-size", default="240x320", help="HxW of the dataset's frames")
    parser.add_argument("--preset", default="diffusion_head_wrist")
    parser.add_argument("--backend", nargs="+", default=["pyav", "torchcodec"], help="video decoders (loader)")
    parser.add_argument("--workers", type=int, default=16, help="data-loader workers (loader)")
    parser.add_argument("--device", default="cuda")
    parser.add_argument("--batch", type=int, default=64)
    parser.add_argument("--batches", type=int, default=60, help="timed batches (loader)")
    parser.add_argument("--steps", type=int, default=40, help="timed updates (update)")
    parser.add_argument("--skip", type=int, default=10, help="warm-up batches or updates, not timed")
    args, extra = parser.parse_known_args()
    extra = [a for a in extra if a != "--"]
    (profile_loader if args.stage == "loader" else profile_update)(args, extra)


if __name__ == "__main__":
    main()
