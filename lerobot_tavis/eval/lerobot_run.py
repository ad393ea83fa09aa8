"""One lerobot-eval run inside this process, filming as many episodes as its env config's `filmed_envs`.

LeRobot's `eval_main` films the first 10 episodes of every task, and while it films a batch it holds every frame of
the batch's filmed episodes in memory, then a second, stacked copy while the videos are written: two copies of 10
episodes of 400 frames per run, more memory than several jobs sharing one GPU machine have. `evaluate` builds the
run exactly as `eval_main` does (LeRobot's env, policy and processors from the same `EvalPipelineConfig`), then calls
LeRobot's `eval_policy_all` filming the episodes of the sub-envs that draw frames (`TavisEnvConfig.filmed_envs`); it
writes the same `eval_info.json`. With `filmed_envs=0` no frame is rendered for a video at all.

LeRobot's own progress bars (one per batch and one per rollout, nested) are off: the caller draws one bar for its
whole run (`tavis eval`'s `cell_runs`). Its rollout converts each step's camera images from uint8 to float on the
device instead of the CPU (`images_converted_on`), to the same values as LeRobot's own conversion. A process that runs
one task after another (`tavis eval --policy`'s jobs) can keep its env workers between runs (`keep_workers`): the
next run's task and split are built in the same worker processes.
"""

from __future__ import annotations

import json
import logging
import multiprocessing.util
from contextlib import contextmanager, nullcontext
from pathlib import Path

import numpy as np

from lerobot_tavis.atomic import write_text
from lerobot_tavis.envs.vector import LazyAsyncVectorEnv
from lerobot_tavis.eval.outputs import EVAL_INFO_NAME

_KEPT: dict[tuple, LazyAsyncVectorEnv] = {}  # this process's kept one-task async batch, by what fixes its workers


def pipeline_config(**fields):
    """LeRobot's `EvalPipelineConfig(**fields)` for a policy config whose `pretrained_path` is set. Its constructor
    looks for `--policy.path` on the command line and, not finding it there, warns that the policy will be built
    with random weights, which is not so here: that one warning is dropped."""
    from lerobot.configs.eval import EvalPipelineConfig

    if fields["policy"].pretrained_path is None:
        raise ValueError("pipeline_config: the policy config has no pretrained_path")
    logger = logging.getLogger("lerobot.configs.eval")
    drop = _DropMessage("No pretrained path was provided")
    logger.addFilter(drop)
    try:
        return EvalPipelineConfig(**fields)
    finally:
        logger.removeFilter(drop)


class _DropMessage(logging.Filter):
    """Drops the log records whose message starts with `prefix`."""

    def __init__(self, prefix: str):
        super().__init__()
        self.prefix = prefix

    def filter(self, record: logging.LogRecord) -> bool:
        return not record.getMessage().startswith(self.prefix)


@contextmanager
def images_converted_on(device):
    """Within the context, lerobot-eval's rollout sends each step's camera images to `device` (a torch device) as
    uint8 and makes them channel-first float in [0, 1] there; the other observation entries go through LeRobot's
    `preprocess_observation` unchanged.

    LeRobot converts them on the CPU, in the process that also runs the policy, and its device processor then
    copies four times the bytes to the GPU, while that job's envs wait. Here each pixel value looks up
    its float in a table that LeRobot's CPU conversion computed (a division by 255 on the GPU rounds 126 of the 256
    values differently, like a multiplication by the reciprocal), so the tensors are the same, already on `device`."""
    import torch
    from lerobot.scripts import lerobot_eval
    from lerobot.utils.constants import OBS_IMAGES

    lerobots = lerobot_eval.preprocess_observation
    levels = lerobots({"pixels": {"all": np.arange(256, dtype=np.uint8).reshape(1, 16, 16, 1)}})
    floats = levels[f"{OBS_IMAGES}.all"].flatten().to(device)  # floats[v]: LeRobot's float for pixel value v

    def to_float(image):
        batch = torch.from_numpy(image).to(device)
        if batch.ndim == 3:  # one env, not a vector env
            batch = batch.unsqueeze(0)
        if batch.dtype != torch.uint8 or batch.shape[-1] >= min(batch.shape[1:3]):
            raise ValueError(f"camera images must be uint8, channel last; got {batch.dtype} {tuple(batch.shape)}")
        return floats[batch.permute(0, 3, 1, 2).int()]

    def preprocess(observations: dict) -> dict:
        pixels = observations.get("pixels")
        if not isinstance(pixels, dict):
            return lerobots(observations)
        converted = {f"{OBS_IMAGES}.{name}": to_float(image) for name, image in pixels.items()}
        converted.update(lerobots({key: value for key, value in observations.items() if key != "pixels"}))
        return converted

    lerobot_eval.preprocess_observation = preprocess
    try:
        yield
    finally:
        lerobot_eval.preprocess_observation = lerobots


@contextmanager
def without_lerobot_progress_bars():
    """Within the context, lerobot-eval draws no progress bar: its bars are off where `inside_slurm()` says so."""
    from lerobot.scripts import lerobot_eval

    inside_slurm = lerobot_eval.inside_slurm
    lerobot_eval.inside_slurm = lambda: True
    try:
        yield
    finally:
        lerobot_eval.inside_slurm = inside_slurm


