"""GALT as an episode metric: `galt_*` fields of successful episodes whose neck moves (head-camera modes).

Values are seconds from the episode start (`galt_t_*`) or spans in seconds (`galt_s`, `galt_arm_reach_s`),
computed by `compute_galt` from the applied actions at the episode's fps, as the reference does.
"""

from __future__ import annotations

from lerobot_tavis.envs.modes import neck_locked
from lerobot_tavis.metrics.episode_metric import Episode, EpisodeMetric, Histogram
from lerobot_tavis.metrics.galt import compute_galt


class GaltMetric(EpisodeMetric):
    name = "galt"
    fields = ("galt_s", "galt_reason", "galt_arm", "galt_t_head_arrival_s", "galt_t_hand_arrival_s",
              "galt_t_hand_onset_s", "galt_arm_reach_s")
    caption = "GALT (gaze-action lead time, s) over successful episodes of head-camera modes."
    histogram = Histogram(-0.5, 4.05, 0.1, "GALT (s)")

    def applies(self, episode: Episode) -> bool:
        return episode.success and not neck_locked(episode.camera_mode)

    def measure(self, episode: Episode) -> dict:
        result = compute_galt(episode.actions, fps=episode.fps)
        return {"galt_s": result.galt_s, "galt_reason": result.reason, "galt_arm": result.arm,
                "galt_t_head_arrival_s": result.t_head_arrival_s, "galt_t_hand_arrival_s": result.t_hand_arrival_s,
                "galt_t_hand_onset_s": result.t_hand_onset_s, "galt_arm_reach_s": result.arm_reach_s}


GALT = GaltMetric()
