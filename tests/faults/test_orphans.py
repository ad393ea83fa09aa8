"""Worker processes of `tavis record` and `tavis eval` die with their parent, kill -9 included."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="needs Linux /proc")


def _children(pid: int) -> set[int]:
    found = set()
    for task in Path(f"/proc/{pid}/task").iterdir():
        found |= {int(child) for child in (task / "children").read_text().split()}
    return found


def _alive(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().split()[2] != "Z"
    except FileNotFoundError:
        return False


def _wait_for(condition, timeout_s: float) -> bool:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.2)
    return False


COMMANDS = {
    "record": ["record", "--robot", "gr1t2", "--tasks", "conditional_pick", "--episodes-per-task", "50",
               "--workers", "2", "--out"],
    "eval": ["eval", "--expert", "--suite", "tavis_hands", "--splits", "id", "--episodes", "50", "--workers", "2",
             "--out"],
}


@pytest.mark.parametrize("name", COMMANDS)
def test_workers_exit_when_the_parent_is_killed(tmp_path, name):
    command = [sys.executable, "-m", "lerobot_tavis.cli", *COMMANDS[name], str(tmp_path / "out")]
    parent = subprocess.Popen(command, env={**os.environ, "MUJOCO_GL": "egl"}, stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)
    try:
        assert _wait_for(lambda: len(_children(parent.pid)) >= 2, 120), "the workers never started"
        workers = _children(parent.pid)
        time.sleep(3)  # let them import and start recording
        parent.send_signal(signal.SIGKILL)
        parent.wait()
        assert _wait_for(lambda: not any(_alive(pid) for pid in workers), 10), "workers outlived their parent"
    finally:
        parent.kill()
