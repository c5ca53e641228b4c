"""`pftrack track`'s process skips the collector's passes at its exit; a library call does not."""

from __future__ import annotations

import gc
import subprocess
import sys
from pathlib import Path

import pytest

from pftrack.cli import main
from pftrack.synthetic import make_scene


@pytest.fixture(scope="module")
def video(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return make_scene(n_frames=30, rng=0).write_video(tmp_path_factory.mktemp("v") / "s.avi")


def _console_lines(argv: list[str]) -> list[str]:
    """The lines `pftrack ARGV` prints, run as the console script runs it (``_console.main`` in
    a process of its own), the last being whether objects were frozen at its exit."""
    code = (
        "import atexit, gc, sys; "
        "atexit.register(lambda: print('frozen', gc.get_freeze_count() > 0)); "
        f"sys.argv = ['pftrack', *{argv!r}]; "
        "from pftrack._console import main; sys.exit(main())"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return run.stdout.splitlines()


def test_the_console_process_freezes_its_objects_once_the_outputs_are_written(
    video: Path, tmp_path: Path
) -> None:
    """``gc.freeze()`` after the summary: the interpreter's exit then skips the cyclic collector's
    passes over every object (0.15-0.2 s of a PETS09 run at load; the same file, the same
    summary)."""
    out = tmp_path / "t.txt"
    lines = _console_lines(["track", str(video), "--out", str(out)])
    assert lines[-1] == "frozen True", lines
    assert "30 frames" in lines[-2] and out.stat().st_size > 0


def test_a_library_call_of_the_command_leaves_the_collector_alone(
    video: Path, tmp_path: Path
) -> None:
    """``pftrack.cli.main(argv)`` runs inside a caller's process, which goes on: nothing frozen."""
    before = gc.get_freeze_count()
    assert main(["-q", "track", str(video), "--out", str(tmp_path / "t.txt")]) == 0
    assert gc.get_freeze_count() == before


@pytest.mark.parametrize("command", ["recover", "smooth"])
def test_every_command_freezes_its_objects_in_the_console_process(
    video: Path, tmp_path: Path, command: str
) -> None:
    """Was: ``pftrack track`` alone; ``recover`` and ``smooth`` paid the collector's passes
    over every object at their exit too."""
    tracks, out = tmp_path / "t.txt", tmp_path / "o.txt"
    assert main(["-q", "track", str(video), "--out", str(tracks)]) == 0
    lines = _console_lines(["-q", command, str(tracks), "--out", str(out)])
    assert lines[-1] == "frozen True", lines
    assert out.stat().st_size > 0
