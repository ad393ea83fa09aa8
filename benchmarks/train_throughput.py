"""Training throughput (samples/s) of lerobot-train on TAVIS datasets, per frame storage and training setting.

    python benchmarks/train_throughput.py data --work /tmp/tp [--episodes 24] [--workers 16]
    python benchmarks/train_throughput.py train --work /tmp/tp --storage av1 h264 png [--steps 300] [--batch 64]
        [--preset diffusion_head_wrist] [--tag NAME -- <extra lerobot-train arguments>]

`data` records `--episodes` conditional_pick demonstrations (GR1T2) and converts them once per frame storage
(`tavis convert --storage`) at `--image-size` (240x320) with the preset's cameras. `train` runs lerobot-train on
each storage for `--steps` steps (no evaluation, no checkpoint) and reads LeRobot's own log: it prints one Markdown
row per run with the median over the log lines after the first 100 steps (warm-up: worker start, cudnn autotuning)
of samples/s
(`smp/s`), update time and data-wait time per step (`updt_s`, `data_s`), and the dataset's size on disk.
"""

from __future__ import annotations

import argparse
import re
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

TASK, ROBOT = "conditional_pick", "gr1t2"
WARM_UP_STEPS = 100
LOG_FIELDS = re.compile(r"step:(?P<step>\d+).*updt_s:(?P<update>[\d.]+) data_s:(?P<data>[\d.]+) smp/s:(?P<sps>[\d.]+)")


def dataset_root(work: Path, storage: str, image_size: str) -> Path:
    return work / f"dataset_{storage}_{image_size}"


def make_data(work: Path, episodes: int, workers: int, storages: list[str], cameras: str, image_size: str) -> None:
    tavis = [sys.executable, "-m", "lerobot_tavis.cli"]
    if not (work / "raw" / "manifest.json").exists():  # one recording serves every storage and image size
        subprocess.run([*tavis, "record", "--robot", ROBOT, "--tasks", TASK, "--episodes-per-task", str(episodes),
                        "--workers", str(workers), "--out", str(work / "raw")], check=True)
    converts = [subprocess.Popen([*tavis, "convert", str(work / "raw"), "--repo-id", f"local/tp-{storage}",
                                  "--root", str(dataset_root(work, storage, image_size)), "--image-size", image_size,
                                  "--cameras", cameras, "--storage", storage, "--overwrite"])
                for storage in storages]
    if any(process.wait() for process in converts):
        raise SystemExit("a conversion failed")


def train(work: Path, storage: str, image_size: str, preset: str, steps: int, batch: int, workers: int,
          extra: list[str], tag: str) -> dict:
    """One lerobot-train run; the medians of its log after the warm-up."""
    from lerobot_tavis.policy_configs import preset_path

    out = work / f"train_{storage}_{image_size}_{tag}"
    shutil.rmtree(out, ignore_errors=True)
    command = [sys.executable, "-m", "lerobot.scripts.lerobot_train", f"--config_path={preset_path(preset)}",
               f"--dataset.repo_id=local/tp-{storage}", f"--dataset.root={dataset_root(work, storage, image_size)}",
               "--policy.device=cuda", "--policy.use_amp=true", f"--steps={steps}", f"--batch_size={batch}",
               f"--num_workers={workers}", "--log_freq=20", "--save_checkpoint=false", "--env_eval_freq=0",
               f"--output_dir={out}", *extra]
    started = time.perf_counter()
    log = subprocess.run(command, capture_output=True, text=True)
    wall_s = time.perf_counter() - started
    if log.returncode != 0:
        raise SystemExit(f"lerobot-train failed ({' '.join(command)}):\n{log.stderr[-3000:]}")
    lines = [m.groupdict() for m in LOG_FIELDS.finditer(log.stdout + log.stderr)]
    steady = [line for line in lines if int(line["step"]) > WARM_UP_STEPS] or lines
    return {key: statistics.median(float(line[key]) for line in steady) for key in ("sps", "update", "data")} | {
        "wall_s": wall_s, "log_lines": len(steady)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("stage", choices=["data", "train"])
    parser.add_argument("--work", type=Path, required=True)
    parser.add_argument("--storage", nargs="+", default=["av1", "h264", "png"])
    parser.add_argument("--episodes", type=int, default=24)
    parser.add_argument("--workers", type=int, default=16, help="recording processes / data-loader workers")
    parser.add_argument("--cameras", default="head,left_wrist,right_wrist")
    parser.add_argument("--image-size", default="240x320", help="HxW of the dataset's frames")
    parser.add_argument("--preset", default="diffusion_head_wrist")
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--batch", type=int, default=64)
    parser.add_argument("--tag", default="preset", help="name of the extra-argument setting, for the table")
    args, extra = parser.parse_known_args()
    extra = [a for a in extra if a != "--"]
    if args.stage == "data":
        make_data(args.work, args.episodes, args.workers, args.storage, args.cameras, args.image_size)
        return
    print("| storage | frames | preset | setting | batch | samples/s | update s/step | data wait s/step | dataset MB "
          "| run s |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for storage in args.storage:
        root = dataset_root(args.work, storage, args.image_size)
        result = train(args.work, storage, args.image_size, args.preset, args.steps, args.batch, args.workers, extra,
                       args.tag)
        size_mb = sum(p.stat().st_size for p in root.rglob("*") if p.is_file()) / 1e6
        print(f"| {storage} | {args.image_size} | {args.preset} | {args.tag} {' '.join(extra)} | {args.batch} "
              f"| {result['sps']:.0f} "
              f"| {result['update']:.3f} | {result['data']:.3f} | {size_mb:.0f} | {result['wall_s']:.0f} |",
              flush=True)


if __name__ == "__main__":
    main()
