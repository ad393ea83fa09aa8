"""TAVIS-Hands peeking_box: an object inside a closed box with one open side (+y or -y); retrieve and lift it.

The front and back walls span the full width, so the opening is not visible head-on: a wrist camera has to look.
The declaration (readable without MuJoCo); `task.py` simulates it.
"""

from lerobot_tavis.envs.tasks.info import HANDS_EXPERTS, HIGH_LIFT_HEIGHT_M, TaskInfo, lift_rule

SUCCESS_HEIGHT_M = HIGH_LIFT_HEIGHT_M
INFO = TaskInfo("peeking_box", "tavis_hands", ("Retrieve the object from inside the box.",),
                lift_rule("object", SUCCESS_HEIGHT_M),
                task_class=f"{__name__}.task:PeekingBox", demonstrator=f"{HANDS_EXPERTS}:PeekingBoxExpert")
