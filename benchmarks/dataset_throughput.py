"""Recording and conversion throughput of the dataset tools.

    python benchmarks/dataset_throughput.py [--robot gr1t2] [--suite tavis_head] [--episodes-per-task 4]
                                            [--workers 2] [--image-size 480x640]
                                            [--cameras head,fixed,left_wrist,right_wrist]

Records `episodes-per-task` demonstrator episodes per task of the suite at 60 Hz (`tavis record`), then converts
them to a 20 Hz LeRobotDataset with the given cameras (`tavis convert`, AV1 video), in a temporary directory.
Prints episodes per minute and frames per second for both stages, and the sizes on disk.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path


def _size_mb(path: Path) -> float:
    return sum(f.stat().st_size for f in path.rglob("*") if f.is_file()) / 1e6


def main() -> None:
    os.environ.setdefault("MUJOCO_GL", "egl")
    from lerobot_tavis.checks import image_size_text
    from lerobot_tavis.dataset_tools.convert import ConvertConfig, convert
    from lerobot_tavis.dataset_tools.features import parse_cameras
    from lerobot_tavis.dataset_tools.record import RecordConfig, record
    from lerobot_tavis.envs.tasks.catalog import suite_tasks

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--robot", default="gr1t2")
    parser.add_argument("--suite", default="tavis_head")
    parser.add_argument("--episodes-per-task", type=int, default=4)
    parser.add_argument("--workers", type=int, default=os.cpu_count())
    parser.add_argument("--image-size", default="480x640")
    parser.add_argument("--cameras", default="head,fixed,left_wrist,right_wrist")
    args = parser.parse_args()

    with tempfile.TemporaryDirectory() as scratch:
        raw_dir, root = Path(scratch) / "raw", Path(scratch) / "dataset"
        start = time.perf_counter()
        manifest = record(RecordConfig(out_dir=raw_dir, robot=args.robot, tasks=suite_tasks(args.suite),
                                       episodes_per_task=args.episodes_per_task, workers=args.workers),
                          progress=False)
        record_s = time.perf_counter() - start
        tried = len(manifest.episodes) + len(manifest.discarded)
        steps = sum(e.n_steps for e in manifest.episodes + manifest.discarded)

        start = time.perf_counter()
        convert(ConvertConfig(raw_dir, "local/throughput", root, image_size=image_size_text(args.image_size),
                              cameras=parse_cameras(args.cameras)), progress=False)
        convert_s = time.perf_counter() - start
        frames = sum(-(-e.n_steps // 3) for e in manifest.episodes)

        print(f"{args.robot} {args.suite}: {len(manifest.episodes)} episodes kept of {tried}, {os.cpu_count()} CPUs")
        print(f"record  ({args.workers} workers): {record_s:6.1f} s, {60 * tried / record_s:6.1f} episodes/min, "
              f"{steps / record_s:7.0f} steps/s at 60 Hz; raw {_size_mb(raw_dir):.1f} MB")
        print(f"convert ({args.image_size}, {args.cameras}): {convert_s:6.1f} s, "
              f"{60 * len(manifest.episodes) / convert_s:6.1f} episodes/min, {frames / convert_s:5.1f} frames/s "
              f"at 20 Hz ({frames} frames); dataset {_size_mb(root):.1f} MB")


if __name__ == "__main__":
    main()
