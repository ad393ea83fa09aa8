"""The gaze and hand events GALT found, drawn onto the videos lerobot-eval wrote.

lerobot-eval films `TavisEnv.render()`: the overview beside the policy's views, with the prompt, the clock and
success, all known while the episode runs. The events (head arrival on the final fixation, hand onset, grasp) are
known only once it is over, in the episode log. For every `videos/<suite>_<task_id>/eval_episode_<i>.mp4` of an
evaluation, this writes `videos_annotated/<suite>_<task_id>/eval_episode_<i>.mp4` with the caption band redrawn
from episode i's log record (episode i is the one with seed start_seed + i, as `report.join` pairs them).
"""

from __future__ import annotations

from pathlib import Path

from lerobot_tavis.envs.physics import POLICY_HZ
from lerobot_tavis.eval.report import join
from lerobot_tavis.media import read_mp4, write_mp4
from lerobot_tavis.overlay import Caption, EpisodeEvents, redraw_caption

ANNOTATED_DIR = "videos_annotated"


def annotate_videos(eval_dir: Path, fps: int = POLICY_HZ) -> list[Path]:
    """Write the annotated copy of every episode video of one lerobot-eval output directory; returns them."""
    videos = sorted((eval_dir / "videos").glob("*/eval_episode_*.mp4"))
    if not videos:
        return []
    episodes, _ = join(eval_dir)
    by_episode = {(f"{r['suite']}_{r['task_id']}", r["episode_ix"]): r for r in episodes}
    written = []
    for video in videos:
        record = by_episode.get((video.parent.name, int(video.stem.rsplit("_", 1)[1])))
        if record is None:  # a video of an episode LeRobot did not score
            continue
        events = EpisodeEvents.from_episode_record(record, fps)
        duration_s = record["length_steps"] / fps
        frames = [redraw_caption(frame, Caption(record["prompt"], step / fps, duration_s, events))
                  for step, frame in enumerate(read_mp4(video))]
        written.append(write_mp4(eval_dir / ANNOTATED_DIR / video.parent.name / video.name, frames, fps))
    return written
