"""`tavis record`: run the scripted demonstrators at 60 Hz and store replayable raw episodes.

Seeds `seed_start, seed_start + 1, ...` are tried per task until `episodes_per_task` episodes are kept (successes
only, unless `keep_failures`), giving up on a task after `max_attempts_factor` x that many tries. Evaluation uses
seeds from 1000, so the default start (100000) keeps demonstrations off the evaluation scenes. Every finished
episode is written at once (file, then manifest), so an interrupted run resumes where it stopped; a damaged kept
file is reported and recorded again.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Iterator
from concurrent.futures import FIRST_COMPLETED, Future, wait
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from tqdm import tqdm

from lerobot_tavis import canonical, checks
from lerobot_tavis.cli_options import option
from lerobot_tavis.dataset_tools.raw import Manifest, ManifestEntry, RawEpisode, episode_filename, save_episode
from lerobot_tavis.envs.robots import DEFAULT_ROBOT, robot_names
from lerobot_tavis.envs.tasks.catalog import SUITES, expand_tasks, split_names
from lerobot_tavis.errors import FieldError, InputError
from lerobot_tavis.locking import exclusive_output
from lerobot_tavis.workers import BACKENDS, executor

RECORD_FPS = 60


@dataclass(frozen=True, kw_only=True)
class RecordConfig:
    """What `tavis record` records; also its command-line options. `tasks` (task or suite names) default to every
    task of `suite`, and hold the task names after construction."""

    robot: str = option(DEFAULT_ROBOT, choices=robot_names)
    suite: str = option(SUITES[0], choices=SUITES)
    tasks: tuple[str, ...] = option((), "task names (default: every task of --suite)")
    split: str = option("id", choices=split_names)
    episodes_per_task: int = option(160, "kept episodes per task (default 160)")
    keep_failures: bool = option(False, "keep failed episodes too (default: discard)")
    seed_start: int = option(100_000, "first seed (evaluation uses 1000..)")
    workers: int = option(1, "episodes at once (local backend: processes)")
    backend: str = option("local", "local processes, or a Ray cluster (RAY_ADDRESS; docs/scaling.md)",
                          choices=BACKENDS)
    out_dir: Path = option(help="raw directory; re-running resumes it", flag="--out")
    max_attempts_factor: float = option(3.0, command_line=False)

    def __post_init__(self):
        groups = expand_tasks(",".join(self.tasks or (self.suite,)), "tasks")
        object.__setattr__(self, "tasks", tuple(task for tasks in groups.values() for task in tasks))
        checks.integer("episodes_per_task", self.episodes_per_task, 1)
        checks.integer("workers", self.workers, 1)
        checks.integer("seed_start", self.seed_start, 0)
        checks.choice("backend", self.backend, BACKENDS)

    @property
    def max_attempts(self) -> int:
        return int(np.ceil(self.episodes_per_task * self.max_attempts_factor))


def record(cfg: RecordConfig, progress: bool = True) -> Manifest:
    """Record (or finish recording) `cfg.out_dir`; returns its manifest. One run at a time per directory
    (`locking`): another run recording into it is refused, naming it."""
    with exclusive_output(cfg.out_dir):
        return _record(cfg, progress)


def _record(cfg: RecordConfig, progress: bool) -> Manifest:
    from lerobot_tavis.envs.tasks.catalog import parse_split, task_info

    for task in cfg.tasks:
        if parse_split(cfg.split)[0] not in task_info(task).splits:
            raise FieldError("split", f"of task {task!r} must be one of {task_info(task).splits}, got {cfg.split!r}")
    manifest = open_manifest(cfg.out_dir, cfg.robot, cfg.split, cfg.seed_start)
    pending: set[Future] = set()
    in_flight = dict.fromkeys(cfg.tasks, 0)
    seeds = {task: _free_seeds(cfg, manifest, task) for task in cfg.tasks}
    total = cfg.episodes_per_task * len(cfg.tasks)
    with executor(cfg.workers, cfg.backend) as pool, tqdm(total=total, initial=sum(map(manifest.kept, cfg.tasks)),
                                              desc=f"record {cfg.robot}", unit="ep", disable=not progress) as bar:
        def refill() -> None:
            for task in cfg.tasks:
                while manifest.kept(task) + in_flight[task] < cfg.episodes_per_task and in_flight[task] < cfg.workers:
                    seed = next(seeds[task], None)
                    if seed is None:
                        break
                    in_flight[task] += 1
                    pending.add(pool.submit(record_episode, cfg.robot, task, cfg.split, seed, cfg.keep_failures))

        refill()
        while pending:
            done, _ = wait(pending, return_when=FIRST_COMPLETED)
            for future in done:
                pending.remove(future)
                entry, episode = future.result()
                in_flight[entry.task] -= 1
                store_episode(cfg.out_dir, manifest, entry, episode)
                bar.update(bool(entry.file))
            refill()
    for task, count in manifest.counts().items():
        if count["kept"] < cfg.episodes_per_task:
            print(f"tavis record: {task}: only {count['kept']} of {cfg.episodes_per_task} episodes kept after "
                  f"{cfg.max_attempts} attempts", file=sys.stderr)
    return manifest


def open_manifest(out_dir: Path, robot: str, split: str, seed_start: int, command: str = "tavis record") -> Manifest:
    """A new manifest, or the existing one of a compatible recording with its damaged episodes dropped."""
    if not (out_dir / "manifest.json").exists():
        out_dir.mkdir(parents=True, exist_ok=True)
        return Manifest(robot, split, RECORD_FPS, seed_start)
    manifest = Manifest.load(out_dir)
    found = (manifest.robot, manifest.split, manifest.seed_start)
    if found != (robot, split, seed_start):
        raise InputError(f"{out_dir} holds a recording of robot/split/seed_start {found}, not "
                         f"{(robot, split, seed_start)}: choose another --out")
    damaged = manifest.damaged(out_dir)
    for file, problem in damaged.items():
        print(f"{command}: {file}: {problem}; recording it again", file=sys.stderr)
    manifest.episodes = [e for e in manifest.episodes if e.file not in damaged]
    return manifest


def store_episode(out_dir: Path, manifest: Manifest, entry: ManifestEntry, episode: RawEpisode | None) -> None:
    """Write a kept episode's file, then the manifest that lists it (or the discarded seed)."""
    if episode is not None:
        entry.file = episode_filename(entry.task, entry.seed)
        entry.sha256 = save_episode(out_dir / entry.file, episode)
    manifest.add(entry)
    manifest.save(out_dir)


