"""`--policy.type=act_hand_relative`: ACT whose arm actions are planned in the hand's frame (see `hand_frame`).

LeRobot resolves the policy class and its processors by naming convention from the configuration's module:
`configuration_act_hand_relative` -> `modeling_act_hand_relative.ACTHandRelativePolicy` and
`processor_act_hand_relative.make_act_hand_relative_pre_post_processors`.
"""
