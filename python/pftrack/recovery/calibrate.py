"""The ``"auto"`` method: choose a recovery method per file and gap length, on the file itself.

Calibration cuts artificial gaps into the observed runs of consecutive frames of the file's
own tracks, with the lengths of the gaps that need filling, recovers them with every candidate
method (:data:`CANDIDATES`) and keeps, per gap-length bucket, the method with the lowest
validation MMAE (mean over gaps of the mean Euclidean error). A straight line wins ties within
:data:`LINEAR_MARGIN`: where nothing beats it clearly, the result is a straight line.

Only observed points are used: the points inside the gaps to fill are not part of the input.
The artificial gaps are drawn with a seeded generator, so the same input gives the same output.

Buckets are powers of two of the number of missing frames: ``1``, ``2``, ``3-4``, ``5-8``,
``9-16``, ... (:func:`bucket_of`).

By default (``combine=True``) a bucket may instead use a convex combination of two candidates'
paths (the chosen method and the best other one; :func:`_combine`): the weight is fitted to the
bucket's validation gaps, shrunk toward the chosen method, and the combination replaces the
chosen method only if it beats it by the same paired test. The :class:`Calibration` then
names both methods and their weights. ``combine=False`` gives the single-method choice (and
no bagging by default: averaging the resamples' choices would blend methods again).

Two rules hold whatever the rule above chooses: the real gaps are matched in a canonical order
(sorted), so the same tracks under other ids are filled alike; and a bucket whose choice does
worse than ``linear`` on its own validation gaps uses ``linear``
(:attr:`BucketChoice.replaced` keeps what it replaced).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from pftrack import _check, _core
from pftrack._check import MAX_FRAME
from pftrack._progress import progress
from pftrack._typing import F64
from pftrack.recovery.baselines import _BASELINES, RTS_HISTORY, _rts_batch
from pftrack.recovery.gdt import GdtModel
from pftrack.recovery.mixture import WINDOW, MotionFit, _fit_motion, recover_mixture_gaps
from pftrack.recovery.neighbours import (
    NB_SUFFIX,
    Neighbourhood,
    correct_by_neighbours,
)
from pftrack.recovery.noise import NoiseEstimate, _estimate_noise
from pftrack.recovery.problems import SegmentModel
from pftrack.recovery.segments import (
    as_segment,
    checked_at_once,
    distinct_runs,
    gap_ends,
    split_rows,
)

__all__ = [
    "CANDIDATES",
    "COMBINE_SHRINK",
    "GapWindows",
    "LINEAR_MARGIN",
    "MAX_CALIBRATION_GAPS",
    "BAGS",
    "RECOVER_BLOCK",
    "REGION_SQUARES",
    "WINDOW_POINTS",
    "BucketChoice",
    "Calibration",
    "bucket_of",
    "bags_for",
    "bucket_quotas",
    "calibrate",
    "fixed_noise_model",
    "gap_windows",
    "recover_auto",
    "recover_with",
]

#: Methods scored by the calibration (``"gdt-fixed"``: two-sided goal, the paper's fixed noise;
#: ``"-nb"``: corrected by the errors of the tracks seen over the same frames,
#: :mod:`pftrack.recovery.neighbours`).
CANDIDATES = ("linear", "rts", "gdt-bi", "gdt-mix", "gdt-fixed", "linear-nb", "rts-nb")
#: Linear is kept unless the best candidate's validation MMAE is lower by more than this share.
LINEAR_MARGIN = 0.01
#: A lower validation MMAE by less than this (px) is a tie, whatever the test says: rounding
#: (straight, noise-free paths where linear errs by 1e-15 px and rts by 0 chose rts).
TIE = 1e-6
#: Artificial gaps per file, shared among the buckets in proportion to their real gaps
#: (:func:`bucket_quotas`: at least MIN_VALIDATION_GAPS each, so a few more in all at most).
MAX_CALIBRATION_GAPS = 300
#: Fewer validation gaps than this in a bucket: the bucket takes the file's pooled choice.
MIN_VALIDATION_GAPS = 5
#: A method replaces the reference (linear for the file, the file's choice for a bucket) only
#: if its mean paired validation error is lower by more than this many standard errors.
PAIRED_Z = 2.0
#: Observed points kept on each side of an artificial gap, at least.
CONTEXT = 3
#: An artificial gap keeps as many observed points on each side as the real gap it matches
#: (the filters see as much history as they will on the real gap), and is placed only where
#: the run has that many, up to this bound (more would leave few places in short runs).
MAX_CONTEXT = 10
#: Random places drawn per artificial gap; the one nearest the real gap's speed is kept.
MATCH_DRAWS = 16
#: Square regions placed over the observed runs to cut artificial gaps the way the real ones
#: were made (:func:`_region_blocks`): a track is lost while it is inside a region, so its
#: lost points are those that moved in and its end points those that stayed out.
REGION_SQUARES = 2000
#: At most this many point tests for the squares (each tests the points of its band of x): on
#: big files or big squares fewer squares are laid, so the cost stays bounded (about 0.1 s in
#: the NumPy loop it was set for; the C++ kernel, which finds the points of a band in a grid,
#: takes about 10 ms there).
#: The eight test scenes need 0.1-2.3 million, the 500-track file of ``bench.recovery_file``
#: about 4.7 million (1700 squares of 2000 are laid there).
REGION_WORK = 4_000_000
#: Decimals (px) the distances between gap ends are compared at: a translated copy of a file
#: has the same differences only up to round-off, which reordered exact ties (the real gaps
#: sorted by distance, the nearest of the drawn places) and changed the choice (up to 0.23 px
#: on a translated PETS09-S2L1 with holes; a user trial).
SPAN_DECIMALS = 6
#: Noise levels and the motion model of ``"auto"`` are fitted to at most about this many
#: observed points (whole runs, drawn with the calibration's seed), so big files stay fast.
MAX_FIT_POINTS = 1000
#: Weights tried for the second method of a combination: 0, 0.05, ..., 1.
COMBINE_GRID = np.linspace(0.0, 1.0, 21)
#: A combination's fitted weight ``a`` is shrunk toward the chosen method as ``a n / (n + S)``
#: (``n`` validation gaps): a prior worth this many gaps on the chosen method alone.
COMBINE_SHRINK = 20
#: Bootstrap resamples of the validation gaps the choice is bagged over (:func:`calibrate`):
#: the rule runs on each resample and the methods' weights are averaged; 0: the rule runs once
#: on the validation gaps as drawn.
BAGS = 32
#: Points of a segment next to its gap that a method reads besides the run of consecutive
#: frames there (which the ``gdt`` filters read whole): ``rts``' history and ``gdt-mix``'s
#: window (``cubic`` and ``bspline`` read 30 and 12; ``gsi`` the whole track: :func:`gap_windows`).
WINDOW_POINTS = max(RTS_HISTORY, WINDOW)
#: Gaps :func:`recover_auto` checks and recovers at a time (the calibration sees every gap's
#: length, distance and context first): the checked copies of their segments, the methods'
#: temporaries and the ``"-nb"`` neighbours' windows are a block's, not every gap's. Was every
#: gap at once: ``fill_gaps(rows, "auto")`` peaked at 1.2 KB a row of ``tracemalloc`` on 200 170
#: rows with 39 830 holes (243 MB in ``recover_auto``: its copies 115, the neighbours' windows 130).
RECOVER_BLOCK = 2048
#: Attempts :func:`_artificial_gaps` draws at a time, at least (as many as gaps are still
#: wanted when more): where places repeat, few chunks reach the gaps wanted (was one attempt
#: per gap still wanted, a chunk each time: 62 draws for 60 gaps on PETS09-S2L1's region cuts).
DRAW_CHUNK = 1024


def bucket_of(length: int) -> int:
    """Bucket index of a gap of `length` missing frames (``1 -> 0, 2 -> 1, 3-4 -> 2, ...``)."""
    return int(length - 1).bit_length()


def _bucket_range(b: int) -> tuple[int, int]:
    return (1, 1) if b == 0 else (2 ** (b - 1) + 1, 2**b)


@dataclass(frozen=True)
class BucketChoice:
    """The choice for one gap-length bucket.

    Attributes
    ----------
    lengths : (int, int)
        Smallest and largest number of missing frames of the bucket.
    method : str
        The chosen method.
    n_gaps : int
        Gaps to fill in this bucket.
    n_validation : int
        Artificial gaps scored.
    mmae : tuple of (str, float)
        Validation MMAE (px) of each candidate, in :data:`CANDIDATES` order (empty without
        validation gaps).
    weights : tuple of (str, float)
        A combination's methods and weights (they sum to 1; `method` is then ``"a+b"``);
        empty when one method is used.
    combined_mmae : float or None
        The combination's validation MMAE (px), when one was chosen.
    replaced : (str, float) or None
        The choice the rule made (a method or ``"a+b"``) and its validation MMAE, when it did
        worse than ``linear`` on the bucket's validation gaps and ``linear`` was used instead;
        None otherwise.
    n_region : int
        Of the `n_validation` artificial gaps, those cut where a square region crosses a run
        (:attr:`Calibration.region`); the others were cut at random places.
    """

    lengths: tuple[int, int]
    method: str
    n_gaps: int
    n_validation: int
    mmae: tuple[tuple[str, float], ...]
    weights: tuple[tuple[str, float], ...] = ()
    combined_mmae: float | None = None
    replaced: tuple[str, float] | None = None
    n_region: int = 0

    @property
    def span(self) -> str:
        """The bucket's gap lengths as ``--explain`` writes them: ``"2"``, ``"3-4"``."""
        lo, hi = self.lengths
        return f"{lo}" if lo == hi else f"{lo}-{hi}"


