"""Pictures people would rather look at than read: annotated video and trajectory plots."""

from __future__ import annotations

import functools
import itertools
import operator
import queue
import threading
import time
from collections import deque
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Protocol, TypeVar

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack._check import (
    bgr_array,
    bgr_frame,
    brief,
    flag,
    integer,
    number,
    path_arg,
    real_array,
    shown,
    text,
)
from pftrack._threads import join_through_interrupts
from pftrack._typing import F64, PathLike, RealLike
from pftrack.io.mot import group_by_frame
from pftrack.io.opencv_io import text_for_opencv, write_image
from pftrack.io.video_writer import VideoWriter
from pftrack.recovery.linking import FILLED_MARK, FLAG_COLUMN

__all__ = [
    "TrackRenderer",
    "colour_of",
    "draw_tracks",
    "draw_trails",
    "ink_scale",
    "paths_title",
    "plot_trajectories",
    "write_annotated_video",
]

Box = tuple[int, int, int, int]  # a drawn tag's pixels: x0, y0, x1, y1, inclusive


def colour_of(track_id: int) -> tuple[int, int, int]:
    """A stable, distinct BGR colour for an id (golden-ratio hue steps).

    Cached: every drawn frame asks again for the colour of each track, box and trail.

    Raises
    ------
    TypeError
        `track_id` is not a number (text, None, an array).
    ValueError
        `track_id` is NaN or infinite.
    """
    try:  # checked where it fails: the cached call is the per-box path
        return _colour_of(track_id)
    except TypeError:  # was: "unhashable type: 'numpy.ndarray'", "can't multiply sequence"
        raise TypeError(f"colour_of: track_id must be a number, got {shown(track_id)}") from None
    except (ValueError, OverflowError):  # was: "cannot convert float NaN to integer"
        raise ValueError(f"colour_of: track_id is {track_id}, expected a finite number") from None


@functools.lru_cache(maxsize=4096)
def _colour_of(track_id: int) -> tuple[int, int, int]:
    """:func:`colour_of`, unchecked and cached."""
    hue = int((track_id * 0.618033988749895 % 1.0) * 179)
    hsv = np.array([[[hue, 220, 255]]], dtype=np.uint8)
    b, g, r = cv2.cvtColor(hsv, cv2.COLOR_HSV2BGR)[0, 0]
    return int(b), int(g), int(r)


