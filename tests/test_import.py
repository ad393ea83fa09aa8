"""LeRobot imports the plugin in every CLI, robot and teleop ones included: the top-level import must stay light.

Registering the env type needs `lerobot.envs.configs` (which LeRobot's CLIs load anyway); beyond that, importing
the plugin must not load the simulator, the demonstrators or any policy, dataset or video code.
"""

import os
import subprocess
import sys

HEAVY = ("mujoco", "mink", "lerobot.policies", "lerobot.datasets", "cv2", "av", "lerobot_tavis.envs.env",
         "lerobot_tavis.experts", "lerobot_tavis.eval.report")


def _modules_after(statement: str) -> set[str]:
    code = f"import sys; {statement}; print('\\n'.join(sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout
    return set(out.split())


def test_plugin_import_registers_the_env_type_and_loads_nothing_heavy():
    baseline = _modules_after("import lerobot.envs.configs")
    loaded = _modules_after("import lerobot_env_tavis; from lerobot.envs.configs import EnvConfig; "
                            "assert EnvConfig.get_choice_class('tavis').__name__ == 'TavisEnvConfig'")
    added = loaded - baseline
    assert "lerobot_tavis" in added
    assert not [m for m in added if m.startswith(HEAVY)]


def test_where_lerobot_policies_are_loaded_the_plugin_registers_the_policy_types_too():
    loaded = _modules_after("import lerobot.policies, lerobot_env_tavis; from lerobot.configs.policies import "
                            "PreTrainedConfig; assert PreTrainedConfig.get_choice_class('act_hand_relative')"
                            ".__name__ == 'ACTHandRelativeConfig'; assert PreTrainedConfig.get_choice_class("
                            "'diffusion_hand_relative').__name__ == 'DiffusionHandRelativeConfig'")
    assert "lerobot_tavis.policies.act_hand_relative.configuration_act_hand_relative" in loaded
    assert "lerobot_tavis.policies.diffusion_hand_relative.configuration_diffusion_hand_relative" in loaded


def test_where_lerobots_dataset_factory_is_loaded_the_switch_points_it_at_the_frame_cache():
    """lerobot-train loads the factory before its plugins; TAVIS_FRAME_CACHE=1 swaps its dataset class, else not."""
    code = ("import lerobot.datasets.factory as factory, lerobot_env_tavis; "
            "print(factory.LeRobotDataset.__module__, factory.LeRobotDataset.__name__)")
    for switch, expected in (("1", "lerobot_tavis.dataset_tools.cached_dataset TrainingFrameCachedDataset"),
                             ("0", "lerobot.datasets.lerobot_dataset LeRobotDataset")):
        out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True,
                             env={**os.environ, "TAVIS_FRAME_CACHE": switch}).stdout
        assert out.split("\n")[-2] == expected
    loaded = _modules_after("import lerobot_env_tavis")
    assert not [m for m in loaded if m.endswith((".frame_cache", ".cached_dataset"))]


def test_task_catalog_and_camera_modes_need_no_mujoco():
    loaded = _modules_after(
        "import lerobot_tavis.envs.tasks.catalog, lerobot_tavis.envs.modes, lerobot_tavis.canonical")
    assert "mujoco" not in loaded
