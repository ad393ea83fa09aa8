"""One private temporary directory per `tavis` process, holding what it and its worker processes put in the
system's temporary directory: the evaluation's chunk scratch folders (`tavis-chunk-*`), multiprocessing's
`pymp-*` folders, and the `tmp*.json` files LeRobot writes each time it reads a policy config and never removes.

`use_private_tempdir` points TMPDIR (inherited by every process started afterwards) and Python's `tempfile` at
`<system temp>/tavis-run-<pid>-<random>/`, which is removed when the process exits; a folder left by a killed run
(kill -9: nothing runs) is removed by the next `tavis` run, which tells it by its process id, no longer alive. It
stays in the system temp directory rather than in the output directory because multiprocessing puts its sockets
there, and a socket's path must fit in 108 bytes.
"""

from __future__ import annotations

import multiprocessing.util
import os
import shutil
import tempfile
from pathlib import Path

from lerobot_tavis.process import alive

PREFIX = "tavis-run-"
# Removes the folder after multiprocessing's own exit clean-up (priority -100: this process's `pymp-*` folder,
# which stays in use until then).
_REMOVAL_PRIORITY = -200


def use_private_tempdir() -> Path:
    """Send this process's temporary files, and those of the processes it starts from now on, to a folder of its
    own, removed at exit (once per process: later calls return the same folder). Removes the folders of `tavis`
    processes that no longer run first."""
    current = Path(tempfile.gettempdir())
    if current.name.startswith(f"{PREFIX}{os.getpid()}-"):
        return current
    remove_dead_tempdirs(current)
    private = Path(tempfile.mkdtemp(prefix=f"{PREFIX}{os.getpid()}-", dir=current))
    multiprocessing.util.Finalize(None, shutil.rmtree, args=(private,), kwargs={"ignore_errors": True},
                                  exitpriority=_REMOVAL_PRIORITY)
    os.environ.setdefault("RAY_TMPDIR", str(current))  # a local Ray keeps its sessions (and short socket paths)
    os.environ["TMPDIR"] = str(private)
    tempfile.tempdir = str(private)
    return private


def remove_dead_tempdirs(base: Path) -> list[Path]:
    """Remove the private temporary folders under `base` whose process is gone; returns them."""
    removed = []
    for folder in base.glob(f"{PREFIX}*-*"):
        pid = folder.name[len(PREFIX):].split("-")[0]
        if folder.is_dir() and pid.isdigit() and not alive(int(pid)):
            shutil.rmtree(folder, ignore_errors=True)
            removed.append(folder)
    return removed
