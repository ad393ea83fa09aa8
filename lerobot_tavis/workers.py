"""Where jobs run: the calling process, local worker processes, or a Ray cluster.

Every job here is a picklable call whose result depends only on its arguments and is returned to the calling
process, which alone writes files. So the backend, the number of workers and the order in which jobs finish never
change what is written, and a Ray cluster needs no filesystem shared with the caller.

- `local`: `workers` spawned processes, or the calling process when workers == 1. A worker never outlives the
  process that started it (`lerobot_tavis.process`), so no orphan keeps recording or holds staging files. With
  `share_cpus`, each worker runs on its own share of the caller's CPUs (`cpu_share`): libraries that start one
  thread per CPU they may use (FFmpeg's AV1 decoder starts about 1.5 per CPU for every video it opens) then start
  a few, not one per core of the machine in every worker (on 64 cores, thousands of threads fighting over them).
  Only for jobs whose results do not depend on a thread count: a video encoder's output does.
- `ray`: Ray tasks, on the cluster named by `RAY_ADDRESS` (`ray start --head` on one node, `ray start
  --address=...` on the others), else on a Ray instance started on this machine for the run. Install with
  `pip install 'lerobot_env_tavis[ray]'`; docs/scaling.md.
"""

from __future__ import annotations

import multiprocessing.context
import os
from concurrent.futures import Future, ProcessPoolExecutor

from lerobot_tavis import checks
from lerobot_tavis.errors import TavisError
from lerobot_tavis.process import MAX_NICENESS, die_with_parent, interrupt_deferred, leave_interrupt_to_parent

BACKENDS = ("local", "ray")


class InlineExecutor:
    """Runs submitted calls at once in this process (workers=1: no process start-up, easy to debug)."""

    def submit(self, fn, *args) -> Future:
        future = Future()
        future.set_result(fn(*args))
        return future

    def shutdown(self, wait: bool = True, cancel_futures: bool = False) -> None:
        return None

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        return None


class RayExecutor:
    """`submit` sends the call to Ray as a task needing `cpus` CPUs and `gpus` GPUs (a fraction shares one GPU).

    Ray schedules as many tasks at once as the cluster's resources allow. Worker processes get `MUJOCO_GL` from
    this process (default egl).
    """

    def __init__(self, cpus: float = 1.0, gpus: float = 0.0):
        try:
            import ray
        except ImportError:
            raise TavisError("--backend ray needs Ray: pip install 'lerobot_env_tavis[ray]'") from None
        self._ray = ray
        self._options = {"num_cpus": cpus, "num_gpus": gpus, "max_retries": 0}
        self._pending: list = []
        self._remote: dict = {}  # fn -> its Ray remote function, registered once
        self._started_ray = False

    def __enter__(self):
        if not self._ray.is_initialized():
            env = {"MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
            self._ray.init(address=os.environ.get("RAY_ADDRESS"), runtime_env={"env_vars": env},
                           log_to_driver=False, include_dashboard=False, logging_level="ERROR")
            self._started_ray = True
        return self

    def submit(self, fn, *args) -> Future:
        if fn not in self._remote:
            self._remote[fn] = self._ray.remote(**self._options)(fn)
        ref = self._remote[fn].remote(*args)
        self._pending.append(ref)
        return ref.future()

    def shutdown(self, wait: bool = True, cancel_futures: bool = False) -> None:
        if cancel_futures:
            for ref in self._pending:
                self._ray.cancel(ref, force=True)
        self._pending.clear()

    def __exit__(self, *exc) -> None:
        self.shutdown(cancel_futures=True)
        if self._started_ray:
            self._ray.shutdown()


def usable_cores() -> int:
    """The CPUs this process may run on (its affinity: `taskset`, a container's cpuset), not the machine's count."""
    return len(os.sched_getaffinity(0))


def executor(workers: int, backend: str = "local", gpus_per_job: float = 0.0, niceness: int = 0,
             share_cpus: bool = False):
    """The pool for `backend`: local spawned processes (MuJoCo's EGL contexts and torch do not survive a fork), or
    inline for one worker; Ray ignores `workers` and runs what the cluster's resources allow. Local worker
    processes add `niceness` to their niceness (as `nice`: 19 runs them only on cores nothing else wants); the
    calling process and Ray's workers keep theirs. `share_cpus`: each local worker on its own share of the CPUs."""
    checks.integer("workers", workers, 1)
    checks.integer("niceness", niceness, 0, MAX_NICENESS)
    if checks.choice("backend", backend, BACKENDS) == "ray":
        return RayExecutor(gpus=gpus_per_job)
    if workers == 1:
        return InlineExecutor()
    context = _SpawnContext()
    # (workers started so far, each taking the next share; the CPUs shared out)
    sharing = (context.Value("i", 0), sorted(os.sched_getaffinity(0))) if share_cpus else None
    return ProcessPoolExecutor(workers, mp_context=context, initializer=_start_local_worker,
                               initargs=(os.getpid(), niceness, workers, sharing))


def cpu_share(index: int, workers: int, cpus: list[int]) -> set[int]:
    """The CPUs worker `index` (0-based) of `workers` runs on: every `workers`-th of `cpus` from its index on, so
    the shares cover `cpus` and differ; with more workers than CPUs, one CPU (`index` modulo their number)."""
    share = cpus[index % workers::workers] if workers <= len(cpus) else []
    return set(share or [cpus[index % len(cpus)]])


class _SpawnedWorker(multiprocessing.context.SpawnProcess):
    """A spawned process that starts with Ctrl-C held back: one while it imports waits until it has been told to
    end quietly on one (`_start_local_worker`), instead of printing a KeyboardInterrupt traceback."""

    def start(self) -> None:
        with interrupt_deferred():
            super().start()


class _SpawnContext(multiprocessing.context.SpawnContext):
    Process = _SpawnedWorker


def _start_local_worker(parent_pid: int, niceness: int, workers: int, sharing: tuple | None) -> None:
    die_with_parent(parent_pid)
    leave_interrupt_to_parent()
    if niceness:
        os.nice(niceness)
    if sharing is None:
        return
    started, cpus = sharing
    with started.get_lock():
        index = started.value
        started.value += 1
    os.sched_setaffinity(0, cpu_share(index, workers, cpus))
