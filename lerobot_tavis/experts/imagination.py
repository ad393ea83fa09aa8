"""Trying a plan in the demonstrator's head: actions played on a copy of the simulator state.

A person picking something up has a good feel for whether a grasp will work before trying it; the scripted
demonstrators get the same from the simulator itself. The copy starts from the live state (bodies, controller
setpoints), so a plan that works here works the same when executed: the simulation is deterministic.
"""

from __future__ import annotations

import mujoco
import numpy as np

from lerobot_tavis.envs import physics
from lerobot_tavis.envs.control import Controller
from lerobot_tavis.envs.world import World


class Imagination:
    def __init__(self, world: World):
        self.world = world
        self.data = mujoco.MjData(world.model)
        self.controller = Controller(world)

    def rollout(self, data: mujoco.MjData, controller: Controller, actions: list[np.ndarray]) -> mujoco.MjData:
        """The state after playing `actions` (one per policy step) from `data` / `controller`."""
        mujoco.mj_copyData(self.data, self.world.model, data)
        self.controller.copy_setpoints(controller)
        for action in actions:
            self.controller.set_command(action)
            for _ in range(physics.TICKS_PER_STEP):
                self.controller.tick(self.data)
                mujoco.mj_step(self.world.model, self.data, nstep=physics.SUBSTEPS_PER_TICK)
        return self.data
