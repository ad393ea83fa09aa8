"""`tavis eval`: the benchmark protocol for one policy checkpoint (or the demonstrators) on one robot.

Cells are suite x split (`id`, `ood_spatial`, `ood_init_pose`), 96 episodes per task (all of the suite's, or those
of `--tasks`) by default, seeds from 1000 as lerobot-eval uses them. Policy and demonstrators alike play (cell,
task, seed chunk) jobs over all workers (`cell_runs`): a policy chunk is one lerobot-eval run in a worker process,
so several share one GPU; the demonstrators play through the same env and episode log. Finished chunks survive a
kill and each cell is moved into place when complete, so a re-run skips finished cells and chunks: those played with
the same settings (`eval.run_identity`); others are refused, naming the difference, or with `--restart` played again.
One run at a time writes an output directory (`locking`).
`wall_clock_s.txt` in a cell is the time from the start of the command to the cell's completion. The report
(`tavis report`) is written at the end.
"""

from __future__ import annotations

import json
import logging
import shutil
import time
from dataclasses import dataclass
from pathlib import Path

from lerobot_tavis import checks
from lerobot_tavis.cli_options import option, spelling
from lerobot_tavis.envs.checkpoint_settings import (CheckpointSettings, match_settings, pretrained_model_dir,
                                                    read_checkpoint_settings)
from lerobot_tavis.envs.modes import DEFAULT_CAMERA_MODE, RENAMED_MODES, camera_mode_names, resolve_camera_mode
from lerobot_tavis.envs.physics import POLICY_HZ
from lerobot_tavis.envs.robots import DEFAULT_ROBOT, robot_names
from lerobot_tavis.envs.tasks.catalog import (BENCHMARK_TASKS, PROTOCOL_SPLITS, SUITES, split_names, suite_tasks,
                                              task_info)
from lerobot_tavis.errors import FieldError, InputError
from lerobot_tavis.eval.cell_runs import played_tasks, run_cells
from lerobot_tavis.eval.outputs import EVAL_INFO_NAME, read_eval_info
from lerobot_tavis.eval.report import write_report
from lerobot_tavis.eval.run_identity import (RUN_FIELD, RUN_FILE, difference_text, differences, read_identity,
                                             run_identity)
from lerobot_tavis.locking import exclusive_output
from lerobot_tavis.workers import BACKENDS

START_SEED = 1000


@dataclass(frozen=True)
class Cell:
    suite: str
    split: str

    @property
    def name(self) -> str:
        return f"{self.suite}__{self.split}"


def policy_options(texts: tuple[str, ...]) -> tuple[tuple[str, object], ...]:
    """("num_inference_steps=10", ...) -> (("num_inference_steps", 10), ...): values are read as JSON, else kept as
    text."""
    options = []
    for text in texts:
        name, sign, value = text.partition("=")
        if not (sign and name.strip()):
            raise FieldError("policy_options", f"must be FIELD=VALUE, e.g. num_inference_steps=10, got {text!r}")
        try:
            options.append((name.strip(), json.loads(value)))
        except json.JSONDecodeError:
            options.append((name.strip(), value))
    return tuple(options)


# The env settings of a run when neither the config nor the policy checkpoint's training config gives them.
ENV_DEFAULTS = {"robot": DEFAULT_ROBOT, "camera_mode": DEFAULT_CAMERA_MODE, "image_size": (480, 640)}


