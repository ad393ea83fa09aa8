"""The tasks: one package each (`<task>/__init__.py` declares it without MuJoCo, `<task>/task.py` simulates it),
collected by name in `catalog`."""
