"""Run a tracker over a whole video or image folder: the library behind ``pftrack track``."""

from __future__ import annotations

import itertools
import os
import sys
import time
from collections import deque
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from contextlib import closing
from dataclasses import dataclass
from types import FrameType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack._check import (
    MAX_FRAME,
    bgr_frame,
    first_bad_box,
    flag,
    generator,
    number,
    option,
    path_arg,
    real_array,
)
from pftrack._progress import Bar, bars, progress
from pftrack._stand_in import standing_in
from pftrack._text import counted
from pftrack._typing import F64, BootstrapMode, FillMode, IntLike, PathLike, RngLike
from pftrack._warn import Held, warn
from pftrack.detection.bootstrap import BOOTSTRAPS, bootstrap_frames
from pftrack.io.mot import first_row_fields, group_by_frame, read_mot
from pftrack.io.prefetch import prefetch
from pftrack.io.video import FrameSource, SequenceInfo
from pftrack.recovery.linking import LinkConfig
from pftrack.tracking.ahead import DetectAhead
from pftrack.tracking.api import (
    OUTSIDE_SHARE,
    ROUND_RATIOS,
    SMALL_LAYOUT_BOXES,
    Tracker,
    xywh_to_xyxy_dets,
)
from pftrack.tracking.config import TrackerConfig
from pftrack.tracking.offline import BoxSmoother
from pftrack.tracking.track import Track

__all__ = ["TrackingRun", "load_detections", "track_frames", "track_path"]


@dataclass(frozen=True)
class TrackingRun:
    """Result of :func:`track_frames`.

    Attributes
    ----------
    rows : (M, 10) ndarray
        MOTChallenge rows (1-based frames) in the frame's pixel coordinates.
    n_frames : int
        Frames processed.
    seconds : float
        Wall time of decoding, detection and tracking.
    """

    rows: F64
    n_frames: int
    seconds: float

    @property
    def fps(self) -> float:
        """Frames per second over the whole run."""
        return self.n_frames / self.seconds if self.seconds > 0 else float("inf")

    def __str__(self) -> str:
        """What ``print(run)`` shows: frames, tracks, rows and speed (``repr``: the rows)."""
        n_ids = len(np.unique(self.rows[:, 1])) if len(self.rows) else 0
        return (
            f"TrackingRun: {counted(self.n_frames, 'frame')}, {counted(n_ids, 'track')}, "
            f"{counted(len(self.rows), 'row')} in {self.seconds:.2f} s ({self.fps:.1f} frames/s)"
        )


#: The detection scales :func:`load_detections` accepts (``--det-scale``, ``TrackOptions``).
DET_SCALE_RANGE = (1e-3, 1e3)


def load_detections(path: PathLike, scale: float = 1.0) -> dict[int, F64]:
    """Read a MOTChallenge detection file as ``{frame: (k, 5) [left, top, w, h, score]}``.

    Parameters
    ----------
    path : str or os.PathLike
        ``det.txt`` (``frame,-1,left,top,width,height,score,...``).
    scale : float
        Multiplies the box coordinates (e.g. 0.625 for PETS09 boxes on the 480x360 video), in
        [0.001, 1000] as ``--det-scale``.

    Raises
    ------
    TypeError
        `scale` is not a real number; `path` is not a str or os.PathLike.
    ValueError
        `scale` outside [0.001, 1000], or a bad detection file.

    Warns
    -----
    UserWarning
        Boxes of zero width or height are left out (a box with no area cannot be tracked); a
        file without a score column (6 fields a row) gives every box the score 1; rows whose
        id is not -1 (another tracker's output) are read as detections, their ids ignored.
    """
    lo, hi = DET_SCALE_RANGE
    if not (lo <= number(scale, "detection scale", finite=False) <= hi):
        raise ValueError(f"detection scale is {scale}, expected a number in [{lo:g}, {hi:g}]")
    path = path_arg(path, "load_detections: path")
    rows = read_mot(path, what="detection file")
    if len(rows) and first_row_fields(path) == 6:
        warn(
            f"{path}: no score column (6 fields a row): every detection scores 1, so "
            "birth_score and min_conf gate none of them",
            stacklevel=2,
        )
    tracked = rows[:, 1] != -1  # detection files hold id -1 (MOTChallenge's "no id")
    if tracked.any():
        k = int(np.argmax(tracked))
        warn(
            f"{path}: {int(tracked.sum())} of {len(rows)} rows have a track id, not -1 (the "
            f"first: id {rows[k, 1]:g} in frame {int(rows[k, 0])}): a tracks file? Read as "
            "detections: the ids are ignored, the tracker makes its own",
            stacklevel=2,
        )
    flat = (rows[:, 4] <= 0) | (rows[:, 5] <= 0)
    if flat.any():
        warn(
            f"{path}: {int(flat.sum())} detection(s) with zero width or height left out (the "
            f"first in frame {int(rows[np.argmax(flat), 0])})",
            stacklevel=2,
        )
        rows = rows[~flat]
    return _Scaled(
        {f: np.column_stack([r[:, 2:6] * scale, r[:, 6]]) for f, r in group_by_frame(rows).items()},
        float(scale),
        stated=not isinstance(scale, SeqinfoScale),
    )


