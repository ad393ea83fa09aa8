"""`lerobot-eval --env.type=tavis --help` explains every field of the env config, with its allowed values."""

import os
import subprocess
import sys
from dataclasses import fields

from lerobot_tavis.envs.modes import CAMERA_MODES
from lerobot_tavis.envs.robots import ROBOTS
from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS, SPLITS, SUITES
from lerobot_tavis.eval.env_config import TavisEnvConfig


def test_every_field_has_help_naming_its_allowed_values():
    lerobot_eval = os.path.join(os.path.dirname(sys.executable), "lerobot-eval")
    done = subprocess.run([lerobot_eval, "--env.type=tavis", "--help"], capture_output=True, text=True, timeout=300,
                          env={**os.environ, "HF_HUB_OFFLINE": "1"})
    text = done.stdout.split("TavisEnvConfig ['env']:")[1].split("Config ['eval']:")[0]
    entries = {}
    for block in text.split("\n  --env.")[1:]:
        name, _, rest = block.partition(" ")
        entries[name] = " ".join(rest.split())
    assert set(entries) == {f.name for f in fields(TavisEnvConfig) if f.name != "type"}
    for name, help_text in entries.items():
        assert "(default:" in help_text, f"--env.{name} has no help: {help_text!r}"
    for name, values in (("task", (*SUITES, *BENCHMARK_TASKS)), ("robot", ROBOTS), ("camera_mode", CAMERA_MODES),
                         ("split", SPLITS)):
        missing = [v for v in values if v not in entries[name]]
        assert not missing, f"--env.{name} help does not name {missing}"
