import os
import sys
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")  # before anything imports mujoco

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from lerobot_tavis.envs.robots import BUILTIN_ROBOTS  # noqa: E402

ROBOTS = BUILTIN_ROBOTS


@pytest.fixture(params=ROBOTS)
def robot_name(request) -> str:
    return request.param


@pytest.fixture
def small_env():
    """Factory for envs with tiny images (fast to render); closes them at the end of the test."""
    from lerobot_tavis.envs.env import TavisEnv

    envs = []

    def make(**kwargs):
        kwargs.setdefault("image_size", (48, 64))
        env = TavisEnv(**kwargs)
        envs.append(env)
        return env

    yield make
    for env in envs:
        env.close()


def run_steps(env, action, steps: int):
    obs = None
    for _ in range(steps):
        obs, *_ = env.step(np.asarray(action))
    return obs


@pytest.fixture
def benchmark_script(monkeypatch):
    """Loads a script of benchmarks/ as a module: benchmark_script("grasp_tolerance")."""
    import importlib.util

    def load(name: str):
        path = Path(__file__).resolve().parents[1] / "benchmarks" / f"{name}.py"
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        monkeypatch.setitem(sys.modules, name, module)  # dataclasses look their module up there
        spec.loader.exec_module(module)
        return module

    return load
