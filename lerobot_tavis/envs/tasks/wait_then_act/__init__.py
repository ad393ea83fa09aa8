"""TAVIS-Head wait_then_act: watch a red light; once it turns green (after a seeded delay), lift the object.

Lifting before the light is green does not end the episode (as in the reference); success counts only once the
light is green, and fires at once if the object is already held up when it turns. The declaration (readable
without MuJoCo); `task.py` simulates it.
"""

from lerobot_tavis.envs.tasks.info import HEAD_EXPERTS, LIFT_HEIGHT_M, TaskInfo, lift_rule

SUCCESS_HEIGHT_M = LIFT_HEIGHT_M
INFO = TaskInfo(
    "wait_then_act", "tavis_head", ("Watch the red light. When it turns green, pick up the object.",),
    "once the light is green: " + lift_rule("object", SUCCESS_HEIGHT_M),
    task_class=f"{__name__}.task:WaitThenAct", demonstrator=f"{HEAD_EXPERTS}:WaitThenActExpert")
