"""The reader's warnings name the user's line, not one inside pftrack/io/video.py.

A damaged start, a live cut and a variable frame rate are said while a video is read: the
user's loop over a :class:`~pftrack.io.video.FrameSource` named video.py's ``__iter__``, and
:func:`~pftrack.track_frames` / :func:`~pftrack.track_path` named a line of pftrack's own (with
threads, the reading thread's: prefetch.py or threading.py). They name the line that iterated
the source, or called ``track_frames`` / ``track_path``, now, as the detector's do
(tests/tracking/test_damaged_start.py).
"""

from __future__ import annotations

import sys
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from pftrack.detection.bootstrap import bootstrap_frames
from pftrack.io.video import FrameSource
from pftrack.synthetic import make_scene
from pftrack.tracking.run import track_frames, track_path
from tests.io.test_estimated_count import write_vfr
from tests.io.test_live_cut import _cut, _stream
from tests.io.test_video import damaged_inside
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


STOOD_IN = "damaged.avi: frame 10 could not be decoded (a damaged file?): the frame before stands"


@pytest.mark.parametrize("split", [False, True], ids=["one pass", "split"])
def test_a_stand_in_among_the_spread_bootstraps_frames_is_said_naming_the_users_line(
    tmp_path: Path, split: bool
) -> None:
    """The spread bootstrap's frames 0, 3, 6, 9 (frame 10, standing in), ... of a video whose
    frame 10 does not decode: its pass says so, once, from the line that asked for them
    (apinames, 6 December; was: nothing, the stand-in taken for frame 10 without a word)."""
    damaged = damaged_inside(tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # said there too: another source
        iterated = list(FrameSource(damaged))
    source = FrameSource(damaged)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        line = sys._getframe().f_lineno + 1
        frames = bootstrap_frames(source, 11, "spread", split=split)
    said = [w for w in caught if STOOD_IN in str(w.message)]
    assert [(w.filename, w.lineno) for w in said] == [(__file__, line)], said
    assert len(frames) == 11
    for got, k in zip(frames, np.linspace(0, 29, 11).round().astype(int), strict=True):
        np.testing.assert_array_equal(got, iterated[k])  # frame 10 (k = 9) is frame 9's
    with warnings.catch_warnings(record=True) as caught:  # once a source
        warnings.simplefilter("always")
        list(source)
    assert not [w for w in caught if STOOD_IN in str(w.message)]


def test_a_stand_in_among_the_bootstrap_frames_stops_a_run_under_w_error_before_tracking(
    tmp_path: Path,
) -> None:
    """Under ``-W error`` the run stops at its bootstrap, before it tracks a frame (was: after
    tracking every frame, at the end of the tracking pass, the run's work lost)."""
    tracked: list[int] = []
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UserWarning, match="frame 10 could not be decoded"):
            track_frames(
                FrameSource(damaged_inside(tmp_path)),
                prime_frames=11,
                on_frame=lambda n, *_: tracked.append(n),
            )
    assert tracked == []
