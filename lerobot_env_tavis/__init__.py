"""The plugin module LeRobot imports in every CLI: registers `--env.type=tavis` (it loads LeRobot itself), and
`--policy.type=act_hand_relative` where LeRobot's policies are loaded already, as lerobot-train and lerobot-eval load
them before their plugins; the robot and teleop CLIs stay without them. Elsewhere
`lerobot_tavis.policies.register_policy_types()` registers the policy type. LeRobot's warning that torchcodec cannot
load (no system FFmpeg) is one line in these CLIs instead of torchcodec's 100-line error."""

import sys

from lerobot_tavis.dataset_tools.quiet import shorten_torchcodec_fallback
from lerobot_tavis.envs.config import TavisEnvConfig

shorten_torchcodec_fallback()

if "lerobot.policies" in sys.modules:
    from lerobot_tavis.policies import register_policy_types

    register_policy_types()

__all__ = ["TavisEnvConfig"]
