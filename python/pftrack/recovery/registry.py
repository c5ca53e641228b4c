"""The recovery methods by name, and the two entry points that dispatch to them.

Recovering the path of one object across a gap between two observed segments: a *segment* is an
``(k, 3)`` or ``(k, 5)`` array of rows ``(frame, x, y[, w, h])`` with increasing frames; the gap
is every frame strictly between the last frame of segment A and the first frame of segment B.
Time is measured in frames (``dt = 1``).

Methods
-------
``"gdt"``
    Goal-directed tracking exactly as in Oh & Jung (2015)
    (:func:`~pftrack.recovery.problems.gdt_problem`).
``"gdt-bi"`` (pftrack's variant)
    Goal-directed tracking towards the state of a backward Kalman filter over segment B, noise
    levels estimated from the observed segments
    (:func:`~pftrack.recovery.problems.gdt_bi_problem`,
    :func:`~pftrack.recovery.noise.estimate_noise`).
``"auto"`` (the default, :data:`DEFAULT_METHOD`)
    Calibrated on the file itself: artificial gaps of the lengths to fill are cut into the
    observed runs, every candidate method recovers them, and each gap-length bucket uses the
    best (a straight line unless another method is clearly better), or a convex combination
    of the best two where it is clearly better still (:mod:`pftrack.recovery.calibrate`).
``"gdt-fixed"`` (pftrack's variant)
    ``gdt-bi``'s two-sided goal with the paper's fixed noise levels (nothing estimated, so
    camera motion and annotation jitter cannot inflate them).
``"gdt-mix"``
    ``gdt-bi`` mixed over "walks through" and "stands still for a while" hypotheses, each
    weighted by its evidence, with the Singer motion model (correlated acceleration) where the
    observed points support it; every parameter estimated from the observed points
    (:mod:`pftrack.recovery.mixture`).
``"linear"``, ``"cubic"``, ``"bspline"``, ``"gsi"``, ``"rts"``
    The baselines of :mod:`pftrack.recovery.baselines`.
``"linear-nb"``, ``"rts-nb"`` (pftrack's variants)
    ``"linear"`` and ``"rts"``, each path corrected by the median error the same method makes
    on the other tracks observed over the gap's frames, cut like the gap: the motion they
    share, such as a moving camera's (:mod:`pftrack.recovery.neighbours`). They need the
    file's other tracks (`observed`); without them, or without a track seen over the whole
    gap, the path is the baseline's.

Box sizes (``w, h``), when given, are interpolated linearly by every method.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import cast

import numpy as np
from numpy.typing import ArrayLike

from pftrack import _check
from pftrack._check import MAX_FRAME
from pftrack._progress import progress
from pftrack._typing import F64, RecoveryMethod
from pftrack.recovery import calibrate
from pftrack.recovery.baselines import _BASELINES, _interpolate_sizes, _rts_batch
from pftrack.recovery.calibrate import bags_for, fixed_noise_model, recover_auto
from pftrack.recovery.mixture import MotionFit, _fit_motion, check_models, recover_mixture_gaps
from pftrack.recovery.names import (
    DEFAULT_METHOD,
    GOAL_DIRECTED_METHODS,
    METHODS,
    NEIGHBOUR_METHODS,
)
from pftrack.recovery.neighbours import (
    NB_SUFFIX,
    Neighbourhood,
    correct_by_neighbours,
)
from pftrack.recovery.noise import NoiseEstimate, _estimate_noise
from pftrack.recovery.problems import SegmentModel
from pftrack.recovery.segments import (
    as_observed,
    as_segment,
    checked_at_once,
    distinct_runs,
    gap_ends,
    gap_frames,
)

__all__ = ["DEFAULT_METHOD", "GOAL_DIRECTED_METHODS", "METHODS", "recover_gap", "recover_gaps"]


def recover_gap(
    segment_a: ArrayLike,
    segment_b: ArrayLike,
    frames: ArrayLike | None = None,
    method: RecoveryMethod = DEFAULT_METHOD,
    *,
    noise: NoiseEstimate | None = None,
    motion: MotionFit | None = None,
) -> F64:
    """Positions (and sizes) of an object in the frames between two observed segments.

    Parameters
    ----------
    segment_a, segment_b : (k, 3) or (k, 5) array_like
        Rows ``(frame, x, y[, w, h])`` before and after the gap, frames increasing.
    frames : (F,) array_like of int, optional
        Frames to fill, strictly between the two segments; default: all of them.
    method : str
        One of :data:`METHODS` (see the module docstring), best given by keyword (the third
        parameter is `frames`); default ``"auto"`` (calibrated on the two segments only;
        :func:`recover_gaps` with `observed` calibrates on a whole file).
    noise : NoiseEstimate, optional
        For ``"gdt-bi"``: noise levels to use instead of estimating them from the two segments
        (e.g. pooled over a whole file with :func:`~pftrack.recovery.noise.estimate_noise`).
    motion : MotionFit, optional
        For ``"gdt-mix"``: the model to use instead of fitting it to the two segments
        (e.g. fitted to a whole file with :func:`pftrack.recovery.mixture.fit_motion`).

    Returns
    -------
    (F, 2) or (F, 4) ndarray of float64
        ``(x, y)`` per frame, plus ``(w, h)`` (linear) when both segments carry sizes.

    Raises
    ------
    TypeError
        `frames` is a string: a method given positionally, as :func:`recover_gaps` and
        :func:`~pftrack.recovery.fill.fill_gaps` take it (second); here it goes by keyword.
        `noise` not a NoiseEstimate or `motion` not a MotionFit.
    ValueError
        Empty or malformed segments (:func:`~pftrack.recovery.segments.as_segment`: NaN, a
        frame that is not an integer, a negative width or height, a value beyond ±1e9 px),
        overlapping segments, frames outside the gap or an unknown method.

    Examples
    --------
    >>> from pftrack import recover_gap
    >>> a = [[1, 10, 50], [2, 12, 50], [3, 14, 50]]  # frames 1-3, moving 2 px a frame in x
    >>> b = [[7, 22, 50], [8, 24, 50]]
    >>> recover_gap(a, b, method="linear")  # frames 4, 5, 6
    array([[16., 50.],
           [18., 50.],
           [20., 50.]])
    >>> recover_gap(a, b, frames=[5], method="gdt-bi").round(2)
    array([[18., 50.]])
    """
    if isinstance(frames, str):  # recover_gap(a, b, "linear"): frames come third here
        hint = f"; the method goes by keyword: method={frames!r}" if frames in METHODS else ""
        raise TypeError(
            f"recover_gap: frames must be a 1-D array of frame numbers, got the string "
            f"{frames!r}{hint}"
        )
    a = as_segment(segment_a, "segment_a")
    b = as_segment(segment_b, "segment_b")
    fr = gap_frames(a, b, frames)
    _check.option(method, "recover_gap: method", METHODS)
    if method not in METHODS:
        raise ValueError(f"recover_gap: method is {method!r}, expected one of {METHODS}")
    check_models(noise, motion, "recover_gap")
    if fr.size == 0:
        return np.zeros((0, 4 if a.shape[1] == 5 and b.shape[1] == 5 else 2))
    if method in GOAL_DIRECTED_METHODS or method in NEIGHBOUR_METHODS:
        full = recover_gaps([(a, b)], method, noise=noise, motion=motion)[0]
        xy = full[(fr - a[-1, 0] - 1).astype(int)]
    else:
        xy = _BASELINES[method](a, b, fr)
    wh = _interpolate_sizes(a, b, fr)
    return xy if wh is None else np.hstack([xy, wh])


def _checked_pairs(gaps: Sequence[tuple[ArrayLike, ArrayLike]]) -> list[tuple[F64, F64]]:
    """The gaps as checked ``(segment_a, segment_b)`` arrays, each B after its A.

    Every method's segments meet the same rules (:func:`as_segment`, errors naming
    ``recover_gaps`` and the gap); a segment of other than 3 or 5 columns is taken by its
    ``frame, x, y``, the only columns :func:`recover_gaps` reads.
    """
    try:
        if isinstance(gaps, (str, bytes)):
            raise TypeError
        each = iter(gaps)
    except TypeError:  # was: "'NoneType' object is not iterable"
        raise TypeError(
            "recover_gaps: gaps must be a sequence of (segment_a, segment_b) pairs, got "
            f"{type(gaps).__name__}"
        ) from None
    fast = checked_at_once(gaps)
    if fast is not None:
        return fast
    pairs = []
    for k, gap in enumerate(each):
        # "not enough values to unpack"; an int (a DataFrame's column labels): "has no len()"
        if isinstance(gap, (str, bytes)) or not hasattr(gap, "__len__") or len(gap) != 2:
            n = len(gap) if hasattr(gap, "__len__") else None
            got = type(gap).__name__ if n is None else f"{n} value{'' if n == 1 else 's'}"
            raise ValueError(
                f"recover_gaps: gap {k} must be a pair (segment_a, segment_b), got {got}"
            )
        a, b = gap
        sa, sb = _gap_segment(a, "segment_a", k), _gap_segment(b, "segment_b", k)
        gap_ends(sa, sb, "recover_gaps", f"gap {k}: ")
        pairs.append((sa, sb))
    return pairs


def _gap_segment(seg: ArrayLike, name: str, k: int) -> F64:
    """Segment `name` of gap `k`, checked by :func:`as_segment` (see :func:`_checked_pairs`)."""
    return as_observed(seg, f"{name} of gap {k}", "recover_gaps")


def _recover_nb(pairs: Sequence[tuple[F64, F64]], method: str, hood: Neighbourhood) -> list[F64]:
    """`pairs` recovered by a ``"-nb"`` `method` (:data:`NEIGHBOUR_METHODS`), corrected by `hood`.

    :data:`~pftrack.recovery.calibrate.RECOVER_BLOCK` gaps at a time, as ``"auto"`` recovers
    them (`pairs` sliced: ``fill_rows`` makes each hole's segments when read), the
    neighbours' windows forgotten after each block: each gap is recovered on its own, so the
    paths are those of one call over all the gaps, while the windows, their paths and the
    base method's temporaries are a block's (were every gap's at once: memory grew with the
    file). Each block's segments are checked by the base method's :func:`recover_gaps`.
    """
    base = cast("RecoveryMethod", method.removesuffix(NB_SUFFIX))  # rts-nb -> rts

    def recover(ps: list[tuple[F64, F64]]) -> list[F64]:
        return recover_gaps(ps, base)

    block = calibrate.RECOVER_BLOCK
    paths: list[F64] = []
    # one bar over the whole run (each block's own would be short, or none at all)
    for lo in progress(range(0, len(pairs), block), desc=method, unit="block"):
        paths += correct_by_neighbours(recover, pairs[lo : lo + block], hood)
        hood.forget()
    return paths


def recover_gaps(
    gaps: Sequence[tuple[ArrayLike, ArrayLike]],
    method: RecoveryMethod = DEFAULT_METHOD,
    *,
    noise: NoiseEstimate | None = None,
    history: int | None = None,
    motion: MotionFit | None = None,
    observed: Sequence[F64] | None = None,
    seed: int = 0,
    combine: bool = True,
    bags: int | None = None,
) -> list[F64]:
    """Recover many gaps at once.

    Parameters
    ----------
    gaps : sequence of (segment_a, segment_b)
        Segments as in :func:`recover_gap` (only ``frame, x, y`` are used).
    method : str
        One of :data:`METHODS`; default ``"auto"``.
    noise : NoiseEstimate, optional
        For ``"gdt-bi"``: noise levels shared by all gaps; default: estimated from all the
        segments given (:func:`~pftrack.recovery.noise.estimate_noise`).
    history : int, optional
        For ``"gdt"`` and ``"gdt-bi"``: the Kalman filters use at most this many points of the
        run of consecutive frames next to the gap; default: the whole run.
    motion : MotionFit, optional
        For ``"gdt-mix"``: the model shared by all gaps; default: fitted to all the segments
        given (:func:`pftrack.recovery.mixture.fit_motion`, with `noise` as its fallback).
    observed : sequence of (k, 3+) ndarray, optional
        For ``"auto"``: every observed track of the file to calibrate on; for ``"linear-nb"``
        and ``"rts-nb"``: the tracks whose errors correct the paths. Default: the segments
        given (:func:`pftrack.recovery.calibrate.recover_auto`, which also returns what was
        chosen).
    seed, combine, bags
        For ``"auto"``: the calibration's seed, whether a bucket may blend two methods and the
        bootstrap resamples the choice is averaged over (None: 32 with `combine`, 0 without;
        :func:`~pftrack.recovery.calibrate.recover_auto`).

    Returns
    -------
    list of (T_g - 1, 2) ndarray
        ``(x, y)`` of every frame inside each gap.

    Raises
    ------
    TypeError
        `gaps` that is not a sequence (None, a number, a str), a `seed` or `history` that is
        not an int, `noise` not a NoiseEstimate or `motion` not a MotionFit.
    ValueError
        An unknown method, a gap that is not a pair of segments, segments :func:`recover_gap`
        refuses, whatever the method (the message names the gap), a negative `seed`, or
        `bags` not None or an integer in ``0..10000`` (or more than 0 with ``combine=False``).

    Notes
    -----
    ``"gdt"`` and ``"gdt-bi"`` filter the segments and solve every gap in one C++ call with
    the GIL released (O(T) per gap, :meth:`SegmentModel.recover
    <pftrack.recovery.problems.SegmentModel.recover>`).
    """
    _check.option(method, "recover_gaps: method", METHODS)
    if method not in METHODS:
        raise ValueError(f"recover_gaps: method is {method!r}, expected one of {METHODS}")
    seed = _check.seed(seed, "recover_gaps: seed")
    check_models(noise, motion, "recover_gaps")
    combine = _check.flag(combine, "recover_gaps: combine")
    bags = bags_for(bags, combine, "recover_gaps")
    if history is not None:
        history = _check.integer(history, "recover_gaps: history", 1, MAX_FRAME)
    pairs = _checked_pairs(gaps)
    if method == "rts" and pairs:  # one vectorised pass over all gaps
        return _rts_batch(pairs)
    if method in NEIGHBOUR_METHODS:
        runs = (
            distinct_runs([s for p in pairs for s in p])
            if observed is None
            else distinct_runs(observed, strict="recover_gaps")
        )
        return _recover_nb(pairs, method, Neighbourhood(runs))
    if method not in GOAL_DIRECTED_METHODS:
        return [  # recover_gap's path, without checking the checked pairs again
            _BASELINES[method](a, b, fr) if fr.size else np.zeros((0, 2))
            for a, b in progress(pairs, desc=method, unit="gap")
            for fr in (gap_frames(a, b, None),)
        ]
    if not pairs:
        return []
    if method == "auto":
        return recover_auto(  # the pairs are checked: not again, block by block
            pairs, observed, noise, motion, seed=seed, combine=combine, bags=bags, _checked=True
        )[0]
    seg_a = [a for a, _ in pairs]
    seg_b = [b for _, b in pairs]
    if method == "gdt-mix":
        if motion is None:
            motion = _fit_motion(seg_a + seg_b, noise)
        return recover_mixture_gaps(pairs, motion)
    if method == "gdt":
        model = SegmentModel.paper()
    elif method == "gdt-fixed":
        model = fixed_noise_model()
    else:
        model = SegmentModel.two_sided(_estimate_noise(seg_a + seg_b) if noise is None else noise)
    return model.recover(seg_a, seg_b, history)
