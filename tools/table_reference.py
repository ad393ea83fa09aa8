"""The TAVIS paper's overview figure beside our views of the same tasks (docs/images/table_reference.png).

    MUJOCO_GL=egl .venv/bin/python tools/table_reference.py --figure overview.png

`--figure` is the paper's overview figure (1654x787 px), whose TAVIS-Head panel shows each task's head and fixed
camera views on GR1T2. Top row: its thumbnails of TASKS (head, then fixed, for each task); bottom row: ours, GR1T2
at the grasp of seed 0's demonstrator episode (the gallery's grasp still), as the figure
shows a hand at an object.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import cv2
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
FIGURE_SIZE = (787, 1654)  # height, width (px)
HEAD_ROWS, FIXED_ROWS = (181, 270), (291, 380)  # the figure's thumbnail rows (px)
TASK_COLUMNS = {"conditional_pick": (197, 316), "clutter_pick_cube": (350, 469)}  # a task's thumbnail column (px)
TASKS = tuple(TASK_COLUMNS)
PANEL_SIZE = (120, 160)


def figure_panels(path: Path) -> list[np.ndarray]:
    """The figure's head and fixed thumbnails of TASKS, resized to PANEL_SIZE (RGB)."""
    figure = cv2.imread(str(path), cv2.IMREAD_COLOR)
    if figure is None:
        raise SystemExit(f"table_reference: error: cannot read {path} as an image")
    if figure.shape[:2] != FIGURE_SIZE:
        raise SystemExit(f"table_reference: error: {path} is {figure.shape[1]}x{figure.shape[0]} px, the paper's "
                         f"overview figure is {FIGURE_SIZE[1]}x{FIGURE_SIZE[0]}")
    figure = cv2.cvtColor(figure, cv2.COLOR_BGR2RGB)
    panels = []
    for task in TASKS:
        x0, x1 = TASK_COLUMNS[task]
        for y0, y1 in (HEAD_ROWS, FIXED_ROWS):
            crop = figure[y0:y1, x0:x1]
            panels.append(cv2.resize(crop, PANEL_SIZE[::-1], interpolation=cv2.INTER_CUBIC))
    return panels


def our_panels() -> list[np.ndarray]:
    """GR1T2's head and fixed views of TASKS at the demonstrator's grasp, seed 0 (the gallery's grasp stills)."""
    from lerobot_tavis.gallery import capture_stills

    panels = []
    for task in TASKS:
        grasp = capture_stills(task, "gr1t2", image_size=PANEL_SIZE).grasp
        panels += [grasp["head"], grasp["fixed"]]
    return panels


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--figure", type=Path, required=True, help="the TAVIS paper's overview figure (PNG)")
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "images" / "table_reference.png")
    args = parser.parse_args()

    from lerobot_tavis.media import label, write_png

    views = ("head", "fixed") * len(TASKS)
    rows = [np.concatenate([label(p, f"paper {v}") for p, v in zip(figure_panels(args.figure), views)], axis=1),
            np.concatenate([label(p, f"ours {v}") for p, v in zip(our_panels(), views)], axis=1)]
    print(write_png(args.out, np.concatenate(rows, axis=0)))


if __name__ == "__main__":
    main()
