"""The reader's warnings name the user's line, not one inside pftrack/io/video.py.

A damaged start, a live cut and a variable frame rate are said while a video is read: the
user's loop over a :class:`~pftrack.io.video.FrameSource` named video.py's ``__iter__``, and
:func:`~pftrack.track_frames` / :func:`~pftrack.track_path` named a line of pftrack's own (with
threads, the reading thread's: prefetch.py or threading.py). They name the line that iterated
the source, or called ``track_frames`` / ``track_path``, now, as the detector's do
(tests/tracking/test_damaged_start.py).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from pathlib import Path

import pytest

from pftrack.io.video import FrameSource
from pftrack.synthetic import make_scene
from pftrack.tracking.run import track_frames, track_path
from tests.io.test_estimated_count import write_vfr
from tests.io.test_live_cut import _cut, _stream
from tests.tracking.test_damaged_start import _damaged_start

pytest.importorskip("av")

KINDS: dict[str, tuple[Callable[[Path], Path], str]] = {
    "damaged start": (_damaged_start, "could not be decoded (a damaged start?)"),
    "live cut": (
        lambda tmp: _cut(_stream(tmp / "whole.ts"), tmp / "cut.ts", 3),
        "begins without a key frame",
    ),
    "variable rate": (
        lambda tmp: write_vfr(tmp / "vfr.mkv", make_scene(40, 160, 120, rng=1), [100, 200] * 20),
        "variable frame rate",
    ),
}


def _iterate(path: Path) -> None:
    for _ in FrameSource(path):
        pass


CALLS: dict[str, Callable[[Path], object]] = {
    "for loop": _iterate,
    "list": lambda path: list(FrameSource(path)),
    "track_frames": lambda path: track_frames(FrameSource(path)),
    "track_frames without threads": lambda path: track_frames(FrameSource(path), threads=False),
    "track_path": lambda path: track_path(path),
    "track_path without threads": lambda path: track_path(path, threads=False),
}


@pytest.mark.parametrize("kind", list(KINDS))
@pytest.mark.parametrize("call", list(CALLS))
def test_the_readers_warning_names_the_users_line(tmp_path: Path, kind: str, call: str) -> None:
    make, text = KINDS[kind]
    path = make(tmp_path)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        CALLS[call](path)
    (said,) = [w for w in caught if text in str(w.message)]
    assert (said.filename, said.lineno) == (__file__, _line(CALLS[call])), said


def _line(call: Callable[[Path], object]) -> int:
    """The line of `call` that reads the source: its loop, or its one line."""
    code = call.__code__
    return code.co_firstlineno + (1 if call is _iterate else 0)


def test_a_warning_made_an_error_stops_the_run_between_frames(tmp_path: Path) -> None:
    """Under ``-W error`` the reader's warning stops the run from the tracker's thread,
    between two frames (was: raised inside the reader, on the reading thread, and handed
    over by prefetch). Without priming: the bootstrap's pass, on this thread, reads the
    damaged start first otherwise."""
    source = FrameSource(_damaged_start(tmp_path))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UserWarning, match="a damaged start") as raised:
            track_frames(source, prime_frames=0)
    where = [Path(entry.path).name for entry in raised.traceback]
    assert "run.py" in where and "video.py" not in where and "prefetch.py" not in where, where
