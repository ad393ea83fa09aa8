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


def test_three_views_stand_in_one_column_beside_the_overview_no_tile_empty():
    frame = compose(views(), solid(GREY), Caption("pick the can", 1.0, 20.0))
    panel_h, overview_w = PANEL_HEIGHT, 480  # the 60x80 overview scaled to 360x480
    cell_h, cell_w = panel_h // 3, overview_w // 3  # the views at a third of its size, one above the other
    assert frame.shape == (panel_h + band_height(overview_w + cell_w), overview_w + cell_w, 3)
    assert frame.shape[0] % 2 == 0 and frame.shape[1] % 2 == 0
    assert colour_at(frame, panel_h // 2, overview_w // 2) == GREY
    centre_x = overview_w + cell_w // 2
    for row, colour in enumerate((RED, BLUE, GREEN_VIEW)):  # head, left wrist, right wrist, from the top
        assert colour_at(frame, row * cell_h + 3 * cell_h // 4, centre_x) == colour  # below the cell's label


def test_four_views_fill_a_two_by_two_grid():
    four = {**views(), "fixed": solid((200, 200, 30))}
    frame = compose(four, solid(GREY), Caption("p", 1.0, 20.0))
    assert frame.shape[1] == 2 * 480
    cell_h, cell_w = PANEL_HEIGHT // 2, 240
    centres = [(3 * cell_h // 4 + row * cell_h, 480 + cell_w // 2 + col * cell_w) for row in (0, 1) for col in (0, 1)]
    assert [colour_at(frame, y, x) for y, x in centres] == [RED, BLUE, GREEN_VIEW, (200, 200, 30)]


def test_labels_are_white_on_a_dark_box_and_grow_with_the_image():
    from lerobot_tavis.media import label

    small, large = (label(solid((180, 180, 180), size), "head") for size in ((120, 160), (360, 480)))
    for image in (small, large):
        corner = image[:image.shape[0] // 5, :image.shape[1] // 2]
        assert corner.max() > 240 and corner.min() < 80  # white text over a darkened box
    text_height = [np.ptp(np.flatnonzero((image[:, :30] > 200).all(axis=-1).any(axis=1))) for image in (small, large)]
    assert 8 <= text_height[0] < text_height[1]


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
    upper_line = slice(base.shape[0] - band, base.shape[0] - band + int(0.28 * band))  # prompt, clock, badge
    before = redraw_caption(base, Caption("p", 2.9, 20.0, events))[upper_line]
    after = redraw_caption(base, Caption("p", 3.0, 20.0, events))[upper_line]
    assert not has_colour(before, EVENT_COLOURS["success"]) and has_colour(after, EVENT_COLOURS["success"])


@pytest.mark.parametrize("name,time_s", [("gaze", 1.0), ("reach", 10.0), ("grasp", 19.0)])
def test_each_event_is_ticked_where_it_happened_on_the_timeline(name, time_s):
    frame = compose(views(), solid(GREY), Caption("p", 0.0, 20.0, EpisodeEvents(**{name: time_s})))
    band = frame[-band_height(frame.shape[1]):]
    bar_rows = band[int(0.52 * len(band)):int(0.70 * len(band))]  # around the timeline, above the legend
    columns = np.flatnonzero([has_colour(bar_rows[:, x:x + 1], EVENT_COLOURS[name], 30)
                              for x in range(frame.shape[1])])
    tick_x = columns.mean()
    width = frame.shape[1]
    expected = width * time_s / 20.0
    assert abs(tick_x - expected) < 0.06 * width


def test_a_long_prompt_is_wrapped_whole_not_cut_nor_drawn_over_the_clock():
    from lerobot_tavis.envs.tasks.catalog import task_info
    from lerobot_tavis.overlay import text_scale, wrap

    prompt = task_info("conditional_pick").prompts[0]  # its green branch was cut off
    frame = compose(views(), solid(GREY), Caption(prompt, 12.5, 20.0))
    width = frame.shape[1]
    scale, lines = wrap(prompt, 3 * width // 4, text_scale(width), 1, 2)  # about the room left of the clock
    assert len(lines) == 2 and " ".join(lines) == prompt and scale == text_scale(width)
    band = frame[-band_height(width):]
    second_line = band[int(0.28 * len(band)):int(0.5 * len(band)), :width // 2]
    assert second_line.max() > 200  # the prompt's second line is drawn
    assert band[:, -6:].max() < 60  # nothing runs off the right edge


def test_a_prompt_too_long_for_two_lines_is_drawn_smaller_and_cut_only_past_half_size():
    from lerobot_tavis.overlay import wrap

    words = "look at the card and pick the object on its side " * 3
    scale, lines = wrap(words, 400, 0.5, 1, 2)
    assert len(lines) == 2 and scale < 0.5 and " ".join(lines) == words.strip()
    scale, lines = wrap(words * 10, 400, 0.5, 1, 2)
    assert len(lines) == 2 and scale == pytest.approx(0.25) and lines[-1].endswith("...")


def test_events_of_an_episode_log_record():
    record = {"success": True, "length_steps": 70, "galt_t_head_arrival_s": 1.2, "galt_t_hand_onset_s": 1.5,
              "galt_t_hand_arrival_s": 2.4}
    assert EpisodeEvents.from_episode_record(record, fps=20) == EpisodeEvents(1.2, 1.5, 2.4, 3.5)
    failed = {"success": False, "length_steps": 400, "galt_t_head_arrival_s": None}
    assert EpisodeEvents.from_episode_record(failed, fps=20) == EpisodeEvents()
    assert EpisodeEvents(gaze=1.0, success=2.0).items() == [("gaze", 1.0), ("success", 2.0)]
