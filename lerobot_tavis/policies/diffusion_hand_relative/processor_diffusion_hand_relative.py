"""Pre- and post-processors of `diffusion_hand_relative`: Diffusion Policy's own. The policy converts between
absolute and hand-frame actions itself, so the pipelines normalise and un-normalise absolute actions with the
dataset's min and max, as for Diffusion Policy, and leave `observation.state` raw (the config's
`normalization_mapping`) for the policy to anchor on."""

from lerobot.policies.diffusion.processor_diffusion import make_diffusion_pre_post_processors


def make_diffusion_hand_relative_pre_post_processors(config, dataset_stats=None):
    return make_diffusion_pre_post_processors(config, dataset_stats)
