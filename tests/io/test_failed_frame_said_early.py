"""A frame that fails to decode inside a video is said at that frame, not after the last one.

The reader said "frame(s) ... could not be decoded" once a pass had read every frame: a loop
over a :class:`~pftrack.io.video.FrameSource`, or a run of :func:`~pftrack.track_frames`,
under ``-W error`` (or one that stops at a warning) learnt of it after every frame was
processed, and a ``"first"`` bootstrap's pass, which stops after its frames, said nothing of
a failure among them (the tracking pass did, at its end). Now it is said as the reader goes on
after the failure, before the frame standing in is given (once a source); the end of a pass
says the frames again only when there were more.
"""

from __future__ import annotations

import re
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from pftrack._typing import BootstrapMode
from pftrack.io.video import FrameSequence, FrameSource
from pftrack.tracking.run import track_frames
from tests.io.test_video import damaged_inside

FAILED = "could not be decoded (a damaged file?)"


def test_a_loop_under_w_error_stops_at_the_failed_frame(tmp_path: Path) -> None:
    """Frames 1-9 are given, then the error, before frame 10's stand-in (was: all 30 frames
    given, the error after the last)."""
    given = 0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UserWarning, match=re.escape(f"damaged.avi: frame 10 {FAILED}")):
            for _ in FrameSource(damaged_inside(tmp_path)):
                given += 1
    assert given == 9


@pytest.mark.parametrize("threads", [True, False], ids=["threads", "no threads"])
@pytest.mark.parametrize(
    ("bootstrap", "prime", "tracked"),
    [
        ("first", 5, list(range(1, 10))),  # frame 10 past the bootstrap's: stops before it
        ("first", 11, []),  # among the bootstrap's frames: stops before tracking
        ("spread", 30, []),  # no more frames than the prime count: read as "first"
    ],
    ids=["first after", "first among", "as many frames as the prime count"],
)
def test_a_run_under_w_error_stops_at_the_failed_frame(
    tmp_path: Path, threads: bool, bootstrap: BootstrapMode, prime: int, tracked: list[int]
) -> None:
    """The run stops before frame 10 is tracked, with the reader's warning as its error, from
    the tracker's thread (was: after tracking all 30 frames)."""
    done: list[int] = []
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UserWarning, match=re.escape(f"frame 10 {FAILED}")) as raised:
            track_frames(
                FrameSource(damaged_inside(tmp_path)),
                bootstrap=bootstrap,
                prime_frames=prime,
                threads=threads,
                on_frame=lambda n, *_: done.append(n),
            )
    assert done == tracked
    where = [Path(entry.path).name for entry in raised.traceback]
    assert "prefetch.py" not in where and "ahead.py" not in where, where


def test_later_failures_are_said_at_the_end_once_and_the_first_at_its_frame(
    tmp_path: Path,
) -> None:
    """Frames 10 and 22 fail: frame 10 is said as it is read, from the loop's line; the end
    of the pass says both (more than was said); a second pass says nothing (said already)."""
    source = FrameSource(damaged_inside(tmp_path, (0.3, 0.7)))
    said: list[tuple[int, str, int]] = []  # frames given when said, the message, its line
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        given = 0
        line = sys._getframe().f_lineno + 1
        for _ in source:
            said.extend(
                (given, str(w.message), w.lineno) for w in caught if FAILED in str(w.message)
            )
            caught.clear()
            given += 1
        said.extend((given, str(w.message), w.lineno) for w in caught if FAILED in str(w.message))
    assert [(at, text.split(": ")[1], lineno) for at, text, lineno in said] == [
        (9, f"frame 10 {FAILED}", line),
        (30, f"frames 10, 22 {FAILED}", line),
    ]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        list(source)
    assert not [w for w in caught if FAILED in str(w.message)]


def test_a_clean_video_says_nothing(tmp_path: Path) -> None:
    """The same video undamaged: no warning in a loop or a run, under ``-W error``."""
    damaged_inside(tmp_path)
    clean = tmp_path / "walk.avi"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert len(list(FrameSource(clean))) == 30
        modes: tuple[BootstrapMode, ...] = ("first", "spread")
        for bootstrap in modes:
            run = track_frames(FrameSource(clean), bootstrap=bootstrap, prime_frames=11)
            assert run.n_frames == 30


def test_a_frame_sequence_asked_again_after_the_error_gives_the_frame(tmp_path: Path) -> None:
    """`FrameSequence` (link_tracklets' frames): the error at frame 10, then frame 12 when asked
    again, not "the video ended" (its pass had ended with the error)."""
    damaged = damaged_inside(tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        expected = list(FrameSource(damaged))
    sequence = FrameSequence(damaged)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UserWarning, match=re.escape(f"frame 10 {FAILED}")):
            sequence[11]
        np.testing.assert_array_equal(sequence[11], expected[11])
        np.testing.assert_array_equal(sequence[9], expected[8])  # the stand-in


def test_frames_that_fail_are_no_variable_frame_rate(tmp_path: Path) -> None:
    """A 10 fps file whose frames 10 and 22 fail: its stamps skip them, steps of 300 ms among
    100 ms ones, 2 in 29, which said "variable frame rate: its frames are 100 to 300 ms apart"
    at the end of a pass; the steps across a failure are left out now."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        frames = list(FrameSource(damaged_inside(tmp_path, (0.3, 0.7))))
    assert len(frames) == 30
    said = [str(w.message) for w in caught]
    assert len(said) == 2 and all(FAILED in text for text in said), said
