"""Benchmark metrics: success statistics, GALT, and the episode metrics the log writes and the report summarises
(`logged_metrics.py`). Numpy only (plus `envs.modes`, pure Python): no MuJoCo, LeRobot or torch."""
