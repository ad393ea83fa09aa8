"""Evaluation: `--env.type=tavis` (the LeRobot env config and its sub-envs), the per-episode log, the report, and the
96-episode protocol runner."""
