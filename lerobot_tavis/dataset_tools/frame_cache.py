"""`tavis cache-frames`: a LeRobotDataset's video frames decoded once, kept beside it as uint8 arrays.

Training on videos decodes every sample's frames again in the loader workers; the cache decodes each frame once,
with LeRobot's own decoder, and stores it at the dataset's resolution (the resolution it was converted at, which
the compact presets train at). Layout, in `<root>.frame_cache/` next to the dataset directory `<root>` (outside it,
so a push of the dataset never uploads the cache):

- `<camera key>.npy`: one per video key, shape (frames, channels, height, width), uint8, row r the frame of the
  dataset's absolute index r (the `index` column), read through a memory map;
- `timestamps.npy`: row r's timestamp within its episode (s), the one LeRobot decodes row r's frame at;
- `cache.json`: the format, the video backend that decoded the frames and the dataset's fingerprint: the SHA-256
  of every file the frames depend on (meta/info.json, meta/episodes/, data/, videos/).

`FrameCache.open` refuses a cache whose dataset changed since it was written, naming the first file that differs.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lerobot_tavis import checks
from lerobot_tavis.cli_options import option
from lerobot_tavis.errors import InputError, PathNotFoundError

FORMAT = 1
CACHE_FILE = "cache.json"
TIMESTAMPS_FILE = "timestamps.npy"
FINGERPRINTED = ("meta/info.json", "meta/episodes", "data", "videos")  # what decides a dataset's frames
DECODE_TOLERANCE_S = 1e-4  # LeRobot's default `tolerance_s` (LeRobotDataset and lerobot-train)
VIDEO_BACKENDS = ("pyav", "torchcodec")


class StaleFrameCacheError(InputError):
    """A frame cache written for other dataset files than those there now (or none written yet)."""


@dataclass(frozen=True)
class CacheFramesConfig:
    """What `tavis cache-frames` caches; also its command-line options."""

    root: Path = option(help="the dataset directory (LeRobotDataset v3.0 with video cameras)", positional=True)
    workers: int = option(1, "processes decoding episodes (the cache does not depend on it)")
    video_backend: str = option("pyav", "LeRobot's decoder that makes the frames: pyav (the presets' "
                                "`dataset.video_backend`) or torchcodec (needs FFmpeg's shared libraries)",
                                choices=VIDEO_BACKENDS)

    def __post_init__(self):
        checks.integer("workers", self.workers, 1)


def cache_dir(root: str | Path) -> Path:
    """Where the frame cache of the dataset at `root` lives: `<root>.frame_cache` beside it."""
    root = Path(root).absolute()
    return root.with_name(f"{root.name}.frame_cache")


def dataset_fingerprint(root: str | Path) -> dict[str, str]:
    """Relative path -> SHA-256 of each file of `root` that decides its frames (FINGERPRINTED), sorted by path."""
    root = Path(root)
    files = []
    for name in FINGERPRINTED:
        path = root / name
        if path.is_dir():
            files += sorted(p for p in path.rglob("*") if p.is_file())
        elif path.is_file():
            files.append(path)
    digests = {}
    for path in files:
        with path.open("rb") as file:
            digests[path.relative_to(root).as_posix()] = hashlib.file_digest(file, "sha256").hexdigest()
    return digests


def write_frame_cache(cfg: CacheFramesConfig) -> list[str]:
    """Decode every video frame of the dataset at `cfg.root` into its cache (an up-to-date cache is kept as it is);
    returns the lines `tavis cache-frames` prints."""
    from concurrent.futures import as_completed

    from tqdm import tqdm

    from lerobot_tavis.staging import staged_directory
    from lerobot_tavis.workers import executor

    root = Path(cfg.root).absolute()
    if not (root / "meta" / "info.json").is_file():
        raise PathNotFoundError(f"{root} is not a LeRobotDataset (no meta/info.json)")
    fingerprint = dataset_fingerprint(root)
    destination = cache_dir(root)
    try:
        cache = FrameCache.open(root)
    except StaleFrameCacheError:
        pass
    else:
        if cache.video_backend == cfg.video_backend:
            return [f"{destination}: up to date ({cache.frame_count} frames, {len(cache.cameras)} cameras)"]
    meta, rows = _dataset_layout(root)
    with staged_directory(destination, overwrite=True) as staging:
        staging.mkdir()
        arrays = {key: np.lib.format.open_memmap(staging / f"{key}.npy", mode="w+", dtype=np.uint8,
                                                 shape=(len(rows), *_channels_first(meta.features[key]["shape"])))
                  for key in meta.video_keys}
        np.save(staging / TIMESTAMPS_FILE, rows["timestamp"].to_numpy(np.float64))
        jobs = [(episode, key) for episode in range(meta.total_episodes) for key in meta.video_keys]
        with executor(min(cfg.workers, len(jobs)), share_cpus=True) as pool:  # decoders: a few threads each
            futures = {pool.submit(decode_episode, *_decode_arguments(meta, rows, episode, key),
                                   cfg.video_backend): (episode, key) for episode, key in jobs}
            for future in tqdm(as_completed(futures), total=len(jobs), desc=f"cache-frames {root.name}",
                               unit="video", disable=len(jobs) < 2):  # written as they come: memory stays bounded
                episode, key = futures[future]
                start, end = _episode_rows(meta, episode)
                arrays[key][start:end] = future.result()
        for array in arrays.values():
            array.flush()
        cameras = {key: {"file": f"{key}.npy", "shape": list(array.shape)} for key, array in arrays.items()}
        del arrays
        record = {"format": FORMAT, "video_backend": cfg.video_backend, "frames": len(rows), "cameras": cameras,
                  "fingerprint": fingerprint}
        (staging / CACHE_FILE).write_text(json.dumps(record, indent=1) + "\n")
    size_gb = sum(p.stat().st_size for p in destination.iterdir()) / 1e9
    return [f"{destination}: {len(rows)} frames of {len(cameras)} cameras, {size_gb:.2f} GB "
            f"(decoded with {cfg.video_backend})"]


def decode_episode(video_path: str, timestamps: list[float], backend: str) -> np.ndarray:
    """One episode's frames of one camera, (frames, channels, height, width) uint8, decoded by LeRobot at the
    video timestamps given (s), exactly as its loader decodes a sample's frames."""
    from lerobot.datasets.video_utils import decode_video_frames

    return decode_video_frames(video_path, timestamps, DECODE_TOLERANCE_S, backend, return_uint8=True).numpy()


