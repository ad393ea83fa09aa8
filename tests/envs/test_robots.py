"""Model facts from docs/reference.md §12 survive the procedural build."""

import math

import mujoco
import numpy as np
import pytest

from lerobot_tavis import canonical
from lerobot_tavis.envs.robots import BUILTIN_ROBOTS, make_robot
from lerobot_tavis.envs.transforms import quat_angle_rad


def _compiled(name):
    robot = make_robot(name)
    model = robot.build_spec().compile()
    return robot, model, mujoco.MjData(model)


def test_unknown_robot_is_rejected():
    with pytest.raises(ValueError, match="robot must be one of"):
        make_robot("atlas")


def test_gr1t2_official_joint_order_and_tilted_shoulder_axis():
    robot, model, data = _compiled("gr1t2")
    assert robot.arm_joint_names("left") == (
        "left_shoulder_pitch_joint", "left_shoulder_roll_joint", "left_shoulder_yaw_joint",
        "left_elbow_pitch_joint", "left_wrist_yaw_joint", "left_wrist_roll_joint", "left_wrist_pitch_joint")
    assert robot.neck_joint_names() == ("head_roll_joint", "head_pitch_joint", "head_yaw_joint")
    mujoco.mj_forward(model, data)
    np.testing.assert_allclose(data.xaxis[model.joint("left_shoulder_pitch_joint").id], (0, 0.908, 0.419), atol=2e-3)
    np.testing.assert_allclose(data.xanchor[model.joint("left_shoulder_pitch_joint").id], (0.003, 0.101, 1.305),
                               atol=2e-3)
    np.testing.assert_allclose(model.jnt_range[model.joint("right_shoulder_roll_joint").id], (-2.53, 0.57))


def test_reachy2_zero_pose_anchors():
    robot, model, data = _compiled("reachy2")
    assert robot.arm_joint_names("right")[:4] == ("r_shoulder_pitch", "r_shoulder_roll", "r_elbow_yaw",
                                                  "r_elbow_pitch")
    mujoco.mj_forward(model, data)
    np.testing.assert_allclose(data.xanchor[model.joint("r_elbow_yaw").id], (0.003, -0.271, 0.726), atol=3e-3)
    np.testing.assert_allclose(data.xanchor[model.joint("r_wrist_roll").id], (0.015, -0.343, 0.455), atol=3e-3)
    np.testing.assert_allclose(data.xaxis[model.joint("r_shoulder_pitch").id], (-0.168, 0.951, -0.259), atol=3e-3)
    np.testing.assert_allclose(data.xanchor[model.joint("neck_pitch").id], (-0.01, 0.0, 1.111), atol=1e-3)


def test_both_robots_declare_the_shoulder_the_demonstrators_aim_from():
    """0.2 m is the one value the demonstrators used on both robots before each robot declared it; Reachy2's
    shoulder pitch and roll axes meet there, GR1T2's shoulder axes pass through y 0.10-0.23 m."""
    for name in BUILTIN_ROBOTS:
        robot = make_robot(name)
        assert (robot.shoulder_y("left"), robot.shoulder_y("right")) == (0.2, -0.2)
    robot, model, data = _compiled("reachy2")
    mujoco.mj_forward(model, data)
    for side, joint in (("left", "l_shoulder_pitch"), ("right", "r_shoulder_roll")):
        assert data.xanchor[model.joint(joint).id][1] == pytest.approx(robot.shoulder_y(side), abs=1e-9)
    robot, model, data = _compiled("gr1t2")
    mujoco.mj_forward(model, data)
    ys = [data.xanchor[model.joint(j).id][1] for j in robot.arm_joint_names("left")[:3]]
    assert min(ys) < robot.shoulder_y("left") < max(ys)


@pytest.mark.parametrize("name", BUILTIN_ROBOTS)
def test_cameras_have_the_reference_fields_of_view(name):
    robot, model, _ = _compiled(name)

    def hfov(camera):
        vfov = math.radians(model.cam_fovy[model.camera(camera).id])
        return math.degrees(2 * math.atan(math.tan(vfov / 2) * 640 / 480))

    assert hfov("head") == pytest.approx(69.9, abs=0.1)
    assert hfov("left_wrist") == pytest.approx(53.0, abs=0.1)
    assert hfov("right_wrist") == pytest.approx(53.0, abs=0.1)


