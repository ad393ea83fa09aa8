"""Training throughput (samples/s) of lerobot-train on TAVIS datasets: per frame storage and training setting, and
at scale (several GPUs through `accelerate launch`, the frame cache).

    python benchmarks/train_throughput.py data --work /tmp/tp [--episodes 24] [--workers 16]
    python benchmarks/train_throughput.py train --work /tmp/tp --storage av1 h264 png [--steps 300] [--batch 64]
        [--preset diffusion_head_wrist] [--tag NAME -- <extra lerobot-train arguments>]
    python benchmarks/train_throughput.py scale --work /tmp/scale [--episodes 24] [--gpus 1 2 4]
        [--cache off float32 uint8] [--batch 128 256] [--steps 300] [--warm-up 100]
        [--settings act_hand_relative_head_wrist_compact diffusion_head_wrist_compact <any shipped preset>]

`data` records `--episodes` conditional_pick demonstrations (GR1T2) and converts them once per frame storage
(`tavis convert --storage`) at `--image-size` (240x320) with the preset's cameras. `train` runs lerobot-train on
each storage for `--steps` steps (no evaluation, no checkpoint) and reads LeRobot's own log: it prints one Markdown
row per run with the median over the log lines after the first 100 steps (warm-up: worker start, cudnn autotuning)
of samples/s (`smp/s`), update time and data-wait time per step (`updt_s`, `data_s`), and the dataset's size on disk.

`scale` is docs/training.md's "Training at scale" measurement in one command. Where `--work` holds no dataset yet it
records `--episodes` demonstrations and converts them (AV1, 120x160, head and wrist cameras), then writes the frame
cache (`tavis cache-frames`); then it trains each setting of `--settings` (a name of SCALE_SETTINGS, or any shipped
preset as it ships) at each batch per GPU of `--batch` (default: the setting's) on each GPU count of `--gpus` (one
process per GPU: `accelerate launch --multi_gpu` for more than one) with each frame source of `--cache` (off: decoded
from the videos; uint8: the frame cache, `TAVIS_FRAME_CACHE=1`, frames as uint8 to the GPU; float32: the cache with
the loader workers converting to float32, `TAVIS_FRAME_CACHE=float32`), `--steps` steps each. Per run it keeps
LeRobot's samples/s (median after the first `--warm-up` steps: worker start, cudnn autotuning), the wall-clock
samples/s (samples trained between the first log line after the warm-up and the last, over the time between them),
update and data-wait time per step, each GPU's mean utilisation over that window
(nvidia-smi's `utilization.gpu`, the share of time a kernel was running, sampled every 0.5 s) and the minutes
`--budget` samples take at the wall-clock rate. `--device cpu` runs the same grid on CPU processes (no AMP, no
utilisation) to check the command before GPU time is spent. Each run's result is saved as it ends
(`<work>/scale/<run>.json`) and a later call skips the runs already measured, so the whole grid can be measured
over several calls; every call rewrites `<work>/scale.json` and `<work>/scale.md` from all the runs measured.
The video decoder (without the cache) and the cache's decoder are `--video-backend`: torchcodec where it loads
(`eval "$(tools/pyav_ffmpeg.sh)"` first on a machine without FFmpeg's libraries), else PyAV.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import threading
import time
from dataclasses import asdict, dataclass
from pathlib import Path

TASK, ROBOT = "conditional_pick", "gr1t2"
WARM_UP_STEPS = 100
LOG_FREQ = 20
LOG_FIELDS = re.compile(r"step:(?P<step>\d+).*updt_s:(?P<update>[\d.]+) data_s:(?P<data>[\d.]+) smp/s:(?P<sps>[\d.]+)")
SCALE_STORAGE, SCALE_IMAGE_SIZE, SCALE_CAMERAS = "av1", "120x160", "head,left_wrist,right_wrist"
UTILISATION_PERIOD_MS = 500
FRAME_SOURCES = {"off": "0", "float32": "float32", "uint8": "1"}  # --cache value -> TAVIS_FRAME_CACHE


@dataclass(frozen=True)
class Setting:
    """A training setting of `scale`: a shipped preset, its batch per GPU, and lerobot-train overrides."""

    preset: str
    batch: int
    overrides: tuple[str, ...] = ()


SCALE_SETTINGS = {
    # the hand-frame ACT baseline preset as it ships (batch 128)
    "act_hand_relative_head_wrist_compact": Setting("act_hand_relative_head_wrist_compact", 128),
    # Diffusion Policy at the compact presets' frame size: the fastest diffusion setting of the earlier table
    # (120x160 frames, UNet 256-512-1024 with batch norm, batch 64)
    "diffusion_head_wrist_compact": Setting("diffusion_head_wrist", 64, (
        "--policy.resize_shape=[120,160]", "--policy.down_dims=[256,512,1024]", "--policy.use_group_norm=false")),
}


def scale_setting(name: str) -> Setting:
    """The setting `name` of SCALE_SETTINGS, else the shipped preset `name` with its own batch size."""
    from lerobot_tavis.policy_configs import preset_path

    if name in SCALE_SETTINGS:
        return SCALE_SETTINGS[name]
    preset = json.loads(preset_path(name).read_text())  # InputError naming the presets for an unknown name
    return Setting(name, int(preset.get("batch_size", 8)))  # 8: LeRobot's default batch


def dataset_root(work: Path, storage: str, image_size: str) -> Path:
    return work / f"dataset_{storage}_{image_size}"


def tavis_command() -> list[str]:
    return [sys.executable, "-m", "lerobot_tavis.cli"]


def make_data(work: Path, episodes: int, workers: int, storages: list[str], cameras: str, image_size: str) -> None:
    if not (work / "raw" / "manifest.json").exists():  # one recording serves every storage and image size
        subprocess.run([*tavis_command(), "record", "--robot", ROBOT, "--tasks", TASK, "--episodes-per-task",
                        str(episodes), "--workers", str(workers), "--out", str(work / "raw")], check=True)
    converts = [subprocess.Popen([*tavis_command(), "convert", str(work / "raw"), "--repo-id", f"local/tp-{storage}",
                                  "--root", str(dataset_root(work, storage, image_size)), "--image-size", image_size,
                                  "--cameras", cameras, "--storage", storage,
                                  "--workers", str(max(1, workers // len(storages))),
                                  "--overwrite"])
                for storage in storages]
    if any(process.wait() for process in converts):
        raise SystemExit("a conversion failed")


def visible_gpus() -> list[str]:
    """The GPUs this process may use: CUDA_VISIBLE_DEVICES where set, else every GPU nvidia-smi lists."""
    if os.environ.get("CUDA_VISIBLE_DEVICES"):
        return os.environ["CUDA_VISIBLE_DEVICES"].split(",")
    try:
        listing = subprocess.run(["nvidia-smi", "--query-gpu=index", "--format=csv,noheader"], capture_output=True,
                                 text=True, check=True).stdout
    except (FileNotFoundError, subprocess.CalledProcessError):
        return []
    return listing.split()


class GpuUtilisation:
    """nvidia-smi's `utilization.gpu` (%) of some GPUs every UTILISATION_PERIOD_MS, read by a thread while the
    block runs; none where nvidia-smi is missing."""

    def __init__(self, gpus: list[str]):
        self.gpus = gpus
        self.samples: list[tuple[float, str, float]] = []  # (monotonic time s, GPU index, utilisation %)
        self._process = None
        self._reader = None

    def __enter__(self) -> GpuUtilisation:
        if not self.gpus:
            return self
        command = ["nvidia-smi", f"--id={','.join(self.gpus)}", "--query-gpu=index,utilization.gpu",
                   "--format=csv,noheader,nounits", f"--loop-ms={UTILISATION_PERIOD_MS}"]
        try:
            self._process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        except FileNotFoundError:
            return self
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        return self

    def _read(self) -> None:
        for line in self._process.stdout:
            index, _, value = line.partition(",")
            try:
                self.samples.append((time.monotonic(), index.strip(), float(value)))
            except ValueError:  # "[N/A]" or a partial line
                continue

    def __exit__(self, *exc) -> None:
        if self._process is not None:
            self._process.terminate()
            self._process.wait()
            self._reader.join()

    def means(self, start: float, end: float) -> dict[str, float]:
        """Each GPU's mean utilisation (%) over the samples taken between `start` and `end` (monotonic s)."""
        window: dict[str, list[float]] = {}
        for moment, index, value in self.samples:
            if start <= moment <= end:
                window.setdefault(index, []).append(value)
        return {index: statistics.mean(values) for index, values in sorted(window.items())}