def _dataset_layout(root: Path):
    """LeRobot's metadata of the dataset at `root` and its rows (pandas: `index`, `episode_index`, `timestamp`)
    in absolute-index order; refuses datasets the cache cannot hold."""
    import pandas as pd
    from lerobot.datasets.dataset_metadata import LeRobotDatasetMetadata

    meta = LeRobotDatasetMetadata("local/frame-cache", root=root)
    if not meta.video_keys:
        raise InputError(f"{root}: the dataset stores no video cameras; there is nothing to cache")
    if meta.depth_keys:
        raise InputError(f"{root}: the frame cache holds colour videos only, the dataset has depth cameras "
                         f"{list(meta.depth_keys)}")
    paths = sorted((root / "data").rglob("*.parquet"))
    if not paths:
        raise InputError(f"{root}: no data files under data/")
    rows = pd.concat([pd.read_parquet(p, columns=["index", "episode_index", "timestamp"]) for p in paths])
    rows = rows.sort_values("index").reset_index(drop=True)
    if not np.array_equal(rows["index"].to_numpy(), np.arange(len(rows))):
        raise InputError(f"{root}: the data files' `index` column is not 0..{len(rows) - 1}, one row each")
    return meta, rows


def _episode_rows(meta, episode: int) -> tuple[int, int]:
    """The absolute index range [start, end) of `episode`."""
    entry = meta.episodes[episode]
    return int(entry["dataset_from_index"]), int(entry["dataset_to_index"])


