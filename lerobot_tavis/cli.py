"""The `tavis` command. Each subcommand's options are one dataclass, its parser generated from it (`cli_options`):
the config of the package module the subcommand runs where it has one, else one below. `build_parser` lists every
subcommand with the function that imports its module (a plain import, run only when that subcommand is parsed, so
`tavis --help` loads none of them) and returns its options dataclass and the function that runs it."""

from __future__ import annotations

import argparse
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterable
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path

from lerobot_tavis.cli_options import CommandParser, from_args, option, spelling
from lerobot_tavis.errors import FieldError, InputError, PathNotFoundError, TavisError, surroundings_message
from lerobot_tavis.tempdir import use_private_tempdir

INTERRUPT_GRACE_S = 1.0  # how long a broken worker pool waits for the Ctrl-C that may have broken it


@dataclass(frozen=True)
class VerifyOptions:
    root: Path = option(help="the dataset directory (a `tavis convert` output)", positional=True)
    episodes: tuple[int, ...] | None = option(None, "episode indices (default: all)")


@dataclass(frozen=True)
class NoiseStateOptions:
    source_root: Path = option(help="the dataset directory (LeRobotDataset v3.0, canonical observation.state)",
                               positional=True)
    out_root: Path = option(help="where the noisy copy goes (must not exist)", flag="--out")
    position_m: float = option(help="standard deviation of each hand position's noise per axis, m")
    rotation_deg: float = option(help="standard deviation of each component of each hand's rotation-vector noise, "
                                 "degrees")
    seed: int = option(0, "seed of the noise: the same seed makes the same copy")


@dataclass(frozen=True)
class PushOptions:
    root: Path = option(help="the dataset directory (a `tavis convert` output)", positional=True)
    repo_id: str = option(help="<user>/<name> on the Hub")
    private: bool = option(False, "make the Hub repository private")
    branch: str | None = option(None, "push to this branch (default: main)")


@dataclass(frozen=True)
class PushPolicyOptions:
    checkpoint: Path = option(help="the checkpoint's pretrained_model folder (<train output>/checkpoints/<step>/"
                                   "pretrained_model)", positional=True)
    repo_id: str = option(help="<user>/<name> of the model on the Hub")
    results: Path | None = option(None, "a `tavis eval` or `tavis report` results.json: uploaded, and its success "
                                        "rates written into the model card (default: none)")
    private: bool = option(False, "make the Hub repository private")
    branch: str | None = option(None, "push to this branch (default: main)")
    out: Path | None = option(None, "write the folder that would be uploaded (checkpoint, model card, results) here "
                                    "instead, without network or login, for a later `huggingface-cli upload` "
                                    "(default: upload)")


@dataclass(frozen=True)
class PullOptions:
    repo_id: str = option(help="<user>/<name> on the Hub", positional=True)
    root: Path | None = option(None, "where to put it (default: LeRobot's cache)")
    revision: str | None = option(None, "branch, tag or commit (default: the tag of LeRobot's dataset format, v3.0)")


@dataclass(frozen=True)
class PresetsOptions:
    name: str | None = option(None, "a preset name, e.g. diffusion_head_wrist", positional=True)


@dataclass(frozen=True)
class TrainOptions:
    preset: str = option(help="a preset name (see `tavis presets`)", positional=True)
    lerobot_args: tuple[str, ...] = option(help="e.g. --dataset.root=... --steps=1000", positional=True,
                                           nargs=argparse.REMAINDER)


@dataclass(frozen=True)
class ReportOptions:
    eval_dir: Path = option(help="directory holding lerobot-eval outputs (eval_info.json, episodes.jsonl)",
                            positional=True)
    workers: int | None = option(None, "processes annotating the videos (default: every core this process may use)")


@dataclass(frozen=True)
class CurveOptions:
    eval_root: Path = option(help="directory holding one `tavis eval` output per checkpoint, named step_<N>",
                             positional=True)


@dataclass(frozen=True)
class CompareOptions:
    eval_a: Path = option(help="a `tavis eval` output (or any folder of lerobot-eval outputs with episode logs)",
                          positional=True)
    eval_b: Path = option(help="another one, evaluated on the same seeds", positional=True)


def _printing(run: Callable[..., Iterable]) -> Callable[..., None]:
    """A subcommand's run: call `run` with the options and print each line it returns (written files, messages)."""

    def printed(cfg) -> None:
        for line in run(cfg):
            print(line)

    return printed