@dataclass(frozen=True, kw_only=True)
class ProtocolConfig:
    """The protocol run of `tavis eval`; also its command-line options. Exactly one of `policy_path` and `expert`;
    `robot`, `camera_mode` and `image_size` left None are the checkpoint's, else ENV_DEFAULTS, and a given one that
    differs from the checkpoint's is logged as a warning (`checkpoint_settings.match_settings`); `image_size` is
    refused with `expert` (the demonstrators render nothing); `suites` left None are those of `tasks`, else the
    first of SUITES."""

    policy_path: str | None = option(None, "policy checkpoint directory (pretrained_model) or Hub repo id (default: "
                                     "none, give this or --expert)", flag="--policy")
    expert: bool = option(False, "evaluate the scripted demonstrators instead")
    robot: str | None = option(None, f"default: the checkpoint's, else {DEFAULT_ROBOT}", choices=robot_names)
    suites: tuple[str, ...] | None = option(None, f"default: the suites of --tasks, else {SUITES[0]}", flag="--suite",
                                            choices=SUITES)
    tasks: tuple[str, ...] = option((), "only these tasks of the suites (default: all of them), e.g. the task of a "
                                    "single-task policy", choices=BENCHMARK_TASKS)
    splits: tuple[str, ...] = option(PROTOCOL_SPLITS, "default: the reference's id ood_spatial ood_init_pose; also "
                                     "ood_visual (the look changed) and ood_visual:<factor> for one factor alone",
                                     choices=split_names)
    n_episodes: int = option(96, "episodes per task and split (default 96)", flag="--episodes")
    camera_mode: str | None = option(None, "default: the checkpoint's, else head_wrist; head_wrist and fixed_wrist "
                                     "are the paper's headcam and fixedcam conditions",
                                     choices=lambda: [*camera_mode_names(), *RENAMED_MODES])
    image_size: tuple[int, int] | None = option(None, "HxW of the policy's camera images (default: the checkpoint's, "
                                                "else 480x640; refused with --expert)",
                                                parse=checks.image_size_text)
    batch_size: int = option(1, "parallel envs per task (policy runs)")
    device: str = "cpu"
    episode_length_s: float = option(20.0, "seconds per episode (default 20)")
    policy_options: tuple[tuple[str, object], ...] = option(  # (field, value) set on the checkpoint's policy config
        (), "set a field of the checkpoint's policy config, e.g. num_inference_steps=10 or use_amp=true (repeatable; "
        "default: none)",
        flag="--policy-option", action="append", metavar="FIELD=VALUE", parse=policy_options)
    workers: int = option(1, "(cell, task, seed chunk) jobs at once; with a policy on a GPU they share it")
    chunk_episodes: int | None = option(None, "consecutive episodes per job, also what a killed run loses at most "
                                        "(default 8 for the demonstrators, 96 for a policy: each policy job starts "
                                        "a lerobot-eval run)")
    film_episodes: int = option(4, "episodes filmed per task and split, its first ones (default 4; lerobot-eval "
                                "films 10): a filming job holds about 1 GB of frames per filmed episode at 20 s")
    backend: str = option("local", "local processes, or a Ray cluster (RAY_ADDRESS; docs/scaling.md)",
                          choices=BACKENDS)
    seed: int = option(START_SEED, "first episode seed, as lerobot-eval's first")
    out_dir: Path = option(help="output directory; a re-run with the same settings resumes it, skipping finished "
                           "cells and chunks", flag="--out")
    restart: bool = option(False, "play again the cells of --out that were played with other settings (default: "
                           "refuse them, naming the difference)")

    def __post_init__(self):
        if bool(self.policy_path) == self.expert:
            raise InputError("give exactly one of --policy PATH and --expert")
        object.__setattr__(self, "policy_path", self.policy_path or None)
        if self.image_size is not None and checks.image_size(self.image_size) and self.expert:
            raise FieldError("image_size", "does not apply to --expert: the demonstrators act on the simulator state "
                                           "and render nothing")
        if self.camera_mode is not None:
            object.__setattr__(self, "camera_mode", resolve_camera_mode(self.camera_mode))
        given = {name: getattr(self, name) for name in ENV_DEFAULTS if getattr(self, name) is not None}
        checkpoint = _checkpoint_settings(self.policy_path) if self.policy_path else CheckpointSettings()
        settings, warnings = match_settings(checkpoint, given, ENV_DEFAULTS,
                                            spell=lambda name: spelling(ProtocolConfig, name))
        for warning in warnings:
            logging.getLogger(__name__).warning("tavis eval: warning: %s", warning)
        for name, value in settings.items():
            object.__setattr__(self, name, value)
        if self.suites is None:
            object.__setattr__(self, "suites", tuple(dict.fromkeys(task_info(task).suite for task in self.tasks))
                               or SUITES[:1])
        outside = [task for task in self.tasks if not any(task in suite_tasks(suite) for suite in self.suites)]
        if outside:
            raise FieldError("tasks", f"{outside} are not tasks of the suites {list(self.suites)}: "
                                      "name their suite too")
        checks.integer("n_episodes", self.n_episodes, 1)
        checks.integer("batch_size", self.batch_size, 1)
        checks.integer("workers", self.workers, 1)
        checks.integer("seed", self.seed, 0)
        checks.integer("film_episodes", self.film_episodes, 0)
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