@dataclass(frozen=True)
class Calibration:
    """What ``"auto"`` chose for one file.

    Attributes
    ----------
    buckets : tuple of BucketChoice
        One per gap-length bucket.
    pooled : str
        The file's choice (every bucket's validation gaps, weighted by its real gaps): used by
        buckets without enough validation gaps, and kept by the others unless their own best
        beats it by a paired test.
    pooled_weights : tuple of (str, float)
        With bagging (:data:`BAGS`), the file's choice as methods and weights (the share of
        resamples choosing each), used by buckets without enough validation gaps; empty when
        every resample chose :attr:`pooled` or without bagging.
    bags : int
        Bootstrap resamples the weights were averaged over (0: one choice, no bagging).
    region : float or None
        Side (px) of the square regions the artificial gaps were cut by where they could be
        (:func:`_region_blocks`; the others at random places of the runs), or None when every
        artificial gap was cut at a random place.
    """

    buckets: tuple[BucketChoice, ...]
    pooled: str = "linear"
    pooled_weights: tuple[tuple[str, float], ...] = ()
    bags: int = 0
    region: float | None = None

    def method_for(self, length: int) -> str:
        """The method chosen for a gap of `length` missing frames (:attr:`pooled` if unseen).

        A combination is named ``"a+b"`` (:meth:`weights_for` gives its weights).
        """
        lo_hi = _bucket_range(bucket_of(length))
        for c in self.buckets:
            if c.lengths == lo_hi:
                return c.method
        return "+".join(m for m, _ in self.pooled_weights) or self.pooled

    def weights_for(self, length: int) -> tuple[tuple[str, float], ...]:
        """Methods and weights (summing to 1) used for a gap of `length` missing frames."""
        lo_hi = _bucket_range(bucket_of(length))
        for c in self.buckets:
            if c.lengths == lo_hi:
                return c.weights or ((c.method, 1.0),)
        return self.pooled_weights or ((self.pooled, 1.0),)

    def __str__(self) -> str:
        """:meth:`describe`, what ``print(calibration)`` shows (``repr``: every field)."""
        return self.describe()

    def describe(self) -> str:
        """A table: per bucket, the chosen method, each candidate's validation MMAE, counts."""
        if not self.buckets:
            return "auto: no gap to fill"
        names = [m for m, _ in next((c.mmae for c in self.buckets if c.mmae), ())]
        wide = max([10] + [len(c.method) + 1 for c in self.buckets])
        head = f"{'gap length':<12}{'gaps':>6}{'val.':>6}  {'chosen':<{wide}}"
        head += "".join(f"{m:>11}" for m in names)
        over = ""
        if self.pooled_weights:  # the weights a bucket without validation gaps takes
            mix = " + ".join(f"{_weight(w)} {m}" for m, w in self.pooled_weights)
            over = f" ({mix} over {self.bags} bootstrap resamples)"
        n_val = sum(c.n_validation for c in self.buckets)
        scored = "validation MMAE (px) on artificial gaps cut into observed runs"
        if n_val == 0:  # was "(0 of 0 where a square of side ... px crosses them)"
            scored = (
                f"no validation gap could be cut: no observed run holds a gap of these lengths "
                f"with at least {CONTEXT} observed frames on each side"
            )
        elif self.region is not None:
            n_reg = sum(c.n_region for c in self.buckets)
            rest = ", the others at random places" if n_reg < n_val else ""
            scored += (
                f" ({n_reg} of {n_val} where a square of side {self.region:.3g} px crosses "
                f"them{rest})"
            )
        lines = [f"auto: {scored}; file's choice {self.pooled}{over}", head]
        for c in self.buckets:
            span = c.span
            vals = dict(c.mmae)
            cells = "".join(f"{vals[m]:>11.3f}" if m in vals else f"{'-':>11}" for m in names)
            lines.append(f"{span:<12}{c.n_gaps:>6}{c.n_validation:>6}  {c.method:<{wide}}{cells}")
        for c in self.buckets:
            span = c.span
            if c.replaced is not None:
                chosen, line = _apart(c.replaced[1], dict(c.mmae)["linear"])
                lines.append(
                    f"gap length {span}: linear, because the rule's choice {c.replaced[0]} "
                    f"(validation MMAE {chosen}) did worse than linear ({line}) on this "
                    "length's validation gaps"
                )
            if not c.mmae and not c.weights:  # was: a row naming a method, no reason
                lines.append(f"gap length {span}: {c.method}, the file's choice{_unscored(c)}")
            if c.weights:
                mix = " + ".join(f"{_weight(w)} {m}" for m, w in c.weights)
                if c.combined_mmae is None:  # no validation gaps: the file's weights
                    lines.append(  # was "the file's choice", the header naming one method
                        f"gap length {span}: combination {mix}, the file's choice over the "
                        f"resamples{_unscored(c)}"
                    )
                    continue
                lines.append(
                    f"gap length {span}: combination {mix}, validation MMAE "
                    f"{c.combined_mmae:.3f}{_blend_note(c, self.bags)}"
                )
        return "\n".join(lines)


def _unscored(c: BucketChoice) -> str:
    """Why a bucket takes the file's choice: too few validation gaps of its lengths."""
    if c.n_validation == 0:
        return " (no validation gap of this length)"
    gaps = "1 validation gap" if c.n_validation == 1 else f"{c.n_validation} validation gaps"
    return f" (only {gaps} of this length, fewer than the {MIN_VALIDATION_GAPS} a bucket needs)"


def _apart(a: float, b: float) -> tuple[str, str]:
    """`a` and `b` with 3 decimals, or as many more (up to 9) as it takes to tell them apart.

    (Was "did worse than linear ... (validation MMAE 0.019) ... (0.019)": two numbers that
    differ, said alike; a user trial.)
    """
    for digits in range(3, 10):
        x, y = f"{a:.{digits}f}", f"{b:.{digits}f}"
        if x != y:
            break
    return x, y


def _weight(w: float) -> str:
    """A blend weight as ``--explain`` prints it: 2 decimals, more when they would read 0.00."""
    return f"{w:.2f}" if round(w, 2) > 0 else f"{w:.2g}"


def _blend_note(c: BucketChoice, bags: int = 0) -> str:
    """Why a blend is used: it beat the chosen method; a better part alone did not.

    The blend is tested against the bucket's chosen method only (and shrunk toward it), not
    against every candidate, so its other part alone may score lower on the validation gaps:
    that part alone did not beat the chosen method by the paired test. With bagging (`bags`
    resamples) the weights are the mean of each resample's choice.
    """
    vals = dict(c.mmae)
    if bags > 0:
        return f"; mean of the choices on {bags} bootstrap resamples of the validation gaps"
    (chosen, _), (other, _) = c.weights
    if chosen not in vals or other not in vals or c.combined_mmae is None:
        return ""
    note = f"; beats {chosen} alone ({vals[chosen]:.3f}), the chosen method, by the paired test"
    if vals[other] <= c.combined_mmae:
        note += (
            f"; {other} alone ({vals[other]:.3f}) did not, so it is not chosen (the blend is "
            f"compared with {chosen}, not with every candidate)"
        )
    return note


def fixed_noise_model(model: GdtModel | None = None) -> SegmentModel:
    """``"gdt-fixed"``: the two-sided goal of ``gdt-bi`` with the paper's fixed noise levels.

    Nothing is estimated, so camera motion or annotation jitter cannot inflate the noise.
    """
    m = GdtModel() if model is None else model
    return SegmentModel(m.A, m.Q, m.H, m.R, m.p_init_velocity, "backward_state", True)


