"""`tavis eval`: the benchmark protocol for one policy checkpoint (or the demonstrators) on one robot.

Cells are suite x split (`id`, `ood_spatial`, `ood_init_pose`), 96 episodes per task by default, seeds from 1000
as lerobot-eval uses them. A policy is evaluated through LeRobot's own `eval_main` (one lerobot-eval run per
cell); the demonstrators play the same episodes through the same env and episode log, as (cell, task, seed chunk)
jobs over all workers (`expert_runs`). Each cell is written to a temporary directory and moved into place when
complete, so a re-run skips finished cells (and, for the demonstrators, finished chunks). `wall_clock_s.txt` in a
cell is the time from the start of the command to the cell's completion. The report (`tavis report`) is written at
the end.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path

from lerobot_tavis import checks
from lerobot_tavis.dataset_tools.staging import staged_directory
from lerobot_tavis.envs.modes import DEFAULT_CAMERA_MODE, resolve_camera_mode
from lerobot_tavis.envs.physics import POLICY_HZ
from lerobot_tavis.eval.episode_log import EPISODE_LOG_NAME
from lerobot_tavis.eval.expert_runs import run_expert_cells
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
    workers: int = 1  # demonstrators: processes playing (cell, task, seed chunk) jobs
    seed: int = START_SEED
    chunk_episodes: int = 8  # demonstrators: consecutive seeds per job
    policy_options: tuple[tuple[str, object], ...] = ()  # (field, value) set on the checkpoint's policy config

    def __post_init__(self):
        object.__setattr__(self, "camera_mode", resolve_camera_mode(self.camera_mode))
        checks.integer("n_episodes", self.n_episodes, 1)
        checks.integer("batch_size", self.batch_size, 1)
        checks.integer("workers", self.workers, 1)
        checks.integer("seed", self.seed, 0)
        checks.integer("chunk_episodes", self.chunk_episodes, 1)
        checks.image_size(self.image_size)
        checks.episode_steps(self.episode_length_s, POLICY_HZ)


def checkpoint_env(policy_path: str | Path) -> dict:
    """The tavis env settings a checkpoint was trained with (robot, camera_mode, image_size), read from the
    `train_config.json` lerobot-train saves beside it; empty when there is none or it is not a tavis run."""
    path = Path(policy_path) / "train_config.json"
    if not path.is_file():
        return {}
    try:
        env = json.loads(path.read_text()).get("env") or {}
    except json.JSONDecodeError as error:
        raise ValueError(f"{path}: not a JSON file ({error.msg})") from None
    if env.get("type") != "tavis":
        return {}
    found = {key: env[key] for key in ("robot", "camera_mode", "image_size") if key in env}
    if "image_size" in found:
        found["image_size"] = tuple(found["image_size"])
    return found


def run_protocol(cfg: ProtocolConfig) -> list[Path]:
    cfg.out_dir.mkdir(parents=True, exist_ok=True)
    cells = [Cell(suite, split) for split in cfg.splits for suite in cfg.suites]
    pending = []
    for cell in cells:
        if (cfg.out_dir / cell.name / EVAL_INFO_NAME).exists():
            print(f"{cell.name}: done already, skipped")
        else:
            pending.append(cell)
    start = time.perf_counter()
    if cfg.policy_path is None:
        run_expert_cells(cfg, pending)
        return write_report(cfg.out_dir)
    for cell in pending:
        with staged_directory(cfg.out_dir / cell.name, overwrite=True) as partial:  # an unfinished cell is replaced
            partial.mkdir()
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
    for name, value in cfg.policy_options:  # e.g. num_inference_steps=10, use_amp=true
        if not hasattr(policy, name):
            raise ValueError(f"--policy-option {name}: the {policy.type} policy has no such field")
        setattr(policy, name, value)
    env = TavisEnvConfig(task=cell.suite, robot=cfg.robot, camera_mode=cfg.camera_mode, split=cell.split,
                         image_size=cfg.image_size, episode_length_s=cfg.episode_length_s,
                         episode_log=str(out / EPISODE_LOG_NAME))
    eval_main(EvalPipelineConfig(env=env, eval=EvalConfig(n_episodes=cfg.n_episodes, batch_size=cfg.batch_size,
                                                          use_async_envs=cfg.batch_size > 1),
                                 policy=policy, output_dir=out, seed=cfg.seed))
