"""Options declared as dataclass fields: the parser `add_options` generates, and the dataclass `from_args` builds."""

import argparse
from dataclasses import dataclass
from pathlib import Path

import pytest

from lerobot_tavis.cli_options import CommandParser, add_options, command_fields, from_args, option, spelling
from lerobot_tavis.errors import FieldError

COLOURS = ["red", "green"]


def _pair(text: str) -> tuple[int, int]:
    left, sep, right = text.partition(",")
    if not (sep and left.isdigit() and right.isdigit()):
        raise FieldError("pair", f"must be A,B, got {text!r}")
    return int(left), int(right)


@dataclass(frozen=True)
class Toy:
    source: Path | None = option(help="where from", positional=True)
    name: str = option(help="required: no default")
    count: int = 3
    ratio: float = option(0.5, "a fraction")
    loud: bool = option(False, "a switch")
    colours: tuple[str, ...] = option(("red",), choices=lambda: COLOURS)
    sizes: tuple[int, ...] | None = None
    pair: tuple[int, int] = option((1, 2), "A,B", parse=_pair)
    n_items: int = option(1, flag="--items")
    internal: float = option(9.0, command_line=False)


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="toy")
    add_options(parser, Toy)
    return parser


def _parsed(argv: list[str]) -> Toy:
    return from_args(Toy, _parser().parse_args(argv))


def test_every_field_is_an_option_spelled_after_its_name_unless_declared_otherwise():
    flags = {action.dest: action.option_strings for action in _parser()._actions if action.dest != "help"}
    assert flags == {"source": [], "name": ["--name"], "count": ["--count"], "ratio": ["--ratio"], "loud": ["--loud"],
                     "colours": ["--colours"], "sizes": ["--sizes"], "pair": ["--pair"], "n_items": ["--items"]}
    assert [f.name for f in command_fields(Toy)] == list(flags)  # `internal` stays off the command line
    assert spelling(Toy, "n_items") == "--items" and spelling(Toy, "source") == "source"
    assert spelling(Toy, "not_a_field") == "--not-a-field"


def test_left_out_options_take_the_dataclass_defaults():
    assert _parsed(["--name", "x"]) == Toy(source=None, name="x")


def test_types_convert_and_parse_functions_read_the_text():
    toy = _parsed(["src", "--name", "x", "--count", "4", "--ratio", "0.25", "--loud", "--colours", "green", "red",
                   "--sizes", "1", "2", "--pair", "3,4", "--items", "5"])
    assert toy == Toy(source=Path("src"), name="x", count=4, ratio=0.25, loud=True, colours=("green", "red"),
                      sizes=(1, 2), pair=(3, 4), n_items=5)
    with pytest.raises(FieldError, match="pair must be A,B, got 'x'"):
        _parsed(["--name", "x", "--pair", "x"])


def test_argparse_refuses_what_the_declaration_excludes(capsys):
    for argv, message in ((["--count", "4"], "the following arguments are required: --name"),
                          (["--name", "x", "--count", "four"], "argument --count: invalid int value: 'four'"),
                          (["--name", "x", "--colours", "blue"], "argument --colours: invalid choice: 'blue'"),
                          (["--name", "x", "--internal", "1"], "unrecognized arguments: --internal")):
        with pytest.raises(SystemExit):
            _parser().parse_args(argv)
        assert message in capsys.readouterr().err


def test_choices_are_read_when_the_parser_is_built(monkeypatch):
    monkeypatch.setattr(f"{__name__}.COLOURS", ["red", "green", "blue"])
    assert _parsed(["--name", "x", "--colours", "blue"]).colours == ("blue",)


def test_a_field_added_to_the_dataclass_appears_on_the_command_line():
    @dataclass(frozen=True)
    class Grown(Toy):
        speed_m_s: float = option(1.0, "a new option")

    parser = argparse.ArgumentParser()
    add_options(parser, Grown)
    assert from_args(Grown, parser.parse_args(["--name", "x", "--speed-m-s", "2"])).speed_m_s == 2.0
    assert "--speed-m-s SPEED_M_S" in parser.format_help() and "a new option" in parser.format_help()


def test_a_command_parser_adds_its_options_when_first_parsed():
    loaded = []

    def toy_command():
        loaded.append(Toy)
        return Toy, print

    parser = CommandParser(prog="toy", command=toy_command)
    assert parser.options_added is False and loaded == []
    args = parser.parse_args(["--name", "x"])
    assert parser.options_added and args.options is Toy and args.run is print
    assert from_args(args.options, args) == Toy(source=None, name="x")
