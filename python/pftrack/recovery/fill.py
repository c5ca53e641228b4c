"""Gap filling of any tracker's MOTChallenge output.

Every hole of at most ``max_gap`` frames inside an id's track is filled by a recovery method
(:mod:`pftrack.recovery.registry`); filled rows carry the **interpolated flag in column 8**
(1-based; index :data:`~pftrack.recovery.linking.FLAG_COLUMN`): ``1`` on every row pftrack filled,
with columns 9-10 ``-1`` (:data:`~pftrack.recovery.linking.FILLED_MARK`; test a row with
:func:`~pftrack.recovery.linking.filled_mask`, as column 8 alone may hold 1 in ground truth);
observed rows untouched. Rows already flagged count as observed when a file is processed again,
so running the fill twice changes nothing more.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from itertools import pairwise
from typing import overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack import _check
from pftrack._check import MAX_COORD
from pftrack._stats import percentile
from pftrack._text import counted
from pftrack._typing import F64, IntLike, RecoveryMethod
from pftrack.particle_filter.colour import bhattacharyya_distance
from pftrack.recovery import calibrate
from pftrack.recovery.calibrate import Calibration, bags_for, gap_windows, recover_auto
from pftrack.recovery.linking import (
    FILLED_MARK,
    FLAG_COLUMN,
    box_centres,
    check_rows,
    check_tracked,
    check_unique,
    frame_histograms,
    sorted_tracks,
)
from pftrack.recovery.mixture import MotionFit, _fit_motion, check_models
from pftrack.recovery.names import NEIGHBOUR_METHODS
from pftrack.recovery.neighbours import Neighbourhood
from pftrack.recovery.noise import NoiseEstimate, _estimate_noise
from pftrack.recovery.registry import DEFAULT_METHOD, METHODS, _recover_nb, recover_gaps
from pftrack.recovery.segments import (
    MAX_GAP_LIMIT,  # Largest `max_gap` accepted
    distinct_runs,
)

__all__ = [
    "DEFAULT_MAX_GAP",
    "MAX_GAP_LIMIT",
    "SIZE_CANDIDATES",
    "FillReport",
    "copied_values",
    "fill_gaps",
    "fill_rows",
    "jump_holes",
    "jump_note",
    "long_holes",
    "short_holes",
    "side_frames",
    "swap_holes",
    "swap_note",
    "unfilled_note",
]

#: Longest hole filled by default, in frames, everywhere pftrack fills holes (``recover``,
#: ``smooth``, the tracker's offline pass): longer holes stay holes, so work and memory are
#: bounded by the number of rows whatever the frame numbers.
DEFAULT_MAX_GAP = 30
#: Methods ``"auto"`` scores for box sizes ``(w, h)``, calibrated like the centres.
SIZE_CANDIDATES = ("linear", "rts")
#: At most this many artificial gaps calibrate the box sizes.
SIZE_GAPS = 120
#: Methods that read the whole track around a hole (``gsi``'s kernel length depends on the
#: track's length): their segments are not cut to :func:`~pftrack.recovery.calibrate.gap_windows`.
WHOLE_SEGMENT_METHODS = ("gsi",)
#: Named methods whose holes are recovered :data:`~pftrack.recovery.calibrate.RECOVER_BLOCK`
#: at a time (each gap on its own, so the same paths): their batches stack every gap's window
#: (``rts`` and ``gdt-bi`` peaked 48 and 72 MB of RSS above ``linear`` on 200 170 rows with
#: 39 830 holes). The ``"-nb"`` methods go by the same blocks, with one neighbourhood for the
#: file (``registry._recover_nb``).
BLOCK_METHODS = ("gdt", "gdt-bi", "gdt-mix", "gdt-fixed", "rts")
#: A hole is left unfilled when its two sides are farther apart than this many times the
#: distance the object could have moved over it (:func:`jump_holes`): two objects under one id
#: (a tracker that hands an id on). The real holes of eight ground truths (41 851, the masks of
#: ``pftrack experiment gaps`` and a fifth of rows dropped) reach at most 1.87 times; 4 leaves
#: a margin of 2.1 (docs/recovery.md, "A hole between two objects is left").
JUMP_FACTOR = 4.0
#: The quantile of the file's frame-to-frame steps (in box sizes) any track may move at: the
#: file's own robust speed scale, so a camera that moves, a frame rate or a class of fast
#: objects raises it for the whole file.
STEP_QUANTILE = 0.9
#: Frame-to-frame steps on each side of a hole that give the track's own speed.
OWN_STEPS = 5
#: The least speed any object may have moved at over a hole, in box sizes a frame (and at
#: least 1 px a frame): where nothing in the file moves (no speed scale of its own), a person
#: who stood still on both sides may have walked across the hole.
MIN_SPEED = 0.05
#: With the video (`frames`), a hole is left unfilled when each of its sides looks more like
#: another box of the other side's frame than like the other side, by more than this factor
#: (:func:`swap_holes`): an id handed to a neighbour, whose jump is plausible. The true holes of
#: five ground truths with their videos (23 627) reach at most 1.71 times; 2.5 leaves a margin
#: of 1.47 (docs/recovery.md, "A hole between two neighbours").
SWAP_FACTOR = 2.5
#: The least colour distance a side's best other match counts as (Bhattacharyya distance): a
#: box whose pixels another box also covers matches it almost exactly, and a ratio to nearly 0
#: would judge nothing but noise.
SWAP_FLOOR = 0.02


@dataclass(frozen=True)
class FillReport:
    """What :func:`fill_gaps` did.

    ``n_gaps``, ``n_filled_rows``: the holes filled and the rows added; ``noise``: the noise
    levels of ``"gdt-bi"`` and ``"gdt-mix"`` (the `noise` given to :func:`fill_gaps`, or
    estimated from every track when none was), else the `noise` given (None by default);
    ``calibration``: with ``"auto"``, the method chosen per gap-length bucket and the
    validation MMAE of every candidate (:class:`~pftrack.recovery.calibrate.Calibration`);
    ``size_calibration``: the same for the box sizes ``(w, h)`` (candidates
    :data:`SIZE_CANDIDATES`); ``n_long_holes``: the holes of more than ``max_gap`` missing
    frames, left unfilled (bounded work), and ``longest_hole`` the missing frames of the
    longest of them (0 without one; :func:`long_holes`, :func:`unfilled_note`); ``method``:
    the method of the fill (:meth:`describe` tells what it chose); ``n_jumps``: the holes of
    at most ``max_gap`` frames left unfilled because their two sides are too far apart to be
    one object (:func:`jump_holes`), and ``largest_jump`` the largest of their jumps, in
    times the distance allowed (0 without one; :func:`jump_note`); ``n_swaps``: with the
    video, the holes left unfilled because each side looks more like another box than like
    the other side (:func:`swap_holes`), and ``largest_swap`` the largest of their ratios (0
    without one; :func:`swap_note`).
    """

    n_gaps: int
    n_filled_rows: int
    noise: NoiseEstimate | None
    calibration: Calibration | None = None
    size_calibration: Calibration | None = None
    n_long_holes: int = 0
    longest_hole: int = 0
    method: RecoveryMethod = DEFAULT_METHOD
    n_jumps: int = 0
    largest_jump: float = 0.0
    n_swaps: int = 0
    largest_swap: float = 0.0

    def __str__(self) -> str:
        """What ``print(report)`` shows: the counts, then :meth:`describe` (``repr``: fields).

        Was the dataclass's every field, nested calibrations and all, on one line.
        """
        filled = f"{counted(self.n_gaps, 'gap')} filled, {counted(self.n_filled_rows, 'row')} added"
        if self.n_long_holes:
            filled += (
                f"; {counted(self.n_long_holes, 'hole')} longer than max_gap left unfilled "
                f"(the longest {counted(self.longest_hole, 'frame')})"
            )
        if self.n_jumps:
            filled += f"; {jump_note(self.n_jumps, self.largest_jump)}"
        if self.n_swaps:
            filled += f"; {swap_note(self.n_swaps, self.largest_swap)}"
        return f"fill_gaps ({self.method}): {filled}\n{self.describe()}"

    def describe(self, method: str | None = None) -> str:
        """What was chosen: what ``pftrack recover --explain`` prints.

        With ``"auto"``, the choice for the box centres, then for the box sizes
        (:meth:`~pftrack.recovery.calibrate.Calibration.describe`), or that there was no gap
        to fill (and how many holes were longer than ``max_gap``); with a named method, that
        it filled every gap and nothing was chosen.

        Parameters
        ----------
        method : str, optional
            Only for compatibility (the report records its method, :attr:`method`): a
            method other than the fill's is refused.

        Raises
        ------
        ValueError
            `method` given and not the fill's.
        """
        if method is not None and method != self.method:
            raise ValueError(
                f"FillReport.describe: the fill used {self.method!r}, not {method!r} (the "
                "report records its method: call describe() without one)"
            )
        parts = []
        if self.calibration is not None:
            parts += ["box centres (x, y):", self.calibration.describe()]
        if self.size_calibration is not None:
            parts += ["box sizes (w, h):", self.size_calibration.describe()]
        elif self.method == "auto" and self.n_long_holes:  # was "no gap to fill" of them
            holes = (
                f"1 hole longer, left unfilled: {self.longest_hole} frames"
                if self.n_long_holes == 1
                else f"{self.n_long_holes} holes longer, left unfilled; the longest "
                f"{self.longest_hole} frames"
            )
            parts.append(
                f"auto: no gap of at most max_gap frames to fill, nothing was chosen ({holes})"
            )
        elif self.method == "auto":
            parts.append("auto: no gap to fill")
        else:
            gaps = "1 gap" if self.n_gaps == 1 else f"{self.n_gaps} gaps"
            parts.append(
                f"{self.method}: {gaps} filled by the method given, nothing was chosen (auto "
                "chooses a method per gap length)"
            )
        if self.n_jumps:  # was filled: a path drawn between two objects (issue 12)
            parts.append(jump_note(self.n_jumps, self.largest_jump))
        if self.n_swaps:  # was filled: a path drawn between two neighbours (issue 12)
            parts.append(swap_note(self.n_swaps, self.largest_swap))
        return "\n".join(parts)


def long_holes(rows: F64, max_gap: int) -> tuple[int, int]:
    """The holes of more than `max_gap` missing frames inside the ids' tracks of `rows`.

    What :func:`fill_gaps` and :func:`pftrack.tracking.smooth_tracks` leave unfilled (every
    shorter hole is filled): of their output, these are its only holes.

    Parameters
    ----------
    rows : (M, >=2) ndarray
        Rows ``frame, id, ...``, each (frame, id) at most once, in any order.
    max_gap : int
        Longest hole filled, in frames.

    Returns
    -------
    count : int
        How many holes are longer than `max_gap`.
    longest : int
        The missing frames of the longest of them (0 without one).
    """
    _, missing = _missing_after(np.asarray(rows, dtype=np.float64))
    missing = missing[missing > max_gap]
    return len(missing), int(missing.max()) if len(missing) else 0


def _missing_after(a: F64) -> tuple[F64, NDArray[np.float64]]:
    """`a` by id then frame, and the frames missing after each row before its id's next.

    -1 where the next row is another id's: the one walk of :func:`long_holes`,
    :func:`short_holes` and :func:`side_frames`.
    """
    a = a[np.lexsort((a[:, 0], a[:, 1]))]
    missing = np.diff(a[:, 0]) - 1
    missing[a[1:, 1] != a[:-1, 1]] = -1
    return a, missing


def unfilled_note(count: int, longest: int, max_gap: int) -> str:
    """What ``pftrack recover`` and ``smooth`` say of the holes longer than ``--max-gap``.

    ``"3 holes longer than --max-gap 30 left unfilled (longest 9999998 frames)"`` (a `count`
    of 1: ``"1 hole ... (9999998 frames)"``); empty when `count` is 0.
    """
    if not count:
        return ""
    holes, longest_ = ("1 hole", "") if count == 1 else (f"{count} holes", "longest ")
    return f"{holes} longer than --max-gap {max_gap} left unfilled ({longest_}{longest} frames)"


def short_holes(rows: F64, max_gap: int) -> int:
    """How many holes of at most `max_gap` missing frames the ids' tracks of `rows` have.

    Of the output of :func:`fill_gaps` or :func:`pftrack.tracking.smooth_tracks` with the same
    `max_gap`, these are the holes :func:`jump_holes` left (every other one is filled): what
    ``pftrack smooth`` counts, as its fill's report is not returned.
    """
    _, missing = _missing_after(np.asarray(rows, dtype=np.float64))
    return int(np.count_nonzero((missing >= 1) & (missing <= max_gap)))


def jump_holes(r: F64, holes: NDArray[np.int64]) -> F64:
    """How far each hole's two sides are apart, in times the distance its object could move.

    The jump is the distance between the box centres on the two sides of the hole, in box
    sizes (the mean of the two boxes' ``(w + h) / 2``); the distance allowed is the frames
    between them times a speed: the largest of the track's own :data:`OWN_STEPS`
    frame-to-frame steps on each side of the hole, the file's :data:`STEP_QUANTILE` quantile of
    every track's frame-to-frame steps (its robust speed scale: camera motion and fast classes
    raise it) and :data:`MIN_SPEED` (or 1 px a frame, the more). A hole of a track with no two
    rows on consecutive frames among the :data:`OWN_STEPS` steps on each side is not judged
    (0). :func:`fill_gaps` leaves a hole of more than :data:`JUMP_FACTOR` unfilled: its sides
    are two objects under one id, and a filled path would join them (issue 12: a tracker that
    hands its ids on; was filled without a word).

    Parameters
    ----------
    r : (M, >=6) ndarray
        Rows ``frame, id, left, top, width, height, ...`` sorted by id, then frame.
    holes : (H,) ndarray of int
        Rows of `r` followed by a later frame of the same id (the last row before each hole).

    Returns
    -------
    (H,) ndarray of float
        Each hole's jump over the distance allowed (0 where nothing can be judged: no step
        between consecutive frames near the hole, or anywhere in `r`).
    """
    if not len(holes):
        return np.zeros(0)
    size = 0.5 * (r[:, 4] + r[:, 5])  # a box 0 wide still has a size
    pair = 0.5 * (size[1:] + size[:-1])
    # jump of every pair of neighbouring rows, in box sizes (a 0 x 0 box: in pixels)
    step = np.hypot(*(r[1:, 2:4] + 0.5 * r[1:, 4:6] - r[:-1, 2:4] - 0.5 * r[:-1, 4:6]).T)
    step = step / np.maximum(pair, 1.0)
    same = r[1:, 1] == r[:-1, 1]
    consecutive = same & (r[1:, 0] - r[:-1, 0] == 1)
    if not consecutive.any():
        return np.zeros(len(holes))
    file_speed = percentile(step[consecutive], 100 * STEP_QUANTILE)  # np.quantile's, no numpy.ma
    # the track's own steps: the pairs within OWN_STEPS of the hole, of consecutive frames of
    # its id (other holes and other ids left out)
    offsets = np.r_[np.arange(-OWN_STEPS, 0), np.arange(1, OWN_STEPS + 1)]
    at = holes[:, None] + offsets[None, :]
    inside = (at >= 0) & (at < len(step))
    at = np.clip(at, 0, len(step) - 1)
    mine = inside & consecutive[at] & (r[at, 1] == r[holes, 1][:, None])
    own = np.where(mine, step[at], 0.0).max(axis=1)
    scale = np.maximum(pair[holes], 1.0)
    speed = np.maximum(np.maximum(own, file_speed), np.maximum(MIN_SPEED, 1.0 / scale))
    frames = r[holes + 1, 0] - r[holes, 0]
    out: F64 = step[holes] / (frames * speed)
    # a track seen on no two consecutive frames near the hole has no speed of its own: the
    # file's alone would judge a sparse track (a detector run every few frames) by others
    out[~mine.any(axis=1)] = 0.0
    return out


def jump_note(count: int, largest: float) -> str:
    """What `recover`, `smooth` and the report say of the holes :func:`jump_holes` left.

    ``"2 holes left unfilled: their two sides are too far apart for one object (up to 9.3
    times the distance it could move; two objects under one id?)"``; empty when `count` is 0.
    """
    if not count:
        return ""
    holes = "1 hole" if count == 1 else f"{count} holes"
    its = "its" if count == 1 else "their"
    up = "" if count == 1 or largest <= 0 else "up to "
    times = f"{up}{largest:.1f} times the distance it could move; " if largest > 0 else ""
    return (
        f"{holes} left unfilled: {its} two sides are too far apart for one object "
        f"({times}two objects under one id?)"
    )


def swap_holes(r: F64, holes: NDArray[np.int64], frames: Sequence[NDArray[np.uint8]]) -> F64:
    """How much more each hole's sides look like other boxes than like each other (colour).

    A hole's sides are the boxes before it (frame ``a``) and after it (frame ``b``); ``d`` is
    the Bhattacharyya distance of their colour histograms (the linker's colour term,
    :func:`~pftrack.recovery.linking.frame_histograms`), ``m_a`` the least distance of the
    side before to another id's box at frame ``b``, ``m_b`` that of the side after to another
    id's box at frame ``a``. The ratio is ``d / max(m_a, m_b, SWAP_FLOOR)``: above 1 when *both*
    sides have a better match among the other objects than each other, as when a tracker hands
    an id to a neighbour and the two go on under each other's ids. The scale is the file's and
    video's own (the objects seen at those two frames), so lighting, camera and clothing set
    it, not a constant. :func:`fill_gaps` with `frames` leaves a hole of more than
    :data:`SWAP_FACTOR` unfilled (issue 12: the jump of :func:`jump_holes` is plausible
    between two neighbours). Only the frames of the holes' sides are read, in one pass.

    Parameters
    ----------
    r : (M, >=6) ndarray
        Rows ``frame, id, left, top, width, height, ...`` sorted by id, then frame.
    holes : (H,) ndarray of int
        Rows of `r` followed by a later frame of the same id (the last row before each hole).
    frames : sequence of (H, W, 3) uint8
        The video's BGR frames, index ``frame - 1``.

    Returns
    -------
    (H,) ndarray of float
        Each hole's ratio; 0 where nothing can be judged: a side with nothing to count (out of
        the frame, or past the end of `frames`), or no other box at one of the two frames.
    """
    out = np.zeros(len(holes))
    if not len(holes):
        return out
    frame = r[:, 0].astype(np.int64)
    sides = np.unique(np.r_[frame[holes], frame[holes + 1]])
    at = np.flatnonzero(_among(frame, sides))
    at = at[np.argsort(frame[at], kind="stable")]  # the rows of each side frame, together
    cuts = np.flatnonzero(np.diff(frame[at])) + 1
    groups = {int(frame[g[0]]): g for g in np.split(at, cuts)}
    hists = frame_histograms({f - 1: r[g, 2:6] for f, g in groups.items()}, frames)
    where = np.empty(len(r), dtype=np.int64)  # each side row's place in its frame's group
    for g in groups.values():
        where[g] = np.arange(len(g))

    def others(f: int, tid: float) -> F64 | None:
        h = hists[f - 1]
        if h is None:
            return None
        h = h[(r[groups[f], 1] != tid) & (h.sum(axis=1) > 0)]
        return h if len(h) else None

    for k, e in enumerate(holes.tolist()):
        fa, fb, tid = int(frame[e]), int(frame[e + 1]), float(r[e, 1])
        ha_all, hb_all = hists[fa - 1], hists[fb - 1]
        if ha_all is None or hb_all is None:
            continue
        ha, hb = ha_all[where[e]], hb_all[where[e + 1]]
        xa, xb = others(fb, tid), others(fa, tid)
        if ha.sum() <= 0 or hb.sum() <= 0 or xa is None or xb is None:
            continue
        d = float(bhattacharyya_distance(hb[None], ha)[0])
        best = max(
            float(bhattacharyya_distance(xa, ha).min()),  # the side before, among frame b's
            float(bhattacharyya_distance(xb, hb).min()),  # the side after, among frame a's
            SWAP_FLOOR,
        )
        out[k] = d / best
    return out


def side_frames(rows: ArrayLike, max_gap: int) -> set[int]:
    """The 0-based frames of the two sides of every hole of at most `max_gap` missing frames.

    A superset of the frames :func:`swap_holes` reads for `rows` (it judges only the holes
    the jump rule lets through): with :func:`pftrack.recovery.linking.link_frames`, what a
    :class:`~pftrack.recovery.linking.BoxColours` must hold for ``recover --link --video``
    to decode its video once. The holes a join of the linker makes have the joined
    fragments' ends as sides, which ``link_frames`` holds.
    """
    r, missing = _missing_after(check_rows(rows, "side_frames"))
    hole = np.flatnonzero((missing >= 1) & (missing <= max_gap))
    return set((r[hole, 0].astype(np.int64) - 1).tolist()) | set(
        (r[hole + 1, 0].astype(np.int64) - 1).tolist()
    )


def swap_note(count: int, largest: float) -> str:
    """What `recover --video` and the report say of the holes :func:`swap_holes` left.

    ``"1 hole left unfilled: each side looks more like another object than like the other
    (2.8 times; an id handed to a neighbour?)"``; empty when `count` is 0.
    """
    if not count:
        return ""
    holes = "1 hole" if count == 1 else f"{count} holes"
    up = "" if count == 1 else "up to "
    return (
        f"{holes} left unfilled: each side looks more like another object than like the "
        f"other in the video ({up}{largest:.1f} times; an id handed to a neighbour?)"
    )


#: The methods whose recovery uses :func:`fill_gaps`' `noise`.
NOISE_METHODS = ("auto", "gdt-bi", "gdt-mix")


def fill_gaps(
    tracks: ArrayLike,
    method: RecoveryMethod = DEFAULT_METHOD,
    max_gap: IntLike = DEFAULT_MAX_GAP,
    noise: NoiseEstimate | None = None,
    *,
    seed: int = 0,
    combine: bool = True,
    bags: int | None = None,
    frames: Sequence[NDArray[np.uint8]] | None = None,
) -> tuple[F64, FillReport]:
    """Fill every hole of at most `max_gap` missing frames inside each id's track.

    Parameters
    ----------
    tracks : (M, 6..10) array_like
        MOTChallenge rows; each (frame, id) at most once. Rows of fewer than 10 columns get
        the columns a file's shorter lines get (conf 1, x, y, z -1:
        :func:`pftrack._check.mot_rows`), as ``pftrack recover`` reads them; an empty array
        (``[]``) is no rows.
    method : str
        One of :data:`~pftrack.recovery.registry.METHODS`; default ``"auto"`` (calibrated on
        the file's own observed tracks, :mod:`pftrack.recovery.calibrate`).
    max_gap : int
        Longest hole filled, in frames (>= 1).
    noise : NoiseEstimate, optional
        For ``"gdt-bi"`` and ``"gdt-mix"``: noise levels to use; default: estimated from every
        track of the file (:func:`~pftrack.recovery.noise.estimate_noise`). ``"gdt-mix"`` fits
        one motion model to the whole file.
    seed : int
        For ``"auto"``: seed of the generator placing the artificial calibration gaps.
    combine : bool
        For ``"auto"``: a gap-length bucket may use a convex combination of two methods when
        it beats the single best on the validation gaps (default;
        :func:`~pftrack.recovery.calibrate.calibrate`). False: one method per bucket, for the
        box centres and sizes (and no bagging, which would blend the resamples' choices).
    bags : int or None
        For ``"auto"``: bootstrap resamples of the validation gaps the choice is averaged over
        (:func:`~pftrack.recovery.calibrate.calibrate`; 0: one choice). None (default):
        :data:`~pftrack.recovery.calibrate.BAGS` with `combine`, 0 without; more than 0 with
        ``combine=False`` is refused.
    frames : sequence of (H, W, 3) uint8, optional
        The video's BGR frames (index ``frame - 1``; a
        :class:`pftrack.io.video.FrameSequence` reads only those asked for, in one pass): a
        hole whose two sides each look more like another object than like each other is
        left unfilled (:func:`swap_holes`, ``report.n_swaps``). Without it, nothing is read.

    Returns
    -------
    rows : (M + n, 10) ndarray
        The rows plus the filled ones, sorted by (frame, id). Filled rows get positions from
        `method`; sizes from the same calibration with ``"auto"`` (:data:`SIZE_CANDIDATES`,
        never below half the smaller end size), else by linear interpolation; ``conf`` = the
        smaller of the two neighbours' and columns 8-10 ``1, -1, -1``: the interpolated flag
        (column 8, :data:`FLAG_COLUMN`) and no world ``y``, ``z`` (:data:`FILLED_MARK`).
        Observed rows are returned unchanged (with 10 columns).
    report : FillReport
        How many holes and rows were filled, how many holes were longer than `max_gap` (left
        unfilled: ``report.n_long_holes``, ``report.longest_hole``); with ``"auto"``, what
        was chosen (``report.calibration``).

    Raises
    ------
    TypeError
        Rows that are not real numbers, `combine` not a bool, `seed` or `max_gap` not an int,
        `noise` not a NoiseEstimate.
    ValueError
        Unknown method, a negative `seed`, a `seed` other than 0 with a method other than
        ``"auto"`` or `noise` with a method that does not use it (neither would change
        anything), `bags` not None or an integer in ``0..10000`` (or
        more than 0 with ``combine=False``), `max_gap` outside ``1..MAX_GAP_LIMIT``,
        rows not ``(M, 6..10)``, a frame that is not an integer in ``1..2**31-1``, a non-integer
        id, a non-finite box, a box :func:`pftrack.io.mot.read_mot` refuses (a negative width
        or height, a value beyond ±1e9 px), a duplicate (frame, id), a row of id -1 (an
        unassociated box, not a track: :func:`pftrack.recovery.linking.check_tracked`) or of
        another negative id (``pftrack eval`` and TrackEval refuse it).
    """
    rows = _check.mot_rows(tracks, "fill_gaps", "tracks")  # (M, 6..10), [] too, as smooth_tracks
    # what the method does not use is refused, as the command refuses --seed (was ignored
    # without a word; a user trial)
    _check.option(method, "fill_gaps: method", METHODS)
    if isinstance(noise, NoiseEstimate) and method in METHODS and method not in NOISE_METHODS:
        raise ValueError(
            f"fill_gaps: noise is used by methods {', '.join(NOISE_METHODS)}, not {method!r}"
        )
    if not isinstance(seed, bool) and isinstance(seed, (int, np.integer)) and seed != 0:
        if method in METHODS and method != "auto":
            raise ValueError(f"fill_gaps: seed is used by method 'auto' only, not {method!r}")
    new_rows, report = fill_rows(
        rows, method, max_gap, noise, seed=seed, combine=combine, bags=bags, frames=frames
    )
    filled = np.vstack([rows, new_rows])
    order = np.lexsort((filled[:, 1], filled[:, 0]))
    return filled[order], report


def fill_rows(
    rows: ArrayLike,
    method: RecoveryMethod = DEFAULT_METHOD,
    max_gap: IntLike = DEFAULT_MAX_GAP,
    noise: NoiseEstimate | None = None,
    *,
    seed: int = 0,
    combine: bool = True,
    bags: int | None = None,
    frames: Sequence[NDArray[np.uint8]] | None = None,
) -> tuple[F64, FillReport]:
    """The rows :func:`fill_gaps` adds (flagged, in no particular order), and its report.

    Parameters are those of :func:`fill_gaps`; `rows` are checked the same way.
    """
    if method not in METHODS:
        raise ValueError(f"fill_gaps: method is {method!r}, expected one of {METHODS}")
    if not isinstance(combine, (bool, np.bool_)):
        raise TypeError(f"fill_gaps: combine must be a bool, got {type(combine).__name__}")
    seed = _check.seed(seed, "fill_gaps: seed")  # NumPy's refusal named no argument
    if frames is not None and not (hasattr(frames, "__len__") and hasattr(frames, "__getitem__")):
        raise TypeError(
            "fill_gaps: frames must be a sequence indexable by frame - 1 (a list, an array, "
            f"a FrameSequence) or None, got {type(frames).__name__}"
        )
    bags = bags_for(bags, bool(combine), "fill_gaps")
    check_models(noise, None, "fill_gaps")
    max_gap = _check.integer(max_gap, "fill_gaps: max_gap", 1, MAX_GAP_LIMIT)
    rows = check_rows(rows, "fill_gaps")
    check_unique(rows, who="fill_gaps")
    check_tracked(rows, who="fill_gaps")
    # every track's rows one after the other (by id, then frame), its centres and segment rows:
    # one sorted copy of the rows (was a dict of tracks and their concatenation, two copies,
    # 80 bytes a row more at the peak), none of rows in that order already (smooth's)
    r, track_ends = sorted_tracks(rows, share=True)
    c = box_centres(r)
    seg = np.column_stack([c, r[:, 4], r[:, 5]])
    ends = track_ends.tolist()
    # every track's centres (frame, x, y): noise, motion, calibration
    bounds = list(pairwise([0, *ends]))
    whole: list[F64] = [c[i:j] for i, j in bounds]
    win = gap_windows(r[:, 0], r[:, 1])
    missing = (r[win.holes + 1, 0] - r[win.holes, 0] - 1).astype(np.int64)
    too_long = missing > max_gap  # bounded work: longer holes stay holes
    n_long = int(too_long.sum())
    longest = int(missing[too_long].max()) if n_long else 0
    # Every method but gsi gets only the points each hole's recovery reads (gap_windows; for
    # "auto" the whole segments' lengths go as contexts): memory about the tracks' length, not
    # a track's length per hole. A centre beyond MAX_COORD keeps the whole segments: they are
    # refused naming the row, as they were (any far centre: every track's, the same bits).
    cut = method not in WHOLE_SEGMENT_METHODS and (
        not len(c) or np.abs(c[:, 1:3]).max() <= MAX_COORD
    )
    lo, hi = (win.lo, win.hi) if cut else (win.first, win.end)
    # two objects under one id (issue 12): judged on the holes short enough to fill only
    jump = np.zeros(len(win.holes))
    jump[~too_long] = jump_holes(r, win.holes[~too_long])
    jumps = jump > JUMP_FACTOR
    n_jumps = int(jumps.sum())
    largest_jump = float(jump[jumps].max()) if n_jumps else 0.0
    keep = ~too_long & ~jumps
    n_swaps, largest_swap = 0, 0.0
    if frames is not None:  # two neighbours under one id: their jump is plausible (issue 12)
        swap = np.zeros(len(win.holes))
        swap[keep] = swap_holes(r, win.holes[keep], frames)
        swaps = swap > SWAP_FACTOR
        n_swaps = int(swaps.sum())
        largest_swap = float(swap[swaps].max()) if n_swaps else 0.0
        keep &= ~swaps
    holes, lo, hi = win.holes[keep], lo[keep], hi[keep]
    segs = _HolePairs(seg, holes, lo, hi)  # made a block at a time as recover_auto reads them
    before = (holes + 1 - win.first[keep]).tolist()  # observed points before each hole
    after = (win.end[keep] - holes - 1).tolist()  # and after it
    contexts = list(zip(before, after, strict=True))
    motion: MotionFit | None = None
    calibration: Calibration | None = None
    if method in ("gdt-bi", "gdt-mix") and segs:
        if noise is None:
            noise = _estimate_noise(whole)
        if method == "gdt-mix":  # one model for the file, not one per pair of segments
            motion = _fit_motion(whole, noise)
    new_rows: list[F64] = []
    size_cal: Calibration | None = None
    if segs:
        wh_paths: list[F64] | None = None
        if method == "auto":
            paths, calibration = recover_auto(
                segs, whole, noise, motion, seed=seed, combine=combine, bags=bags, contexts=contexts
            )
            wh = r[:, [0, 4, 5]]
            sizes = [wh[i:j] for i, j in bounds]
            wh_paths, size_cal = recover_auto(
                _HolePairs(seg, holes, lo, hi, [0, 3, 4]),
                sizes,
                seed=seed,
                candidates=SIZE_CANDIDATES,
                max_gaps=SIZE_GAPS,
                combine=combine,
                bags=bags,
                contexts=contexts,
                regions=False,  # sizes are not image positions: no region cuts them
            )
        elif method in NEIGHBOUR_METHODS:  # a block of holes at a time, one neighbourhood
            hood = Neighbourhood(distinct_runs(whole, strict="recover_gaps"))
            paths = _recover_nb(segs, method, hood)
        else:
            # the batched methods a block of holes at a time, as "auto" (each gap is recovered
            # on its own: the same paths, a block's stacked windows); the others in one call
            # (the baselines' loop shows a bar)
            step = calibrate.RECOVER_BLOCK if method in BLOCK_METHODS else len(segs)
            paths = []
            for at in range(0, len(segs), step):
                paths += recover_gaps(segs[at : at + step], method, noise=noise, motion=motion)
        for k, (e, xy) in enumerate(zip(holes.tolist(), paths, strict=True)):
            tid, ra, rb = int(r[e, 1]), r[e], r[e + 1]
            fr = np.arange(ra[0] + 1, rb[0])
            if wh_paths is None:  # sizes by linear interpolation
                s = (fr - ra[0]) / (rb[0] - ra[0])
                w = (1 - s) * ra[4] + s * rb[4]
                h = (1 - s) * ra[5] + s * rb[5]
            else:  # never below half the smaller end size
                w = np.maximum(wh_paths[k][:, 0], 0.5 * min(ra[4], rb[4]))
                h = np.maximum(wh_paths[k][:, 1], 0.5 * min(ra[5], rb[5]))
            out = np.empty((len(fr), 10))
            out[:, 0] = fr
            out[:, 1] = tid
            out[:, 2] = xy[:, 0] - 0.5 * w
            out[:, 3] = xy[:, 1] - 0.5 * h
            out[:, 4] = w
            out[:, 5] = h
            out[:, 6] = min(ra[6], rb[6])
            out[:, FLAG_COLUMN : FLAG_COLUMN + 3] = FILLED_MARK
            new_rows.append(out)
    added = np.vstack(new_rows) if new_rows else np.zeros((0, 10))
    return added, FillReport(
        len(segs),
        len(added),
        noise,
        calibration,
        size_cal,
        n_long,
        longest,
        method,
        n_jumps,
        largest_jump,
        n_swaps,
        largest_swap,
    )


class _HolePairs(Sequence[tuple[F64, F64]]):
    """Each hole's segments: rows ``lo[j] : holes[j] + 1`` and ``holes[j] + 1 : hi[j]`` of `seg`.

    Made when read (views of `seg`; with `cols`, copies of those columns), so
    :func:`~pftrack.recovery.calibrate.recover_auto`, which reads a block of holes at a time,
    holds a block's: the list of every hole's views took about 600 bytes a hole, the copies of
    the size columns ``frame, w, h`` 84 MB on 200 170 rows with 39 830 holes.
    """

    def __init__(
        self,
        seg: F64,
        holes: NDArray[np.int64],
        lo: NDArray[np.int64],
        hi: NDArray[np.int64],
        cols: list[int] | None = None,
    ) -> None:
        self.seg, self.holes, self.lo, self.hi, self.cols = seg, holes, lo, hi, cols

    def __len__(self) -> int:
        return len(self.holes)

    @overload
    def __getitem__(self, k: int) -> tuple[F64, F64]: ...
    @overload
    def __getitem__(self, k: slice) -> list[tuple[F64, F64]]: ...
    def __getitem__(self, k: int | slice) -> tuple[F64, F64] | list[tuple[F64, F64]]:
        if isinstance(k, slice):
            return [self[j] for j in range(*k.indices(len(self)))]
        if not -len(self) <= k < len(self):
            raise IndexError(k)
        e = int(self.holes[k])
        a, b = self.seg[int(self.lo[k]) : e + 1], self.seg[e + 1 : int(self.hi[k])]
        return (a, b) if self.cols is None else (a[:, self.cols], b[:, self.cols])


def copied_values(rows: F64, filled: F64) -> NDArray[np.bool_]:
    """Which values of `filled` (:func:`fill_gaps` of `rows`) are copies of given values.

    Every value of a row of `rows` (matched by frame and id), and the ``conf`` and columns
    8-10 of a filled row (a neighbour's ``conf``, then :data:`FILLED_MARK`); the filled boxes
    are computed. ``write_mot(path, filled, exact=copied_values(rows, filled))`` writes the
    given values unchanged, however many digits they have, and the computed boxes with 2
    decimals (:func:`pftrack.io.mot.write_mot`), as ``pftrack recover`` does.

    Returns
    -------
    (M', 10) ndarray of bool
    """

    def key(a: F64) -> NDArray[np.int64]:
        out: NDArray[np.int64] = a[:, 0].astype(np.int64) * (1 << 32) + a[:, 1].astype(np.int64)
        return out

    f, r = np.asarray(filled, np.float64), np.asarray(rows, np.float64)
    mask = np.zeros(f.shape, dtype=bool)
    if len(f):
        mask[:, 6:] = True
        mask[_among(key(f), key(r))] = True
    return mask


def _among(keys: NDArray[np.int64], given: NDArray[np.int64]) -> NDArray[np.bool_]:
    """``np.isin(keys, given)`` by a sorted search, without ``numpy.ma``.

    ``np.isin`` calls ``np.unique``, whose first call imports ``numpy.ma`` (15-20 ms of CPU of
    every ``pftrack recover``; :mod:`pftrack._stats`).
    """
    if not len(given):
        return np.zeros(len(keys), bool)
    order = np.sort(given)
    at = np.minimum(np.searchsorted(order, keys), len(order) - 1)
    out: NDArray[np.bool_] = order[at] == keys
    return out
