"""Frames that stand in for frames a video could not decode: marked, so that checks skip them.

A video whose first frames do not decode is read with a black frame in place of each
(:attr:`pftrack.io.video.FrameSource.lead_black` counts them; its reader says so once). The
checks made on a run's frames (the tracker's blank first frame and blockiness, the detector's
dark frames) would take those black frames for the footage and give advice wrong for them
("placeholder frames?", "lights switched off?"), and blockiness measured on them would hide
a blocky video. The code that knows which frames are stand-ins (the run, which has the source)
processes each of them inside :func:`standing_in`; a check asks :func:`is_stand_in` and skips
the frame. The mark is per thread, as the frame's processing is: the detector's thread marks
its own detection of the frame (:class:`~pftrack.tracking.ahead.DetectAhead`), the tracker's
thread its ``update``.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["is_stand_in", "standing_in"]

_local = threading.local()


@contextmanager
def standing_in(stand_in: bool = True) -> Iterator[None]:
    """Mark the frame processed inside the block, on this thread, as a stand-in (or not)."""
    before = getattr(_local, "stand_in", False)
    _local.stand_in = stand_in
    try:
        yield
    finally:
        _local.stand_in = before


def is_stand_in() -> bool:
    """Whether the frame this thread processes is a stand-in (:func:`standing_in`)."""
    return bool(getattr(_local, "stand_in", False))