def recover_with(
    method: str,
    pairs: Sequence[tuple[F64, F64]],
    noise: NoiseEstimate,
    motion: MotionFit,
    hood: Neighbourhood | None = None,
    excludes: Sequence[int] | None = None,
    base_paths: Sequence[F64] | None = None,
) -> list[F64]:
    """Recover checked ``(segment_a, segment_b)`` pairs with one of :data:`CANDIDATES`.

    `hood`, `excludes` and `base_paths` are for the ``"-nb"`` methods: the observed runs whose
    errors correct each path, per pair the run not to use (default: the pairs' own segments,
    none left out), and the uncorrected method's paths if already recovered
    (:func:`~pftrack.recovery.neighbours.correct_by_neighbours`).

    Returns the ``(x, y)`` of every frame inside each gap.
    """
    if not pairs:
        return []
    if method.endswith(NB_SUFFIX) and method in CANDIDATES:
        base = method[: -len(NB_SUFFIX)]
        if hood is None:
            hood = Neighbourhood(distinct_runs([s for pair in pairs for s in pair]))

        def recover(ps: list[tuple[F64, F64]]) -> list[F64]:
            return recover_with(base, ps, noise, motion)

        return correct_by_neighbours(recover, pairs, hood, excludes, base_paths)
    if method == "linear":  # vectorised: one straight line per gap between the end points
        ends_a = np.array([a[-1, :3] for a, _ in pairs])
        ends_b = np.array([b[0, :3] for _, b in pairs])
        n = (ends_b[:, 0] - ends_a[:, 0] - 1).astype(np.int64)
        k = np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n) + 1.0
        s = (k / np.repeat(n + 1, n))[:, None]
        xy = (1.0 - s) * np.repeat(ends_a[:, 1:3], n, axis=0) + s * np.repeat(
            ends_b[:, 1:3], n, axis=0
        )
        return split_rows(xy, n)
    if method == "rts":
        return _rts_batch(pairs)
    if method in _BASELINES:
        out = []
        for a, b in pairs:
            fr = np.arange(int(a[-1, 0]) + 1, int(b[0, 0]), dtype=np.int64)
            out.append(np.asarray(_BASELINES[method](a, b, fr), dtype=np.float64)[:, :2])
        return out
    seg_a = [a for a, _ in pairs]
    seg_b = [b for _, b in pairs]
    if method == "gdt-mix":
        return recover_mixture_gaps(list(pairs), motion)
    if method == "gdt":
        return SegmentModel.paper().recover(seg_a, seg_b)
    if method == "gdt-bi":
        return SegmentModel.two_sided(noise).recover(seg_a, seg_b)
    if method == "gdt-fixed":
        return fixed_noise_model().recover(seg_a, seg_b)
    raise ValueError(f"recover_with: method is {method!r}, expected one of {CANDIDATES}")


def _fit_sample(runs: Sequence[F64], seed: int) -> list[F64]:
    """Whole runs drawn at random (seeded) until :data:`MAX_FIT_POINTS` points are reached."""
    if sum(len(r) for r in runs) <= MAX_FIT_POINTS:
        return list(runs)
    order = np.random.default_rng([seed, 999]).permutation(len(runs))
    out: list[F64] = []
    total = 0
    for i in order:
        if total >= MAX_FIT_POINTS:
            break
        out.append(runs[i])
        total += len(runs[i])
    return out


def _flat(runs: Sequence[F64]) -> tuple[NDArray[np.int64], NDArray[np.int64], F64]:
    """Lengths and offsets of the runs, and all their ``(x, y)`` stacked."""
    sizes = np.array([len(r) for r in runs], dtype=np.int64)
    offset = np.r_[0, np.cumsum(sizes)[:-1]].astype(np.int64)
    xy = np.vstack([r[:, 1:3] for r in runs]) if runs else np.zeros((0, 2))
    return sizes, offset, xy


def bucket_quotas(real_gaps: dict[int, int], max_gaps: int) -> dict[int, int]:
    """Artificial gaps to cut per bucket: `max_gaps` in proportion to its real gaps.

    The validation budget goes where the file's errors will be made: a bucket holding most
    of the gaps to fill gets most of the artificial ones. Every bucket gets at least
    :data:`MIN_VALIDATION_GAPS` (rounded shares; so the total may pass `max_gaps` by a few).
    """
    total = sum(real_gaps.values())
    if total <= 0:
        return {b: MIN_VALIDATION_GAPS for b in real_gaps}
    return {b: max(MIN_VALIDATION_GAPS, round(max_gaps * n / total)) for b, n in real_gaps.items()}


class RegionBlocks(NamedTuple):
    """Stretches of observed runs inside a square region, with observed points on both sides.

    One entry per (square, stretch): the run (an index into the runs), the stretch's first
    point in the run and its number of points. A stretch cut by several squares appears once
    per square, so drawing entries uniformly draws stretches as random squares cut them.
    """

    run: NDArray[np.int64]
    start: NDArray[np.int64]
    length: NDArray[np.int64]


def _region_blocks(
    flat: tuple[NDArray[np.int64], NDArray[np.int64], F64],
    side: float,
    rng: np.random.Generator,
    squares: int = REGION_SQUARES,
) -> RegionBlocks:
    """The stretches of the runs that `squares` random squares of `side` px leave unobserved.

    Each square is centred on a random observed point, so the squares fall where the tracks
    are, and the other tracks pass through them at every offset, grazing their edges too (a
    centre moved at random along each axis would tie the draws to the axes: swapping x and y
    would cut other gaps). Inside a square every point is lost, as a mask or an occluder
    loses them: a stretch of consecutive points inside, with a point outside it before and
    after in its run, is a gap such a region makes.
    """
    sizes, _, xy = flat
    n = len(xy)
    none = np.zeros(0, dtype=np.int64)
    if n == 0 or not side > 0:
        return RegionBlocks(none, none, none)
    centres = xy[rng.integers(n, size=squares)]
    # One C++ call (was a NumPy loop over the squares, 0.1-0.15 s on the 500-track file and
    # PETS09-S2L1; tests/reference/regions.py): each square takes the points of its band of x
    # (the points sorted by x) and of y, the distances compared rounded to SPAN_DECIMALS as the
    # spans are (a translated copy of the file, the same differences up to round-off, is cut
    # by the same squares), and their stretches with a point outside before and after; the
    # squares are laid in turn while the points in their bands of x stay within REGION_WORK.
    run, start, length = _core.region_blocks(
        np.ascontiguousarray(xy, dtype=np.float64),
        np.asarray(sizes, dtype=np.int64),
        centres,
        float(side),
        REGION_WORK,
        SPAN_DECIMALS,
    )
    return RegionBlocks(run, start, length)


