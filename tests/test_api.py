"""``import pftrack`` exposes the public API, lazily."""

from __future__ import annotations

import subprocess
import sys

import pytest

import pftrack


@pytest.mark.parametrize("name", [n for n in pftrack.__all__ if n != "__version__"])
def test_every_public_name_resolves_to_its_home(name: str) -> None:
    obj = getattr(pftrack, name)
    assert obj.__module__.startswith("pftrack.")
    assert name in dir(pftrack)


def test_all_lists_exactly_the_lazy_names() -> None:
    assert sorted(pftrack.__all__) == sorted(["__version__", *pftrack._MODULE_OF])


def test_unknown_name_is_an_attribute_error() -> None:
    with pytest.raises(AttributeError, match="no_such_thing"):
        pftrack.no_such_thing  # noqa: B018


def test_import_pftrack_loads_no_wing() -> None:
    """The top-level import stays light: the wings (and SciPy) load on first use."""
    code = (
        "import sys, pftrack; "
        "print(sorted(m for m in sys.modules if m.startswith(('pftrack.tracking', "
        "'pftrack.recovery', 'scipy'))))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_cli_parser_loads_no_scipy() -> None:
    """``pftrack --help`` builds every sub-command's parser without loading a method."""
    code = (
        "import sys; from pftrack.cli import build_parser; build_parser(); "
        "print(sorted(m for m in sys.modules if m.startswith(('scipy', 'pftrack.recovery.'))))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "['pftrack.recovery.names']"