def ink_scale(shape: tuple[int, ...]) -> int:
    """How much thicker lines and larger labels are drawn on a frame of `shape` (H, W, ...).

    One step per 540 pixels of the shorter side, at least 1: 1 up to 1280x720 (as they always
    looked), 2 at 1920x1080, 4 at 3840x2160, so that labels stay readable when a large video
    is shown scaled down.

    Raises
    ------
    TypeError
        `shape` is not a sequence of at least two integers (a frame given for its shape:
        ``ink_scale(frame.shape)``).
    ValueError
        Its height or width is negative.
    """
    try:  # was: an IndexError of a str or an empty array, NumPy's "truth value" of a frame
        h, w = (operator.index(v) for v in shape[:2])
    except (TypeError, ValueError, IndexError):
        got = f"a {shape.shape} array" if isinstance(shape, np.ndarray) else brief(shape)
        raise TypeError(
            f"ink_scale: shape must be a frame's shape (H, W, ...) of integers, got {got}"
            + ("; give frame.shape" if isinstance(shape, np.ndarray) and shape.ndim > 1 else "")
        ) from None
    if h < 0 or w < 0:
        raise ValueError(f"ink_scale: shape is {tuple(shape)}, expected H, W >= 0")
    return max(1, min(h, w) // 540)


def draw_tracks(
    frame: NDArray[np.uint8], rows: NDArray[np.float64], label: str = ""
) -> NDArray[np.uint8]:
    """Draw MOT rows (k, 6+) of one frame on a copy of `frame`: boxes and ids.

    A box is dashed where it was not observed: a row that ``pftrack recover`` or ``smooth``
    filled (columns 8-10 ``1, -1, -1``, :func:`pftrack.recovery.filled_mask`), or a track
    coasting in :class:`TrackRenderer`; other rows are solid (MOT16+ ground truth's class 1
    in column 8 too). Lines and labels grow with the frame (:func:`ink_scale`). `label` goes in
    the top-left corner of a frame with room for it there (at most half its width and a third
    of its height: ``"frame 123"`` from 138x48 pixels).

    Raises
    ------
    ValueError
        `rows` are not (k, 6+) MOT rows with finite frame, id and box; `frame` is not
        (H, W, 3) with pixels.
    TypeError
        `rows` are not real numbers; `label` is not a str; `frame` is not a uint8 array.
    """
    rows = _track_rows(rows, "draw_tracks")  # was "not enough values to unpack" of (k, 5)
    text(label, "draw_tracks: label")  # was an AttributeError ('encode')
    return _draw_boxes(bgr_frame(frame, "draw_tracks: frame"), rows, label)


def _draw_boxes(frame: NDArray[np.uint8], rows: F64, label: str) -> NDArray[np.uint8]:
    """:func:`draw_tracks` of rows checked already (each frame of a video whose rows were)."""
    out: NDArray[np.uint8] = frame.copy()
    k = ink_scale(out.shape)
    # the tags drawn so far: each id's tag misses them when there is room, moved up or down the
    # least (was: ids of people walking side by side drawn over one another, and over the
    # frame number)
    taken: list[Box] = []
    size = _text_size(label, 0.45 * k, k) if label else ((0, 0), 0)
    (tw, _), base = size
    # only where it fits in a corner (was: on a 32x24 frame, a tag over two thirds of it)
    corner = (
        bool(label) and 2 * (6 * k + tw) <= out.shape[1] and 3 * (15 * k + base) <= out.shape[0]
    )
    if corner:  # its place is taken now; it is drawn last, over the boxes, as before
        taken.append(_tag_place(out.shape, (5 * k, 15 * k), k, size)[1])
    # was: column 8 == 1 alone, drawn thin: every box of MOT16+ truth (class 1, pedestrian)
    filled = _filled(rows)
    for i, r in enumerate(rows):
        tid = int(r[1])
        x, y, w, h = (int(round(v)) for v in r[2:6])
        c = colour_of(tid)
        if filled[i]:
            _dashed_rectangle(out, (x, y), (x + w, y + h), c, 2 * k, 6 * k)
        else:
            cv2.rectangle(out, (x, y), (x + w, y + h), c, 2 * k)
        # the whole label inside the frame, over the part of the box that is (was: at the box's
        # left edge, off the frame for a box entering from the left, cut for one leaving right)
        _tag(out, str(tid), (x, y - 3 * k), 0.4 * k, c, k, None, taken)
    if corner:
        _tag(out, label, (5 * k, 15 * k), 0.45 * k, (0, 0, 0), k, size)
    return out


def _filled(rows: F64) -> NDArray[np.bool_]:
    """Which MOT rows (M, 6+) carry a filled row's mark, columns 8-10 ``1, -1, -1``."""
    marks = rows[:, FLAG_COLUMN : FLAG_COLUMN + 3]
    if marks.shape[1] < 3:
        return np.zeros(len(rows), bool)
    out: NDArray[np.bool_] = np.all(marks == FILLED_MARK, axis=1)
    return out


@functools.lru_cache(maxsize=4096)
def _text_size(text: str, scale: float, k: int) -> tuple[tuple[int, int], int]:
    """``cv2.getTextSize`` of `text` as :func:`_tag` draws it: ((width, height), baseline).

    Cached: a video asks again for the size of each id on every frame it is drawn on.
    """
    (tw, th), base = cv2.getTextSize(text_for_opencv(text), cv2.FONT_HERSHEY_SIMPLEX, scale, k)
    return (tw, th), base


def _tag(
    image: NDArray[np.uint8],
    text: str,
    org: tuple[int, int],
    scale: float,
    colour: tuple[int, int, int],
    k: int,
    size: tuple[tuple[int, int], int] | None = None,
    taken: list[Box] | None = None,
) -> Box:
    """`text` near `org` (its baseline's left end) on a box of `colour`, in black or white.

    Legible on any frame (was: a white frame number on a white frame, a coloured id on that
    colour): the ink is whichever of black and white stands out of `colour` more; `k` is the
    ink's thickness and the box's margin. The tag is moved the least that puts it whole inside
    `image` (a box's id on a box partly outside the frame, a path's id at a point outside the
    plot). `size`: :func:`_text_size` of `text`, when the caller has it. `taken`: the boxes of
    the tags drawn before, which this one is moved up or down the least to miss, when there is
    room (:func:`_free_y`), and joins. Returns the tag's box (x0, y0, x1, y1), inclusive.
    """
    size = _text_size(text, scale, k) if size is None else size
    (x, y), box = _tag_place(image.shape, org, k, size)
    if taken:
        (_, th), base = size
        moved = _free_y(taken, box[0], box[2], y, th + k, base, image.shape[0]) - y
        y, box = y + moved, (box[0], box[1] + moved, box[2], box[3] + moved)
    if taken is not None:
        taken.append(box)
    cv2.rectangle(image, box[:2], box[2:], colour, -1)
    luma = 0.114 * colour[0] + 0.587 * colour[1] + 0.299 * colour[2]  # BT.601, BGR
    ink = (0, 0, 0) if luma > 127 else (255, 255, 255)
    cv2.putText(
        image, text_for_opencv(text), (x, y), cv2.FONT_HERSHEY_SIMPLEX, scale, ink, k, cv2.LINE_AA
    )
    return box


def _tag_place(
    shape: tuple[int, ...], org: tuple[int, int], k: int, size: tuple[tuple[int, int], int]
) -> tuple[tuple[int, int], Box]:
    """Where :func:`_tag` puts a tag of `size` asked at `org` on an image of `shape`.

    Whole inside the image, before it misses other tags: its text's origin (x, y) and its box
    (x0, y0, x1, y1), inclusive.
    """
    (tw, th), base = size
    x = max(k, min(org[0], shape[1] - tw - k))
    y = min(max(th + k, org[1]), shape[0] - base - k)
    return (x, y), (x - k, y - th - k, x + tw + k - 1, y + base)


def _free_y(taken: list[Box], x0: int, x1: int, y: int, above: int, below: int, rows: int) -> int:
    """The baseline nearest `y` whose tag, `above` rows over it and `below` under, misses `taken`.

    The tag spans columns `x0` to `x1`; only baselines that keep it inside `rows` rows are
    tried: `y` itself, and just under or just over each box of `taken` (the nearest free place
    is one of them). None free (a crowd of tags taller than the image): `y`.
    """

    def free(b: int) -> bool:
        return all(x1 < t[0] or t[2] < x0 or b + below < t[1] or t[3] < b - above for t in taken)

    inside = range(above, rows - below)
    if y in inside and free(y):  # the first try (distance 0): most tags, without the sort
        return y  # of 2 len(taken) + 1 tries (a crowd's 48 tags: a fifth of drawing a frame)
    tries = [y] + [t[3] + above + 1 for t in taken] + [t[1] - below - 1 for t in taken]
    return next((b for b in sorted(tries, key=lambda b: abs(b - y)) if b in inside and free(b)), y)


def _dashed_rectangle(
    image: NDArray[np.uint8],
    p0: tuple[int, int],
    p1: tuple[int, int],
    colour: tuple[int, int, int],
    thickness: int,
    dash: int,
) -> None:
    """A rectangle from corner `p0` to `p1` of dashes `dash` px long and gaps as long."""
    (x0, y0), (x1, y1) = p0, p1
    corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)]
    for a, b in itertools.pairwise(corners):
        length = max(abs(b[0] - a[0]), abs(b[1] - a[1]))
        for s in range(0, length + 1, 2 * dash):
            e = min(s + dash, length)
            t0, t1 = s / max(length, 1), e / max(length, 1)
            q0 = (round(a[0] + (b[0] - a[0]) * t0), round(a[1] + (b[1] - a[1]) * t0))
            q1 = (round(a[0] + (b[0] - a[0]) * t1), round(a[1] + (b[1] - a[1]) * t1))
            cv2.line(image, q0, q1, colour, thickness)


