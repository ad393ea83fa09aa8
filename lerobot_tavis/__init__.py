"""TAVIS benchmark in MuJoCo, as a LeRobot env plugin.

Importing the package loads neither LeRobot nor torch, so processes that only simulate stay lean. `--env.type=tavis`
is registered with LeRobot by importing `lerobot_tavis.eval.env_config`, which LeRobot's CLIs do through the plugin
module `lerobot_env_tavis` (the distribution's name: LeRobot imports it in every CLI).
"""


def __getattr__(name: str):
    """`lerobot_tavis.TavisEnvConfig`, imported (and registered with LeRobot) on first use."""
    if name == "TavisEnvConfig":
        from lerobot_tavis.eval.env_config import TavisEnvConfig

        return TavisEnvConfig
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["TavisEnvConfig"]
