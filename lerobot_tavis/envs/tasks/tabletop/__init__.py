"""Sandbox scene: the five YCB objects standing in a row on the table; there is nothing to succeed at.

The declaration (readable without MuJoCo); `task.py` simulates it.
"""

from lerobot_tavis.envs.tasks.info import TaskInfo

INFO = TaskInfo("tabletop", "sandbox", ("Look at the objects on the table.",),
                "never succeeds: a free scene (the five YCB objects on the table) for trying the robots",
                splits=("id",), task_class=f"{__name__}.task:Tabletop")
