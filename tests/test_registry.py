"""The registry: one declaration per task, robot and camera mode, readable without MuJoCo, open to additions.

The toy task, demonstrator and robot below are the working examples docs/extending.md points at: a researcher's
task is a `Task` subclass (declaring the episode facts its demonstrator reads) plus an `Expert` subclass plus one
`register_task` call; a robot is a `Robot` subclass plus one `register_robot` call; a camera mode is one
`register_camera_mode` call.
"""

import json
import subprocess
import sys
from collections.abc import Iterator

import numpy as np
import pytest

from lerobot_tavis import canonical, registry
from lerobot_tavis.cli import build_parser
from lerobot_tavis.cli_options import from_args
from lerobot_tavis.envs import placement
from lerobot_tavis.envs.objects import RED_CUBE, add_prop
from lerobot_tavis.envs.robots.gr1t2 import GR1T2
from lerobot_tavis.envs.tasks.base import TargetFacts, Task, lift_conditions
from lerobot_tavis.envs.tasks.catalog import expand_tasks
from lerobot_tavis.experts.base import Expert, Hold, Move, Segment
from lerobot_tavis.experts.rollout import make_expert, run_episode

# -- a toy task: the red cube on the table, lift it ---------------------------------------------------------------
TOY_TASK = registry.TaskInfo(
    "toy_lift_cube", "toy_suite", ("Lift the red cube.",), "the red cube's origin is above 1.2 m, slower than 1 m/s",
    splits=("id", "ood_spatial", "ood_init_pose"),
    task_class=f"{__name__}:ToyLiftCube", demonstrator=f"{__name__}:ToyReachExpert")


class ToyLiftCube(Task):
    info = TOY_TASK
    VARIANTS = {"id": 0.05, "ood_spatial": 0.15}  # half-width (m) of the cube's lateral placement

    def build(self, spec) -> None:
        add_prop(spec, RED_CUBE)

    def bind(self, model) -> None:
        self._model = model

    def props(self) -> tuple[str, ...]:
        return (RED_CUBE.name,)

    def initialize_episode(self, model, data, rng: np.random.Generator) -> None:
        y = rng.uniform(-self.variant, self.variant)
        placement.place_on_table(model, data, RED_CUBE.name, 0.42, y, rng.uniform(-np.pi, np.pi))

    def episode_facts(self) -> TargetFacts:
        """What the demonstrator may know: the prop to pick (here always the cube) and the scene's props."""
        return TargetFacts(props=self.props(), succeeds=self.is_success, target=RED_CUBE.name)

    def evaluate(self, data) -> dict:
        return lift_conditions(self._model, data, RED_CUBE.name, 1.2)


class ToyReachExpert(Expert):
    """Look down toward the target (named by the task's facts, found in the simulator state) and move the right hand
    10 cm forward; no grasp."""

    def behaviour(self) -> Iterator[Segment]:
        yield Hold(self.uniform(0.05, 0.1))
        cube = self.env.data.xpos[self.env.model.body(self.facts.target).id]
        target = canonical.rest_action()
        target[canonical.HEAD_PITCH] = 0.4
        target[canonical.HEAD_YAW] = np.arctan2(cube[1], cube[0])
        target[canonical.RIGHT.position.start] += 0.1
        yield Move(target, 0.5)


# -- a toy robot: GR1T2's model under another name ----------------------------------------------------------------
class ToyRobot(GR1T2):
    name = "toy_gr1t2"


TOY_ROBOT = registry.RobotInfo("toy_gr1t2", f"{__name__}:ToyRobot", "Toy GR1T2")
TOY_MODE, TOY_MODE_CAMERAS = "fixed_left", ("fixed", "left_wrist")


@pytest.fixture
def toys():
    """Register the toy task, robot and camera mode for one test, and remove them afterwards."""
    registry.register_task(TOY_TASK)
    registry.register_robot(TOY_ROBOT)
    registry.register_camera_mode(TOY_MODE, TOY_MODE_CAMERAS)
    yield
    registry.unregister_task(TOY_TASK.name)
    registry.unregister_robot(TOY_ROBOT.name)
    registry.unregister_camera_mode(TOY_MODE)