def close_kept_envs() -> None:
    """Stop the env workers this process kept for a next run."""
    while _KEPT:
        _KEPT.popitem()[1].close()


# At exit, before multiprocessing terminates this process's daemonic children (the env workers): an atexit hook
# ran after that in pool worker processes, and its close found the workers' pipes broken.
multiprocessing.util.Finalize(None, close_kept_envs, exitpriority=10)


def _env_batches(cfg, keep_workers: bool) -> tuple[dict, bool]:
    """make_env's batches for `cfg`, and whether they are kept for a next run. With `keep_workers`, a one-task async
    batch stays started after the run, and the next run with the same robot, camera mode, image size, episode length,
    shadows, batch size and worker niceness retargets its workers to its own task and split instead of starting new
    ones: starting a batch's workers (imports, EGL contexts, scenes) leaves the GPU idle at every chunk."""
    from lerobot.envs import make_env

    env = cfg.env
    key = (env.robot, env.camera_mode, tuple(env.image_size), env.episode_length_s, env.shadows, env.worker_niceness,
           cfg.eval.batch_size)
    if keep_workers and key in _KEPT:
        factories = [(suite, task_id, factory)
                     for suite, by_id in env.sub_env_factories().items() for task_id, factory in by_id.items()]
        if len(factories) == 1:
            suite, task_id, factory = factories[0]
            _KEPT[key].retarget([factory] * cfg.eval.batch_size, env.filmed_envs)
            return {suite: {task_id: _Lent(_KEPT[key])}}, True
    close_kept_envs()
    envs = make_env(env, n_envs=cfg.eval.batch_size, use_async_envs=cfg.eval.use_async_envs,
                    trust_remote_code=cfg.trust_remote_code)
    batches = [(suite, task_id, batch) for suite, by_id in envs.items() for task_id, batch in by_id.items()]
    if keep_workers and len(batches) == 1 and isinstance(batches[0][2], LazyAsyncVectorEnv):
        suite, task_id, batch = batches[0]
        _KEPT[key] = batch
        return {suite: {task_id: _Lent(batch)}}, True
    return envs, False


class _Lent:
    """A kept batch as one run sees it: everything but `close`, which LeRobot's `eval_policy_all` calls after each
    task, and which here leaves the workers started for the next run."""

    def __init__(self, batch: LazyAsyncVectorEnv):
        self._batch = batch

    def __getattr__(self, name: str):
        return getattr(self._batch, name)

    def close(self) -> None:
        return None


def evaluate(cfg, keep_workers: bool = False) -> None:
    """Run the evaluation `cfg` (a LeRobot `EvalPipelineConfig` of the tavis env), filming the first
    `cfg.env.filmed_envs` episodes of each task into `<output_dir>/videos/`; write `<output_dir>/eval_info.json`.
    With `keep_workers` a one-task async batch's workers outlive the run, for this process's next one
    (`close_kept_envs` stops them; they also stop when the process exits)."""
    import torch
    from lerobot.envs import close_envs, make_env_pre_post_processors
    from lerobot.policies import make_policy, make_pre_post_processors
    from lerobot.scripts.lerobot_eval import eval_policy_all
    from lerobot.utils.device_utils import get_safe_torch_device
    from lerobot.utils.random_utils import set_seed

    device = get_safe_torch_device(cfg.policy.device)
    torch.backends.cudnn.benchmark = True  # as eval_main sets them, so that results equal a lerobot-eval run's
    torch.backends.cuda.matmul.allow_tf32 = True
    set_seed(cfg.seed)
    envs, kept = _env_batches(cfg, keep_workers)
    finished = False
    try:
        policy = make_policy(cfg=cfg.policy, env_cfg=cfg.env, rename_map=cfg.rename_map)
        policy.eval()
        preprocessor, postprocessor = make_pre_post_processors(
            policy_cfg=cfg.policy, pretrained_path=cfg.policy.pretrained_path,
            preprocessor_overrides={"device_processor": {"device": str(policy.config.device)},
                                    "rename_observations_processor": {"rename_map": cfg.rename_map}})
        env_preprocessor, env_postprocessor = make_env_pre_post_processors(env_cfg=cfg.env, policy_cfg=cfg.policy)
        autocast = torch.autocast(device_type=device.type) if cfg.policy.use_amp else nullcontext()
        with torch.no_grad(), autocast, images_converted_on(device), without_lerobot_progress_bars():
            info = eval_policy_all(envs=envs, policy=policy, env_preprocessor=env_preprocessor,
                                   env_postprocessor=env_postprocessor, preprocessor=preprocessor,
                                   postprocessor=postprocessor, n_episodes=cfg.eval.n_episodes,
                                   max_episodes_rendered=cfg.env.filmed_envs,
                                   videos_dir=Path(cfg.output_dir) / "videos",
                                   start_seed=cfg.seed, max_parallel_tasks=cfg.env.max_parallel_tasks)
        finished = True
    finally:
        if not kept:
            close_envs(envs)
        elif not finished:  # workers stopped mid-rollout are not reused
            close_kept_envs()
    write_text(Path(cfg.output_dir) / EVAL_INFO_NAME, json.dumps(info, indent=2))
