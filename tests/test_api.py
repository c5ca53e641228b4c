"""``import pftrack`` exposes the public API, lazily."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

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
        "'pftrack.recovery', 'scipy', 'numpy', 'cv2', 'pftrack._core'))))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_cli_parser_loads_no_scipy() -> None:
    """``pftrack --help`` builds every sub-command's parser without loading a method.

    Not even NumPy or OpenCV: ``pftrack --help`` then takes about 0.1 s more than Python
    itself (0.19 s against 0.11 s, measured while the machine was busy).
    """
    code = (
        "import sys; from pftrack.cli import build_parser; build_parser(); "
        "print(sorted(m for m in sys.modules if m.startswith(('scipy', 'numpy', 'cv2', "
        "'pftrack.recovery.'))))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "['pftrack.recovery.names']"


def test_recover_loads_no_tracker(tmp_path: Path) -> None:
    """``pftrack recover`` runs without importing the tracker (about 0.14 s of imports)."""
    tracks = tmp_path / "t.txt"
    tracks.write_text("1,1,10,10,5,5,1,-1,-1,-1\n4,1,13,10,5,5,1,-1,-1,-1\n")
    code = (
        "import sys; from pftrack.cli import main; "
        f"status = main(['-q', 'recover', {str(tracks)!r}, '--out', {str(tmp_path / 'o.txt')!r}]); "
        "print(status, sorted(m for m in sys.modules if m.startswith(('pftrack.tracking', "
        "'pftrack.detection'))))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip().splitlines()[-1] == "0 []"
    assert (tmp_path / "o.txt").read_text().count("\n") == 4  # frames 2 and 3 filled


def test_the_api_is_typed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """mypy sees the real signatures through the lazy re-exports (and the package's py.typed)."""
    api = pytest.importorskip("mypy.api")
    root = Path(pftrack.__file__).parents[1]
    if root.name not in ("site-packages", "dist-packages"):
        # a source checkout (PYTHONPATH=python): mypy finds installed packages by itself and
        # refuses site-packages on MYPYPATH
        monkeypatch.setenv("MYPYPATH", str(root))
    code = tmp_path / "use.py"
    code.write_text(
        "import pftrack\n"
        "reveal_type(pftrack.read_mot)\n"
        "reveal_type(pftrack.FrameSource('x').fps)\n"
        "pftrack.fill_gaps(1, method=2)\n"
    )
    out, _, status = api.run(["--strict", "--no-incremental", "--follow-imports=silent", str(code)])
    assert status == 1, out  # the bad call is caught, so the names are not Any
    assert 'Revealed type is "def (path: ' in out
    assert 'Revealed type is "float"' in out or 'Revealed type is "builtins.float"' in out
    assert 'Argument "method" to "fill_gaps" has incompatible type "int"' in out