def _artificial_gaps(
    runs: Sequence[F64],
    targets: Sequence[tuple[int, float] | tuple[int, float, int, int]],
    n: int,
    rng: np.random.Generator,
    flat: tuple[NDArray[np.int64], NDArray[np.int64], F64] | None = None,
    regions: RegionBlocks | None = None,
    marks: list[bool] | None = None,
) -> list[tuple[F64, F64, F64, int]]:
    """Up to `n` artificial gaps ``(segment_a, segment_b, truth, run)`` matched to `targets`.

    ``run`` is the index in `runs` of the run the gap was cut from.

    Each target is a real gap's ``(missing frames, distance between its two end points)``,
    optionally followed by its observed points before and after (``n_a, n_b``; negative:
    whole runs). Targets are taken in turn (shuffled); for each, :data:`MATCH_DRAWS` random
    places of that length are drawn from the runs and the one whose end-point distance is
    nearest the target's (in log scale) is kept, so the validation gaps have the real gaps'
    lengths and speeds. With ``n_a, n_b``, a place needs ``clip(n, CONTEXT, MAX_CONTEXT)``
    observed points on each side and the artificial segments are cut to ``n_a`` and ``n_b``
    points: the candidates see as much of the track as on the real gap.

    With `regions` (:func:`_region_blocks`), an attempt draws its places among the stretches
    square regions cut that have the target's length and room for its context, when there
    are any, and at random places of the runs otherwise; when the stretches run out (each is
    used once) before `n` gaps are cut, the rest are cut at random places. `marks` (if given)
    gets one flag per gap returned, True for a region's.
    """
    sizes, offset, xy = _flat(runs) if flat is None else flat
    out: list[tuple[F64, F64, F64, int]] = []
    used: set[tuple[int, int, int]] = set()
    places: dict[int, tuple[NDArray[np.int64], NDArray[np.int64], int]] = {}
    # per (length, context before, context after): the regions' stretches that fit
    fits: dict[tuple[int, int, int], int] = {}  # the index in `fitting` of each key's
    fitting: list[tuple[NDArray[np.int64], NDArray[np.int64]]] = []
    order = rng.permutation(len(targets)) if len(targets) else np.zeros(0, dtype=np.int64)
    # Each target's length, distance, contexts (n_a, n_b as given, ctx_a clipped), and where its
    # places are (span -1 - k: the stretches of fitting[k]; else the span of the random places)
    # with their number (0: none), worked out the first time an attempt takes the target.
    tl, ta, tb, tc, tspan, tcount = (np.zeros(len(targets), dtype=np.int64) for _ in range(6))
    td = np.zeros(len(targets), dtype=np.float64)
    seen = np.zeros(len(targets), dtype=bool)
    # The attempts (up to 4 n; the targets in turn) are drawn and matched a chunk at a time in a
    # few array operations, then taken in turn until `n` gaps are cut: an attempt's draws do not
    # depend on what the attempts before it gave, so they are those of one attempt at a time.
    # One Generator.integers call draws a chunk's MATCH_DRAWS places per attempt, each bound
    # repeated MATCH_DRAWS times: NumPy draws an array of bounds element by element as it draws
    # one bound's `size` values (Lemire's rejection on 32 bits for a bound up to 2**32), so the
    # integers are those of one call per attempt in turn (tests/recovery/test_draws.py; was a
    # call per attempt). When the gaps are cut before a chunk's last attempt, the generator is
    # set back and draws the chunk's attempts taken only: its state is theirs, as when the
    # attempts stopped. A chunk is as many attempts as gaps are still wanted, at least
    # DRAW_CHUNK (few calls where places repeat; memory bounded as one attempt per gap wanted).
    attempt, limit = 0, 4 * n if len(order) else 0
    while attempt < limit and len(out) < n:
        stop = min(limit, attempt + max(n - len(out), DRAW_CHUNK))
        tix = order[np.arange(attempt, stop) % len(order)]
        attempt = stop
        # sorted(set()), not np.unique: NumPy 2.4's unique imports numpy.ma (0.1 s), which
        # `pftrack recover` never needs (tests/test_stats.py)
        for i in sorted(set(tix[~seen[tix]].tolist())):
            t = targets[i]
            L, dist = int(t[0]), float(t[1])
            n_a, n_b = (int(t[2]), int(t[3])) if len(t) == 4 else (-1, -1)
            ctx_a = CONTEXT if n_a < 0 else min(max(n_a, CONTEXT), MAX_CONTEXT)
            ctx_b = CONTEXT if n_b < 0 else min(max(n_b, CONTEXT), MAX_CONTEXT)
            tl[i], td[i], ta[i], tb[i], tc[i], seen[i] = L, dist, n_a, n_b, ctx_a, True
            if regions is not None:
                key = (L, ctx_a, ctx_b)
                if key not in fits:
                    ok = (
                        (regions.length == L)
                        & (regions.start >= ctx_a)
                        & (regions.start + L + ctx_b <= sizes[regions.run])
                    )
                    fits[key] = len(fitting)
                    fitting.append((regions.run[ok], regions.start[ok]))
                if len(fitting[fits[key]][0]):
                    tspan[i], tcount[i] = -1 - fits[key], len(fitting[fits[key]][0])
                    continue
            span = L + ctx_a + ctx_b  # the places depend on it only: computed once per span
            if span not in places:
                slots_of = np.maximum(sizes - span + 1, 0)
                cum_of = np.cumsum(slots_of)
                places[span] = (slots_of, cum_of, int(cum_of[-1]) if len(cum_of) else 0)
            tspan[i], tcount[i] = span, places[span][2]
        tix = tix[tcount[tix] > 0]  # an attempt without any place draws nothing
        k = len(tix)
        if not k:
            continue
        before = rng.bit_generator.state
        draws = rng.integers(np.repeat(tcount[tix], MATCH_DRAWS)).reshape(k, MATCH_DRAWS)
        idx = np.zeros((k, MATCH_DRAWS), dtype=np.int64)
        starts = np.zeros((k, MATCH_DRAWS), dtype=np.int64)
        spans = tspan[tix]
        for span in set(spans.tolist()):  # each row as its own attempt computed it
            rows = np.flatnonzero(spans == span)
            ks = draws[rows]
            if span < 0:  # a region's stretches: the run and start of each drawn entry
                run_r, start_r = fitting[-1 - span]
                idx[rows], starts[rows] = run_r[ks], start_r[ks]
                continue
            slots, cum, _ = places[span]
            got = np.searchsorted(cum, ks, side="right")
            idx[rows] = got
            starts[rows] = tc[tix[rows]][:, None] + ks - (cum[got] - slots[got])
        # the draw whose end-point distance is nearest the target's (the first when no target)
        near = np.zeros(k, dtype=np.int64)
        aim = np.flatnonzero(td[tix] >= 0)
        if len(aim):
            L_of = tl[tix[aim]][:, None]
            at = offset[idx[aim]] + starts[aim]
            gap = xy[at + L_of] - xy[at - 1]  # (rows, MATCH_DRAWS, 2)
            d = np.round(np.hypot(gap[..., 0], gap[..., 1]), SPAN_DECIMALS)
            log_dist = np.log1p(td[tix[aim]])[:, None]
            near[aim] = np.argmin(np.abs(np.log1p(d) - log_dist), axis=1)
        chosen = zip(
            tl[tix].tolist(),
            ta[tix].tolist(),
            tb[tix].tolist(),
            idx[np.arange(k), near].tolist(),
            starts[np.arange(k), near].tolist(),
            (spans < 0).tolist(),
            strict=True,
        )
        taken = k
        for row, (L, n_a, n_b, i, st, by_region) in enumerate(chosen):
            if len(out) >= n:
                taken = row
                break
            if (i, st, L) in used:
                continue
            used.add((i, st, L))
            r = runs[i]
            lo = 0 if n_a < 0 else max(0, st - n_a)
            hi = len(r) if n_b < 0 else st + L + n_b
            out.append((r[lo:st], r[st + L : hi], r[st : st + L], i))
            if marks is not None:
                marks.append(by_region)
        if taken < k:  # the attempts after the n-th gap were never made: their draws undone
            rng.bit_generator.state = before
            rng.integers(np.repeat(tcount[tix[:taken]], MATCH_DRAWS))
    if regions is not None and len(out) < n:
        # the regions' stretches ran out (each is used once): the rest at random places
        for seg_a, seg_b, lost, k in _artificial_gaps(runs, targets, 4 * (n - len(out)), rng, flat):
            st = int(np.searchsorted(runs[k][:, 0], lost[0, 0]))
            if len(out) >= n or (k, st, len(lost)) in used:
                continue
            used.add((k, st, len(lost)))
            out.append((seg_a, seg_b, lost, k))
            if marks is not None:
                marks.append(False)
    return out


def _rank_z(x: F64, y: F64) -> float:
    """One-sided Mann-Whitney statistic that `x` tends to be larger than `y`, in standard errors.

    ``(U - n_x n_y / 2) / sd(U)`` with ``U`` from mid-ranks (tied values share their ranks) and
    the normal approximation's tie-corrected variance
    ``n_x n_y / 12 * (n + 1 - sum(t^3 - t) / (n (n - 1)))``, ``t`` the sizes of the groups of
    equal values (the ``z`` of ``scipy.stats.mannwhitneyu(x, y, alternative="greater",
    method="asymptotic", use_continuity=False)``). Without the correction the variance is too
    large where end-point distances repeat, and the test too timid.
    0 when there is nothing to rank: an empty sample, or every value equal.
    """
    n1, n2 = len(x), len(y)
    n = n1 + n2
    if n1 == 0 or n2 == 0:
        return 0.0
    _, inv, counts = np.unique(np.concatenate([x, y]), return_inverse=True, return_counts=True)
    first = np.r_[0, np.cumsum(counts)[:-1]]
    ranks = (first + (counts + 1) / 2.0)[inv]  # mid-ranks, ties shared
    u = float(ranks[:n1].sum()) - n1 * (n1 + 1) / 2.0
    ties = float((counts.astype(np.float64) ** 3 - counts).sum())
    var = n1 * n2 / 12.0 * ((n + 1) - ties / (n * (n - 1)))
    if not var > 0:
        return 0.0
    return (u - n1 * n2 / 2.0) / math.sqrt(var)


def _matched_weights(
    cut: Sequence[tuple[F64, F64, F64, int]],
    targets: Sequence[tuple[int, float, int, int]],
) -> F64 | None:
    """Weights of a bucket's validation gaps when the real gaps are faster than they are.

    The artificial gaps are matched to the real gaps' end-point distances by the nearest of
    :data:`MATCH_DRAWS` random places, each place used once. Where the file holds few places
    as fast as the real gaps (KITTI-17's pedestrians passing the car at the image's edge),
    those are used up and the bucket fills with slower places, which rate the methods for
    slower motion. When a one-sided rank test (Mann-Whitney, normal approximation) says the
    real gaps' distances are larger than the validation gaps' by more than :data:`PAIRED_Z`
    standard errors (:func:`_rank_z`), each real gap takes the ``ceil(n / n_real)`` validation
    gaps nearest to it (``|log(1 + d) - log(1 + d_real)| + |log(L + 1) - log(L_real + 1)|``)
    and a validation gap's weight is the number of real gaps that took it. None otherwise
    (every gap alike).
    """
    if not cut or not targets or any(t[1] < 0 for t in targets):
        return None
    dv = np.array(
        [np.round(np.hypot(*(b[0, 1:3] - a[-1, 1:3])), SPAN_DECIMALS) for a, b, _, _ in cut]
    )
    lv = np.array([len(t) for _, _, t, _ in cut], dtype=np.float64)
    val = np.log1p(dv)
    n1, n2 = len(targets), len(val)
    if _rank_z(np.log1p(np.array([t[1] for t in targets])), val) <= PAIRED_Z:
        return None
    k = math.ceil(n2 / n1)
    count = np.zeros(n2)
    for length, dist, _, _ in targets:
        far = np.abs(val - np.log1p(dist)) + np.abs(np.log(lv + 1) - math.log(length + 1))
        count[np.argsort(far, kind="stable")[:k]] += 1
    out: F64 = count / count.sum()
    return out