def _checkpoint_settings(policy_path: str) -> CheckpointSettings:
    """What the checkpoint says of its env: a local checkpoint's (a folder without config.json is refused, naming
    the checkpoint below it), a Hub repo's (its config files downloaded, as the run would); a path that is neither
    is refused."""
    if Path(policy_path).exists():
        return read_checkpoint_settings(pretrained_model_dir(policy_path))
    try:
        checks.repo_id(policy_path)
    except FieldError:
        raise FieldError("policy_path", f"{policy_path}: no such checkpoint directory") from None
    return read_checkpoint_settings(policy_path, download=True)


def run_protocol(cfg: ProtocolConfig) -> list[Path]:
    """Play the cells of `cfg` not yet in `cfg.out_dir`, then write the report; returns the written files. One run
    at a time per output directory (`locking`)."""
    with exclusive_output(cfg.out_dir):
        cfg.out_dir.mkdir(parents=True, exist_ok=True)
        identity = run_identity(cfg)
        cells = [Cell(suite, split) for split in cfg.splits for suite in cfg.suites if played_tasks(cfg, suite)]
        _check_other_cells(cfg, cells, identity)
        pending = [cell for cell in cells if not _finished(cfg, cell, identity)]
        # A bad --policy-option fails in the first job, when it reads the checkpoint's config: checking it here
        # first would import LeRobot in this process too, holding back the start of every job.
        started = time.perf_counter()
        run_cells(cfg, pending, identity)
        played = time.perf_counter()
        written = write_report(cfg.out_dir)
    print(f"episodes played in {played - started:.1f} s, report written in {time.perf_counter() - played:.1f} s")
    return written


def _check_other_cells(cfg: ProtocolConfig, cells: list[Cell], identity: dict) -> None:
    """Refuse an output directory holding cells (finished or begun) that this run does not play, of a run with
    other settings: one output directory holds the cells of one run, so its report compares like with like."""
    played = {name for cell in cells for name in (cell.name, f".{cell.name}.chunks")}
    held = [info.parent for info in cfg.out_dir.glob(f"*/{EVAL_INFO_NAME}")] + list(cfg.out_dir.glob(".*.chunks"))
    for folder in sorted(held):
        if folder.name not in played and (problem := _played_with(folder, identity)):
            raise InputError(f"{cfg.out_dir} holds {folder.name}, which {problem}: one output directory holds the "
                             "cells of one run; give another --out")


def _finished(cfg: ProtocolConfig, cell: Cell, identity: dict) -> bool:
    """Whether `cell` is in `cfg.out_dir` already, played with these settings. A finished or begun copy of the cell
    from a run with other settings (or from before runs recorded them) is refused, naming the difference; with
    `cfg.restart` it is removed, to be played again."""
    folder, chunks = cfg.out_dir / cell.name, cfg.out_dir / f".{cell.name}.chunks"
    for held, exists in ((folder, (folder / EVAL_INFO_NAME).exists()), (chunks, chunks.exists())):
        if not exists or not (problem := _played_with(held, identity)):
            continue
        if not cfg.restart:
            raise InputError(f"{held} {problem}: pass --restart to play it again with these settings, or give "
                             "another --out")
        print(f"{cell.name}: played with other settings, playing it again (--restart)")
        shutil.rmtree(held)
    if not (folder / EVAL_INFO_NAME).exists():
        return False
    held = [task["task_id"] for task in read_eval_info(folder / EVAL_INFO_NAME)["per_task"]]
    if held != [task_id for task_id, _ in played_tasks(cfg, cell.suite)]:
        raise InputError(f"{folder} holds the tasks {[suite_tasks(cell.suite)[i] for i in held]}, not those "
                         "asked for: give another --out")
    shutil.rmtree(chunks, ignore_errors=True)  # left by a run killed between writing the cell and removing them
    print(f"{cell.name}: done already, skipped")
    return True


def _played_with(folder: Path, identity: dict) -> str | None:
    """How the cell in `folder` (a finished cell, or a `.<cell>.chunks` folder) was played, when its settings differ
    from `identity` or are unknown; None when they are the same."""
    if folder.name.endswith(".chunks"):
        stored = read_identity(folder / RUN_FILE) if (folder / RUN_FILE).exists() else None
    else:
        stored = read_eval_info(folder / EVAL_INFO_NAME).get(RUN_FIELD)
        if stored is not None and not isinstance(stored, dict):
            raise InputError(f"{folder / EVAL_INFO_NAME}: its {RUN_FIELD!r} is not a run identity (a JSON object)")
    if stored is None:
        return "predates run identities (its settings are unknown; `tavis report` still reads it)"
    return f"was played with {difference_text(stored, identity)}" if differences(stored, identity) else None
