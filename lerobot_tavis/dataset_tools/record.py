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
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from lerobot_tavis import checks
from lerobot_tavis.dataset_tools.raw import Manifest, ManifestEntry, RawEpisode, episode_filename, save_episode
from lerobot_tavis.dataset_tools.workers import BACKENDS, executor

RECORD_FPS = 60


@dataclass(frozen=True)
class RecordConfig:
    out_dir: Path
    robot: str
    tasks: tuple[str, ...]
    episodes_per_task: int
    split: str = "id"
    keep_failures: bool = False
    seed_start: int = 100_000
    workers: int = 1  # episodes in flight at once (local backend: worker processes)
    max_attempts_factor: float = 3.0
    backend: str = "local"  # or "ray" (dataset_tools.workers)

    def __post_init__(self):
        checks.integer("episodes_per_task", self.episodes_per_task, 1)
        checks.integer("workers", self.workers, 1)
        checks.integer("seed_start", self.seed_start, 0)
        checks.choice("backend", self.backend, BACKENDS)
        if not self.tasks:
            raise ValueError("tasks must name at least one task")

    @property
    def max_attempts(self) -> int:
        return int(np.ceil(self.episodes_per_task * self.max_attempts_factor))


def record(cfg: RecordConfig, progress: bool = True) -> Manifest:
    """Record (or finish recording) `cfg.out_dir`; returns its manifest."""
    from lerobot_tavis.envs.tasks.catalog import task_info

    for task in cfg.tasks:
        if cfg.split not in task_info(task).splits:
            raise ValueError(f"split of task {task!r} must be one of {task_info(task).splits}, got {cfg.split!r}")
    manifest = _open_manifest(cfg)
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
                if episode is not None:
                    entry.file = episode_filename(entry.task, entry.seed)
                    entry.sha256 = save_episode(cfg.out_dir / entry.file, episode)
                manifest.add(entry)
                manifest.save(cfg.out_dir)
                bar.update(bool(entry.file))
            refill()
    for task, count in manifest.counts().items():
        if count["kept"] < cfg.episodes_per_task:
            print(f"tavis record: {task}: only {count['kept']} of {cfg.episodes_per_task} episodes kept after "
                  f"{cfg.max_attempts} attempts", file=sys.stderr)
    return manifest


def _open_manifest(cfg: RecordConfig) -> Manifest:
    """A new manifest, or the existing one of a compatible recording with its damaged episodes dropped."""
    if not (cfg.out_dir / "manifest.json").exists():
        cfg.out_dir.mkdir(parents=True, exist_ok=True)
        return Manifest(cfg.robot, cfg.split, RECORD_FPS, cfg.seed_start)
    manifest = Manifest.load(cfg.out_dir)
    found = (manifest.robot, manifest.split, manifest.seed_start)
    if found != (cfg.robot, cfg.split, cfg.seed_start):
        raise ValueError(f"{cfg.out_dir} holds a recording of robot/split/seed_start {found}, not "
                         f"{(cfg.robot, cfg.split, cfg.seed_start)}: choose another --out")
    damaged = manifest.damaged(cfg.out_dir)
    for file, problem in damaged.items():
        print(f"tavis record: {file}: {problem}; recording it again", file=sys.stderr)
    manifest.episodes = [e for e in manifest.episodes if e.file not in damaged]
    return manifest


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
    from lerobot_tavis.experts.registry import run_episode

    env = _env(robot, task, split)
    qpos, qvel, task_state = [], [], []

    def snapshot() -> None:
        qpos.append(env.data.qpos.copy())
        qvel.append(env.data.qvel.copy())
        task_state.append(env.task_object.task_state().copy())

    result = run_episode(env, seed, on_step=snapshot)
    entry = ManifestEntry(task, seed, result.success, result.length_steps)
    if not (result.success or keep_failures):
        return entry, None
    return entry, RawEpisode(robot, task, split, seed, env.task_description, RECORD_FPS, result.success,
                             result.actions, np.array(qpos), np.array(qvel), np.array(task_state))


_ENVS: dict[tuple[str, str, str], object] = {}


def _env(robot: str, task: str, split: str):
    """One env per (robot, task, split) per process, rendering nothing (the demonstrators read the state)."""
    key = (robot, task, split)
    if key not in _ENVS:
        os.environ.setdefault("MUJOCO_GL", "egl")
        from lerobot_tavis.envs.env import TavisEnv

        _ENVS[key] = TavisEnv(task, robot, split=split, fps=RECORD_FPS, cameras=())
    return _ENVS[key]