def calibrate(
    observed: Sequence[F64],
    gap_lengths: Sequence[int],
    noise: NoiseEstimate | None = None,
    motion: MotionFit | None = None,
    *,
    candidates: Sequence[str] = CANDIDATES,
    max_gaps: int = MAX_CALIBRATION_GAPS,
    seed: int = 0,
    spans: Sequence[float] | None = None,
    contexts: Sequence[tuple[int, int]] | None = None,
    combine: bool = True,
    bags: int | None = None,
    regions: bool = True,
) -> Calibration:
    """Choose a method per gap-length bucket by recovering artificial gaps of observed runs.

    Parameters
    ----------
    observed : sequence of (k, 3+) ndarray
        Observed rows ``(frame, x, y, ...)`` of the file's tracks (runs of consecutive frames
        are used; duplicates are counted once).
    gap_lengths : sequence of int
        Missing frames of every gap to fill (each >= 1).
    noise, motion : optional
        For ``"gdt-bi"`` and ``"gdt-mix"``: default estimated from `observed`.
    candidates : sequence of str
        Methods scored (some of :data:`CANDIDATES`; ``"linear"`` is always added).
    max_gaps : int
        Artificial gaps in all (>= 1), shared among the buckets in proportion to their gaps
        (:func:`bucket_quotas`; a bucket gets at least :data:`MIN_VALIDATION_GAPS`).
    seed : int
        Seed of the generator that places the artificial gaps.
    spans : sequence of float, optional
        Distance (px) between the two end points of each gap in `gap_lengths`: artificial
        gaps are matched to it (default: no matching, any place of the right length).
    contexts : sequence of (int, int), optional
        Observed points before and after each gap (each >= 1): artificial gaps keep as many
        (:func:`_artificial_gaps`; default: the whole run on each side).
    combine : bool
        Let a bucket use a convex combination of its chosen method and the best other
        candidate when it beats the chosen method by the paired test (:func:`_combine`;
        default). False: one method per bucket (then `bags` is 0).
    bags : int or None
        Bootstrap resamples of each bucket's validation gaps (>= 0, seeded by `seed`): the
        choice (file, bucket, combination) is made on each and the methods' weights are
        averaged, which blends the methods different resamples chose. A bucket whose real
        gaps a rank test finds faster than its validation gaps draws them by nearness to the
        real gaps (:func:`_matched_weights`), and its floor at ``linear`` is weighted alike.
        0: one choice on the validation gaps as drawn. None (default): :data:`BAGS` with
        `combine`, 0 without (:func:`bags_for`; more than 0 with ``combine=False`` is
        refused).
    regions : bool
        With `spans`, cut the artificial gaps where possible as the real gaps of a masked or
        occluded region are made: :data:`REGION_SQUARES` random squares whose side is the
        longest of `spans` (a region that holds every real gap's end points) are laid over
        the runs, and a validation gap of a given length is a stretch of that many points
        inside a square (:func:`_region_blocks`). So its lost points are those that moved
        into the region and its end points those that stayed out, which a random place does
        not reproduce. Lengths no square cuts are cut at random places. Default True; False
        (or no `spans`): random places only (for signals that are not image positions, such
        as box sizes).

    Returns
    -------
    Calibration

    Raises
    ------
    TypeError
        A `seed`, gap length, context, `max_gaps` or `bags` that is not an int, a `combine`
        that is not a bool, `observed` that is not a sequence of arrays of real numbers.
    ValueError
        A gap length or context that is not an integer >= 1, `max_gaps` not an integer >= 1,
        `bags` not None or an integer >= 0 (or > 0 with ``combine=False``), a negative `seed`,
        an unknown candidate, non-finite `spans`, `spans` / `contexts` of another length than
        `gap_lengths`, an observed run that is not (k, 3+) or has a non-finite frame, x or y.
    """
    lengths = [_check.integer(v, "calibrate: a gap length", 1, MAX_FRAME) for v in gap_lengths]
    combine = _check.flag(combine, "calibrate: combine")
    regions = _check.flag(regions, "calibrate: regions")
    max_gaps, bags, seed = _settings("calibrate", max_gaps, bags, seed, combine)
    for m in candidates:
        _check.option(m, "calibrate: candidate", CANDIDATES)
        if m not in CANDIDATES:
            raise ValueError(f"calibrate: candidate {m!r} is not one of {CANDIDATES}")
    names = tuple(m for m in CANDIDATES if m in candidates or m == "linear")
    dists = [-1.0] * len(lengths) if spans is None else [float(v) for v in spans]
    if not all(math.isfinite(v) for v in dists):
        raise ValueError(f"calibrate: spans must be finite, got {dists}")
    if len(dists) != len(lengths):
        raise ValueError(f"calibrate: {len(dists)} spans for {len(lengths)} gap lengths")
    sides = (
        [(-1, -1)] * len(lengths)
        if contexts is None
        else [
            (
                _check.integer(a, "calibrate: a context", 1, MAX_FRAME),
                _check.integer(b, "calibrate: a context", 1, MAX_FRAME),
            )
            for a, b in contexts
        ]
    )
    if len(sides) != len(lengths):
        raise ValueError(f"calibrate: {len(sides)} contexts for {len(lengths)} gap lengths")
    by_bucket: dict[int, list[int]] = {}
    targets: dict[int, list[tuple[int, float, int, int]]] = {}
    for v, dv, (na, nb) in zip(lengths, dists, sides, strict=True):
        by_bucket.setdefault(bucket_of(v), []).append(v)
        targets.setdefault(bucket_of(v), []).append((v, float(np.round(dv, SPAN_DECIMALS)), na, nb))
    for t in targets.values():  # the gaps' order (the file's id order) must not matter
        t.sort()
    if not by_bucket:
        return Calibration(())
    # recover_auto's runs are distinct_runs' already (they would come back the same)
    runs = (
        observed
        if isinstance(observed, _DistinctRuns)
        else distinct_runs(observed, strict="calibrate")
    )
    whole = _fit_sample([r for r in runs if len(r) >= 4], seed)
    if noise is None and ("gdt-bi" in names or "gdt-mix" in names):
        noise = _estimate_noise(whole) if whole else None
    if motion is None and "gdt-mix" in names and whole:
        motion = _fit_motion(whole, noise)
    quota = bucket_quotas({b: len(v) for b, v in by_bucket.items()}, max_gaps)
    scored = [
        m
        for m in names
        if (m != "gdt-bi" or noise is not None) and (m != "gdt-mix" or motion is not None)
    ]
    errors: dict[int, dict[str, F64]] = {}
    found: dict[int, dict[str, list[F64]]] = {}
    truths: dict[int, list[F64]] = {}
    n_cut: dict[int, int] = {}
    flat = _flat(runs)
    hood = Neighbourhood(runs) if any(m.endswith(NB_SUFFIX) for m in scored) else None
    cuts: dict[int, list[tuple[F64, F64, F64, int]]] = {}
    # the square regions' side: the longest distance between a real gap's two end points
    side = round(max(dists), SPAN_DECIMALS) if regions and spans is not None and dists else None
    blocks = (
        _region_blocks(flat, side, np.random.default_rng([seed, 0x5E6]))
        if side is not None and side > 0
        else None
    )
    n_region: dict[int, int] = {}
    for b in sorted(by_bucket):
        rng = np.random.default_rng([seed, b])
        marks: list[bool] = []
        cut = _artificial_gaps(runs, targets[b], quota[b], rng, flat, blocks, marks)
        n_cut[b] = len(cut)
        n_region[b] = sum(marks)
        if len(cut) >= MIN_VALIDATION_GAPS:
            cuts[b] = cut
    # Every candidate recovers the validation gaps of every bucket in one call (one C++ call,
    # threads over all of them): each gap is recovered on its own, so its path is the one a
    # call per bucket gave (was: a call per bucket and method, 4 buckets on PETS09-S2L1).
    pairs = [(a, c) for cut in cuts.values() for a, c, _, _ in cut]
    cut_from = [i for cut in cuts.values() for _, _, _, i in cut]
    every: dict[str, list[F64]] = {}
    for m in progress(scored if pairs else [], desc="auto: calibrating", unit="method"):
        # a "-nb" method corrects its base's paths, scored before it
        base = every.get(m.removesuffix(NB_SUFFIX)) if m.endswith(NB_SUFFIX) else None
        every[m] = recover_with(
            m, pairs, noise or _NO_NOISE, motion or _NO_MOTION, hood, cut_from, base
        )
    at = 0
    for b, cut in cuts.items():
        truth = [t for _, _, t, _ in cut]
        errors[b] = {}
        found[b] = {}
        truths[b] = truth
        for m in scored:
            paths = every[m][at : at + len(cut)]
            errors[b][m] = _gap_errors(paths, truth)
            found[b][m] = paths
        at += len(cut)
    weights = {b: len(by_bucket[b]) for b in errors}
    blends = _Blends(found, truths)
    stacked = {b: np.stack([errors[b][m] for m in scored]) for b in errors}
    pooled, chosen = _choose(stacked, weights, scored, combine, blends)
    pooled_mix: tuple[tuple[str, float], ...] = ()
    # buckets whose real gaps are faster than their validation gaps: resampled by nearness
    near = {b: p for b, cut in cuts.items() if (p := _matched_weights(cut, targets[b])) is not None}
    if bags > 0:
        rng = np.random.default_rng([seed, 0xBA6])
        runs_of = []
        for _ in range(bags):
            idx = {
                b: (
                    rng.choice(len(truths[b]), size=len(truths[b]), p=near[b])
                    if b in near
                    else rng.integers(len(truths[b]), size=len(truths[b]))
                )
                for b in sorted(errors)
            }
            runs_of.append(_choose(stacked, weights, scored, combine, blends, idx))
        pooled_mix = _average([((p, 1.0),) for p, _ in runs_of])
        chosen = {b: _average([c[b] for _, c in runs_of]) for b in errors}
    choices = []
    for b in sorted(by_bucket):
        mmae: tuple[tuple[str, float], ...] = ()
        replaced: tuple[str, float] | None = None
        mixed: float | None = None  # the choice's validation MMAE
        mix = chosen.get(b, pooled_mix or ((pooled, 1.0),))
        if b in errors:
            mmae = tuple((m, float(errors[b][m].mean())) for m in scored)
            mixed = (
                dict(mmae)[mix[0][0]]
                if len(mix) == 1
                else float(_mix_errors(mix, found[b], truths[b]).mean())
            )
            # never worse than a straight line on the bucket's own validation gaps (weighted
            # by nearness where the real gaps are faster than them)
            w_b = near.get(b)
            worse = (
                mixed > errors[b]["linear"].mean()
                if w_b is None
                else float(np.average(_mix_errors(mix, found[b], truths[b]), weights=w_b))
                > float(np.average(errors[b]["linear"], weights=w_b))
            )
            if worse:
                replaced = ("+".join(m for m, _ in mix), mixed)
                mix = (("linear", 1.0),)
        span = _bucket_range(b)
        if len(mix) == 1:
            choices.append(
                BucketChoice(
                    span,
                    mix[0][0],
                    len(by_bucket[b]),
                    n_cut[b],
                    mmae,
                    replaced=replaced,
                    n_region=n_region[b],
                )
            )
            continue
        name = "+".join(m for m, _ in mix)
        choices.append(
            BucketChoice(
                span, name, len(by_bucket[b]), n_cut[b], mmae, mix, mixed, n_region=n_region[b]
            )
        )
    return Calibration(
        tuple(choices),
        pooled,
        pooled_mix if len(pooled_mix) > 1 else (),
        bags,
        None if blocks is None or side is None else side,
    )


