"""The drop-in tracker: BoxMOT's ``update(dets, frame)`` convention, and the offline pass.

:class:`Tracker` is the one object behind both ``pftrack track`` (through
:func:`~pftrack.tracking.run.track_frames`) and a user's own loop, so that a script and the
command never disagree: the same frames, detections and seed give the same rows.

Time constants given in seconds (``max_coast``, ``prime``) are turned into frames with
``frame_rate`` (``round(seconds * frame_rate)``). Left at their defaults, every time constant
is the command's frame count at any frame rate: a track coasts 10 frames, :meth:`prime` reads
30, the linker bridges 30, the birth threshold watches 50 (from the first with detections),
the offline pass cuts after 7 coasted ones (``LifecycleConfig.relink_coast``) and a blind
coast ends after 3 (``LifecycleConfig.blind_coast``). Frame counts were measured better
than the same seconds at each sequence's own rate (public detections, seed 0, MOTA / IDF1):
PETS09-S2L1 at its 7 frames/s 77.9 / 79.6 against 76.4 / 58.2 with every constant in seconds
(3 frames of coasting, a linking gap of 8); ADL-Rundle-6 at 30/s 38.4 / 45.6 against 36.8 / 44.9;
KITTI-17 at 10/s 65.6 / 79.7 against 65.0 / 77.5; ETH-Sunnyday at 14/s 51.1 / 73.8 against
55.7 / 76.2 (docs/tracking.md, "The drop-in API"). So ``Tracker(frame_rate=r)`` with default
options is exactly ``pftrack track`` with default options, whatever ``r``; ``pftrack track``
keeps its options in frames and does not read the video's frame rate, so its results do not
depend on container metadata. Motion noise levels (particle and centre filters) are per frame.
"""

from __future__ import annotations

import copy
import itertools
import operator
import pickle
import threading
from collections.abc import Callable, Iterable, Sequence
from dataclasses import replace
from typing import Any, NamedTuple, SupportsIndex

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack._check import (
    MAX_CLASS,
    bgr_frame,
    brief,
    first_bad_class,
    flag,
    frames_iterator,
    integer,
    not_an_image,
    option,
    real,
    real_array,
)
from pftrack._check import seed as check_seed
from pftrack._limits import (
    DEFAULT_BURN_IN,
    DEFAULT_MH_ITER,
    DEFAULT_MH_PROPOSAL,
    DEFAULT_MH_RW_SIGMA,
    DEFAULT_MOVES,
    MAX_BURN_IN,
    MAX_MH_ITER,
    MAX_PARTICLES,
    MH_PROPOSALS,
    joint_samples_error,
    moves_error,
    proposal_error,
    unread_error,
)
from pftrack._stand_in import is_stand_in
from pftrack._typing import (
    F64,
    CameraMotion,
    DetectorName,
    DynamicsName,
    FillMode,
    IntLike,
    RealLike,
    RngLike,
    SamplerName,
)
from pftrack._warn import Held, warn
from pftrack.detection import KnnConfig, Mog2Config, PaperConfig
from pftrack.detection.base import BlobConfig
from pftrack.detection.blocking import BLOCK_FRAMES, blockiness, is_blocky
from pftrack.detection.light import BLANK_LEVELS, is_blank
from pftrack.detection.paper import PaperDetector
from pftrack.detection.size_model import PersonSizeModel
from pftrack.recovery.linking import LinkConfig
from pftrack.tracking.camera import Stabiliser
from pftrack.tracking.config import LifecycleConfig, TrackerConfig, hsv_disagrees
from pftrack.tracking.offline import (
    BoxSmoother,
    CrossingConfig,
    complete_boxes,
    drop_nested,
    drop_odd_sizes,
)
from pftrack.tracking.track import Track
from pftrack.tracking.tracker import MultiObjectTracker, first_copies
from pftrack.tracking.writer import TrackWriter

__all__ = [
    "REFERENCE_RATE",
    "CheckedBoxes",
    "Tracker",
    "check_boxes_xyxy",
    "working_size",
    "xywh_to_xyxy_dets",
]

#: Frames per second at which the frame-based defaults of ``pftrack track`` are stated.
REFERENCE_RATE = 25.0
#: Frames :meth:`Tracker.prime` reads by default (``pftrack track`` reads them ahead).
PRIME_FRAMES = 30

#: The longest span an option in seconds may give, in frames (as ``pftrack track --max-coast``).
MAX_SPAN_FRAMES = 100_000
#: The highest frame rate :class:`Tracker` accepts (as ``pftrack track --fps``).
MAX_FRAME_RATE = 1000.0

#: Boxes in one frame above which :meth:`Tracker.update` warns (its association takes seconds a
#: frame beyond: docs/tracking.md, 'Many detections in one frame').
MANY_DETECTIONS = 1000

#: Columns of :meth:`Tracker.update`'s output.
TRACK_COLUMNS = ("x1", "y1", "x2", "y2", "id", "conf", "cls", "det_ind")


def _unpickle_tracker(cls: type[Tracker], data: bytes) -> Tracker:
    """A pickled :class:`Tracker` (:meth:`Tracker.__reduce_ex__`) back."""
    tracker = cls.__new__(cls)
    tracker.__setstate__(pickle.loads(data))  # noqa: S301 - the caller's own pickle
    return tracker


def _frames(value: object, frame_rate: float, name: str) -> int:
    """`value` seconds as a whole number of frames at `frame_rate` (TypeError: not a number).

    Any real number (:func:`pftrack._check.real`: a Fraction, a NumPy scalar), taken as a
    float (was: a NumPy ``float16`` multiplied in ``float16``, which overflowed comparing).
    """
    seconds = real(value, name, finite=False)
    if not (np.isfinite(seconds) and seconds >= 0):
        raise ValueError(f"{name} is {value} s, expected a finite number of seconds >= 0")
    n = seconds * frame_rate
    if n > MAX_SPAN_FRAMES:
        raise ValueError(
            f"{name} is {seconds:g} s, {n:.3g} frames at {frame_rate:g} frames/s: more than "
            f"{MAX_SPAN_FRAMES}"
        )
    return int(round(n))


def _check_rate(frame_rate: object) -> float:
    """`frame_rate` as a float: TypeError or ValueError unless in ``(0, MAX_FRAME_RATE]``."""
    rate = real(frame_rate, "frame_rate")  # a Fraction too: PyAV's stream.average_rate
    if not 0 < rate <= MAX_FRAME_RATE:
        raise ValueError(
            f"frame_rate is {frame_rate}, expected a number in (0, {MAX_FRAME_RATE:g}]"
        )
    return rate


def xywh_to_xyxy_dets(dets: ArrayLike) -> F64:
    """``[left, top, w, h, ...]`` rows as ``[x1, y1, x2, y2, ...]`` (other columns kept)."""
    d = np.asarray(dets, dtype=np.float64)
    if d.size == 0:
        return np.zeros((0, 5))
    out: F64 = d.copy()
    out[:, 2:4] = d[:, :2] + d[:, 2:4]
    return out


def working_size(shape: tuple[int, ...], max_side: int | None) -> tuple[int, int] | None:
    """The (width, height) a frame of `shape` is tracked at, or None for its own size.

    A frame whose longer side exceeds `max_side` is scaled to that longer side, the other side
    rounded (at least 1 pixel) (:attr:`TrackerConfig.max_side`).
    """
    rows, cols = int(shape[0]), int(shape[1])
    if max_side is None or max(rows, cols) <= max_side:
        return None
    s = max_side / max(rows, cols)
    return max(1, round(cols * s)), max(1, round(rows * s))


class CheckedBoxes(NamedTuple):
    """What :func:`check_boxes_xyxy` returns (a tuple: ``xywh, cls, kept, ... = ...``)."""

    xywh_score: F64
    classes: NDArray[np.int64]
    kept: NDArray[np.int64]
    clipped: bool
    flat: int
    inverted: int
    extent: int


def _inside_working(
    xywh: F64, cls: NDArray[np.int64], kept: NDArray[np.int64], shape: tuple[int, ...]
) -> tuple[F64, NDArray[np.int64], NDArray[np.int64]]:
    """Scaled boxes without those the working frame of `shape` does not hold.

    A box inside the frame, scaled to the working size (``max_side``), may end up with no
    width or height, or with its near edge on the working frame's far edge: a sliver at the
    frame's edge, dropped here as the tracker's own check would drop it (was: the tracker
    dropped it after the classes had been matched to the rows, and refused the frame).
    """
    rows, cols = shape[0], shape[1]
    x, y, w, h = xywh[:, 0], xywh[:, 1], xywh[:, 2], xywh[:, 3]
    held = (w > 0) & (h > 0) & (x < cols) & (y < rows) & (x + w > 0) & (y + h > 0)
    if held.all():
        return xywh, cls, kept
    return xywh[held], cls[held], kept[held]