def draw_trails(
    frame: NDArray[np.uint8], trails: Mapping[int, Sequence[tuple[float, float]]]
) -> None:
    """Draw each id's recent foot points on `frame` in place, as a line in the id's colour.

    Raises
    ------
    TypeError
        `frame` is not a uint8 array; `trails` is not a mapping of ids (numbers) to points;
        an id's points are not real numbers.
    ValueError
        `frame` is not (H, W, 3) with pixels, is read-only, or is a view OpenCV cannot draw
        into in place (a flipped or Fortran-ordered one); an id's points are not (n, 2), or
        not finite within ±1e9.
    """
    # each was an AttributeError, an IndexError, NumPy's "cannot reshape" or OpenCV's
    # assertion over several lines; NaN points were drawn at -2**31 with a RuntimeWarning
    frame = bgr_array(frame, "draw_trails: frame")  # the same array: drawn in place
    if frame.shape[0] == 0 or frame.shape[1] == 0:
        raise ValueError(f"draw_trails: frame shape is {frame.shape}, expected H, W > 0")
    if not frame.flags.writeable:
        raise ValueError("draw_trails: frame is read-only; it is drawn in place (frame.copy())")
    if frame.strides[0] < 0 or frame.strides[1:] != (3, 1):
        raise ValueError(
            f"draw_trails: frame has strides {frame.strides}, a view OpenCV cannot draw into "
            "in place (flipped or Fortran-ordered): draw on np.ascontiguousarray(frame)"
        )
    if not isinstance(trails, Mapping):
        raise TypeError(
            f"draw_trails: trails must be a mapping of ids to foot points {{id: [(x, y), ...]}}, "
            f"got {type(trails).__name__}"
        )
    checked: dict[int, F64] = {}  # every id checked before the first is drawn
    for tid, pts in trails.items():
        number(tid, "draw_trails: trails' id")
        what = f"draw_trails: trails[{tid!r}]"
        a = real_array(pts, what, booleans=False)
        if a.size and (a.ndim != 2 or a.shape[1] != 2):
            raise ValueError(f"{what} has shape {a.shape}, expected (n, 2) points x, y")
        if not np.all(np.abs(a) <= 1e9):
            raise ValueError(f"{what} has NaN, inf or a value beyond ±1e9")
        checked[tid] = a
    _draw_trails(frame, checked)


