"""The `tavis` command. Subcommands delegate to the package modules; heavy imports happen inside them."""

from __future__ import annotations

import argparse
import re
import signal
import sys
import threading
from pathlib import Path

from lerobot_tavis.dataset_tools.features import STORAGES
from lerobot_tavis.dataset_tools.workers import BACKENDS
from lerobot_tavis.envs.modes import CAMERA_NAMES, DEFAULT_CAMERA_MODE, RENAMED_MODES, VIEW_CAMERAS, camera_mode_names
from lerobot_tavis.envs.robots import DEFAULT_ROBOT, robot_names
from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS, PROTOCOL_SPLITS, SUITES, split_names, task_names
from lerobot_tavis.errors import FieldError, InputError, PathNotFoundError, TavisError


def _demo(args: argparse.Namespace) -> None:
    from lerobot_tavis.demo import TASKS, run_demo

    tasks = args.tasks or TASKS
    for path in run_demo(args.out, robots=args.robots, tasks=tasks, image_size=_image_size(args.image_size),
                         seed=args.seed):
        print(path)


def _gallery(args: argparse.Namespace) -> None:
    from lerobot_tavis.gallery import write_gallery

    for path in write_gallery(args.out, robots=args.robots, tasks=args.tasks or BENCHMARK_TASKS,
                              image_size=_image_size(args.image_size), seed=args.seed):
        print(path)


# `tavis eval` settings when neither the command line nor the checkpoint's training config gives them.
EVAL_DEFAULTS = {"robot": DEFAULT_ROBOT, "camera_mode": DEFAULT_CAMERA_MODE, "image_size": (480, 640)}


def _eval(args: argparse.Namespace) -> None:
    from lerobot_tavis.eval.protocol import ProtocolConfig, checkpoint_env, run_protocol

    if bool(args.policy) == bool(args.expert):
        raise InputError("give exactly one of --policy PATH and --expert")
    trained = {}
    if args.policy:
        if Path(args.policy).exists():
            trained = checkpoint_env(args.policy)
        elif not _looks_like_repo_id(args.policy):
            raise PathNotFoundError(f"--policy {args.policy}: no such checkpoint directory")
    given = {"robot": args.robot, "camera_mode": args.camera_mode,
             "image_size": _image_size(args.image_size) if args.image_size else None}
    settings = {**EVAL_DEFAULTS, **trained, **{key: value for key, value in given.items() if value is not None}}
    cfg = ProtocolConfig(out_dir=Path(args.out), suites=tuple(args.suite), splits=tuple(args.splits),
                         n_episodes=args.episodes, policy_path=args.policy, batch_size=args.batch_size,
                         device=args.device, workers=args.workers, seed=args.seed, backend=args.backend,
                         chunk_episodes=args.chunk_episodes, episode_length_s=args.episode_length_s,
                         policy_options=tuple(_policy_option(text) for text in args.policy_option), **settings)
    for path in run_protocol(cfg):
        print(path)


def _policy_option(text: str) -> tuple[str, object]:
    """`num_inference_steps=10` -> ("num_inference_steps", 10): values are read as JSON, else kept as text."""
    import json

    name, sign, value = text.partition("=")
    if not (sign and name.strip()):
        raise InputError(f"--policy-option must be FIELD=VALUE, e.g. num_inference_steps=10, got {text!r}")
    try:
        return name.strip(), json.loads(value)
    except json.JSONDecodeError:
        return name.strip(), value


def _looks_like_repo_id(text: str) -> bool:
    from lerobot_tavis.checks import repo_id

    try:
        repo_id(text)
    except ValueError:
        return False
    return True


def _report(args: argparse.Namespace) -> None:
    from lerobot_tavis.eval.report import write_report

    for path in write_report(args.eval_dir):
        print(path)


def _record(args: argparse.Namespace) -> None:
    from lerobot_tavis.dataset_tools.record import RecordConfig, record
    from lerobot_tavis.envs.tasks.catalog import expand_tasks

    tasks = tuple(t for group in expand_tasks(",".join(args.tasks or [args.suite])).values() for t in group)
    manifest = record(RecordConfig(out_dir=Path(args.out), robot=args.robot, tasks=tasks,
                                   episodes_per_task=args.episodes_per_task, split=args.split,
                                   keep_failures=args.keep_failures, seed_start=args.seed_start,
                                   workers=args.workers, backend=args.backend))
    for task, count in manifest.counts().items():
        print(f"{task}: {count['kept']} kept, {count['discarded']} discarded")


