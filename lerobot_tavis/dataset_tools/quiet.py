"""Keep dataset commands' output to their own progress bar and real problems.

LeRobot's writer encodes videos through PyAV: FFmpeg logs a line per file ("Starting second pass: moving the moov
atom ..."), the SVT-AV1 encoder prints its 20-line banner and configuration for every video it opens, and the
`datasets` library draws a "Map" progress bar per saved episode. Errors still reach stderr.

Where torchcodec cannot load (FFmpeg's shared libraries missing: `make setup` installs them), LeRobot logs
torchcodec's whole error, one traceback per FFmpeg version it tried, before it decodes with PyAV instead;
`shorten_torchcodec_fallback` makes that warning one line saying what to install.
"""

from __future__ import annotations

import ctypes
import logging
import os
from pathlib import Path

SVT_LOG_ERRORS_ONLY = "1"  # SVT-AV1 log levels: 0 fatal, 1 error, 2 warning, 3 info (its default)


def quiet_media_libraries() -> None:
    """Silence the encoders' informational logs and the per-episode progress bars of `datasets` (this process)."""
    os.environ.setdefault("SVT_LOG", SVT_LOG_ERRORS_ONLY)  # read by SVT-AV1 when an encoder is created
    import av.logging
    import datasets

    av.logging.set_level(av.logging.ERROR)
    _set_ffmpeg_level(av.logging.ERROR)
    datasets.disable_progress_bars()


def _set_ffmpeg_level(level: int) -> None:
    """FFmpeg's own threshold, which its default logger obeys: LeRobot's encoder threads hand logging back to that
    logger after every video (`av.logging.restore_default_callback`), so PyAV's level alone does not last. Found
    through the libavutil this process has loaded (Linux); elsewhere nothing changes."""
    maps = Path("/proc/self/maps")
    if not maps.exists():
        return
    for line in maps.read_text().splitlines():
        path = line.split()[-1]
        if Path(path).name.startswith("libavutil"):
            ctypes.CDLL(path).av_log_set_level(level)
            return


def video_backend() -> str:
    """torchcodec where it can load (it needs FFmpeg's shared libraries), else PyAV, chosen without the long
    traceback LeRobot shows when it picks torchcodec on a machine without those libraries."""
    try:
        import torchcodec.decoders  # noqa: F401
    except Exception:  # torchcodec raises RuntimeError (and others) listing every FFmpeg it tried
        return "pyav"
    return "torchcodec"


FALLBACK_LOGGER = "lerobot.utils.import_utils"  # where LeRobot's `get_safe_default_video_backend` logs
FALLBACK_MARK = "'torchcodec' is installed but cannot be loaded"  # in that warning, after torchcodec's error
FALLBACK_LINE = ("torchcodec cannot load FFmpeg's shared libraries (Debian/Ubuntu: apt-get install ffmpeg, which "
                 "`make setup` runs); videos are decoded with PyAV instead")


class _OneLineTorchcodecFallback(logging.Filter):
    """Rewrites LeRobot's torchcodec fallback warning to FALLBACK_LINE; other records pass unchanged."""

    def filter(self, record: logging.LogRecord) -> bool:
        if FALLBACK_MARK in record.getMessage():
            record.msg, record.args = FALLBACK_LINE, ()
        return True


def shorten_torchcodec_fallback() -> None:
    """Make LeRobot's warning that torchcodec cannot load one line (FALLBACK_LINE), in this process."""
    logger = logging.getLogger(FALLBACK_LOGGER)
    if not any(isinstance(existing, _OneLineTorchcodecFallback) for existing in logger.filters):
        logger.addFilter(_OneLineTorchcodecFallback())
