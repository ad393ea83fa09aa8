"""`tavis eval`: the benchmark protocol for one policy checkpoint (or the demonstrators) on one robot.

Cells are suite x split (`id`, `ood_spatial`, `ood_init_pose`), 96 episodes per task by default, seeds from 1000
as lerobot-eval uses them. A policy is evaluated through LeRobot's own `eval_main` (one lerobot-eval run per
cell); the demonstrators (`expert=True`) play the same episodes through the same env and episode log. Each cell
is written to a temporary directory and moved into place when complete, so a re-run skips finished cells.
The report (`tavis report`) is written at the end.
"""

from __future__ import annotations

import json
import multiprocessing
import os
import time
from dataclasses import dataclass
from pathlib import Path

from tqdm import tqdm

from lerobot_tavis import checks
from lerobot_tavis.dataset_tools.staging import staged_directory
from lerobot_tavis.envs.modes import DEFAULT_CAMERA_MODE, resolve_camera_mode
from lerobot_tavis.envs.physics import POLICY_HZ
from lerobot_tavis.envs.tasks.catalog import expand_tasks
from lerobot_tavis.eval.episode_log import EPISODE_LOG_NAME
from lerobot_tavis.eval.report import EVAL_INFO_NAME, write_report

START_SEED = 1000


@dataclass(frozen=True)
class Cell:
    suite: str
    split: str

    @property
    def name(self) -> str:
        return f"{self.suite}__{self.split}"


@dataclass(frozen=True)
class ProtocolConfig:
    out_dir: Path
    robot: str = "gr1t2"
    suites: tuple[str, ...] = ("tavis_head",)
    splits: tuple[str, ...] = ("id", "ood_spatial", "ood_init_pose")
    n_episodes: int = 96
    camera_mode: str = DEFAULT_CAMERA_MODE
    image_size: tuple[int, int] = (480, 640)
    episode_length_s: float = 20.0
    policy_path: str | None = None  # None: the scripted demonstrators
    batch_size: int = 1
    device: str = "cpu"
    workers: int = 1  # demonstrators: tasks of a cell in parallel processes
    seed: int = START_SEED

    def __post_init__(self):
        object.__setattr__(self, "camera_mode", resolve_camera_mode(self.camera_mode))
        checks.integer("n_episodes", self.n_episodes, 1)
        checks.integer("batch_size", self.batch_size, 1)
        checks.integer("workers", self.workers, 1)
        checks.integer("seed", self.seed, 0)
        checks.image_size(self.image_size)
        checks.episode_steps(self.episode_length_s, POLICY_HZ)


def run_protocol(cfg: ProtocolConfig) -> list[Path]:
    cfg.out_dir.mkdir(parents=True, exist_ok=True)
    cells = [Cell(suite, split) for split in cfg.splits for suite in cfg.suites]
    for cell in cells:
        final = cfg.out_dir / cell.name
        if (final / EVAL_INFO_NAME).exists():
            print(f"{cell.name}: done already, skipped")
            continue
        start = time.perf_counter()
        with staged_directory(final, overwrite=True) as partial:  # an unfinished cell is replaced
            partial.mkdir()
            if cfg.policy_path is None:
                _run_expert_cell(cfg, cell, partial)
            else:
                _run_policy_cell(cfg, cell, partial)
            (partial / "wall_clock_s.txt").write_text(f"{time.perf_counter() - start:.1f}\n")
        print(f"{cell.name}: {time.perf_counter() - start:.0f} s")
    return write_report(cfg.out_dir)


def _run_policy_cell(cfg: ProtocolConfig, cell: Cell, out: Path) -> None:
    from lerobot.configs.default import EvalConfig
    from lerobot.configs.eval import EvalPipelineConfig
    from lerobot.configs.policies import PreTrainedConfig
    from lerobot.scripts.lerobot_eval import eval_main

    from lerobot_tavis.envs.config import TavisEnvConfig

    policy = PreTrainedConfig.from_pretrained(cfg.policy_path)
    policy.pretrained_path = Path(cfg.policy_path)
    policy.device = cfg.device
    env = TavisEnvConfig(task=cell.suite, robot=cfg.robot, camera_mode=cfg.camera_mode, split=cell.split,
                         image_size=cfg.image_size, episode_length_s=cfg.episode_length_s,
                         episode_log=str(out / EPISODE_LOG_NAME))
    eval_main(EvalPipelineConfig(env=env, eval=EvalConfig(n_episodes=cfg.n_episodes, batch_size=cfg.batch_size,
                                                          use_async_envs=cfg.batch_size > 1),
                                 policy=policy, output_dir=out, seed=cfg.seed))


def _run_expert_cell(cfg: ProtocolConfig, cell: Cell, out: Path) -> None:
    tasks = expand_tasks(cell.suite)[cell.suite]
    jobs = [(cfg, cell, task_id, task, out / f".{task}.jsonl") for task_id, task in enumerate(tasks)]
    if cfg.workers > 1:
        with multiprocessing.get_context("spawn").Pool(min(cfg.workers, len(jobs))) as pool:
            successes = pool.map(_expert_task, jobs)
    else:
        successes = [_expert_task(job) for job in jobs]
    with open(out / EPISODE_LOG_NAME, "w") as log:
        for *_, part in jobs:
            log.write(part.read_text())
            part.unlink()
    per_task = [{"task_group": cell.suite, "task_id": task_id,
                 "metrics": {"successes": ok, "sum_rewards": [float(s) for s in ok],
                             "max_rewards": [float(s) for s in ok], "video_paths": []}}
                for task_id, ok in enumerate(successes)]
    flat = [s for ok in successes for s in ok]
    summary = {"pc_success": 100.0 * sum(flat) / len(flat), "n_episodes": len(flat)}
    info = {"per_task": per_task, "per_group": {cell.suite: summary}, "overall": summary,
            "policy": "scripted demonstrators"}
    (out / EVAL_INFO_NAME).write_text(json.dumps(info, indent=2) + "\n")


def _expert_task(job) -> list[bool]:
    """Episodes seed .. seed + n - 1 of one task with its demonstrator; returns LeRobot-style successes."""
    cfg, cell, task_id, task, log_path = job
    os.environ.setdefault("MUJOCO_GL", "egl")
    from lerobot_tavis.envs.factory import make_tavis_env
    from lerobot_tavis.experts.registry import run_episode

    env = make_tavis_env(task, cfg.robot, cfg.camera_mode, cell.split, cfg.image_size, cfg.episode_length_s,
                         str(log_path), suite=cell.suite, task_id=task_id)
    successes = []
    for ix in tqdm(range(cfg.n_episodes), desc=f"{cell.name} {task}", unit="ep", position=task_id):
        successes.append(run_episode(env, cfg.seed + ix).success)
    env.close()
    return successes
