"""The gripper closes on each of the five YCB objects and holds it while the hand lifts it 20 cm."""

import mujoco
import numpy as np
import pytest

from lerobot_tavis import canonical
from lerobot_tavis.envs import placement
from lerobot_tavis.envs.objects import OBJECT_NAMES, YCB_OBJECTS
from lerobot_tavis.experts.grasping import plan_grasp
from lerobot_tavis.experts.base import Move, play

LIFT_M = 0.20


@pytest.mark.parametrize("name", OBJECT_NAMES)
def test_grasp_and_lift(small_env, robot_name, name):
    env = small_env(task="tabletop", robot=robot_name, camera_mode="fixed_only", cameras=())  # nothing to render
    env.reset(seed=0)
    model, data, ik = env.model, env.data, env.controller.ik
    side = "left" if OBJECT_NAMES.index(name) % 2 == 0 else "right"
    placement.hide(model, data, [other for other in OBJECT_NAMES if other != name])
    yaw = np.pi / 2  # narrow side facing the hand
    placement.place_on_table(model, data, name, 0.42, 0.12 if side == "left" else -0.12, yaw)
    mujoco.mj_forward(model, data)
    body = model.body(name).id
    start_z = data.xpos[body][2]

    grasp = plan_grasp(ik, side, YCB_OBJECTS[name], data.xpos[body].copy(), yaw, carry_m=(0.0, 0.0, LIFT_M),
                       carry_tolerance_m=0.01)
    arm = canonical.LEFT if side == "left" else canonical.RIGHT
    rest = canonical.rest_action()
    hover = grasp.action(ik, rest, offset_m=0.08)
    hover[arm.position][2] += 0.12
    closed, lifted = (g.action(ik, rest, closed=True) for g in (grasp, grasp.carried()))
    segments = [Move(hover, 1.5), Move(grasp.action(ik, rest, offset_m=0.08), 0.8), Move(grasp.action(ik, rest), 0.8),
                Move(closed, 0.8), Move(lifted, 1.5)]
    for action in play(segments, rest):
        env.step(action)
    site = env.world.arms[side].grasp_site
    offset_before_hold = data.xpos[body] - data.site_xpos[site]
    for _ in range(20):  # hold for 1 s
        state = env.step(lifted)[0]["agent_pos"]
    offset_after_hold = data.xpos[body] - data.site_xpos[site]
    rise = data.xpos[body][2] - start_z
    assert rise > 0.17, f"{name} rose only {rise:.3f} m"
    assert np.linalg.norm(offset_after_hold - offset_before_hold) < 0.005, "the object slipped in the hand"
    assert np.linalg.norm(offset_after_hold) < 0.03, "the object is not between the pads"
    assert state[arm.gripper] < 0.95, "fingers closed fully: nothing between them"
