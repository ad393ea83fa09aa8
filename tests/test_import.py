"""LeRobot imports the plugin in every CLI, robot and teleop ones included: the top-level import must stay light."""

import subprocess
import sys

HEAVY = ("mujoco", "mink", "lerobot.policies", "lerobot.datasets", "transformers", "diffusers", "cv2", "av")


def _modules_after(statement: str) -> set[str]:
    code = f"import sys; {statement}; print('\\n'.join(sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout
    return set(out.split())


def test_plugin_import_loads_no_simulator_or_policy_code():
    loaded = _modules_after("import lerobot_env_tavis")
    assert "lerobot_tavis" in loaded
    assert not [m for m in HEAVY if m in loaded]


def test_task_catalog_and_camera_modes_need_no_mujoco():
    loaded = _modules_after(
        "import lerobot_tavis.envs.tasks.catalog, lerobot_tavis.envs.modes, lerobot_tavis.canonical")
    assert "mujoco" not in loaded