def _draw_trails(image: NDArray[np.uint8], trails: Mapping[int, ArrayLike]) -> None:
    """:func:`draw_trails` of a frame and trails checked already.

    The render worker's, every frame: its trails are the feet of rows that
    :meth:`TrackRenderer.add` checked (was: every point checked again there, each frame).
    """
    for tid, pts in trails.items():
        _trail_line(image, pts, colour_of(tid))


def _foot(box: NDArray[np.float64]) -> tuple[float, float]:
    """Bottom centre of an ``[left, top, width, height]`` box: where a walker stands."""
    return float(box[0] + box[2] / 2), float(box[1] + box[3])


#: Seconds between the render worker's looks at its queue, and the caller's at a full queue:
#: neither thread sleeps on the queue's condition alone (see :meth:`TrackRenderer._put`).
_POLL = 0.05
#: Longest trail, in frames (``pftrack render --trail``'s limit).
MAX_TRAIL = 100_000
#: The columns of a MOT row that the pictures read.
ROW_COLUMNS = "frame, id, left, top, width, height"
#: Largest side of a plot's canvas in pixels (OpenCV's image limit).
MAX_CANVAS = 32767


def _track_rows(rows: ArrayLike, who: str, what: str = "rows") -> F64:
    """MOT rows (M, 6+) as float64, their first six columns finite; TypeError/ValueError.

    Named by `who` (the function) and `what` (the argument): ``plot_trajectories: rows has
    shape (4, 5), expected (M, 6+) MOT rows: frame, id, left, top, width, height[, ...]``.
    """
    a = real_array(rows, f"{who}: {what}", booleans=False)
    if a.size == 0:
        return np.zeros((0, 10))
    if a.ndim != 2 or a.shape[1] < 6:
        raise ValueError(
            f"{who}: {what} has shape {a.shape}, expected (M, 6+) MOT rows: {ROW_COLUMNS}[, ...]"
        )
    finite = np.isfinite(a[:, :6])
    if not finite.all():
        k = int(np.flatnonzero(~finite.all(axis=1))[0])
        raise ValueError(f"{who}: {what} row {k} has NaN or inf in {ROW_COLUMNS}")
    return a


def write_annotated_video(
    path: PathLike,
    frames: Iterable[NDArray[np.uint8]],
    rows: NDArray[np.float64],
    fps: RealLike = 10.0,
    *,
    trail: int = 40,
    preset: str = "ultrafast",
) -> Path:
    """Write `frames` with the tracks of `rows` (MOT, 1-based frames) drawn on, atomically.

    ``.mp4`` is H.264 (see :class:`~pftrack.io.video_writer.VideoWriter`, whose x264 `preset`
    this is), ``.avi`` MJPG. Each track trails its foot points of the last `trail` frames,
    one line for each run of frames it was seen on (none across a frame it is absent from).

    Parameters
    ----------
    path : str or os.PathLike
        Output video: ``.mp4`` or ``.avi``, written atomically.
    frames : iterable of (H, W, 3) ndarray of uint8
        The BGR frames, frame 1 first (a generator is read once).
    rows : (M, 6+) ndarray
        MOT rows of the tracks: frame, id, left, top, width, height, ...
    fps : float
        Frame rate of the video (default 10).
    trail : int
        Foot points of the last `trail` frames drawn behind each track (0: none).
    preset : str
        x264 preset of an ``.mp4`` (default ``"ultrafast"``).

    Returns
    -------
    Path
        `path`.

    Raises
    ------
    ValueError
        `frames` is empty (nothing is written); `rows` are not (M, 6+) MOT rows (frame, id,
        left, top, width, height, ...) with those six values finite; `trail` is not in
        [0, :data:`MAX_TRAIL`]; a frame is not (H, W, 3) with pixels, or not of the first
        frame's size.
    TypeError
        `rows` are not real numbers; `trail` is not an integer; `frames` is not iterable (None);
        a frame is not a uint8 array; `path` is not a str or os.PathLike.
    """
    path = path_arg(path, "write_annotated_video: path")
    trail = integer(trail, "trail", 0, MAX_TRAIL)  # was: -1 drew none, 2.5 a TypeError
    rows = _track_rows(rows, "write_annotated_video")
    try:
        it = iter(frames)
    except TypeError:  # was: "'NoneType' object is not iterable", naming nothing
        raise TypeError(
            "write_annotated_video: frames must be an iterable of (H, W, 3) uint8 frames, got "
            f"{type(frames).__name__}"
        ) from None
    try:  # not next(it, None): [None] is a bad frame, not no frame
        first = next(it)
    except StopIteration:
        raise ValueError("write_annotated_video: frames is empty; no frame to write") from None
    by_frame = group_by_frame(rows)
    empty = np.zeros((0, 10))
    paths = _foot_paths(rows) if trail > 0 else {}
    with VideoWriter(path, fps, preset=preset) as writer:
        for k, frame in enumerate(itertools.chain([first], it), start=1):
            here = by_frame.get(k, empty)
            # was: a float frame OpenCV's assertion in putText
            frame = bgr_frame(frame, "write_annotated_video: frame")
            image = _draw_boxes(frame, here, f"frame {k}")
            for tid in {int(r[1]) for r in here} if trail > 0 else ():
                # the foot points of frames k - trail + 1 .. k (was: the last `trail` points
                # however old, a line across the track's absence from a point long gone), one
                # line for each run of frames it was seen on (was: a straight line across its
                # absence, from where it left to where it came back, as if walked)
                frames, feet, _ = paths[tid]
                a, b = np.searchsorted(frames, [k - trail, k], side="right")
                for run in _runs(frames[a:b], feet[a:b]):
                    _trail_line(image, run, colour_of(tid))
            writer.write(image)
    return Path(path)


