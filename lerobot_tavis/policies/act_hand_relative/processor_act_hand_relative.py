"""Pre- and post-processors of `act_hand_relative`: ACT's own. The policy converts between absolute and hand-frame
actions itself, so the pipelines normalise and un-normalise absolute actions with the dataset's statistics, as for
ACT, and leave `observation.state` (not a network input) raw for the policy to anchor on."""

from lerobot.policies.act.processor_act import make_act_pre_post_processors


def make_act_hand_relative_pre_post_processors(config, dataset_stats=None):
    return make_act_pre_post_processors(config, dataset_stats)
