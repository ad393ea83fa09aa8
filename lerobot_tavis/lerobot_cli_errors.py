"""One line, not a traceback, for a bad `--env.*` value of `--env.type=tavis` in a LeRobot CLI, and for the plugin's
other refusals there.

LeRobot's CLIs build their config with draccus, which wraps an error raised while `TavisEnvConfig` checks its fields
(a `FieldError` naming the field and what it accepts) in a ParsingError that no LeRobot entry point catches: the user
saw a 56-line traceback around the one line that matters. `report_env_field_errors` installs an exception hook that
prints that line as `<command>: error: --env.<field> <problem>` (exit status 1, as before), and any other TavisError
(the user's input, e.g. an env that does not fit the checkpoint of `--policy.path`) as `<command>: error: <message>`;
any other exception keeps its traceback.
"""

from __future__ import annotations

import os
import sys

from lerobot_tavis.errors import FieldError, TavisError


def env_field_error(error: BaseException) -> FieldError | None:
    """The FieldError of `TavisEnvConfig` that `error` (draccus's ParsingError) wraps, else None."""
    cause = error.__cause__
    if type(error).__name__ == "ParsingError" and "TavisEnvConfig" in str(error) and isinstance(cause, FieldError):
        return cause
    return None


def _hook(previous):
    def report(kind, error, traceback):
        field_error = env_field_error(error)
        if field_error is not None:
            line = f"--env.{field_error.field} {field_error.problem}"
        elif isinstance(error, TavisError):
            line = str(error)
        else:
            return previous(kind, error, traceback)
        print(f"{os.path.basename(sys.argv[0])}: error: {line}", file=sys.stderr)
        return None

    report.tavis_env_field_errors = True
    return report


def report_env_field_errors() -> None:
    """Install the exception hook in this process (once)."""
    if not getattr(sys.excepthook, "tavis_env_field_errors", False):
        sys.excepthook = _hook(sys.excepthook)
