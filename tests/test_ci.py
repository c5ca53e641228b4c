""".ci/run runs the README's test command, and the suite can run on pytest-xdist's processes."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tests.conftest import ids_with_addresses

ROOT = Path(__file__).resolve().parents[1]


def _readme_command() -> str:
    """The README's install-and-test line (the bash block that runs ``python -m pytest``)."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    lines = re.findall(r"^python3 -m venv .* python -m pytest.*$", text, flags=re.M)
    assert len(lines) == 1, lines
    return str(lines[0])


def test_ci_runs_the_readmes_test_command_verbatim() -> None:
    lines = (ROOT / ".ci" / "run").read_text().splitlines()
    assert _readme_command() in lines


def test_every_pytest_step_of_ci_runs_on_xdist_which_the_test_extra_installs() -> None:
    steps = [s for s in (ROOT / ".ci" / "run").read_text().splitlines() if "python -m pytest" in s]
    assert len(steps) == 3, steps  # tests/, bench/, -m slow
    for step in steps:
        assert step.endswith("-n 2 --dist loadfile"), step
    tomllib = pytest.importorskip("tomllib")  # Python 3.11+
    extra = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    test = extra["optional-dependencies"]["test"]
    assert any(r.startswith("pytest-xdist") for r in test), test


def test_ids_holding_an_address_are_found() -> None:
    ids = [
        "tests/test_path_arguments.py::test_a[read_mot-<object object at 0x7fad815b08c0>]",
        "tests/test_path_arguments.py::test_a[read_mot-object()]",
        "tests/test_x.py::test_b[0x10]",
    ]
    assert ids_with_addresses(ids) == ids[:1]
