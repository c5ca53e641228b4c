"""README.md and docs/*.md as a reader follows them: every relative link and #anchor lands, the
set-up commands are the ones CI runs, every ``pftrack`` command of the README's bash blocks is
one the parser takes with its options spelt in full, every `pftrack ...` and `python -m
experiments.X ...` quoted anywhere in them names a command, module and options that exist, and
the Goals table keeps short cells.

The README's Python blocks are run by tests/test_api.py and tests/tracking/test_api_tracker.py.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import importlib
import importlib.util
import inspect
import io
import re
import shlex
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import NoReturn

import pytest

from pftrack.cli import build_parser

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
DOCS = [README, *sorted((ROOT / "docs").glob("*.md"))]


def slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation but ``-`` and ``_`` dropped
    (backticks, apostrophes, colons, dots, parentheses), each space a ``-``."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def _prose(text: str) -> Iterator[tuple[int, str]]:
    """(line number, line) outside fenced code blocks."""
    fenced = False
    for number, line in enumerate(text.splitlines(), start=1):
        if line.startswith("```"):
            fenced = not fenced
        elif not fenced:
            yield number, line


def anchors(text: str) -> set[str]:
    """Every heading's anchor; a repeated heading gets ``-1``, ``-2``, ... as on GitHub."""
    seen: dict[str, int] = {}
    found = set()
    for _, line in _prose(text):
        m = re.match(r"#+\s+(.*)", line)
        if m:
            s = slug(m.group(1))
            n = seen.get(s, 0)
            found.add(s if n == 0 else f"{s}-{n}")
            seen[s] = n + 1
    return found


def broken_links(doc: Path) -> list[str]:
    """``doc:line: target`` for each relative link whose file or #anchor does not exist."""
    bad = []
    for number, line in _prose(doc.read_text(encoding="utf-8")):
        for m in re.finditer(r"\]\(([^)\s]+)\)", re.sub(r"`[^`]*`", "", line)):
            target = m.group(1)
            if re.match(r"[a-z][a-z0-9+.-]*:", target):  # https:, mailto:
                continue
            name, _, anchor = target.partition("#")
            dest = (doc.parent / name).resolve() if name else doc
            if not dest.exists():
                bad.append(f"{doc.name}:{number}: {target} (no such file)")
            elif anchor and dest.suffix == ".md":
                if anchor not in anchors(dest.read_text(encoding="utf-8")):
                    bad.append(f"{doc.name}:{number}: {target} (no such heading)")
    return bad


@pytest.mark.parametrize(
    ("heading", "anchor"),
    [
        ("Set-up: two commands", "set-up-two-commands"),
        ("Cost of `update` per frame", "cost-of-update-per-frame"),
        ("The README's figures: history and reasons", "the-readmes-figures-history-and-reasons"),
        ("Where the time goes at stop 61 (6 December, 12:05-12:35)",
         "where-the-time-goes-at-stop-61-6-december-1205-1235"),
        ("Working resolution (`max_side`)", "working-resolution-max_side"),
    ],
)  # fmt: skip
def test_slug_is_githubs(heading: str, anchor: str) -> None:
    assert slug(heading) == anchor


def test_the_checker_finds_a_missing_file_and_a_missing_anchor(tmp_path: Path) -> None:
    (tmp_path / "a.md").write_text("# Top\n\n## Top\n\n```\n# not a heading\n```\n")
    doc = tmp_path / "b.md"
    doc.write_text(
        "[ok](a.md#top) [ok](a.md#top-1) [ok](#here) [web](https://x.org/#y) `[code](c.md)`\n"
        "# Here\n[gone](c.md) [no](a.md#not-a-heading) [no](a.md#top-2) [no](#nowhere)\n"
    )
    assert broken_links(doc) == [
        "b.md:3: c.md (no such file)",
        "b.md:3: a.md#not-a-heading (no such heading)",
        "b.md:3: a.md#top-2 (no such heading)",
        "b.md:3: #nowhere (no such heading)",
    ]


@pytest.mark.parametrize("doc", DOCS, ids=lambda p: p.name)
def test_every_relative_link_and_anchor_resolves(doc: Path) -> None:
    """The README moved its history to docs/results.md: each link to it, and every other
    relative link of README.md and docs/*.md, names a file and heading that exist."""
    assert broken_links(doc) == []


def _bash_blocks(text: str) -> list[str]:
    return [b.strip() for b in re.findall(r"```bash\n(.*?)```", text, re.S)]


def test_the_set_up_commands_are_the_two_ci_runs() -> None:
    """The README's set-up section holds exactly two commands, the demo and the test command,
    and .ci/run runs the second one verbatim."""
    text = README.read_text(encoding="utf-8")
    section = text.split("## Set-up: two commands", 1)[1].split("\n## ", 1)[0]
    demo, tests = _bash_blocks(section)
    assert demo == (
        "python3 -m venv .venv && . .venv/bin/activate && python -m pip install . && pftrack demo"
    )
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    assert tests in ci and tests.endswith("python -m pytest -n 2 --dist loadfile")


