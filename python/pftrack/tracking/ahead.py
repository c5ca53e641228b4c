"""The detector a frame ahead of the tracker, on a thread: detection overlaps tracking.

The built-in detector's result for frame t depends only on frames 1..t and the priming (the
tracker never writes to it: camera motion decides which of the detector's bins the tracker
uses, not what the detector computes), so it can run on a second thread, in order, while the
main thread tracks the frames before. Its heavy parts (the C++ background pass, the ghost test,
OpenCV's morphology and labelling) release the GIL, so on two cores detection of frame t+1 runs
while frame t is tracked.

:class:`DetectAhead` swaps the tracker's detector for a stand-in for the length of a run: the
stand-in hands the tracker, for the very frame object it was given, what the thread computed
with the real detector, or raises the error the detector raised on that frame, at the place in
``update`` where the detector would have raised it. The tracker's output is therefore the same,
byte for byte, as with the detector called in ``update``.

Each frame's grey, which the tracker's camera-motion check measures
(:meth:`~pftrack.tracking.camera.CameraMotion.grey`, a pure function of the frame), is made
ahead too and handed to the camera with the frame. With ``read_depth`` the frames are read on a
thread of their own, which also prepares them and makes their grey: on two cores the reading
thread has time to spare, the detector's thread (the larger frames) or the tracker's (the
smaller) has not.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterable, Iterator
from types import TracebackType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pftrack._stand_in import standing_in
from pftrack._warn import Held, warn
from pftrack.detection import FrameDetector
from pftrack.io.prefetch import prefetch
from pftrack.tracking.camera import CameraMotion
from pftrack.tracking.tracker import MultiObjectTracker

__all__ = ["DetectAhead"]

# (the frame as read, the frame the detector sees, the camera's grey of it or None, the error
# of making them)
_Prepared = tuple[Any, Any, Any, BaseException | None]
_Warning = tuple[str, type[Warning]]
# (the frame as read, the frame the detector saw, its result, its error, the camera's grey,
# the warnings the detector gave on it, held for the tracker's thread to give)
_Work = tuple[NDArray[np.uint8], NDArray[np.uint8], Any, BaseException | None, Any, list[_Warning]]
_Frame = NDArray[np.uint8]


class _StandIn:
    """The tracker's detector during a run: returns what the thread computed for each frame."""

    def __init__(self, foreground_only: bool, shadows: bool) -> None:
        self._foreground_only = foreground_only
        self._next: _Work | None = None
        self.foreground_shadows = shadows  # whether the thread computed the mask with them

    def expect(self, work: _Work) -> None:
        """The next frame the tracker will ask about, and the thread's result or error."""
        self._next = work

    def _take(self, frame: NDArray[np.uint8], foreground_only: bool) -> Any:
        work, self._next = self._next, None
        if work is None or work[1] is not frame or foreground_only != self._foreground_only:
            raise RuntimeError(
                "DetectAhead: the tracker asked about a frame the detection thread did not "
                "detect (one update per frame of the run, in order)"
            )
        if work[3] is not None:
            raise work[3]
        for message, category in work[5]:  # held inside update, given from the user's line
            warn(message, category)
        return work[2]

    def detect(self, frame: NDArray[np.uint8]) -> Any:
        """The thread's ``detect(frame)``."""
        return self._take(frame, False)

    def foreground(self, frame: NDArray[np.uint8], shadows: bool = False) -> Any:
        """The thread's ``foreground(frame)`` (or the mask and bins of its ``detect``).

        Computed there with the `shadows` the tracker asks for (its ``shadows_of``).
        """
        return self._take(frame, True)

    def reset(self) -> None:
        """Refused: the real detector belongs to the thread during a run."""
        raise RuntimeError("DetectAhead: the detector cannot be reset during a run")