def check_boxes_xyxy(
    dets: ArrayLike,
    shape: tuple[int, int],
    *,
    name: str = "dets",
    xywh_hint: bool = True,
    seen: tuple[int, int] = (0, 0),
) -> CheckedBoxes:
    """Check detections ``[x1, y1, x2, y2(, conf(, cls))]`` and clip them to the frame.

    Parameters
    ----------
    dets : (N, 4), (N, 5) or (N, 6) array_like of float
        Boxes in pixels, optionally with confidence (default 1) and class id (default 0).
    shape : (int, int)
        The frame's rows and columns.
    name : str
        What the messages call `dets`.
    xywh_hint : bool
        Whether the refusal of inverted boxes may say they look like ``x, y, w, h`` (False
        where the boxes come from a library that always gives ``x1, y1, x2, y2``).
    seen : (int, int)
        Inverted boxes and boxes with an extent (not without area) of the run's earlier
        frames: the evidence of a layout mistake adds up over a run (:meth:`Tracker.update`).

    Returns
    -------
    CheckedBoxes
        A named tuple of:
    xywh_score : (K, 5) ndarray
        The boxes inside the frame as ``[left, top, w, h, conf]``, clipped to it.
    classes : (K,) ndarray of int
    kept : (K,) ndarray of int
        Row of `dets` each kept box comes from (boxes wholly outside the frame, and boxes
        without area, are dropped).
    clipped : bool
        Whether any box reached outside the frame.
    flat : int
        Boxes without area (``x2 == x1`` or ``y2 == y1``: a detector's box trimmed to nothing
        at the frame's edge) dropped, however many there are.
    inverted : int
        Boxes with ``x2 < x1`` or ``y2 < y1`` (inverted) dropped: a detector's stray box.
    extent : int
        Boxes that are not without area (inverted ones too): with `inverted`, what to add to
        `seen` for the next frame.

    Raises
    ------
    TypeError
        Not real numbers (text, booleans, complex numbers).
    ValueError
        Rows of different lengths, wrong shape, NaN or inf, a class id that is not an integer
        in ``[-2**31, 2**31 - 1]``, or a layout mistake: inverted boxes in this frame, and,
        with those of `seen`, at least two and more than half of the boxes with an extent (the
        message says when the rows look like ``x, y, w, h``). One stray box never trips it,
        nor do boxes without area, which are no evidence of a layout.
    """
    # ragged rows named as such (was NumPy's "inhomogeneous shape", naming no argument)
    d = real_array(dets, name, booleans=False)
    if d.shape == (0,) or (d.ndim == 2 and d.shape[0] == 0 and d.shape[1] in (4, 5, 6)):
        return CheckedBoxes(np.zeros((0, 5)), np.zeros(0, np.int64), np.zeros(0, np.int64),
                            False, 0, 0, 0)  # fmt: skip
    if d.ndim != 2 or d.shape[1] not in (4, 5, 6):
        raise ValueError(
            f"{name} must have shape (N, 4), (N, 5) or (N, 6) [x1, y1, x2, y2(, conf(, cls))], "
            f"got {d.shape}"
        )
    if not np.isfinite(d).all():
        k = int(np.flatnonzero(~np.isfinite(d).all(axis=1))[0])
        raise ValueError(f"{name} row {k} contains NaN or inf: {d[k].tolist()}")
    if d.shape[1] == 6:
        c = d[:, 5]
        j = first_bad_class(c)
        if j is not None:
            raise ValueError(
                f"{name} row {j} has class id {c[j]:.17g}, expected an integer in "
                f"[{-MAX_CLASS - 1}, {MAX_CLASS}] (column 6: x1, y1, x2, y2, conf, cls)"
            )
    rows, cols = shape
    limit = np.array([cols, rows, cols, rows], np.float64)
    corners = d[:, :4]
    size = corners[:, 2:] - corners[:, :2]  # > 0 exactly where x2 > x1 (finite floats)
    if (size > 0).all() and corners.min() >= 0.0 and (corners <= limit).all():
        # the usual frame: every box has an extent and lies in the frame, nothing to clip
        # or drop: the arrays of the general path below in a third of its NumPy calls
        n = len(d)
        xywh = np.empty((n, 5))
        xywh[:, 0:2] = corners[:, :2] + 0.0  # -0.0 as +0.0, as np.clip makes it below
        xywh[:, 2:4] = size
        xywh[:, 4] = d[:, 4] if d.shape[1] >= 5 else 1.0
        cls = d[:, 5].astype(np.int64) if d.shape[1] == 6 else np.zeros(n, np.int64)
        return CheckedBoxes(xywh, cls, np.arange(n, dtype=np.int64), False, 0, 0, n)
    inverted = (d[:, 2] < d[:, 0]) | (d[:, 3] < d[:, 1])
    flat = ~inverted & ((d[:, 2] == d[:, 0]) | (d[:, 3] == d[:, 1]))
    n_inverted, n_flat = int(inverted.sum()), int(flat.sum())
    # inverted boxes, at least two and most of the run's boxes with an extent: the layout is
    # wrong (a stray one among good ones is dropped; boxes without area are no evidence)
    bad, extent = seen[0] + n_inverted, seen[1] + len(d) - n_flat
    if n_inverted and bad >= 2 and bad > extent / 2:
        k = int(np.flatnonzero(inverted)[0])
        which = (
            f"{name} row {k} {d[k, :4].tolist()} has x2 < x1 or y2 < y1, as have {bad} of "
            f"the {extent} boxes given{' so far' if seen[1] else ''}"
        )
        if xywh_hint and np.all(d[inverted, 2:4] > 0):  # positive as widths and heights
            raise ValueError(
                f"{which}: the boxes look like x, y, w, h; give x1, y1, x2, y2 "
                "(x2 = x + w, y2 = y + h)"
            )
        raise ValueError(f"{which} (x1, y1, x2, y2 expected)")
    box = np.clip(corners, 0.0, limit)
    clipped = bool((box != d[:, :4]).any())
    inside = (box[:, 2] > box[:, 0]) & (box[:, 3] > box[:, 1]) & ~inverted & ~flat
    kept = inside.nonzero()[0].astype(np.int64)
    box = box[kept]
    conf = d[kept, 4] if d.shape[1] >= 5 else np.ones(len(kept))
    cls = d[kept, 5].astype(np.int64) if d.shape[1] == 6 else np.zeros(len(kept), np.int64)
    xywh = np.empty((len(box), 5))
    xywh[:, 0:2] = box[:, :2]
    xywh[:, 2:4] = box[:, 2:] - box[:, :2]
    xywh[:, 4] = conf
    return CheckedBoxes(xywh, cls, kept, clipped, n_flat, n_inverted, len(d) - n_flat)


def _outside_the_frame(
    dets: ArrayLike, shape: tuple[int, int], seen: tuple[int, float, float]
) -> tuple[int, float, float]:
    """`seen` plus `dets`'s boxes wholly past the frame's right or bottom edge; furthest x2, y2.

    `dets`: boxes :func:`check_boxes_xyxy` took (x1, y1, x2, y2 first); only those with an
    extent count, as in its `extent`. The evidence of boxes in a larger frame's pixels over a
    run (:meth:`Tracker.update`; :func:`_refuse_larger_frame`).
    """
    d = np.asarray(dets, dtype=np.float64)[:, :4]  # checked: (N, 4), (N, 5) or (N, 6)
    d = d[(d[:, 2] > d[:, 0]) & (d[:, 3] > d[:, 1])]
    if len(d) == 0:
        return seen
    rows, cols = shape
    past = int(((d[:, 0] >= cols) | (d[:, 1] >= rows)).sum())
    return seen[0] + past, max(seen[1], float(d[:, 2].max())), max(seen[2], float(d[:, 3].max()))


#: Boxes a run or file needs before their extent says anything about their pixels.
SMALL_LAYOUT_BOXES = 20
#: Share of the boxes wholly outside the frame that says they are a larger frame's pixels.
OUTSIDE_SHARE = 0.1
#: Round ratios of image sizes a hint names in place of an estimate just above them (the
#: boxes seldom reach the image's last pixel: PETS09's reach 767 of 768, 0.626 for 0.625).
ROUND_RATIOS = (0.5, 0.25, 0.625, 0.75, 0.8, 1 / 3, 2 / 3)


def _refuse_larger_frame(
    outside: tuple[int, float, float], extent: int, shape: tuple[int, int], name: str
) -> None:
    """Refuse a run's boxes in a larger frame's pixels: ValueError naming the scale.

    `outside`: :func:`_outside_the_frame`'s count and reach over the run's boxes so far,
    `extent` of them with an extent. The rule of ``pftrack track`` and :func:`track_frames`
    (``_check_layout``), decided on the boxes given so far: at least ``SMALL_LAYOUT_BOXES``
    (20), more than ``OUTSIDE_SHARE`` (10 %) of them wholly outside the frame. None of the
    five det.txt files here at their scale (PETS09's times 0.625, TUD-Campus, ADL-Rundle-6,
    ETH-Sunnyday, KITTI-17), nor their gt.txt files, has a box wholly outside at any point of
    the run; PETS09's det.txt unscaled on its 480x360 video has 65 % of its first boxes so and
    is refused at frame 7 (its 21st box). Was: a warning that boxes were clipped (wrong
    coordinate scale?), and tracks of the clipped boxes. The scale is not named as the
    command names it (``_scale_hint``, from the whole file's reach): the first frames' boxes
    seldom reach the far edges (PETS09's first 7 frames reach 694x328 of 768x576, 0.692 where
    the scale is 0.625), so their reach gives an upper bound, said as one, and the round
    ratios below it with the sizes they mean.
    """
    n_out, right, bottom = outside
    if extent < SMALL_LAYOUT_BOXES or n_out <= OUTSIDE_SHARE * extent:
        return
    rows, cols = shape
    bound = min(cols / right, rows / bottom)  # < 1: a box starts past an edge
    ratios = sorted((k for k in ROUND_RATIOS if k <= bound), reverse=True)[:3]
    sizes = ", ".join(f"{k:.3g} for {cols / k:.0f}x{rows / k:.0f}" for k in ratios)
    raise ValueError(
        f"{name}: {n_out} of the {extent} boxes given so far lie wholly outside the "
        f"{cols}x{rows} frame (they reach {right:.0f}x{bottom:.0f}): are they in a larger "
        "frame's pixels? Multiply x1, y1, x2, y2 by the frame's size over theirs: at most "
        f"{bound:.3g} by their reach so far{f' (e.g. {sizes} pixels)' if sizes else ''}"
    )


def _moves(moves: object) -> tuple[float, float, float, float]:
    """``Tracker``'s `moves`: 4 real numbers (birth, death, update, swap) the chain can use.

    TypeError for what is not a sequence of 4 real numbers, ValueError (the command's check
    and message, :func:`pftrack._limits.moves_error`) for probabilities it cannot use.
    """
    items: list[object] | None = None
    if not isinstance(moves, (str, bytes)):
        try:
            items = list(moves)  # type: ignore[call-overload]  # any iterable, checked here
        except TypeError:
            pass
    if items is None:
        raise TypeError(
            f"moves must be 4 numbers (birth, death, update, swap probabilities), got "
            f"{brief(moves)}"
        )
    values = [real(v, "moves", finite=False) for v in items]
    bad = moves_error(values, "moves")
    if bad:
        raise ValueError(bad)
    return values[0], values[1], values[2], values[3]


class _NotGiven:
    """The default of an argument that may come under another name.

    :meth:`Tracker.update`'s `frame`, BoxMOT's `img`: tells "not given" from a None given.
    """

    def __repr__(self) -> str:
        return "<not given>"


_NOT_GIVEN: Any = _NotGiven()


def _the_frame(frame: object, img: object) -> tuple[Any, str]:
    """:meth:`Tracker.update`'s frame and the name it came under (what its refusals name).

    Given once: as `frame` or as `img` (BoxMOT's name).

    Raises
    ------
    TypeError
        Neither given, or both.
    """
    if img is _NOT_GIVEN:
        if frame is _NOT_GIVEN:
            raise TypeError(
                "Tracker.update: no frame given: update(dets, frame), or img=frame as BoxMOT "
                "names it"
            )
        return frame, "frame"
    if frame is not _NOT_GIVEN:
        raise TypeError(
            "Tracker.update: the frame is given twice, as frame and as img (BoxMOT's name for "
            "it): give one"
        )
    return img, "img"


