"""Protocol cells as (cell, task, seed chunk) jobs spread over every worker, for the demonstrators and policies.

All chunks of all pending cells go to one pool (`workers`: local processes or Ray), so every core,
or every share of a GPU, stays busy whatever the number of tasks. A chunk's outcome depends only on its task,
split and seeds (a policy chunk is one lerobot-eval run seeded with its first seed), each chunk's results come back
to this process, and each cell is assembled in a fixed order (task, then seed) once its last chunk is done: the
results do not depend on the backend, the number of workers or the finishing order. Finished chunks are kept in the
hidden folder `.<cell>.chunks/` (episode log and a `done` record, and the run's identity in `run.json`,
`eval.run_identity`), so a killed run resumes at chunk granularity; `tavis report` never reads hidden folders. Every
episode record and the cell's `eval_info.json` carry the run's identity (`"run"`).

- Demonstrators render nothing: they act on the simulator state, so pixels cannot change an outcome (the camera
  mode still fixes whether the neck moves).
- Policies run as lerobot-eval runs (`lerobot_run.evaluate`: LeRobot's env, policy, processors and
  `eval_policy_all`), each chunk in a scratch folder; the first chunk of each task films its first
  `film_episodes` episodes, the other chunks film none (lerobot-eval films 10 and holds their frames in memory).
  A worker keeps its env worker processes from one chunk to the next and builds the next chunk's task and split in
  them (`lerobot_run.evaluate(keep_workers=True)`): a new episode starts from its seed either way. A filmed chunk's
  videos are annotated (`eval.annotate`) by low-priority processes of this machine while the other chunks play,
  and its cell is assembled with those copies, so the report has none left to make.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
import time
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import as_completed
from dataclasses import dataclass
from pathlib import Path

from tqdm import tqdm

from lerobot_tavis.atomic import write_text
from lerobot_tavis.envs.tasks.catalog import suite_tasks
from lerobot_tavis.errors import InputError, PathNotFoundError
from lerobot_tavis.eval.annotate import ANNOTATED_DIR, Annotator, episode_index
from lerobot_tavis.eval.episode_log import EPISODE_LOG_NAME
from lerobot_tavis.eval.outputs import EVAL_INFO_NAME
from lerobot_tavis.eval.run_identity import RUN_FIELD, RUN_FILE
from lerobot_tavis.policies import register_policy_types
from lerobot_tavis.staging import staged_directory
from lerobot_tavis.workers import executor, usable_cores

METRICS = ("successes", "sum_rewards", "max_rewards")  # per-episode lists of lerobot-eval's per-task metrics
ENV_WORKER_NICENESS = 10  # env workers yield contended cores to the policy's process, use idle ones; same outcomes


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


@dataclass(frozen=True)
class ChunkResult:
    chunk: Chunk
    log_text: str  # the chunk's episode log lines
    metrics: dict[str, list]  # METRICS, one value per episode
    videos: dict[str, bytes]  # file name -> mp4, for the first chunk of a task


def run_cells(cfg, cells: Sequence, identity: dict) -> None:
    """Play every pending cell's episodes (policy `cfg.policy_path`, else the demonstrators) and write each cell
    as lerobot-eval would, with the run's `identity` (`run_identity.run_identity(cfg)`) in every record. A cell's
    chunk folder, when there is one, holds chunks of this identity (the caller checks it)."""
    play = _play_expert_chunk if cfg.policy_path is None else _play_policy_chunk
    chunks = {cell.name: _chunks(cfg, cell) for cell in cells}
    work = {cell.name: cfg.out_dir / f".{cell.name}.chunks" for cell in cells}
    waiting = {name: [c for c in cell_chunks if not _done_path(work[name], c).exists()]
               for name, cell_chunks in chunks.items()}
    todo = [chunk for name in waiting for chunk in waiting[name]]
    total = sum(chunk.n for cell_chunks in chunks.values() for chunk in cell_chunks)
    started = time.perf_counter()
    desc = "demonstrators" if cfg.policy_path is None else "policy"
    with (tqdm(total=total, initial=total - sum(c.n for c in todo), desc=desc, unit="ep") as bar,
          Annotator(usable_cores()) as annotator):
        for name in [name for name, left in waiting.items() if not left]:  # finished before a kill
            _assemble(cfg, name, chunks[name], work[name], started, identity)
        for result in _completed(cfg, play, [(cfg, chunk) for chunk in todo]):
            chunk = result.chunk
            _keep_chunk(work[chunk.cell_name], result, identity)
            _annotate_chunk(annotator, work[chunk.cell_name], result)
            bar.update(chunk.n)
            waiting[chunk.cell_name].remove(chunk)
            if not waiting[chunk.cell_name]:
                annotator.write(chunk.cell_name)
                _assemble(cfg, chunk.cell_name, chunks[chunk.cell_name], work[chunk.cell_name], started, identity)


def _chunks(cfg, cell) -> list[Chunk]:
    last = cfg.seed + cfg.n_episodes
    size = cfg.chunk_size
    return [Chunk(cell.name, cell.suite, cell.split, task_id, task, first, min(size, last - first))
            for task_id, task in played_tasks(cfg, cell.suite) for first in range(cfg.seed, last, size)]


def played_tasks(cfg, suite: str) -> list[tuple[int, str]]:
    """(index in the suite, name) of the tasks of `suite` a run plays: all of them, or those of `cfg.tasks`."""
    return [(task_id, task) for task_id, task in enumerate(suite_tasks(suite)) if not cfg.tasks or task in cfg.tasks]


def _completed(cfg, fn: Callable, jobs: list[tuple]) -> Iterator:
    """fn(*job) for every job, yielded as each finishes (in order with one local worker)."""
    if cfg.workers == 1 and cfg.backend == "local":
        try:
            for job in jobs:
                yield fn(*job)
        finally:
            _close_envs()
        return
    with executor(cfg.workers, cfg.backend, gpus_per_job=cfg.gpus_per_job) as pool:
        futures = [pool.submit(fn, *job) for job in jobs]
        try:
            for done, future in enumerate(as_completed(futures), 1):
                if done == len(futures):  # the workers exit while the last result is handled
                    pool.shutdown(wait=False)
                yield future.result()
        finally:
            pool.shutdown(wait=True, cancel_futures=True)


_ENVS: dict[tuple, object] = {}  # per process: the last chunk's (task, split) -> its TavisEnv, for the next chunk


def _play_expert_chunk(cfg, chunk: Chunk) -> ChunkResult:
    """Play one chunk with the demonstrators (in a worker)."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    from lerobot_tavis.eval.env_factory import make_tavis_env
    from lerobot_tavis.eval.episode_log import EpisodeLogger
    from lerobot_tavis.experts.rollout import run_episode

    key = (chunk.task, chunk.split)
    if key not in _ENVS:
        _close_envs()  # one compiled scene per worker: each holds its model and data
        _ENVS[key] = make_tavis_env(chunk.task, cfg.robot, cfg.camera_mode, chunk.split, cfg.image_size,
                                    cfg.episode_length_s, cameras=())  # the demonstrators read the state
    with tempfile.TemporaryDirectory(prefix="tavis-chunk-") as scratch:
        log_path = Path(scratch) / EPISODE_LOG_NAME
        env = EpisodeLogger(_ENVS[key], log_path, suite=chunk.suite, task_id=chunk.task_id)
        successes = [run_episode(env, seed).success for seed in range(chunk.first_seed, chunk.first_seed + chunk.n)]
        rewards = [float(s) for s in successes]
        return ChunkResult(chunk, log_path.read_text(),
                           {"successes": successes, "sum_rewards": rewards, "max_rewards": rewards}, {})


