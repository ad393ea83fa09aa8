"""`benchmarks/env_speed.py --peer-python`: the peer's measurement process runs in an interpreter that has
gym-aloha and not this package, so it must import nothing of lerobot_tavis."""

import os
import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).parents[1] / "benchmarks" / "env_speed.py"


def test_the_peer_measurement_does_not_need_this_package():
    # -S: no site-packages, so neither lerobot_tavis (installed in editable mode) nor gym_aloha imports; the
    # measurement must get as far as importing gym_aloha.
    env = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    done = subprocess.run([sys.executable, "-S", str(SCRIPT), "--one", "aloha", "--steps", "1"], capture_output=True,
                          text=True, env=env, cwd=SCRIPT.parent, timeout=60)
    assert done.returncode != 0
    assert "No module named 'gym_aloha'" in done.stderr and "lerobot_tavis" not in done.stderr, done.stderr
