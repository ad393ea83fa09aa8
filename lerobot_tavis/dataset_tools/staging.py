"""Write a directory completely or not at all: build it beside its destination, then move it into place."""

from __future__ import annotations

import contextlib
import os
import shutil
import uuid
from collections.abc import Iterator
from pathlib import Path


@contextlib.contextmanager
def staged_directory(destination: str | Path, *, overwrite: bool = False) -> Iterator[Path]:
    """Yield a fresh path (not yet created) next to `destination`; when the block ends without error it becomes
    `destination`, otherwise it is removed. An existing destination is an error unless `overwrite`, and is then
    replaced only once the new one is complete."""
    destination = Path(destination).absolute()
    if destination.exists() and not overwrite:
        raise FileExistsError(f"{destination} already exists (pass --overwrite to replace it)")
    destination.parent.mkdir(parents=True, exist_ok=True)
    staging = destination.with_name(f".{destination.name}.partial-{uuid.uuid4().hex[:8]}")
    try:
        yield staging
        if destination.exists():
            retired = destination.with_name(f".{destination.name}.old-{uuid.uuid4().hex[:8]}")
            os.replace(destination, retired)
            os.replace(staging, destination)
            shutil.rmtree(retired)
        else:
            os.replace(staging, destination)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
