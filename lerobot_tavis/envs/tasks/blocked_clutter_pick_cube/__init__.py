"""TAVIS-Hands blocked_clutter_pick_cube: clutter_pick_cube with a black head camera (the head still moves).

The declaration (readable without MuJoCo); `task.py` simulates it.
"""

from lerobot_tavis.envs.tasks.clutter_pick_cube import CUBE_PROMPT, SUCCESS_HEIGHT_M
from lerobot_tavis.envs.tasks.info import HANDS_EXPERTS, TaskInfo, lift_rule

INFO = TaskInfo("blocked_clutter_pick_cube", "tavis_hands", (CUBE_PROMPT,),
                lift_rule("red cube", SUCCESS_HEIGHT_M) + "; the head camera image is black",
                task_class=f"{__name__}.task:BlockedClutterPickCube",
                demonstrator=f"{HANDS_EXPERTS}:BlockedClutterExpert")