def _at_hand(options: type, run: Callable[..., None]) -> Callable[[], tuple[type, Callable[..., None]]]:
    """A subcommand whose options dataclass is in this module; its run imports what it needs."""
    return lambda: (options, run)


def _demo_command():
    from lerobot_tavis.demo import DemoConfig, run_demo

    return DemoConfig, _printing(run_demo)


def _gallery_command():
    from lerobot_tavis.gallery import GalleryConfig, write_gallery

    return GalleryConfig, _printing(write_gallery)


def _eval_command():
    from lerobot_tavis.eval.protocol import ProtocolConfig, run_protocol

    return ProtocolConfig, _printing(run_protocol)


def _record_command():
    from lerobot_tavis.dataset_tools.record import RecordConfig, record

    def run(cfg: RecordConfig) -> None:
        for task, count in record(cfg).counts().items():
            print(f"{task}: {count['kept']} kept, {count['discarded']} discarded")

    return RecordConfig, run


def _teleop_command():
    from lerobot_tavis.teleop import TeleopConfig, teleop

    return TeleopConfig, _printing(teleop)


def _view_command():
    from lerobot_tavis.viewer import ViewConfig, view

    return ViewConfig, view


def _convert_command():
    from lerobot_tavis.dataset_tools.convert import ConvertConfig, convert

    return ConvertConfig, lambda cfg: print(convert(cfg))


def _cache_frames_command():
    from lerobot_tavis.dataset_tools.frame_cache import CacheFramesConfig, write_frame_cache

    return CacheFramesConfig, _printing(write_frame_cache)


def _table_add_command():
    from lerobot_tavis.eval.baselines import TableAddConfig, run_table_add

    return TableAddConfig, _printing(run_table_add)


def _table_command():
    from lerobot_tavis.eval.baselines_table import TableConfig, run_table

    return TableConfig, _printing(run_table)


def _ablation_command():
    from lerobot_tavis.eval.baselines_table import AblationConfig, run_ablation

    return AblationConfig, _printing(run_ablation)


def _report(options: ReportOptions) -> None:
    from lerobot_tavis.eval.report import write_report

    for path in write_report(options.eval_dir, options.workers):
        print(path)


def _curve(options: CurveOptions) -> None:
    from lerobot_tavis.eval.checkpoint_curve import write_curve

    for path in write_curve(options.eval_root):
        print(path)


def _compare(options: CompareOptions) -> None:
    from lerobot_tavis.eval.compare import run_compare

    for line in run_compare(options):
        print(line)


def _verify_dataset(options: VerifyOptions) -> None:
    from lerobot_tavis.dataset_tools.verify import TOLERANCE_M, verify_dataset

    checks = verify_dataset(options.root, options.episodes)
    for check in checks:
        print(f"episode {check.episode_index:4d} {check.task} seed {check.seed}: hands within "
              f"{100 * check.max_hand_error_m:.2f} cm of the recording, replay "
              f"{'succeeds' if check.success else 'fails'}: {'ok' if check.passed else 'FAILED'}")
    failed = [check.episode_index for check in checks if not check.passed]
    if failed:
        sys.exit(f"tavis verify-dataset: {len(failed)} of {len(checks)} episodes do not replay as recorded "
                 f"(tolerance {100 * TOLERANCE_M:.1f} cm, success required): {failed}")
    print(f"{len(checks)} episodes replay as recorded")


def _noise_state(options: NoiseStateOptions) -> None:
    from lerobot_tavis.dataset_tools.state_noise import write_state_noise_copy

    summary = write_state_noise_copy(options.source_root, options.out_root, options.position_m, options.rotation_deg,
                                     options.seed)
    print(f"{options.out_root}: {summary.frames_changed} of {summary.frames} frames changed; hands moved "
          f"{summary.mean_position_shift_mm:.1f} mm and turned {summary.mean_rotation_deg:.2f} deg on average")


def _push(options: PushOptions) -> None:
    from lerobot_tavis.dataset_tools.hub import push_dataset

    print(push_dataset(options.root, options.repo_id, private=options.private, branch=options.branch))


def _push_policy(options: PushPolicyOptions) -> None:
    from lerobot_tavis.policy_hub import push_policy

    print(push_policy(options.checkpoint, options.repo_id, results=options.results, private=options.private,
                      branch=options.branch, out=options.out))


