"""Raw demonstrations: one compressed `.npz` per episode (no pickle) and a `manifest.json` with checksums.

A raw episode holds what replays it exactly: robot, task, split, seed and prompt, the actions the env applied at
the recording rate (60 Hz), and the simulator state after the reset and after every step (`qpos`, `qvel`, and the
task state that lives outside the simulator, such as the light colour), to check a replay against. No images.
"""

from __future__ import annotations

import hashlib
import json
import re
import zipfile
from dataclasses import asdict, dataclass, field
from pathlib import Path, PurePosixPath, PureWindowsPath

import numpy as np

from lerobot_tavis import canonical
from lerobot_tavis.atomic import atomic_path, write_text
from lerobot_tavis.envs.robots import robot_info
from lerobot_tavis.envs.tasks.catalog import parse_split, task_info
from lerobot_tavis.errors import InputError, PathNotFoundError, TavisError
from lerobot_tavis.readers import KINDS, checked, get, get_integer, read_json

FORMAT = "tavis-raw"
FORMAT_VERSION = 1
MANIFEST_NAME = "manifest.json"
ARRAYS = ("actions", "qpos", "qvel", "task_state")
# The fields of a raw file's metadata (besides format and version) and what each must be (`readers.KINDS`).
METADATA_KINDS = {"robot": "str", "task": "str", "split": "str", "seed": "int", "prompt": "str", "fps": "int",
                  "success": "bool"}


class RawEpisodeError(TavisError, ValueError):
    """A raw episode file or the manifest is missing, corrupt, or does not match the recording."""


@dataclass
class RawEpisode:
    robot: str
    task: str
    split: str
    seed: int
    prompt: str
    fps: int
    success: bool
    actions: np.ndarray  # (T, 19) canonical actions as applied, float64
    qpos: np.ndarray  # (T + 1, nq): after the reset, then after each step
    qvel: np.ndarray  # (T + 1, nv)
    task_state: np.ndarray  # (T + 1, k)

    @property
    def n_steps(self) -> int:
        return len(self.actions)

    def metadata(self) -> dict:
        return {"format": FORMAT, "version": FORMAT_VERSION, "robot": self.robot, "task": self.task,
                "split": self.split, "seed": self.seed, "prompt": self.prompt, "fps": self.fps,
                "success": self.success}


def episode_filename(task: str, seed: int) -> str:
    return f"{task}/seed_{seed:08d}.npz"


def save_episode(path: str | Path, episode: RawEpisode) -> str:
    """Write `episode` to `path` atomically; returns the file's SHA-256."""
    with atomic_path(path) as partial, open(partial, "wb") as file:
        np.savez_compressed(file, metadata=np.array(json.dumps(episode.metadata())),
                            **{name: getattr(episode, name) for name in ARRAYS})
    return file_sha256(path)


def load_episode(path: str | Path, sha256: str | None = None) -> RawEpisode:
    """Read a raw episode, checking its checksum when given; any damage raises RawEpisodeError naming the file."""
    path = Path(path)
    if not path.is_file():
        raise RawEpisodeError(f"{path}: raw episode file is missing")
    if sha256 is not None and file_sha256(path) != sha256:
        raise RawEpisodeError(f"{path}: checksum does not match the manifest (the file is corrupt or was changed)")
    try:
        return _read_episode(path)
    except RawEpisodeError as error:
        raise RawEpisodeError(f"{path}: {error}") from None


def _read_episode(path: Path) -> RawEpisode:
    """The episode in `path`; RawEpisodeError saying what is wrong with it (without the path)."""
    try:
        with np.load(path, allow_pickle=False) as archive:
            metadata = json.loads(str(archive["metadata"]))
            arrays = {name: np.array(archive[name]) for name in ARRAYS}
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as error:
        raise RawEpisodeError(f"not a readable raw episode ({type(error).__name__}: {error})") from None
    if not isinstance(metadata, dict) or metadata.get("format") != FORMAT or metadata.get("version") != FORMAT_VERSION:
        raise RawEpisodeError(f"not a {FORMAT} v{FORMAT_VERSION} file")
    fields = {}
    for name, kind in METADATA_KINDS.items():
        value = metadata.get(name)
        if not KINDS[kind][1](value):
            raise RawEpisodeError(f"its metadata's {name} must be {KINDS[kind][0]}, got {value!r}")
        fields[name] = value
    episode = RawEpisode(**fields, **arrays)
    _check_arrays(episode)
    return episode


