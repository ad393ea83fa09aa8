"""`tavis demo`: a scripted look-and-reach on each robot, filmed by all four cameras.

The head turns to centre an object, holds the fixation, then the arm on the object's side reaches, grasps and
lifts it. Writes one MP4 per camera per robot and a PNG sheet of the four views at the moment of the grasp.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from tqdm import tqdm

from lerobot_tavis import canonical
from lerobot_tavis.envs.env import TavisEnv
from lerobot_tavis.envs.objects import OBJECT_NAMES, YCB_OBJECTS
from lerobot_tavis.envs.rendering import CameraRig
from lerobot_tavis.experts.gaze import GazeSolver
from lerobot_tavis.experts.grasping import plan_grasp
from lerobot_tavis.experts.motion import ActionScript, Keyframe
from lerobot_tavis.media import sheet, write_mp4, write_png

FPS = 20


def look_and_reach_script(env: TavisEnv, target: str) -> tuple[ActionScript, float]:
    """The keyframes of the demo and the time (s) at which the gripper has closed."""
    model, data, world = env.model, env.data, env.world
    centre = data.xpos[model.body(target).id].copy()
    yaw = float(np.arctan2(*data.xmat[model.body(target).id].reshape(3, 3)[[1, 0], 0]))
    side = "left" if centre[1] >= 0 else "right"
    ik = env.controller.ik
    grasp = plan_grasp(ik, side, YCB_OBJECTS[target], centre, yaw)
    pitch, head_yaw = GazeSolver(world).angles_to(centre)
    look = canonical.rest_action()
    look[canonical.HEAD_PITCH], look[canonical.HEAD_YAW] = pitch, head_yaw
    pre = grasp.action(ik, look, offset_m=0.08)
    hover = pre.copy()
    hover[(canonical.LEFT if side == "left" else canonical.RIGHT).position][2] += 0.12
    keyframes = [
        Keyframe(canonical.rest_action(), 0.5),  # a look at the scene
        Keyframe(look, 0.25),  # saccade to the object
        Keyframe(look, 0.6),  # fixation
        Keyframe(hover, 1.5),
        Keyframe(pre, 0.8),
        Keyframe(grasp.action(ik, look), 0.8),
        Keyframe(grasp.action(ik, look, closed=True), 0.8),
        Keyframe(grasp.carried().action(ik, look, closed=True), 1.5),
        Keyframe(grasp.carried().action(ik, look, closed=True), 0.7),
    ]
    closed_at = sum(k.duration_s for k in keyframes[:7])
    return ActionScript(canonical.rest_action(), keyframes), closed_at


def run_demo(out_dir: str | Path, robots=("gr1t2", "reachy2"), image_size=(480, 640), seed: int = 0) -> list[Path]:
    out_dir = Path(out_dir)
    written = []
    for robot in robots:
        env = TavisEnv("tabletop", robot, camera_mode="headcam", image_size=image_size)
        env.reset(seed=seed)
        rig = CameraRig(env.model, env.world.cameras, image_size)
        target = OBJECT_NAMES[int(np.random.default_rng(seed).integers(len(OBJECT_NAMES)))]
        script, closed_at = look_and_reach_script(env, target)
        frames: dict[str, list[np.ndarray]] = {name: [] for name in env.world.cameras}
        grasp_views = None
        steps = int(np.ceil(script.duration_s * FPS))
        for step in tqdm(range(steps), desc=f"demo {robot}: look at and lift the {target}", unit="step"):
            env.step(script.action_at((step + 1) / FPS))
            views = rig.render(env.data)
            for name, image in views.items():
                frames[name].append(image)
            if grasp_views is None and (step + 1) / FPS >= closed_at:
                grasp_views = views
        rig.close()
        env.close()
        for name, images in frames.items():
            written.append(write_mp4(out_dir / robot / f"{name}.mp4", images, FPS))
        written.append(write_png(out_dir / robot / "cameras.png", sheet(grasp_views)))
    return written
