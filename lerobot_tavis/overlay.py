"""Annotated video frames for people: a third-person overview beside the policy's own views, and a caption band
with the prompt, the clock, success and the gaze and hand events GALT found.

    +-------------------+------+        +-------------------+---------+---------+
    |                   | head |        |                   | head    | fixed   |
    |     overview      +------+        |     overview      +---------+---------+
    |                   | left |        |                   | left    | right   |
    |                   +------+        +-------------------+---------+---------+
    |                   | right|        four views: half size, two per row; one view: the overview's size;
    +-------------------+------+        two or three: one column, so that no tile is left empty
    | prompt, wrapped to two lines       t 3.25 s |     caption band: prompt, clock, SUCCESS once it happened
    | |--gaze---reach----grasp--|--------->        |     timeline of the episode with its events and the cursor
    +---------------------------------------------+

Live frames (the env's `render()`, which lerobot-eval films) know only what has happened so far: the clock and
success. Once an episode is over its events are known (`EpisodeEvents`) and `redraw_caption` rewrites the band of
frames already composed, so the same layout serves `tavis demo` and the videos `tavis report` annotates. Numpy and
OpenCV only: no simulator here.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from lerobot_tavis.media import label

PANEL_HEIGHT = 360  # composed panels are this many pixels high whatever the cameras' size: the text stays legible,
# and a filmed frame stays about 1 MB (lerobot-eval holds every frame of its filmed episodes in memory)
PROMPT_LINES = 2  # the band holds this many lines of prompt; a longer prompt is drawn smaller to fit them
FONT = cv2.FONT_HERSHEY_SIMPLEX
# caption band rows, in pixels at text scale 1: top margin, each prompt line, the timeline, the legend, bottom margin
BAND_TOP, BAND_LINE, BAND_TIMELINE, BAND_LEGEND, BAND_BOTTOM = 8, 30, 32, 28, 8
WHITE, GREY, GREEN, BLACK = (255, 255, 255), (150, 150, 150), (60, 200, 90), (20, 20, 20)
EVENT_COLOURS = {"gaze": (80, 170, 255), "reach": (255, 170, 60), "grasp": (240, 80, 80), "success": GREEN}


@dataclass(frozen=True)
class EpisodeEvents:
    """Times (s from the first observation) of what happened in one episode; None where nothing was found.
    `gaze`: the head's arrival on its final fixation, `reach`: the grasping hand's onset, `grasp`: the final
    gripper closing (GALT's anchor), `success`: the step the task first reported success."""

    gaze: float | None = None
    reach: float | None = None
    grasp: float | None = None
    success: float | None = None

    @classmethod
    def from_episode_record(cls, record: dict, fps: float) -> EpisodeEvents:
        """The events of one line of the episode log (`lerobot_tavis.eval.episode_log`)."""
        success = record["length_steps"] / fps if record.get("success") else None
        return cls(gaze=record.get("galt_t_head_arrival_s"), reach=record.get("galt_t_hand_onset_s"),
                   grasp=record.get("galt_t_hand_arrival_s"), success=success)

    def items(self) -> list[tuple[str, float]]:
        return [(name, time) for name, time in vars(self).items() if time is not None]


@dataclass(frozen=True)
class Caption:
    """What the band of one frame says: `time_s` of `duration_s` seconds, and the events known at that frame
    (drawn on the timeline; SUCCESS shows once `time_s` reaches `events.success`)."""

    prompt: str
    time_s: float
    duration_s: float
    events: EpisodeEvents = EpisodeEvents()


def compose(views: dict[str, np.ndarray], overview: np.ndarray, caption: Caption) -> np.ndarray:
    """One annotated frame: the overview, the labelled policy views (each (h, w, 3) like the overview) and the
    caption band; height and width even, as H.264 needs."""
    height, width = panel_size(overview.shape[:2])
    shrink = height < overview.shape[0]
    overview = cv2.resize(overview, (width, height), interpolation=cv2.INTER_AREA if shrink else cv2.INTER_LINEAR)
    panel = np.concatenate([label(overview, "overview"), _view_grid(views, height, width)], axis=1)
    band = np.zeros((band_height(panel.shape[1]), panel.shape[1], 3), np.uint8)
    return redraw_caption(np.concatenate([panel, band], axis=0), caption)


def panel_size(overview_hw: tuple[int, int]) -> tuple[int, int]:
    """(height, width) in pixels of the overview's block: PANEL_HEIGHT high, the overview's aspect ratio, width
    even."""
    return PANEL_HEIGHT, 2 * round(overview_hw[1] * PANEL_HEIGHT / overview_hw[0] / 2)


def grid_shape(n_views: int) -> tuple[int, int]:
    """(rows, columns) of the views' grid: 2x2 for four views, else one column (one view fills the block)."""
    return (2, 2) if n_views == 4 else (n_views, 1)


def text_scale(frame_width: int) -> float:
    """OpenCV font scale of the caption band's text in a frame `frame_width` pixels wide."""
    return max(0.5, frame_width / 1400)


def band_height(frame_width: int) -> int:
    """Height in pixels of the caption band of a frame `frame_width` pixels wide (even): PROMPT_LINES lines of
    prompt, the timeline and its legend."""
    rows = BAND_TOP + PROMPT_LINES * BAND_LINE + BAND_TIMELINE + BAND_LEGEND + BAND_BOTTOM
    return 2 * int(np.ceil(rows * text_scale(frame_width) / 2))


def redraw_caption(frame: np.ndarray, caption: Caption) -> np.ndarray:
    """A copy of `frame` (made by `compose`) with its caption band drawn anew for `caption`."""
    frame = frame.copy()
    band = frame[-band_height(frame.shape[1]):]
    band[:] = BLACK
    _draw_band(band, caption)
    return frame


def _view_grid(views: dict[str, np.ndarray], height: int, width: int) -> np.ndarray:
    """The views, labelled, in a block `height` pixels high laid out by `grid_shape`, each cell of the overview's
    aspect ratio (`width` / `height`); at most four views."""
    rows, cols = grid_shape(len(views))
    cell_h = height // rows
    cell_w = 2 * round(width * cell_h / height / 2)
    grid = np.zeros((height, cols * cell_w, 3), np.uint8)
    for index, (name, image) in enumerate(list(views.items())[:4]):
        row, col = divmod(index, cols)
        cell = cv2.resize(image, (cell_w, cell_h), interpolation=cv2.INTER_LINEAR)
        grid[row * cell_h:(row + 1) * cell_h, col * cell_w:(col + 1) * cell_w] = label(cell, name)
    return grid


def _draw_band(band: np.ndarray, caption: Caption) -> None:
    """The prompt wrapped on PROMPT_LINES lines with the clock (and SUCCESS when reached) at the right of the first,
    then the timeline with its events and their legend (in place)."""
    height, width = band.shape[:2]
    scale = text_scale(width)
    thickness = max(1, int(round(scale * 1.6)))
    margin = int(10 * scale) + 4
    clock = f"t {caption.time_s:5.2f} s"
    clock_w = _text_width(clock, scale, thickness)
    succeeded = caption.events.success is not None and caption.time_s >= caption.events.success
    badge = "SUCCESS" if succeeded else ""
    badge_w = _text_width(badge, scale, thickness + 1) + margin if badge else 0
    first_y = int((BAND_TOP + BAND_LINE - 8) * scale)
    prompt_scale, lines = wrap(caption.prompt, width - 3 * margin - clock_w - badge_w, scale, thickness, PROMPT_LINES)
    for index, line in enumerate(lines):
        _put(band, line, (margin, first_y + int(index * BAND_LINE * scale)), prompt_scale, WHITE, thickness)
    _put(band, clock, (width - margin - clock_w, first_y), scale, WHITE, thickness)
    if badge:
        _put(band, badge, (width - margin - clock_w - badge_w, first_y), scale, GREEN, thickness + 1)

    left, right = margin, width - margin
    bar_y = int((BAND_TOP + PROMPT_LINES * BAND_LINE + BAND_TIMELINE / 2) * scale)
    duration = max(caption.duration_s, 1e-6)
    to_x = lambda t: int(round(left + (right - left) * min(max(t / duration, 0.0), 1.0)))  # noqa: E731
    cv2.line(band, (left, bar_y), (right, bar_y), GREY, thickness, cv2.LINE_AA)
    cv2.line(band, (left, bar_y), (to_x(caption.time_s), bar_y), WHITE, thickness + 1, cv2.LINE_AA)
    tick = int(BAND_TIMELINE * scale * 0.35)
    legend_x, legend_y = left, int((BAND_TOP + PROMPT_LINES * BAND_LINE + BAND_TIMELINE + BAND_LEGEND - 8) * scale)
    for name, time_s in caption.events.items():
        x = to_x(time_s)
        colour = EVENT_COLOURS[name]
        cv2.line(band, (x, bar_y - tick), (x, bar_y + tick), colour, thickness + 1, cv2.LINE_AA)
        entry = f"{name} {time_s:.2f} s"
        _put(band, entry, (legend_x, legend_y), 0.8 * scale, colour, thickness)
        legend_x += _text_width(entry + "   ", 0.8 * scale, thickness)
    cv2.circle(band, (to_x(caption.time_s), bar_y), max(3, tick // 2), WHITE, -1, cv2.LINE_AA)


def wrap(text: str, room: int, scale: float, thickness: int, max_lines: int) -> tuple[float, list[str]]:
    """(font scale, lines): `text` broken at spaces into at most `max_lines` lines of at most `room` pixels, at
    `scale` or, for a longer text, the largest smaller scale down to half of it that fits; below that, the last line
    ends with "..." where the text is cut."""
    for step in range(6):
        size = scale * (1 - 0.1 * step)
        lines = _break_lines(text, room, size, thickness)
        if len(lines) <= max_lines:
            return size, lines
    kept = lines[:max_lines]
    kept[-1] = _fit(" ".join([kept[-1], *lines[max_lines:]]), room, size, thickness)
    return size, kept


def _break_lines(text: str, room: int, scale: float, thickness: int) -> list[str]:
    """`text` broken at spaces into lines of at most `room` pixels (a word wider than that has a line of its own)."""
    lines: list[str] = []
    for word in text.split():
        if lines and _text_width(f"{lines[-1]} {word}", scale, thickness) <= room:
            lines[-1] = f"{lines[-1]} {word}"
        else:
            lines.append(word)
    return lines or [""]


def _text_width(text: str, scale: float, thickness: int) -> int:
    return cv2.getTextSize(text, FONT, scale, thickness)[0][0]


def _put(image, text, origin, scale, colour, thickness) -> None:
    cv2.putText(image, text, origin, FONT, scale, colour, thickness, cv2.LINE_AA)


def _fit(text: str, room: int, scale: float, thickness: int) -> str:
    """`text`, cut with an ellipsis to fit `room` pixels."""
    if _text_width(text, scale, thickness) <= room:
        return text
    while text and _text_width(text + "...", scale, thickness) > room:
        text = text[:-1]
    return text + "..."