def test_goals_is_one_short_row_per_goal() -> None:
    """Each Goals cell is a few lines (the figure, the command, met or not); the longer account
    lives in docs/results.md, linked from the section."""
    text = README.read_text(encoding="utf-8")
    section = text.split("### Goals", 1)[1].split("\n### ", 1)[0]
    assert "docs/results.md#goals-in-full-as-of-stop-61" in section
    rows = [line for line in section.splitlines() if line.startswith("| ")][1:]
    assert len(rows) >= 14
    for row in rows:
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert len(cells) == 4 and cells[3], row
        assert len(cells[2]) <= 450, f"a Goals cell of {len(cells[2])} characters: {cells[2]}"


def _readme_pftrack_commands() -> list[list[str]]:
    """Every ``pftrack ...`` command of the README's bash blocks, as argv after ``pftrack``."""
    commands = []
    for block in _bash_blocks(README.read_text(encoding="utf-8")):
        for line in block.replace("\\\n", " ").splitlines():
            for part in re.split(r"\s(?:;|&&)\s", line):
                argv = shlex.split(part, comments=True)
                if argv[:1] == ["pftrack"]:
                    commands.append(argv[1:])
    return commands


def test_the_readme_runs_pftrack_commands() -> None:
    commands = _readme_pftrack_commands()
    assert {c[0] for c in commands if c} >= {"demo", "track", "eval", "smooth", "recover",
                                             "render", "batch", "experiment"}  # fmt: skip