class DetectAhead:
    """Run `tracker`'s detector on a thread, one or more frames ahead of ``tracker.update``.

    Use as a context manager around the run's loop: it yields the frames, in order, and each
    frame's detection is ready when ``update`` asks for it. On exit the thread is stopped and
    the tracker gets its own detector back.

    Parameters
    ----------
    tracker : MultiObjectTracker
        The tracker of the run, primed already (priming must come before any detection).
    frames : iterable of (H, W, 3) uint8 arrays
        The run's frames (e.g. a :func:`~pftrack.io.prefetch.prefetch` of a video).
    external : bool
        Whether ``update`` gets the caller's detections: then only the foreground (box
        refinement) is computed ahead, as ``update`` asks for it; otherwise ``detect``.
    depth : int
        How many frames may wait detected.
    prepare : callable, optional
        Turns each frame into the one the tracker's detector sees (the working resolution,
        :meth:`pftrack.Tracker.working_frame`), on a thread (the reading thread with
        `read_depth`); default: the frame itself.
    hand_over : callable, optional
        Called as ``hand_over(frame, prepared)`` just before `frame` is yielded, so that the
        caller's ``update`` uses the very prepared array (:meth:`pftrack.Tracker.hand_over`).
    read_depth : int, optional
        Read `frames` on a thread of their own (a :func:`~pftrack.io.prefetch.prefetch` this
        deep), which also prepares each frame and makes the camera's grey of it; default: all
        on the detector's thread.
    black_stand_in : callable, optional
        ``black_stand_in(k)``: whether frame k (1-based) is a black frame in place of one the
        video could not decode (:attr:`pftrack.io.video.FrameSource.lead_black`), asked once
        frame k is read; the detector's checks skip those (:mod:`pftrack._stand_in`).

    Examples
    --------
    >>> with DetectAhead(mot, source, external=False, read_depth=4) as frames:  # doctest: +SKIP
    ...     for frame in frames:
    ...         mot.update(frame, None)
    """

    def __init__(self, tracker: MultiObjectTracker, frames: Iterable[NDArray[np.uint8]],
                 *, external: bool, depth: int = 2,
                 prepare: Callable[[_Frame], _Frame] | None = None,
                 hand_over: Callable[[_Frame, _Frame], None] | None = None,
                 read_depth: int | None = None,
                 black_stand_in: Callable[[int], bool] | None = None) -> None:  # fmt: skip
        self._tracker = tracker
        self._black_stand_in = black_stand_in
        self._read_depth = read_depth
        self._frames = frames
        self._external = external
        self._depth = depth
        self._prepare = prepare
        self._hand = hand_over
        self._detector: Any = None
        self._stand_in: _StandIn | None = None
        self._stream: Iterator[_Work] | None = None

    def __enter__(self) -> Iterator[NDArray[np.uint8]]:
        detector = self._tracker.detector
        # what update() reads: detect(); with external detections the foreground, from the
        # detector's foreground() when it has one, else from its detect()
        shadows = False  # whether the thread's foreground has them (the stand-in says so)
        if not self._external:
            call = detector.detect
        elif hasattr(detector, "foreground"):
            shadows = self._tracker.shadows_of(detector)
            call = detector.foreground
            if shadows:
                call = functools.partial(detector.foreground, shadows=True)
        else:
            call = _mask_and_bins(detector)
        self._detector = detector
        self._stand_in = _StandIn(self._external, shadows)
        camera = self._tracker.camera
        grey = None if camera.mode == "off" else camera.grey
        prepared = _prepared(self._frames, self._prepare, grey)
        if self._read_depth is not None:
            prepared = prefetch(prepared, depth=self._read_depth)
        self._stream = prefetch(_work(prepared, call, self._black_stand_in), depth=self._depth)
        self._tracker.detector = self._stand_in
        return self._hand_over(self._stream, self._stand_in, self._hand, camera)

    def __exit__(self, kind: type[BaseException] | None, error: BaseException | None,
                 trace: TracebackType | None) -> None:  # fmt: skip
        close = getattr(self._stream, "close", None)
        if close is not None:
            close()  # stops the thread and waits for it
        self._tracker.detector = self._detector

    @staticmethod
    def _hand_over(stream: Iterator[_Work], stand_in: _StandIn,
                   hand: Callable[[_Frame, _Frame], None] | None,
                   camera: CameraMotion) -> Iterator[_Frame]:  # fmt: skip
        for work in stream:
            stand_in.expect(work)
            if hand is not None:
                hand(work[0], work[1])
            if work[4] is not None:
                camera.hand_over(work[1], work[4])
            yield work[0]


def _mask_and_bins(detector: FrameDetector) -> Any:
    """``detect`` as the tracker reads it without ``foreground``: the mask and full-frame bins."""

    def call(frame: NDArray[np.uint8]) -> tuple[Any, Any]:
        det = detector.detect(frame)
        return det.mask, det.frame_bins

    return call


def _prepared(frames: Iterable[Any], prepare: Callable[[_Frame], _Frame] | None,
              grey: Callable[[_Frame], Any] | None) -> Iterator[_Prepared]:  # fmt: skip
    """Each frame, prepared, with its `grey`, or with the error of preparing it (then no more).

    The grey is None without `grey`, or when it refuses the frame (``update`` then refuses it
    in its own words). `frames`' iterator is closed when this ends, however it ends.
    """
    it = iter(frames)
    try:
        for item in it:
            # the very object update() will be given, and uses as it is: an array packed
            # (update() copies a view, frame[..., ::-1], which the thread would not have
            # detected), anything else as it came, for update() to refuse in its words (a PIL
            # image, RGB, made an array here was tracked as BGR)
            frame = np.ascontiguousarray(item) if isinstance(item, np.ndarray) else item
            try:
                # the very object update() hands the detector
                work = frame if prepare is None else prepare(frame)
            except Exception as error:  # raised by the stand-in in update(), where it belongs
                yield frame, frame, None, error
                return
            measured = None
            if grey is not None:
                try:
                    measured = grey(work)
                except Exception:  # not a frame update() takes: it refuses it itself
                    measured = None
            yield frame, work, measured, None
    finally:
        close = getattr(it, "close", None)
        if close is not None:
            close()


def _work(prepared: Iterable[_Prepared], call: Any,
          black_stand_in: Callable[[int], bool] | None = None) -> Iterator[_Work]:  # fmt: skip
    """Each prepared frame with the detector's result and warnings, or its error (then no more).

    The detector's warnings (:func:`pftrack._warn.warn`) are held, not given on this thread
    (whose line, inside this module, they named): the stand-in gives them inside the
    tracker's ``update`` of the frame, which gives them from its caller's line, as when the
    detector runs inside ``update``. Frame k (1-based) is detected inside
    :func:`~pftrack._stand_in.standing_in` when ``black_stand_in(k)`` (a black frame in place
    of one the video could not decode). `prepared`'s iterator is closed when this ends, however
    it ends (a reader thread stops).
    """
    it = iter(prepared)
    try:
        for index, (frame, work, measured, error) in enumerate(it, start=1):
            said: list[_Warning] = []
            if error is None:
                try:
                    with (
                        Held() as held,
                        standing_in(black_stand_in is not None and black_stand_in(index)),
                    ):
                        result = call(work)
                    said = held.pending
                except Exception as raised:  # raised by the stand-in in update(), as above
                    error = raised
            if error is not None:
                yield frame, frame, None, error, None, []
                return
            yield frame, work, result, None, measured, said
    finally:
        close = getattr(it, "close", None)
        if close is not None:
            close()
