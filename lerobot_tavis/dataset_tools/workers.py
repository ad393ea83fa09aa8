"""Process pools for the dataset tools: `workers` spawned processes, or the calling process when workers == 1.

A worker never outlives the process that started it (`lerobot_tavis.process`), so no orphan keeps recording or
holds staging files.
"""

from __future__ import annotations

import multiprocessing
import os
from concurrent.futures import Future, ProcessPoolExecutor

from lerobot_tavis import checks
from lerobot_tavis.process import die_with_parent


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


def executor(workers: int) -> InlineExecutor | ProcessPoolExecutor:
    """`workers` spawned processes (MuJoCo's EGL contexts and torch do not survive a fork), or inline for one."""
    if checks.integer("workers", workers, 1) == 1:
        return InlineExecutor()
    return ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"), initializer=die_with_parent,
                               initargs=(os.getpid(),))

