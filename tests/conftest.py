import fcntl
import os
import shutil
import socket
import sys
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")  # before anything imports mujoco

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from lerobot_tavis.envs.robots import BUILTIN_ROBOTS  # noqa: E402
from lerobot_tavis.process import without_realtime_priority  # noqa: E402

ROBOTS = BUILTIN_ROBOTS


@pytest.fixture(scope="session", autouse=True)
def normal_priority():
    """The test processes stay at normal scheduling whatever their tests encode: the fixtures that write datasets
    through LeRobot's own API encode AV1 in the test process, and SVT-AV1 would otherwise leave it real-time (as
    root), and with it every process it starts afterwards (`process.without_realtime_priority`)."""
    with without_realtime_priority():
        yield


def pytest_collection_modifyitems(items):
    """The files marked slow run first, each file's tests still together and in order: `make test` hands whole
    files to its workers in this order (pytest-xdist's --dist loadfile --no-loadscope-reorder), so the run does not
    end on one long file while the other workers sit idle."""
    items.sort(key=lambda item: item.get_closest_marker("slow") is None)


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


def free_port() -> int:
    """A TCP port of the loopback interface that was free a moment ago (connecting to it is refused at once)."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


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


def built_once_per_run(tmp_path_factory, name: str, build) -> Path:
    """`build(path)` run once per test run, however many pytest-xdist workers ask for `name`: the first to take the
    lock builds it in the run's temporary root, the others wait and reuse it. Tests must only read what it holds
    (damage copies)."""
    root = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        root = root.parent  # the folder the workers' own temporary roots share
    path, done = root / name, root / f"{name}.done"
    with open(root / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not done.exists():
            shutil.rmtree(path, ignore_errors=True)  # what a failed attempt left
            build(path)
            done.touch()
    return path


def _conditional_pick_recording(tmp_path_factory, episodes: int) -> Path:
    """`tavis record` of `episodes` conditional_pick demonstrations (GR1T2, seeds from 100000), once per run."""
    from lerobot_tavis.dataset_tools.record import RecordConfig, record

    def build(path):
        record(RecordConfig(out_dir=path, robot="gr1t2", tasks=("conditional_pick",), episodes_per_task=episodes),
               progress=False)

    return built_once_per_run(tmp_path_factory, f"conditional_pick_raw_{episodes}", build)


@pytest.fixture(scope="session")
def conditional_pick_raw(tmp_path_factory) -> Path:
    """Two conditional_pick demonstrations (GR1T2) in a `tavis record` directory."""
    return _conditional_pick_recording(tmp_path_factory, 2)


@pytest.fixture(scope="session")
def conditional_pick_demonstration(tmp_path_factory) -> Path:
    """One conditional_pick demonstration (GR1T2) in a `tavis record` directory."""
    return _conditional_pick_recording(tmp_path_factory, 1)


@pytest.fixture(scope="session")
def conditional_pick_dataset(conditional_pick_raw, tmp_path_factory) -> Path:
    """The two demonstrations converted once per run: 20 Hz, the head camera only, 48x64 AV1 video."""
    from lerobot_tavis.dataset_tools.convert import ConvertConfig, convert

    def build(path):
        convert(ConvertConfig(conditional_pick_raw, "local/conditional_pick", path, image_size=(48, 64),
                              cameras=("head",)), progress=False)

    return built_once_per_run(tmp_path_factory, "conditional_pick_dataset", build)
