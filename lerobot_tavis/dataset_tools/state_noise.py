"""`tavis noise-state`: a copy of a dataset whose arm poses in `observation.state` carry fixed Gaussian noise.

A training experiment: a policy that copies its own pose from the state gains less from it when the pose it reads
is off by a few centimetres. lerobot-train has no hook to perturb its inputs, so the noise is written into a copy
of the dataset, drawn once per frame. Per frame, in the canonical hip frame (layout: `lerobot_tavis.canonical`):

- each arm's end-effector position gets N(0, position_m^2) added per axis (metres);
- each arm's quaternion (w, x, y, z) is turned by a rotation whose rotation vector, expressed in the canonical
  frame, has N(0, rotation_deg^2) components (degrees; the rotation is applied in radians, left-multiplied:
  q' = r * q), then renormalised and sign-flipped to w >= 0, the convention of the measured state;
- the head angles, the grippers and every other column (`action` included) stay bit for bit as they were.

The frame whose `index` is i gets row i of the noise drawn from `np.random.default_rng(seed)` (the positions of all
frames, then their rotations), so the copy depends on the source and the seed alone. Data files are rewritten with
the same names, schema and row groups; videos are hard-linked (copied where the filesystem cannot link; nothing
rewrites them in place); every other file is copied. The `observation.state` statistics are computed again as
LeRobot computes them (per episode in `meta/episodes`, aggregated over episodes in `meta/stats.json`), and the noise
settings with the measured shifts go to `meta/state_noise.json`. The copy is built beside `out_root` and renamed
into place when complete.
"""

from __future__ import annotations

import json
import math
import os
import shutil
from collections import defaultdict
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from lerobot_tavis import canonical
from lerobot_tavis.dataset_tools.features import STATE_KEY
from lerobot_tavis.dataset_tools.frames import INFO, check_files, dataset_info
from lerobot_tavis.envs.transforms import quat_angles_rad
from lerobot_tavis.errors import FieldError, InputError, PathExistsError, PathNotFoundError
from lerobot_tavis.readers import get_integer, read_parquet
from lerobot_tavis.staging import staged_directory

NOISE_RECORD = "meta/state_noise.json"
STATS_PREFIX = f"stats/{STATE_KEY}/"  # per-episode statistics columns in meta/episodes/*.parquet


@dataclass(frozen=True)
class StateNoiseSummary:
    """What a noisy copy holds: its settings and the shifts measured between the source's states and its own."""

    source_root: str
    position_m: float  # standard deviation of the position noise per axis, m
    rotation_deg: float  # standard deviation of each rotation-vector component, degrees
    seed: int
    frames: int  # frames in the dataset
    frames_changed: int  # frames whose state differs from the source's
    mean_position_shift_mm: float  # mean distance between a source and a copied hand position, over hands and frames
    mean_rotation_deg: float  # mean angle between a source and a copied hand orientation, over hands and frames
    quaternion_sign: str = "w >= 0"


def write_state_noise_copy(source_root: str | Path, out_root: str | Path, position_m: float, rotation_deg: float,
                           seed: int = 0) -> StateNoiseSummary:
    """Copy the LeRobotDataset v3.0 at `source_root` to `out_root` (which must not exist) with each frame's arm
    positions moved by N(0, position_m^2) per axis (m) and its arm orientations turned by a rotation vector of
    N(0, rotation_deg^2) per component (degrees), in the canonical hip frame; see the module's docstring.

    Returns the settings and the measured shifts (also written to `meta/state_noise.json`). Raises FieldError for a
    bad noise scale, seed or out_root, PathNotFoundError for a missing source, PathExistsError for an existing
    out_root, InputError for a source that is not a LeRobotDataset v3.0 with a 19-D float32 observation.state (or
    is a noisy copy already, or has a damaged metadata or data file, which it names); nothing is written then, nor
    when the copy fails half-way."""
    position_m, rotation_deg = _noise_scale("position_m", position_m), _noise_scale("rotation_deg", rotation_deg)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise FieldError("seed", f"must be an integer >= 0, got {seed!r}")
    source, out = Path(source_root).absolute(), Path(out_root).absolute()
    frames = _check_source(source)
    if out.exists():
        raise PathExistsError(f"out_root {out} already exists; remove it or name another")
    if out.is_relative_to(source):
        raise FieldError("out_root", f"must lie outside source_root {source}, got {out}")
    rng = np.random.default_rng(int(seed))
    shift_m = rng.normal(0.0, position_m, (frames, len(canonical.ARMS), 3))
    rotvec_rad = rng.normal(0.0, math.radians(rotation_deg), (frames, len(canonical.ARMS), 3))
    with staged_directory(out) as staging:
        _copy_unchanged(source, staging)
        originals, noisy = _rewrite_data_files(source, staging, shift_m, rotvec_rad)
        _rewrite_state_stats(source, staging, noisy)
        summary = _summary(source, position_m, rotation_deg, int(seed), originals, noisy)
        (staging / NOISE_RECORD).write_text(json.dumps(asdict(summary), indent=2) + "\n")
    return summary


