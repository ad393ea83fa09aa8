"""`--policy.type=diffusion_hand_relative`: Diffusion Policy whose arm actions are planned in the hand's frame (see
`hand_frame`, `hand_relative`).

LeRobot resolves the policy class and its processors by naming convention from the configuration's module:
`configuration_diffusion_hand_relative` -> `modeling_diffusion_hand_relative.DiffusionHandRelativePolicy` and
`processor_diffusion_hand_relative.make_diffusion_hand_relative_pre_post_processors`.
"""
