"""TAVIS-Head clutter_pick_cube: the red cube among four of the five YCB objects; pick up the cube.

The declaration (readable without MuJoCo); `task.py` simulates it.
"""

from lerobot_tavis.envs.tasks.info import HEAD_EXPERTS, LIFT_HEIGHT_M, TaskInfo, lift_rule

CUBE_PROMPT = "Find the red cube and pick it up."
SUCCESS_HEIGHT_M = LIFT_HEIGHT_M
INFO = TaskInfo("clutter_pick_cube", "tavis_head", (CUBE_PROMPT,), lift_rule("red cube", SUCCESS_HEIGHT_M),
                task_class=f"{__name__}.task:ClutterPickCube", demonstrator=f"{HEAD_EXPERTS}:ClutterExpert")
