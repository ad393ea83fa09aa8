"""`tavis eval`: the benchmark protocol for one policy checkpoint (or the demonstrators) on one robot.

Cells are suite x split (`id`, `ood_spatial`, `ood_init_pose`), 96 episodes per task by default, seeds from 1000
as lerobot-eval uses them. Policy and demonstrators alike play (cell, task, seed chunk) jobs over all workers
(`cell_runs`): a policy chunk is one run of LeRobot's own `eval_main`, so several share one GPU; the demonstrators
play through the same env and episode log. Finished chunks survive a kill and each cell is moved into place when
complete, so a re-run skips finished cells and chunks. `wall_clock_s.txt` in a cell is the time from the start of
the command to the cell's completion. The report (`tavis report`) is written at the end.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from lerobot_tavis import checks
from lerobot_tavis.dataset_tools.workers import BACKENDS
from lerobot_tavis.envs.modes import DEFAULT_CAMERA_MODE, resolve_camera_mode
from lerobot_tavis.envs.physics import POLICY_HZ
from lerobot_tavis.errors import InputError
from lerobot_tavis.eval.cell_runs import policy_config, run_cells
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
    workers: int = 1  # (cell, task, seed chunk) jobs at once: local processes, or sharers of one GPU under Ray
    seed: int = START_SEED
    chunk_episodes: int | None = None  # consecutive seeds per job; default 8 (demonstrators), 96 (policies)
    policy_options: tuple[tuple[str, object], ...] = ()  # (field, value) set on the checkpoint's policy config
    backend: str = "local"  # or "ray" (dataset_tools.workers)

    def __post_init__(self):
        object.__setattr__(self, "camera_mode", resolve_camera_mode(self.camera_mode))
        checks.integer("n_episodes", self.n_episodes, 1)
        checks.integer("batch_size", self.batch_size, 1)
        checks.integer("workers", self.workers, 1)
        checks.integer("seed", self.seed, 0)
        if self.chunk_episodes is not None:
            checks.integer("chunk_episodes", self.chunk_episodes, 1)
        checks.choice("backend", self.backend, BACKENDS)
        checks.image_size(self.image_size)
        checks.episode_steps(self.episode_length_s, POLICY_HZ)

    @property
    def chunk_size(self) -> int:
        """Episodes per job; for a policy a whole number of env batches."""
        if self.policy_path is None:
            return self.chunk_episodes or 8
        wanted = self.chunk_episodes or 96  # a lerobot-eval run costs tens of seconds to start
        return self.batch_size * -(-wanted // self.batch_size)

    @property
    def gpus_per_job(self) -> float:
        """The share of a GPU a Ray job asks for: `workers` policy jobs share each GPU."""
        return 1.0 / self.workers if self.policy_path is not None and self.device.startswith("cuda") else 0.0


def checkpoint_env(policy_path: str | Path) -> dict:
    """The tavis env settings a checkpoint was trained with (robot, camera_mode, image_size), read from the
    `train_config.json` lerobot-train saves beside it; empty when there is none or it is not a tavis run."""
    path = Path(policy_path) / "train_config.json"
    if not path.is_file():
        return {}
    try:
        env = json.loads(path.read_text()).get("env") or {}
    except json.JSONDecodeError as error:
        raise InputError(f"{path}: not a JSON file ({error.msg})") from None
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
    if cfg.policy_path is not None:
        policy_config(cfg)  # a bad --policy-option fails here, before any job starts
    run_cells(cfg, pending)
    return write_report(cfg.out_dir)