def policy_config(cfg):
    """The checkpoint's policy config with the run's device and `--policy-option` fields set; an option the policy
    does not have is refused, naming it."""
    from lerobot.configs.policies import PreTrainedConfig

    register_policy_types()

    try:
        policy = PreTrainedConfig.from_pretrained(cfg.policy_path)
    except FileNotFoundError as error:  # e.g. a folder without config.json; LeRobot's message names it
        raise PathNotFoundError(str(error)) from error
    policy.pretrained_path = Path(cfg.policy_path)
    policy.device = cfg.device
    for name, value in cfg.policy_options:  # e.g. num_inference_steps=10, use_amp=true
        if not hasattr(policy, name):
            raise InputError(f"--policy-option {name}: the {policy.type} policy has no such field")
        setattr(policy, name, value)
    return policy


def _play_policy_chunk(cfg, chunk: Chunk) -> ChunkResult:
    """Play one chunk with the policy: one lerobot-eval run of its task and seeds, in a scratch folder (in a
    worker)."""
    from lerobot.configs.default import EvalConfig

    from lerobot_tavis.eval.env_config import TavisEnvConfig
    from lerobot_tavis.eval.lerobot_run import evaluate, pipeline_config

    if cfg.device != "cpu":
        _share_cores(cfg.workers)
    policy = policy_config(cfg)
    batch = min(cfg.batch_size, chunk.n)
    with tempfile.TemporaryDirectory(prefix="tavis-chunk-") as scratch:
        out = Path(scratch) / "eval"
        film = cfg.film_episodes if chunk.first_seed == cfg.seed else 0  # the task's first episodes only
        env = TavisEnvConfig(task=chunk.task, robot=cfg.robot, camera_mode=cfg.camera_mode, split=chunk.split,
                             image_size=cfg.image_size, episode_length_s=cfg.episode_length_s,
                             episode_log=str(out / EPISODE_LOG_NAME), filmed_envs=film,
                             worker_niceness=ENV_WORKER_NICENESS if cfg.device != "cpu" else 0)
        batches = EvalConfig(n_episodes=chunk.n, batch_size=batch, use_async_envs=batch > 1)
        evaluate(pipeline_config(env=env, eval=batches, policy=policy, output_dir=out, seed=chunk.first_seed,
                                 job_name=f"tavis_{chunk.task}_{chunk.split}"), keep_workers=True)
        task_metrics = json.loads((out / EVAL_INFO_NAME).read_text())["per_task"][0]["metrics"]
        lines = sorted((json.loads(line) for line in (out / EPISODE_LOG_NAME).read_text().splitlines()),
                       key=lambda record: record["seed"])  # async envs log in the order episodes finish
        videos = {path.name: path.read_bytes() for path in sorted((out / "videos").rglob("*.mp4"))}
        return ChunkResult(chunk, "".join(json.dumps(line) + "\n" for line in lines),
                           {key: task_metrics[key] for key in METRICS}, videos)


