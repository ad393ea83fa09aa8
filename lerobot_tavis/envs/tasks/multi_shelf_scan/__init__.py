"""TAVIS-Head multi_shelf_scan: five objects in six slots of a three-shelf unit; take the named one out.

No table. Success: the target's origin is nearer than x = `SHELF_EXIT_X_M` (out of the shelf) and slower than
`MAX_SUCCESS_SPEED_M_S`; no height condition (docs/reference.md §4). The declaration (readable without MuJoCo);
`task.py` simulates it.
"""

from lerobot_tavis.envs.tasks.info import HEAD_EXPERTS, SPEED_RULE, TaskInfo

SHELF_X, SHELF_DEPTH = 0.52, 0.11  # world x of the shelf unit's centre and its depth along x, m
SHELF_EXIT_X_M = SHELF_X - SHELF_DEPTH / 2 - 0.03  # 0.435: 3 cm in front of the shelf's front edge
# object -> its three phrasings; an episode draws one of the target's
PROMPTS = {
    "soup_can": ("Find the tomato soup can on the shelf and bring it to me.",
                 "Retrieve the soup can from the shelves.",
                 "Look through the shelves, find the red soup can, and take it."),
    "meat_can": ("Find the potted meat can on the shelf and bring it to me.",
                 "Retrieve the spam can from the shelves.",
                 "Look through the shelves, find the meat can, and take it."),
    "tuna_fish_can": ("Find the tuna fish can on the shelf and bring it to me.",
                      "Retrieve the tuna can from the shelves.",
                      "Look through the shelves, find the tuna can, and take it."),
    "gelatin_box": ("Find the gelatin box on the shelf and bring it to me.",
                    "Retrieve the gelatin box from the shelves.",
                    "Look through the shelves, find the gelatin box, and take it."),
    "pudding_box": ("Find the pudding box on the shelf and bring it to me.",
                    "Retrieve the pudding box from the shelves.",
                    "Look through the shelves, find the pudding box, and take it."),
}
INFO = TaskInfo("multi_shelf_scan", "tavis_head", tuple(p for ps in PROMPTS.values() for p in ps),
                f"the named object's origin is closer than x = {SHELF_EXIT_X_M:.3f} m (out of the shelf) and "
                + SPEED_RULE,
                task_class=f"{__name__}.task:MultiShelfScan", demonstrator=f"{HEAD_EXPERTS}:ShelfExpert")