def _check_embs(embs: object, dets: object) -> None:
    """Refuse :meth:`Tracker.update`'s `embs` (not None) that BoxMOT's ReID trackers would.

    Not used, but checked as they are taken: a NumPy array with one row per row of `dets`
    (BoxMOT's ``(N, D)``; `dets` of no clear row count, None included, are not compared).
    Was: any object, of any row count, taken without a word.

    Raises
    ------
    TypeError
        `embs` is not a NumPy array (a list, a tensor).
    ValueError
        `embs` has no rows (0-d), or another row count than `dets`.
    """
    if not isinstance(embs, np.ndarray):
        raise TypeError(
            f"Tracker.update: embs is {type(embs).__name__}, expected a NumPy array with one "
            "row per row of dets (BoxMOT's (N, D) appearance embeddings) or None"
        )
    if isinstance(dets, np.ndarray):
        rows = len(dets) if dets.ndim == 2 else None
    else:
        rows = len(dets) if isinstance(dets, (list, tuple)) else None
    if embs.ndim == 0 or (rows is not None and len(embs) != rows):
        want = "(N, D)" if rows is None else f"{rows} rows, one per row of dets"
        raise ValueError(f"Tracker.update: embs has shape {embs.shape}, expected {want}")


class _Alone:
    """``with``: take `lock` without waiting (RuntimeError naming ``Tracker.method`` if held).

    A class, not ``contextlib.contextmanager``: 0.4 us a call instead of 2.8 on ``update``.
    """

    __slots__ = ("lock", "method")

    def __init__(self, lock: threading.Lock, method: str) -> None:
        self.lock, self.method = lock, method

    def __enter__(self) -> None:
        if not self.lock.acquire(blocking=False):
            raise RuntimeError(
                f"Tracker.{self.method}: this Tracker is in use by another thread (use one "
                "Tracker per thread, or a lock around it)"
            )

    def __exit__(self, *exc: object) -> None:
        self.lock.release()


