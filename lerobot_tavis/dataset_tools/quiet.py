"""Keep dataset commands' output to their own progress bar and real problems.

LeRobot's writer encodes videos through PyAV: FFmpeg logs a line per file ("Starting second pass: moving the moov
atom ..."), the SVT-AV1 encoder prints its 20-line banner and configuration for every video it opens, and the
`datasets` library draws a "Map" progress bar per saved episode. Errors still reach stderr.
"""

from __future__ import annotations

import ctypes
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
