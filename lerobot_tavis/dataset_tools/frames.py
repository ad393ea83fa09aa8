"""A LeRobotDataset v3.0's files, read with one-line errors naming the damaged file: its `meta/info.json`, its frames
per episode (from the data files, which hold no video frames) in frame order, and the camera frames of episodes,
decoded one by one from their videos (or PNG images) to prove they are there."""

from __future__ import annotations

import io
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from lerobot_tavis.errors import InputError, PathNotFoundError
from lerobot_tavis.readers import expect, get, get_integer, read_json, read_parquet

INFO = "meta/info.json"
FRAME_COLUMNS = ("episode_index", "frame_index", "timestamp")  # what a replay needs in every data file


def dataset_info(root: str | Path) -> dict:
    """The dataset's `meta/info.json`, checked for what this package reads: codebase_version, fps, features (each
    with dtype and shape), robot_type, data_path and, with video features, video_path."""
    path = Path(root) / INFO
    if not path.is_file():
        raise PathNotFoundError(f"{path}: missing ({root} is not a LeRobotDataset)")
    info = read_json(path)
    if not isinstance(info, dict):
        raise InputError(f"{path}: must be a JSON object, got {type(info).__name__}")
    get(info, "codebase_version", "str", path)
    info["fps"] = get_integer(info, "fps", path, minimum=1)
    get(info, "robot_type", "str", path, optional=True)
    get(info, "data_path", "str", path)
    for key, feature in get(info, "features", "object", path).items():
        expect(feature, "object", path, f"features.{key}")
        get(feature, "dtype", "str", path, f"features.{key}.")
        get(feature, "shape", "list", path, f"features.{key}.")
        if feature["dtype"] == "video":
            get(info, "video_path", "str", path)
    return info


def check_files(root: str | Path) -> None:
    """Read every JSON and Parquet file of the dataset's meta/ and data/ whole: an error names the first damaged
    one."""
    root = Path(root)
    for path in sorted((root / "meta").rglob("*.json")):
        read_json(path)
    for folder in ("meta", "data"):
        for path in sorted((root / folder).rglob("*.parquet")):
            read_parquet(path)


def episode_frames(root: str | Path, columns: tuple[str, ...] = FRAME_COLUMNS) -> dict:
    """Per episode index, its rows of the data files under `root` (a pandas DataFrame) sorted by `frame_index`;
    each row also names its `data_file`. A data file without one of `columns` is refused, naming it."""
    import pandas as pd

    paths = sorted((Path(root) / "data").rglob("*.parquet"))
    if not paths:
        raise InputError(f"{Path(root) / 'data'}: holds no data files (Parquet)")
    tables = []
    for path in paths:
        table = read_parquet(path).to_pandas()
        missing = [column for column in dict.fromkeys(("episode_index", "frame_index", *columns))
                   if column not in table.columns]
        if missing:
            raise InputError(f"{path}: not a LeRobotDataset data file (no column {', '.join(missing)})")
        tables.append(table.assign(data_file=str(path)))
    table = pd.concat(tables).sort_values(["episode_index", "frame_index"])
    return {int(index): rows for index, rows in table.groupby("episode_index")}


def column_array(rows, key: str) -> np.ndarray:
    """A vector column (e.g. `action`) of an episode's rows as one (frames, size) array."""
    return np.stack(rows[key].to_numpy())


def check_camera_frames(root: str | Path, info: dict, episodes: Mapping) -> None:
    """Decode every camera frame of `episodes` ({episode index: its `episode_frames` rows}): each video frame at
    the episode's start in its video plus the row's timestamp, each PNG image of a row. InputError names the file,
    the episode and the frame that fails."""
    root = Path(root)
    for key, feature in info["features"].items():
        if feature["dtype"] == "video":
            _check_video_frames(root, info, key, episodes)
        elif feature["dtype"] == "image":
            for index, rows in episodes.items():
                for frame, data_file, image in zip(rows["frame_index"], rows["data_file"], rows[key]):
                    _decode_png(image, f"{data_file}: {key} of frame {frame} of episode {index}")


def _check_video_frames(root: Path, info: dict, key: str, episodes: Mapping) -> None:
    """Every frame of camera `key` of `episodes` decoded: a frame within half a frame period of each row's time."""
    import pandas as pd

    meta_paths = sorted((root / "meta/episodes").rglob("*.parquet"))
    if not meta_paths:
        raise PathNotFoundError(f"{root / 'meta/episodes'}: no episode metadata (Parquet files)")
    columns = [f"videos/{key}/{name}" for name in ("chunk_index", "file_index", "from_timestamp")]
    meta = pd.concat([read_parquet(path).to_pandas() for path in meta_paths])
    if "episode_index" not in meta.columns:
        raise InputError(f"{root / 'meta/episodes'}: not LeRobot episode metadata (no column episode_index)")
    meta = meta.set_index("episode_index")
    tolerance_s = 0.5 / info["fps"]
    decoded: dict[Path, tuple[np.ndarray, str | None]] = {}
    for index, rows in episodes.items():
        if index not in meta.index or any(column not in meta.columns for column in columns):
            raise InputError(f"{root / 'meta/episodes'}: no video of {key} for episode {index}")
        try:
            chunk, file, start_s = (cast(meta.loc[index, column]) for cast, column in zip((int, int, float), columns))
        except (TypeError, ValueError):
            raise InputError(f"{root / 'meta/episodes'}: episode {index}: {', '.join(columns)} must be "
                             "numbers") from None
        try:
            video = root / info["video_path"].format(video_key=key, chunk_index=chunk, file_index=file)
        except (KeyError, IndexError, ValueError) as error:
            raise InputError(f"{root / INFO}: video_path {info['video_path']!r} is not a LeRobot path pattern "
                             f"({type(error).__name__}: {error})") from None
        if video not in decoded:
            decoded[video] = _frame_times(video)
        times, failure = decoded[video]
        for frame, timestamp in zip(rows["frame_index"], rows["timestamp"]):
            wanted_s = start_s + float(timestamp)
            if not (len(times) and np.min(np.abs(times - wanted_s)) <= tolerance_s):
                reason = failure or (f"not in the video, which holds {len(times)} frames"
                                     + (f" up to {times.max():.2f} s" if len(times) else ""))
                raise InputError(f"{video}: frame {frame} of episode {index} ({wanted_s:.2f} s) cannot be decoded: "
                                 f"{reason}")


def _frame_times(video: Path) -> tuple[np.ndarray, str | None]:
    """The times (s) of the frames of `video` decoded until its end or its first error, and that error."""
    import av

    if not video.is_file():
        raise PathNotFoundError(f"{video}: missing")
    times, failure = [], None
    try:
        with av.open(str(video)) as container:
            if not container.streams.video:
                raise InputError(f"{video}: not a video (no video stream)")
            for frame in container.decode(video=0):
                times.append(np.nan if frame.time is None else frame.time)
    except av.FFmpegError as error:
        failure = f"decoding stops after {len(times)} frames ({error.strerror or error})"
    return np.array(times, dtype=float), failure


def _decode_png(image, where: str) -> None:
    from PIL import Image, UnidentifiedImageError

    data = image.get("bytes") if isinstance(image, dict) else None
    try:
        Image.open(io.BytesIO(data)).load()
    except (TypeError, OSError, UnidentifiedImageError, SyntaxError, ValueError) as error:
        raise InputError(f"{where} cannot be decoded ({type(error).__name__})") from None
