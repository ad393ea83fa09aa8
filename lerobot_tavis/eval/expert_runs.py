"""The demonstrators' protocol cells as (cell, task, seed chunk) jobs spread over every worker.

All chunks of all pending cells go to one pool, so every core stays busy whatever the number of tasks. An
episode's outcome depends only on its task, split and seed, and each cell is assembled in a fixed order (task, then
seed) once its last chunk is done, so the results do not depend on the number of workers or on finishing order.
Finished chunks are kept in the hidden folder `.<cell>.chunks/` (their episode log and a `done` record), so a
killed run resumes at chunk granularity; `tavis report` never reads hidden folders. Nothing is rendered: the
demonstrators act on the simulator state, so pixels cannot change an outcome (the camera mode still fixes whether
the neck moves).
"""

from __future__ import annotations

import json
import os
import shutil
import time
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import as_completed
from dataclasses import dataclass
from pathlib import Path

from tqdm import tqdm

from lerobot_tavis.dataset_tools.staging import staged_directory
from lerobot_tavis.dataset_tools.workers import executor
from lerobot_tavis.envs.tasks.catalog import expand_tasks
from lerobot_tavis.eval.episode_log import EPISODE_LOG_NAME
from lerobot_tavis.eval.report import EVAL_INFO_NAME


@dataclass(frozen=True)
class Chunk:
    """Episodes `first_seed .. first_seed + n - 1` of one task of one cell."""

    cell_name: str
    suite: str
    split: str
    task_id: int
    task: str
    first_seed: int
    n: int

    @property
    def stem(self) -> str:
        return f"{self.task_id:02d}_{self.task}_{self.first_seed:07d}"


def run_expert_cells(cfg, cells: Sequence) -> None:
    """Play every pending cell's episodes with the demonstrators and write each cell as lerobot-eval would."""
    chunks = {cell.name: _chunks(cfg, cell) for cell in cells}
    work = {cell.name: cfg.out_dir / f".{cell.name}.chunks" for cell in cells}
    waiting = {name: [c for c in cell_chunks if not _done_path(work[name], c).exists()]
               for name, cell_chunks in chunks.items()}
    todo = [chunk for name in waiting for chunk in waiting[name]]
    total = sum(chunk.n for cell_chunks in chunks.values() for chunk in cell_chunks)
    started = time.perf_counter()
    with tqdm(total=total, initial=total - sum(c.n for c in todo), desc="demonstrators", unit="ep") as bar:
        for name in [name for name, left in waiting.items() if not left]:  # finished before a kill
            _assemble(cfg, name, chunks[name], work[name], started)
        for chunk in _completed(cfg.workers, _play_chunk, [(cfg, chunk, work[chunk.cell_name]) for chunk in todo]):
            bar.update(chunk.n)
            waiting[chunk.cell_name].remove(chunk)
            if not waiting[chunk.cell_name]:
                _assemble(cfg, chunk.cell_name, chunks[chunk.cell_name], work[chunk.cell_name], started)


def _chunks(cfg, cell) -> list[Chunk]:
    tasks = expand_tasks(cell.suite)[cell.suite]
    last = cfg.seed + cfg.n_episodes
    return [Chunk(cell.name, cell.suite, cell.split, task_id, task, first, min(cfg.chunk_episodes, last - first))
            for task_id, task in enumerate(tasks) for first in range(cfg.seed, last, cfg.chunk_episodes)]


def _completed(workers: int, fn: Callable, jobs: list[tuple]) -> Iterator:
    """fn(*job) for every job, yielded as each finishes (in order when workers == 1)."""
    if workers == 1:
        try:
            for job in jobs:
                yield fn(*job)
        finally:
            _close_envs()
        return
    with executor(workers) as pool:
        futures = [pool.submit(fn, *job) for job in jobs]
        try:
            for future in as_completed(futures):
                yield future.result()
        finally:
            pool.shutdown(wait=True, cancel_futures=True)


_ENVS: dict[tuple, object] = {}  # per process: (task, split) -> its TavisEnv, reused across chunks


def _play_chunk(cfg, chunk: Chunk, work: Path) -> Chunk:
    """Play one chunk, writing its episode log and then its `done` record (the proof it is complete)."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    from lerobot_tavis.envs.factory import make_tavis_env
    from lerobot_tavis.eval.episode_log import EpisodeLogger
    from lerobot_tavis.experts.registry import run_episode

    key = (chunk.task, chunk.split)
    if key not in _ENVS:
        _ENVS[key] = make_tavis_env(chunk.task, cfg.robot, cfg.camera_mode, chunk.split, cfg.image_size,
                                    cfg.episode_length_s, cameras=())  # the demonstrators read the state
    work.mkdir(parents=True, exist_ok=True)
    log_path = work / f"{chunk.stem}.jsonl"
    log_path.unlink(missing_ok=True)  # what a killed run left of this chunk
    env = EpisodeLogger(_ENVS[key], log_path, suite=chunk.suite, task_id=chunk.task_id)
    successes = [run_episode(env, seed).success for seed in range(chunk.first_seed, chunk.first_seed + chunk.n)]
    partial = work / f".{chunk.stem}.done.partial"
    partial.write_text(json.dumps({"successes": successes}))
    os.replace(partial, _done_path(work, chunk))
    return chunk


def _close_envs() -> None:
    while _ENVS:
        _ENVS.popitem()[1].close()


def _done_path(work: Path, chunk: Chunk) -> Path:
    return work / f"{chunk.stem}.done.json"


def _assemble(cfg, cell_name: str, chunks: list[Chunk], work: Path, started: float) -> None:
    """Write the cell from its chunks, in task then seed order, and drop the chunks."""
    suite = chunks[0].suite
    per_task: dict[int, list[bool]] = {}
    with staged_directory(cfg.out_dir / cell_name, overwrite=True) as partial:
        partial.mkdir()
        with open(partial / EPISODE_LOG_NAME, "w") as log:
            for chunk in sorted(chunks, key=lambda c: (c.task_id, c.first_seed)):
                log.write((work / f"{chunk.stem}.jsonl").read_text())
                per_task.setdefault(chunk.task_id, []).extend(
                    json.loads(_done_path(work, chunk).read_text())["successes"])
        tasks = [{"task_group": suite, "task_id": task_id,
                  "metrics": {"successes": ok, "sum_rewards": [float(s) for s in ok],
                              "max_rewards": [float(s) for s in ok], "video_paths": []}}
                 for task_id, ok in sorted(per_task.items())]
        flat = [s for ok in per_task.values() for s in ok]
        summary = {"pc_success": 100.0 * sum(flat) / len(flat), "n_episodes": len(flat)}
        info = {"per_task": tasks, "per_group": {suite: summary}, "overall": summary,
                "policy": "scripted demonstrators"}
        (partial / EVAL_INFO_NAME).write_text(json.dumps(info, indent=2) + "\n")
        (partial / "wall_clock_s.txt").write_text(f"{time.perf_counter() - started:.1f}\n")
    shutil.rmtree(work)
