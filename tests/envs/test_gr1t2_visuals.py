"""GR1T2-specific checks of its visual meshes: Robotiq pads on the collision pads, a clear head camera (the shared
checks of both robots are in test_robot_visuals.py)."""

import json
import math

import mujoco
import numpy as np
import pytest

from lerobot_tavis.envs.assets import ASSET_DIR
from lerobot_tavis.envs.robots.gr1t2 import GR1T2
from lerobot_tavis.envs.transforms import matrix_from_quat

MANIFEST = json.loads((ASSET_DIR / "gr1t2" / "visuals.json").read_text())
PAD_TOLERANCE_M = 0.003
HEAD_NEAR_CLIP_M = 0.15  # the reference head camera's near clip


@pytest.fixture(scope="module")
def models():
    robot = GR1T2()
    return robot.build_spec().compile(), robot.build_spec(dressed=True).compile()


def _in_hand_frame(model, data, hand, geom, points):
    world = points @ data.geom_xmat[geom].reshape(3, 3).T + data.geom_xpos[geom]
    return (world - data.xpos[hand]) @ data.xmat[hand].reshape(3, 3)


def _mesh_points(model, geom):
    mesh = model.geom_dataid[geom]
    return model.mesh_vert[model.mesh_vertadr[mesh]:model.mesh_vertadr[mesh] + model.mesh_vertnum[mesh]]


def _box_corners(model, geom):
    return np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * model.geom_size[geom]


@pytest.mark.parametrize("opening_m", [0.0, 0.0425])
@pytest.mark.parametrize("side", ["left", "right"])
def test_visual_pads_sit_on_the_collision_pads(models, side, opening_m):
    _, model = models
    data = mujoco.MjData(model)
    for finger in ("a", "b"):
        data.qpos[model.jnt_qposadr[model.joint(f"{side}_finger_{finger}").id]] = opening_m
    mujoco.mj_kinematics(model, data)
    hand = model.body(f"{side}_hand_pitch_link").id
    for finger, sign in (("a", 1.0), ("b", -1.0)):
        body = model.body(f"{side}_finger_{finger}").id
        pads = [g for g in range(model.ngeom) if model.geom_bodyid[g] == body
                and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH and "pad" in model.mesh(model.geom_dataid[g]).name]
        assert len(pads) == 2  # the metal pad and its silicone face
        visual = np.concatenate([_in_hand_frame(model, data, hand, g, _mesh_points(model, g)) for g in pads])
        collision = model.geom(f"{side}_finger_{finger}_pad").id
        box = _in_hand_frame(model, data, hand, collision, _box_corners(model, collision))
        np.testing.assert_allclose(visual.min(axis=0), box.min(axis=0), atol=PAD_TOLERANCE_M)
        np.testing.assert_allclose(visual.max(axis=0), box.max(axis=0), atol=PAD_TOLERANCE_M)
        gripping_face = visual[:, 1].min() if sign > 0 else visual[:, 1].max()
        assert gripping_face == pytest.approx(sign * opening_m, abs=5e-4)  # the silicone meets the collision face


@pytest.mark.parametrize("pitch, yaw", [(0.0, 0.0), (0.87, 0.0), (0.87, 0.5), (0.87, -0.5), (0.6, 1.0)])
def test_head_camera_sees_no_robot_mesh_within_the_near_clip(models, pitch, yaw):
    _, model = models
    data = mujoco.MjData(model)
    data.qpos[model.jnt_qposadr[model.joint("head_pitch_joint").id]] = pitch
    data.qpos[model.jnt_qposadr[model.joint("head_yaw_joint").id]] = yaw
    mujoco.mj_forward(model, data)
    camera = model.camera("head").id
    half_v = math.tan(math.radians(model.cam_fovy[camera]) / 2)
    rotation = data.cam_xmat[camera].reshape(3, 3)
    drawn, hit = np.array([1, 1, 1, 0, 0, 0], dtype=np.uint8), np.zeros(1, dtype=np.int32)
    for u in np.linspace(-half_v * 640 / 480, half_v * 640 / 480, 33):
        for v in np.linspace(-half_v, half_v, 25):
            ray = rotation @ (np.array([u, v, -1.0]) / np.linalg.norm([u, v, -1.0]))
            distance = mujoco.mj_ray(model, data, data.cam_xpos[camera], ray, drawn, 1, -1, hit)
            assert distance < 0 or distance >= HEAD_NEAR_CLIP_M, (model.geom(hit[0]).name, distance)


def test_finger_b_is_finger_a_turned_about_the_approach_axis():
    entries = [e for e in MANIFEST["meshes"] if e["body"].endswith(("_finger_a", "_finger_b"))]
    by_file = {}
    for entry in entries:
        by_file.setdefault(entry["file"], {})[entry["body"]] = entry["quat"]
    for quats in by_file.values():
        for side in ("left", "right"):
            np.testing.assert_allclose(matrix_from_quat(quats[f"{side}_finger_a"]), np.eye(3))
            np.testing.assert_allclose(matrix_from_quat(quats[f"{side}_finger_b"]), np.diag([-1.0, -1.0, 1.0]),
                                       atol=1e-12)
