"""Files written whole or not at all: the content goes to a dot-named partial file beside the destination and is
renamed onto it when complete, so a reader sees the old file or the new one, never half of one; a failure removes
the partial file. (Whole directories are staged by `dataset_tools.staging`.)"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


@contextmanager
def atomic_path(path: str | Path, suffix: str = "") -> Iterator[Path]:
    """Yields the partial path to write (`.<name>.partial<suffix>` beside `path`; `suffix` keeps an extension for
    writers that infer the format from it, e.g. ".png"); moves it onto `path` when the block ends without error."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(f".{path.name}.partial{suffix}")
    try:
        yield partial
        os.replace(partial, path)
    finally:
        partial.unlink(missing_ok=True)


def write_text(path: str | Path, text: str) -> Path:
    with atomic_path(path) as partial:
        partial.write_text(text)
    return Path(path)


def write_bytes(path: str | Path, data: bytes) -> Path:
    with atomic_path(path) as partial:
        partial.write_bytes(data)
    return Path(path)