class SeqinfoScale(float):
    """A detection scale taken from ``seqinfo.ini`` (the frames' width over ``imWidth``).

    What ``pftrack track`` and ``batch`` pass to :func:`load_detections` when no
    ``--det-scale`` is given, so that the dict knows its scale was not stated
    (:attr:`_Scaled.stated`).
    """


class _Scaled(dict[int, F64]):
    """:func:`load_detections`' dict, knowing the scale its boxes were multiplied by.

    For the scale a refusal suggests (:func:`_scale_hint`): the file's boxes need the whole
    factor, not a factor on top of ``--det-scale`` (``--det-scale 2`` on PETS09 suggested
    0.313, where 0.625 is right). `stated`: the scale was given (``--det-scale``,
    ``load_detections(scale=...)``), not taken from ``seqinfo.ini`` (:class:`SeqinfoScale`);
    :func:`_refuse_scaled_off`'s edge rule doubts only the latter.
    """

    def __init__(self, frames: dict[int, F64], scale: float, stated: bool = True) -> None:
        super().__init__(frames)
        self.scale = float(scale)
        self.stated = stated


def track_frames(
    source: PathLike | FrameSource | Sequence[NDArray[np.uint8]],
    *,
    detections: Mapping[int, ArrayLike] | None = None,
    config: TrackerConfig | None = None,
    rng: RngLike = 0,
    coasting: str = "confirmed",
    fill: FillMode = "linear",
    show_progress: bool | None = None,
    prime_frames: IntLike = 30,
    bootstrap: BootstrapMode = "auto",
    smoother: BoxSmoother | None = BoxSmoother(),  # noqa: B008 - frozen, shared safely
    link: LinkConfig | None = LinkConfig(),  # noqa: B008 - frozen, shared safely
    on_frame: Callable[[int, NDArray[np.uint8], list[Track], F64], None] | None = None,
    threads: bool = True,
) -> TrackingRun:
    """Track every frame of `source`: :class:`~pftrack.tracking.api.Tracker` over every frame.

    The same object a user's loop drives (priming, ``update``, ``finalize``): this function
    only reads the frames and turns each frame's ``[left, top, w, h, score]`` detections into
    ``[x1, y1, x2, y2, score]`` for :meth:`Tracker.update`.

    Parameters
    ----------
    source : path, FrameSource or sequence of frames
        Video file or image folder, or BGR uint8 frames in memory.
    detections : dict, optional
        Per-frame detections ``{frame: (k, 5) [left, top, w, h, score]}`` (or (k, 4), every
        score 1) with 1-based int frames, as :func:`load_detections` returns them (a file's
        path is refused: load it with ``pftrack.load_detections(path)``, or call
        :func:`track_path`); None uses the built-in detector.
    config : TrackerConfig, optional
        Tracker settings (default ``TrackerConfig()``).
    rng : numpy.random.Generator, int or None
        Seed (default 0, as ``pftrack track`` and :class:`~pftrack.Tracker`: the same frames
        give the same rows; None: fresh entropy).
    coasting, fill : str
        How gaps bridged by the particle filters are written (see
        :class:`~pftrack.tracking.TrackWriter`).
    show_progress : bool, optional
        Progress bar on stderr (default: when stderr is a terminal).
    prime_frames : int
        Start the built-in detector's background from the median of this many frames (0: learn
        from frame 1 on).
    bootstrap : {"auto", "spread", "first", "none"}
        Which frames (:func:`pftrack.detection.bootstrap.bootstrap_frames`): spread over the
        whole video (a first pass over a file or in-memory frames), the first ones, or none.
        "auto": spread for the built-in detector; the first ones with `detections` (only box
        refinement uses the background then, and a :class:`Tracker` loop can prime the same
        way, so the loop and this function agree).
    smoother : BoxSmoother or None
        Offline smoothing of every track's boxes once the run is over (None: boxes as the
        tracker reported them, frame by frame).
    link : LinkConfig or None
        Join fragments of one object once the run is over (None: keep every id).
    on_frame : callable, optional
        Called after each frame as ``on_frame(index, frame, tracks, rows)``: the 1-based frame
        index, the BGR frame, the tracks reported on it, and the (k, 10) MOTChallenge rows the
        run's writer settled during this frame (online boxes, before the offline pass; a
        bridged gap's rows arrive when the track is re-detected). For rendering while tracking
        and for writing rows of a live source as they come.
    threads : bool
        Decode and detect on threads ahead of the tracker (below), and decode the two halves
        of a file at once for the spread bootstrap (``bootstrap_frames(split=True)``). False
        does all the work on the calling thread, with the same rows: for a process that already
        has one task per core, such as a worker of ``pftrack batch``, where the extra threads
        only cost CPU.

    Raises
    ------
    TypeError
        `source` is not a path, a FrameSource or a sequence of frames (an iterator, an int,
        one frame alone: ``track_frames([frame])``); `detections` is not a dict (a path, a
        list), a key is not an int, or a value does not hold real numbers; `rng` is not a
        Generator, an int or None (a float, a bool); `threads` is not a bool, `show_progress`
        not a bool or None, `on_frame` not callable or None.
    ValueError
        A negative `rng`. A key below 1 (frames are 1-based: 0-based keys would put every box
        one frame late), a value not of shape (k, 5) or (k, 4), NaN, inf, a negative width or
        height;
        `detections` of frames after the video's last, by its frame count (one rule for every
        length; a source of unknown length, count 0, is not checked); `detections` for an image
        folder whose names skip numbers (:attr:`FrameSource.gap`: whether the detections count
        frames by name or by position is not known); or no frame could be read.

    Warns
    -----
    UserWarning
        A video that ended before its header's count left detections of later frames unused.

    Notes
    -----
    Three threads share the work: one decodes (:func:`~pftrack.io.prefetch.prefetch`; it also
    scales each frame to the working resolution and makes the grey the camera-motion check
    measures), one runs the detector on the frames in order ahead of the tracker
    (:class:`~pftrack.tracking.ahead.DetectAhead`: the built-in detector, or the foreground that
    refines external detections), and this one tracks. The rows are those of the loop that calls
    the detector inside ``update``, byte for byte, and a detector error is raised from
    ``update`` on its frame as there.
    """
    option(bootstrap, "bootstrap", ("auto", *BOOTSTRAPS))
    if bootstrap not in ("auto", *BOOTSTRAPS):
        raise ValueError(
            f"bootstrap mode is {bootstrap!r}, expected one of auto, {', '.join(BOOTSTRAPS)}"
        )
    # before any frame is read (was: any value taken for its truth, threads="no" ran threads)
    threads = flag(threads, "track_frames: threads")
    if show_progress is not None:
        show_progress = flag(show_progress, "track_frames: show_progress")
    if on_frame is not None and not callable(on_frame):  # was: "'str' object is not callable"
        raise TypeError(  # after the first frame was tracked
            f"track_frames: on_frame is {type(on_frame).__name__}, expected a callable "
            "on_frame(index, frame, tracks, rows) or None"
        )
    if detections is not None:
        detections = _check_detections(detections)
    config = config if config is not None else TrackerConfig()
    frames = FrameSource(source) if isinstance(source, (str, os.PathLike)) else source
    _check_frames(frames)
    if detections:
        _check_numbering(frames)
        # a FrameSource's count only when known: FFmpeg's estimate (Matroska's) may be short
        last = max((f for f, d in detections.items() if len(d)), default=0)
        # a header count below the detections' last frame is checked by counting the frames
        held = (
            frames.frames_to(last)
            if isinstance(frames, FrameSource)
            else getattr(frames, "counted_frames", len(frames))
        )
        _check_last_frame(detections, held)
    # an int seed goes on as it is; anything else through generator(), whose errors name rng
    # (a float, a string, a bool or a negative int were NumPy's or MultiObjectTracker's)
    seed = (
        rng
        if rng is None
        or (isinstance(rng, (int, np.integer)) and not isinstance(rng, bool) and rng >= 0)
        else int(generator(rng, "track_frames: rng").integers(2**63))
    )
    tracker = Tracker.from_config(
        config, seed, coasting=coasting, fill=fill, smoother=smoother, link=link,
        prime_frames=prime_frames,
    )  # fmt: skip
    # the warnings of update() (the detector's too, from its thread) name the line that called
    # track_frames, or track_path, not this module's loop
    tracker._caller_depth = _calls_from_here(sys._getframe(1))
    _refuse_stopped(frames)
    if prime_frames > 0 and (detections is None or config.refine.enabled):
        if bootstrap == "auto":
            bootstrap = "spread" if detections is None else "first"
        if isinstance(frames, FrameSource):
            # held at the working size as they are read (a 4K video's 30 frames were 750 MB);
            # a bar of the frames read, as the spread pass decodes the whole file first (was:
            # nothing drawn for it, minutes on an hour's video)
            n_prime = int(prime_frames)
            with Bar(n_prime, desc="background", enable=show_progress, unit="frame") as bar:
                read = itertools.count(1)

                def prepare(frame: NDArray[np.uint8]) -> NDArray[np.uint8]:
                    kept = tracker.working_frame(frame)
                    # from the pass's two threads too (next() is atomic), whose check of the
                    # halves' joint reads a frame twice; a batch's sequences draw no bar of
                    # their own and count nothing here
                    if bar.enabled:
                        bar.set(min(next(read), n_prime))
                    return kept

                primer = bootstrap_frames(
                    frames, prime_frames, bootstrap, split=threads, prepare=prepare
                )
            if primer:
                tracker.prime(primer, shape=(frames.height, frames.width, 3))
        else:  # frames in memory already, checked as the caller gave them (was: "prime frame
            # dtype is float64", naming prime, which the caller did not call)
            primer = bootstrap_frames(
                frames, prime_frames, bootstrap, split=threads, prepare=_source_frame
            )
            if primer:
                tracker.prime(primer)
    _refuse_stopped(frames)  # stopped while its bootstrap frames were read
    empty = np.zeros((0, 5))
    start = time.perf_counter()
    n = 0
    total = len(frames) or None
    # the detector runs on a thread ahead of the tracker (exact: it never reads the tracker's
    # state), whenever update() would call it: always with the built-in detector, for box
    # refinement's foreground with external detections
    ahead = detections is None or config.refine.enabled or config.sampler == "rjmcmc"

    def black_stand_in(k: int) -> bool:
        """Whether frame k is black in place of one the video could not decode, once read."""
        return k <= getattr(frames, "lead_black", 0)

    # the reader's warnings (a damaged start, a variable frame rate), on a reading thread with
    # threads: held there, given here from the caller's line before the frame read with them
    said: deque[_Said] = deque()
    reads = _reading(frames, said)
    if not threads:
        stream: Any = closing(reads)
    elif ahead:
        stream = DetectAhead(
            tracker.tracker,
            reads,
            external=detections is not None,
            prepare=tracker.working_frame,
            hand_over=tracker.hand_over,
            read_depth=4,  # as prefetch's: the reading thread prepares the frames too
            black_stand_in=black_stand_in,
        )
    else:
        stream = closing(prefetch(reads))
    with stream as decoded:  # the reading threads stop first
        for n, frame in enumerate(
            progress(decoded, total=total, desc="tracking", enable=show_progress, unit="frame"),
            start=1,
        ):
            _give(said, n, 2 + tracker._caller_depth)
            settled = tracker.n_settled
            if detections is None:
                with standing_in(black_stand_in(n)):
                    tracker.update(None, frame)
            else:
                dets = detections.get(n, empty)
                if n == 1:
                    _check_layout(
                        detections,
                        frame.shape[:2],
                        getattr(frames, "sequence", None),
                        getattr(frames, "rotation", 0),
                    )
                with standing_in(black_stand_in(n)):
                    tracker.update(xywh_to_xyxy_dets(dets), frame)
            if on_frame is not None:
                on_frame(n, frame, tracker.last_reports, tracker.settled_rows(settled))
    _give(said, n + 1, 2 + tracker._caller_depth)  # those of reading on to the end
    if n == 0:  # a FrameSource by its name, not its repr
        _refuse_stopped(source)
        raise ValueError(f"no frame could be read from {getattr(source, 'name', source)}")
    if detections:
        unused = [f for f in detections if f > n and len(detections[f])]
        if unused:  # the video ended early (a truncated file): say what was not tracked
            warn(
                f"detections of {len(unused)} frames after the video's last frame {n} were not "
                f"used (frames {min(unused)}-{max(unused)})",
                stacklevel=1 + tracker._caller_depth,
            )
    with bars(show_progress):  # the offline pass's bars ("smoothing") follow show_progress too
        rows = tracker.finalize()
    return TrackingRun(rows, n, time.perf_counter() - start)


