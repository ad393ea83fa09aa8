"""Errors caused by the user's input or surroundings; the `tavis` command reports them in one line."""


class TavisError(Exception):
    """Base class: bad input, damaged files, a replay that differs from its recording, an unreachable Hub."""