def _foot_paths(rows: F64) -> dict[int, tuple[F64, F64, NDArray[np.bool_]]]:
    """Each id's frames (n,), foot points (n, 2) and rows seen, not filled (n,), by frame.

    :func:`write_annotated_video`'s trails and :func:`plot_trajectories`' paths.
    """
    ids = np.trunc(rows[:, 1])  # as int() takes an id
    r = rows[np.lexsort((rows[:, 0], ids))]
    cuts = [0, *(np.flatnonzero(np.diff(np.trunc(r[:, 1]))) + 1), len(r)]
    feet = np.column_stack([r[:, 2] + r[:, 4] / 2, r[:, 3] + r[:, 5]])
    seen = ~_filled(r)
    return {
        int(r[a, 1]): (r[a:b, 0], feet[a:b], seen[a:b])
        for a, b in itertools.pairwise(cuts)
        if b > a
    }


_S = TypeVar("_S", bound=np.generic)


def _runs(frames: F64, points: NDArray[_S]) -> list[NDArray[_S]]:
    """`points` split where `frames` (ascending) skip a frame: one part for each run."""
    return np.split(points, np.flatnonzero(np.diff(frames) > 1) + 1)


def _trail_line(image: NDArray[np.uint8], pts: ArrayLike, colour: tuple[int, int, int]) -> None:
    """Foot points `pts` (n, 2) as a line on `image`, in place; nothing for fewer than 2."""
    line = np.round(np.asarray(pts, dtype=np.float64)).astype(np.int32).reshape(-1, 1, 2)
    if len(line) > 1:
        cv2.polylines(image, [line], False, colour, ink_scale(image.shape), cv2.LINE_AA)


class TrackLike(Protocol):
    """What :class:`TrackRenderer` reads of a track (e.g. :class:`pftrack.tracking.Track`)."""

    @property
    def id(self) -> int: ...  # noqa: D102

    @property
    def box_xywh(self) -> NDArray[np.float64]: ...  # noqa: D102

    @property
    def time_since_update(self) -> int: ...  # noqa: D102


_Job = tuple[int, NDArray[np.uint8], NDArray[np.float64], dict[int, list[tuple[float, float]]]]


def _track_fields(track: TrackLike, i: int) -> tuple[int, F64, bool]:
    """`track`'s id, box (x, y, w, h) and whether it is coasting, or a TypeError naming it.

    Was: an AttributeError ('numpy.ndarray' object has no attribute 'box_xywh') for the drop-in
    :class:`~pftrack.Tracker`'s (M, 8) rows given instead of Track objects.
    """
    try:
        tid, box, since = track.id, track.box_xywh, track.time_since_update
    except AttributeError:
        raise TypeError(
            f"TrackRenderer.add: tracks[{i}] is {type(track).__name__}, expected a track with "
            "id, box_xywh and time_since_update (pftrack.tracking.Track, as "
            "MultiObjectTracker.update returns them; not Tracker.update's (M, 8) rows)"
        ) from None
    return tid, np.asarray(box, dtype=np.float64), bool(since)