def _pull(options: PullOptions) -> None:
    from lerobot_tavis.dataset_tools.hub import pull_dataset

    dataset = pull_dataset(options.repo_id, root=options.root, revision=options.revision)
    print(f"{dataset.root}: {dataset.num_episodes} episodes, {dataset.num_frames} frames at {dataset.fps} fps")


def _presets(options: PresetsOptions) -> None:
    from lerobot_tavis.policy_configs import preset_names, preset_path

    if options.name:
        print(preset_path(options.name))
        return
    for name in preset_names():
        print(name)


def _train(options: TrainOptions) -> None:
    import subprocess

    from lerobot_tavis.policy_configs import check_training_dataset, missing_pi0_downloads, preset_path

    path = preset_path(options.preset)
    _check_dataset_root(path, options.lerobot_args)
    check_training_dataset(path, options.lerobot_args)
    if options.preset.startswith("pi0") and (missing := missing_pi0_downloads()):
        raise InputError(f"pi0 needs {', '.join(missing)}, which are neither in the Hugging Face cache nor "
                         "downloadable here: log in (`hf auth login`, and accept the PaliGemma licence on the Hub) "
                         "or fill HF_HOME on a machine with network access")
    command = [sys.executable, "-m", "lerobot.scripts.lerobot_train", f"--config_path={path}", *options.lerobot_args]
    sys.exit(subprocess.call(command))


def version_line() -> str:
    """`tavis --version`: this package's version and those of the packages a bug report needs, read from their
    installed metadata (nothing is imported)."""
    from importlib.metadata import PackageNotFoundError, version

    def installed(name: str) -> str:
        try:
            return version(name)
        except PackageNotFoundError:
            return "not installed"

    others = ", ".join(f"{name} {installed(name)}" for name in ("lerobot", "mujoco", "torch"))
    return f"tavis (lerobot_env_tavis) {installed('lerobot_env_tavis')}; {others}"


def _check_dataset_root(preset: Path, lerobot_args: tuple[str, ...]) -> None:
    """The dataset a training reads must be on disk unless it is a Hub dataset: a missing --dataset.root is one line
    here, not lerobot-train's failed Hub download of the preset's placeholder `local/...` repo id. The root is
    --dataset.root, else LeRobot's default `$HF_LEROBOT_HOME/<repo_id>`."""
    import json

    from huggingface_hub.constants import HF_HOME

    dataset = argparse.ArgumentParser(add_help=False, allow_abbrev=False)  # LeRobot's --a.b=x and --a.b x alike
    dataset.add_argument("--dataset.root", dest="root")
    dataset.add_argument("--dataset.repo_id", dest="repo_id")
    given, _ = dataset.parse_known_args(lerobot_args)
    repo_id = given.repo_id or json.loads(preset.read_text())["dataset"]["repo_id"]
    root = given.root
    if root is not None:
        if not (Path(root) / "meta" / "info.json").is_file():
            raise PathNotFoundError(f"--dataset.root {root} holds no LeRobotDataset (no meta/info.json): pass the "
                                    "folder `tavis convert --root` wrote")
    elif repo_id.startswith("local/"):
        home = Path(os.environ.get("HF_LEROBOT_HOME", Path(HF_HOME) / "lerobot")).expanduser()
        if not (home / repo_id / "meta" / "info.json").is_file():
            raise InputError(f"no --dataset.root: pass --dataset.root=<the folder `tavis convert --root` wrote> (the "
                             f"dataset {repo_id} is local, not on the Hub), or --dataset.repo_id=<owner>/<name> of a "
                             "dataset on the Hub")