def _perturb_states(states: np.ndarray, shift_m: np.ndarray, rotvec_rad: np.ndarray) -> np.ndarray:
    """States (N, 19) with each arm's position moved by `shift_m` (N, 2, 3; m) and its quaternion turned by the
    rotation vector `rotvec_rad` (N, 2, 3; rad; canonical frame), renormalised with w >= 0; the arms in
    `canonical.ARMS` order. Every other entry is returned unchanged, in the states' dtype."""
    out = states.copy()
    for k, arm in enumerate(canonical.ARMS):
        out[:, arm.position] = states[:, arm.position] + shift_m[:, k]
        turned = _quat_multiply(_quat_from_rotvec(rotvec_rad[:, k]), states[:, arm.quaternion].astype(np.float64))
        turned /= np.linalg.norm(turned, axis=1, keepdims=True)
        out[:, arm.quaternion] = np.where(turned[:, :1] < 0, -turned, turned)
    return out


def _noise_scale(field: str, value) -> float:
    """`value` as a float, refused unless it is a finite number >= 0 (a standard deviation)."""
    number = isinstance(value, (int, float, np.number)) and not isinstance(value, bool)
    if not (number and math.isfinite(value) and value >= 0):
        raise FieldError(field, f"must be a finite number >= 0, got {value!r}")
    return float(value)


def _check_source(source: Path) -> int:
    """The number of frames of the dataset at `source`, refused unless it is a LeRobotDataset v3.0 with a canonical
    19-D float32 `observation.state`, whose metadata and data files all read whole, and not itself a noisy copy."""
    if not source.is_dir():
        raise PathNotFoundError(f"source_root {source} is not a directory")
    info = dataset_info(source)
    check_files(source)
    version, features = info["codebase_version"], info["features"]
    frames = get_integer(info, "total_frames", source / INFO)
    if version != "v3.0":
        raise InputError(f"source_root {source} is a LeRobotDataset {version}, not v3.0")
    if frames < 1:
        raise InputError(f"source_root {source} holds no frames")
    state = features.get(STATE_KEY) or {}
    if state.get("dtype") != "float32" or list(state.get("shape", ())) != [canonical.ACTION_DIM]:
        raise InputError(f"source_root {source}: {STATE_KEY} must be float32 of shape ({canonical.ACTION_DIM},) "
                         f"(the canonical state), got {state or 'no such feature'}")
    if (source / NOISE_RECORD).exists():
        raise InputError(f"source_root {source} is already a noisy copy ({NOISE_RECORD}); noise its source instead")
    return frames


def _copy_unchanged(source: Path, staging: Path) -> None:
    """Every file of `source` but its data files into `staging`: videos hard-linked where possible, the rest copied."""
    for path in sorted(source.rglob("*")):
        relative = path.relative_to(source)
        if path.is_dir() or (relative.parts[0] == "data" and path.suffix == ".parquet"):
            continue
        target = staging / relative
        target.parent.mkdir(parents=True, exist_ok=True)
        if relative.parts[0] == "videos":
            _link_or_copy(path, target)
        else:
            shutil.copy2(path, target)


def _link_or_copy(path: Path, target: Path) -> None:
    try:
        os.link(path, target)
    except OSError:  # another filesystem, or one without hard links
        shutil.copy2(path, target)


