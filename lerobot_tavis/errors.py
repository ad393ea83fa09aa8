"""Errors caused by the user's input or surroundings; the `tavis` command reports them in one line."""


class TavisError(Exception):
    """Base class: bad input, damaged files, a replay that differs from its recording, an unreachable Hub."""


class FieldError(TavisError, ValueError):
    """A bad value of one named field of a config or function; the `tavis` command names its option instead."""

    def __init__(self, field: str, problem: str):
        super().__init__(f"{field} {problem}")
        self.field = field
        self.problem = problem
