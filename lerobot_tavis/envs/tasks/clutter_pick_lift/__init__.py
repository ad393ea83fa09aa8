"""TAVIS-Head clutter_pick_lift: five YCB objects scattered on the table; lift the one the prompt names.

The declaration (readable without MuJoCo); `task.py` simulates it.
"""

from lerobot_tavis.envs.tasks.info import HEAD_EXPERTS, LIFT_HEIGHT_M, TaskInfo, lift_rule

# object -> its three phrasings; an episode draws one of the target's
PROMPTS = {
    "soup_can": ("Pick up the tomato soup can and lift it.", "Grasp the soup can and hold it up.",
                 "Lift the red soup can off the table."),
    "meat_can": ("Pick up the potted meat can and lift it.", "Grasp the can of spam and hold it up.",
                 "Lift the meat can off the table."),
    "tuna_fish_can": ("Pick up the tuna fish can and lift it.", "Grasp the tuna can and hold it up.",
                      "Lift the tuna fish can off the table."),
    "gelatin_box": ("Pick up the gelatin box and lift it.", "Grasp the gelatin box and hold it up.",
                    "Lift the gelatin box off the table."),
    "pudding_box": ("Pick up the pudding box and lift it.", "Grasp the pudding box and hold it up.",
                    "Lift the pudding box off the table."),
}
SUCCESS_HEIGHT_M = LIFT_HEIGHT_M
INFO = TaskInfo("clutter_pick_lift", "tavis_head", tuple(p for ps in PROMPTS.values() for p in ps),
                lift_rule("named object", SUCCESS_HEIGHT_M),
                task_class=f"{__name__}.task:ClutterPickLift", demonstrator=f"{HEAD_EXPERTS}:ClutterExpert")
