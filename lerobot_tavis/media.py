"""Videos and stills of camera frames. Files are written to a temporary name and renamed when complete."""

from __future__ import annotations

import io
import itertools
from collections.abc import Iterable, Iterator
from pathlib import Path

import cv2
import numpy as np

from lerobot_tavis.atomic import atomic_path, write_bytes
from lerobot_tavis.errors import InputError

LABEL_MIN_SCALE, LABEL_MAX_SCALE = 0.5, 1.0  # OpenCV font scales of `label`'s text
LABEL_BOX_OPACITY = 0.65  # how much of the image under a label's box is darkened


def encode_mp4(frames: Iterable[np.ndarray], fps: int) -> bytes:
    """H.264 MP4 of RGB uint8 frames (H, W, 3; H and W even), encoded as they come: an iterator of frames is never
    held whole."""
    import av  # PyAV: only where videos are written

    frames = iter(frames)
    first = next(frames, None)
    if first is None:
        raise ValueError("no frames to encode")
    height, width = first.shape[:2]
    buffer = io.BytesIO()
    with av.open(buffer, mode="w", format="mp4") as container:
        stream = container.add_stream("libx264", rate=fps)
        stream.width, stream.height, stream.pix_fmt = width, height, "yuv420p"
        stream.options = {"crf": "20", "preset": "veryfast"}
        for frame in itertools.chain([first], frames):
            container.mux(stream.encode(av.VideoFrame.from_ndarray(np.ascontiguousarray(frame), format="rgb24")))
        container.mux(stream.encode())
    return buffer.getvalue()


def write_mp4(path: str | Path, frames: list[np.ndarray], fps: int) -> Path:
    """Write RGB uint8 frames (H, W, 3; H and W even) as an H.264 MP4 file (`encode_mp4`)."""
    if not frames:
        raise ValueError(f"no frames to write to {path}")
    return write_bytes(path, encode_mp4(frames, fps))


def iter_mp4(path: str | Path) -> Iterator[np.ndarray]:
    """The RGB uint8 frames (H, W, 3) of a video file, decoded one at a time; a file that is not a video or stops
    decoding is an InputError naming it and the frame."""
    import av  # PyAV: only where videos are read

    decoded = 0
    try:
        with av.open(str(path)) as container:
            if not container.streams.video:
                raise InputError(f"{path}: not a video (no video stream)")
            for frame in container.decode(video=0):
                yield frame.to_ndarray(format="rgb24")
                decoded += 1
    except av.FFmpegError as error:
        raise InputError(f"{path}: frame {decoded} cannot be decoded ({error.strerror or error})") from None


def write_png(path: str | Path, rgb: np.ndarray) -> Path:
    """Write an RGB uint8 image (H, W, 3) as PNG."""
    with atomic_path(path, suffix=".png") as partial:  # OpenCV picks the format from the extension
        if not cv2.imwrite(str(partial), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR)):
            raise OSError(f"could not write {path}")
    return Path(path)


def label(image: np.ndarray, text: str) -> np.ndarray:
    """A copy of `image` with `text` in white on a dark box in its top-left corner, its size following the image's
    height (at least LABEL_MIN_SCALE, legible on a 120-pixel tile)."""
    out = image.copy()
    scale = min(LABEL_MAX_SCALE, max(LABEL_MIN_SCALE, image.shape[0] / 400))
    thickness = 1 if scale < 0.7 else 2
    (text_w, text_h), baseline = cv2.getTextSize(text, cv2.FONT_HERSHEY_SIMPLEX, scale, thickness)
    pad = max(3, int(6 * scale))
    box = out[:text_h + baseline + 2 * pad, :text_w + 2 * pad]
    box[:] = (box * (1 - LABEL_BOX_OPACITY)).astype(np.uint8)  # the view stays visible through the box
    cv2.putText(out, text, (pad, pad + text_h), cv2.FONT_HERSHEY_SIMPLEX, scale, (255, 255, 255), thickness,
                cv2.LINE_AA)
    return out
