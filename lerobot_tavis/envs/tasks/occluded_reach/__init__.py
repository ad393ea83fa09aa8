"""TAVIS-Hands occluded_reach: an object behind a portrait monitor; reach around the screen and lift it.

The screen (fixed) hides the object from the head camera. The declaration (readable without MuJoCo); `task.py`
simulates it.
"""

from lerobot_tavis.envs.tasks.info import HANDS_EXPERTS, HIGH_LIFT_HEIGHT_M, TaskInfo, lift_rule

SUCCESS_HEIGHT_M = HIGH_LIFT_HEIGHT_M
INFO = TaskInfo("occluded_reach", "tavis_hands", ("Reach around the screen and pick up the object behind it.",),
                lift_rule("object", SUCCESS_HEIGHT_M),
                task_class=f"{__name__}.task:OccludedReach", demonstrator=f"{HANDS_EXPERTS}:OccludedReachExpert")
