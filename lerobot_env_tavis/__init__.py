"""The plugin module LeRobot imports in every CLI: registers `--env.type=tavis` (it loads LeRobot itself)."""

from lerobot_tavis.envs.config import TavisEnvConfig

__all__ = ["TavisEnvConfig"]