class TrackRenderer:
    """Draw tracks with trails on frames as they are tracked, and encode them, on a thread.

    Tracking hands each decoded frame and its tracks to :meth:`add`; a worker thread draws
    and encodes while the next frame is tracked (OpenCV's drawing and the encoder release the
    GIL), so the video costs no second decode. Boxes are the tracker's online estimates.

    Parameters
    ----------
    path : str or os.PathLike
        ``.mp4`` (H.264) or ``.avi``; written atomically by
        :class:`~pftrack.io.video_writer.VideoWriter`.
    fps : float
        Frame rate of the video.
    trail : int
        Foot points of the last `trail` frames drawn behind each track (0: none), up to
        :data:`MAX_TRAIL`.
    threaded : bool
        Draw and encode on a worker thread (False: in :meth:`add`).
    backend : {"pyav", "opencv"}, optional
        Encoder (default: PyAV when installed).
    queue_size : int
        Frames waiting for the worker at most; :meth:`add` blocks beyond.
    preset : str
        x264 preset of an ``.mp4`` (:class:`~pftrack.io.video_writer.VideoWriter`).
    """

    def __init__(
        self,
        path: PathLike,
        fps: RealLike,
        *,
        trail: int = 40,
        threaded: bool = True,
        backend: str | None = None,
        queue_size: int = 8,
        preset: str = "ultrafast",
    ) -> None:
        path = path_arg(path, "TrackRenderer: path")
        self.trail = integer(trail, "trail", 0, MAX_TRAIL)  # was: 2.5 and True taken as 2, 1
        queue_size = integer(queue_size, "queue_size", 0, 2**31 - 1)  # 0: as 1
        threaded = flag(threaded, "threaded")  # was: asked for its truth (an array's: ambiguous)
        self.writer = VideoWriter(path, fps, backend=backend, preset=preset)
        self._trails: dict[int, deque[tuple[float, float]]] = {}
        self._error: BaseException | None = None
        self._n = 0
        self._ended = False  # closed or aborted: add() refuses frames after it
        self._queue: queue.Queue[_Job | None] | None = None
        self._thread: threading.Thread | None = None
        self._finished = threading.Event()  # the worker's last act
        if threaded:
            self._queue = queue.Queue(maxsize=max(queue_size, 1))
            self._thread = threading.Thread(target=self._work, name="pftrack-render", daemon=True)
            self._thread.start()

    def add(self, frame: NDArray[np.uint8], tracks: Iterable[TrackLike]) -> None:
        """Queue `frame` (BGR, not modified) with the tracks reported on it."""
        if self._ended:
            # was: queued for a worker that had stopped, silently, until the queue was full;
            # then add() waited for room for ever
            raise ValueError(
                f"TrackRenderer.add: the renderer of {self.writer.path} is "
                f"{self.writer.ended or 'closed'} already; make a new TrackRenderer for more frames"
            )
        # checked here, in the caller's thread (was: a float frame drawn black without a word)
        frame = bgr_frame(frame, "TrackRenderer.add: frame")
        self._raise_worker_error()
        try:
            each = iter(tracks)
        except TypeError:  # was: "'NoneType' object is not iterable"
            raise TypeError(
                "TrackRenderer.add: tracks must be an iterable of tracks "
                f"(MultiObjectTracker.update's list), got {type(tracks).__name__}"
            ) from None
        read = [_track_fields(t, i) for i, t in enumerate(each)]  # before anything changes
        self._n += 1
        rows, seen = [], set()
        for tid, box, coasting in read:
            # MOT row; columns 8-10 a filled row's mark when coasting: drawn dashed
            unseen = FILLED_MARK if coasting else (-1.0, -1.0, -1.0)
            rows.append([self._n, tid, *box[:4], 0.0, *unseen])
            seen.add(tid)
            if self.trail:
                trail = self._trails.setdefault(tid, deque(maxlen=self.trail))
                trail.append(_foot(box))
        for tid in set(self._trails) - seen:
            del self._trails[tid]
        trails = {tid: list(pts) for tid, pts in self._trails.items()}
        # checked here, in the caller's thread (was: a NaN box named by the worker, later)
        table = _track_rows(np.reshape(rows, (-1, 10)), "TrackRenderer.add", "tracks")
        job = (self._n, frame, table, trails)
        if self._queue is None:
            self._draw(job)
        else:
            self._put(job)

    def _put(self, item: _Job | None) -> None:
        """Queue `item` for the worker, never waiting inside the queue's condition.

        A Ctrl-C that lands in ``Queue.put``'s wait for room, as it takes the queue's lock
        back, leaves with the lock released under the worker's feet; the worker then missed
        the ``None`` that :meth:`abort` queued and ``pftrack track --render`` hung on Ctrl-C
        (1 run of 20 at random moments). The caller waits for room in short sleeps instead,
        and the worker looks at the queue every :data:`_POLL` s even if a wake-up was lost.
        """
        assert self._queue is not None
        while True:
            try:
                self._queue.put_nowait(item)
                return
            except queue.Full:
                time.sleep(_POLL / 10)

    def _draw(self, job: _Job) -> None:
        n, frame, rows, trails = job
        # the frame and rows were checked by add (was: checked again here, each frame)
        image = _draw_boxes(frame, rows, f"frame {n}")
        _draw_trails(image, trails)
        self.writer.write(image)

    def _work(self) -> None:
        try:
            self._work_queue()
        finally:
            self._finished.set()

    def _work_queue(self) -> None:
        assert self._queue is not None
        while True:
            try:
                job = self._queue.get(timeout=_POLL)  # a wake-up lost: found at the next look
            except queue.Empty:
                continue
            if job is None:
                return
            if self._error is None:
                try:
                    self._draw(job)
                except BaseException as exc:  # handed to the caller by add() or close()
                    self._error = exc

    def _raise_worker_error(self) -> None:
        if self._error is not None:
            self.abort()
            raise self._error

    def _join(self) -> None:
        if self._thread is not None and self._queue is not None:
            self._put(None)
            join_through_interrupts(self._thread, self._finished)  # not left inside OpenCV
            self._thread = None

    def close(self) -> Path:
        """Wait for the queued frames, finish the file and return its path."""
        self._ended = True
        self._join()
        self._raise_worker_error()
        return self.writer.close()

    def abort(self) -> None:
        """Stop without writing: the partial file is removed (a finished one stays)."""
        self._ended = True
        try:
            self._join()
        finally:  # an interrupt in the wait too: no partial file left
            self.writer.abort()

    @property
    def n_frames(self) -> int:
        """Frames encoded so far."""
        return self.writer.n_frames