def _refuse_stopped(source: Any) -> None:
    """Raise "stopped before its first frame" for a source whose ``stop()`` was called.

    Before a pass is begun, too: a read of a stopped :class:`FrameSource` is its own
    ValueError, which names no frame.
    """
    if getattr(source, "stopped", False):  # a FrameSource by its name, not its repr
        raise ValueError(f"{getattr(source, 'name', source)}: stopped before its first frame")


# a warning the reader gave while reading frame k (1-based; one past the last: at the end)
_Said = tuple[int, str, type[Warning]]


def _reading(frames: Iterable[Any], said: deque[_Said]) -> Iterator[Any]:
    """`frames`, each read inside a :class:`~pftrack._warn.Held`, its warnings put in `said`.

    On whatever thread iterates it (a reading thread with ``threads``): :func:`_give` gives
    them on the tracker's. `frames`' iterator is closed when this ends, however it ends.
    """
    it = iter(frames)
    end = object()
    try:
        for k in itertools.count(1):
            with Held() as held:
                frame = next(it, end)
            said.extend((k, message, category) for message, category in held.pending)
            if frame is end:
                return
            yield frame
    finally:
        close = getattr(it, "close", None)
        if close is not None:
            close()


def _give(said: deque[_Said], upto: int, stacklevel: int) -> None:
    """Give the warnings in `said` of reading frames 1..`upto`, from the line `stacklevel` names.

    `stacklevel` as ``warnings.warn``'s if it were called here: 2 names this function's caller.
    """
    while said and said[0][0] <= upto:
        _, message, category = said.popleft()
        warn(message, category, stacklevel=stacklevel)


