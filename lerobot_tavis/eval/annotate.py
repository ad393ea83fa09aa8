"""The gaze and hand events GALT found, drawn onto the videos lerobot-eval wrote.

lerobot-eval films `TavisEnv.render()`: the overview beside the policy's views, with the prompt, the clock and
success, all known while the episode runs. The events (head arrival on the final fixation, hand onset, grasp) are
known only once it is over, in the episode log. For every `videos/<suite>_<task_id>/eval_episode_<i>.mp4` of an
evaluation, this writes `videos_annotated/<suite>_<task_id>/eval_episode_<i>.mp4` with the caption band redrawn
from episode i's log record (episode i is the one with seed start_seed + i, as `report.join` pairs them).
Videos are annotated by worker processes side by side (a protocol films 60); this process writes them, in a fixed
order.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from lerobot_tavis.atomic import write_bytes
from lerobot_tavis.dataset_tools.workers import executor
from lerobot_tavis.envs.physics import POLICY_HZ
from lerobot_tavis.eval.report import join
from lerobot_tavis.media import encode_mp4, iter_mp4
from lerobot_tavis.overlay import Caption, EpisodeEvents, redraw_caption

ANNOTATED_DIR = "videos_annotated"


def annotate_videos(eval_dirs: Sequence[Path], workers: int, fps: int = POLICY_HZ) -> list[Path]:
    """Write the annotated copy of every episode video of the lerobot-eval output directories `eval_dirs`, annotated
    by up to `workers` processes; returns the written files. The files do not depend on `workers`."""
    jobs = [job for eval_dir in eval_dirs for job in _annotation_jobs(eval_dir)]
    if not jobs:
        return []
    with executor(min(workers, len(jobs))) as pool:
        pending = [(out, pool.submit(annotated_mp4, video, record, fps)) for video, out, record in jobs]
        return [write_bytes(out, future.result()) for out, future in pending]


def annotated_mp4(video: Path, record: dict, fps: int) -> bytes:
    """`video` (an episode lerobot-eval filmed at `fps`) with its caption band redrawn from the episode's log
    `record`, as MP4 bytes; decoded, redrawn and encoded one frame at a time (in a worker)."""
    events = EpisodeEvents.from_episode_record(record, fps)
    duration_s = record["length_steps"] / fps
    return encode_mp4((redraw_caption(frame, Caption(record["prompt"], step / fps, duration_s, events))
                       for step, frame in enumerate(iter_mp4(video))), fps)


def _annotation_jobs(eval_dir: Path) -> list[tuple[Path, Path, dict]]:
    """(video, annotated copy's path, the episode's log record) of every scored episode video of `eval_dir`."""
    videos = sorted((eval_dir / "videos").glob("*/eval_episode_*.mp4"))
    if not videos:
        return []
    episodes, _ = join(eval_dir)
    by_episode = {(f"{r['suite']}_{r['task_id']}", r["episode_ix"]): r for r in episodes}
    jobs = []
    for video in videos:
        record = by_episode.get((video.parent.name, int(video.stem.rsplit("_", 1)[1])))
        if record is not None:  # else a video of an episode LeRobot did not score
            jobs.append((video, eval_dir / ANNOTATED_DIR / video.parent.name / video.name, record))
    return jobs