class _Blends:
    """Per-gap validation errors of ``(1 - w) first + w second``, cached per bucket and pair.

    For a bucket of `n` validation gaps, row ``k`` of ``blends(b, first, second)`` holds the
    errors with the weight ``COMBINE_GRID[k]``, and ``blends.shrunk(b, first, second, k)``
    those with that weight shrunk as in :func:`_combine` (only the row of the fitted weight is
    ever needed: computed when asked), so a resample of the gaps (same `n`) only indexes
    columns.
    """

    def __init__(self, found: dict[int, dict[str, list[F64]]], truths: dict[int, list[F64]]):
        self.found = found
        self.truths = truths
        self.cache: dict[tuple[int, str, str], F64] = {}
        self.rows: dict[tuple[int, str, str, int], F64] = {}
        self.inputs: dict[
            tuple[int, str, str], tuple[tuple[F64, ...], NDArray[np.int64], NDArray[np.int64]]
        ] = {}

    def _errors(self, b: int, first: str, second: str, w: F64) -> F64:
        """Rows of per-gap errors, one per weight of `w`."""
        key = (b, first, second)
        if key not in self.inputs:
            truth = self.truths[b]
            sizes = np.array([len(v) for v in truth])
            p1 = np.concatenate(self.found[b][first])
            p2 = np.concatenate(self.found[b][second])
            t = np.concatenate([v[:, 1:3] for v in truth])
            self.inputs[key] = (  # x and y apart: contiguous rows below
                tuple(np.ascontiguousarray(a[:, i]) for a in (p1, p2, t) for i in (0, 1)),
                np.r_[0, np.cumsum(sizes)[:-1]],
                sizes,
            )
        (x1, y1, x2, y2, xt, yt), starts, sizes = self.inputs[key]
        # every weight at once, (weights, points): the same operations per element as one
        # weight at a time; the sums per gap stay one 1-D reduceat per weight
        a, c = (1.0 - w)[:, None], w[:, None]
        dist = np.hypot(a * x1 + c * x2 - xt, a * y1 + c * y2 - yt)
        out: F64 = np.array([np.add.reduceat(row, starts) for row in dist]) / sizes
        return out

    def __call__(self, b: int, first: str, second: str) -> F64:
        key = (b, first, second)
        if key not in self.cache:
            self.cache[key] = self._errors(b, first, second, COMBINE_GRID)
        return self.cache[key]

    def shrunk(self, b: int, first: str, second: str, k: int) -> F64:
        """Errors with the weight ``COMBINE_GRID[k]`` shrunk as in :func:`_combine`."""
        key = (b, first, second, k)
        if key not in self.rows:
            n = len(self.truths[b])
            w = float(COMBINE_GRID[k]) * (n / (n + COMBINE_SHRINK))
            self.rows[key] = self._errors(b, first, second, np.array([w]))[0]
        return self.rows[key]

    def fit(
        self, b: int, first: str, second: str, idx: NDArray[np.int64] | None = None
    ) -> tuple[float, F64]:
        """The shrunk weight of `second` and the per-gap errors it gives (:func:`_combine`).

        On the validation gaps `idx` of bucket `b` (a resample, with repeats; None: all).
        """
        fit = self(b, first, second)
        if idx is not None:
            fit = fit[:, idx]
        k = int(np.argmin(fit.mean(axis=1)))  # the first of equal minima, as min() takes it
        w = float(COMBINE_GRID[k]) * fit.shape[1] / (fit.shape[1] + COMBINE_SHRINK)
        err = self.shrunk(b, first, second, k)
        return w, err if idx is None else err[idx]


def _choose(
    stacked: dict[int, F64],
    weights: dict[int, int],
    names: Sequence[str],
    combine: bool,
    blends: _Blends,
    idx: dict[int, NDArray[np.int64]] | None = None,
) -> tuple[str, dict[int, tuple[tuple[str, float], ...]]]:
    """The file's choice and, per bucket with validation gaps, its methods and weights.

    `stacked` holds, per bucket, the validation errors of `names` (one row each, one column
    per gap); `idx` (optional), per bucket, the validation gaps to use (a resample, with
    repeats).
    """
    if idx is not None:
        stacked = {b: v[:, idx[b]] for b, v in stacked.items()}
    errors = {b: dict(zip(names, v, strict=True)) for b, v in stacked.items()}
    # every row's mean as row.mean() gives it (one pairwise sum per row of a C-contiguous
    # copy: `stacked` is not, after the resample), once for the pooled choice and the tests
    row_means = {
        b: dict(zip(names, np.ascontiguousarray(v).mean(axis=1).tolist(), strict=True))
        for b, v in stacked.items()
    }
    pooled = _pooled_choice(errors, weights, names, row_means)
    out: dict[int, tuple[tuple[str, float], ...]] = {}
    for b, e in errors.items():
        means = row_means[b]
        method = pooled
        best = min(names, key=lambda m: means[m])
        if best != pooled and _better(e[best], e[pooled], row_means[b][pooled]):
            method = best
        out[b] = ((method, 1.0),)
        if combine and len(names) > 1:
            other = min((m for m in names if m != method), key=lambda m: means[m])
            w, err = blends.fit(b, method, other, None if idx is None else idx[b])
            if 0.0 < w and _better(err, e[method], row_means[b][method]):
                out[b] = ((method, 1.0 - w), (other, w))
    return pooled, out


def _average(
    mixes: Sequence[tuple[tuple[str, float], ...]],
) -> tuple[tuple[str, float], ...]:
    """Mean weight of every method over `mixes`, heaviest first (ties: in order of appearance)."""
    total: dict[str, float] = {}
    for mix in mixes:
        for m, w in mix:
            total[m] = total.get(m, 0.0) + w / len(mixes)
    kept = [(m, w) for m, w in total.items() if w > 0.0]
    kept.sort(key=lambda mw: -mw[1])
    return tuple(kept)


