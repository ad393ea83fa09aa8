import lerobot_tavis  # noqa: F401  (registers the `tavis` env type with LeRobot)