def _teleop(args: argparse.Namespace) -> None:
    from lerobot_tavis.teleop import TeleopConfig, teleop

    for line in teleop(TeleopConfig(out_dir=Path(args.out), task=args.task, robot=args.robot, split=args.split,
                                    episodes=args.episodes, seed_start=args.seed_start,
                                    keep_failures=args.keep_failures, view=args.view, gamepad=args.gamepad)):
        print(line)


def _view(args: argparse.Namespace) -> None:
    from lerobot_tavis.viewer import ViewConfig, view

    driver = args.driver or ("policy" if args.policy else "demonstrator")
    view(ViewConfig(task=args.task, robot=args.robot, split=args.split, seed=args.seed, driver=driver,
                    policy=args.policy, device=args.device, camera=None if args.camera == "free" else args.camera))


def _convert(args: argparse.Namespace) -> None:
    if bool(args.raw_dir) == bool(args.from_tavis):
        raise InputError("give exactly one of RAW_DIR (a `tavis record` output) and --from-tavis ROOT")
    image_size = _image_size(args.image_size) if args.image_size else None
    if args.from_tavis:
        if args.zero_neck or args.storage != "av1":
            raise InputError("--zero-neck and --storage apply to raw episodes, not to --from-tavis")
        from lerobot_tavis.dataset_tools.from_tavis import convert_from_tavis

        root = convert_from_tavis(Path(args.from_tavis), args.repo_id, Path(args.root), fps=args.fps,
                                  image_size=image_size, overwrite=args.overwrite, task=args.task)
    else:
        from lerobot_tavis.dataset_tools.convert import ConvertConfig, convert

        root = convert(ConvertConfig(raw_dir=Path(args.raw_dir), repo_id=args.repo_id, root=Path(args.root),
                                     fps=args.fps, image_size=image_size or (480, 640), cameras=args.cameras,
                                     task=args.task, overwrite=args.overwrite, zero_neck=args.zero_neck,
                                     storage=args.storage, workers=args.workers))
    print(root)


def _verify_dataset(args: argparse.Namespace) -> None:
    from lerobot_tavis.dataset_tools.verify import TOLERANCE_M, verify_dataset

    checks = verify_dataset(Path(args.root), args.episodes)
    for check in checks:
        print(f"episode {check.episode_index:4d} {check.task} seed {check.seed}: hands within "
              f"{100 * check.max_hand_error_m:.2f} cm of the recording, replay "
              f"{'succeeds' if check.success else 'fails'}: {'ok' if check.passed else 'FAILED'}")
    failed = [check.episode_index for check in checks if not check.passed]
    if failed:
        sys.exit(f"tavis verify-dataset: {len(failed)} of {len(checks)} episodes do not replay as recorded "
                 f"(tolerance {100 * TOLERANCE_M:.1f} cm, success required): {failed}")
    print(f"{len(checks)} episodes replay as recorded")


def _push(args: argparse.Namespace) -> None:
    from lerobot_tavis.dataset_tools.hub import push_dataset

    print(push_dataset(Path(args.root), args.repo_id, private=args.private, branch=args.branch))


def _pull(args: argparse.Namespace) -> None:
    from lerobot_tavis.dataset_tools.hub import pull_dataset

    dataset = pull_dataset(args.repo_id, root=args.root, revision=args.revision)
    print(f"{dataset.root}: {dataset.num_episodes} episodes, {dataset.num_frames} frames at {dataset.fps} fps")


def _presets(args: argparse.Namespace) -> None:
    from lerobot_tavis.policy_configs import preset_names, preset_path

    if args.name:
        print(preset_path(args.name))
        return
    for name in preset_names():
        print(name)


