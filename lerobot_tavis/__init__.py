"""TAVIS benchmark in MuJoCo, as a LeRobot env plugin.

Importing the package registers `--env.type=tavis` with LeRobot (`lerobot_tavis.envs.config`); it imports neither
MuJoCo nor any policy or dataset code, because LeRobot imports plugins in every CLI.
"""

from lerobot_tavis.envs.config import TavisEnvConfig

__all__ = ["TavisEnvConfig"]