def train(work: Path, root: Path, preset: str, steps: int, batch: int, workers: int, extra: list[str], name: str,
          gpus: list[str] | None = None, cache: str = "off", device: str = "cuda",
          warm_up: int = WARM_UP_STEPS) -> dict:
    """One lerobot-train run on the dataset at `root` (one process per GPU of `gpus` under `accelerate launch` when
    several; None: the GPU lerobot-train picks), with `workers` loader workers per process and frames from `cache`
    (FRAME_SOURCES). Returns the medians of LeRobot's log after `warm_up` steps, the wall-clock rate over the same
    window and the GPUs' utilisation then. `device` cpu (with `gpus` standing for processes) checks the plumbing on
    a machine without GPUs."""
    from lerobot_tavis.policy_configs import preset_path

    out = work / f"train_{name}"
    shutil.rmtree(out, ignore_errors=True)
    arguments = [f"--config_path={preset_path(preset)}", f"--dataset.repo_id=local/{root.name}",
                 f"--dataset.root={root}", f"--policy.device={device}",
                 f"--policy.use_amp={'true' if device == 'cuda' else 'false'}",
                 f"--steps={steps}", f"--batch_size={batch}", f"--num_workers={workers}",
                 f"--log_freq={min(LOG_FREQ, max(1, steps // 10))}",
                 "--save_checkpoint=false", "--env_eval_freq=0", f"--output_dir={out}", *extra]
    processes = len(gpus) if gpus else 1
    if processes > 1:
        command = [sys.executable, "-m", "accelerate.commands.launch", "--multi_gpu", f"--num_processes={processes}",
                   "--num_machines=1", "--mixed_precision=no", "--dynamo_backend=no",
                   "-m", "lerobot.scripts.lerobot_train", *arguments]
    else:
        command = [sys.executable, "-m", "lerobot.scripts.lerobot_train", *arguments]
    env = {**os.environ, "TAVIS_FRAME_CACHE": FRAME_SOURCES[cache], "PYTHONUNBUFFERED": "1"}
    if gpus and device == "cuda":
        env["CUDA_VISIBLE_DEVICES"] = ",".join(gpus)
    log_path = work / "logs" / f"{name}.log"
    log_path.parent.mkdir(parents=True, exist_ok=True)
    lines = []  # (arrival time, LeRobot's log fields)
    started = time.perf_counter()
    with GpuUtilisation(gpus if device == "cuda" else []) as utilisation, log_path.open("w") as log:
        process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
        for text in process.stdout:
            log.write(text)
            lines += [(time.monotonic(), match.groupdict()) for match in LOG_FIELDS.finditer(text)]
        returncode = process.wait()
    wall_s = time.perf_counter() - started
    if returncode != 0 or not lines:
        tail = log_path.read_text()[-3000:]
        raise RuntimeError(f"lerobot-train failed (exit {returncode}, {len(lines)} log lines; {log_path}): "
                           f"{' '.join(command)}\n{tail}")
    steady = [(moment, fields) for moment, fields in lines if int(fields["step"]) > warm_up] or lines
    result = {key: statistics.median(float(fields[key]) for _, fields in steady) for key in ("sps", "update", "data")}
    result |= {"run_s": wall_s, "log_lines": len(steady), "command": command, "log": str(log_path)}
    (first, first_fields), (last, last_fields) = steady[0], steady[-1]
    if last > first:
        samples = (int(last_fields["step"]) - int(first_fields["step"])) * batch * processes
        result["wall_sps"] = samples / (last - first)
        result["gpu_utilisation"] = utilisation.means(first, last)
    return result