def _share_cores(jobs: int) -> None:
    """Give this job's torch its share of the cores this process may run on (its CPU affinity: `taskset`, a
    container's cpuset). Each process's torch uses every core by default, so `jobs` policy jobs at once
    oversubscribed them (each job's main process busy on many cores while its env workers waited). Only for a
    policy on an accelerator: there the CPU work is element-wise; a policy on the CPU keeps torch's default, as its
    results would depend on the thread count, and so on `--workers`."""
    import torch

    torch.set_num_threads(max(1, usable_cores() // jobs))


def _close_envs() -> None:
    """Close this process's kept envs: the demonstrators' scene, a policy job's env workers."""
    from lerobot_tavis.eval.lerobot_run import close_kept_envs

    while _ENVS:
        _ENVS.popitem()[1].close()
    close_kept_envs()


def _done_path(work: Path, chunk: Chunk) -> Path:
    return work / f"{chunk.stem}.done.json"


def _keep_chunk(work: Path, result: ChunkResult, identity: dict) -> None:
    """Write a finished chunk's episode log, each record with the run's `identity`, and videos, then its `done`
    record (the proof it is complete). The cell's first kept chunk writes the identity into the folder first."""
    chunk = result.chunk
    if not (work / RUN_FILE).exists():
        write_text(work / RUN_FILE, json.dumps(identity, indent=1) + "\n")
    (work / f"{chunk.stem}.jsonl").write_text("".join(json.dumps(json.loads(line) | {RUN_FIELD: identity}) + "\n"
                                                      for line in result.log_text.splitlines()))
    for name, data in result.videos.items():
        video = work / f"{chunk.stem}.videos" / name
        video.parent.mkdir(exist_ok=True)
        video.write_bytes(data)
    write_text(_done_path(work, chunk), json.dumps(result.metrics))


def _annotate_chunk(annotator: Annotator, work: Path, result: ChunkResult) -> None:
    """Have the chunk's videos annotated beside them (`<stem>.videos_annotated/`) while other chunks play: the
    report would otherwise annotate a protocol's videos after its last rollout, one after the other. Video i is
    the episode of the chunk's seed first_seed + i."""
    chunk = result.chunk
    records = {record["seed"]: record for record in map(json.loads, result.log_text.splitlines())}
    for name in sorted(result.videos):
        video = work / f"{chunk.stem}.videos" / name
        record = records.get(chunk.first_seed + episode_index(video))
        if record is not None:  # else an episode LeRobot filmed but did not score
            annotator.submit(chunk.cell_name, video, work / f"{chunk.stem}.{ANNOTATED_DIR}" / name, record)


def _assemble(cfg, cell_name: str, chunks: list[Chunk], work: Path, started: float, identity: dict) -> None:
    """Write the cell from its chunks, in task then seed order, and drop the chunks."""
    suite = chunks[0].suite
    per_task: dict[int, dict[str, list]] = {}
    with staged_directory(cfg.out_dir / cell_name, overwrite=True) as partial:
        partial.mkdir()
        with open(partial / EPISODE_LOG_NAME, "w") as log:
            for chunk in sorted(chunks, key=lambda c: (c.task_id, c.first_seed)):
                log.write((work / f"{chunk.stem}.jsonl").read_text())
                metrics = json.loads(_done_path(work, chunk).read_text())
                task = per_task.setdefault(chunk.task_id, {key: [] for key in METRICS})
                for key in METRICS:
                    task[key].extend(metrics[key])
                for kind in ("videos", ANNOTATED_DIR):
                    videos = work / f"{chunk.stem}.{kind}"
                    if videos.is_dir():  # copied with their times: an annotated copy stays newer than its video
                        shutil.copytree(videos, partial / kind / f"{suite}_{chunk.task_id}")
        tasks = [{"task_group": suite, "task_id": task_id,
                  "metrics": {**metrics, "video_paths": sorted(
                      str(p.relative_to(partial)) for p in (partial / "videos" / f"{suite}_{task_id}").glob("*.mp4"))}}
                 for task_id, metrics in sorted(per_task.items())]
        flat = [s for metrics in per_task.values() for s in metrics["successes"]]
        summary = {"pc_success": 100.0 * sum(flat) / len(flat), "n_episodes": len(flat)}
        policy = "scripted demonstrators" if cfg.policy_path is None else str(cfg.policy_path)
        info = {"per_task": tasks, "per_group": {suite: summary}, "overall": summary, "policy": policy,
                RUN_FIELD: identity}
        (partial / EVAL_INFO_NAME).write_text(json.dumps(info, indent=2) + "\n")
        (partial / "wall_clock_s.txt").write_text(f"{time.perf_counter() - started:.1f}\n")
    shutil.rmtree(work)
