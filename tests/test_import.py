"""LeRobot imports the plugin in every CLI, robot and teleop ones included: the top-level import must stay light.

Registering the env type needs `lerobot.envs.configs` (which LeRobot's CLIs load anyway); beyond that, importing
the plugin must not load the simulator, the demonstrators or any policy, dataset or video code. Each check reads
`sys.modules` of a fresh interpreter; one interpreter takes the light imports' snapshots in turn (a module loaded by
an earlier step is in every later snapshot), as starting one costs more than any check.
"""

import os
import subprocess
import sys

import pytest

HEAVY = ("mujoco", "mink", "lerobot.policies", "lerobot.datasets", "cv2", "av", "lerobot_tavis.envs.env",
         "lerobot_tavis.experts", "lerobot_tavis.eval.report")
SNAPSHOT = "print('--snapshot--', *sys.modules)"


def _snapshots(*statements: str, env: dict | None = None) -> tuple[str, list[set[str]]]:
    """What the first of `statements` printed, and the modules a fresh interpreter holds after each of them, run in
    order in it (with `env` added to this process's environment)."""
    code = "import sys\n" + "".join(f"{statement}\n{SNAPSHOT}\n" for statement in statements)
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True,
                         env={**os.environ, **(env or {})}).stdout
    printed, *snapshots = out.split("--snapshot--")
    return printed, [set(chunk.split()) for chunk in snapshots]


@pytest.fixture(scope="module")
def light_imports() -> dict[str, set[str]]:
    """The modules after LeRobot's env configs, then the plugin (and its env type looked up), then the task catalog
    and the camera modes."""
    names = ("lerobot configs", "plugin", "catalog")
    return dict(zip(names, _snapshots(
        "import lerobot.envs.configs",
        "import lerobot_env_tavis; from lerobot.envs.configs import EnvConfig; "
        "assert EnvConfig.get_choice_class('tavis').__name__ == 'TavisEnvConfig'",
        "import lerobot_tavis.envs.tasks.catalog, lerobot_tavis.envs.modes, lerobot_tavis.canonical")[1]))


@pytest.fixture(scope="module")
def training_imports() -> tuple[str, set[str]]:
    """What lerobot-train loads before its plugins (the dataset factory, LeRobot's policies), then the plugin (whose
    policy types it registers), with TAVIS_FRAME_CACHE=1: the factory's dataset class then (module and name), and
    the modules loaded."""
    printed, (loaded,) = _snapshots(
        "import lerobot.datasets.factory as factory, lerobot.policies, lerobot_env_tavis; "
        "from lerobot.configs.policies import PreTrainedConfig; assert PreTrainedConfig.get_choice_class('act_hand_relative').__name__ == "
        "'ACTHandRelativeConfig'; assert PreTrainedConfig.get_choice_class('diffusion_hand_relative').__name__ == "
        "'DiffusionHandRelativeConfig'; print(factory.LeRobotDataset.__module__, factory.LeRobotDataset.__name__)",
        env={"TAVIS_FRAME_CACHE": "1"})
    return printed, loaded


def test_plugin_import_registers_the_env_type_and_loads_nothing_heavy(light_imports):
    added = light_imports["plugin"] - light_imports["lerobot configs"]
    assert "lerobot_tavis" in added
    assert not [m for m in added if m.startswith(HEAVY)]


def test_where_lerobot_policies_are_loaded_the_plugin_registers_the_policy_types_too(training_imports):
    _, loaded = training_imports
    assert "lerobot_tavis.policies.act_hand_relative.configuration_act_hand_relative" in loaded
    assert "lerobot_tavis.policies.diffusion_hand_relative.configuration_diffusion_hand_relative" in loaded


def test_where_lerobots_dataset_factory_is_loaded_the_switch_points_it_at_the_frame_cache(light_imports,
                                                                                         training_imports):
    """lerobot-train loads the factory before its plugins; TAVIS_FRAME_CACHE=1 swaps its dataset class, else not."""
    assert training_imports[0].split() == ["lerobot_tavis.dataset_tools.cached_dataset", "TrainingFrameCachedDataset"]
    printed, _ = _snapshots("import lerobot.datasets.factory as factory, lerobot_env_tavis; "
                            "print(factory.LeRobotDataset.__module__, factory.LeRobotDataset.__name__)",
                            env={"TAVIS_FRAME_CACHE": "0"})
    assert printed.split() == ["lerobot.datasets.lerobot_dataset", "LeRobotDataset"]
    assert not [m for m in light_imports["plugin"] if m.endswith((".frame_cache", ".cached_dataset"))]


def test_task_catalog_and_camera_modes_need_no_mujoco(light_imports):
    assert "mujoco" not in light_imports["catalog"]