def run_name(setting: str, gpus: int, cache: str, batch: int) -> str:
    return f"{setting}_{gpus}gpu_{'decode' if cache == 'off' else f'cache_{cache}'}_batch{batch}"


def scale(args) -> None:
    """The `scale` stage (module docstring)."""
    root = dataset_root(args.work, SCALE_STORAGE, SCALE_IMAGE_SIZE)
    if not (root / "meta" / "info.json").exists():
        make_data(args.work, args.episodes, args.workers, [SCALE_STORAGE], SCALE_CAMERAS, SCALE_IMAGE_SIZE)
    subprocess.run([*tavis_command(), "cache-frames", str(root), "--workers", str(args.workers),
                    "--video-backend", args.video_backend], check=True)
    available = visible_gpus() if args.device == "cuda" else ["cpu"] * max(args.gpus)
    results_dir = args.work / "scale"
    results_dir.mkdir(parents=True, exist_ok=True)
    failed = []
    for setting_name in args.settings:
        setting = scale_setting(setting_name)
        for batch in args.batch or [setting.batch]:
            for count in args.gpus:
                if count > len(available):
                    print(f"scale: {count} GPUs asked, {len(available)} visible: {setting_name} on {count} skipped")
                    continue
                for cache in args.cache:
                    name = run_name(setting_name, count, cache, batch)
                    if (results_dir / f"{name}.json").exists() and not args.again:
                        continue
                    workers = (max(1, args.workers // count - 2) if args.loader_workers is None
                               else args.loader_workers)
                    extra = [*setting.overrides, f"--dataset.video_backend={args.video_backend}", *args.extra]
                    print(f"scale: {name} ({workers} loader workers per GPU)", flush=True)
                    try:
                        result = train(args.work, root, setting.preset, args.steps, batch, workers, extra, name,
                                       available[:count], cache, args.device, args.warm_up)
                    except RuntimeError as error:
                        print(f"scale: {error}", file=sys.stderr)
                        failed.append(name)
                        continue
                    result |= {"setting": setting_name, "setting_detail": asdict(setting), "gpus": count,
                               "cache": cache, "batch_per_gpu": batch, "loader_workers_per_gpu": workers,
                               "device": args.device, "steps": args.steps, "warm_up_steps": args.warm_up,
                               "video_backend": args.video_backend}
                    (results_dir / f"{name}.json").write_text(json.dumps(result, indent=1) + "\n")
    write_scale_report(args.work, args.budget, args.episodes)
    if failed:
        raise SystemExit(f"scale: {len(failed)} runs failed: {', '.join(failed)} (logs in {args.work / 'logs'})")


def machine() -> dict:
    """What the numbers were measured on: GPUs, cores, the project's commit where the tree is a git checkout."""
    try:
        gpus = subprocess.run(["nvidia-smi", "--query-gpu=name,memory.total,driver_version", "--format=csv,noheader"],
                              capture_output=True, text=True, check=True).stdout.strip().splitlines()
    except (FileNotFoundError, subprocess.CalledProcessError):
        gpus = []
    try:
        commit = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                                cwd=Path(__file__).parent).stdout.strip() or None
    except FileNotFoundError:  # no git on the machine
        commit = None
    return {"gpus": gpus, "cores": len(os.sched_getaffinity(0)), "host": platform.node(), "commit": commit}