def _calls_from_here(caller: FrameType | None) -> int:
    """Calls between :func:`track_frames` and the code outside this module that made it.

    `caller`: track_frames' caller's frame; 1 when it is outside this module, 2 through
    :func:`track_path`: the ``stacklevel`` past ``track_frames`` of the line a warning names.
    """
    depth = 1
    while caller is not None and caller.f_globals.get("__name__") == __name__:
        depth, caller = depth + 1, caller.f_back
    return depth


def _source_frame(frame: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """A frame of :func:`track_frames`' in-memory `source` checked, named as the caller's."""
    return bgr_frame(frame, "track_frames: source frame")


def _check_frames(frames: object) -> None:
    """Refuse a `source` that is neither a FrameSource nor a sequence of frames, naming it.

    Were Python's words: "object of type 'generator' has no len()", "'int' object is not
    iterable", and for bytes "prime frame is int". One frame alone (an (H, W, 3) or (H, W)
    array) is refused as :meth:`Tracker.prime` refuses it (its rows were taken for frames,
    and the message said they looked like grey frames).
    """
    if isinstance(frames, np.ndarray) and (
        frames.ndim == 2 or (frames.ndim == 3 and frames.shape[-1] == 3)
    ):
        raise TypeError(
            f"track_frames: source is one {frames.shape} frame, expected a sequence of frames: "
            "track_frames([frame])"
        )
    if isinstance(frames, np.ndarray) and frames.ndim not in (3, 4):
        # was: "len() of unsized object" (0-d), numbers taken for frames (1-d), 5-d frames
        raise TypeError(
            f"track_frames: source is an array of shape {frames.shape}, expected a sequence of "
            "frames: a (K, H, W, 3) uint8 array or a list of (H, W, 3) frames"
        )
    if isinstance(frames, FrameSource) or (
        hasattr(frames, "__len__")
        and hasattr(frames, "__getitem__")
        and not isinstance(frames, (bytes, bytearray))
    ):
        return
    if isinstance(frames, (int, np.integer)):
        hint = "; for a camera, FrameSource(index)"
    elif isinstance(frames, (bytes, bytearray)):
        hint = "; a path as a str"
    elif hasattr(frames, "__iter__"):
        hint = "; list(frames) for an iterator (the frames are read twice: to prime, to track)"
    else:
        hint = ""
    raise TypeError(
        f"track_frames: source is {type(frames).__name__}, expected a path, a FrameSource or "
        f"a sequence of frames{hint}"
    )


def _check_numbering(frames: object) -> None:
    """Refuse detections for an image folder whose names skip numbers (:attr:`FrameSource.gap`).

    Detection frame k is the k-th image; a detector run over such a folder may have numbered
    its frames by the names instead (``6.png`` as frame 6), and nothing tells which: every frame
    after the first gap would get another image's boxes, silently.
    """
    gap = frames.gap if isinstance(frames, FrameSource) else None
    if gap is not None:
        raise ValueError(
            f"{gap}: detections cannot be matched to these images (their frame numbers may be "
            "the names or the images' positions); rename the images 1..N in their order and "
            "number the detections' frames alike (frame k: the k-th image), or track without "
            "detections (frames 1..N in the names' order)"
        )


def _check_detections(detections: object, what: str = "detections") -> dict[int, F64]:
    """`detections` as ``{frame: (k, 5) or (k, 4) float64 array}``, checked value by value.

    What :func:`track_frames` takes: the dict of :func:`load_detections`, 1-based int frames
    (NumPy's too, not bools) to ``[left, top, w, h(, score)]`` rows; an empty value is any
    array without rows (``[]``, ``np.zeros((0, 5))``). The box rule of a detection file holds
    (:func:`pftrack._check.first_bad_box`: no negative width or height, nothing beyond ±1e9
    px), and every value is finite.

    Raises
    ------
    TypeError
        Not a mapping (a file's path: the message says to load it with ``load_detections``),
        a key that is not an int, a value that does not hold real numbers.
    ValueError
        A key outside 1..2**31-1, a value of another shape, NaN or inf, a bad box.
    """
    if isinstance(detections, (str, bytes, os.PathLike)):
        raise TypeError(
            f"{what} is a path ({os.fsdecode(detections)!r}), expected the dict "
            "{frame: (k, 5) [left, top, w, h, score]} of its boxes: load the file first with "
            "pftrack.load_detections(path), or call "
            "pftrack.tracking.run.track_path(source, detections=path)"
        )
    if not isinstance(detections, Mapping):
        raise TypeError(
            f"{what} must be a dict {{frame: (k, 5) [left, top, w, h, score] array}}, as "
            f"pftrack.load_detections returns, got {type(detections).__name__}"
        )
    checked: dict[int, F64] = {}
    for key, value in detections.items():
        if isinstance(key, (bool, np.bool_)) or not isinstance(key, (int, np.integer)):
            raise TypeError(
                f"{what} key {key!r} is {type(key).__name__}, expected an int frame number "
                "(1-based)"
            )
        f = int(key)
        if not 1 <= f <= MAX_FRAME:
            hint = (
                ": frames are 1-based, as in det.txt and load_detections (0-based keys would "
                "put every box one frame late; add 1 to each)"
                if f <= 0
                else ""
            )
            raise ValueError(f"{what} key {f} is not a frame number in 1..{MAX_FRAME}{hint}")
        name = f"{what}[{f}]"
        d = real_array(value, name, booleans=False)
        if d.ndim >= 1 and d.shape[0] == 0:
            checked[f] = np.zeros((0, 5))
            continue
        if d.ndim != 2 or d.shape[1] not in (4, 5):
            raise ValueError(
                f"{name} must have shape (k, 5) [left, top, w, h, score] (or (k, 4)), got {d.shape}"
            )
        finite = np.isfinite(d).all(axis=1)
        if not finite.all():
            r = int(np.argmin(finite))
            raise ValueError(f"{name} row {r} contains NaN or inf: {d[r].tolist()}")
        bad = first_bad_box(d[:, :4])
        if bad is not None:
            r, _, problem = bad
            raise ValueError(f"{name} row {r} {d[r, :4].tolist()}: {problem} (left, top, w, h)")
        checked[f] = d
    if isinstance(detections, _Scaled):
        return _Scaled(checked, detections.scale, detections.stated)
    return checked


def _check_last_frame(detections: dict[int, F64], n_frames: int) -> None:
    """Refuse detections of frames after the video's last, by the video's frame count.

    One rule for every length, a 1-frame video too. A count of 0 is unknown (a camera, a
    stream, a raw ``.h264`` file whose header has none) and is not checked; a video that ends
    before its header's count is found out while reading (:func:`track_frames` then warns
    about the detections it did not use).
    """
    last = max((f for f, d in detections.items() if len(d)), default=0)
    if n_frames <= 0 or last <= n_frames:
        return
    frames = "frame 1" if n_frames == 1 else f"frames 1-{n_frames}"
    raise ValueError(
        f"detections go up to frame {last} but the video has {n_frames} "
        f"frame{'s' * (n_frames != 1)}: they belong to a longer video; keep only the rows of "
        f"{frames} (e.g. awk -F, '$1<={n_frames}' det.txt > short.txt) or give the whole video"
    )


#: How far past ``seqinfo.ini``'s image size (a share of it) boxes may reach and still be taken
#: for boxes in its pixels (detectors' boxes overhang the edge a little).
SEQINFO_SLACK = 0.1
#: How near the frames' right and bottom edges (a share of each) boxes as given must reach to be
#: taken for boxes in the frames' pixels when ``seqinfo.ini`` is larger than the frames: every
#: det.txt here reaches at least 98.3 % of its own image size on each axis (PETS09 767x575 of
#: 768x576, TUD-Campus 639x472 of 640x480, ADL-Rundle-6, ETH-Sunnyday, KITTI-17 99.7 % or more).
EDGE_REACH = 0.98
#: The largest scale (frames' width over ``imWidth``) :data:`EDGE_REACH` is applied at: closer to
#: 1, boxes in ``seqinfo.ini``'s pixels reach the frames' edges too (at 0.98, TUD-Campus's bottom
#: 472 of 470 rows), and the scale moves boxes by under 5 %. Up to it no det.txt here (>= 98.3 %
#: of its size) can be taken for one in the frames' pixels: that needs under (1 + 0.95) / 2.
EDGE_MAX_SCALE = 0.95
#: How far above a round ratio (a share of it) an estimate may be to be named by it.
ROUND_RATIO_REACH = 0.02


def _scale_hint(
    cols: int,
    rows: int,
    right: float,
    bottom: float,
    sequence: SequenceInfo | None,
    applied: float = 1.0,
) -> str:
    """The scale that brings boxes reaching `right` x `bottom` into `cols` x `rows` frames.

    `applied`: the scale the boxes were already multiplied by; the hint is the file's whole
    scale (the value to give ``--det-scale``). Exact where it is known: the frames' width over
    ``seqinfo.ini``'s ``imWidth``, when the file's boxes fit that size (``0.625 here (480 px
    frames, imWidth=768 in SEQ/seqinfo.ini)``). Else an estimate from the boxes' reach, which
    is an upper bound (the boxes seldom reach the last pixel): a round ratio of
    :data:`ROUND_RATIOS` just below it, or it to 3 digits.
    """
    right, bottom = right / applied, bottom / applied  # in the file's own pixels
    if sequence is not None and sequence.width is not None:
        w, h = sequence.width, sequence.height
        if right <= w * (1 + SEQINFO_SLACK) and (h is None or bottom <= h * (1 + SEQINFO_SLACK)):
            return (
                f"{cols / w:.4g} here ({cols} px frames, imWidth={w} in "
                f"{sequence.folder / 'seqinfo.ini'})"
            )
    estimate = min(cols / right, rows / bottom)
    near = [k for k in ROUND_RATIOS if k <= estimate <= k * (1 + ROUND_RATIO_REACH)]
    return f"about {max(near):.4g} here" if near else f"about {estimate:.3g} here"


def _at_edges(right: float, bottom: float, cols: int, rows: int, scale: float) -> bool:
    """Whether boxes reaching `right` x `bottom` as given are in `cols` x `rows` frames' pixels.

    For a ``seqinfo.ini`` larger than its frames (`scale` < 1, the frames' width over
    ``imWidth``): boxes in its pixels reach about ``cols / scale`` (every det.txt reaches at
    least :data:`EDGE_REACH` of its own image size on each axis), boxes in the frames' pixels
    about `cols`. Theirs when both reach at least :data:`EDGE_REACH` of the frames' edges and
    stay nearer them than ``seqinfo.ini``'s (below the mean of the two sizes on each axis): a
    real downscale by 0.95, whose boxes reach about 1.05 times the frames, is not taken for
    them, nor are boxes that stop short of the frames' edges (a detector's file of a scene
    whose people keep to one side: too little to tell, the scale taken).
    """
    far = (1 + 1 / scale) / 2
    return EDGE_REACH * cols <= right < far * cols and EDGE_REACH * rows <= bottom < far * rows


def _refuse_scaled_off(
    cols: int,
    rows: int,
    right: float,
    bottom: float,
    outside: NDArray[np.bool_],
    as_xyxy: NDArray[np.bool_],
    sequence: SequenceInfo | None,
    detections: Mapping[int, F64],
) -> None:
    """Refuse boxes that a scale moved off the frames they fit as given: ValueError.

    The scale is the one the file was read with (``scale`` of :func:`load_detections`:
    ``--det-scale``, or ``pftrack track``'s and ``batch``'s own, the frames' width over
    ``seqinfo.ini``'s ``imWidth``). Refused when the file's own boxes fit the frames (within
    :data:`SEQINFO_SLACK`) while the scaled ones lie in the frames' top-left quarter (within
    that slack too), or more than :data:`OUTSIDE_SHARE` of them wholly outside the frames, the
    conditions of :func:`_check_layout`'s warning and refusal: a ``seqinfo.ini`` whose size is
    not its images' (trial60cli: ``imWidth=1280`` beside 640x480 images tracked the boxes
    shrunk into the top-left corner, exit 0, with a warning to scale them; ``imWidth=320`` was
    refused as "in a larger frame's pixels? ... about 1 here", the scale 2 applied unsaid).
    Also refused, when the scale is ``seqinfo.ini``'s and was not stated (:class:`SeqinfoScale`)
    and at most :data:`EDGE_MAX_SCALE`: boxes that as given reach the frames' right and bottom
    edges (:func:`_at_edges`). A ``--det-scale`` or ``load_detections(scale=...)`` of that value
    is the user's word that the boxes are in ``seqinfo.ini``'s pixels, and is taken (was
    refused like the automatic scale). `outside` and `as_xyxy` are :func:`_check_layout`'s,
    one per box.
    """
    applied = float(getattr(detections, "scale", 1.0))
    n = len(outside)
    if applied == 1.0 or n < SMALL_LAYOUT_BOXES:
        return
    slack = 1 + SEQINFO_SLACK
    if right / applied > cols * slack or bottom / applied > rows * slack:
        return  # as given they do not fit the frames: the scale is theirs (PETS09's 0.625)
    # the sequence whose seqinfo.ini the scale is (a --det-scale of another value: the user's)
    seqinfo = (
        sequence
        if sequence is not None and sequence.width and abs(applied * sequence.width - cols) < 0.5
        else None
    )
    fit = "as given they fit those frames"
    if right <= 0.5 * cols * slack and bottom <= 0.5 * rows * slack:  # overhanging a little
        where = f"lie in the top-left {right:.3g}x{bottom:.3g} pixels of the {cols}x{rows} frames"
        which = f"all {n} detection boxes"
    elif outside.mean() > OUTSIDE_SHARE and not as_xyxy.all():
        where = f"lie wholly outside the {cols}x{rows} frames (they reach {right:.0f}x{bottom:.0f})"
        which = f"{outside.sum()} of {n} detection boxes"
    elif (
        seqinfo is not None
        and not getattr(detections, "stated", True)  # a scale the user states is theirs
        and applied <= EDGE_MAX_SCALE
        and _at_edges(right / applied, bottom / applied, cols, rows, applied)
    ):
        where = (
            f"stop at {right:.0f}x{bottom:.0f}, short of the {cols}x{rows} frames' right and "
            "bottom edges by the scale"
        )
        which, fit = f"all {n} detection boxes", "as given they reach those edges"
    else:
        return
    ini, why = "", ""
    if seqinfo is not None:
        size = f"{seqinfo.width}x{seqinfo.height}" if seqinfo.height else f"{seqinfo.width}"
        why = f" (the frames' width {cols} over imWidth={seqinfo.width} in "
        why += f"{seqinfo.folder / 'seqinfo.ini'})"
        ini = (  # batch and eval scale gt.txt by it too: --det-scale 1 alone is not enough
            f": seqinfo.ini's {size} is not its images' size? correct it to {cols}x{rows} "
            "(gt.txt is scaled by it too), or"
        )
    raise ValueError(
        f"{which}, scaled by {applied:g}{why}, {where}, and {fit} "
        f"(they reach {right / applied:.0f}x{bottom / applied:.0f}): they are in the frames' "
        f"pixels already{ini or ';'} give --det-scale 1 / load_detections(scale=1)"
    )


def _check_layout(
    detections: Mapping[int, F64],
    shape: tuple[int, ...],
    sequence: SequenceInfo | None = None,
    rotation: int = 0,
) -> None:
    """Refuse x1, y1, x2, y2 boxes as left, top, w, h and a larger frame's; warn of a smaller's.

    Decided on the whole file: more than half of the boxes, read as ``left, top, w, h``, reach
    past the frame's right or bottom edge, while every box read as ``x1, y1, x2, y2`` lies in it.
    A larger frame's pixels: at least :data:`SMALL_LAYOUT_BOXES` boxes, more than
    :data:`OUTSIDE_SHARE` of them wholly outside the frame (the tracker would drop them and
    clip the rest: PETS09's 768x576 det.txt on its 480x360 video loses half its boxes so).
    The warning: at least :data:`SMALL_LAYOUT_BOXES` boxes, and none reaches past half the
    frame's width or height (boxes too large for the frame are clipped, with a warning, by
    the tracker). The scale the refusal suggests is :func:`_scale_hint`'s (`sequence`: the
    source's ``seqinfo.ini``, if any); when the video is turned 90 or 270 degrees as it is
    read (`rotation`: :attr:`FrameSource.rotation`) and the boxes fit its frames unturned, the
    refusal says that instead: detections made on the stored frames.
    """
    d = np.concatenate([v[:, :4] for v in detections.values() if len(v)] or [np.zeros((0, 4))])
    if len(d) == 0:
        return
    rows, cols = shape[0], shape[1]
    past = (d[:, 0] + d[:, 2] > cols) | (d[:, 1] + d[:, 3] > rows)
    as_xyxy = (d[:, 2] > d[:, 0]) & (d[:, 3] > d[:, 1]) & (d[:, 2] <= cols) & (d[:, 3] <= rows)
    right, bottom = float(np.max(d[:, 0] + d[:, 2])), float(np.max(d[:, 1] + d[:, 3]))
    outside = (d[:, 0] >= cols) | (d[:, 1] >= rows)
    _refuse_scaled_off(cols, rows, right, bottom, outside, as_xyxy, sequence, detections)
    if len(d) >= SMALL_LAYOUT_BOXES and right < 0.5 * cols and bottom < 0.5 * rows:
        warn(
            f"all {len(d)} detection boxes lie in the top-left {right:.3g}x{bottom:.3g} pixels "
            f"of the {cols}x{rows} frames: are they in a smaller frame's pixels? (scale them "
            "with --det-scale / load_detections(scale=...))",
            stacklevel=3,
        )
    if len(d) >= SMALL_LAYOUT_BOXES and outside.mean() > OUTSIDE_SHARE and not as_xyxy.all():
        slack = 1 + SEQINFO_SLACK  # detectors' boxes overhang the edge a little
        if rotation in (90, 270) and right <= rows * slack and bottom <= cols * slack:
            raise ValueError(  # they fit the frames unturned: made on the stored frames
                f"{outside.sum()} of {len(d)} detection boxes lie wholly outside the "
                f"{cols}x{rows} frames (they reach {right:.0f}x{bottom:.0f}), and all fit "
                f"{rows}x{cols}: the video is stored {rows}x{cols} and turned {rotation} "
                "degrees clockwise by its rotation metadata, as players, FFmpeg and OpenCV "
                "show it and pftrack reads it; run the detector on the frames as shown "
                "(OpenCV's VideoCapture turns them), not on the stored ones"
            )
        raise ValueError(
            f"{outside.sum()} of {len(d)} detection boxes lie wholly outside the {cols}x{rows} "
            f"frames (they reach {right:.0f}x{bottom:.0f}): are they in a larger frame's "
            f"pixels? Scale them with --det-scale / load_detections(scale=...), "
            f"{_scale_hint(cols, rows, right, bottom, sequence, getattr(detections, 'scale', 1.0))}"
        )
    if past.mean() > 0.5 and as_xyxy.all():
        raise ValueError(
            f"{past.sum()} of {len(d)} detection boxes reach past the {cols}x{rows} frame as "
            "left, top, width, height, and all fit it as x1, y1, x2, y2: the file's boxes look "
            "like x1, y1, x2, y2 (MOTChallenge det.txt has left, top, width, height)"
        )


def say_zero_based(detections: Mapping[int, F64], n_frames: int, path: object) -> None:
    """Warn when :func:`load_detections`' file looks numbered from 0 without a frame-0 row.

    Every box would be drawn on the frame before its own, and nothing else tells
    (:func:`pftrack.io.mot.zero_based_note`); ``pftrack track`` and :func:`track_path` say it.
    """
    from pftrack.io.mot import zero_based_note

    base = zero_based_note((f for f, d in detections.items() if len(d)), n_frames, path)
    if base is not None:
        warn(base)


def track_path(
    source: PathLike | FrameSource,
    *,
    detections: PathLike | None = None,
    det_scale: float = 1.0,
    config: TrackerConfig | None = None,
    seed: int = 0,
    fill: FillMode = "linear",
    smooth: bool = True,
    link: bool = True,
    show_progress: bool | None = None,
    threads: bool = True,
    on_frame: Callable[[int, Any, Any, Any], None] | None = None,
) -> TrackingRun:
    """Track a video file or image folder as ``pftrack track`` does (and ``pftrack batch``).

    The one place that turns the command's settings into a run, so that ``pftrack track`` and
    every task of ``pftrack batch`` give the same rows for the same seed.

    Parameters
    ----------
    source : path or FrameSource
        Video file, image folder or MOTChallenge sequence folder.
    detections : path, optional
        MOTChallenge detection file; None uses the built-in detector of `config`.
    det_scale : float
        Multiplies the detection boxes (see :func:`load_detections`).
    config : TrackerConfig, optional
        Tracker settings (default ``TrackerConfig()``).
    seed : int
        Random seed.
    fill : {"linear", "pf"}
        Boxes of bridged gaps when `smooth` is False (see :func:`track_frames`).
    smooth, link : bool
        Smooth every track offline (:class:`BoxSmoother`); join fragments of one object
        (:class:`~pftrack.recovery.LinkConfig`). Only ``True`` or ``False`` (TypeError).
    show_progress : bool, optional
        Per-frame progress bar on stderr (default: when stderr is a terminal).
    threads : bool
        Decode and detect on threads ahead of the tracker (see :func:`track_frames`).
    on_frame : callable, optional
        Called after each frame (see :func:`track_frames`): ``pftrack batch`` reports its
        progress through it.
    """
    smooth, link = flag(smooth, "smooth"), flag(link, "link")
    frames = source if isinstance(source, FrameSource) else FrameSource(source)
    dets = None
    if detections is not None:
        dets = load_detections(detections, det_scale)
        say_zero_based(dets, frames.counted_frames, detections)
    return track_frames(
        frames,
        detections=dets,
        config=config,
        rng=seed,
        fill=fill,
        show_progress=show_progress,
        smoother=BoxSmoother() if smooth else None,
        link=LinkConfig() if link else None,
        threads=threads,
        on_frame=on_frame,
    )