def _mix_errors(
    mix: tuple[tuple[str, float], ...], found: dict[str, list[F64]], truth: Sequence[F64]
) -> F64:
    """Per-gap validation errors of the weighted sum of the methods' paths."""
    paths = [np.sum([w * found[m][k] for m, w in mix], axis=0) for k in range(len(truth))]
    return _gap_errors(paths, truth)


def _combine(
    first: Sequence[F64], second: Sequence[F64], truth: Sequence[F64]
) -> tuple[float, F64]:
    """Weight of `second` in ``(1 - w) first + w second`` and the per-gap errors it gives.

    `w` minimises the validation MMAE over :data:`COMBINE_GRID` and is then shrunk toward 0
    (`first` alone) as ``w n / (n + COMBINE_SHRINK)`` for `n` validation gaps, so few gaps
    give a combination close to the chosen method. (:meth:`_Blends.fit` on one bucket: the
    rule :func:`calibrate` applies.)
    """
    return _Blends({0: {"a": list(first), "b": list(second)}}, {0: list(truth)}).fit(0, "a", "b")


def _gap_errors(paths: Sequence[F64], truth: Sequence[F64]) -> F64:
    """Mean Euclidean error of each gap's path against its truth (rows ``frame, x, y``)."""
    n = np.array([len(t) for t in truth])
    d = np.concatenate(paths) - np.concatenate([t[:, 1:3] for t in truth])
    out: F64 = np.add.reduceat(np.hypot(d[:, 0], d[:, 1]), np.r_[0, np.cumsum(n)[:-1]]) / n
    return out


def _better(cand: F64, ref: F64, ref_mean: float) -> bool:
    """`cand` beats `ref` on the same validation gaps: a paired test and the margin.

    `ref_mean` is ``float(ref.mean())``, which the caller has already.
    """
    d = cand - ref
    se = float(np.std(d, ddof=1)) / np.sqrt(len(d)) if len(d) > 1 else np.inf
    mean = float(d.mean())
    return mean < -PAIRED_Z * se and mean < -max(LINEAR_MARGIN * ref_mean, TIE)


def _pooled_choice(
    errors: dict[int, dict[str, F64]],
    weights: dict[int, int],
    names: Sequence[str],
    means: dict[int, dict[str, float]],
) -> str:
    """The file's method: validation MMAE of every bucket weighted by its real gaps.

    ``"linear"`` unless the best beats it by :data:`LINEAR_MARGIN` and :data:`PAIRED_Z`
    standard errors of the weighted paired difference. `means` holds
    ``float(errors[b][m].mean())`` of every bucket and method (each computed once).
    """
    if not errors:
        return "linear"
    total = float(sum(weights.values()))
    w = {b: weights[b] / total for b in errors}

    def score(m: str) -> float:
        return sum(w[b] * means[b][m] for b in errors)

    best = min(names, key=score)
    if best == "linear":
        return "linear"
    diff = sum(w[b] * float((errors[b][best] - errors[b]["linear"]).mean()) for b in errors)
    var = sum(
        w[b] ** 2
        * float(np.var(errors[b][best] - errors[b]["linear"], ddof=1))
        / len(errors[b][best])
        for b in errors
    )
    if diff < -PAIRED_Z * np.sqrt(var) and diff < -max(LINEAR_MARGIN * score("linear"), TIE):
        return best
    return "linear"


class _DistinctRuns(list[F64]):
    """Runs :func:`~pftrack.recovery.segments.distinct_runs` gave, as :func:`recover_auto` has them.

    :func:`calibrate` takes them as they are: they would come back the same (splitting them
    again cost 3 ms a call on a file of 500 tracks).
    """


# Placeholders that are never used (the methods needing them are skipped without them).
_NO_NOISE = NoiseEstimate(q=(0.1, 0.1), r=(1.0, 1.0))
_NO_MOTION: MotionFit = None  # type: ignore[assignment]


def bags_for(bags: object, combine: bool, who: str) -> int:
    """The bootstrap resamples of a calibration: `bags` checked, or its default for `combine`.

    None gives :data:`BAGS` with `combine` and 0 without: bagging averages the methods the
    resamples chose, a blend, so one method per bucket (``combine=False``) means no bagging.

    Raises
    ------
    ValueError
        `bags` not None or an integer in ``0..10000``, or more than 0 with ``combine=False``;
        the message starts with `who` (the function called, e.g. ``"fill_gaps"``).
    """
    if bags is None:
        return BAGS if combine else 0
    n = _check.integer(bags, f"{who}: bags", 0, 10**4)
    if n and not combine:
        raise ValueError(
            f"{who}: bags is {n} with combine=False: bagging averages the methods the "
            "resamples choose (a blend), combine=False is one method per bucket; pass bags=0 "
            "or None with combine=False"
        )
    return n


class GapWindows(NamedTuple):
    """The holes of tracks and the rows around each that the recovery methods read.

    Indices into the rows given to :func:`gap_windows`, one entry per hole: hole ``j`` lies
    after row ``holes[j]``, in the track of rows ``first[j] : end[j]``; its segments may be cut
    to rows ``lo[j] : holes[j] + 1`` and ``holes[j] + 1 : hi[j]``.
    """

    holes: NDArray[np.int64]
    lo: NDArray[np.int64]
    hi: NDArray[np.int64]
    first: NDArray[np.int64]
    end: NDArray[np.int64]


def gap_windows(frames: NDArray[np.float64], ids: NDArray[np.float64] | None = None) -> GapWindows:
    """Every hole of the tracks and the rows of its segments the recovery methods read.

    A window holds the run of consecutive frames next to the hole on each side and at least
    :data:`WINDOW_POINTS` points (fewer where the track has fewer): all that any method but
    ``gsi`` reads of a gap's segments, and for ``"auto"`` all but their lengths, which the
    calibration and the ``"-nb"`` windows read and which go as `contexts` to
    :func:`recover_auto`. So the segments of a
    track with many holes hold about its length plus ``2 WINDOW_POINTS`` points per hole in
    all, not its length per hole (``fill_gaps`` on one track of 8000 holes took 4 GB with
    whole segments).

    Parameters
    ----------
    frames : (n,) ndarray
        Frames of one track, increasing strictly, or of several tracks one after the other.
    ids : (n,) ndarray, optional
        The track of each row (rows of a track together), for several tracks.

    Returns
    -------
    GapWindows
        The holes of every track (of any length), their windows and their tracks' rows.
    """
    n = len(frames)
    step = np.diff(frames)
    same = np.ones(max(n - 1, 0), dtype=bool) if ids is None else ids[1:] == ids[:-1]
    bounds = np.flatnonzero((step != 1) | ~same)  # the last row of each run but the last run
    k = np.flatnonzero((step[bounds] > 1) & same[bounds])
    holes = bounds[k]
    prev = np.r_[-1, bounds][k]  # the last row before the run that ends at each hole
    after = np.r_[bounds, n - 1][k + 1]  # the last row of the run that starts after it
    starts = np.flatnonzero(np.r_[True, ~same])  # every track's first row
    t = np.searchsorted(starts, holes, side="right") - 1
    first, end = starts[t], np.r_[starts[1:], n][t]
    lo = np.maximum(first, np.minimum(holes + 1 - WINDOW_POINTS, prev + 1))
    hi = np.minimum(end, np.maximum(holes + 1 + WINDOW_POINTS, after + 1))
    i64 = np.int64
    return GapWindows(
        holes.astype(i64), lo.astype(i64), hi.astype(i64), first.astype(i64), end.astype(i64)
    )


def _settings(
    who: str, max_gaps: object, bags: object, seed: object, combine: bool
) -> tuple[int, int, int]:
    """`max_gaps`, `bags` (:func:`bags_for`) and `seed` checked, or an error naming the one."""
    return (
        _check.integer(max_gaps, f"{who}: max_gaps", 1, 10**7),
        bags_for(bags, combine, who),
        _check.seed(seed, f"{who}: seed"),
    )


