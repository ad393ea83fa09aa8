"""Reachy2-specific checks of its visual meshes: fingertips on the collision pads, clear camera views (the shared
checks of both robots are in test_robot_visuals.py)."""

import json
import math

import mujoco
import numpy as np
import pytest

from lerobot_tavis.envs import physics
from lerobot_tavis.envs.assets import ASSET_DIR
from lerobot_tavis.envs.robots.reachy2 import Reachy2

GROUP = ASSET_DIR / "reachy2"
MANIFEST = json.loads((GROUP / "visuals.json").read_text())
TIP_TOLERANCE_M = 0.002
FACE_TOLERANCE_M = 0.0005
HEAD_CLEARANCE_M = 0.15  # nothing of the robot is drawn nearer the head camera (the reference clips it there)
MAX_WRIST_COVERAGE = 0.5  # share of a wrist camera's view that the robot (its gripper) may cover
MESH = mujoco.mjtGeom.mjGEOM_MESH


@pytest.fixture(scope="module")
def models():
    robot = Reachy2()
    return robot.build_spec().compile(), robot.build_spec(dressed=True).compile()


def _mesh_geoms(model, body=None):
    return [g for g in range(model.ngeom) if model.geom_type[g] == MESH
            and (body is None or model.geom_bodyid[g] == model.body(body).id)]


def _in_frame(data, body, points):
    """World points in the frame of `body`."""
    return (points - data.xpos[body]) @ data.xmat[body].reshape(3, 3)


def _mesh_world_points(model, data, geom):
    mesh = model.geom_dataid[geom]
    verts = model.mesh_vert[model.mesh_vertadr[mesh]:model.mesh_vertadr[mesh] + model.mesh_vertnum[mesh]]
    return verts @ data.geom_xmat[geom].reshape(3, 3).T + data.geom_xpos[geom]


@pytest.mark.parametrize("opening_m", [0.0, 0.03, 0.0525])
@pytest.mark.parametrize("side", ["left", "right"])
def test_visual_fingertips_follow_the_collision_pads(models, side, opening_m):
    _, model = models
    data = mujoco.MjData(model)
    for finger in ("a", "b"):
        data.qpos[model.jnt_qposadr[model.joint(f"{side}_finger_{finger}").id]] = opening_m
    mujoco.mj_kinematics(model, data)
    hand = model.body(f"{side[0]}_hand").id
    for finger, sign in (("a", 1.0), ("b", -1.0)):
        meshes = _mesh_geoms(model, f"{side}_finger_{finger}")
        assert meshes, f"{side}_finger_{finger} carries no mesh"
        visual = _in_frame(data, hand, np.concatenate([_mesh_world_points(model, data, g) for g in meshes]))
        pad = model.geom(f"{side}_finger_{finger}_pad").id
        centre = _in_frame(data, hand, data.geom_xpos[pad])
        half = model.geom_size[pad]
        assert visual[:, 2].min() == pytest.approx(centre[2] - half[2], abs=TIP_TOLERANCE_M)  # fingertip
        gripping_face = visual[:, 1].min() if sign > 0 else visual[:, 1].max()
        assert gripping_face == pytest.approx(sign * opening_m, abs=FACE_TOLERANCE_M)
        assert (visual[:, 0].min() + visual[:, 0].max()) / 2 == pytest.approx(centre[0], abs=TIP_TOLERANCE_M)


def _drawn_hits(model, data, camera, width=640, height=480) -> list[float]:
    """For a grid of rays across the camera's image, the distance (m) from the lens to the nearest drawn geom that
    the camera shows (beyond its near clip plane), or inf where a ray meets none."""
    cam = model.camera(camera).id
    half_v = math.tan(math.radians(model.cam_fovy[cam]) / 2)
    rotation = data.cam_xmat[cam].reshape(3, 3)
    drawn, hit = np.array([1, 1, 1, 0, 0, 0], dtype=np.uint8), np.zeros(1, dtype=np.int32)
    hits = []
    for u in np.linspace(-half_v * width / height, half_v * width / height, 33):
        for v in np.linspace(-half_v, half_v, 25):
            direction = np.array([u, v, -1.0])
            to_near_plane = physics.NEAR_CLIP_M * np.linalg.norm(direction)  # along the ray, to z = -near
            ray = rotation @ (direction / np.linalg.norm(direction))
            distance = mujoco.mj_ray(model, data, data.cam_xpos[cam] + to_near_plane * ray, ray, drawn, 1, -1, hit)
            hits.append(to_near_plane + distance if distance >= 0 else math.inf)
    return hits


@pytest.mark.parametrize("roll, pitch, yaw", [(0.0, 0.0, 0.0), (0.35, 0.35, 1.0), (-0.35, -0.35, -1.57)])
def test_the_robot_stays_out_of_the_head_view_and_leaves_most_of_the_wrist_views_free(models, roll, pitch, yaw):
    _, model = models
    data = mujoco.MjData(model)
    for joint, angle in (("neck_roll", roll), ("neck_pitch", pitch), ("neck_yaw", yaw)):
        data.qpos[model.jnt_qposadr[model.joint(joint).id]] = angle
    for side in ("left", "right"):
        for finger in ("a", "b"):
            data.qpos[model.jnt_qposadr[model.joint(f"{side}_finger_{finger}").id]] = 0.0525 * (pitch > 0)
    mujoco.mj_forward(model, data)
    # the head camera sits inside the head shell, whose face (37 mm ahead) the near clip cuts away
    assert min(_drawn_hits(model, data, "head")) >= HEAD_CLEARANCE_M
    for camera in ("left_wrist", "right_wrist"):
        covered = np.isfinite(_drawn_hits(model, data, camera)).mean()
        assert covered < MAX_WRIST_COVERAGE, camera  # the gripper fills the bottom of the view, not the view


def test_finger_b_carries_finger_a_turned_half_a_turn_about_the_approach_axis():
    quats = {}
    for entry in MANIFEST["meshes"]:
        if entry["body"].endswith(("_finger_a", "_finger_b")):
            quats.setdefault(entry["file"], {})[entry["body"][-1]] = entry.get("quat", [1.0, 0.0, 0.0, 0.0])
    assert quats
    for pair in quats.values():
        assert pair == {"a": [1.0, 0.0, 0.0, 0.0], "b": [0.0, 0.0, 0.0, 1.0]}