LEAN = """
import json, sys
import lerobot_tavis.registry as registry
names = {"tasks": registry.task_names(), "suites": registry.suite_names(), "robots": registry.robot_names(),
         "modes": registry.camera_mode_names(), "demonstrators": [str(registry.task_info(t).demonstrator) for t in
         registry.BENCHMARK_TASKS]}
print(json.dumps({"loaded": [m for m in ("mujoco", "torch", "lerobot") if m in sys.modules], **names}))
"""


def test_reading_the_registry_loads_neither_mujoco_torch_nor_lerobot():
    out = subprocess.run([sys.executable, "-c", LEAN], check=True, capture_output=True, text=True)
    report = json.loads(out.stdout.splitlines()[-1])
    assert report["loaded"] == []
    assert report["tasks"] == [*registry.BENCHMARK_TASKS, "tabletop"]
    assert report["suites"] == ["tavis_head", "tavis_hands", "sandbox"]
    assert report["robots"] == ["gr1t2", "reachy2"]
    assert report["modes"] == ["head_wrist", "fixed_wrist", "head_only", "fixed_only"]
    assert all(path.startswith("lerobot_tavis.experts.") for path in report["demonstrators"])


def test_every_declared_class_resolves_and_agrees_with_its_declaration():
    for name in registry.task_names():
        assert registry.task_class(name).info is registry.task_info(name)
    assert [name for name in registry.task_names() if registry.demonstrator_class(name) is None] == ["tabletop"]
    for name in registry.robot_names():
        assert registry.make_robot(name).name == name


def test_a_registered_task_robot_and_mode_run_in_the_env_with_the_demonstrator(toys):
    from lerobot_tavis.envs.env import TavisEnv

    env = TavisEnv("toy_lift_cube", "toy_gr1t2", camera_mode=TOY_MODE, image_size=(24, 32), episode_length_s=1.0)
    try:
        obs, _ = env.reset(seed=3)
        assert list(obs["pixels"]) == list(TOY_MODE_CAMERAS)
        assert env.task_description == "Lift the red cube." and env.world.robot.name == "toy_gr1t2"
        assert obs["agent_pos"][canonical.HEAD] == pytest.approx(0.0)  # a fixed-camera mode holds the neck
        expert = make_expert(env, seed=3)
        assert isinstance(expert, ToyReachExpert)
        assert env.episode_facts.target == RED_CUBE.name and env.episode_facts.props == (RED_CUBE.name,)
        expert.reset()
        start = obs["agent_pos"].copy()
        for _ in range(15):
            obs, reward, terminated, truncated, info = env.step(action := expert.act())
        assert not (terminated or truncated or info["is_success"])
        assert obs["agent_pos"][canonical.RIGHT.position.start] > start[canonical.RIGHT.position.start] + 0.05
        cube = env.model.body(RED_CUBE.name).id
        # the expert turned its gaze toward the cube the facts named (the fixed-camera mode then holds the neck)
        x, y, _ = env.data.xpos[cube]
        assert action[canonical.HEAD_YAW] == pytest.approx(np.arctan2(y, x), abs=1e-3)
        first = env.data.xpos[cube].copy()
        env.reset(seed=3)
        assert np.allclose(env.data.xpos[cube], first, atol=1e-3)  # same seed, same layout
    finally:
        env.close()
    env = TavisEnv("toy_lift_cube", "gr1t2", camera_mode="head_only", split="ood_spatial", episode_length_s=1.0,
                   cameras=())
    result = run_episode(env, seed=0)  # the registered demonstrator, through the package's episode runner
    env.close()
    assert result.length_steps == 20 and not result.success


