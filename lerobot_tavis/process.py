"""Worker processes never outlive the process that started them (kill -9 included). No heavy imports."""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import signal
import sys

_PR_SET_PDEATHSIG = 1  # from <linux/prctl.h>
MAX_NICENESS = 19  # Linux's lowest CPU priority; a process's niceness stops there


def die_with_parent(parent_pid: int) -> None:
    """Ask the kernel to kill this process when its parent dies (Linux); exit now if the parent is already gone."""
    if sys.platform.startswith("linux"):
        libc = ctypes.CDLL(None, use_errno=True)
        if libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL) != 0:
            raise OSError(ctypes.get_errno(), "prctl(PR_SET_PDEATHSIG) failed")
    if os.getppid() != parent_pid:  # the parent died before the request took effect
        os._exit(1)


def bind_worker_to_parent() -> None:
    """In a multiprocessing worker (not in a main process): die with the parent that started it, and leave Ctrl-C
    to it (`leave_interrupt_to_parent`)."""
    if multiprocessing.parent_process() is not None:
        die_with_parent(os.getppid())
        leave_interrupt_to_parent()


def leave_interrupt_to_parent() -> None:
    """In a worker: Ctrl-C ends this process quietly (SystemExit, whose exit multiprocessing does not report)
    instead of raising KeyboardInterrupt, which printed a traceback per worker. The terminal sends SIGINT to
    every process of its group; the main process reports it once and unwinds, removing its staging copies."""
    signal.signal(signal.SIGINT, _exit_quietly)


def alive(pid: int) -> bool:
    """Whether process `pid` exists (another user's counts)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _exit_quietly(signum, frame) -> None:
    raise SystemExit(128 + signum)