def _decode_arguments(meta, rows, episode: int, key: str) -> tuple[str, list[float]]:
    """The video file holding `episode` of camera `key`, and the timestamps of the episode's frames in it."""
    start, end = _episode_rows(meta, episode)
    offset = meta.episodes[episode][f"videos/{key}/from_timestamp"]
    timestamps = rows["timestamp"].to_numpy(np.float64)[start:end]
    return str(meta.root / meta.get_video_file_path(episode, key)), [offset + float(t) for t in timestamps]


def _channels_first(shape) -> tuple[int, int, int]:
    """LeRobot's video feature shape (height, width, channels) as the (channels, height, width) it decodes to."""
    height, width, channels = shape
    return channels, height, width


class FrameCache:
    """A dataset's frame cache, checked against the dataset's files when opened. Picklable for spawned loader
    workers: the memory maps are opened in each process on first use, never pickled."""

    def __init__(self, directory: Path, record: dict):
        self.directory = directory
        self.video_backend: str = record["video_backend"]
        self.frame_count: int = record["frames"]
        self.cameras: dict[str, dict] = record["cameras"]
        self._arrays: dict[str, np.ndarray] = {}
        self._timestamps: np.ndarray | None = None

    @classmethod
    def open(cls, root: str | Path) -> FrameCache:
        """The cache of the dataset at `root`; StaleFrameCacheError (one line, naming what differs and the command
        that rebuilds it) if there is none or the dataset's files are not those it was written from."""
        directory = cache_dir(root)
        rebuild = f"run `tavis cache-frames {Path(root).absolute()}`"
        try:
            record = json.loads((directory / CACHE_FILE).read_text())
        except FileNotFoundError:
            raise StaleFrameCacheError(f"no frame cache for {root} (expected {directory}); {rebuild}") from None
        if record.get("format") != FORMAT:
            raise StaleFrameCacheError(f"{directory} has format {record.get('format')}, this version reads "
                                       f"{FORMAT}; {rebuild}")
        now, then = dataset_fingerprint(root), record["fingerprint"]
        if now != then:
            changed = sorted(set(now) ^ set(then)) + sorted(p for p in set(now) & set(then) if now[p] != then[p])
            more = f" and {len(changed) - 1} more files" if len(changed) > 1 else ""
            raise StaleFrameCacheError(f"the frame cache {directory} is stale: {root} changed after it was written "
                                       f"({changed[0]}{more}); {rebuild}")
        return cls(directory, record)

    def __getstate__(self) -> dict:
        return {**self.__dict__, "_arrays": {}, "_timestamps": None}

    def rows(self, start: int, end: int, timestamps, tolerance_s: float) -> np.ndarray:
        """The rows in [start, end) (one episode) whose timestamps are nearest to `timestamps` (s); a timestamp
        with no row within `tolerance_s` is an error, as in LeRobot's decoders."""
        if self._timestamps is None:
            self._timestamps = np.load(self.directory / TIMESTAMPS_FILE, mmap_mode="r")
        episode = np.asarray(self._timestamps[start:end])
        query = np.asarray(timestamps, dtype=np.float64)
        distance = np.abs(query[:, None] - episode[None, :])
        nearest = distance.argmin(axis=1)
        misses = distance[np.arange(len(query)), nearest] >= tolerance_s
        if misses.any():
            raise InputError(f"{self.directory}: no cached frame within {tolerance_s} s of timestamps "
                             f"{query[misses].tolist()} in rows {start}..{end - 1}")
        return start + nearest

    def frames(self, key: str, rows: np.ndarray) -> np.ndarray:
        """Camera `key`'s frames at `rows`, (len(rows), channels, height, width) uint8 (a copy)."""
        if key not in self._arrays:
            if key not in self.cameras:
                raise InputError(f"{self.directory} holds no camera {key!r} (it has {sorted(self.cameras)})")
            self._arrays[key] = np.load(self.directory / self.cameras[key]["file"], mmap_mode="r")
        return self._arrays[key][rows]
