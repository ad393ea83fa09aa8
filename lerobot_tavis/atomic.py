"""Files written whole or not at all: the content goes to a dot-named partial file beside the destination and is
renamed onto it when complete, so a reader sees the old file or the new one, never half of one; a failure removes
the partial file. (Whole directories are staged by `staging`.)"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

NAME_MAX_BYTES = 255  # the longest file name of Linux's file systems (ext4, xfs, btrfs, tmpfs), in bytes
NAME_HASH_CHARS = 16  # hex digits of a long name's SHA-256 kept in the names of its hidden siblings


def hidden_stem(name: str, tag_bytes: int) -> str:
    """What the hidden sibling `.<stem>.<tag>` of a file or directory called `name` starts with, for tags of at
    most `tag_bytes` bytes: `name` itself when the sibling's name fits in NAME_MAX_BYTES, else the start of `name`
    and a hash of all of it, so that a valid long name still gets siblings and two long names sharing a start do
    not share them."""
    encoded = os.fsencode(name)
    room = NAME_MAX_BYTES - len(b"..") - tag_bytes
    if len(encoded) <= room:
        return name
    digest = hashlib.sha256(encoded).hexdigest()[:NAME_HASH_CHARS]
    start = encoded[:room - len(digest) - 1].decode("utf-8", errors="ignore")  # never half a character
    return f"{start}~{digest}"


@contextmanager
def atomic_path(path: str | Path, suffix: str = "") -> Iterator[Path]:
    """Yields the partial path to write (`.<name>.partial<suffix>` beside `path`; `suffix` keeps an extension for
    writers that infer the format from it, e.g. ".png"); moves it onto `path` when the block ends without error."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tag = f"partial{suffix}"
    partial = path.with_name(f".{hidden_stem(path.name, len(os.fsencode(tag)))}.{tag}")
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
