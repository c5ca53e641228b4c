"""Observed segments of a trajectory: checking them and cutting them into runs.

A *segment* is a ``(k, 3)`` or ``(k, 5)`` array of rows ``(frame, x, y[, w, h])`` with
increasing frames. A gap lies between two segments: every frame strictly between the last frame
of segment A and the first frame of segment B. Time is measured in frames.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack._check import MAX_COORD, MAX_FRAME, real_array
from pftrack._typing import F64

#: Most frames a gap may miss (a longer one is refused, not filled): what one call fills is
#: bounded, as ``fill_gaps``' `max_gap` (:data:`pftrack.recovery.fill.MAX_GAP_LIMIT`) is.
MAX_GAP_LIMIT = 100_000

#: Gaps :func:`checked_at_once` checks together: its copies of their rows stay small (a
#: ``fill_gaps`` hole's segments hold up to twice its windows' points, many times the rows of
#: a track with many holes).
CHECK_BLOCK = 256

__all__ = [
    "MAX_GAP_LIMIT",
    "as_observed",
    "as_segment",
    "checked_at_once",
    "consecutive_runs",
    "contiguous_head",
    "contiguous_tail",
    "distinct_runs",
    "gap_ends",
    "gap_frames",
    "observed_segments",
    "pairs_meet_rules",
    "split_rows",
]


def as_segment(seg: ArrayLike, name: str, fn: str = "recover_gap") -> F64:
    """Check and convert one segment to a C-contiguous ``(k, 3|5)`` float64 array.

    Parameters
    ----------
    seg : (k, 3) or (k, 5) array_like
        Rows ``(frame, x, y[, w, h])``.
    name : str
        How error messages name the segment (``"segment_a"``, ...).
    fn : str
        How they name the function called (``"recover_gaps"``, ...).

    Returns
    -------
    (k, 3) or (k, 5) ndarray of float64

    Raises
    ------
    TypeError
        Values that are not real numbers (complex, text, objects).
    ValueError
        Wrong shape, no row, a non-finite value, a frame that is not an integer with
        ``|frame| <= MAX_FRAME`` (whole frames only, as `frames` and
        :func:`~pftrack.recovery.fill.fill_gaps` take them), a negative width or height (as
        :func:`pftrack.io.mot.read_mot`), a position or size beyond ``MAX_COORD`` (1e9 px) or
        frames that do not increase strictly.
    """
    a = real_array(seg, f"{fn}: {name}", booleans=False)
    if a.ndim != 2 or a.shape[1] not in (3, 5):
        raise ValueError(f"{fn}: {name} must have shape (k, 3) or (k, 5), got {a.shape}")
    if a.shape[0] == 0:
        raise ValueError(f"{fn}: {name} is empty")
    # every rule in a few passes, then the checks below name what is wrong only when something
    # is (frames that increase are within ±MAX_FRAME when their ends are)
    f = a[:, 0]
    if (
        np.isfinite(a).all()
        and (np.diff(f) > 0).all()
        and -MAX_FRAME <= f[0]
        and f[-1] <= MAX_FRAME
        and (f == np.floor(f)).all()
        and (a.shape[1] == 3 or a[:, 3:].min() >= 0)
        and np.abs(a[:, 1:]).max() <= MAX_COORD
    ):
        return np.ascontiguousarray(a)
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{fn}: {name} has a non-finite value")
    f = a[:, 0]
    fractional = (np.abs(f) > MAX_FRAME) | (f != np.floor(f))
    if fractional.any():
        r = int(np.argmax(fractional))
        raise ValueError(
            f"{fn}: {name} row {r} has frame {f[r]:.17g}, expected an integer with "
            f"|frame| <= {MAX_FRAME} (refused)"
        )
    if a.shape[1] == 5 and (a[:, 3:] < 0).any():
        r, c = np.argwhere(a[:, 3:] < 0)[0]
        raise ValueError(
            f"{fn}: {name} row {r} has {('w', 'h')[c]} = {a[r, c + 3]:g}: negative box "
            "width or height (refused)"
        )
    far = np.abs(a[:, 1:]) > MAX_COORD
    if far.any():
        r, c = np.argwhere(far)[0]
        raise ValueError(
            f"{fn}: {name} row {r} has {('x', 'y', 'w', 'h')[c]} = {a[r, c + 1]:g}, "
            f"beyond ±{MAX_COORD:g} px (refused)"
        )
    if np.any(np.diff(a[:, 0]) <= 0):
        raise ValueError(f"{fn}: {name} frames must increase strictly")
    return np.ascontiguousarray(a)


def pairs_meet_rules(x: F64, sizes: NDArray[np.int64]) -> bool:
    """Whether segments meet :func:`as_segment`'s rules on ``frame, x, y``, each B after its A.

    `x` holds the ``frame, x, y`` rows of segments of `sizes` rows one after the other:
    segment A, then segment B, of each gap in turn. A few passes over all the rows, for
    callers that check a batch of gaps at once and, when this is False, gap by gap to name
    what is wrong (:func:`checked_at_once`, ``calibrate.recover_auto``).
    """
    f = x[:, 0]
    ends = np.cumsum(sizes)
    step = np.diff(f)
    step[ends[:-1] - 1] = 1.0  # from one segment to the next: not a step of either
    return bool(
        np.isfinite(x).all()
        and (step > 0).all()
        and np.abs(f).max() <= MAX_FRAME
        and (f == np.floor(f)).all()
        and np.abs(x[:, 1:]).max() <= MAX_COORD
        and (f[ends[1::2] - sizes[1::2]] > f[ends[0::2] - 1]).all()
    )


def checked_at_once(gaps: object, xy: bool = False) -> list[tuple[F64, F64]] | None:
    """The gaps as :func:`as_segment` and :func:`gap_ends` check them, all in a few passes.

    When `gaps` is a list or tuple of pairs of non-empty C-contiguous float64 ``(k, 3)`` or
    ``(k, 5)`` ndarrays that meet every rule of :func:`as_segment` (the arrays it returns are
    these ones) and every segment B starts after its segment A within :data:`MAX_GAP_LIMIT`
    frames: the pairs, each segment as given. Otherwise None: the caller checks gap by gap
    and names what is wrong. ``recover_gaps`` checks its pairs so (every hole of a
    ``fill_gaps`` file: checked one segment at a time, they took half of
    ``fill_gaps(rows, "linear")`` on 200 000 rows with 40 000 holes, 2.1-2.2 s of CPU, now
    1.0-1.2 s).

    With `xy`, for callers that read only ``frame, x, y`` (each block of
    ``calibrate.recover_auto``): C-contiguous copies of those columns instead (the rows the
    check stacks, split: no second copy), and only those are checked, of float64 ndarrays of
    any layout and at least 3 columns (as the caller's pair-by-pair check takes them).
    """
    if not isinstance(gaps, (list, tuple)) or not gaps:
        return None
    segs: list[F64] = []
    for gap in gaps:
        if not isinstance(gap, (list, tuple)) or len(gap) != 2:
            return None
        for seg in gap:
            if not (
                type(seg) is np.ndarray  # not a masked array, nor any other subclass
                and seg.dtype == np.float64
                and seg.ndim == 2
                and seg.shape[0] > 0
                and (seg.shape[1] >= 3 if xy else seg.shape[1] in (3, 5))
                and (xy or seg.flags.c_contiguous)
            ):
                return None
            segs.append(seg)
    parts: list[F64] = []
    for lo in range(0, len(segs), 2 * CHECK_BLOCK):  # copies of a block at a time, not all
        block = segs[lo : lo + 2 * CHECK_BLOCK]
        sizes = np.array([len(seg) for seg in block], dtype=np.int64)
        x = np.concatenate([seg[:, :3] for seg in block])
        if not pairs_meet_rules(x, sizes):
            return None
        f = x[:, 0]
        ends = np.cumsum(sizes)
        if (f[ends[1::2] - sizes[1::2]] - f[ends[0::2] - 1] - 1).max() > MAX_GAP_LIMIT:
            return None
        if xy:
            parts += split_rows(x, sizes)
            continue
        wh = [seg[:, 3:] for seg in block if seg.shape[1] == 5]
        if wh:
            w = np.concatenate(wh)
            if not (np.isfinite(w).all() and w.min() >= 0 and w.max() <= MAX_COORD):
                return None
    out = parts if xy else segs
    return list(zip(out[0::2], out[1::2], strict=True))


def as_observed(seg: ArrayLike, name: str, fn: str) -> F64:
    """One segment of (k, 3+) rows ``(frame, x, y, ...)``, checked by :func:`as_segment`.

    The columns :func:`as_segment` reads (``frame, x, y``, and ``w, h`` of a (k, 5) segment)
    are checked and kept; those of any other width (a MOTChallenge row's ten) are left out.

    Raises
    ------
    TypeError, ValueError
        As :func:`as_segment`; ``{fn}: {name} must have shape (k, 3|5), non-empty; got (4,)``.
    """
    a = real_array(seg, f"{fn}: {name}", booleans=False)
    if a.ndim != 2 or a.shape[1] < 3 or a.shape[0] == 0:
        raise ValueError(f"{fn}: {name} must have shape (k, 3|5), non-empty; got {a.shape}")
    return as_segment(a if a.shape[1] in (3, 5) else a[:, :3], name, fn)


def observed_segments(segments: object, fn: str) -> list[F64]:
    """`segments`, the observed segments a noise or motion model is fitted to, checked.

    Each is (k, 3+) rows ``(frame, x, y, ...)``: its ``frame, x, y`` meet the rules of
    :func:`as_segment` (finite, whole frames increasing strictly, within ±1e9 px); an empty
    one adds nothing. Was: :func:`consecutive_runs` left out, without a word, whatever it
    could not read, so that one segment given alone (``estimate_noise(seg)``: its rows read as
    segments), frames in the wrong column or in decreasing order gave the default model as if
    fitted to the data.

    Raises
    ------
    TypeError
        `segments` not a sequence of arrays (a string, a number); values that are not real
        numbers.
    ValueError
        One (k, 3+) array or a (3+,) row given for the sequence (pass ``[segment]``); a segment
        not of shape (k, 3+); a value :func:`as_segment` refuses, named by its place
        (``estimate_noise: segments[2] frames must increase strictly``).
    """
    if isinstance(segments, (str, bytes)) or not isinstance(segments, Iterable):
        raise TypeError(
            f"{fn}: segments must be a sequence of (k, 3+) arrays (frame, x, y, ...), got "
            f"{type(segments).__name__}"
        )
    if isinstance(segments, np.ndarray) and segments.ndim < 3:
        raise ValueError(
            f"{fn}: segments is one {segments.shape} array, expected a sequence of (k, 3+) "
            "segments: pass [segment] for one"
        )
    checked = []
    for k, seg in enumerate(list(segments)):
        a = real_array(seg, f"{fn}: segments[{k}]", booleans=False)
        if a.ndim != 2 or a.shape[1] < 3:
            one = " (one segment given alone? pass [segment])" if a.ndim == 1 else ""
            raise ValueError(
                f"{fn}: segments[{k}] has shape {a.shape}, expected (k, 3+) rows frame, x, y" + one
            )
        if len(a):
            as_segment(a[:, :3], f"segments[{k}]", fn)
        checked.append(a)
    return checked


def gap_ends(seg_a: F64, seg_b: F64, fn: str = "recover_gap", gap: str = "") -> tuple[int, int]:
    """Last frame of segment A and first of segment B, checked segments around one gap.

    Parameters
    ----------
    seg_a, seg_b : (k, 3+) ndarray
        Checked segments (:func:`as_segment`).
    fn, gap : str
        How errors name the function called and the gap (``"recover_gaps"``, ``"gap 3: "``).

    Raises
    ------
    ValueError
        Segment B does not start after segment A ends, or the gap misses more than
        :data:`MAX_GAP_LIMIT` frames (its path would not fit in memory long before 2**31
        frames: refused, not cut short).
    """
    f0, f1 = int(seg_a[-1, 0]), int(seg_b[0, 0])
    if f1 <= f0:
        raise ValueError(
            f"{fn}: {gap}segment_b starts at frame {f1}, expected after segment_a's end {f0}"
        )
    if f1 - f0 - 1 > MAX_GAP_LIMIT:
        raise ValueError(
            f"{fn}: {gap}the gap from frame {f0} to {f1} misses {f1 - f0 - 1} frames, more than "
            f"{MAX_GAP_LIMIT} (refused)"
        )
    return f0, f1


def gap_frames(
    seg_a: F64, seg_b: F64, frames: ArrayLike | None, fn: str = "recover_gap"
) -> NDArray[np.int64]:
    """Frames to fill between two checked segments (default: every frame of the gap).

    `fn` names the function called in the messages.

    Raises
    ------
    TypeError
        `frames` holds what is not real numbers.
    ValueError
        The gap :func:`gap_ends` refuses, or `frames` is not 1-D integers strictly inside the
        gap, in increasing order.
    """
    f0, f1 = gap_ends(seg_a, seg_b, fn)
    if frames is None:
        return np.arange(f0 + 1, f1, dtype=np.int64)
    fr = real_array(frames, f"{fn}: frames", booleans=False)
    if fr.ndim != 1 or not np.all(fr == np.round(fr)):
        raise ValueError(f"{fn}: frames must be a 1-D array of integers")
    if fr.size and (fr.min() <= f0 or fr.max() >= f1):
        raise ValueError(f"{fn}: frames must lie strictly between {f0} and {f1}")
    if np.any(np.diff(fr) <= 0):  # one row per frame, in order (gsi reads the first and last)
        k = int(np.flatnonzero(np.diff(fr) <= 0)[0])
        raise ValueError(
            f"{fn}: frames must increase strictly, got {fr[k]:.17g} then {fr[k + 1]:.17g}"
        )
    return fr.astype(np.int64)


def split_rows(a: F64, sizes: ArrayLike) -> list[F64]:
    """Consecutive blocks of `sizes` rows of `a` (views): ``np.split(a, cumsum(sizes)[:-1])``.

    The same arrays, by plain slicing (``np.split`` costs a Python call per piece).
    """
    ends = np.cumsum(np.asarray(sizes, dtype=np.int64)).tolist()
    return [a[s:e] for s, e in zip([0, *ends[:-1]], ends, strict=True)]


def consecutive_runs(segments: Sequence[ArrayLike], min_points: int) -> list[F64]:
    """Split segments (rows ``(frame, x, y, ...)``) into runs of consecutive frames.

    Runs shorter than `min_points` and malformed or empty segments are skipped.
    """
    runs: list[F64] = []
    for s in segments:
        a = np.asarray(s, dtype=np.float64)
        if a.ndim != 2 or a.shape[1] < 3 or len(a) == 0:
            continue
        for run in np.split(a, np.flatnonzero(np.diff(a[:, 0]) != 1) + 1):
            if len(run) >= min_points:
                runs.append(run)
    return runs


def distinct_runs(observed: Sequence[F64], strict: str | None = None) -> list[F64]:
    """Distinct runs of consecutive frames (rows ``frame, x, y``), in a canonical order.

    Each array of `observed` is split where a frame is skipped, as :func:`consecutive_runs`
    does, but in one vectorised pass over all of them (files of many tracks) and keeping only
    ``frame, x, y``; runs with a non-finite value are left out, and a run given twice (a
    segment shared by two gaps) is kept once.

    With `strict` (the caller's name, for the message) nothing is left out silently:
    `observed` must be a sequence of (k, 3+) arrays of real numbers whose frames, x and y are
    finite and whose frames increase strictly (as a segment's, :func:`as_segment`; tracks in
    decreasing order, with a duplicated row or the frame in another column were cut into runs
    of one point and left out), and a TypeError or ValueError names the first entry that is
    not.
    """
    if strict is not None and (
        isinstance(observed, (str, bytes))
        or not isinstance(observed, Iterable)
        or (isinstance(observed, np.ndarray) and observed.ndim == 0)
    ):
        raise TypeError(
            f"{strict}: observed must be a sequence of (k, 3+) arrays, got "
            f"{type(observed).__name__}"
        )
    arrs = []
    where = []  # the place in `observed` of each array kept, for the messages
    for k, s in enumerate(observed):
        if strict is None:
            a = np.asarray(s, dtype=np.float64)
        else:
            a = real_array(s, f"{strict}: observed[{k}]")
            if a.ndim != 2 or a.shape[1] < 3:
                one = " (one track given alone? pass [track])" if a.ndim == 1 else ""
                raise ValueError(
                    f"{strict}: observed[{k}] has shape {a.shape}, expected (k, 3+) rows "
                    f"frame, x, y{one}"
                )
        if a.ndim == 2 and a.shape[1] >= 3 and len(a):
            arrs.append(a[:, :3])
            where.append(k)
    if not arrs:
        return []
    X = np.vstack(arrs)
    bound = np.zeros(len(X), dtype=bool)
    bound[np.cumsum([len(a) for a in arrs])[:-1]] = True
    brk = np.flatnonzero(bound[1:] | (np.diff(X[:, 0]) != 1)) + 1
    starts, ends = np.r_[0, brk], np.r_[brk, len(X)]
    ok = np.add.reduceat((~np.isfinite(X)).any(axis=1), starts) == 0
    if strict is not None and not ok.all():
        row = int(np.flatnonzero(~np.isfinite(X).all(axis=1))[0])
        k = where[int(np.searchsorted(np.cumsum([len(a) for a in arrs]), row, side="right"))]
        raise ValueError(
            f"{strict}: observed run {k} has a non-finite frame, x or y: {X[row].tolist()}"
        )
    if strict is not None:
        _frames_increase(X[:, 0], bound, arrs, where, strict)
    starts, ends = starts[ok], ends[ok]
    if not len(starts):
        return []
    keys = np.column_stack([X[starts], X[ends - 1, 0], ends - starts])
    _, first = np.unique(keys, axis=0, return_index=True)  # sorted: a canonical order
    return [X[starts[k] : ends[k]] for k in first]


def _frames_increase(
    f: F64, bound: NDArray[np.bool_], arrs: Sequence[F64], where: Sequence[int], who: str
) -> None:
    """Refuse frames that do not increase strictly within their track.

    `f` holds the frames of the arrays `arrs` stacked, `bound` marks each one's first row and
    `where` their places in `observed`, whose entry the message names. Fractional frames pass:
    a track on other frame times than the gap's is no neighbour of it, not an error.
    """
    bad = ~bound[1:] & (np.diff(f) <= 0)
    if not bad.any():
        return
    row = int(np.argmax(bad)) + 1
    i = int(np.searchsorted(np.cumsum([len(a) for a in arrs]), row, side="right"))
    r = row - sum(len(a) for a in arrs[:i])
    raise ValueError(
        f"{who}: observed[{where[i]}] row {r} has frame {f[row]:.17g} after {f[row - 1]:.17g}: "
        "a track's frames must increase strictly (rows frame, x, y, ...)"
    )


def contiguous_tail(seg: F64) -> F64:
    """The last run of consecutive frames of a segment (Kalman filters step one frame at a time)."""
    br = np.flatnonzero(np.diff(seg[:, 0]) != 1)
    return seg[br[-1] + 1 :] if len(br) else seg


def contiguous_head(seg: F64) -> F64:
    """The first run of consecutive frames of a segment."""
    br = np.flatnonzero(np.diff(seg[:, 0]) != 1)
    return seg[: br[0] + 1] if len(br) else seg
