"""Policy variants registered with LeRobot by this plugin (`--policy.type=...` in lerobot-train and lerobot-eval)."""


def register_policy_types() -> None:
    """Register LeRobot's policy types and this package's with LeRobot's config registry, as a checkpoint's
    `config.json` needs before `PreTrainedConfig.from_pretrained` can read it (LeRobot's CLIs do this through the
    plugin module `lerobot_env_tavis`)."""
    import lerobot.policies  # noqa: F401
    import lerobot_tavis.policies.act_hand_relative.configuration_act_hand_relative  # noqa: F401
    import lerobot_tavis.policies.diffusion_hand_relative.configuration_diffusion_hand_relative  # noqa: F401
