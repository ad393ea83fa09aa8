"""`lerobot-eval --env.type=tavis --help` explains every field of the env config, with its allowed values."""

from dataclasses import fields

import pytest

from lerobot_tavis.envs.modes import CAMERA_MODES
from lerobot_tavis.envs.robots import ROBOTS
from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS, SPLITS, SUITES
from lerobot_tavis.eval.env_config import TavisEnvConfig


def test_every_field_has_help_naming_its_allowed_values(monkeypatch, capsys):
    """LeRobot's eval_main in this process, as its console script runs it (the help text is draccus's)."""
    from lerobot.scripts import lerobot_eval

    monkeypatch.setattr("sys.argv", ["lerobot-eval", "--env.type=tavis", "--help"])
    monkeypatch.setenv("COLUMNS", "80")  # the width the help is wrapped at, as in a pipe
    with pytest.raises(SystemExit) as done:
        lerobot_eval.eval_main()
    assert done.value.code in (None, 0)
    text = capsys.readouterr().out.split("TavisEnvConfig ['env']:")[1].split("Config ['eval']:")[0]
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