def test_registered_names_reach_the_config_the_cli_and_suite_expansion(toys):
    from lerobot_tavis.eval.env_config import TavisEnvConfig

    assert expand_tasks("toy_suite") == {"toy_suite": ["toy_lift_cube"]}
    config = TavisEnvConfig(task="toy_suite", robot="toy_gr1t2", camera_mode=TOY_MODE)
    assert sorted(key for key in config.features if key.startswith("pixels/")) == ["pixels/fixed", "pixels/left_wrist"]
    args = build_parser().parse_args(["eval", "--expert", "--robot", "toy_gr1t2", "--camera-mode", TOY_MODE,
                                      "--out", "unused"])
    assert (args.robot, args.camera_mode) == ("toy_gr1t2", TOY_MODE)
    demo = build_parser().parse_args(["demo"])
    assert "toy_gr1t2" in from_args(demo.options, demo).robots  # the default: every registered robot
    view = build_parser().parse_args(["view", "--task", "toy_lift_cube", "--robot", "toy_gr1t2"])
    assert (view.task, view.robot) == ("toy_lift_cube", "toy_gr1t2")


def test_a_registered_camera_mode_gets_a_preset_config_but_no_shipped_file(toys):
    from lerobot_tavis.policy_configs import build_preset, preset_names

    assert not any(TOY_MODE in name for name in preset_names())  # `tavis presets` lists files that exist
    inputs = build_preset("diffusion", TOY_MODE)["policy"]["input_features"]
    assert sorted(inputs) == ["observation.images.fixed", "observation.images.left_wrist", "observation.state"]


def test_the_toys_are_gone_after_the_fixture():
    assert "toy_lift_cube" not in registry.task_names() and "toy_suite" not in registry.suite_names()
    assert "toy_gr1t2" not in registry.robot_names() and TOY_MODE not in registry.camera_mode_names()
    with pytest.raises(ValueError, match="robot must be one of"):
        registry.make_robot("toy_gr1t2")


@pytest.mark.parametrize("change,message", [
    ({"name": "conditional_pick"}, "already registered"),
    ({"name": "Bad Name"}, "lower_snake_case"),
    ({"suite": "tavis_head"}, "none of the benchmark's"),
    ({"suite": "wait_then_act"}, "may not share a name"),
    ({"prompts": ()}, "prompts of task"),
    ({"prompts": "Lift the red cube."}, "prompts of task"),
    ({"splits": ("ood_spatial",)}, "must include 'id'"),
    ({"task_class": "no_colon_here"}, "task_class must be a class or an import path"),
    ({"demonstrator": 3}, "demonstrator must be a class or an import path"),
])
def test_bad_task_registrations_are_refused_and_leave_the_registry_as_it_was(change, message):
    from dataclasses import replace

    before = dict(registry.TASKS)
    with pytest.raises(ValueError, match=message):
        registry.register_task(replace(TOY_TASK, **change))
    assert registry.TASKS == before


def test_bad_robot_and_mode_registrations_and_built_in_removals_are_refused():
    with pytest.raises(ValueError, match="already registered"):
        registry.register_robot(registry.RobotInfo("gr1t2", f"{__name__}:ToyRobot", "again"))
    with pytest.raises(ValueError, match="robot_class must be"):
        registry.register_robot(registry.RobotInfo("toy", "not a path", "Toy"))
    with pytest.raises(ValueError, match="already registered"):
        registry.register_camera_mode("headcam", ("head",))
    with pytest.raises(ValueError, match="must be distinct names among"):
        registry.register_camera_mode("stereo", ("head", "head"))
    with pytest.raises(ValueError, match="must be distinct names among"):
        registry.register_camera_mode("overview_only", ("overview",))
    for unregister, name in ((registry.unregister_task, "peeking_box"), (registry.unregister_robot, "reachy2"),
                             (registry.unregister_camera_mode, "head_wrist")):
        with pytest.raises(ValueError, match="built in"):
            unregister(name)


def test_a_robot_registered_under_another_name_than_its_class_is_refused_when_built():
    registry.register_robot(registry.RobotInfo("mislabelled", f"{__name__}:ToyRobot", "Mislabelled"))
    try:
        with pytest.raises(ValueError, match="they must agree"):
            registry.make_robot("mislabelled")
    finally:
        registry.unregister_robot("mislabelled")
