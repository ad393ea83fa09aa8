"""Compose arena + robot + task into one MjModel, and index the addresses the env reads and writes."""

from __future__ import annotations

import ctypes
import ctypes.util
from dataclasses import dataclass

import mujoco
import numpy as np

from lerobot_tavis.envs import physics, scene, visual_ood
from lerobot_tavis.envs.modes import CAMERA_NAMES, VIEW_CAMERAS
from lerobot_tavis.envs.robots.base import Robot
from lerobot_tavis.envs.tasks.base import Task



@dataclass(frozen=True)
class ArmIndex:
    qpos: np.ndarray  # (7,) qpos addresses of the arm joints, shoulder to wrist
    actuators: np.ndarray  # (7,) actuator ids, same order
    ee_site: int
    grasp_site: int
    finger_qpos: np.ndarray  # (2,) qpos addresses of the fingers (each one's distance from the centre line, m)
    gripper_actuator: int


@dataclass(frozen=True)
class World:
    model: mujoco.MjModel
    robot: Robot
    arms: dict[str, ArmIndex]
    neck_qpos: np.ndarray  # (3,) roll, pitch, yaw
    neck_actuators: np.ndarray
    cameras: dict[str, int]  # camera name (CAMERA_NAMES and VIEW_CAMERAS) -> model camera id
    robot_joint_qpos: np.ndarray  # qpos addresses of Robot.joint_names(), in that order


def build_world(robot: Robot, task: Task, *, image_size: tuple[int, int], shadows: bool = True,
                visual_variation: bool = False) -> World:
    """The compiled world of `task` on `robot`; `visual_variation` adds what the ood_visual split varies."""
    spec = mujoco.MjSpec()
    spec.modelname = f"tavis_{task.info.name}_{robot.name}"
    physics.configure(spec, image_size=image_size)
    scene.add_arena(spec, table=task.has_table, shadows=shadows)
    spec.attach(robot.build_spec(dressed=True), prefix=robot.prefix, frame=spec.worldbody.add_frame())
    task.build(spec)
    if visual_variation:
        visual_ood.add_variation_pieces(spec, has_table=task.has_table)
    model = spec.compile()
    del spec
    release_compiler_memory()
    physics.set_clip_planes(model)
    scene.fit_shadow_map(model)
    task.bind(model)
    return index_world(model, robot)


def release_compiler_memory() -> None:
    """Give back what compiling a scene leaves behind in this process: MuJoCo's process-wide asset cache (the
    decoded textures and meshes; it only speeds up compiling the same assets again) and, under glibc, the heap
    pages the compiler freed (`malloc_trim`): memory a simulating worker would otherwise hold for nothing
    (docs/benchmarks.md, "Worker footprint")."""
    mujoco.mj_clearCache(mujoco.mj_getCache())
    libc_name = ctypes.util.find_library("c")
    libc = ctypes.CDLL(libc_name) if libc_name else None
    if libc is not None and hasattr(libc, "malloc_trim"):  # glibc only
        libc.malloc_trim(0)


def index_world(model: mujoco.MjModel, robot: Robot) -> World:
    p = robot.prefix

    def qpos_of(joints) -> np.ndarray:
        return np.array([model.joint(p + j).qposadr[0] for j in joints])

    def actuators_of(joints) -> np.ndarray:
        return np.array([model.actuator(p + j).id for j in joints])

    arms = {
        side: ArmIndex(
            qpos=qpos_of(robot.arm_joint_names(side)),
            actuators=actuators_of(robot.arm_joint_names(side)),
            ee_site=model.site(p + robot.ee_site(side)).id,
            grasp_site=model.site(p + robot.grasp_site(side)).id,
            finger_qpos=qpos_of((f"{side}_finger_a", f"{side}_finger_b")),
            gripper_actuator=model.actuator(f"{p}{side}_gripper").id,
        )
        for side in robot.SIDES
    }
    cameras = {name: model.camera(p + name).id for name in robot.CAMERAS}
    for name in (scene.FIXED_CAMERA, *VIEW_CAMERAS):
        cameras[name] = model.camera(name).id
    return World(
        model=model,
        robot=robot,
        arms=arms,
        neck_qpos=qpos_of(robot.neck_joint_names()),
        neck_actuators=actuators_of(robot.neck_joint_names()),
        cameras={name: cameras[name] for name in CAMERA_NAMES + VIEW_CAMERAS},
        robot_joint_qpos=qpos_of(robot.joint_names()),
    )
