"""The wrist lead as an episode metric: `wrist_lead_*` fields of successful TAVIS-Hands episodes.

`wrist_lead_s` is how long (seconds) before the episode's final grasp the grasping hand's wrist camera settled
for its last look (`wrist_lead_per_grasp`, read from the hand's applied motion, so any camera mode).
"""

from __future__ import annotations

from lerobot_tavis.metrics.episode_metric import Episode, EpisodeMetric
from lerobot_tavis.metrics.galt import wrist_lead_per_grasp


class WristLeadMetric(EpisodeMetric):
    name = "wrist_lead"
    fields = ("wrist_lead_s", "wrist_lead_reason", "wrist_lead_arm")
    caption = ("Wrist lead (s): the grasping hand's wrist camera settles before the final grasp "
               "(successful TAVIS-Hands episodes).")

    def applies(self, episode: Episode) -> bool:
        return episode.success and episode.suite == "tavis_hands"

    def measure(self, episode: Episode) -> dict:
        leads = wrist_lead_per_grasp(episode.actions, fps=episode.fps)
        if not leads:
            return {}
        final = leads[-1]
        return {"wrist_lead_s": final.lead_s, "wrist_lead_reason": final.reason, "wrist_lead_arm": final.arm}


WRIST_LEAD = WristLeadMetric()
