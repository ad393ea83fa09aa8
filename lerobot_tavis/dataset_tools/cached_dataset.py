"""LeRobot's dataset with its video frames read from the frame cache (`frame_cache`), and the switch that makes
lerobot-train use it: `TAVIS_FRAME_CACHE=1` in lerobot-train's environment (docs/training.md).

Only the lookups change. LeRobot's reader still chooses each sample's rows, delta timestamps, padding flags and image
transforms; where it would decode a camera's frames at a list of timestamps, this reader takes the cache's rows at
those timestamps (the nearest within `tolerance_s`, as LeRobot's decoders choose), and where it would query its
Hugging Face dataset for a feature's rows (the state, the action chunk, the frames' timestamps), this reader indexes
that feature's column, read once per process: the same tensors without a query per feature and sample.

The frames come back as LeRobot's decoders return them: uint8 where the dataset is asked for uint8 (`return_uint8`,
as lerobot-train asks), else float32 in [0, 1] (`x / 255` of the same uint8 frame). lerobot-train converts uint8
camera batches to float itself, after Accelerate has moved the batch to the training device, so uint8 frames travel
from the loader workers to the GPU at one byte per value. `TAVIS_FRAME_CACHE=float32` makes the loader workers
convert instead (four times the bytes through the worker queue, pinned memory and the copy to the GPU): the
measurement's alternative (benchmarks/train_throughput.py `scale`).
"""

from __future__ import annotations

import logging
import os
import sys

import torch
from lerobot.datasets.dataset_reader import DatasetReader
from lerobot.datasets.lerobot_dataset import LeRobotDataset

from lerobot_tavis.dataset_tools.frame_cache import FrameCache, StaleFrameCacheError

SWITCH = "TAVIS_FRAME_CACHE"
SWITCH_VALUES = {"1": "read video frames from the frame cache",
                 "float32": "the same, converted to float32 in the loader workers",
                 "0": "decode them"}


class CachedFrameReader(DatasetReader):
    """LeRobot's DatasetReader whose video frames come from a FrameCache."""

    def __init__(self, frame_cache: FrameCache, **reader_arguments):
        super().__init__(**reader_arguments)
        self.frame_cache = frame_cache
        self._columns: dict[str, torch.Tensor] = {}
        self._episode_rows: dict[int, tuple[int, int]] = {}

    def __getstate__(self) -> dict:
        return {**self.__dict__, "_columns": {}, "_episode_rows": {}}  # each loader worker reads its own once

    def _column(self, key: str) -> torch.Tensor:
        """Feature `key` of every row of the Hugging Face dataset, stacked in row order: each row as LeRobot's
        torch transform gives it, read once per process."""
        if key not in self._columns:
            self._columns[key] = torch.stack(self.hf_dataset.select_columns([key])[:][key])
        return self._columns[key]

    def _relative_rows(self, absolute_indices: list[int]) -> list[int]:
        """The Hugging Face dataset's rows of the dataset's absolute indices (they differ in an episode subset)."""
        if self._absolute_to_relative_idx is None:
            return absolute_indices
        return [self._absolute_to_relative_idx[index] for index in absolute_indices]

    def _query_hf_dataset(self, query_indices: dict[str, list[int]]) -> dict[str, torch.Tensor]:
        """Per non-video key, its rows at the absolute indices, stacked, as LeRobot's reader returns them; from the
        in-memory columns instead of a Hugging Face dataset query per key and sample, which costs a loader worker
        several times the cached frames' read."""
        return {key: self._column(key)[self._relative_rows(indices)] for key, indices in query_indices.items()
                if key not in self._meta.video_keys}

    def _get_query_timestamps(self, current_ts: float, query_indices: dict[str, list[int]] | None = None
                              ) -> dict[str, list[float]]:
        """Per video key, the timestamps (s) of its query rows (the current one alone where it has no delta
        timestamps), as LeRobot's reader computes them, from the in-memory timestamp column."""
        if query_indices is None:
            return {key: [current_ts] for key in self._meta.video_keys}
        timestamps = self._column("timestamp")
        return {key: timestamps[self._relative_rows(query_indices[key])].tolist() if key in query_indices
                else [current_ts] for key in self._meta.video_keys}

    def _query_videos(self, query_timestamps: dict[str, list[float]], ep_idx: int) -> dict[str, torch.Tensor]:
        """Per camera key, the frames at the timestamps (s, within episode `ep_idx`): (channels, height, width) for
        one timestamp, (timestamps, channels, height, width) for several; uint8 with `return_uint8`, else float32
        in [0, 1], as LeRobot's."""
        if ep_idx not in self._episode_rows:
            episode = self._meta.episodes[ep_idx]
            self._episode_rows[ep_idx] = int(episode["dataset_from_index"]), int(episode["dataset_to_index"])
        start, end = self._episode_rows[ep_idx]
        frames = {}
        for key, timestamps in query_timestamps.items():
            rows = self.frame_cache.rows(start, end, timestamps, self._tolerance_s)
            frames[key] = torch.from_numpy(self.frame_cache.frames(key, rows)).squeeze(0)
            if not self._return_uint8:
                frames[key] = frames[key].to(torch.float32) / 255.0
        return frames