def _train(args: argparse.Namespace) -> None:
    import subprocess

    from lerobot_tavis.policy_configs import missing_pi0_downloads, preset_path

    path = preset_path(args.preset)
    if args.preset.startswith("pi0") and (missing := missing_pi0_downloads()):
        raise InputError(f"pi0 needs {', '.join(missing)}, which are neither in the Hugging Face cache nor "
                         "downloadable here: log in (`hf auth login`, and accept the PaliGemma licence on the Hub) "
                         "or fill HF_HOME on a machine with network access")
    command = [sys.executable, "-m", "lerobot.scripts.lerobot_train", f"--config_path={path}", *args.lerobot_args]
    sys.exit(subprocess.call(command))


def _image_size(text: str) -> tuple[int, int]:
    match = re.fullmatch(r"\s*([0-9]+)\s*[xX]\s*([0-9]+)\s*", text)
    if not match or not all(int(side) > 0 for side in match.groups()):
        raise InputError(f"--image-size must be HxW in pixels, e.g. 480x640 (height x width), got {text!r}")
    return int(match[1]), int(match[2])


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="tavis", description="TAVIS active-vision benchmark in MuJoCo")
    commands = parser.add_subparsers(dest="command", required=True)
    demo = commands.add_parser("demo", help="one demonstrator episode per task and robot: MP4 of the four views")
    demo.add_argument("--out", default="outputs/demo", help="output directory (default: outputs/demo)")
    demo.add_argument("--robots", nargs="+", default=list(robot_names()), choices=robot_names())
    demo.add_argument("--tasks", nargs="+", help="task names (default: the eight TAVIS tasks)")
    demo.add_argument("--image-size", default="240x320", help="HxW of every camera (default 240x320)")
    demo.add_argument("--seed", type=int, default=0)
    demo.set_defaults(run=_demo, options={"task": "--tasks"})

    gallery = commands.add_parser("gallery", help="stills of every task and robot (first observation, grasp) and "
                                  "the README overview figure")
    gallery.add_argument("--out", default="docs/images", help="output directory (default: docs/images)")
    gallery.add_argument("--robots", nargs="+", default=list(robot_names()), choices=robot_names())
    gallery.add_argument("--tasks", nargs="+", choices=BENCHMARK_TASKS, help="default: the eight TAVIS tasks")
    gallery.add_argument("--image-size", default="240x320", help="HxW of every view (default 240x320)")
    gallery.add_argument("--seed", type=int, default=0, help="episode seed of every task (default 0)")
    gallery.set_defaults(run=_gallery)

    evaluate = commands.add_parser("eval", help="the 96-episode protocol for a policy checkpoint or the demonstrators")
    evaluate.add_argument("--policy", help="policy checkpoint directory (pretrained_model)")
    evaluate.add_argument("--expert", action="store_true", help="evaluate the scripted demonstrators instead")
    evaluate.add_argument("--robot", choices=robot_names(), help=f"default: the checkpoint's, else {DEFAULT_ROBOT}")
    evaluate.add_argument("--suite", nargs="+", default=[SUITES[0]], choices=SUITES)
    evaluate.add_argument("--splits", nargs="+", default=list(PROTOCOL_SPLITS), choices=split_names(),
                          help="default: the reference's id ood_spatial ood_init_pose; also ood_visual (the look "
                          "changed) and ood_visual:<factor> for one factor alone")
    evaluate.add_argument("--episodes", type=int, default=96, help="episodes per task and split (default 96)")
    evaluate.add_argument("--camera-mode", choices=[*camera_mode_names(), *RENAMED_MODES],
                          help="default: the checkpoint's, else head_wrist; head_wrist and fixed_wrist are the "
                          "paper's headcam and fixedcam conditions")
    evaluate.add_argument("--image-size", help="HxW; default: the checkpoint's, else 480x640")
    evaluate.add_argument("--batch-size", type=int, default=1, help="parallel envs per task (policy runs)")
    evaluate.add_argument("--device", default="cpu")
    evaluate.add_argument("--episode-length-s", type=float, default=20.0, help="seconds per episode (default 20)")
    evaluate.add_argument("--policy-option", action="append", default=[], metavar="FIELD=VALUE",
                          help="set a field of the checkpoint's policy config, e.g. num_inference_steps=10 or "
                          "use_amp=true (repeatable)")
    evaluate.add_argument("--workers", type=int, default=1,
                          help="(cell, task, seed chunk) jobs at once; with a policy on a GPU they share it")
    evaluate.add_argument("--chunk-episodes", type=int,
                          help="consecutive episodes per job, also what a killed run loses at most (default 8 for the "
                          "demonstrators, 96 for a policy: each policy job starts a lerobot-eval run)")
    evaluate.add_argument("--backend", default="local", choices=BACKENDS,
                          help="local processes, or a Ray cluster (RAY_ADDRESS; docs/scaling.md)")
    evaluate.add_argument("--seed", type=int, default=1000, help="first episode seed (lerobot-eval's default)")
    evaluate.add_argument("--out", required=True, help="output directory; finished cells are skipped on re-runs")
    evaluate.set_defaults(run=_eval, options={"n_episodes": "--episodes"})

    rec = commands.add_parser("record", help="record scripted demonstrations at 60 Hz (replayable raw episodes)")
    rec.add_argument("--robot", default=DEFAULT_ROBOT, choices=robot_names())
    rec.add_argument("--suite", default=SUITES[0], choices=SUITES)
    rec.add_argument("--tasks", nargs="+", help="task names (default: every task of --suite)")
    rec.add_argument("--split", default="id", choices=split_names())
    rec.add_argument("--episodes-per-task", type=int, default=160, help="kept episodes per task (default 160)")
    rec.add_argument("--keep-failures", action="store_true", help="keep failed episodes too (default: discard)")
    rec.add_argument("--seed-start", type=int, default=100_000, help="first seed (evaluation uses 1000..)")
    rec.add_argument("--workers", type=int, default=1, help="episodes at once (local backend: processes)")
    rec.add_argument("--backend", default="local", choices=BACKENDS,
                     help="local processes, or a Ray cluster (RAY_ADDRESS; docs/scaling.md)")
    rec.add_argument("--out", required=True, help="raw directory; re-running resumes it")
    rec.set_defaults(run=_record, options={"task": "--tasks"})

    tele = commands.add_parser("teleop", help="drive the robot with the keyboard and record raw episodes (a window)")
    tele.add_argument("--task", required=True, choices=task_names())
    tele.add_argument("--robot", default=DEFAULT_ROBOT, choices=robot_names())
    tele.add_argument("--split", default="id", choices=split_names())
    tele.add_argument("--episodes", type=int, default=1, help="kept episodes to record (default 1)")
    tele.add_argument("--seed-start", type=int, default=200_000, help="first seed (default 200000)")
    tele.add_argument("--keep-failures", action="store_true", help="keep episodes that did not succeed too")
    tele.add_argument("--view", default="head", choices=[*CAMERA_NAMES, *VIEW_CAMERAS, "free"],
                      help="the window's camera (default head)")
    tele.add_argument("--gamepad", action="store_true",
                      help="also drive the active hand with a gamepad (LeRobot's controller; needs pygame)")
    tele.add_argument("--out", required=True, help="raw directory, as `tavis record` writes; re-running adds to it")
    tele.set_defaults(run=_teleop)

    view = commands.add_parser("view", help="MuJoCo's interactive viewer on one episode (a window)")
    view.add_argument("--task", required=True, choices=task_names())
    view.add_argument("--robot", choices=robot_names(), help=f"default: the checkpoint's, else {DEFAULT_ROBOT}")
    view.add_argument("--split", default="id", choices=split_names())
    view.add_argument("--seed", type=int, default=1000)
    view.add_argument("--driver", choices=["demonstrator", "policy", "paused"],
                      help="who acts (default: the policy when --policy is given, else the demonstrator)")
    view.add_argument("--policy", help="a checkpoint's pretrained_model folder; its camera mode and image size apply")
    view.add_argument("--device", default="cpu", help="the policy's device (default cpu)")
    view.add_argument("--camera", default="free", choices=[*CAMERA_NAMES, *VIEW_CAMERAS, "free"],
                      help="the window's camera (default: the free camera, moved with the mouse)")
    view.set_defaults(run=_view)

    conv = commands.add_parser("convert", help="raw episodes (or an original TAVIS dataset) -> LeRobotDataset v3.0")
    conv.add_argument("raw_dir", nargs="?", help="a `tavis record` output directory")
    conv.add_argument("--from-tavis", metavar="ROOT", help="convert an original TAVIS dataset (60 Hz) instead")
    conv.add_argument("--repo-id", required=True, help="dataset id, e.g. <user>/tavis-head-gr1t2")
    conv.add_argument("--root", required=True, help="destination directory (must not exist unless --overwrite)")
    conv.add_argument("--fps", type=int, default=20, help="dataset rate; must divide 60 (default 20)")
    conv.add_argument("--image-size", help="HxW of every camera (default 480x640; --from-tavis: the source size)")
    conv.add_argument("--cameras", default="head,fixed,left_wrist,right_wrist", help="comma list of cameras")
    conv.add_argument("--task", help="convert only this task")
    conv.add_argument("--overwrite", action="store_true", help="replace an existing destination")
    conv.add_argument("--storage", default="av1", choices=STORAGES,
                      help="camera frames as AV1 video (LeRobot's default, smallest), all-intra H.264 video (fast "
                           "random access for training) or PNG images (no video decoding; largest)")
    conv.add_argument("--zero-neck", action="store_true",
                      help="neck dims of state and action = 0 (datasets for the fixed-camera presets)")
    conv.add_argument("--workers", type=int, default=1,
                      help="processes replaying and rendering episodes (the dataset does not depend on it)")
    conv.set_defaults(run=_convert)

    verify = commands.add_parser("verify-dataset", help="replay a converted dataset's actions open loop and check "
                                 "they reproduce its recorded states (exit 1 if not)")
    verify.add_argument("root", help="the dataset directory (a `tavis convert` output)")
    verify.add_argument("--episodes", type=int, nargs="+", help="episode indices (default: all)")
    verify.set_defaults(run=_verify_dataset)

    push = commands.add_parser("push", help="upload a converted dataset to the Hugging Face Hub, with its card")
    push.add_argument("root", help="the dataset directory (a `tavis convert` output)")
    push.add_argument("--repo-id", required=True, help="<user>/<name> on the Hub")
    push.add_argument("--private", action="store_true")
    push.add_argument("--branch", help="push to this branch (default: main)")
    push.set_defaults(run=_push)

    pull = commands.add_parser("pull", help="download a TAVIS dataset from the Hugging Face Hub")
    pull.add_argument("repo_id", help="<user>/<name> on the Hub")
    pull.add_argument("--root", help="where to put it (default: LeRobot's cache)")
    pull.add_argument("--revision", help="branch, tag or commit")
    pull.set_defaults(run=_pull, options={"repo_id": "repo_id"})

    presets = commands.add_parser("presets", help="list the training presets, or print the path of one")
    presets.add_argument("name", nargs="?", help="a preset name, e.g. diffusion_head_wrist")
    presets.set_defaults(run=_presets)

    train = commands.add_parser("train", help="lerobot-train with a preset (checks pi0 downloads first); "
                                "extra arguments go to lerobot-train")
    train.add_argument("preset", help="a preset name (see `tavis presets`)")
    train.add_argument("lerobot_args", nargs=argparse.REMAINDER, help="e.g. --dataset.root=... --steps=1000")
    train.set_defaults(run=_train)

    report = commands.add_parser("report", help="success rates with Wilson CIs, GALT, plots from eval outputs")
    report.add_argument("eval_dir", help="directory holding lerobot-eval outputs (eval_info.json, episodes.jsonl)")
    report.set_defaults(run=_report)
    return parser


def _exit_on_sigterm(signum, frame) -> None:
    raise SystemExit(128 + signum)  # unwinds like Ctrl-C: staging copies are removed, workers stop


def main(argv: list[str] | None = None) -> None:
    args = build_parser().parse_args(argv)
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _exit_on_sigterm)
    try:
        args.run(args)
    except TavisError as error:  # the user's input or surroundings; anything else is a bug, with its traceback
        sys.exit(f"tavis {args.command}: error: {_message(error, args)}")


def _message(error: Exception, args: argparse.Namespace) -> str:
    """The error in one line; a config's error about one of its fields names the option that set it instead."""
    if isinstance(error, FieldError):
        option = getattr(args, "options", {}).get(error.field, "--" + error.field.replace("_", "-"))
        return f"{option} {error.problem}"
    return str(error)


if __name__ == "__main__":
    main()