@dataclass
class StateLog:
    """The simulator state after the reset and after every step: what a raw episode checks a replay against."""

    qpos: list = field(default_factory=list)
    qvel: list = field(default_factory=list)
    task_state: list = field(default_factory=list)

    def snapshot(self, env) -> None:
        self.qpos.append(env.data.qpos.copy())
        self.qvel.append(env.data.qvel.copy())
        self.task_state.append(env.task_object.task_state().copy())

    def episode(self, env, seed: int, success: bool, actions: np.ndarray) -> RawEpisode:
        """The raw episode of `env` (a TavisEnv stepped at RECORD_FPS) with these applied actions."""
        return RawEpisode(env.robot_name, env.task, env.split, seed, env.task_description, RECORD_FPS, success,
                          np.asarray(actions, dtype=np.float64).reshape(-1, canonical.ACTION_DIM), np.array(self.qpos),
                          np.array(self.qvel), np.array(self.task_state))


def _free_seeds(cfg: RecordConfig, manifest: Manifest, task: str) -> Iterator[int]:
    """Seeds not tried yet, within the task's attempt budget (re-recording a damaged file reuses its seed)."""
    tried = manifest.tried_seeds(task)
    for seed in range(cfg.seed_start, cfg.seed_start + cfg.max_attempts):
        if seed not in tried:
            yield seed


def record_episode(robot: str, task: str, split: str, seed: int,
                   keep_failures: bool) -> tuple[ManifestEntry, RawEpisode | None]:
    """Play one demonstrator episode at 60 Hz; returns its manifest entry and, if kept, the episode (the calling
    process writes it). Runs in a worker."""
    from lerobot_tavis.experts.rollout import run_episode

    env = _env(robot, task, split)
    states = StateLog()
    result = run_episode(env, seed, on_step=lambda: states.snapshot(env))
    entry = ManifestEntry(task, seed, result.success, result.length_steps)
    if not (result.success or keep_failures):
        return entry, None
    return entry, states.episode(env, seed, result.success, result.actions)


_ENVS: dict[tuple[str, str, str], object] = {}


def _env(robot: str, task: str, split: str):
    """One env per (robot, task, split) per process, rendering nothing (the demonstrators read the state)."""
    key = (robot, task, split)
    if key not in _ENVS:
        os.environ.setdefault("MUJOCO_GL", "egl")
        from lerobot_tavis.envs.env import TavisEnv

        _ENVS[key] = TavisEnv(task, robot, split=split, fps=RECORD_FPS, cameras=())
    return _ENVS[key]
