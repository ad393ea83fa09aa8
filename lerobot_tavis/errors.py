"""Errors caused by the user's input or surroundings; the `tavis` command reports them in one line.

The family is TavisError and its subclasses: a bad option or config value (FieldError), other input that cannot be
used, such as a damaged or foreign file (InputError), a path that is missing or already there (PathNotFoundError,
PathExistsError), and a few modules' own (damaged raw episodes, a replay that differs from its recording, an
unreachable Hub, no display, OpenGL or gamepad). Those replacing a built-in exception also subclass it (FieldError
and InputError are ValueErrors), so `except ValueError` keeps working. The operating system's refusals caused by the
surroundings (a read-only or full disk, a file where a directory should be, a name too long: SURROUNDINGS_ERRNOS)
are reported in one line too (`surroundings_message`). Any other exception is a bug: the `tavis` command lets it
through with its traceback.
"""

from __future__ import annotations

import errno
import os
from pathlib import Path

# OSError numbers that say what is wrong with the file system the command was given, not with the command.
SURROUNDINGS_ERRNOS = frozenset({errno.EACCES, errno.EPERM, errno.EROFS, errno.ENOSPC, errno.EDQUOT, errno.EFBIG,
                                 errno.ENAMETOOLONG, errno.ENOTDIR, errno.EISDIR, errno.EEXIST})


class TavisError(Exception):
    """Base class: bad input, damaged files, a replay that differs from its recording, an unreachable Hub."""


class InputError(TavisError, ValueError):
    """Input the command cannot use: a bad combination of options, a file that is damaged or not what it should be,
    a download the command needs that is missing."""


class FieldError(InputError):
    """A bad value of one named field of a config or function; the `tavis` command names its option instead."""

    def __init__(self, field: str | FieldError, problem: str | None = None):
        if isinstance(field, FieldError) and problem is None:  # gymnasium re-raises a worker's error as type(e)(e)
            field, problem = field.field, field.problem
        super().__init__(f"{field} {problem}")
        self.field = field
        self.problem = problem

    def __reduce__(self):  # pickled whole, so that it crosses from a worker process intact
        return type(self), (self.field, self.problem)


class PathNotFoundError(TavisError, FileNotFoundError):
    """A file or directory the user named (or the install should hold) is not there."""


class PathExistsError(TavisError, FileExistsError):
    """A destination the user named is there already."""


def surroundings_message(error: OSError) -> str | None:
    """One line for an OSError whose number is in SURROUNDINGS_ERRNOS, naming the path when the error has one and
    the file standing where a directory is needed; None for any other OSError."""
    if error.errno not in SURROUNDINGS_ERRNOS:
        return None
    reason = os.strerror(error.errno)
    if error.filename is None:  # a write to an open file: ENOSPC, EDQUOT, EFBIG
        return f"{reason} (while writing)"
    path = Path(os.fsdecode(error.filename))
    if error.errno in (errno.ENOTDIR, errno.EEXIST):  # os.path's tests answer False where the system refuses
        in_the_way = next((p for p in (path, *path.parents) if os.path.exists(p) and not os.path.isdir(p)), None)
        if in_the_way is not None:
            return f"{in_the_way} is a file, not a directory" + ("" if in_the_way == path else f" (needed for {path})")
    return f"{path}: {reason}"
