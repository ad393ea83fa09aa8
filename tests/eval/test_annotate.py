"""`tavis report` draws each episode's GALT events onto a copy of the videos lerobot-eval wrote."""

import json
import os

import numpy as np

from lerobot_tavis.eval.annotate import Annotator
from lerobot_tavis.eval.report import write_report
from lerobot_tavis.media import iter_mp4, write_mp4
from lerobot_tavis.overlay import EVENT_COLOURS, Caption, band_height, compose

FPS = 20
SUCCESS_STEPS, FAILURE_STEPS = 24, 30  # the two filmed episodes' lengths: a video holds one frame more


def _record(seed, success, length_steps, gaze=None):
    return {"robot": "gr1t2", "suite": "tavis_head", "task": "conditional_pick", "task_id": 0, "split": "id",
            "camera_mode": "head_wrist", "seed": seed, "success": success, "length_steps": length_steps,
            "prompt": "pick it", "galt_s": 1.0 if gaze else None, "galt_reason": "ok" if gaze else None,
            "galt_t_head_arrival_s": gaze, "galt_t_hand_onset_s": gaze and gaze + 0.3,
            "galt_t_hand_arrival_s": gaze and gaze + 1.0}


def _live_video(path, n_frames):
    """What lerobot-eval films: composed frames whose band knows only the clock."""
    views = {"head": np.full((48, 64, 3), 90, np.uint8)}
    overview = np.full((48, 64, 3), 160, np.uint8)
    write_mp4(path, [compose(views, overview, Caption("pick it", i / FPS, 20.0)) for i in range(n_frames)], FPS)


def _has(region, colour):
    return bool(np.any(np.all(np.abs(region.astype(int) - colour) < 40, axis=-1)))


def _filmed_evaluation(eval_dir):
    """An evaluation folder as lerobot-eval leaves it: a success (seed 1000, 1.2 s: its gaze at 0.1 s, its grasp at
    1.1 s) and a failure (1.5 s), both filmed."""
    records = [_record(1000, True, SUCCESS_STEPS, gaze=0.1), _record(1001, False, FAILURE_STEPS)]
    (eval_dir / "eval_info.json").write_text(json.dumps({"per_task": [
        {"task_group": "tavis_head", "task_id": 0, "metrics": {"successes": [True, False]}}]}))
    (eval_dir / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in records))
    for ix, record in enumerate(records):
        _live_video(eval_dir / "videos" / "tavis_head_0" / f"eval_episode_{ix}.mp4", record["length_steps"] + 1)


def test_videos_get_a_copy_with_the_episode_events(tmp_path):
    _filmed_evaluation(tmp_path)

    written = write_report(tmp_path, workers=1)

    annotated = [tmp_path / "videos_annotated" / "tavis_head_0" / f"eval_episode_{ix}.mp4" for ix in (0, 1)]
    assert all(path in written for path in annotated)
    success_frames, failure_frames = list(iter_mp4(annotated[0])), list(iter_mp4(annotated[1]))
    original = list(iter_mp4(tmp_path / "videos" / "tavis_head_0" / "eval_episode_0.mp4"))
    assert len(success_frames) == SUCCESS_STEPS + 1 and len(failure_frames) == FAILURE_STEPS + 1
    band = band_height(original[0].shape[1])
    assert np.abs(success_frames[5][:-band].astype(int) - original[5][:-band]).mean() < 2  # panel untouched
    for colour in ("gaze", "reach", "grasp", "success"):
        assert _has(success_frames[0][-band:], EVENT_COLOURS[colour]), colour
    assert not _has(original[0][-band:], EVENT_COLOURS["gaze"])
    assert not any(_has(failure_frames[-1][-band:], EVENT_COLOURS[name]) for name in EVENT_COLOURS)


def test_annotated_videos_do_not_depend_on_the_number_of_workers(tmp_path):
    """Same frames: x264's threads may code them into different bytes."""
    frames = {}
    for workers in (1, 2):
        eval_dir = tmp_path / f"workers_{workers}"
        eval_dir.mkdir()
        _filmed_evaluation(eval_dir)
        written = sorted(path for path in write_report(eval_dir, workers=workers) if path.suffix == ".mp4")
        frames[workers] = [np.stack(list(iter_mp4(path))) for path in written]
    assert [len(video) for video in frames[1]] == [SUCCESS_STEPS + 1, FAILURE_STEPS + 1]
    assert all(np.array_equal(one, two) for one, two in zip(frames[1], frames[2], strict=True))
    assert not list(tmp_path.rglob("*.partial*"))


def test_a_copy_newer_than_its_video_is_kept_and_an_older_one_redone(tmp_path):
    _filmed_evaluation(tmp_path)
    first = [path for path in write_report(tmp_path, workers=1) if path.suffix == ".mp4"]
    assert len(first) == 2
    assert not [path for path in write_report(tmp_path, workers=1) if path.suffix == ".mp4"]
    video = tmp_path / "videos" / "tavis_head_0" / "eval_episode_1.mp4"
    copy = tmp_path / "videos_annotated" / "tavis_head_0" / "eval_episode_1.mp4"
    later = copy.stat().st_mtime_ns + 10**9
    os.utime(video, ns=(later, later))  # the video filmed again after its copy was made
    assert [path for path in write_report(tmp_path, workers=1) if path.suffix == ".mp4"] == [copy]


def test_the_annotator_writes_each_group_when_asked_from_worker_processes(tmp_path):
    _filmed_evaluation(tmp_path)
    videos = tmp_path / "videos" / "tavis_head_0"
    records = [json.loads(line) for line in (tmp_path / "episodes.jsonl").read_text().splitlines()]
    with Annotator(workers=2) as annotator:
        for ix, record in enumerate(records):
            annotator.submit(f"group {ix}", videos / f"eval_episode_{ix}.mp4", tmp_path / f"copy_{ix}.mp4", record)
        assert annotator.write("group 1") == [tmp_path / "copy_1.mp4"]
        assert not (tmp_path / "copy_0.mp4").exists()
        assert annotator.write("group 0") == [tmp_path / "copy_0.mp4"]
    expected = [path for path in write_report(tmp_path, workers=1) if path.suffix == ".mp4"]
    for ix, path in enumerate(expected):
        assert np.array_equal(np.stack(list(iter_mp4(tmp_path / f"copy_{ix}.mp4"))), np.stack(list(iter_mp4(path))))