def _nice_step(span: float, ticks: int = 6) -> int:
    """A tick step of 1, 2 or 5 times a power of ten giving about `ticks` ticks over `span`."""
    raw = max(span / ticks, 1.0)
    power = 10 ** int(np.floor(np.log10(raw)))
    return int(next(m * power for m in (1, 2, 5, 10) if m * power >= raw))


def _with_axes(canvas: NDArray[np.uint8], title: str) -> NDArray[np.uint8]:
    """`canvas` framed, with ticks and labels in its pixel coordinates (x right, y down).

    The frame's margins take the labels (x below, y on the left) and `title` (above).
    """
    h, w = canvas.shape[:2]
    font, scale, ink, grey = cv2.FONT_HERSHEY_SIMPLEX, 0.35, 1, (170, 170, 170)
    step = _nice_step(max(w, h))

    def size(text: str) -> tuple[int, int]:
        (tw, th), _ = cv2.getTextSize(text, font, scale, ink)
        return tw, th

    xs, ys = range(0, w, step), range(0, h, step)
    left = max(size(str(y))[0] for y in ys) + 10
    right = max(10, size(str(xs[-1]))[0] // 2 + 4)
    top = 24 if title else 10
    bottom = size("0")[1] + 14
    out = np.full((h + top + bottom, w + left + right, 3), 20, np.uint8)
    out[top : top + h, left : left + w] = canvas
    cv2.rectangle(out, (left - 1, top - 1), (left + w, top + h), grey, 1)
    for x in xs:
        cv2.line(out, (left + x, top + h), (left + x, top + h + 4), grey, 1)
        tw, th = size(str(x))
        org = (left + x - tw // 2, top + h + 6 + th)
        cv2.putText(out, text_for_opencv(str(x)), org, font, scale, grey, ink, cv2.LINE_AA)
    for y in ys:
        cv2.line(out, (left - 5, top + y), (left - 1, top + y), grey, 1)
        tw, th = size(str(y))
        org = (left - 7 - tw, top + y + th // 2)
        cv2.putText(out, text_for_opencv(str(y)), org, font, scale, grey, ink, cv2.LINE_AA)
    if title:
        cv2.putText(
            out, text_for_opencv(title), (left, 16), font, 0.45, (255, 255, 255), 1, cv2.LINE_AA
        )
    return out


def paths_title(name: str, rows: ArrayLike) -> str:
    """A title saying what :func:`plot_trajectories` of `rows` shows, for a source `name`.

    ``"PETS09-S2L1: foot-point paths of 23 tracks, frames 1-795"`` (no rows: ``0 tracks``).
    """
    a = _track_rows(rows, "paths_title")
    n = len(np.unique(a[:, 1]))
    what = f"{name}: foot-point paths of {n} track{'s' * (n != 1)}"
    if not len(a):
        return what
    first, last = int(a[:, 0].min()), int(a[:, 0].max())
    return f"{what}, frame {first}" if first == last else f"{what}, frames {first}-{last}"


def plot_trajectories(
    path: PathLike,
    rows: NDArray[np.float64],
    background: NDArray[np.uint8] | None = None,
    size: tuple[int, int] | None = None,
    truth: NDArray[np.float64] | None = None,
    title: str = "",
) -> Path:
    """Draw each track's foot-point path (bottom centre of its box) as a PNG, atomically.

    Each path is 2 px wide over the frames its track was seen on and 1 px across a hole (frames
    it has no row on, or filled rows: columns 8-10 ``1, -1, -1``, as ``pftrack recover`` marks
    them), with its id at its first point and a dot at its last.

    Parameters
    ----------
    path : str or os.PathLike
        Output image (``.png``).
    rows : (M, 6+) ndarray
        MOT rows of the tracks: frame, id, left, top, width, height, ...
    background : (H, W, 3) ndarray of uint8, optional
        Image to draw on (e.g. the first frame), dimmed; the picture is its size.
    size : (W, H), optional
        Canvas size when there is no background (default: the boxes' extent, and 10 px).
    truth : (M, 6+) ndarray, optional
        Ground truth, drawn thin and grey under the tracks.
    title : str
        Caption.

    Returns
    -------
    Path
        `path`.

    Raises
    ------
    ValueError
        `rows` or `truth` are not (M, 6+) MOT rows with finite frame, id and box; `size`
        is not two whole numbers from 1 to 32767, or the boxes reach beyond 32767 px.
    TypeError
        `rows` or `truth` are not real numbers; `background` is not a (H, W, 3) uint8 image;
        `title` is not a str; `path` is not a str or os.PathLike.

    Notes
    -----
    Without a background the canvas is framed by axes in image coordinates (pixels, x to the
    right, y down, as the boxes are given), with tick labels in margins around it: the PNG
    is larger than the canvas by them.
    """
    who = "plot_trajectories"
    path = path_arg(path, f"{who}: path")
    rows = _track_rows(rows, who)
    text(title, f"{who}: title")
    truth = None if truth is None else _track_rows(truth, who, "truth")
    if background is not None:
        background = bgr_frame(background, f"{who}: background")
        canvas = (background.astype(np.float32) * 0.45).astype(np.uint8)
    else:
        if size is None:
            both = rows if truth is None else np.vstack([rows[:, :6], truth[:, :6]])
            w = int(np.ceil(np.max(both[:, 2] + both[:, 4], initial=320))) + 10
            h = int(np.ceil(np.max(both[:, 3] + both[:, 5], initial=240))) + 10
            if max(w, h) > MAX_CANVAS:
                raise ValueError(
                    f"{who}: the boxes reach {w - 10}x{h - 10} px, beyond {MAX_CANVAS} px a "
                    "side; give a background or a size"
                )
        else:
            try:
                w, h = (int(v) for v in size)
                ok = (w, h) == tuple(size) and 1 <= min(w, h) and max(w, h) <= MAX_CANVAS
            except (TypeError, ValueError):
                ok = False
            if not ok:
                raise ValueError(
                    f"{who}: size is {brief(size)}, expected (width, height), whole numbers from 1 "
                    f"to {MAX_CANVAS}"
                )
        canvas = np.full((h, w, 3), 30, np.uint8)

    def paths(r: F64) -> dict[int, tuple[F64, NDArray[np.int32], NDArray[np.bool_]]]:
        """:func:`_foot_paths` of `r`, the points as the canvas's pixels."""
        return {
            tid: (frames, np.round(np.clip(feet, -MAX_CANVAS, MAX_CANVAS)).astype(np.int32), seen)
            for tid, (frames, feet, seen) in _foot_paths(r).items()
        }

    if truth is not None and len(truth):
        for _, pts, _ in paths(truth).values():
            cv2.polylines(canvas, [pts.reshape(-1, 1, 2)], False, (170, 170, 170), 1, cv2.LINE_AA)
    drawn = paths(rows) if len(rows) else {}
    for tid, (frames, pts, seen) in drawn.items():
        c = colour_of(tid)
        # the frames it was seen on 2 px wide, a hole in the track, or the rows filled there,
        # 1 px (was: 2 px, as if seen)
        cv2.polylines(canvas, [pts.reshape(-1, 1, 2)], False, c, 1, cv2.LINE_AA)
        runs = [run.reshape(-1, 1, 2) for run in _runs(frames[seen], pts[seen])]
        cv2.polylines(canvas, runs, False, c, 2, cv2.LINE_AA)
        cv2.circle(canvas, tuple(int(v) for v in pts[-1]), 3, c, -1)
    # each id at its path's first point, on a tag of its colour, over every path, whole inside
    # the canvas (was: the id's colour on the dimmed frame, off it for a track from outside)
    # (was: drawn over one another where paths begin together, at a door or the image's side)
    taken: list[Box] = []  # the tags drawn so far: each misses them when there is room
    for tid, (_, pts, _) in drawn.items():
        _tag(
            canvas, str(tid), (int(pts[0][0]), int(pts[0][1])), 0.4, colour_of(tid), 1, None, taken
        )
    if background is None:
        canvas = _with_axes(canvas, title)
    elif title:  # on as many lines as the frame's width needs (was: cut at its right edge)
        for i, line in enumerate(_wrapped(title, canvas.shape[1] - 10, 0.45)):
            cv2.putText(
                canvas, text_for_opencv(line), (5, 15 + 16 * i), cv2.FONT_HERSHEY_SIMPLEX, 0.45,
                (255, 255, 255), 1, cv2.LINE_AA,
            )  # fmt: skip
    return write_image(path, canvas, mark=True)  # any name (pftrack.io.opencv_io)


def _wrapped(text: str, width: int, scale: float) -> list[str]:
    """`text` split at its spaces into lines of at most `width` pixels, for a narrow frame.

    The width is measured in OpenCV's simplex font at `scale`; a word wider than `width` is
    alone on its line (a plot's title on a 320x240 frame: two lines).
    """
    lines: list[str] = []
    for word in text.split(" "):
        longer = f"{lines[-1]} {word}" if lines else word
        drawn = text_for_opencv(longer)
        fits = cv2.getTextSize(drawn, cv2.FONT_HERSHEY_SIMPLEX, scale, 1)[0][0] <= width
        if lines and fits:
            lines[-1] = longer
        else:
            lines.append(word)
    return lines