def recover_auto(
    pairs: Sequence[tuple[F64, F64]],
    observed: Sequence[F64] | None = None,
    noise: NoiseEstimate | None = None,
    motion: MotionFit | None = None,
    *,
    seed: int = 0,
    candidates: Sequence[str] = CANDIDATES,
    max_gaps: int = MAX_CALIBRATION_GAPS,
    combine: bool = True,
    bags: int | None = None,
    contexts: Sequence[tuple[int, int]] | None = None,
    regions: bool = True,
    _checked: bool = False,
) -> tuple[list[F64], Calibration]:
    """Recover every gap with the method :func:`calibrate` chose for its length.

    Parameters
    ----------
    pairs : sequence of (segment_a, segment_b)
        Segments around each gap (rows ``frame, x, y[, w, h]``), read :data:`RECOVER_BLOCK`
        gaps at a time (sliced), twice: each block is checked as the calibration reads every
        gap's length, distance and context, then read again (not checked again: with
        `observed`, the checked copies are a block's at a time) and recovered.
    observed : sequence of (k, 3+) ndarray, optional
        Every observed track of the file, for calibration; default: the segments of `pairs`.
    noise, motion : optional
        For ``"gdt-bi"`` and ``"gdt-mix"``: default estimated from the observed runs (at most
        about :data:`MAX_FIT_POINTS` points of them).
    seed : int
        Seed of the calibration.
    candidates : sequence of str
        Methods scored (some of :data:`CANDIDATES`; ``"linear"`` is always added). Without
        ``"gdt-mix"`` no motion model is fitted, without ``"gdt-bi"`` no noise levels.
    max_gaps : int
        At most this many artificial gaps (:func:`calibrate`).
    combine : bool
        Allow a convex combination of two candidates per bucket (:func:`calibrate`; default).
        False: one method per bucket.
    bags : int or None
        Bootstrap resamples the choice is averaged over (:func:`calibrate`; >= 0). None
        (default): :data:`BAGS` with `combine`, 0 without (:func:`bags_for`).
    contexts : sequence of (int, int), optional
        Observed points before and after each gap in its track, when `pairs` hold only the
        points next to the gaps that the candidates read (:func:`gap_windows`; the artificial
        gaps keep as many, :func:`calibrate`); default: the segments' lengths. With it, pass
        `observed`: the calibration runs on the whole tracks, not on the windows.
    regions : bool
        Cut the artificial gaps by square regions where possible (:func:`calibrate`;
        default). False for signals that are not image positions (``fill_gaps`` passes it for
        box sizes).

    Returns
    -------
    paths : list of (T_g - 1, 2) ndarray
        ``(x, y)`` of every frame inside each gap.
    calibration : Calibration
        What was chosen, and why.

    Raises
    ------
    TypeError
        A `seed` that is not an int, a `combine` that is not a bool, `observed` that is not a
        sequence of arrays of real numbers.
    ValueError
        Malformed segments, a segment B that does not start after its segment A or a gap
        of more than :data:`~pftrack.recovery.segments.MAX_GAP_LIMIT` frames (as
        ``recover_gaps``), settings :func:`calibrate` refuses, an observed run that is not
        (k, 3+) or has a non-finite frame, x or y, `contexts` of another length than `pairs`.

    Notes
    -----
    ``recover_gaps(..., "auto")`` passes the private ``_checked=True``: its pairs are
    already checked (``registry._checked_pairs``, C-contiguous float64 ``(k, 3|5)``), so the
    first pass only takes their ``frame, x, y`` (:func:`_read_block`; was a second check of
    every block, :func:`_checked_block`).
    """
    combine = _check.flag(combine, "recover_auto: combine")
    _, bags, seed = _settings("recover_auto", max_gaps, bags, seed, combine)
    if not isinstance(pairs, Sequence):
        pairs = list(pairs)
    n_pairs = len(pairs)
    if contexts is not None and len(contexts) != n_pairs:
        raise ValueError(f"recover_auto: {len(contexts)} contexts for {n_pairs} pairs")
    # First pass, a block of gaps at a time: each gap checked (the only time), its length, the
    # distance between its ends and its context kept (numbers; the checked copies of a block
    # are dropped, unless the segments are also what the calibration observes)
    lengths: list[int] = []
    spans: list[float] = []
    sides: list[tuple[int, int]] = []
    kept: list[tuple[F64, F64]] | None = [] if observed is None else None
    for lo in range(0, n_pairs, RECOVER_BLOCK):
        checked = _read_block(pairs, lo) if _checked else _checked_block(pairs, lo)
        lengths += [int(b[0, 0] - a[-1, 0]) - 1 for a, b in checked]
        spans += [float(np.hypot(*(b[0, 1:3] - a[-1, 1:3]))) for a, b in checked]
        if contexts is None:
            sides += [(len(a), len(b)) for a, b in checked]
        if kept is not None:
            kept += checked
    if observed is None:  # the segments themselves, checked
        observed = [s for pair in kept or () for s in pair]
    all_runs = _DistinctRuns(distinct_runs(observed, strict="recover_auto"))
    runs = _fit_sample([r for r in all_runs if len(r) >= 4], seed)
    if noise is None:
        needs = "gdt-bi" in candidates or "gdt-mix" in candidates
        noise = _estimate_noise(runs) if runs and needs else _NO_NOISE
    if motion is None and runs and "gdt-mix" in candidates:
        motion = _fit_motion(runs, noise)
    keep = [k for k, v in enumerate(lengths) if v > 0]
    cal = calibrate(
        all_runs,
        [lengths[k] for k in keep],
        noise,
        motion,
        seed=seed,
        spans=[spans[k] for k in keep],
        contexts=[sides[k] if contexts is None else contexts[k] for k in keep],
        candidates=candidates,
        max_gaps=max_gaps,
        combine=combine,
        bags=bags,
        regions=regions,
    )
    del spans, sides
    mixes = {L: cal.weights_for(L) if L > 0 else (("linear", 1.0),) for L in set(lengths)}
    used = {m for mix in mixes.values() for m, _ in mix}
    hood = Neighbourhood(all_runs) if any(m.endswith(NB_SUFFIX) for m in used) else None
    # Second pass, a block of gaps at a time: each gap is recovered on its own (every method's
    # path of a gap is the same in any batch), so the paths are those of one call over all the
    # gaps, while the copies, the methods' temporaries and the neighbours' windows are a
    # block's (the neighbours' are forgotten after each block)
    paths: list[F64] = []
    for lo in range(0, n_pairs, RECOVER_BLOCK):
        checked = _read_block(pairs, lo) if kept is None else kept[lo : lo + RECOVER_BLOCK]
        block = [mixes[L] for L in lengths[lo : lo + len(checked)]]
        groups: dict[str, list[int]] = {}  # each method once, over every gap that uses it
        for k, mix in enumerate(block):
            for m, _ in mix:
                groups.setdefault(m, []).append(k)
        found: dict[tuple[str, int], F64] = {}
        for m, idx in groups.items():
            got = recover_with(m, [checked[k] for k in idx], noise, motion or _NO_MOTION, hood)
            for k, p in zip(idx, got, strict=True):
                found[m, k] = p
        if hood is not None:
            hood.forget()
        paths += [
            found[mix[0][0], k]
            if len(mix) == 1
            else np.sum([w * found[m, k] for m, w in mix], axis=0)
            for k, mix in enumerate(block)
        ]
    return paths, cal


def _checked_block(pairs: Sequence[tuple[F64, F64]], lo: int) -> list[tuple[F64, F64]]:
    """Gaps ``lo`` to ``lo + RECOVER_BLOCK`` of `pairs`, checked as :func:`recover_auto` does.

    Contiguous float64 copies of each segment's ``frame, x, y``: in a few passes
    (:func:`~pftrack.recovery.segments.checked_at_once`) when they are valid float64 arrays,
    else pair by pair (:func:`~pftrack.recovery.segments.as_segment`,
    :func:`~pftrack.recovery.segments.gap_ends`), naming the first bad gap by its place in
    `pairs`. A gap of more than :data:`~pftrack.recovery.segments.MAX_GAP_LIMIT` frames is
    refused, as ``recover_gaps`` refuses it (was filled: the one-pass check did not look).
    """
    block = pairs[lo : lo + RECOVER_BLOCK]
    checked = checked_at_once(block, xy=True)
    if checked is not None:
        return checked
    checked = []  # something to refuse (or not float64 arrays): pair by pair
    for k, (a, b) in enumerate(block, start=lo):
        sa, sb = (
            as_segment(np.asarray(a)[:, :3], "segment_a"),
            as_segment(np.asarray(b)[:, :3], "segment_b"),
        )
        gap_ends(sa, sb, "recover_gaps", f"gap {k}: ")  # B after A, at most MAX_GAP_LIMIT
        checked.append((sa, sb))
    return checked


def _read_block(pairs: Sequence[tuple[F64, F64]], lo: int) -> list[tuple[F64, F64]]:
    """Gaps ``lo`` to ``lo + RECOVER_BLOCK`` of `pairs` as :func:`_checked_block` gave them.

    Not checked again: :func:`recover_auto`'s first pass checked them and, calibrating on its
    `observed`, dropped the copies (a block's memory, not every gap's), or ``recover_gaps``
    checked them before (``_checked``: the first pass reads them so too); only converted as
    :func:`~pftrack.recovery.segments.as_segment` converts, ``frame, x, y`` of every segment
    stacked into one float64 copy and split (the same values; was a second
    :func:`_checked_block` of every block).
    """
    segs = [np.asarray(s) for pair in pairs[lo : lo + RECOVER_BLOCK] for s in pair]
    x = np.concatenate([s.astype(np.float64, copy=False)[:, :3] for s in segs])
    parts = split_rows(x, [len(s) for s in segs])
    return list(zip(parts[0::2], parts[1::2], strict=True))
