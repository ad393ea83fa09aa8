"""TAVIS-Head conditional_pick: a cue card's colour says which of two objects to lift (red: left, green: right).

The declaration (readable without MuJoCo); `task.py` simulates it.
"""

from lerobot_tavis.envs.tasks.info import HEAD_EXPERTS, LIFT_HEIGHT_M, TaskInfo, lift_rule

SUCCESS_HEIGHT_M = LIFT_HEIGHT_M
INFO = TaskInfo(
    "conditional_pick", "tavis_head",
    ("Look at the card. If it is red, pick the object on the left. If it is green, pick the object on the right.",),
    lift_rule("target (left object if the card is red, right if green)", SUCCESS_HEIGHT_M),
    task_class=f"{__name__}.task:ConditionalPick", demonstrator=f"{HEAD_EXPERTS}:ConditionalPickExpert")
