"""Frames to start a background from: spread over a file, or a window at the start of a stream.

A background started from the first frame keeps every person present in it as a foreground
"ghost"; the median of frames *spread over the whole video* sees each pixel uncovered most of
the time and so gives the empty scene, even when nobody ever leaves. When the frames arrive as
a stream (no second pass possible), the first frames are the only ones to take.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterable, Iterator, Sequence, Sized
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from pftrack._check import brief, option
from pftrack._typing import IntLike

BOOTSTRAPS = ("spread", "first", "none")
Bootstrap = Literal["spread", "first", "none"]

__all__ = ["BOOTSTRAPS", "Bootstrap", "bootstrap_frames"]


def bootstrap_frames(
    frames: Iterable[NDArray[np.uint8]],
    n: IntLike = 30,
    mode: str = "spread",
    *,
    split: bool = False,
    prepare: Callable[[NDArray[np.uint8]], NDArray[np.uint8]] | None = None,
) -> list[NDArray[np.uint8]]:
    """Pick the frames whose per-pixel median starts the background.

    Parameters
    ----------
    frames : iterable of (H, W, 3) uint8 arrays
        The video. ``"spread"`` needs ``len(frames)`` to choose its stride, and falls back to
        ``"first"`` when `frames` has no length. It reads a `pftrack.io.video.FrameSource`
        with its ``frames_at`` (a folder: only the chosen images; an MJPEG file: only the
        chosen frames' packets; another file: one pass that decodes every frame, as it must,
        but converts only the chosen ones), indexes a
        sequence, and otherwise iterates `frames` once up to the last chosen frame.
    n : int
        How many frames to return (fewer if the video is shorter); 0 returns none.
    mode : {"spread", "first", "none"}
        ``"spread"``: `n` frames evenly spaced over the whole video; ``"first"``: the first `n`
        frames (the only choice when streaming); ``"none"``: no frames (the background then
        starts as the first frame).
    split : bool
        ``"spread"`` over a file: decode its two halves at once, on two threads
        (``FrameSource.frames_at(split=True)``; the same frames).
    prepare : callable, optional
        Applied to each chosen frame as it is read, and its result kept instead of the frame
        (``Tracker.working_frame``: a 4K video's 30 frames are held at the working size,
        about 15 MB with ``max_side=960``, not 750 MB at their own size).

    Returns
    -------
    list of (H, W, 3) uint8 arrays
        The chosen frames, or what `prepare` made of them.
    """
    option(mode, "bootstrap mode", BOOTSTRAPS)
    if mode not in BOOTSTRAPS:
        raise ValueError(f"bootstrap mode is {mode!r}, expected one of {', '.join(BOOTSTRAPS)}")
    if not isinstance(n, (int, np.integer)) or isinstance(n, bool) or n < 0:
        raise ValueError(f"bootstrap frame count is {brief(n)}, expected an int >= 0")
    if mode == "none" or n == 0:
        return []
    total = len(frames) if isinstance(frames, Sized) else 0
    keep = prepare if prepare is not None else _same
    if mode == "first" or total <= n:
        return [keep(f) for f in itertools.islice(iter(frames), int(n))]
    wanted = set(np.linspace(0, total - 1, n).round().astype(int).tolist())
    pick = getattr(frames, "frames_at", None)
    if callable(pick):  # a FrameSource: only the wanted images of a folder, no BGR in between
        options: dict[str, Any] = {"split": True} if split else {}
        if prepare is not None:
            options["prepare"] = prepare
        got = list(pick(sorted(wanted), **options))
        recount = getattr(frames, "recount", None)
        if len(got) < len(wanted) and callable(recount) and recount() < total:
            # a header that says more frames than the video holds (a truncated file): spread
            # over the frames there are (was: the few before the end, one frame of 30)
            return bootstrap_frames(frames, n, mode, split=split, prepare=prepare)
        return got
    if isinstance(frames, Sequence):
        return [keep(frames[i]) for i in sorted(wanted)]
    picked: list[NDArray[np.uint8]] = []
    it: Iterator[NDArray[np.uint8]] = iter(frames)
    for i, frame in enumerate(it):
        if i in wanted:
            picked.append(keep(frame))
            if len(picked) == len(wanted):
                break
    return picked


def _same(frame: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """`frame` itself: :func:`bootstrap_frames` without a `prepare`."""
    return frame
