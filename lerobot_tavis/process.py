"""Worker processes never outlive the process that started them (kill -9 included), leave Ctrl-C to it and need
not import its main script; threads that cannot make themselves real-time; whether a process is alive. No heavy
imports."""

from __future__ import annotations

import contextlib
import ctypes
import multiprocessing
import os
import signal
import sys
import threading
from collections.abc import Iterator

_PR_SET_PDEATHSIG = 1  # from <linux/prctl.h>
_CAP_SYS_NICE = 23  # from <linux/capability.h>: may raise a thread's scheduling priority (real-time included)
_CAPABILITY_VERSION_3 = 0x20080522  # capget/capset's header version for 64 capability bits (two 32-bit words)
MAX_NICENESS = 19  # Linux's lowest CPU priority; a process's niceness stops there


class _CapabilityHeader(ctypes.Structure):
    _fields_ = [("version", ctypes.c_uint32), ("pid", ctypes.c_int)]


class _CapabilityWord(ctypes.Structure):
    _fields_ = [("effective", ctypes.c_uint32), ("permitted", ctypes.c_uint32), ("inheritable", ctypes.c_uint32)]


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
    """In a worker: Ctrl-C ends this process at once and quietly, instead of raising KeyboardInterrupt, which
    printed a traceback per worker. The terminal sends SIGINT to every process of its group; the main process,
    which alone writes files, reports it once and unwinds, removing its staging copies. A worker started with
    SIGINT blocked (`workers`, so that a Ctrl-C while it starts up waits) receives it from here on. A worker whose
    parent ignores SIGINT (a job a script started in the background) ignores it too, as the parent does."""
    if signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:  # inherited through exec, as the parent's is
        signal.signal(signal.SIGINT, _exit_quietly)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


@contextlib.contextmanager
def interrupt_deferred() -> Iterator[None]:
    """Within the block, Ctrl-C waits: a process started meanwhile begins with SIGINT blocked (the signal mask is
    inherited) until it calls `leave_interrupt_to_parent`, and a Ctrl-C that reached this process is handled when
    the block ends, not half-way through starting a process (its child then read a truncated start-up message)."""
    held = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    in_main_thread = threading.current_thread() is threading.main_thread()  # Python runs handlers there only
    arrived = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: arrived.append(signum)) if in_main_thread else None
    try:
        yield
    finally:
        if in_main_thread:
            signal.signal(signal.SIGINT, previous)
        signal.pthread_sigmask(signal.SIG_SETMASK, held)
        if arrived:
            signal.raise_signal(signal.SIGINT)


@contextlib.contextmanager
def children_skip_main_module() -> Iterator[None]:
    """Processes started (spawn or forkserver) within the block do not import this process's main script or module
    again. multiprocessing has each such child import the parent's `__main__`, so that objects pickled from it
    resolve: under `lerobot-eval` that is LeRobot's eval script, and with it torch and LeRobot in every child. Only
    for children whose pickled targets live in importable modules (the block hides `__main__`'s file and spec, as in
    an interactive session, whose children import no main either)."""
    main = sys.modules["__main__"]
    saved = {name: main.__dict__[name] for name in ("__file__", "__spec__") if name in main.__dict__}
    main.__dict__.pop("__file__", None)
    main.__spec__ = None
    try:
        yield
    finally:
        main.__dict__.update(saved)


@contextlib.contextmanager
def without_realtime_priority() -> Iterator[None]:
    """Within the block, this thread and the threads it starts cannot switch themselves to real-time scheduling.

    SVT-AV1 (LeRobot's AV1 encoder, through PyAV) moves the thread that opens an encoder to SCHED_FIFO at priority
    99 wherever the process may (root, as in containers and on cloud machines), and with it every thread the encoder
    then starts: encoding preempts everything else on those cores, rendering workers included, and a process that
    such a thread starts inherits the policy. The block takes the capability that allows it (CAP_SYS_NICE) out of
    this thread's effective set, which the threads it starts inherit, and gives it back at the end. Lowering a
    priority (`nice`) needs no capability. Where the capability is not held (not root, most containers), or off
    Linux, nothing changes."""
    held = sys.platform.startswith("linux") and _set_effective_capability(_CAP_SYS_NICE, False)
    try:
        yield
    finally:
        if held:
            _set_effective_capability(_CAP_SYS_NICE, True)


def _set_effective_capability(capability: int, effective: bool) -> bool:
    """Put `capability` in or out of this thread's effective set (out always works; in, if it is permitted);
    returns whether it was effective before."""
    libc = ctypes.CDLL(None, use_errno=True)
    header = _CapabilityHeader(_CAPABILITY_VERSION_3, 0)  # pid 0: the calling thread
    words = (_CapabilityWord * 2)()
    if libc.capget(ctypes.byref(header), words) != 0:
        raise OSError(ctypes.get_errno(), "capget failed")
    word, bit = divmod(capability, 32)
    was_effective = bool(words[word].effective & (1 << bit))
    if was_effective != effective:
        words[word].effective ^= 1 << bit
        if libc.capset(ctypes.byref(header), words) != 0:
            raise OSError(ctypes.get_errno(), "capset failed")
    return was_effective


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
    os._exit(128 + signum)
