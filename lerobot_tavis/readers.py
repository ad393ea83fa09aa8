"""Reading the files a command is given (JSON, JSON lines, Parquet) and checking what they hold.

A file that is missing, unreadable, damaged or of the wrong shape raises one InputError (PathNotFoundError when
missing) whose message starts with the file's path and names the line or field at fault, e.g.
`raw/manifest.json: episodes[1].seed must be an integer, got None`; the `tavis` command prints it as its one error
line. The callers (raw recordings, datasets, evaluation outputs) say what each file must hold.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Callable, Iterator
from pathlib import Path

from lerobot_tavis import checks
from lerobot_tavis.errors import FieldError, InputError, PathNotFoundError

# What a field must be, as `expect` checks it: a name for the message and a test. bool is no integer here.
KINDS: dict[str, tuple[str, Callable[[object], bool]]] = {
    "int": ("an integer", lambda v: isinstance(v, int) and not isinstance(v, bool)),
    "number": ("a finite number", lambda v: isinstance(v, (int, float)) and not isinstance(v, bool)
               and math.isfinite(v)),
    "bool": ("true or false", lambda v: isinstance(v, bool)),
    "str": ("a text", lambda v: isinstance(v, str)),
    "list": ("a list", lambda v: isinstance(v, list)),
    "object": ("an object", lambda v: isinstance(v, dict)),
}


def read_json(path: str | Path) -> object:
    """The content of a JSON file."""
    path = Path(path)
    try:
        return json.loads(path.read_bytes().decode())
    except FileNotFoundError:
        raise PathNotFoundError(f"{path}: missing") from None
    except UnicodeDecodeError:
        raise InputError(f"{path}: not a JSON file (not UTF-8 text)") from None
    except json.JSONDecodeError as error:
        raise InputError(f"{path}: not a JSON file ({error.msg}: line {error.lineno}, column {error.colno})") from None
    except OSError as error:
        raise InputError(f"{path}: unreadable ({error.strerror or error})") from None


def read_json_lines(path: str | Path) -> Iterator[tuple[int, object]]:
    """(line number, content) of every non-blank line of a JSON-lines file."""
    path = Path(path)
    try:
        lines = path.read_bytes().splitlines()
    except FileNotFoundError:
        raise PathNotFoundError(f"{path}: missing") from None
    except OSError as error:
        raise InputError(f"{path}: unreadable ({error.strerror or error})") from None
    for number, line in enumerate(lines, start=1):
        if not line.strip():
            continue
        try:
            yield number, json.loads(line.decode())
        except UnicodeDecodeError:
            raise InputError(f"{path}:{number}: not a JSON line (not UTF-8 text)") from None
        except json.JSONDecodeError as error:
            raise InputError(f"{path}:{number}: not a JSON line ({error.msg})") from None


def read_parquet(path: str | Path):
    """A Parquet file as a pyarrow Table, every page read."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    path = Path(path)
    if not path.is_file():
        raise PathNotFoundError(f"{path}: missing")
    try:
        return pq.read_table(path)
    except (pa.ArrowException, OSError) as error:
        reason = re.sub(r"^Could not open Parquet input source '.*?': ", "", str(error).splitlines()[0]).split(". ")[0]
        raise InputError(f"{path}: not a readable Parquet file ({reason})") from None


def expect(value, kind: str, path: str | Path, field: str, optional: bool = False):
    """`value` (the file's `field`) if it is of `kind` (a key of KINDS), or None when `optional`."""
    name, test = KINDS[kind]
    if (value is None and optional) or test(value):
        return value
    raise InputError(f"{path}: {field} must be {name}{' or null' if optional else ''}, got {_shown(value)}")


def get(document: dict, key: str, kind: str, path: str | Path, where: str = "", optional: bool = False):
    """`document[key]` checked by `expect`; a missing key is an error unless `optional`."""
    if key not in document and not optional:
        raise InputError(f"{path}: {where}{key} is missing")
    return expect(document.get(key), kind, path, where + key, optional)


def get_integer(document: dict, key: str, path: str | Path, where: str = "", minimum: int = 0) -> int:
    """`document[key]` as an int, refused unless it is a whole number >= `minimum` (`checks.integer`)."""
    return checked(lambda value: checks.integer(key, value, minimum), document.get(key), path, where + key)


def checked(check: Callable, value, path: str | Path, field: str):
    """`check(value)` (one of the project's checks, e.g. `robot_info`) with its error naming the file's `field`
    instead of the option the check is written for."""
    try:
        return check(value)
    except InputError as error:
        problem = f" {error.problem}" if isinstance(error, FieldError) else f": {error}"
        raise InputError(f"{path}: {field}{problem}") from None


def _shown(value) -> str:
    text = repr(value)
    return text if len(text) <= 60 else f"{text[:57]}..."