def build_parser() -> argparse.ArgumentParser:
    """The `tavis` parser: one subcommand per (name, command, help) below, where `command()` imports the
    subcommand's module and returns its options dataclass and run function."""
    parser = argparse.ArgumentParser(prog="tavis", description="TAVIS active-vision benchmark in MuJoCo")
    parser.add_argument("--version", action="version", version=version_line())
    commands = parser.add_subparsers(dest="command", required=True, parser_class=CommandParser)
    for name, command, help in (
        ("demo", _demo_command, "one demonstrator episode per task and robot: MP4 of the four views"),
        ("gallery", _gallery_command,
         "stills of every task and robot (first observation, grasp) and the README overview figure"),
        ("eval", _eval_command, "the 96-episode protocol for a policy checkpoint or the demonstrators"),
        ("record", _record_command, "record scripted demonstrations at 60 Hz (replayable raw episodes)"),
        ("teleop", _teleop_command, "drive the robot with the keyboard and record raw episodes (a window)"),
        ("view", _view_command, "MuJoCo's interactive viewer on one episode (a window)"),
        ("convert", _convert_command, "raw episodes (or an original TAVIS dataset) -> LeRobotDataset v3.0"),
        ("cache-frames", _cache_frames_command,
         "decode a dataset's video frames once into a cache beside it, for lerobot-train with TAVIS_FRAME_CACHE=1"),
        ("verify-dataset", _at_hand(VerifyOptions, _verify_dataset),
         "replay a converted dataset's actions open loop and check they reproduce its recorded states (exit 1 if "
         "not)"),
        ("noise-state", _at_hand(NoiseStateOptions, _noise_state),
         "copy a dataset with Gaussian noise on the hand poses of observation.state (a training augmentation)"),
        ("push", _at_hand(PushOptions, _push), "upload a converted dataset to the Hugging Face Hub, with its card"),
        ("push-policy", _at_hand(PushPolicyOptions, _push_policy),
         "upload a trained policy checkpoint to the Hugging Face Hub, with a model card (and its results)"),
        ("pull", _at_hand(PullOptions, _pull), "download a TAVIS dataset from the Hugging Face Hub"),
        ("presets", _at_hand(PresetsOptions, _presets), "list the training presets, or print the path of one"),
        ("train", _at_hand(TrainOptions, _train),
         "lerobot-train with a preset (checks the dataset's cameras and image size and pi0 downloads first); extra "
         "arguments go to lerobot-train"),
        ("report", _at_hand(ReportOptions, _report),
         "success rates with Wilson CIs, GALT, failure stages, plots from eval outputs"),
        ("curve", _at_hand(CurveOptions, _curve),
         "success by training step from one eval output per checkpoint (step_<N>/): checkpoints.md and .png"),
        ("compare", _at_hand(CompareOptions, _compare),
         "two evaluations of the same seeds, episode by episode: successes of each and the exact McNemar test"),
        ("table-add", _table_add_command,
         "add (or replace) one cell of the baselines table in docs/results/baselines.json, checked against its "
         "results.json"),
        ("table", _table_command,
         "the baselines table from docs/results/baselines.json: per robot, tasks x conditions and splits with Wilson "
         "CIs, GALT, pooled rows, the paper's numbers and targets (Markdown), and its plot"),
        ("ablation", _ablation_command,
         "the wrist-only ablation (clutter_pick_cube with and without the head camera's active vision against "
         "blocked_clutter_pick_cube) from the baselines table: Wilson CIs and exact McNemar"),
    ):
        commands.add_parser(name, help=help, command=command)
    return parser


def _exit_on_sigterm(signum, frame) -> None:
    raise SystemExit(128 + signum)  # unwinds like Ctrl-C: staging copies are removed, workers stop


def main(argv: list[str] | None = None) -> None:
    command, args = "tavis", None
    try:
        args = build_parser().parse_args(argv)
        command = f"tavis {args.command}"
        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGTERM, _exit_on_sigterm)
        use_private_tempdir()  # this run's temporary files, and its workers', are removed at exit or by the next run
        args.run(from_args(args.options, args))
    except TavisError as error:  # the user's input or surroundings; anything else is a bug, with its traceback
        sys.exit(f"{command}: error: {_message(error, args)}")
    except OSError as error:
        if (line := surroundings_message(error)) is None:
            raise
        sys.exit(f"{command}: error: {line}")
    except KeyboardInterrupt:  # Ctrl-C; the unwinding has removed the staging copies and stopped the workers
        _interrupted(command)
    except BrokenProcessPool:
        # Ctrl-C reaches the workers too, which end at once: the pool may report them gone before this process's
        # own KeyboardInterrupt arrives. Wait for it; a pool broken otherwise is a bug, with its traceback.
        try:
            time.sleep(INTERRUPT_GRACE_S)
        except KeyboardInterrupt:
            _interrupted(command)
        raise


def _interrupted(command: str) -> None:
    print(f"{command}: interrupted", file=sys.stderr)
    sys.exit(128 + signal.SIGINT)


def _message(error: Exception, args: argparse.Namespace | None) -> str:
    """The error in one line; a config's error about one of its fields names the option that set it instead."""
    if isinstance(error, FieldError) and args is not None:
        return f"{spelling(args.options, error.field)} {error.problem}"
    return str(error)


if __name__ == "__main__":
    main()
