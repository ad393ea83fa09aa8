"""Command options declared once, as dataclass fields; the `tavis` subcommands' parsers are generated from them.

A field is one option: its name gives the flag (`episodes_per_task` -> `--episodes-per-task`), its type the kind
(bool: a switch; int, float, Path: converted; a tuple: one or more values), its default the default (a field
without one is a required option). `option()` adds what the type cannot say: help text, choices (a callable is
called when the parser is built, so registered names count), another spelling, a positional argument, a function
turning the command-line text into the field's value. Options left out of the command line are not set by argparse:
the dataclass's own defaults apply. Every optional option's help ends with its default: written in the help text
where it says "default" (a default that needs words, such as None or one a `parse` function reads), else appended
from the field's value.
"""

from __future__ import annotations

import argparse
import dataclasses
import re
import types
import typing
from collections.abc import Callable, Sequence
from pathlib import Path

from lerobot_tavis import checks

KEY = "tavis_cli"  # where `option()` keeps its settings in a field's metadata


@dataclasses.dataclass(frozen=True)
class OptionSpec:
    """How a field appears on the command line; see `option()`."""

    help: str | None = None
    flag: str | None = None
    positional: bool = False
    choices: Sequence | Callable[[], Sequence] | None = None
    parse: Callable | None = None
    metavar: str | None = None
    nargs: str | None = None
    action: str | None = None
    command_line: bool = True


def option(default=dataclasses.MISSING, help: str | None = None, *, flag: str | None = None,
           positional: bool = False, choices=None, parse: Callable | None = None, metavar: str | None = None,
           nargs: str | None = None, action: str | None = None, command_line: bool = True, **field_kwargs):
    """A dataclass field with its command-line settings. `flag`: another spelling than `--<name>`; `positional`:
    an argument without flag (optional when the type admits None); `choices`: the accepted values, or a function
    returning them; `parse`: turns the parsed text (a list for several values) into the field's value, raising a
    FieldError naming the field; `nargs`, `action`, `metavar` go to argparse as they are; `command_line=False`
    keeps the field off the command line. Other keywords (`default_factory`, `kw_only`) go to `dataclasses.field`."""
    spec = OptionSpec(help, flag, positional, choices, parse, metavar, nargs, action, command_line)
    return dataclasses.field(default=default, metadata={KEY: spec}, **field_kwargs)


def spec(field: dataclasses.Field) -> OptionSpec:
    """The command-line settings of `field` (the defaults for a field declared without `option()`)."""
    return field.metadata.get(KEY, OptionSpec())


def command_fields(cls: type) -> list[dataclasses.Field]:
    """The fields of `cls` that are options, in declaration order."""
    return [field for field in dataclasses.fields(cls) if spec(field).command_line]


def spelling(cls: type, name: str) -> str:
    """How the user writes field `name` of `cls`: its flag, or its name for a positional argument."""
    settings = next((spec(field) for field in dataclasses.fields(cls) if field.name == name), OptionSpec())
    return name if settings.positional else settings.flag or "--" + name.replace("_", "-")


def add_options(parser: argparse.ArgumentParser, cls: type) -> None:
    """Add an argument to `parser` for every option of the dataclass `cls`."""
    hints = typing.get_type_hints(cls)
    for field in command_fields(cls):
        settings, kind = spec(field), _without_none(hints[field.name])
        kwargs = {} if settings.parse else _inferred(kind)
        kwargs.update({key: value for key, value in (("help", _help(field, settings)), ("nargs", settings.nargs),
                                                     ("action", settings.action), ("metavar", settings.metavar))
                       if value is not None})
        if settings.choices is not None:
            kwargs["choices"] = list(settings.choices() if callable(settings.choices) else settings.choices)
        if settings.positional:
            if kind is not hints[field.name]:  # `X | None`: may be left out, then None
                kwargs.update(nargs="?", default=None)
            parser.add_argument(field.name, **kwargs)
            continue
        flag = spelling(cls, field.name)
        if not ("choices" in kwargs or "metavar" in kwargs or kwargs.get("action") == "store_true"):
            kwargs["metavar"] = flag.lstrip("-").replace("-", "_").upper()  # named after the flag, not the field
        required = field.default is dataclasses.MISSING and field.default_factory is dataclasses.MISSING
        parser.add_argument(flag, dest=field.name, required=required, default=argparse.SUPPRESS, **kwargs)


def from_args(cls: type, args: argparse.Namespace):
    """The dataclass `cls` built from the options given in `args` (parsed by a parser `add_options` made); text that
    is not UTF-8 (a path in another encoding) is refused, naming the field (`checks.utf8`)."""
    values = {}
    for field in command_fields(cls):
        if hasattr(args, field.name):
            value = getattr(args, field.name)
            value = tuple(value) if isinstance(value, list) else value  # argparse collects several as a list
            for text in value if isinstance(value, tuple) else (value,):
                if isinstance(text, (str, Path)):
                    checks.utf8(field.name, text)
            parse = spec(field).parse
            values[field.name] = parse(value) if parse is not None and value is not None else value
    return cls(**values)


class CommandParser(argparse.ArgumentParser):
    """A subcommand's parser whose arguments come from its options dataclass, added when the subcommand is parsed.
    `command` imports the subcommand's module and returns (options dataclass, run function): `tavis <command>`
    imports only that command's module, as its run would."""

    def __init__(self, *args, command: Callable[[], tuple[type, Callable]], **kwargs):
        super().__init__(*args, **kwargs)
        self.command = command
        self.options_added = False

    def load_options(self) -> type:
        """Add the arguments of the options dataclass (once); returns the dataclass, also parsed as `options`, with
        the run function as `run`."""
        options, run = self.command()
        if not self.options_added:
            add_options(self, options)
            self.set_defaults(options=options, run=run)
            self.options_added = True
        return options

    def parse_known_args(self, args=None, namespace=None):
        self.load_options()
        return super().parse_known_args(args, namespace)


# A help text that states its option's default: "default: <what>" or "default <value>" (not "LeRobot's default,").
STATES_DEFAULT = re.compile(r"\bdefault:?\s")


def _help(field: dataclasses.Field, settings: OptionSpec) -> str | None:
    """The option's help text, ending with "(default: <value>)" when the field has a default the text does not state
    and that reads as typed on the command line: off for a switch, a number, a word, a path, a list of them."""
    text = settings.help
    if field.default is not dataclasses.MISSING:
        default = field.default
    elif field.default_factory is not dataclasses.MISSING:
        default = field.default_factory()
    else:
        return text
    if (text and STATES_DEFAULT.search(text)) or settings.parse is not None or default is None or default == ():
        return text
    if default is False:
        shown = "off"
    elif isinstance(default, tuple):
        shown = " ".join(str(value) for value in default)
    else:
        shown = str(default)
    shown = f"(default: {shown})".replace("%", "%%")  # argparse formats help texts with %
    return f"{text} {shown}" if text else shown


def _without_none(kind):
    """`X | None` -> X; any other type as it is."""
    if typing.get_origin(kind) in (types.UnionType, typing.Union):
        rest = [arg for arg in typing.get_args(kind) if arg is not type(None)]
        return rest[0] if len(rest) == 1 else kind
    return kind


def _inferred(kind) -> dict:
    """argparse settings a type implies: a switch for bool, one or more values for a tuple, conversions."""
    if kind is bool:
        return {"action": "store_true"}
    if typing.get_origin(kind) is tuple:
        return {"nargs": "+", **_inferred(typing.get_args(kind)[0])}
    return {"type": kind} if kind in (int, float, Path) else {}