@pytest.mark.parametrize("argv", _readme_pftrack_commands(), ids=" ".join)
def test_every_readme_pftrack_command_parses(
    argv: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    """Each command the README shows is one the parser takes: its subcommand, options and
    values exist (``--help`` prints and exits 0). Nothing runs: the files are the reader's."""
    parser = build_parser()
    if "--help" in argv:
        with pytest.raises(SystemExit) as exc:
            parser.parse_args(argv)
        assert exc.value.code == 0 and "usage: pftrack" in capsys.readouterr().out
        return
    assert parser.parse_args(argv) is not None
    with pytest.raises(SystemExit):  # spelt in full, not an abbreviation argparse would take
        parser.parse_args([*argv, "--help"])  # the (sub)command's own --help
    usage = capsys.readouterr().out
    for option in (a.split("=")[0] for a in argv if a.startswith("--")):
        assert re.search(rf"{option}\b(?!-)", usage), f"{option} is not spelt as in --help"


def _quoted_commands(docs: list[Path] = DOCS) -> list[tuple[str, list[str], bool]]:
    """``(doc:line, argv, whole)`` of each ``pftrack ...`` and ``python -m experiments.X ...``
    quoted in README.md and docs/*.md: in a bash block (`whole`: a command as typed, every
    argument it needs), or in a plain block or `code span` of the prose (often a synopsis or
    a part: ``pftrack track --render``). `argv` starts at ``pftrack`` or ``experiments.X``; a
    ``NAME`` or ``CMD`` and an error line quoted (``pftrack track: error: ...``) are left out.
    """
    found = []
    for doc in docs:
        name = doc.relative_to(doc.parents[1] if doc.parent.name == "docs" else doc.parent)
        name = name.as_posix()
        text = doc.read_text(encoding="utf-8").replace("\\\n", " ")
        places: list[tuple[int, str, bool]] = []
        fence = None  # the open block's language
        for number, line in enumerate(text.splitlines(), start=1):
            if line.startswith("```"):
                fence = line[3:].strip() if fence is None else None
            elif fence in ("bash", ""):  # a plain block: synopses ([--scale S]), output
                places.append((number, line, fence == "bash"))
            elif fence is None:
                places += [(number, m.group(1), False) for m in re.finditer(r"`([^`]+)`", line)]
        for number, code, whole in places:
            for part in re.split(r"\s(?:;|&&|\|)\s", code):
                try:
                    argv = shlex.split(part, comments=True)
                except ValueError:
                    continue
                while argv and re.fullmatch(r"[A-Z_]+=\S*|\$|/usr/bin/time|-v", argv[0]):
                    argv = argv[1:]  # PFTRACK_DATA=... cmd, $ cmd, /usr/bin/time -v cmd
                if argv[:3] in (["python", "-m", "pftrack"], ["python", "-m", "pftrack.cli"]):
                    argv = ["pftrack", *argv[3:]]
                elif argv[:2] == ["python", "-m"] and argv[2:3]:
                    argv = argv[2:]
                if not argv or not re.fullmatch(r"pftrack|experiments\.[a-z_]+", argv[0]):
                    continue
                words = [w for w in argv[1:] if not w.startswith("-")][:2]
                if any(w.endswith(":") or w.isupper() for w in words):
                    continue  # an error line (pftrack experiment gaps: ...), or CMD
                found.append((f"{name}:{number}", argv, whole))
    return found


@functools.cache
def _experiment_parser(module: str) -> argparse.ArgumentParser:
    """The parser ``python -m experiments.X`` builds: its ``main`` is run up to its parse
    (once a module: parsing leaves a parser as it was)."""

    class _Built(Exception):
        pass

    seen: list[argparse.ArgumentParser] = []

    def built(self: argparse.ArgumentParser, *args: object, **kwargs: object) -> NoReturn:
        seen.append(self)
        raise _Built

    main = importlib.import_module(module).main
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(argparse.ArgumentParser, "parse_known_args", built)
        patch.setattr(sys, "argv", [module])
        with pytest.raises(_Built):
            main(*([[]] if inspect.signature(main).parameters else []))
    return seen[0]


def _options_taken(parser: argparse.ArgumentParser, argv: list[str]) -> list[str]:
    """Each option of `argv` (after the command's name) its (sub-)command does not take,
    spelt in full: ``--ren`` of ``pftrack track``, a sub-command that does not exist."""
    bad = []
    for word in argv:
        subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
        option = word.strip("[]").split("=")[0]
        if re.fullmatch(r"--?[A-Za-z][\w-]*", option):
            if option not in parser._option_string_actions:
                bad.append(f"{option} (not an option of {parser.prog})")
        elif subs and not word.startswith("-"):
            if word not in subs[0].choices:
                bad.append(f"{word} (not a command of {parser.prog})")
                break
            parser = subs[0].choices[word]
    return bad


QUOTED = _quoted_commands()
_PFTRACK = build_parser()  # one for every quoted command: parsing leaves it as it was


def test_the_command_checker_finds_a_wrong_command_and_option(
    tmp_path: Path,
) -> None:
    (tmp_path / "docs").mkdir()
    doc = tmp_path / "docs" / "a.md"
    doc.write_text(
        "Run `pftrack track v.mp4 --ren r.mp4` or `pftrack trak` (`pftrack track: error: x`,\n"
        "`pftrack --quiet CMD`), `python -m experiments.auto_seeds --seed 2` or\n"
        "`PFTRACK_DATA=d python -m experiments.NAME --help`:\n"
        "```bash\npftrack experiment gaps --gt a.txt \\\n  --n-masks 6 && pftrack eval --gt g\n"
        "```\n"
    )
    quoted = _quoted_commands([doc])
    assert [(place, " ".join(argv), whole) for place, argv, whole in quoted] == [
        ("docs/a.md:1", "pftrack track v.mp4 --ren r.mp4", False),
        ("docs/a.md:1", "pftrack trak", False),
        ("docs/a.md:2", "experiments.auto_seeds --seed 2", False),
        ("docs/a.md:5", "pftrack experiment gaps --gt a.txt --n-masks 6", True),
        ("docs/a.md:5", "pftrack eval --gt g", True),
    ]
    taken = [
        _options_taken(build_parser(), argv[1:]) for _, argv, _ in quoted if argv[0] == "pftrack"
    ]
    assert taken == [
        ["--ren (not an option of pftrack track)"],
        ["trak (not a command of pftrack)"],
        [],
        [],
    ]
    seeds = _experiment_parser("experiments.auto_seeds")
    assert _options_taken(seeds, ["--seed", "2"]) == [
        "--seed (not an option of python -m experiments.auto_seeds)"
    ]
    with pytest.raises(SystemExit):  # a whole command: --res is required
        build_parser().parse_args(quoted[-1][1][1:])


def test_the_docs_quote_commands_of_both_kinds() -> None:
    kinds = {argv[0].partition(".")[0] for _, argv, _ in QUOTED}
    assert kinds == {"pftrack", "experiments"}
    assert len(QUOTED) > 300 and sum(whole for *_, whole in QUOTED) >= 40


def test_every_quoted_command_names_what_its_parser_takes() -> None:
    """Each ``pftrack ...`` and ``python -m experiments.X ...`` of README.md and docs/*.md
    names a command or module that exists and options its parser takes, spelt in full; one
    of a bash block parses as a whole (the real parser; nothing runs). One test for the 537,
    each wrong one listed: a test each took about 40 s more of CI on this machine."""
    wrong = []
    for place, argv, whole in QUOTED:
        if argv[0] == "pftrack":
            parser = _PFTRACK
        elif importlib.util.find_spec(argv[0]) is None:
            wrong.append(f"{place}: no module {argv[0]}")
            continue
        else:
            parser = _experiment_parser(argv[0])
        wrong += [f"{place}: {problem}" for problem in _options_taken(parser, argv[1:])]
        if whole and "--help" not in argv:
            said = io.StringIO()
            try:
                with contextlib.redirect_stderr(said):
                    parser.parse_args(argv[1:])
            except SystemExit:
                wrong.append(f"{place}: {' '.join(argv)}: {said.getvalue().strip()}")
    assert wrong == []