def _rewrite_data_files(source: Path, staging: Path, shift_m: np.ndarray,
                        rotvec_rad: np.ndarray) -> tuple[dict[int, np.ndarray], dict[int, np.ndarray]]:
    """Write each data file of `source` into `staging` with its states perturbed by the noise rows of its frames'
    `index`; returns the source's and the new states per episode index, in frame order."""
    import pyarrow as pa
    from lerobot.datasets.io_utils import write_table_one_row_group_per_episode

    originals, noisy = defaultdict(list), defaultdict(list)
    for path in sorted((source / "data").rglob("*.parquet")):
        table = read_parquet(path)
        column = table.schema.get_field_index(STATE_KEY)
        states = table.column(column).combine_chunks().flatten().to_numpy().reshape(-1, canonical.ACTION_DIM)
        index = table.column("index").to_numpy()
        if index.size and (index.min() < 0 or index.max() >= len(shift_m)):
            raise InputError(f"{path}: frame index {index.min()}..{index.max()} outside the 0..{len(shift_m) - 1} "
                             "of meta/info.json's total_frames")
        new = _perturb_states(states, shift_m[index], rotvec_rad[index])
        values = pa.FixedSizeListArray.from_arrays(pa.array(new.ravel()), canonical.ACTION_DIM)
        table = table.set_column(column, table.schema.field(column), values.cast(table.schema.field(column).type))
        target = staging / path.relative_to(source)
        target.parent.mkdir(parents=True, exist_ok=True)
        write_table_one_row_group_per_episode(table, target)
        episodes = table.column("episode_index").to_numpy()
        for episode in np.unique(episodes):
            originals[int(episode)].append(states[episodes == episode])
            noisy[int(episode)].append(new[episodes == episode])
    return ({episode: np.concatenate(parts) for episode, parts in originals.items()},
            {episode: np.concatenate(parts) for episode, parts in noisy.items()})


def _rewrite_state_stats(source: Path, staging: Path, noisy: dict[int, np.ndarray]) -> None:
    """The `observation.state` statistics of `staging` computed from its new states as LeRobot computes them: per
    episode (the `stats/observation.state/*` columns of meta/episodes) and aggregated (meta/stats.json)."""
    import pyarrow as pa
    import pyarrow.parquet as pq
    from lerobot.datasets.compute_stats import aggregate_stats, get_feature_stats
    from lerobot.datasets.io_utils import load_stats, write_stats

    per_episode = {episode: get_feature_stats(states, axis=0, keepdims=False) for episode, states in noisy.items()}
    for path in sorted((staging / "meta/episodes").rglob("*.parquet")):
        table = read_parquet(path)
        episodes = table.column("episode_index").to_pylist()
        for name in [name for name in table.column_names if name.startswith(STATS_PREFIX)]:
            key, field = name[len(STATS_PREFIX):], table.schema.field(name)
            values = pa.array([per_episode[episode][key].tolist() for episode in episodes], type=field.type)
            table = table.set_column(table.schema.get_field_index(name), field, values)
        pq.write_table(table, path, compression="snappy")
    stats = load_stats(source) or {}
    stats[STATE_KEY] = aggregate_stats([{STATE_KEY: per_episode[episode]} for episode in sorted(per_episode)])[
        STATE_KEY]
    write_stats(stats, staging)


def _summary(source: Path, position_m: float, rotation_deg: float, seed: int, originals: dict[int, np.ndarray],
             noisy: dict[int, np.ndarray]) -> StateNoiseSummary:
    """The settings and the shifts measured between the source's states and the copy's."""
    before, after = (np.concatenate([states[e] for e in sorted(states)]).astype(np.float64)
                     for states in (originals, noisy))
    shifts_m = [np.linalg.norm(after[:, arm.position] - before[:, arm.position], axis=1) for arm in canonical.ARMS]
    angles_deg = [np.degrees(quat_angles_rad(before[:, arm.quaternion], after[:, arm.quaternion]))
                  for arm in canonical.ARMS]
    return StateNoiseSummary(str(source), position_m, rotation_deg, seed, len(before),
                             int(np.any(after != before, axis=1).sum()), float(1000 * np.mean(shifts_m)),
                             float(np.mean(angles_deg)))


def _quat_from_rotvec(rotvec: np.ndarray) -> np.ndarray:
    """Unit quaternions (N, 4; w, x, y, z) of rotation vectors (N, 3; rad)."""
    angle = np.linalg.norm(rotvec, axis=1, keepdims=True)
    return np.concatenate([np.cos(angle / 2), 0.5 * np.sinc(angle / (2 * np.pi)) * rotvec], axis=1)


def _quat_multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton products a * b of quaternions (N, 4; w, x, y, z): rotate by b, then by a."""
    aw, av, bw, bv = a[:, :1], a[:, 1:], b[:, :1], b[:, 1:]
    w = aw * bw - np.sum(av * bv, axis=1, keepdims=True)
    return np.concatenate([w, aw * bv + bw * av + np.cross(av, bv)], axis=1)
