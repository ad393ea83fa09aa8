"""The gaze and hand events GALT found, drawn onto the videos lerobot-eval wrote.

lerobot-eval films `TavisEnv.render()`: the overview beside the policy's views, with the prompt, the clock and
success, all known while the episode runs. The events (head arrival on the final fixation, hand onset, grasp) are
known only once it is over, in the episode log. For every `videos/<suite>_<task_id>/eval_episode_<i>.mp4` of an
evaluation, this writes `videos_annotated/<suite>_<task_id>/eval_episode_<i>.mp4` with the caption band redrawn
from episode i's log record (episode i is the one with seed start_seed + i, as `outputs.join` pairs them).
Videos are annotated by worker processes side by side (a protocol films 60); this process writes them, in a fixed
order. A copy newer than its video is kept: `tavis eval` annotates each finished chunk's videos while the other
chunks still play (`Annotator`), so its report has none left to do.
"""

from __future__ import annotations

from collections.abc import Sequence
from concurrent.futures import Future
from pathlib import Path

from lerobot_tavis.atomic import write_bytes
from lerobot_tavis.envs.physics import POLICY_HZ
from lerobot_tavis.eval.outputs import join
from lerobot_tavis.media import encode_mp4, iter_mp4
from lerobot_tavis.overlay import Caption, EpisodeEvents, redraw_caption
from lerobot_tavis.process import MAX_NICENESS
from lerobot_tavis.workers import executor

ANNOTATED_DIR = "videos_annotated"


def annotate_videos(eval_dirs: Sequence[Path], workers: int, fps: int = POLICY_HZ) -> list[Path]:
    """Write the annotated copy of every episode video of the lerobot-eval output directories `eval_dirs` that has
    no copy newer than itself, annotated by up to `workers` processes; returns the written files. The files do not
    depend on `workers`."""
    jobs = [(video, out, record) for eval_dir in eval_dirs for video, out, record in _annotation_jobs(eval_dir)
            if not (out.exists() and out.stat().st_mtime_ns > video.stat().st_mtime_ns)]
    if not jobs:
        return []
    with Annotator(min(workers, len(jobs)), fps, niceness=0) as annotator:
        for video, out, record in jobs:
            annotator.submit("report", video, out, record)
        return annotator.write("report")


class Annotator:
    """Annotates videos in the background: `submit` hands a video to one of `workers` processes, which run at
    `niceness` (by default the lowest CPU priority: they take only the cores nobody else wants, e.g. between a
    protocol's rollouts), and `write(group)` waits for a group's copies and writes them from this process. Workers
    start at the first `submit`; with one worker, `submit` annotates at once."""

    def __init__(self, workers: int, fps: int = POLICY_HZ, niceness: int = MAX_NICENESS):
        self._workers, self._fps, self._niceness = workers, fps, niceness
        self._pool = None
        self._pending: dict[object, list[tuple[Path, Future]]] = {}

    def submit(self, group, video: Path, out: Path, record: dict) -> None:
        """Annotate `video` (an episode filmed at the annotator's fps) from its log `record`, as `out`, in `group`."""
        if self._pool is None:
            self._pool = executor(self._workers, niceness=self._niceness)
        self._pending.setdefault(group, []).append((out, self._pool.submit(annotated_mp4, video, record, self._fps)))

    def write(self, group) -> list[Path]:
        """Wait for the copies submitted in `group` and write them, in submission order."""
        return [write_bytes(out, future.result()) for out, future in self._pending.pop(group, [])]

    def close(self) -> None:
        """Stop the workers; copies not written yet are dropped."""
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None
        self._pending.clear()

    def __enter__(self) -> Annotator:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def episode_index(video: Path) -> int:
    """i of a video lerobot-eval named `eval_episode_<i>.mp4`: the episode of seed start_seed + i."""
    return int(video.stem.rsplit("_", 1)[1])


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
        record = by_episode.get((video.parent.name, episode_index(video)))
        if record is not None:  # else a video of an episode LeRobot did not score
            jobs.append((video, eval_dir / ANNOTATED_DIR / video.parent.name / video.name, record))
    return jobs
