"""Write a directory completely or not at all: build it beside its destination, then move it into place.

The staging copy is named `.<name>.partial-<pid>-<id>`, so a later run can tell the leftovers of a killed run
(whose process is gone) from those of a run still going, and removes them. Readers of finished outputs skip
dot-named directories. A name too long to take that suffix within the file system's limit is shortened in it
(`atomic.hidden_stem`).
"""

from __future__ import annotations

import contextlib
import glob
import os
import shutil
import uuid
from collections.abc import Iterator
from pathlib import Path

from lerobot_tavis.atomic import hidden_stem
from lerobot_tavis.errors import PathExistsError
from lerobot_tavis.process import alive

_LONGEST_TAG = "partial-4194304-0a1b2c3d"  # "<kind>-<pid>-<id>": Linux pids have at most 7 digits


@contextlib.contextmanager
def staged_directory(destination: str | Path, *, overwrite: bool = False) -> Iterator[Path]:
    """Yield a fresh path (not yet created) next to `destination`; when the block ends without error it becomes
    `destination`, otherwise it is removed. An existing destination is an error unless `overwrite`, and is then
    replaced only once the new one is complete."""
    destination = Path(destination).absolute()
    clear_leftovers(destination)
    if destination.exists() and not destination.is_dir():  # --overwrite replaces a result, never another file
        raise PathExistsError(f"{destination} is a file, not a directory")
    if destination.exists() and not overwrite:
        raise PathExistsError(f"{destination} already exists (pass --overwrite to replace it)")
    destination.parent.mkdir(parents=True, exist_ok=True)
    staging = _sibling(destination, "partial")
    try:
        yield staging
        if destination.exists():
            retired = _sibling(destination, "old")
            os.replace(destination, retired)
            os.replace(staging, destination)
            shutil.rmtree(retired)
        else:
            os.replace(staging, destination)
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def clear_leftovers(destination: Path) -> None:
    """Remove the staging copies that killed runs left beside `destination`; a run killed while swapping in its
    result leaves the previous destination retired: it is put back if nothing replaced it."""
    stem = _stem(destination)
    for leftover in sorted(destination.parent.glob(f".{glob.escape(stem)}.*-*-*")):
        kind, _, owner = leftover.name[len(stem) + 2:].partition("-")
        pid = owner.split("-")[0]
        if kind not in ("partial", "old") or not pid.isdigit() or alive(int(pid)):
            continue
        if kind == "old" and not destination.exists():
            os.replace(leftover, destination)
        else:
            shutil.rmtree(leftover, ignore_errors=True)


def _sibling(destination: Path, kind: str) -> Path:
    """A fresh `.<name>.<kind>-<pid>-<id>` beside `destination`: its staging copy, or its retired previous result."""
    return destination.with_name(f".{_stem(destination)}.{kind}-{os.getpid()}-{uuid.uuid4().hex[:8]}")


def _stem(destination: Path) -> str:
    return hidden_stem(destination.name, len(_LONGEST_TAG))
