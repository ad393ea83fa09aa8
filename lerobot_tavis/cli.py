"""The `tavis` command. Subcommands delegate to the package modules; heavy imports happen inside them."""

from __future__ import annotations

import argparse
import sys


def _demo(args: argparse.Namespace) -> None:
    from lerobot_tavis.demo import TASKS, run_demo

    tasks = args.tasks or TASKS
    for path in run_demo(args.out, robots=args.robots, tasks=tasks, image_size=_image_size(args.image_size),
                         seed=args.seed):
        print(path)


def _eval(args: argparse.Namespace) -> None:
    from pathlib import Path

    from lerobot_tavis.eval.protocol import ProtocolConfig, run_protocol

    if bool(args.policy) == bool(args.expert):
        raise ValueError("give exactly one of --policy PATH and --expert")
    cfg = ProtocolConfig(out_dir=Path(args.out), robot=args.robot, suites=tuple(args.suite), splits=tuple(args.splits),
                         n_episodes=args.episodes, camera_mode=args.camera_mode,
                         image_size=_image_size(args.image_size), policy_path=args.policy,
                         batch_size=args.batch_size, device=args.device, workers=args.workers, seed=args.seed)
    for path in run_protocol(cfg):
        print(path)


def _report(args: argparse.Namespace) -> None:
    from lerobot_tavis.eval.report import write_report

    for path in write_report(args.eval_dir):
        print(path)


def _image_size(text: str) -> tuple[int, int]:
    try:
        height, width = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"image size must look like 480x640 (height x width), got {text!r}")
    return height, width


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="tavis", description="TAVIS active-vision benchmark in MuJoCo")
    commands = parser.add_subparsers(dest="command", required=True)
    demo = commands.add_parser("demo", help="one demonstrator episode per task and robot: MP4 of the four views")
    demo.add_argument("--out", default="outputs/demo", help="output directory (default: outputs/demo)")
    demo.add_argument("--robots", nargs="+", default=["gr1t2", "reachy2"], choices=["gr1t2", "reachy2"])
    demo.add_argument("--tasks", nargs="+", help="task names (default: the eight TAVIS tasks)")
    demo.add_argument("--image-size", default="240x320", help="HxW of every camera (default 240x320)")
    demo.add_argument("--seed", type=int, default=0)
    demo.set_defaults(run=_demo)

    evaluate = commands.add_parser("eval", help="the 96-episode protocol for a policy checkpoint or the demonstrators")
    evaluate.add_argument("--policy", help="policy checkpoint directory (pretrained_model)")
    evaluate.add_argument("--expert", action="store_true", help="evaluate the scripted demonstrators instead")
    evaluate.add_argument("--robot", default="gr1t2", choices=["gr1t2", "reachy2"])
    evaluate.add_argument("--suite", nargs="+", default=["tavis_head"], choices=["tavis_head", "tavis_hands"])
    evaluate.add_argument("--splits", nargs="+", default=["id", "ood_spatial", "ood_init_pose"],
                          choices=["id", "ood_spatial", "ood_init_pose"])
    evaluate.add_argument("--episodes", type=int, default=96, help="episodes per task and split (default 96)")
    evaluate.add_argument("--camera-mode", default="headcam",
                          choices=["headcam", "fixedcam", "head_wrist", "fixed_wrist"])
    evaluate.add_argument("--image-size", default="480x640")
    evaluate.add_argument("--batch-size", type=int, default=1, help="parallel envs per task (policy runs)")
    evaluate.add_argument("--device", default="cpu")
    evaluate.add_argument("--workers", type=int, default=1, help="parallel processes (demonstrator runs)")
    evaluate.add_argument("--seed", type=int, default=1000, help="first episode seed (lerobot-eval's default)")
    evaluate.add_argument("--out", required=True, help="output directory; finished cells are skipped on re-runs")
    evaluate.set_defaults(run=_eval)

    report = commands.add_parser("report", help="success rates with Wilson CIs, GALT, plots from eval outputs")
    report.add_argument("eval_dir", help="directory holding lerobot-eval outputs (eval_info.json, episodes.jsonl)")
    report.set_defaults(run=_report)
    return parser


def main(argv: list[str] | None = None) -> None:
    args = build_parser().parse_args(argv)
    try:
        args.run(args)
    except (ValueError, FileExistsError, FileNotFoundError) as error:
        sys.exit(f"tavis {args.command}: error: {error}")


if __name__ == "__main__":
    main()