@pytest.mark.parametrize("name,stroke", [("gr1t2", 0.085), ("reachy2", 0.105)])
def test_gripper_stroke(name, stroke):
    _, model, _ = _compiled(name)
    for side in ("left", "right"):
        for finger in "ab":
            assert model.jnt_range[model.joint(f"{side}_finger_{finger}").id][1] == pytest.approx(stroke / 2)


@pytest.mark.parametrize("name", BUILTIN_ROBOTS)
def test_rest_calibration_holds_the_rest_pose_exactly(name):
    robot, model, data = _compiled(name)
    calibration = robot.calibration()
    for side in robot.SIDES:
        for joint, value in zip(robot.arm_joint_names(side), calibration.arm_qpos[side]):
            data.qpos[model.joint(joint).qposadr[0]] = value
    mujoco.mj_forward(model, data)
    rest = canonical.rest_action()
    for arm in canonical.ARMS:
        site = model.site(robot.ee_site(arm.side)).id
        np.testing.assert_allclose(data.site_xpos[site] - robot.canonical_origin, rest[arm.position], atol=1e-3)
        quat = np.empty(4)
        mujoco.mju_mat2Quat(quat, data.site_xmat[site])
        assert quat_angle_rad(quat, rest[arm.quaternion]) < 1e-3


def test_the_references_default_joints_would_put_reachy2s_wrists_under_the_table_top():
    """Why Reachy2 starts from its own rest posture (docs/robots.md): the reference's default arm joints (shoulder
    pitch -0.3, elbow -1.7, the rest 0) hold our wrist centres 0.15 m below the table top, over the table."""
    robot, model, data = _compiled("reachy2")
    reference = {"shoulder_pitch": -0.3, "elbow_pitch": -1.7}
    for side in robot.SIDES:
        for joint in robot.arm_joint_names(side):
            data.qpos[model.joint(joint).qposadr[0]] = reference.get(joint[2:], 0.0)
    mujoco.mj_kinematics(model, data)
    for side in robot.SIDES:
        wrist = data.site_xpos[model.site(robot.ee_site(side)).id]
        assert wrist[2] < 0.86 and 0.25 < wrist[0] < 0.4  # the table top is at 1.0 m, its front edge at x 0.25


def test_gr1t2_wrist_cameras_point_for_a_command_as_the_reference_s():
    """The reference's IK drives the hand link itself to the commanded quaternion, and its wrist camera sits on that
    link at (0.15, 0, 0.05) with the optical axis along +x turned 125° about y; ours rides on the end-effector frame
    the same way, so at rest it looks 24.6° below the horizon from where the reference's does."""
    robot, model, data = _compiled("gr1t2")
    calibration = robot.calibration()
    for side in robot.SIDES:
        for joint, value in zip(robot.arm_joint_names(side), calibration.arm_qpos[side]):
            data.qpos[model.joint(joint).qposadr[0]] = value
    mujoco.mj_forward(model, data)
    mount_axis = np.array([math.cos(math.radians(125.0)), 0.0, -math.sin(math.radians(125.0))])
    for arm in canonical.ARMS:
        rotation = np.empty(9)
        mujoco.mju_quat2Mat(rotation, np.asarray(canonical.REST_QUATERNION[arm.side], dtype=float))
        rotation = rotation.reshape(3, 3)
        wrist = data.site_xpos[model.site(robot.ee_site(arm.side)).id]
        camera = model.camera(f"{arm.side}_wrist").id
        forward = -data.cam_xmat[camera].reshape(3, 3)[:, 2]
        np.testing.assert_allclose(forward, rotation @ mount_axis, atol=1e-3)
        np.testing.assert_allclose(data.cam_xpos[camera], wrist + rotation @ (0.15, 0.0, 0.05), atol=1e-3)
        assert math.degrees(-math.asin(forward[2])) == pytest.approx(24.6, abs=0.1)