class Tracker:
    """pftrack as a drop-in multi-object tracker: one ``update`` per frame, then ``finalize``.

    Parameters
    ----------
    frame_rate : float
        Frames per second of the input: turns the time constants given below (`max_coast`,
        `prime`) into frames. The defaults are the command's frame counts at any rate. Any
        real number: a :class:`~fractions.Fraction` too (PyAV's ``stream.average_rate``).
    seed : int or None
        Seed: the same seed, frames and detections give the same tracks (None: fresh entropy).
    detector : {"paper", "mog2", "knn"}, PaperConfig, Mog2Config or KnnConfig
        Built-in detector, used when ``update`` gets ``dets=None`` (and, with detections, for
        the foreground that shrinks their boxes): by name, with its defaults, or as its
        settings, every one of them (``detector=PaperConfig(alpha_fg=0.01, hold_frames=1000)``;
        :attr:`TrackerConfig.detector`, whose checks it passes, its `hsv` left at the default).
    sampler : {"sis", "mh", "rjmcmc"}
        Particle filter per object (sis, the paper's; mh) or one joint RJ-MCMC chain.
    particles : int or None
        Particles per object. None: 200 for tracks born from given detections, 100 for the
        built-in detector's (``TrackerConfig.given_particles``). At most 1000000
        (:data:`pftrack._limits.MAX_PARTICLES`). With ``sampler="rjmcmc"``, the joint chain's
        kept samples N, at most 10000 (:data:`pftrack._limits.MAX_JOINT_SAMPLES`): its cost
        per frame grows as N² (about 8 ms at 2000 and 0.15 s at 10000 with 5 objects).
        ``pftrack track --particles`` takes the same limits, checked by the same code.
    dynamics : {"ar2", "ar2-mean"}
        AR(2) model per particle, or from the particle-set means.
    mh_iter : int
        With ``sampler="mh"``: Metropolis-Hastings iterations per particle and frame, in
        [1, 1000] (``TrackerConfig.mh_iter``; the likelihood is evaluated ``particles *
        (mh_iter + 1)`` times per object and frame). ``--mh-iter`` of ``pftrack track``.
    mh_proposal : {"dynamics", "random_walk"}
        With ``sampler="mh"``: the chain's proposal, a fresh draw of the AR(2) dynamics (the
        default, the paper's) or a Gaussian random walk from the chain's state
        (``TrackerConfig.mh_proposal``). ``--mh-proposal``.
    mh_rw_sigma : sequence of 3 float
        With ``mh_proposal="random_walk"``: standard deviations of its step (cx, cy in pixels,
        scaled with the frame's size as the filter's noise is; scale), each in
        [0, 10000], default ``(2.0, 2.0, 0.01)`` (``TrackerConfig.mh_rw_sigma``).
        ``--mh-rw-sigma``.
    burn_in : int
        With ``sampler="rjmcmc"``: burn-in iterations of the joint chain per frame, in
        [0, 100000] (``RJMCMCConfig.burn_in``; a frame costs O((burn_in + particles)
        particles)). ``--burn-in``.
    moves : sequence of 4 float
        With ``sampler="rjmcmc"``: probabilities of the joint chain's birth, death, update and
        swap moves (``RJMCMCConfig``'s ``p_birth``, ``p_death``, ``p_update``, ``p_swap``;
        normalised by the chain): finite and >= 0, not all 0, birth and death both > 0 or
        both 0. ``--moves``.
    max_coast : float or None
        Seconds a track survives on its particle filter alone. None (default): the command's
        10 frames at any frame rate (0.4 s at 25/s, 1.4 s at 7/s; see the module's notes).
    min_conf : float
        Detections with a lower confidence are ignored.
    birth_score : float
        Cap of the confidence a detection needs to start a track, in [0, 1].
    birth_quantile : float or None
        The birth threshold is ``min(birth_score, quantile)`` of the confidences seen in the
        50 frames from the first with detections (a scene empty at first learns from its first
        people), so a detector whose scores are all low still starts tracks (None: always
        `birth_score`); each class (the `dets`' column 6) with 20 confidences there has its own;
        beside another class, a class with fewer (or first seen later) learns its own once it
        has 20, whenever that is, and takes the pooled one until then. `min_conf` stays one
        for every class. See
        :class:`~pftrack.tracking.LifecycleConfig`.
    camera_motion : {"auto", "on", "off"}
        Camera-motion compensation (:attr:`TrackerConfig.camera_motion`).
    refine : bool
        Shrink given detection boxes to the foreground of a background model (the default;
        :class:`~pftrack.tracking.RefineConfig`). False takes the boxes as given and runs no
        background model: for a detector with tight boxes, and about 0.5 ms less a frame.
        Refinement (like the built-in detector) assumes upright people: use False for
        sideways or overhead-rotated footage (docs/detection.md, "Known limit: upright
        people").
    fill : {"linear", "pf"}
        Boxes of a gap the particle filter bridged, before smoothing.
    smooth, link : bool
        The offline pass of :meth:`finalize`: smooth each track's boxes, join fragments of one
        object across gaps of up to 30 frames (at any `frame_rate`: the module's notes).
    crossings : bool
        With `smooth`, :meth:`finalize` also gives back the tails of two tracks the tracker
        swapped where they crossed (:class:`~pftrack.tracking.CrossingConfig`, motion and
        size only).
    colour : {"swap", "link", "both"} or None
        The offline pass's colour: the tracker keeps the histogram it holds for each row (the
        matched detection's, or its filter's reference) and :meth:`finalize` hands them to
        the fill's swap rule (``"swap"``: a hole whose two sides each look more like another
        object, an id handed to a neighbour, is left unfilled), the linker's colour term
        (``"link"``) or both; None (default) keeps none. Kept, 880 bytes a row more with the
        default 110 bins and 0.9 % more instructions an ``update`` (docs/recovery.md, "The
        tracker's own colour in the offline pass").
    prime : float or None
        Seconds of frames :meth:`prime` reads (what ``pftrack track`` reads ahead). None
        (default): the command's 30 frames.
    max_side : int or None
        Working resolution (:attr:`TrackerConfig.max_side`): larger frames are scaled down to
        this longer side for detection and tracking; boxes in and out stay in the frame's
        pixels, in [64, 100000]. None or 0 (as ``--max-side 0``): the frame's own size.
    record : bool
        Keep every online row for :meth:`finalize`'s offline pass (the default). False: a
        purely online tracker for an unbounded stream, whose memory stays flat: ``update``
        returns the same tracks, nothing is kept, and :meth:`finalize` and
        :meth:`settled_rows` raise RuntimeError.

    Raises
    ------
    TypeError
        A flag (`refine`, `smooth`, `link`, `crossings`, `record`) that is not ``True`` or ``False``
        (``refine="no"`` would turn refinement on), a `frame_rate`, `max_coast`, `prime`,
        `min_conf` or `birth_score` that is not a number, a `seed`, `particles`, `mh_iter` or
        `burn_in` that is not an int, `moves` or `mh_rw_sigma` not numbers, `mh_proposal` not
        text.
    ValueError
        A value out of its range, ``crossings=True`` with ``smooth=False`` (the repair is
        part of the smoothing pass), or `max_coast`, `birth_score` or `birth_quantile` other
        than its default with ``sampler="rjmcmc"`` (the joint chain keeps and starts tracks by
        its own existence probabilities: they would do nothing); `mh_iter`, `mh_proposal` or
        `mh_rw_sigma` other than its default without ``sampler="mh"``, `burn_in` or `moves`
        without ``sampler="rjmcmc"`` (only that sampler reads them), `mh_rw_sigma` without
        ``mh_proposal="random_walk"``.

    Notes
    -----
    One tracker is one run: use one per video and per thread. A second thread calling a
    method while another is inside one raises RuntimeError (as does the C++ background model
    under any other path). ``copy.deepcopy(tracker)`` or a pickle of it (at any protocol, 0
    to 5) is a checkpoint at any point of a run with the built-in ``"paper"`` detector (or
    given detections) and any sampler: the copy goes on exactly as the original. OpenCV's
    MOG2/KNN cannot be copied once they have seen a frame (TypeError naming the option); a
    checkpoint taken while another thread is inside a method raises RuntimeError,
    and ``copy.copy`` (which would share the run's state) raises TypeError. To keep a
    checkpoint in a file, ``pickle.dumps`` it first and write the bytes atomically (a refused
    pickle then leaves the last file whole; docs/api.md).

    Memory grows with the run: every online row is kept until :meth:`finalize` (its offline
    pass needs the whole run), about 0.2 KB a row (measured with ``tracemalloc`` on a
    synthetic scene: some 19 MB per person tracked for an hour at 25 frames/s), and with
    `colour` its histogram, 0.88 KB more (110 float64; some 80 MB more per person-hour). For an
    unbounded stream, either track online only (``record=False``: nothing is kept, no
    offline pass), or read :meth:`settled_rows` from the last :attr:`n_settled` as you go and
    end a segment now and then with :meth:`finalize` and :meth:`reset`, which frees the rows
    (ids and frame numbers start again; tracks are not linked across segments):
    docs/robustness.md, "Memory of a long Tracker run".

    Examples
    --------
    >>> tracker = pftrack.Tracker(frame_rate=25.0)         # doctest: +SKIP
    >>> for frame in frames:                                # doctest: +SKIP
    ...     dets = my_detector(frame)                       # (N, 6) x1, y1, x2, y2, conf, cls
    ...     tracks = tracker.update(dets, frame)            # (M, 8) x1..y2, id, conf, cls, det_ind
    >>> rows = tracker.finalize()                           # doctest: +SKIP
    """

    #: Calls between the user's code and ``update`` or ``finalize``: an adapter that calls
    #: them sets 1 (:class:`~pftrack.integrations.supervision.SupervisionTracker`), so that
    #: warnings name the user's line, not the adapter's.
    _caller_depth = 0

    #: What messages about the boxes given to :meth:`update` call them; an adapter whose boxes
    #: are always ``x1, y1, x2, y2`` names its own (and gets no ``x, y, w, h`` hint).
    _box_source = "dets"
    #: Inverted boxes (``x2 < x1`` or ``y2 < y1``) and boxes with an extent the run was given:
    #: the evidence of x, y, w, h rows (:func:`check_boxes_xyxy`). A class default for a
    #: checkpoint pickled before it was kept.
    _layout: tuple[int, int] = (0, 0)
    #: Boxes wholly past the frame's right or bottom edge and the furthest x2, y2 the run was
    #: given: the evidence of a larger frame's pixels (:func:`_outside_the_frame`). A class
    #: default for a checkpoint pickled before it was kept.
    _outside: tuple[int, float, float] = (0, 0.0, 0.0)
    #: Stand-ins among the run's frames taken (:mod:`pftrack._stand_in`; a class default for
    #: a checkpoint pickled before they were counted).
    _stood = 0
    #: Whether the run keeps its rows for :meth:`finalize` (the constructor's `record`; a class
    #: default for a checkpoint pickled before it was an option).
    record: bool = True
    #: The shape of the frames given to :meth:`prime` (None: not primed). A class default for
    #: a checkpoint pickled before it was kept.
    _primed: tuple[int, ...] | None = None

    def __init__(
        self,
        frame_rate: RealLike = REFERENCE_RATE,
        *,
        seed: int | None = 0,
        detector: DetectorName | PaperConfig | Mog2Config | KnnConfig = "paper",
        sampler: SamplerName = "sis",
        particles: int | None = None,
        dynamics: DynamicsName = "ar2",
        mh_iter: int = DEFAULT_MH_ITER,
        mh_proposal: str = DEFAULT_MH_PROPOSAL,
        mh_rw_sigma: Sequence[float] = DEFAULT_MH_RW_SIGMA,
        burn_in: int = DEFAULT_BURN_IN,
        moves: Sequence[float] = DEFAULT_MOVES,
        max_coast: RealLike | None = None,
        min_conf: float = 0.0,
        birth_score: float = 0.9,
        birth_quantile: float | None = 0.25,
        camera_motion: CameraMotion = "auto",
        refine: bool = True,
        fill: FillMode = "linear",
        smooth: bool = True,
        link: bool = True,
        crossings: bool = CrossingConfig.enabled,
        colour: str | None = None,
        prime: RealLike | None = None,
        max_side: int | None = TrackerConfig.max_side,
        record: bool = True,
    ) -> None:
        if seed is not None:
            seed = check_seed(seed, "seed")
        frame_rate = _check_rate(frame_rate)
        # any real number as its float (a Fraction: PyAV's rates; the messages format floats)
        min_conf, birth_score = real(min_conf, "min_conf"), real(birth_score, "birth_score")
        if birth_quantile is not None:
            birth_quantile = real(birth_quantile, "birth_quantile")
        for name, value in (("birth_score", birth_score), ("birth_quantile", birth_quantile)):
            if value is not None and not 0 <= value <= 1:  # named as the argument (was:
                # "LifecycleConfig: birth_score is 2.0", a class the caller never touched)
                raise ValueError(f"{name} is {value}, expected a value in [0, 1]")
        if max_coast is not None:
            max_coast = real(max_coast, "max_coast", finite=False)  # _frames says which
        if prime is not None:
            prime = real(prime, "prime", finite=False)
        refine, smooth, link, crossings, record = (
            flag(refine, "refine"), flag(smooth, "smooth"), flag(link, "link"),
            flag(crossings, "crossings"), flag(record, "record"),
        )  # fmt: skip
        if crossings and not smooth:  # as the CLI refuses --crossings on --no-smooth
            raise ValueError(
                "crossings=True needs the smoother, which smooth=False turns off; drop one"
            )
        option(dynamics, "dynamics", ("ar2", "ar2-mean"))
        if dynamics not in ("ar2", "ar2-mean"):
            raise ValueError(f"dynamics is {dynamics!r}, expected 'ar2' or 'ar2-mean'")
        if particles is not None:  # named as the option (was FilterConfig's n_particles)
            particles = integer(particles, "particles", 1, MAX_PARTICLES)
            if sampler == "rjmcmc":  # the command's check and message (pftrack._limits)
                too_many = joint_samples_error(particles, "particles", "sampler 'rjmcmc'")
                if too_many:
                    raise ValueError(too_many)
        mh_iter = integer(mh_iter, "mh_iter", 1, MAX_MH_ITER)
        option(mh_proposal, "mh_proposal", MH_PROPOSALS)
        rw_sigma = real_array(mh_rw_sigma, "mh_rw_sigma", booleans=False)
        if rw_sigma.ndim != 1:
            raise ValueError(f"mh_rw_sigma has shape {rw_sigma.shape}, expected (3,)")
        tau = tuple(float(v) for v in rw_sigma)  # 3: checked below, the config's type
        refused = proposal_error(mh_proposal, tau, ("mh_proposal", "mh_rw_sigma"), cli=False)
        if refused:
            raise ValueError(refused)
        burn_in = integer(burn_in, "burn_in", 0, MAX_BURN_IN)
        moves = _moves(moves)
        base = TrackerConfig()
        if isinstance(detector, (PaperConfig, Mog2Config, KnnConfig)) and hsv_disagrees(
            detector, base.binning
        ):  # TrackerConfig's message says to set binning, which this class does not take
            raise ValueError(
                f"detector's hsv is {detector.hsv}, but the detector bins colour as the tracker "
                f"does ({base.binning}): leave the {type(detector).__name__}'s hsv at its default, "
                "or give TrackerConfig(binning=..., detector=...) to Tracker.from_config"
            )
        model = replace(base.filter.model, use_means=dynamics == "ar2-mean")
        try:  # the arguments share the settings' names: not the class the caller never built
            config = replace(
                base,
                filter=replace(
                    base.filter, n_particles=int(particles or base.filter.n_particles), model=model
                ),
                given_particles=base.given_particles if particles is None else None,
                detector=detector,
                sampler=sampler,
                mh_iter=mh_iter,
                mh_proposal=mh_proposal,
                mh_rw_sigma=tau,  # type: ignore[arg-type]
                rjmcmc=replace(
                    base.rjmcmc,
                    burn_in=burn_in,
                    p_birth=moves[0],
                    p_death=moves[1],
                    p_update=moves[2],
                    p_swap=moves[3],
                ),  # fmt: skip
                camera_motion=camera_motion,
                max_side=max_side,
                refine=replace(base.refine, enabled=refine),
                crossings=replace(base.crossings, enabled=crossings),
                lifecycle=replace(
                    base.lifecycle,
                    max_coast=(
                        base.lifecycle.max_coast
                        if max_coast is None
                        else _frames(max_coast, frame_rate, "max_coast")
                    ),
                    min_score=min_conf,
                    birth_score=birth_score,
                    birth_quantile=birth_quantile,
                ),
            )
        except (TypeError, ValueError) as e:
            raise type(e)(str(e).removeprefix("TrackerConfig: ")) from None
        unread = unread_error(
            sampler,
            {"mh_iter": mh_iter, "mh_proposal": mh_proposal, "mh_rw_sigma": tau,
             "burn_in": burn_in, "moves": moves},
            cli=False,
        )  # fmt: skip
        if unread:  # the command refuses them likewise (pftrack._limits)
            raise ValueError(unread)
        if sampler == "rjmcmc":  # its chain ignores them (the CLI refuses them likewise)
            unused = [
                f"{name} {'None' if value is None else format(value, 'g')}"
                for name, value, default in (
                    ("max_coast", max_coast, None),  # None: the command's frame count
                    ("birth_score", birth_score, LifecycleConfig.birth_score),
                    ("birth_quantile", birth_quantile, LifecycleConfig.birth_quantile),
                )
                if value != default
            ]
            if unused:
                one = len(unused) == 1
                raise ValueError(
                    f"{', '.join(unused)}: the joint sampler (rjmcmc) keeps and starts tracks by "
                    f"its own existence probabilities, so {'it does' if one else 'they do'} "
                    f"nothing: drop {'it' if one else 'them'}, or use sampler 'sis' or 'mh'"
                )
        link_config = LinkConfig()
        self._setup(
            config,
            seed,
            frame_rate=float(frame_rate),
            fill=fill,
            smoother=BoxSmoother() if smooth else None,
            link=link_config if link else None,
            prime_frames=PRIME_FRAMES if prime is None else _frames(prime, frame_rate, "prime"),
            record=record,
            colour=colour,
        )

    @classmethod
    def from_config(
        cls,
        config: TrackerConfig | None = None,
        seed: RngLike = 0,
        *,
        frame_rate: RealLike = REFERENCE_RATE,
        coasting: str = "confirmed",
        fill: str = "linear",
        smoother: BoxSmoother | None = BoxSmoother(),  # noqa: B008 - frozen, shared safely
        link: LinkConfig | None = LinkConfig(),  # noqa: B008 - frozen, shared safely
        prime_frames: IntLike = PRIME_FRAMES,
        colour: str | None = None,
    ) -> Tracker:
        """A tracker from a full :class:`TrackerConfig` (frame-based), as ``pftrack track`` makes.

        Parameters
        ----------
        config : TrackerConfig, optional
            All tracker settings (default ``TrackerConfig()``).
        seed : int, numpy.random.Generator or None
            Seed (with a Generator, :meth:`reset` goes on drawing from it rather than
            starting over).
        frame_rate : float
            Recorded only: `config` is already in frames.
        coasting, fill : str
            What coasting becomes in :meth:`finalize` (:class:`TrackWriter`).
        smoother, link : optional
            The offline pass (None: off).
        prime_frames : int
            Frames :meth:`prime` reads.
        colour : {"swap", "link", "both"} or None
            The tracker's own histograms of its rows kept and handed to the offline pass
            (:class:`TrackWriter`'s ``colour``): ``"swap"`` to the fill's swap rule (a hole
            whose sides each look more like another object is left), ``"link"`` to the
            linker's colour term, ``"both"``; None (default): no colour kept (docs/recovery.md,
            "The tracker's own colour in the offline pass").
        """
        self = cls.__new__(cls)
        self._setup(
            config if config is not None else TrackerConfig(),
            seed,
            frame_rate=frame_rate,
            fill=fill,
            smoother=smoother,
            link=link,
            prime_frames=prime_frames,
            coasting=coasting,
            colour=colour,
        )
        return self

    def _setup(self, config: TrackerConfig, seed: RngLike, *, frame_rate: RealLike, fill: str,
               smoother: BoxSmoother | None, link: LinkConfig | None, prime_frames: IntLike,
               coasting: str = "confirmed", record: bool = True,
               colour: str | None = None) -> None:  # fmt: skip
        if seed is not None and not isinstance(seed, (int, np.integer, np.random.Generator)):
            raise TypeError(f"seed must be an int, a Generator or None, got {type(seed).__name__}")
        if not isinstance(config, TrackerConfig):
            raise TypeError(f"config must be a TrackerConfig, got {type(config).__name__}")
        if (
            isinstance(prime_frames, (bool, np.bool_))
            or not isinstance(prime_frames, (int, np.integer))
            or prime_frames < 0
        ):
            raise ValueError(f"prime_frames is {brief(prime_frames)}, expected an integer >= 0")
        rate = _check_rate(frame_rate)
        self.config = config
        self.frame_rate = rate
        self.seed = seed
        self.prime_frames = int(prime_frames)
        self.record = record
        self._writer_args = (coasting, fill, smoother, link, colour)  # colour: stop 74
        TrackWriter(*self._writer_args)  # check the writer's options now
        self._busy = threading.Lock()
        self.reset()

    def _alone(self, method: str) -> _Alone:
        """Hold the tracker for one call: a second thread raises instead of mixing two runs.

        A tracker is one run's state; two threads calling ``update`` on it at once would
        interleave their frames (and share the C++ background model, which refuses a second
        thread too). Not blocking: waiting would hide the mistake, not make the rows right.
        """
        return _Alone(self._busy, method)

    def _refuse_copy(self) -> None:
        """TypeError naming the option when the run holds state that cannot be copied.

        OpenCV's background subtractors (from :meth:`prime` or the first frame that uses
        them) live outside Python: pickle would otherwise say only ``cannot pickle
        'cv2.BackgroundSubtractorMOG2' object``. The RJ-MCMC chain is copied through
        :class:`~pftrack.particle_filter.RJMCMCFilter`'s own state (since 5 December 2026;
        it was refused).
        """
        detector = getattr(self._tracker, "_detector", None)
        if isinstance(getattr(detector, "_sub", None), cv2.BackgroundSubtractor):
            raise TypeError(
                f"detector={self.config.detector_name!r} cannot be checkpointed (pickle/deepcopy) "
                "once primed or given a frame: OpenCV's background subtractors cannot be "
                "pickled; use detector='paper'"
            )

    def _state(self) -> dict[str, Any]:
        """The run's state to copy (call holding the tracker: :meth:`_alone`)."""
        self._refuse_copy()
        state = self.__dict__.copy()
        del state["_busy"]  # a lock is not copied or pickled: a copy is free
        return state

    def __getstate__(self) -> dict[str, Any]:
        # the state is the live objects: pickle and deepcopy go through __reduce_ex__ and
        # __deepcopy__, which copy them while still holding the tracker
        with self._alone("__getstate__"):
            return self._state()

    def __reduce_ex__(self, protocol: SupportsIndex) -> tuple[Any, ...]:
        """Pickle the run whole while holding the tracker (RuntimeError when in use).

        Pickle walks the state after ``__reduce_ex__`` returns, so the state is pickled here,
        inside the guard: an ``update`` on another thread can neither mix into the
        checkpoint nor start while it is taken.
        """
        with self._alone("__reduce_ex__ (pickle)"):
            data = pickle.dumps(self._state(), protocol=operator.index(protocol))
        return (_unpickle_tracker, (type(self), data))

    def __deepcopy__(self, memo: dict[int, Any]) -> Tracker:
        """An independent copy of the run (a checkpoint), taken while holding the tracker."""
        with self._alone("__deepcopy__ (copy.deepcopy)"):
            new = type(self).__new__(type(self))
            memo[id(self)] = new
            new.__dict__.update(copy.deepcopy(self._state(), memo))
        new._busy = threading.Lock()
        return new

    def __copy__(self) -> Tracker:
        """Refused: a shallow copy would share the run's state with the original."""
        raise TypeError(
            "copy.copy(Tracker) would share the run's state (tracks, background, rows) with the "
            "original; use copy.deepcopy(tracker) for an independent copy"
        )

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self.__dict__.setdefault("_sizes", [])  # a checkpoint pickled before size_ratio
        self._busy = threading.Lock()

    def reset(self) -> None:
        """Forget every track and frame: the tracker is as new (same settings and seed)."""
        with self._alone("reset"):
            self._tracker = MultiObjectTracker(self.config, rng=self.seed)
            self._writer = TrackWriter(*self._writer_args)
            # the histograms of the rows kept for finalize's offline pass (none kept: none)
            self._tracker.keep_colour = self.record and self._writer.colour is not None
            self.frame_count = 0
            #: The class (``cls`` of the detections; 0 without) of each id :meth:`finalize`
            #: returned.
            self.classes: dict[int, int] = {}
            self._stabiliser = Stabiliser()
            self._reports: list[Track] = []
            self._warned: set[str] = set()  # the run's once-only warnings given so far
            self._blocking: list[float] = []  # blockiness of the run's first BLOCK_FRAMES
            self._stood = 0  # stand-ins among the frames taken (pftrack._stand_in)
            self._max_conf = -np.inf
            self._given = False  # some update() of the run had detections
            # foot row, height, class, frame of the given boxes, working pixels (drop_odd_sizes)
            self._sizes: list[F64] = []
            self._layout = (0, 0)  # inverted boxes, boxes with an extent (check_boxes_xyxy)
            self._outside = (0, 0.0, 0.0)  # boxes wholly outside, reach (_outside_the_frame)
            # working / frame pixels as (x, y, x, y), the factors of a left, top, w, h box; set
            # with the run's first frame (None: tracked at the frame's own size)
            self._scale: F64 | None = None
            self._shape: tuple[int, ...] | None = None  # the run's frame shape
            self._primed = None  # the shape of the frames given to prime()
            self._prepared: tuple[NDArray[np.uint8], NDArray[np.uint8]] | None = None
            # the frame whose update was cut short after it changed the tracker (0: none)
            self._torn = 0

    @property
    def tracker(self) -> MultiObjectTracker:
        """The online tracker inside (its live tracks, detector and foreground mask).

        It works at the working resolution (:attr:`TrackerConfig.max_side`): its boxes are in
        the pixels of :meth:`working_frame`, not of the frames given to :meth:`update`.
        """
        return self._tracker

    def working_frame(self, frame: NDArray[np.uint8]) -> NDArray[np.uint8]:
        """`frame` as the tracker inside sees it: scaled down to ``max_side``, or `frame` itself.

        OpenCV's ``INTER_AREA`` (the mean of the pixels each output pixel covers), to the size
        :func:`working_size` gives.

        Raises
        ------
        TypeError, ValueError
            Not a (H, W, 3) uint8 array with pixels (:func:`pftrack._check.bgr_frame`'s
            words; was an AttributeError for a list).
        """
        if not (isinstance(frame, np.ndarray) and frame.dtype == np.uint8 and frame.ndim == 3
                and frame.shape[2] == 3 and frame.size):  # fmt: skip
            frame = bgr_frame(frame, "working_frame: frame")  # raises
        size = working_size(frame.shape, self.config.max_side)
        if size is None:
            return frame
        return np.asarray(cv2.resize(frame, size, interpolation=cv2.INTER_AREA), np.uint8)

    def hand_over(self, frame: NDArray[np.uint8], working: NDArray[np.uint8]) -> None:
        """Give the next :meth:`update` of `frame` its :meth:`working_frame`, made elsewhere.

        :class:`~pftrack.tracking.ahead.DetectAhead` scales each frame on its thread, where
        the detector runs on the scaled frame; ``update`` then takes that very array (the
        detector's result belongs to it) instead of scaling `frame` again.
        """
        self._prepared = (frame, working)

    def _warn_once(self, key: str, message: str | Callable[[], str]) -> None:
        """Warn `message` from ``update``'s caller, the first time `key` comes up in a run.

        `message` may be a function that makes it, called only then (a per-frame caller builds
        no text). Held until ``update`` has taken the frame whole (:class:`pftrack._warn.Held`):
        under ``python -W error`` the error leaves the tracker usable.
        """
        if key not in self._warned:
            self._warned.add(key)
            warn(message if isinstance(message, str) else message())

    def _warn_blocky(self, frame: NDArray[np.uint8]) -> None:
        """Measure one of the run's first frames; say once if they are heavily compressed.

        The median :func:`~pftrack.detection.blocking.blockiness` of the first
        :data:`~pftrack.detection.blocking.BLOCK_FRAMES` frames, at their own size, decides
        (:data:`~pftrack.detection.blocking.BLOCKY`), when the built-in detector ran on them:
        given detections' tracks changed about as much at JPEG quality 40 as at 5.
        """
        self._blocking = [*self._blocking[: self.frame_count - self._stood], blockiness(frame)]
        if len(self._blocking) == BLOCK_FRAMES and is_blocky(self._blocking):
            self._warn_once(
                "blocky",
                f"the frames are heavily compressed: the edges of their 8x8 blocks are "
                f"{np.median(self._blocking):.1f} times as strong as the steps inside them "
                "(1 without blocks; 2 and more at JPEG quality 10 and below): the "
                "built-in detector takes block edges for change and misses people (PETS09 and "
                "TUD-Campus re-saved at JPEG quality 10: MOTA 83 -> 78 and 46 -> 26, 3 seeds); "
                "track a less compressed copy, or give detections of a detector of your own",
            )

    def _warn_moving_camera(self) -> None:
        """Say once a run that the built-in detector runs on a moving camera.

        Background subtraction takes the whole moving scene for foreground: walls and grass
        become tracks (docs/tracking.md, "A moving camera"). The camera is found moving on
        this frame (``camera_motion`` "auto": after ``CameraConfig.on_frames`` moving frames
        in a row, the first of which the message names; "on": on every frame).
        """

        def message() -> str:
            camera = self._tracker.camera
            if camera.mode == "auto":
                first = max(1, self.frame_count + 1 - camera.config.on_frames + 1)
                moves = f"the camera moves (from frame {first})"
            else:
                moves = "the camera counts as moving (camera_motion 'on')"
            return (
                f"{moves}: the built-in background-subtraction detector is unreliable on a "
                "moving camera; give detections (pftrack track --detections, "
                "Tracker.update(dets, frame))"
            )

        self._warn_once("moving camera", message)

    def _working(self, frame: NDArray[np.uint8]) -> NDArray[np.uint8]:
        prepared, self._prepared = self._prepared, None
        if prepared is not None and prepared[0] is frame:
            return prepared[1]
        return self.working_frame(frame)

    def _step(
        self, work: NDArray[np.uint8], xywh: F64 | None, cls: NDArray[np.int64] | None
    ) -> list[Track]:
        """The tracker inside's ``update`` of this frame; the run is torn while it may stop.

        `xywh` (the checked boxes, inside the working frame: not checked again) or None for
        the built-in detector. The tracker inside checks its input before it changes
        anything, and its frame counter moves once the checks are passed: an input it refuses
        leaves the run whole, so the caller may skip the frame and go on (was: every later
        ``update`` said the run was interrupted).
        """
        before = self._tracker.frame_index
        self._tracker.caller_depth = self._caller_depth + 1  # and this method
        self._torn = self.frame_count + 1  # until the frame's bookkeeping is done
        try:
            return self._tracker.update(work, xywh, cls, checked=xywh is not None)
        except BaseException:
            if self._tracker.frame_index == before:  # refused before any change
                self._torn = 0
            raise

    def _restore_rows(self, rows: F64) -> F64:
        """MOTChallenge rows from working pixels to the frame's."""
        if self._scale is None or len(rows) == 0:
            return rows
        out: F64 = rows.copy()
        out[:, 2:6] /= self._scale
        return out

    def _restore_track(self, t: Track) -> Track:
        """A reported track with its boxes in the frame's pixels."""
        k = self._scale
        assert k is not None
        return replace(
            t,
            box_xywh=np.asarray(t.box_xywh, np.float64) / k,
            detection_box=None if t.detection_box is None else t.detection_box / k,
            history=tuple((n, np.asarray(b, np.float64) / k, c) for n, b, c in t.history),
        )

    def prime(
        self, frames: Iterable[NDArray[np.uint8]], *, shape: tuple[int, ...] | None = None
    ) -> None:
        """Start the background model from the median of `frames` (before the first update).

        Reads at most :attr:`prime_frames` of `frames` (the first ones; a longer iterable is
        not read on). ``pftrack track`` primes this way with the built-in detector, or with
        detections when box refinement is on (the default): with detections, its first
        ``prime_frames`` frames; with the built-in detector, ``prime_frames`` frames spread
        over the file (``pftrack.detection.bootstrap.bootstrap_frames(source,
        tracker.prime_frames)``). A loop that primes with the same frames gets the command's
        rows. Detectors without a background ignore it. Optional: unprimed, the model learns
        the run's first frames as their running mean, people walking through them included,
        and refines the boxes after against their ghosts (TUD-Campus with public detections:
        76.9 / 77.7 MOTA / IDF1 against the command's 79.4 / 85.4; docs/tracking.md, "A loop
        without prime").

        `frames` is an iterable of (H, W, 3) uint8 BGR frames: a list, a generator, or a
        (K, H, W, 3) array. One frame alone (an array of shape (H, W, 3) or (H, W)) is refused,
        TypeError (iterated, it was taken for rows of a grey frame): ``prime([frame])``.
        The frames a generator (any iterable but a list, a tuple or an array) yields are
        copied as they come, so one that refills one buffer with each frame primes as its
        frames would.

        With `shape`, the (H, W, 3) shape of the frames of the run, `frames` are their
        :meth:`working_frame` results, made as they were read (``bootstrap_frames(source, n,
        prepare=tracker.working_frame)``: a 4K video's frames held at the working size, not
        25 MB each): each must have the working size of `shape` (ValueError otherwise), and
        the run's frames must have `shape`, as after priming with the frames themselves.
        """
        iterator = frames_iterator(frames, "prime")
        made = None if shape is None else self._made_shape(shape)
        with self._alone("prime"):
            if self.frame_count:
                raise ValueError("prime() must come before the first update()")
            held = isinstance(frames, (list, tuple, np.ndarray))  # frames that stay as given
            first = itertools.islice(iterator, self.prime_frames)  # no more: a whole video is big
            picked = []
            size: tuple[int, ...] | None = None  # of frame 0
            for i, frame in enumerate(first):
                f = bgr_frame(frame, "prime frame")
                if size is None:
                    size = f.shape
                elif f.shape != size:  # checked before the median of mixed sizes is taken
                    raise ValueError(
                        f"prime frame {i} is {f.shape[1]}x{f.shape[0]}, frame 0 "
                        f"{size[1]}x{size[0]} (the frames of one run are one size)"
                    )
                if made is not None and f.shape != made[1]:
                    h, w = made[1][:2]
                    raise ValueError(
                        f"prime frame {i} is {f.shape[1]}x{f.shape[0]}, expected "
                        f"{w}x{h}, the working size of frames of shape {made[0]}"
                    )
                work = self.working_frame(f)
                # an iterator may refill one buffer with each frame (``cap.read(buffer)``):
                # its frames are copied, or the median would be of its last frame alone
                fresh = held or not np.may_share_memory(work, frame)  # a view of it too
                picked.append(work if fresh else work.copy())
            if picked:
                self._tracker.prime(picked)
                self._primed = size if made is None else made[0]

    def _made_shape(self, shape: object) -> tuple[tuple[int, ...], tuple[int, ...]]:
        """:meth:`prime`'s `shape` checked, and the shape of its :meth:`working_frame` results.

        Raises
        ------
        TypeError, ValueError
            `shape` is not an (H, W, 3) tuple of ints >= 1.
        """
        if not (isinstance(shape, tuple) and len(shape) == 3
                and all(isinstance(n, (int, np.integer)) and not isinstance(n, bool)
                        for n in shape)):  # fmt: skip
            raise TypeError(f"prime: shape is {brief(shape)}, expected an (H, W, 3) tuple of ints")
        rows, cols, bands = (int(n) for n in shape)
        if rows < 1 or cols < 1 or bands != 3:
            raise ValueError(f"prime: shape is {brief(shape)}, expected (H, W, 3) with H, W >= 1")
        size = working_size((rows, cols, bands), self.config.max_side)
        work = (rows, cols, 3) if size is None else (size[1], size[0], 3)
        return (rows, cols, bands), work

    def update(
        self,
        dets: ArrayLike | None,
        frame: NDArray[np.uint8] = _NOT_GIVEN,
        embs: object = None,
        *,
        img: NDArray[np.uint8] = _NOT_GIVEN,
    ) -> F64:
        """Track one frame.

        BoxMOT's call, ``update(dets, img, embs)``, runs unchanged, by position or by keyword:
        ``update(dets=dets, img=frame)`` is ``update(dets, frame)``.

        Parameters
        ----------
        dets : (N, 6), (N, 5) or (N, 4) array_like of float, or None
            ``x1, y1, x2, y2, conf, cls`` in pixels (conf default 1, cls default 0); boxes
            reaching outside the frame are clipped to it (with one warning), boxes wholly
            outside are ignored, and so are boxes without area (``x2 == x1`` or ``y2 == y1``)
            and stray inverted ones (``x2 < x1`` or ``y2 < y1``), with one warning a run each.
            Inverted boxes that are most of the run's are refused, ValueError (x, y, w, h rows:
            :func:`check_boxes_xyxy`). None runs the built-in background-subtraction detector
            on this frame; a frame without detections is ``[]`` or ``np.zeros((0, 6))``
            (None after frames with detections warns, see below). The rows' order does not
            matter: the same rows in any order give the same tracks (``det_ind`` follows it).
        frame : (H, W, 3) ndarray of uint8
            BGR frame, as cv2 reads it (TypeError for another dtype, or for what is not a
            NumPy array: a list, a PIL image, whose RGB ``np.asarray(img)[..., ::-1]`` makes
            BGR; ValueError for another shape, naming ``cv2.cvtColor``'s conversion of a grey
            or BGRA frame).
        embs : object, optional
            BoxMOT's third argument, a detector's appearance embeddings: taken, so that a
            BoxMOT loop ``update(dets, frame, embs)`` runs unchanged, and not used (pftrack
            tells objects apart by their colour in `frame` and their motion), with one warning
            a run when given (was: a TypeError naming no argument). As BoxMOT's ReID trackers
            take them: a NumPy array, one row per row of `dets` (TypeError, ValueError; was:
            any object, of any row count, taken without a word).
        img : (H, W, 3) ndarray of uint8, keyword only
            `frame` under BoxMOT's name (its keyword call ``update(dets=..., img=...)``): give
            one of the two (TypeError when both or neither are given; an unknown keyword is
            Python's TypeError naming it).

        Returns
        -------
        (M, 8) ndarray of float
            ``x1, y1, x2, y2, id, conf, cls, det_ind`` of the confirmed tracks matched to a
            detection this frame (BoxMOT's convention): ``det_ind`` is the row of `dets` the
            track was matched to (a merged blob's row for each track inside it; -1 with
            ``dets=None``). Boxes are the track's filtered boxes, ``conf`` the detection's.
            The boxes are the filters' estimates and are not clipped to the frame (only
            `dets` are): near an edge they may reach past it by a few pixels, as ground-truth
            boxes do. Clip them before cropping, e.g. ``np.clip(out[:, [0, 2]], 0, W)`` and
            ``np.clip(out[:, [1, 3]], 0, H)``.

        Warns
        -----
        UserWarning
            Once a run each: boxes clipped to the frame, boxes without area dropped, and, with
            ``dets=None``, a camera found moving (``camera_motion`` "auto" or "on"): background
            subtraction is unreliable there, give detections. Once a run, `embs` given (not
            used). Once a run, ``dets=None`` after
            a frame with detections, naming the frame: it runs the built-in detector on that
            frame (as documented above), which a frame meant to have no detections (``[]``)
            does not want. Once, when the run's first frame is blank (one flat level, as
            ``np.zeros`` placeholders are): the colour filters and box refinement then have
            nothing to use. Once, at the run's 8th frame, when the built-in detector ran on
            the first 8 and they are heavily compressed (the median
            :func:`~pftrack.detection.blocking.blockiness`, 8x8 block edges over the steps
            inside them, is :data:`~pftrack.detection.blocking.BLOCKY` or more: JPEG quality
            10 and below, where the detector's MOTA fell on PETS09 and TUD-Campus).

        Raises
        ------
        TypeError
            `dets` is a uint8 image (``update(frame, dets)``: the message says the arguments
            look swapped), or supervision's ``Detections`` (the message names
            :class:`~pftrack.integrations.supervision.SupervisionTracker`); see `frame`,
            `dets` and `embs` for the others.
        RuntimeError
            An earlier ``update`` of the run was cut short (KeyboardInterrupt, or an error
            inside the tracker) after it had changed the tracker: the run cannot go on, but
            :meth:`finalize` returns the frames before it and :meth:`reset` starts a new run.
        """
        frame, named = _the_frame(frame, img)
        if embs is not None:
            _check_embs(embs, dets)
        with self._alone("update"):
            warned = set(self._warned)
            with Held() as held:  # given once the frame is taken whole (python -W error)
                try:
                    out = self._update(dets, frame, named)
                    if embs is not None:  # BoxMOT's ReID trackers' input; its others ignore it
                        self._warn_once(
                            "embs",
                            "Tracker.update: embs (appearance embeddings) are not used: pftrack "
                            "tells objects apart by their colour in the frame and their motion",
                        )
                except BaseException:
                    self._warned = warned  # the warnings held were not given
                    raise
            held.release(2 + self._caller_depth)  # the user's line, through an adapter too
            return out

    def _update(self, dets: ArrayLike | None, frame: NDArray[np.uint8], named: str) -> F64:
        """:meth:`update`, holding the tracker and its warnings (:class:`pftrack._warn.Held`).

        `named`: the frame's argument, ``"frame"`` or BoxMOT's ``"img"``.
        """
        if self._torn:
            raise RuntimeError(
                f"Tracker.update: the update of frame {self._torn} was interrupted "
                "(KeyboardInterrupt, or an error inside the tracker) after it had changed "
                "the tracker, which no longer holds a whole frame; finalize() still returns "
                f"the rows of frames 1-{self._torn - 1}, reset() starts a new run"
            )
        not_an_image(  # update(frame, dets), the lower-level API's order
            dets, "Tracker.update(dets, frame)", "dets",
            "MultiObjectTracker.update takes (frame, detections)",
        )  # fmt: skip
        kind = type(dets)
        if kind.__name__ == "Detections" and kind.__module__.startswith("supervision"):
            # its fields iterated as rows (or, empty, taken for no detection)
            raise TypeError(
                f"{self._box_source} is a supervision Detections: use pftrack.integrations."
                "supervision.SupervisionTracker's update_with_detections(detections, frame), "
                "or give np.column_stack([d.xyxy, d.confidence, d.class_id])"
            )
        f = bgr_frame(frame, named)
        shape = self._shape  # None until the run's first frame is taken
        first = shape is None
        if shape is None:
            primed = self._primed
            # the frames' own sizes: with max_side two sizes may scale to one, which the
            # tracker inside (it compares the scaled frames) would take
            if primed is not None and f.shape != primed:
                raise ValueError(
                    f"frame is {f.shape[1]}x{f.shape[0]}, the frames given to prime() "
                    f"{primed[1]}x{primed[0]} (one size per run)"
                )
            size = working_size(f.shape, self.config.max_side)
            self._scale = None  # one scale for the whole run's rows
            if size is not None:
                sx, sy = size[0] / f.shape[1], size[1] / f.shape[0]
                self._scale = np.array([sx, sy, sx, sy])
        elif f.shape != shape:
            scales = self.config.max_side is not None
            why = "max_side scales one size per run" if scales else "one size per run"
            raise ValueError(
                f"frame is {f.shape[1]}x{f.shape[0]}, the run's earlier frames "
                f"{shape[1]}x{shape[0]} ({why}; call reset() or use a new "
                "Tracker before a new video)"
            )
        work = self._working(f)
        # a frame the video could not decode, black in its place: no check of the footage
        stand_in = is_stand_in()
        if first and not stand_in and is_blank(f):
            self._warn_once(
                "blank",
                f"frame 1 is blank (every pixel within {BLANK_LEVELS} levels of the others): "
                "on blank frames the colour filters and box refinement have nothing to see, "
                "and tracks follow their detections and motion alone until the picture "
                "comes (a video that starts black is fine; placeholder frames? give the "
                "real ones)",
            )
        if not stand_in and self.frame_count - self._stood < BLOCK_FRAMES and dets is None:
            self._warn_blocky(f)  # the built-in detector's frames, stand-ins not measured
        if dets is None:
            if self._given:  # was silent: a loop's "no detections" for this frame?
                self._warn_once(
                    "none after dets",
                    f"frame {self.frame_count + 1}: dets=None runs the built-in "
                    "background-subtraction detector for this frame, after frames with "
                    "detections; for a frame without detections give [] or "
                    "np.zeros((0, 6))",
                )
            kept = None
            reports = self._step(work, None, None)
            if self._tracker.camera_step.moving:
                self._warn_moving_camera()
        else:
            xywh, cls, kept, clipped, flat, inverted, extent = check_boxes_xyxy(
                dets, (f.shape[0], f.shape[1]), name=self._box_source,
                xywh_hint=self._box_source == "dets", seen=self._layout,
            )  # fmt: skip
            # boxes in a larger frame's pixels, refused once the run's boxes say so
            outside = self._outside
            if clipped:
                outside = _outside_the_frame(dets, (f.shape[0], f.shape[1]), outside)
            if outside[0]:
                extent_seen = self._layout[1] + extent
                _refuse_larger_frame(
                    outside, extent_seen, (f.shape[0], f.shape[1]), self._box_source
                )
            if flat:
                self._warn_once(
                    "empty",
                    f"{flat} detection box{'es' if flat > 1 else ''} without area "
                    "(x2 == x1 or y2 == y1) ignored; later ones are ignored silently",
                )
            if inverted:
                self._warn_once(
                    "inverted",
                    f"{inverted} detection box{'es' if inverted > 1 else ''} with x2 < x1 "
                    "or y2 < y1 ignored (x1, y1, x2, y2 expected); later ones are ignored "
                    "silently",
                )
            if clipped:
                self._warn_once(
                    "clipped",
                    f"detections reaching outside the {f.shape[1]}x{f.shape[0]} frame were "
                    "clipped to it, those wholly outside ignored (wrong coordinate scale?)",
                )
            if (
                isinstance(dets, np.ndarray) and dets.dtype.kind in "iu" and dets.ndim == 2
                and dets.shape[1] >= 5 and len(xywh) and not xywh[:, 4].any()
            ):  # fmt: skip
                self._warn_once(
                    "integer",
                    f"frame {self.frame_count + 1}: detections given as integers ({dets.dtype}) "
                    "with every confidence 0 (truncated by astype(int)? give floats: the "
                    "confidences gate births)",
                )
            if len(xywh) > MANY_DETECTIONS:
                self._warn_once(
                    "many",
                    f"frame {self.frame_count + 1}: {len(xywh)} detections in one frame; each "
                    "frame's association then costs seconds (about 4.5 s of CPU with 10000 "
                    "boxes and 1800 tracks) and (tracks x detections) colour and cost matrices "
                    "(a detector's raw candidates? give its boxes after a confidence threshold "
                    "and non-maximum suppression)",
                )
            confidence = float(xywh[:, 4].max()) if len(xywh) else -np.inf
            if (
                self._max_conf == -np.inf and len(xywh) and min(f.shape[:2]) > 2
                and (xywh[:, 0] + xywh[:, 2]).max() <= 1
                and (xywh[:, 1] + xywh[:, 3]).max() <= 1
            ):  # fmt: skip
                # the run's first boxes, all inside one pixel: a detector's xyxyn output
                self._warn_once(
                    "normalised",
                    f"frame {self.frame_count + 1}: every detection box lies within "
                    "[0, 1] x [0, 1] of a "
                    f"{f.shape[1]}x{f.shape[0]} frame: normalised coordinates? give "
                    "pixels (x times the width, y times the height)",
                )
            if self._scale is not None:
                xywh[:, :4] *= self._scale
                xywh, cls, kept = _inside_working(xywh, cls, kept, work.shape)
            reports = self._step(work, xywh, cls)
            # once the frame is taken (an update that raises changes nothing)
            self._given = True
            life = self.config.lifecycle
            scored = xywh[:, 4] >= life.min_score
            if self.record and life.size_ratio is not None and scored.any():  # finalize's
                box = xywh[scored]
                c = np.zeros(len(box)) if cls is None else cls[scored].astype(np.float64)
                # a row given twice is one detection, as in _step; looked for only when the
                # tracker found a copy among all the rows (the scored ones are some of them)
                once = first_copies(box, c) if self._tracker.copies_given else None
                if once is not None:
                    box, c = box[once], c[once]
                foot, at = box[:, 1] + box[:, 3], np.full(len(box), float(self.frame_count))
                self._sizes.append(np.column_stack([foot, box[:, 3], c, at]))
            self._layout = (self._layout[0] + inverted, self._layout[1] + extent)
            self._outside = outside
            self._max_conf = max(self._max_conf, confidence)
        self.frame_count += 1
        self._stood += stand_in
        if first:  # the run's size, once its first frame is taken
            self._shape = f.shape
        if self.record:
            # the offline pass sees a still camera: boxes in the first frame's coordinates
            self._stabiliser.add(self._tracker.camera_step.apply)
            self._writer.add(self.frame_count, self._stabiliser.stabilise(reports))
        self._reports = reports
        self._torn = 0
        # coasting tracks (carried by the particle filter alone) are held back
        live = [t for t in reports if t.time_since_update == 0]
        if not live:
            return np.zeros((0, 8))
        # the rows on plain floats, one array made of them (the same float64 operations as
        # over arrays: a box divided by the scale, x2 = x1 + w; ids and rows as floats)
        scale = None if self._scale is None else self._scale.tolist()
        rows = kept.tolist() if kept is not None else None
        out = []
        for t in live:
            x, y, w, h = t.box_xywh.tolist()
            if scale is not None:
                x, y, w, h = x / scale[0], y / scale[1], w / scale[2], h / scale[3]
            i = t.detection_index
            row = -1 if rows is None or i is None else rows[i]
            out.append((x, y, x + w, y + h, t.id, t.score, t.cls, row))
        return np.array(out, dtype=np.float64)

    @property
    def last_reports(self) -> list[Track]:
        """Every track the last `update` reported, coasting ones too (what a renderer draws)."""
        if self._scale is None:
            return self._reports
        return [self._restore_track(t) for t in self._reports]

    @property
    def n_settled(self) -> int:
        """How many online rows (before the offline pass) the run has settled so far."""
        return len(self._writer.rows)

    def settled_rows(self, start: int = 0) -> F64:
        """The online MOTChallenge rows settled so far, from row `start` on.

        These are the rows before the offline pass (no linking or smoothing): a live source
        writes them as they come. A gap bridged by a particle filter is settled when the track
        is detected again. RuntimeError with ``record=False``, which keeps none.

        Parameters
        ----------
        start : int
            The first row returned, an int >= 0 (NumPy's too; not a bool): the
            :attr:`n_settled` of an earlier call, to read only the rows settled since. At or
            past :attr:`n_settled`: no row. TypeError for another type (``1.5``), ValueError
            for a negative value (``-1`` was every row, as a slice reads it).
        """
        start = check_seed(start, "Tracker.settled_rows: start")
        self._check_recorded("settled_rows")
        with self._alone("settled_rows"):  # not while another thread's update appends rows
            rows = self._writer.rows.arrays(start)[0]
            return self._restore_rows(self._stabiliser.restore(rows))

    def _check_recorded(self, method: str) -> None:
        if not self.record:
            raise RuntimeError(
                f"Tracker.{method}: this tracker was made with record=False, which keeps no "
                "rows (an online tracker: use update()'s output; record=True for the offline "
                "pass)"
            )

    def _no_track_cause(self, n_tracked: int) -> str:
        """Why :meth:`finalize` has no row: the first cause that holds, in the run's order."""
        cfg = self.config.lifecycle
        started = self._tracker.tracks_started
        if started and n_tracked:  # rows, all of them wholly outside the frame
            return "every box tracked lay outside the frame"
        if started:
            return (
                f"{started} track{'s' * (started != 1)} started but none reached "
                f"min_hits={cfg.min_hits} matched frames (shorter tracks are left out)"
            )
        found = self._tracker.found_own
        if not self._given and found:
            objects = f"{found} object{'s' * (found != 1)}"
            own = f"the built-in detector found {objects} over the run"
            if self._tracker.kept_own and self.config.sampler == "rjmcmc":
                return (
                    f"the joint sampler (rjmcmc) kept none of the {objects} the built-in "
                    "detector found (each is proposed as a birth; too few frames, or no colour "
                    "to weigh them?)"
                )
            if self._tracker.kept_own:  # kept, and not one with colour to start a track from
                return f"{own}, none with colour in its box to start a track from"
            if self._tracker.best_own_score >= cfg.min_score:  # min_area left them out
                return (
                    f"{own}: each one scoring at least min_conf {cfg.min_score:.3g} was under "
                    f"min_area={cfg.min_area:g} pixels (LifecycleConfig.min_area)"
                )
            return (
                f"{own}, scored at most {self._tracker.best_own_score:.3g}: none reached "
                f"min_conf {cfg.min_score:.3g}"
            )
        unboxed = self._tracker.unboxed_own
        if not self._given and unboxed:  # foreground that the blob filters left out
            n = self.frame_count
            detector = self._tracker.detector
            blobs = detector.config.blobs if isinstance(detector, PaperDetector) else BlobConfig()
            h, w = self._tracker.frame_shape[:2]
            return (
                f"the built-in detector found no object, though its foreground held pixels on "
                f"{unboxed} of the {n} frames (at most {self._tracker.unboxed_own_pixels} a "
                "frame): no region passed its blob filters (BlobConfig: min_area "
                f"{blobs.min_area:g} of the frame, {blobs.min_area * w * h:.0f} pixels at "
                f"{w}x{h}; height / width {blobs.min_aspect:g} to {blobs.max_aspect:g}; fill "
                f"{blobs.min_fill:g}): people too small in the frame, or noise? give a person "
                "detector's boxes (pftrack track --detections; Tracker.update's dets)"
            )
        if not self._given and self.frame_count == 1:  # a still image: no background to learn
            return (
                "the built-in detector found no object: it finds objects by their difference "
                "to a background learned over the frames, which one frame cannot give (give "
                "more frames, or a detector's boxes)"
            )
        if not self._given:
            return "the built-in detector found no object (no detection was given)"
        if self.config.sampler == "rjmcmc" and self._tracker.kept_given:
            return (  # its births take every detection kept (min_conf), confident or not
                "the joint sampler (rjmcmc) kept no object of the detections given (each is "
                "proposed as a birth; too few frames, or no colour to weigh them?)"
            )
        tiny, kept = self._tracker.tiny_given, self._tracker.kept_given
        if tiny and not kept:  # not the confidences: every box was too small to track
            return (
                f"every detection inside the frame was under min_area={cfg.min_area:g} pixels "
                f"({tiny} left out; LifecycleConfig.min_area)"
            )
        if np.isfinite(self._max_conf):
            return (
                f"the highest detection confidence was {self._max_conf:.3g} (min_conf "
                f"{cfg.min_score:.3g}, birth_score {cfg.birth_score:.3g})"
            )
        if "clipped" in self._warned:  # boxes were given, every one wholly outside the frame
            return "no detection lay inside the frame (wrong coordinate scale?)"
        if self._warned & {"empty", "inverted"}:  # every box given had x2 <= x1 or y2 <= y1
            return "every detection given was without area or had x2 < x1 or y2 < y1"
        return "the detections given held no box"

    def finalize(self) -> F64:
        """The run's MOTChallenge rows after the offline pass (what ``pftrack track`` writes).

        Returns
        -------
        (R, 10) ndarray of float
            ``frame, id, left, top, width, height, conf, flag, -1, -1`` (``flag`` 1 on a row the
            offline pass filled in a hole, else -1), frames from 1 (one per
            ``update``), sorted by frame then id; no row lies wholly outside the frame, but a
            box, the filters' and the smoother's estimate, is not clipped to it and may reach
            past its edge by a few pixels, as ground-truth boxes do (clip ``left`` and
            ``left + width`` to [0, W], ``top`` and ``top + height`` to [0, H] before
            cropping, e.g. with ``np.clip``). Warns
            when there is no row at all, naming the first cause that holds: tracks started
            but none reached ``min_hits`` matches, the built-in detector found nothing, the
            detections' confidences were below the birth threshold, or lay outside the frame,
            or there were none (once: a second call, with no ``update`` between, returns
            the same rows without warning again). With the
            built-in detector (no ``update`` of the run had detections) and the smoother on,
            boxes mostly inside a larger box of the same frame are left out
            (``LifecycleConfig.nested_inside``), and the boxes of partly seen people completed
            to the detector's expected person (``LifecycleConfig.amodal_share``). With the
            smoother on and ``TrackerConfig.crossings.enabled``, tracks swapped where they
            crossed are exchanged back after linking (:func:`~.offline.repair_crossings`).
            :attr:`classes` maps each id of the rows to its class (the ``cls`` column of the
            detections its track was made of; the offline pass renumbers ids, and never joins
            two classes).

        Raises
        ------
        RuntimeError
            The tracker was made with ``record=False`` (it kept no rows to pass over).
        """
        self._check_recorded("finalize")
        with self._alone("finalize"):
            smoothed = self._writer_args[2] is not None
            crossings = self.config.crossings if smoothed else None  # part of the smoothing pass
            link = self._writer_args[3]
            smoother = self._writer_args[2]
            # faster footage: more acceleration per frame, each class by its own speed
            smoothers = {}
            if smoother is not None:
                self._writer.smoother = smoother  # a class without speed samples: as given
                smoothers = {
                    c: replace(
                        smoother, accel=smoother.accel * g, size_accel=smoother.size_accel * g
                    )
                    for c, g in self._tracker.motion_gains.items()
                }
            if (
                link is not None
            ):  # its pixel gate grows with the frame (TrackerConfig.pixel_diagonal)
                scale = self._tracker.pixel_scale
                self._writer.link = replace(link, max_distance=link.max_distance * scale)
            # given detections only: the built-in detector's tracks coast through merged blobs
            relink = self.config.lifecycle.relink_coast if smoothed and self._given else None
            rows = self._stabiliser.restore(
                self._writer.result(
                    drop=self._tracker.never_confirmed(),
                    crossings=crossings,
                    relink_coast=relink,
                    smoothers=smoothers,
                )
            )
            life = self.config.lifecycle
            if (
                smoothed
                and self._given
                and life.size_ratio is not None
                and self._sizes
                and not self._stabiliser.moved
            ):
                # tracks sized unlike the detections' people at their row (size_ratio); a
                # height-for-row line is a still camera's: not after the camera was found moving
                shape = self._tracker.frame_shape
                cols = min(s.shape[1] for s in self._sizes)  # 3: a checkpoint had no frames
                sizes = np.vstack([s[:, :cols] for s in self._sizes])
                rows = drop_odd_sizes(
                    rows, sizes, life.size_ratio, shape[0] if shape else None,
                    self._writer.classes,
                )  # fmt: skip
            if smoothed and not self._given and life.nested_inside is not None and len(rows):
                # the built-in detector's fragments (LifecycleConfig.nested_inside)
                rows = drop_nested(rows, life.nested_inside, life.nested_area)
            if smoothed and not self._given and life.amodal_share is not None and len(rows):
                # partly seen people completed to the size model's person (amodal_share)
                size = getattr(self._tracker.detector, "size_model", None)
                if isinstance(size, PersonSizeModel) and size.coefficients is not None:
                    rows = complete_boxes(
                        rows,
                        size.coefficients,
                        life.amodal_share,
                        life.amodal_anchor,
                        size.config.split_ratio,
                        self._tracker.frame_shape[0] if self._tracker.frame_shape else None,
                        # the fits over the video disagree on the perspective: a head row a
                        # pixel decides is no evidence of a height (PersonSizeModel.fits_agree)
                        "complete" if size.fits_agree(life.amodal_share) else "leave",
                    )
            n_tracked = len(rows)  # before the rows wholly outside the frame are left out
            if len(rows) and len(self._tracker.frame_shape) >= 2:
                # a track carried past the frame's edge (coasting, or the smoother's extrapolation
                # at a track's end) leaves no row wholly outside the frame
                h, w = self._tracker.frame_shape[:2]
                x, y = rows[:, 2], rows[:, 3]
                inside = (x < w) & (y < h) & (x + rows[:, 4] > 0) & (y + rows[:, 5] > 0)
                rows = rows[inside]
            kept = set(rows[:, 1].astype(int).tolist())
            self.classes = {i: c for i, c in self._writer.classes.items() if i in kept}
            # once for the run's frames: a second finalize() of them returns the same rows
            # without a word (was: the same warning again); after more updates it is a new one
            said = f"no track at {self.frame_count}"
            if len(rows) == 0 and self.frame_count and said not in self._warned:
                self._warned.add(said)
                n = self.frame_count
                warn(
                    f"no track over {n} frame{'s' * (n != 1)}: {self._no_track_cause(n_tracked)}",
                    RuntimeWarning,
                    stacklevel=2 + self._caller_depth,  # the user's line, through an adapter too
                )
            return self._restore_rows(rows)
