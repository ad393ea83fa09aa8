"""`tavis gallery`: stills of every task on both robots, and the overview figure shown at the top of the README.

For each task and robot, one demonstrator episode (the `id` split) is played without rendering; the head, fixed,
grasping-wrist and overview cameras are rendered at the first observation and at the grasp (GRASP_DELAY_STEPS
after the demonstrator first commands a gripper closed). Writes:

- `<out>/gallery/<robot>/<task>.png`: two rows (first observation, grasp) of the four views;
- `<out>/gallery/<robot>/ood_visual.png`: the first observation of one conditional_pick episode in the `id` look,
  with each `ood_visual` factor alone, and with all of them (one row each);
- `<out>/overview.png`: TAVIS-Head tasks seen from the head and fixed cameras, TAVIS-Hands tasks from the head
  camera and the overview camera, and a portrait of each robot.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
from tqdm import tqdm

from lerobot_tavis import canonical, checks
from lerobot_tavis.cli_options import option
from lerobot_tavis.envs.env import TavisEnv
from lerobot_tavis.envs.rendering import CameraRig
from lerobot_tavis.envs.robots import BUILTIN_ROBOTS, DEFAULT_ROBOT, robot_info, robot_names
from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS, VISUAL_FACTORS, VISUAL_SPLIT, task_info
from lerobot_tavis.experts.rollout import make_expert
from lerobot_tavis.media import label, write_png

GRASP_DELAY_STEPS = 8  # 0.4 s after the close command: the fingers have met the object
SHEET_VIEWS = ("head", "fixed", "wrist", "overview")  # "wrist": the wrist camera of the arm that grasps
OOD_VISUAL_TASK, OOD_VISUAL_VIEWS = "conditional_pick", ("head", "fixed", "overview")
CAPTION_PX, CAPTION_SCALE = 26, 0.5
TILE_PAD, PANEL_PAD = 3, 6
HEAD_TINT, HANDS_TINT, ROBOTS_TINT = (190, 215, 235), (190, 230, 215), (245, 215, 190)
PORTRAIT_LOOKAT = (0.05, 0.0, 1.22)  # world point (m) the robot portraits are centred on
PORTRAIT_DISTANCE_M = 1.9
BACKGROUND = (255, 255, 255)


@dataclass(frozen=True)
class Stills:
    """Camera images (view name -> HxWx3 uint8) of one episode at its first observation and at the grasp."""

    task: str
    robot: str
    first: dict[str, np.ndarray]
    grasp: dict[str, np.ndarray]
    grasped: bool  # False: the demonstrator never closed a gripper, `grasp` is the last frame


def capture_stills(task: str, robot: str, *, image_size: tuple[int, int] = (240, 320), seed: int = 0) -> Stills:
    """Play the demonstrator of `task` on `robot` (seed `seed`, split `id`) and render the gallery views."""
    env = TavisEnv(task, robot, camera_mode="head_wrist", image_size=image_size, cameras=())
    env.reset(seed=seed)
    expert = make_expert(env, seed)
    expert.reset()
    cameras = {name: env.world.cameras[name] for name in ("head", "fixed", "left_wrist", "right_wrist", "overview")}
    rig = CameraRig(env.model, cameras, image_size, env.task_object.blacked_out_cameras)
    try:
        first = rig.render(env.data)
        closing_arm, steps_since_close = None, 0
        for _ in range(env._max_episode_steps):
            _, _, terminated, truncated, info = env.step(expert.act())
            if closing_arm is None:
                closing_arm = next((arm.side for arm in canonical.ARMS
                                    if info["applied_action"][arm.gripper] > 0.0), None)
            else:
                steps_since_close += 1
            if steps_since_close >= GRASP_DELAY_STEPS or terminated or truncated:
                break
        last = rig.render(env.data)
    finally:
        rig.close()
        env.close()
    wrist = f"{closing_arm or 'right'}_wrist"
    views = {"head": "head", "fixed": "fixed", "wrist": wrist, "overview": "overview"}
    return Stills(task, robot, first={v: first[c] for v, c in views.items()},
                  grasp={v: last[c] for v, c in views.items()}, grasped=closing_arm is not None)


def ood_visual_sheet(task: str, robot: str, *, image_size: tuple[int, int] = (240, 320), seed: int = 0) -> np.ndarray:
    """One labelled row per look of the same episode's first observation: `id`, each ood_visual factor alone, and
    all factors together (head, fixed and overview views)."""
    rows = []
    for split in ("id", *(f"{VISUAL_SPLIT}:{factor}" for factor in VISUAL_FACTORS), VISUAL_SPLIT):
        env = TavisEnv(task, robot, split=split, image_size=image_size, cameras=OOD_VISUAL_VIEWS)
        observation, _ = env.reset(seed=seed)
        env.close()
        rows.append(np.concatenate([label(observation["pixels"][view], f"{view} - {split}")
                                    for view in OOD_VISUAL_VIEWS], axis=1))
    return np.concatenate(rows, axis=0)


def robot_portrait(robot: str, image_size: tuple[int, int] = (480, 360)) -> np.ndarray:
    """The robot at rest seen from in front of the table (a free camera, not part of any observation)."""
    import mujoco

    env = TavisEnv("tabletop", robot, camera_mode="head_wrist", image_size=image_size, cameras=())
    env.reset(seed=0)
    camera = mujoco.MjvCamera()
    camera.lookat[:] = PORTRAIT_LOOKAT
    camera.distance, camera.azimuth, camera.elevation = PORTRAIT_DISTANCE_M, 180.0, -12.0
    with mujoco.Renderer(env.model, height=image_size[0], width=image_size[1]) as renderer:
        renderer.update_scene(env.data, camera=camera)
        image = renderer.render()
    env.close()
    return image


def task_sheet(stills: Stills) -> np.ndarray:
    """Two labelled rows (first observation, grasp) of the four gallery views."""
    rows = []
    for moment, frames in (("first observation", stills.first), ("grasp" if stills.grasped else "end", stills.grasp)):
        row = [label(frames[view], f"{view} - {moment}") for view in SHEET_VIEWS]
        rows.append(np.concatenate(row, axis=1))
    return np.concatenate(rows, axis=0)


def overview_figure(stills: dict[str, Stills], portraits: dict[str, np.ndarray]) -> np.ndarray:
    """The README figure: per suite, one column per task (head view above, a second view below); the robots beside
    the TAVIS-Hands panel.

    `stills` maps task name -> Stills of one robot (at the grasp), `portraits` robot name -> image.
    """
    head = [t for t in BENCHMARK_TASKS if task_info(t).suite == "tavis_head"]
    hands = [t for t in BENCHMARK_TASKS if task_info(t).suite == "tavis_hands"]
    hands_grid = _grid({t: stills[t].grasp for t in hands}, ("head", "overview"), ("head cam", "external view"))
    hands_panel = _panel("TAVIS-Hands (local occlusion and peeking)", HANDS_TINT, hands_grid)
    robots = _stack_horizontal([
        _stack_vertical([_caption(robot_info(name).title, image.shape[1]), _pad(image, TILE_PAD)])
        for name, image in portraits.items()])
    robots_panel = _panel("Robots", ROBOTS_TINT,
                          _fit_height(robots, hands_panel.shape[0] - 2 * PANEL_PAD - CAPTION_PX))
    return _stack_vertical([
        _panel("TAVIS-Head (global search and clutter)", HEAD_TINT,
               _grid({t: stills[t].grasp for t in head}, ("head", "fixed"), ("head cam", "fixed cam"))),
        _stack_horizontal([hands_panel, robots_panel]),
    ])


@dataclass(frozen=True)
class GalleryConfig:
    """What `tavis gallery` renders, and where; also its command-line options."""

    out_dir: Path = option(Path("docs/images"), "output directory (default: docs/images)", flag="--out")
    robots: tuple[str, ...] = option(default_factory=lambda: tuple(robot_names()), choices=robot_names)
    tasks: tuple[str, ...] = option(BENCHMARK_TASKS, "default: the eight TAVIS tasks", choices=BENCHMARK_TASKS)
    image_size: tuple[int, int] = option((240, 320), "HxW of every view (default 240x320)",
                                         parse=checks.image_size_text)
    seed: int = option(0, "episode seed of every task (default 0)")

    def __post_init__(self):
        checks.integer("seed", self.seed, 0)


def write_gallery(cfg: GalleryConfig, figure_robot: str = DEFAULT_ROBOT) -> list[Path]:
    """Render every task sheet and, when all eight tasks of `figure_robot` are included, the overview figure."""
    out_dir = Path(cfg.out_dir)
    written, by_robot = [], {}
    jobs = [(robot, task) for robot in cfg.robots for task in cfg.tasks]
    for robot, task in tqdm(jobs, desc="gallery", unit="episode"):
        stills = capture_stills(task, robot, image_size=cfg.image_size, seed=cfg.seed)
        by_robot.setdefault(robot, {})[task] = stills
        written.append(write_png(out_dir / "gallery" / robot / f"{task}.png", task_sheet(stills)))
    for robot in cfg.robots:
        sheet = ood_visual_sheet(OOD_VISUAL_TASK, robot, image_size=cfg.image_size, seed=cfg.seed)
        written.append(write_png(out_dir / "gallery" / robot / "ood_visual.png", sheet))
    if figure_robot in by_robot and set(by_robot[figure_robot]) == set(BENCHMARK_TASKS):
        portraits = {robot: robot_portrait(robot) for robot in BUILTIN_ROBOTS}  # the benchmark's robots
        written.append(write_png(out_dir / "overview.png", overview_figure(by_robot[figure_robot], portraits)))
    return written


def _grid(frames: dict[str, dict[str, np.ndarray]], views: tuple[str, ...], row_names: tuple[str, ...]):
    """Columns of tasks (captioned with the task name), rows of views (labelled on the left)."""
    columns = []
    for task, images in frames.items():
        tiles = [_pad(images[view], TILE_PAD) for view in views]
        columns.append(_stack_vertical([_caption(task.replace("_", "-"), tiles[0].shape[1]), *tiles]))
    tile_height = columns[0].shape[0] - CAPTION_PX
    labels = [np.full((CAPTION_PX, CAPTION_PX, 3), BACKGROUND, np.uint8)]
    labels += [np.rot90(_caption(name, tile_height // len(views))).copy() for name in row_names]
    return _stack_horizontal([_stack_vertical(labels), *columns])


def _panel(title: str, tint, body: np.ndarray) -> np.ndarray:
    """A titled panel whose white background is tinted, with a white margin around it."""
    panel = _stack_vertical([_caption(title, body.shape[1], left=True), body])
    background = (panel == BACKGROUND).all(axis=2, keepdims=True)
    return _pad(np.where(background, np.array(tint, np.uint8), panel), PANEL_PAD)


def _caption(text: str, width: int, *, left: bool = False) -> np.ndarray:
    """A CAPTION_PX-high strip with `text` centred (or left-aligned)."""
    strip = np.full((CAPTION_PX, width, 3), BACKGROUND, dtype=np.uint8)
    (text_w, _), _ = cv2.getTextSize(text, cv2.FONT_HERSHEY_SIMPLEX, CAPTION_SCALE, 1)
    x = 6 if left else max(2, (width - text_w) // 2)
    cv2.putText(strip, text, (x, CAPTION_PX - 9), cv2.FONT_HERSHEY_SIMPLEX, CAPTION_SCALE, (30, 30, 30), 1,
                cv2.LINE_AA)
    return strip


def _pad(image: np.ndarray, px: int) -> np.ndarray:
    """`image` with a white border of `px` pixels."""
    return cv2.copyMakeBorder(image, px, px, px, px, cv2.BORDER_CONSTANT, value=BACKGROUND)


def _fit_height(image: np.ndarray, height: int) -> np.ndarray:
    scale = height / image.shape[0]
    return cv2.resize(image, (round(image.shape[1] * scale), height), interpolation=cv2.INTER_AREA)


def _stack_horizontal(images: list[np.ndarray]) -> np.ndarray:
    height = max(i.shape[0] for i in images)
    return np.concatenate([cv2.copyMakeBorder(i, 0, height - i.shape[0], 0, 0, cv2.BORDER_CONSTANT, value=BACKGROUND)
                           for i in images], axis=1)


def _stack_vertical(images: list[np.ndarray]) -> np.ndarray:
    width = max(i.shape[1] for i in images)
    return np.concatenate([cv2.copyMakeBorder(i, 0, 0, 0, width - i.shape[1], cv2.BORDER_CONSTANT, value=BACKGROUND)
                           for i in images], axis=0)
