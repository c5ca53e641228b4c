"""Long options are taken only as spelt in full, by every parser (``allow_abbrev=False``).

Was: argparse's default took an unambiguous prefix for the option, so ``--ren out.mp4`` was
``--render out.mp4``, silently, and an option added later could change what a prefix meant.
"""

from __future__ import annotations

import argparse
from collections.abc import Iterator
from pathlib import Path

import pytest

from experiments._common import experiment_parser
from pftrack.cli import build_parser, main


def _parsers(parser: argparse.ArgumentParser) -> Iterator[argparse.ArgumentParser]:
    """`parser` and every (sub-)command's parser below it."""
    yield parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub in dict.fromkeys(action.choices.values()):  # aliases: one parser
                yield from _parsers(sub)


def test_every_parser_refuses_abbreviations() -> None:
    parsers = list(_parsers(build_parser()))
    assert len(parsers) >= 10  # pftrack, its eight commands, experiment gaps
    assert [p.prog for p in parsers if p.allow_abbrev] == []


def test_the_cli_refuses_a_prefix_of_an_option_in_one_line_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "t.txt"
    with pytest.raises(SystemExit) as exc:
        main(["track", "x", "--ren", "y"])  # was: --render y, then "x" not found
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("pftrack track: error: ")
    assert "unrecognized arguments: --ren" in err and "--ren is not taken for --render" in err
    with pytest.raises(SystemExit) as exc:
        main(["track", "x", "--out", str(out), "--ren", "y"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err == (
        "pftrack track: error: unrecognized arguments: --ren y (--ren is not taken for "
        "--render: spell options in full)\n"
    )
    assert not out.exists()


def test_no_prefix_of_any_long_option_is_taken(capsys: pytest.CaptureFixture[str]) -> None:
    """Each long option's shortest and longest proper prefix (that is not an option itself) is
    refused, named, by its command (``pftrack experiment gaps --gr=1``: not ``--grid 1``)."""
    checked = 0
    for parser in _parsers(build_parser()):
        command = parser.prog.split()[1:]
        subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
        after = [next(iter(subs[0].choices))] if subs else []  # pftrack --qu=1 demo
        options = set(parser._option_string_actions)
        for option in sorted(o for o in options if o.startswith("--")):
            prefixes = [option[:end] for end in range(3, len(option))]
            prefixes = [p for p in prefixes if p not in options]
            for prefix in {prefixes[0], prefixes[-1]} if prefixes else ():  # shortest, longest
                with pytest.raises(SystemExit):
                    main([*command, f"{prefix}=1", *after])
                err = capsys.readouterr().err
                assert f"unrecognized arguments: {prefix}" in err, (parser.prog, prefix, err)
                checked += 1
    assert checked > 200


def test_an_experiments_parser_refuses_a_prefix_too(capsys: pytest.CaptureFixture[str]) -> None:
    parser = experiment_parser("gaps_demo", None)
    with pytest.raises(SystemExit) as exc:
        parser.parse_args(["--da", "x"])  # was: --data x
    assert exc.value.code == 2
    assert capsys.readouterr().err.endswith("error: unrecognized arguments: --da x\n")
