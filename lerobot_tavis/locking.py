"""One run at a time per output directory: an exclusive lock on the hidden file `.<name>.lock` beside it.

The lock is the kernel's (`fcntl.flock`), held by the open file, so it goes with the process that took it, kill -9
included: no stale lock survives a dead run. The file holds its holder's pid and command line, which a refused run
quotes, and is removed when the run ends; it lies beside the directory, not in it, because staged outputs replace
the whole directory when they are complete (`staging`). Linux and macOS; no heavy imports.
"""

from __future__ import annotations

import fcntl
import os
import shlex
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from lerobot_tavis.atomic import hidden_stem
from lerobot_tavis.errors import InputError


class OutputInUseError(InputError):
    """Another live process writes the same output directory."""


def lock_path(directory: str | Path) -> Path:
    """`.<name>.lock` beside `directory`, links resolved: two spellings of one directory share its lock (a name too
    long for that is shortened as `atomic.hidden_stem` does)."""
    directory = Path(directory).resolve()
    return directory.with_name(f".{hidden_stem(directory.name, len('lock'))}.lock")


RETRY_S = 0.1  # how often a waiting process tries the lock again


@contextmanager
def exclusive_output(directory: str | Path, wait_s: float = 0.0) -> Iterator[None]:
    """Hold `directory`'s lock for the block; OutputInUseError naming the holder (pid, command line) when another
    process still holds it after `wait_s` seconds (0: refused at once). The directory itself is neither needed nor
    created; its parent is. The lock file is removed when the block ends (a killed run leaves it, unlocked: the next
    run takes it over)."""
    path = lock_path(directory)
    fd = _locked_within(path, Path(directory), wait_s)
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"pid {os.getpid()} ({shlex.join(_command_line())})\n".encode(), 0)
        yield
    finally:
        path.unlink(missing_ok=True)  # while still locked: a run that opened it before fails, or finds it gone
        os.close(fd)  # releases the lock


def _locked_within(path: Path, directory: Path, wait_s: float) -> int:
    """`_locked`, tried again every RETRY_S while another process holds the lock, until `wait_s` seconds have passed."""
    deadline = time.monotonic() + wait_s
    while True:
        try:
            return _locked(path, directory)
        except OutputInUseError:
            if time.monotonic() >= deadline:
                raise
            time.sleep(RETRY_S)


def _locked(path: Path, directory: Path) -> int:
    """An open descriptor of the lock file `path`, locked by this process."""
    while True:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as error:  # reported as the output's own: read-only, a file in the way, a name too long
            raise OSError(error.errno, error.strerror, str(directory)) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 4096, 0).decode(errors="replace").strip() or "another process"
            os.close(fd)
            raise OutputInUseError(f"{directory} is in use by {holder}: wait for it to end, or give another output "
                                   "directory") from None
        try:
            if os.path.samestat(os.fstat(fd), os.stat(path)):
                return fd
        except FileNotFoundError:
            pass
        os.close(fd)  # its holder removed the file between our open and our lock: lock the new one


def _command_line() -> list[str]:
    """This process's command line as typed: `tavis ...` for the console script and `python -m lerobot_tavis.cli`."""
    program = Path(sys.argv[0]).name if sys.argv and sys.argv[0] else "python"
    return ["tavis" if program in ("tavis", "cli.py") else program, *sys.argv[1:]]
