"""Videos and stills of camera frames. Files are written to a temporary name and renamed when complete."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from lerobot_tavis.atomic import atomic_path


def write_mp4(path: str | Path, frames: list[np.ndarray], fps: int) -> Path:
    """Encode RGB uint8 frames (H, W, 3; H and W even) as H.264 MP4."""
    import av  # PyAV: only where videos are written

    path = Path(path)
    if not frames:
        raise ValueError(f"no frames to write to {path}")
    height, width = frames[0].shape[:2]
    with atomic_path(path) as partial, av.open(str(partial), mode="w", format="mp4") as container:
        stream = container.add_stream("libx264", rate=fps)
        stream.width, stream.height, stream.pix_fmt = width, height, "yuv420p"
        stream.options = {"crf": "20", "preset": "veryfast"}
        for frame in frames:
            container.mux(stream.encode(av.VideoFrame.from_ndarray(np.ascontiguousarray(frame), format="rgb24")))
        container.mux(stream.encode())
    return path


def read_mp4(path: str | Path) -> list[np.ndarray]:
    """The RGB uint8 frames (H, W, 3) of a video file."""
    import av  # PyAV: only where videos are read

    with av.open(str(path)) as container:
        return [frame.to_ndarray(format="rgb24") for frame in container.decode(video=0)]


def write_png(path: str | Path, rgb: np.ndarray) -> Path:
    """Write an RGB uint8 image (H, W, 3) as PNG."""
    with atomic_path(path, suffix=".png") as partial:  # OpenCV picks the format from the extension
        if not cv2.imwrite(str(partial), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR)):
            raise OSError(f"could not write {path}")
    return Path(path)


def label(image: np.ndarray, text: str) -> np.ndarray:
    """A copy of `image` with `text` in its top-left corner."""
    out = image.copy()
    scale = max(0.4, image.shape[0] / 600)
    cv2.putText(out, text, (8, int(22 * scale)), cv2.FONT_HERSHEY_SIMPLEX, scale, (0, 0, 0), 3, cv2.LINE_AA)
    cv2.putText(out, text, (8, int(22 * scale)), cv2.FONT_HERSHEY_SIMPLEX, scale, (255, 255, 255), 1, cv2.LINE_AA)
    return out