def _check_arrays(episode: RawEpisode) -> None:
    """Each array holds finite numbers, `actions` (T, 19) with T > 0, the states T + 1 rows."""
    for name in ARRAYS:
        array = getattr(episode, name)
        if not np.issubdtype(array.dtype, np.number):
            raise RawEpisodeError(f"{name} must hold numbers, got {array.dtype}")
        bad = np.argwhere(~np.isfinite(array))
        if len(bad):
            raise RawEpisodeError(f"{name} holds a non-finite value ({array[tuple(bad[0])]}) at row {bad[0][0]}")
    steps = episode.n_steps
    if episode.actions.ndim != 2 or episode.actions.shape[1] != canonical.ACTION_DIM or steps == 0:
        raise RawEpisodeError(f"actions must be (T, {canonical.ACTION_DIM}) with T > 0, got {episode.actions.shape}")
    for name in ("qpos", "qvel", "task_state"):
        rows = len(getattr(episode, name))
        if rows != steps + 1:
            raise RawEpisodeError(f"{name} must have {steps + 1} rows (T + 1), got {rows}")


def _content_sha256(document: dict) -> str:
    return hashlib.sha256(json.dumps(document, sort_keys=True).encode()).hexdigest()


def file_sha256(path: str | Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as file:
        for block in iter(lambda: file.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


@dataclass
class ManifestEntry:
    task: str
    seed: int
    success: bool
    n_steps: int
    file: str | None = None  # relative to the raw directory; None for a discarded episode
    sha256: str | None = None


@dataclass
class Manifest:
    """What a raw directory holds: kept episodes with checksums, and the seeds tried and discarded."""

    robot: str
    split: str
    fps: int
    seed_start: int
    episodes: list[ManifestEntry] = field(default_factory=list)
    discarded: list[ManifestEntry] = field(default_factory=list)

    def add(self, entry: ManifestEntry) -> None:
        (self.episodes if entry.file else self.discarded).append(entry)

    def tried_seeds(self, task: str) -> set[int]:
        return {e.seed for e in self.episodes + self.discarded if e.task == task}

    def kept(self, task: str) -> int:
        return sum(e.task == task for e in self.episodes)

    def counts(self) -> dict[str, dict[str, int]]:
        tasks = dict.fromkeys(e.task for e in self.episodes + self.discarded)
        return {task: {"kept": self.kept(task), "discarded": sum(e.task == task for e in self.discarded)}
                for task in tasks}

    def save(self, raw_dir: str | Path) -> None:
        """Write the manifest atomically, with a checksum of its own content (hand edits are detected on load)."""
        document = {"format": FORMAT, "version": FORMAT_VERSION, "robot": self.robot, "split": self.split,
                    "fps": self.fps, "seed_start": self.seed_start, "counts": self.counts(),
                    "episodes": [asdict(e) for e in self.episodes],
                    "discarded": [asdict(e) for e in self.discarded]}
        document["sha256"] = _content_sha256(document)
        write_text(Path(raw_dir) / MANIFEST_NAME, json.dumps(document, indent=1) + "\n")

    @classmethod
    def load(cls, raw_dir: str | Path) -> Manifest:
        """The manifest of the `tavis record` output `raw_dir`; RawEpisodeError naming the field when it was edited
        by hand or holds what no recording writes (e.g. an episode file outside `raw_dir`)."""
        path = Path(raw_dir) / MANIFEST_NAME
        if not path.is_file():
            raise PathNotFoundError(f"{path} not found: is {raw_dir} a directory written by `tavis record`?")
        document = read_json(path)
        if not (isinstance(document, dict) and document.get("format") == FORMAT
                and document.get("version") == FORMAT_VERSION):
            raise RawEpisodeError(f"{path}: not a {FORMAT} v{FORMAT_VERSION} manifest")
        recorded = document.pop("sha256", None)
        if recorded is not None and recorded != _content_sha256(document):
            raise RawEpisodeError(f"{path}: changed since `tavis record` wrote it (its checksum no longer matches "
                                  "its content); restore it or record again")
        try:
            robot = checked(robot_info, get(document, "robot", "str", path), path, "robot").name
            split = get(document, "split", "str", path)
            checked(parse_split, split, path, "split")
            manifest = cls(robot, split, get_integer(document, "fps", path, minimum=1),
                           get_integer(document, "seed_start", path))
            for group, kept in (("episodes", True), ("discarded", False)):
                for i, item in enumerate(get(document, group, "list", path)):
                    manifest.add(_entry(item, path, f"{group}[{i}].", kept))
        except InputError as error:
            raise RawEpisodeError(str(error)) from None
        return manifest

    def damaged(self, raw_dir: str | Path) -> dict[str, str]:
        """Kept episodes that cannot be trusted, {file: problem}: a missing or unreadable file, a failed checksum, a
        second entry for the same file or (task, seed), or a field where the manifest and the file's own record
        disagree."""
        problems, seen = {}, set()
        for entry in self.episodes:
            path = Path(raw_dir) / entry.file
            if entry.file in seen or (entry.task, entry.seed) in seen:
                problems[entry.file] = f"listed twice (task {entry.task}, seed {entry.seed})"
            elif not path.is_file():
                problems[entry.file] = "missing"
            elif file_sha256(path) != entry.sha256:
                problems[entry.file] = "checksum mismatch"
            else:
                try:
                    problems |= self._disagreement(_read_episode(path), entry)
                except RawEpisodeError as error:
                    problems[entry.file] = str(error)
            seen |= {entry.file, (entry.task, entry.seed)}
        return problems

    def _disagreement(self, episode: RawEpisode, entry: ManifestEntry) -> dict[str, str]:
        claimed = {"robot": self.robot, "split": self.split, "fps": self.fps, "task": entry.task, "seed": entry.seed,
                   "success": entry.success, "n_steps": entry.n_steps}
        for field_name, value in claimed.items():
            found = getattr(episode, field_name)
            if found != value:
                return {entry.file: f"{field_name}: the manifest says {value!r}, the file {found!r}"}
        return {}


def _entry(item, path: Path, where: str, kept: bool) -> ManifestEntry:
    """One manifest entry (`where`: its place, e.g. "episodes[3]."); a kept one names its file, a path inside the
    raw directory, and that file's SHA-256; a discarded one neither."""
    if not isinstance(item, dict):
        raise InputError(f"{path}: {where.rstrip('.')} must be an object, got {item!r}")
    task = checked(task_info, get(item, "task", "str", path, where), path, f"{where}task").name
    seed = get_integer(item, "seed", path, where)
    n_steps = get_integer(item, "n_steps", path, where, minimum=1 if kept else 0)
    success = get(item, "success", "bool", path, where)
    file = get(item, "file", "str", path, where, optional=not kept)
    sha256 = get(item, "sha256", "str", path, where, optional=not kept)
    if not kept and (file, sha256) != (None, None):
        raise InputError(f"{path}: {where}file and sha256 must be null for a discarded seed")
    if kept:
        relative = PurePosixPath(file)
        if not file or relative.is_absolute() or PureWindowsPath(file).is_absolute() or ".." in relative.parts:
            raise InputError(f"{path}: {where}file must be a path inside the raw directory, got {file!r}")
        if not re.fullmatch(r"[0-9a-f]{64}", sha256):
            raise InputError(f"{path}: {where}sha256 must be 64 hexadecimal digits, got {sha256!r}")
    return ManifestEntry(task, seed, success, n_steps, file, sha256)