FRAMES_LABEL = {"off": "decoded ({backend})", "float32": "cache, float32 from workers", "uint8": "cache, uint8"}


def write_scale_report(work: Path, budget: int, episodes: int) -> None:
    """scale.json (every run measured, the machine) and scale.md (one table row per run) in `work`. "x decoded" is a
    run's wall-clock rate over that of the same setting and batch on one GPU with decoded frames."""
    runs = sorted((json.loads(path.read_text()) for path in (work / "scale").glob("*.json")),
                  key=lambda run: (run["setting"], run["batch_per_gpu"], run["gpus"], list(FRAME_SOURCES).index(
                      run["cache"])))
    decoded = {(run["setting"], run["batch_per_gpu"]): run.get("wall_sps") for run in runs
               if run["gpus"] == 1 and run["cache"] == "off"}
    report = {"machine": machine(), "budget_samples": budget, "runs": runs}
    (work / "scale.json").write_text(json.dumps(report, indent=1) + "\n")
    on_cpu = any(run.get("device") == "cpu" for run in runs)
    lines = [f"Measured by `{' '.join(['python', *sys.argv])}` ({report['machine']['cores']} cores; "
             f"{'; '.join(report['machine']['gpus']) or 'no GPU listed'}; commit {report['machine']['commit']}; "
             f"{episodes} demonstrations at {SCALE_IMAGE_SIZE})"
             f"{'; CPU processes in place of GPUs: a check of the command, not a measurement' if on_cpu else ''}.",
             "",
             "| setting | GPUs | frames | batch per GPU | samples/s (wall) | x decoded, 1 GPU "
             f"| samples/s (LeRobot log) | GPU utilisation % (mean; lowest GPU) | update s/step | data wait s/step "
             f"| min to {budget:,} samples |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for run in runs:
        frames = FRAMES_LABEL[run["cache"]].format(backend=run["video_backend"])
        wall = run.get("wall_sps")
        base = decoded.get((run["setting"], run["batch_per_gpu"]))
        use = run.get("gpu_utilisation") or {}
        utilisation = f"{statistics.mean(use.values()):.0f}; {min(use.values()):.0f}" if use else "n/a"
        lines.append(
            f"| {run['setting']} | {run['gpus']} | {frames} "
            f"| {run['batch_per_gpu']} | {f'{wall:,.0f}' if wall else 'n/a'} "
            f"| {f'{wall / base:.2f}' if wall and base else 'n/a'} | {run['sps']:,.0f} | {utilisation} "
            f"| {run['update']:.3f} | {run['data']:.3f} | {f'{budget / wall / 60:.1f}' if wall else 'n/a'} |")
    (work / "scale.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


def main() -> None:
    from lerobot_tavis.dataset_tools.quiet import video_backend
    from lerobot_tavis.workers import usable_cores
    from lerobot_tavis.errors import InputError

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("stage", choices=["data", "train", "scale"])
    parser.add_argument("--work", type=Path, required=True)
    parser.add_argument("--storage", nargs="+", default=["av1", "h264", "png"])
    parser.add_argument("--episodes", type=int, default=24)
    parser.add_argument("--workers", type=int, default=None, help="recording processes / data-loader workers "
                        "(default 16; scale: all cores, of which each of N training processes gets cores / N - 2 "
                        "loader workers)")
    parser.add_argument("--cameras", default="head,left_wrist,right_wrist")
    parser.add_argument("--image-size", default="240x320", help="HxW of the dataset's frames")
    parser.add_argument("--preset", default="diffusion_head_wrist")
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--batch", type=int, nargs="+", default=None, help="batch per training process (default "
                        "64; scale: the setting's; several: one run each)")
    parser.add_argument("--device", choices=["cuda", "cpu"], default="cuda", help="cpu: check the plumbing of "
                        "`scale` without a GPU (--gpus then counts processes)")
    parser.add_argument("--tag", default="preset", help="name of the extra-argument setting, for the table")
    parser.add_argument("--gpus", type=int, nargs="+", default=[1, 2, 4], help="scale: GPU counts")
    parser.add_argument("--cache", nargs="+", choices=list(FRAME_SOURCES), default=list(FRAME_SOURCES),
                        help="scale: frames decoded (off), from the frame cache as uint8 (uint8) or converted to "
                        "float32 in the loader workers (float32)")
    parser.add_argument("--settings", nargs="+", default=list(SCALE_SETTINGS),
                        help=f"scale: training settings, of {', '.join(SCALE_SETTINGS)} or any shipped preset "
                        "(`tavis presets`) with its own batch")
    parser.add_argument("--warm-up", type=int, default=WARM_UP_STEPS, help="scale: steps left out of the "
                        f"measurement at the start of each run (default {WARM_UP_STEPS})")
    parser.add_argument("--loader-workers", type=int, default=None, help="scale: loader workers per training "
                        "process (default: cores / GPUs - 2)")
    parser.add_argument("--budget", type=int, default=409_600, help="scale: the sample budget whose time the "
                        "table gives (default: the hand-frame preset's 3200 steps of 128)")
    parser.add_argument("--video-backend", choices=["pyav", "torchcodec"], default=None,
                        help="scale: LeRobot's video decoder (default: torchcodec where it loads, else pyav)")
    parser.add_argument("--again", action="store_true", help="scale: measure the runs already measured again")
    args, extra = parser.parse_known_args()
    os.environ.setdefault("MUJOCO_GL", "egl")  # recording renders headless
    extra = [a for a in extra if a != "--"]
    args.extra = extra
    if args.workers is None:
        args.workers = usable_cores() if args.stage == "scale" else 16
    if args.stage == "data":
        make_data(args.work, args.episodes, args.workers, args.storage, args.cameras, args.image_size)
        return
    if args.stage == "scale":
        for name in args.settings:
            try:
                scale_setting(name)
            except InputError as error:
                parser.error(f"--settings: {error}")
        args.video_backend = args.video_backend or video_backend()
        scale(args)
        return
    print("| storage | frames | preset | setting | batch | samples/s | update s/step | data wait s/step | dataset MB "
          "| run s |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for storage in args.storage:
        root = dataset_root(args.work, storage, args.image_size)
        for batch in args.batch or [64]:
            result = train(args.work, root, args.preset, args.steps, batch, args.workers, extra,
                           f"{storage}_{args.image_size}_{args.tag}_batch{batch}")
            size_mb = sum(p.stat().st_size for p in root.rglob("*") if p.is_file()) / 1e6
            print(f"| {storage} | {args.image_size} | {args.preset} | {args.tag} {' '.join(extra)} | {batch} "
                  f"| {result['sps']:.0f} "
                  f"| {result['update']:.3f} | {result['data']:.3f} | {size_mb:.0f} | {result['run_s']:.0f} |",
                  flush=True)


if __name__ == "__main__":
    main()
