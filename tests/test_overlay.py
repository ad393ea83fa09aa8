"""The overlay composer: where the overview, the policy views and the caption band go, and what the band shows."""

import numpy as np
import pytest

from lerobot_tavis.overlay import (EVENT_COLOURS, PANEL_HEIGHT, Caption, EpisodeEvents, band_height, compose,
                                   redraw_caption)

RED, BLUE, GREEN_VIEW, GREY = (200, 30, 30), (30, 30, 200), (30, 200, 30), (128, 128, 128)


def solid(colour, size=(60, 80)):
    return np.full((*size, 3), colour, np.uint8)


def views():
    return {"head": solid(RED), "left_wrist": solid(BLUE), "right_wrist": solid(GREEN_VIEW)}


def colour_at(frame, y, x):
    return tuple(int(c) for c in frame[y, x])


def has_colour(region, colour, tolerance=40):
    return bool(np.any(np.all(np.abs(region.astype(int) - colour) < tolerance, axis=-1)))


def test_layout_overview_left_views_in_a_grid_band_below():
    frame = compose(views(), solid(GREY), Caption("pick the can", 1.0, 20.0))
    panel_h, panel_w = PANEL_HEIGHT, 2 * 480  # the 60x80 overview scaled to 360x480, the views' block beside it
    assert frame.shape == (panel_h + band_height(panel_w), panel_w, 3)
    assert frame.shape[0] % 2 == 0 and frame.shape[1] % 2 == 0
    below_labels = panel_h // 4  # sample cell centres, away from the name labels in their top-left corners
    assert colour_at(frame, panel_h // 2, panel_w // 4) == GREY
    cell_w = panel_w // 4
    assert colour_at(frame, below_labels, 2 * cell_w + cell_w // 2) == RED  # head: top left of the grid
    assert colour_at(frame, below_labels, 3 * cell_w + cell_w // 2) == BLUE  # left wrist: top right
    assert colour_at(frame, 3 * below_labels, 2 * cell_w + cell_w // 2) == GREEN_VIEW  # right wrist: bottom left
    assert colour_at(frame, 3 * below_labels, 3 * cell_w + cell_w // 2) == (0, 0, 0)  # no fourth view


def test_one_view_fills_the_block_beside_the_overview():
    frame = compose({"head": solid(RED)}, solid(GREY), Caption("p", 0.0, 20.0))
    panel_h = frame.shape[0] - band_height(frame.shape[1])
    assert colour_at(frame, panel_h * 3 // 4, frame.shape[1] * 7 // 8) == RED


def test_redraw_caption_changes_only_the_band():
    first = compose(views(), solid(GREY), Caption("pick the can", 1.0, 20.0))
    later = redraw_caption(first, Caption("pick the can", 5.0, 20.0, EpisodeEvents(gaze=2.0, grasp=4.0)))
    band = band_height(first.shape[1])
    np.testing.assert_array_equal(first[:-band], later[:-band])
    assert not np.array_equal(first[-band:], later[-band:])


def test_success_shows_only_from_the_step_it_happened():
    events = EpisodeEvents(success=3.0)
    base = compose(views(), solid(GREY), Caption("p", 0.0, 20.0, events))
    band = band_height(base.shape[1])
    upper_line = slice(base.shape[0] - band, base.shape[0] - band + int(0.38 * band))  # prompt, clock, badge
    before = redraw_caption(base, Caption("p", 2.9, 20.0, events))[upper_line]
    after = redraw_caption(base, Caption("p", 3.0, 20.0, events))[upper_line]
    assert not has_colour(before, EVENT_COLOURS["success"]) and has_colour(after, EVENT_COLOURS["success"])


@pytest.mark.parametrize("name,time_s", [("gaze", 1.0), ("reach", 10.0), ("grasp", 19.0)])
def test_each_event_is_ticked_where_it_happened_on_the_timeline(name, time_s):
    frame = compose(views(), solid(GREY), Caption("p", 0.0, 20.0, EpisodeEvents(**{name: time_s})))
    band = frame[-band_height(frame.shape[1]):]
    bar_rows = band[int(0.45 * len(band)):int(0.62 * len(band))]  # around the timeline, above the legend
    columns = np.flatnonzero([has_colour(bar_rows[:, x:x + 1], EVENT_COLOURS[name], 30)
                              for x in range(frame.shape[1])])
    tick_x = columns.mean()
    width = frame.shape[1]
    expected = width * time_s / 20.0
    assert abs(tick_x - expected) < 0.06 * width


def test_a_long_prompt_is_cut_with_an_ellipsis_not_drawn_over_the_clock():
    words = "look at the card and pick the object on its side " * 8
    frame = compose(views(), solid(GREY), Caption(words, 12.5, 20.0))
    band = frame[-band_height(frame.shape[1]):]
    assert band.max() > 200  # text drawn
    right_margin = band[:, -6:]
    assert right_margin.max() < 60  # nothing runs off the right edge


def test_events_of_an_episode_log_record():
    record = {"success": True, "length_steps": 70, "galt_t_head_arrival_s": 1.2, "galt_t_hand_onset_s": 1.5,
              "galt_t_hand_arrival_s": 2.4}
    assert EpisodeEvents.from_episode_record(record, fps=20) == EpisodeEvents(1.2, 1.5, 2.4, 3.5)
    failed = {"success": False, "length_steps": 400, "galt_t_head_arrival_s": None}
    assert EpisodeEvents.from_episode_record(failed, fps=20) == EpisodeEvents()
    assert EpisodeEvents(gaze=1.0, success=2.0).items() == [("gaze", 1.0), ("success", 2.0)]