class FrameCachedDataset(LeRobotDataset):
    """A LeRobotDataset (same arguments) reading its video frames from the frame cache beside its root, in the type
    `return_uint8` asks (module docstring); refuses a missing or stale cache (StaleFrameCacheError)."""

    def __init__(self, repo_id: str, root=None, **dataset_arguments):
        super().__init__(repo_id, root=root, **dataset_arguments)
        cache = FrameCache.open(self.root)
        if cache.video_backend != self._video_backend:
            logging.warning(f"{cache.directory} was decoded with {cache.video_backend}, this dataset is read with "
                            f"{self._video_backend}: the frames are {cache.video_backend}'s")
        reader = CachedFrameReader(cache, meta=self.meta, root=self.root, episodes=self.episodes,
                                   tolerance_s=self.tolerance_s, video_backend=self._video_backend,
                                   delta_timestamps=self.delta_timestamps, image_transforms=self.image_transforms,
                                   return_uint8=self._return_uint8, depth_output_unit=self._depth_output_unit)
        reader.hf_dataset = self.reader.hf_dataset
        reader._build_index_mapping()
        self.reader = reader
        logging.info(f"{self.root}: video frames from {cache.directory}")


class TrainingFrameCachedDataset(FrameCachedDataset):
    """FrameCachedDataset as lerobot-train's dataset: a missing or stale cache ends the run with one line."""

    def __init__(self, *args, **kwargs):
        try:
            super().__init__(*args, **kwargs)
        except StaleFrameCacheError as error:
            raise SystemExit(f"lerobot-train: error: {error}") from None


class TrainingFloatFrameCachedDataset(TrainingFrameCachedDataset):
    """TrainingFrameCachedDataset whose loader workers convert the frames to float32 in [0, 1], whatever
    lerobot-train asks (`TAVIS_FRAME_CACHE=float32`)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **{**kwargs, "return_uint8": False})


def frame_cache_mode() -> str | None:
    """What TAVIS_FRAME_CACHE asks for: "1" (frames from the cache, as lerobot-train asks for them: uint8),
    "float32" (from the cache, converted in the loader workers), None (0, empty or unset: decode); anything else
    stops the process with one line (a misspelt switch must not train without the cache unnoticed)."""
    value = os.environ.get(SWITCH, "0")
    if value not in (*SWITCH_VALUES, ""):
        choices = ", ".join(f"{choice} ({meaning})" for choice, meaning in SWITCH_VALUES.items())
        sys.exit(f"{SWITCH}={value!r}: set it to {choices}")
    return None if value in ("", "0") else value


def use_frame_cache(mode: str) -> None:
    """Make lerobot-train read video frames from the frame cache in `mode` (`frame_cache_mode`): its datasets
    (training, and the held-out split with `--dataset.eval_split`) are built by `lerobot.datasets.factory`, which
    this points at TrainingFrameCachedDataset (or its float32 variant)."""
    import lerobot.datasets.factory as factory

    factory.LeRobotDataset = TrainingFloatFrameCachedDataset if mode == "float32" else TrainingFrameCachedDataset
