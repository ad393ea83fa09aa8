"""The plugin module LeRobot imports in every CLI: registers `--env.type=tavis` (it loads LeRobot itself), and
`--policy.type=act_hand_relative` and `diffusion_hand_relative` where LeRobot's policies are loaded already, as
lerobot-train and lerobot-eval load them before their plugins; the robot and teleop CLIs stay without them. Elsewhere
`lerobot_tavis.policies.register_policy_types()` registers the policy types. In these CLIs a bad `--env.*` value is
one line instead of a traceback, and so is LeRobot's warning that torchcodec cannot load (no system FFmpeg). In
lerobot-train, a TAVIS config (`--config_path=<preset>`) whose dataset lacks the policy's cameras, or holds them at
another size than an ACT policy's, ends the run in one line (`policy_configs.refuse_unfit_training_dataset`); with
`TAVIS_FRAME_CACHE=1` (or `float32`), lerobot-train (which has loaded LeRobot's dataset factory by then) reads video
frames from the frame cache (`lerobot_tavis.dataset_tools.cached_dataset`)."""

import sys

from lerobot_tavis.dataset_tools.quiet import shorten_torchcodec_fallback
from lerobot_tavis.eval.env_config import TavisEnvConfig
from lerobot_tavis.lerobot_cli_errors import report_env_field_errors

shorten_torchcodec_fallback()
report_env_field_errors()

if "lerobot.policies" in sys.modules:
    from lerobot_tavis.policies import register_policy_types

    register_policy_types()

LEROBOT_TRAIN = "lerobot.scripts.lerobot_train"  # its console script imports it; `python -m` runs it as __main__
MAIN_SPEC = getattr(sys.modules.get("__main__"), "__spec__", None)
if LEROBOT_TRAIN in sys.modules or getattr(MAIN_SPEC, "name", None) == LEROBOT_TRAIN:
    from lerobot_tavis.policy_configs import refuse_unfit_training_dataset

    refuse_unfit_training_dataset(sys.argv[1:])

if "lerobot.datasets.factory" in sys.modules:
    from lerobot_tavis.dataset_tools.cached_dataset import frame_cache_mode, use_frame_cache

    if mode := frame_cache_mode():
        use_frame_cache(mode)

__all__ = ["TavisEnvConfig"]
