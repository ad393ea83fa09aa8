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
    return parser


def main(argv: list[str] | None = None) -> None:
    args = build_parser().parse_args(argv)
    try:
        args.run(args)
    except (ValueError, FileExistsError, FileNotFoundError) as error:
        sys.exit(f"tavis {args.command}: error: {error}")


if __name__ == "__main__":
    main()
