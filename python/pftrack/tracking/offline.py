"""The offline pass over a finished run: link fragments, fill holes, smooth every track.

An online tracker must report each box before it sees the next frame, so its filtered boxes lag
behind turns and carry the detector's frame-to-frame jitter. Once a run is over, every box can
use the frames after it as well: a constant-velocity model for the centre and for the size,
a forward Kalman pass over the track's detections and a backward Rauch-Tung-Striebel pass
(:func:`pftrack.kalman.rts_smooth`) give each frame the mean of its box given the whole track.
Frames without a detection (occlusions the particle filter bridged, merged blobs) get the
smoother's interpolation through the gap.

Noise levels are in units of the track's median box height, so that one rule fits any image
scale. With the defaults (measured on PETS09-S2L1 and TUD-Campus public detections, docs/results.md)
the smoothed boxes match the annotation far more often than the detections themselves.
"""

from __future__ import annotations

import heapq
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack import _check
from pftrack._check import MAX_FRAME, brief, option, real_array, shown
from pftrack._progress import progress
from pftrack._stats import median
from pftrack._typing import F64, IntLike, RecoveryMethod
from pftrack.boxes import _intersection, _iou_rows, _to_cxcywh, _to_xywh
from pftrack.detection.size_model import expected_size, head_height, theil_sen
from pftrack.kalman import Cov, Mean, _cv_predict, _cv_update_where, rts_smooth
from pftrack.recovery.fill import DEFAULT_MAX_GAP, MAX_GAP_LIMIT, fill_rows, side_frames
from pftrack.recovery.linking import (
    MAX_ID,
    BoxColours,
    LinkConfig,
    RowColours,
    _pair_blocks,
    check_boxes,
    check_rows,
    check_tracked,
    check_unique,
    link_config_for,
    link_frames,
    link_tracklets,
)
from pftrack.recovery.names import DEFAULT_METHOD, METHODS

__all__ = [
    "AMODAL_ANCHORS",
    "COLOUR_USES",
    "BoxSmoother",
    "CrossingConfig",
    "complete_boxes",
    "drop_nested",
    "drop_odd_sizes",
    "repair_crossings",
    "size_line",
    "smooth_tracks",
    "smoothed_copies",
    "split_refound",
]

AMODAL_ANCHORS = ("side", "centre")  # complete_boxes: where a widened box keeps its evidence
ILL_POSED = ("complete", "leave")  # complete_boxes: what is done with an ill-posed box
TOP_EDGE = 1.0  # complete_boxes: a box whose top is within this many px of row 0 touches the edge
BOTTOM_EDGE = 2.0  # drop_odd_sizes: a box whose foot is within this many px of the last row is cut
SIZE_SAMPLES = 1500  # drop_odd_sizes: detections the height line is fitted to, evenly spaced
MIN_SIZE_SAMPLES = 30  # drop_odd_sizes: a class with fewer detections is not judged
# drop_odd_sizes: a row is judged only with its foot row within these percentiles of the foot
# rows the line was fitted to (no extrapolation); None judges every row (experiments.size_check)
SIZE_ROWS: tuple[float, float] | None = (5.0, 95.0)
# drop_odd_sizes: a class is judged only if the band [ratio, 1 / ratio] reaches, either side of
# the line, this many robust spreads of the detections' log(height / line) plus half their
# drift over the run (the line explains the heights: size_line); None: judged whatever they are
SIZE_SPREADS: float | None = 2.0
NOISE_MIN = 1e-6  # BoxSmoother's noise levels, in track heights: smaller or larger ones would
NOISE_MAX = 1e6  # only push the smoother to its limits (a straight line, or the detections)


#: What :func:`smooth_tracks`' colour (`frames` or `histograms`) is given to.
COLOUR_USES = ("both", "swap", "link")


def _check_noise_levels(owner: str, config: object, unit: str) -> None:
    """`config`'s ``accel, noise, size_accel, size_noise``: numbers in [NOISE_MIN, NOISE_MAX]."""
    for name in ("accel", "noise", "size_accel", "size_noise"):
        v = _check.number(getattr(config, name), f"{owner}: {name}", finite=False)
        if not NOISE_MIN <= v <= NOISE_MAX:
            raise ValueError(
                f"{owner}: {name} is {brief(v)}, expected a number in [{NOISE_MIN:g}, "
                f"{NOISE_MAX:g}] ({unit})"
            )


@dataclass(frozen=True)
class BoxSmoother:
    """Constant-velocity RTS smoother of box centres and sizes.

    Attributes
    ----------
    accel : float
        Square root of the spectral density of the centre's white-noise acceleration, in track
        heights (per frame^1.5).
    noise : float
        Standard deviation of a detection's centre, in track heights.
    size_accel : float
        The same for the width and height, in track heights.
    size_noise : float
        Standard deviation of a detection's width and height, in track heights.

    max_hole : int
        A track is smoothed in independent pieces split at holes longer than this many frames,
        so the work is bounded by ``(max_hole + 1)`` steps per row whatever the frame numbers.

    Only the ratios ``accel / noise`` and ``size_accel / size_noise`` change the smoothed
    boxes; the smaller they are, the smoother the path. The model is
    :func:`pftrack.kalman.rts_smooth` with the first detection as the initial state. A smoothed
    width or height never falls below half the track's smallest detected one (a size velocity
    extrapolated past the last detection could otherwise shrink a box through zero).
    """

    accel: float = 0.0025
    noise: float = 0.05
    size_accel: float = 0.003
    size_noise: float = 0.1
    max_hole: int = 300

    def __post_init__(self) -> None:
        _check_noise_levels("BoxSmoother", self, "track heights")
        _check.integer(self.max_hole, "BoxSmoother: max_hole", 1, MAX_FRAME)

    def smooth(self, frames: ArrayLike, boxes_xywh: ArrayLike, observed: ArrayLike) -> F64:
        """Smooth one track.

        Parameters
        ----------
        frames : (n,) array_like of int
            Strictly increasing frame numbers of the track's rows (holes are allowed: the model
            steps through every frame in between).
        boxes_xywh : (n, 4) array_like
            Left, top, width, height; rows with ``observed`` False are ignored (their values
            may be anything finite, e.g. an interpolation).
        observed : (n,) array_like of bool
            Which rows are measurements (a matched detection).

        Returns
        -------
        (n, 4) ndarray
            Smoothed boxes for every row. A track with no observed row, or whose median
            observed height is 0 (a degenerate track: flat boxes, no scale to smooth in),
            comes back unchanged.
        """
        fr = real_array(frames, "BoxSmoother.smooth: frames")
        with np.errstate(invalid="ignore"):  # NaN frames are refused just below
            whole = (fr == np.floor(fr)) & (np.abs(fr) <= MAX_FRAME)
        if not np.all(whole):
            raise ValueError(
                f"BoxSmoother.smooth: frames must be integers with |frame| <= {MAX_FRAME}"
            )
        f = fr.astype(np.int64)
        b: F64 = real_array(boxes_xywh, "BoxSmoother.smooth: boxes_xywh")
        obs = np.asarray(observed, dtype=bool)
        n = len(f) if f.ndim == 1 else -1  # was: len() of unsized object (a 0-d array, an int)
        if b.shape != (n, 4) or obs.shape != (n,):
            raise ValueError(
                f"BoxSmoother.smooth: frames {f.shape}, boxes_xywh {b.shape} and observed "
                f"{obs.shape} must be (n,), (n, 4) and (n,)"
            )
        if n > 1 and np.any(np.diff(f) <= 0):
            raise ValueError("BoxSmoother.smooth: frames must be strictly increasing")
        if not np.all(np.isfinite(b[obs])):
            raise ValueError("BoxSmoother.smooth: observed boxes contain NaN or inf")
        if not obs.any():
            return np.array(b, dtype=np.float64)  # a copy
        cuts = np.flatnonzero(np.diff(f) > self.max_hole + 1) + 1
        if len(cuts):  # independent pieces: bounded work
            out_p: F64 = b.copy()
            for i, j in zip(np.r_[0, cuts], np.r_[cuts, n], strict=True):
                if obs[i:j].any():
                    out_p[i:j] = self.smooth(f[i:j], b[i:j], obs[i:j])
            return out_p
        z = _to_cxcywh(b)
        height = median(b[obs, 3])
        if not height > 0:  # no scale to smooth in: the track is kept as it is, as recover does
            return np.array(b, dtype=np.float64)  # a copy
        # in track heights: the same numbers whatever the image scale (no under- or overflow)
        with np.errstate(over="ignore"):
            zh = z / height
        if not np.all(np.isfinite(zh[obs])):
            raise ValueError(
                f"BoxSmoother.smooth: boxes span more than {np.finfo(float).max:g} track heights"
            )
        q = np.array([self.accel, self.accel, self.size_accel, self.size_accel])
        r = np.array([self.noise, self.noise, self.size_noise, self.size_noise])
        first = int(np.argmax(obs))
        steps = int(f[-1] - f[first]) + 1
        zt = np.zeros((steps, 4))
        has = np.zeros(steps, dtype=bool)
        zt[f[first:] - f[first]] = np.where(obs[first:, None], zh[first:], 0.0)
        has[f[first:] - f[first]] = obs[first:]
        mean = height * rts_smooth(zt, has, q * q, r * r, velocity_sd=10.0, update_first=False)
        np.maximum(mean[:, 2:], 0.5 * z[obs, 2:].min(axis=0), out=mean[:, 2:])
        out: F64 = b.copy()
        out[first:] = _to_xywh(mean[f[first:] - f[first]])
        return out  # rows before the first detection keep their own boxes


@dataclass(frozen=True)
class CrossingConfig:
    """Offline repair of identities exchanged where two tracks cross (:func:`repair_crossings`).

    Attributes
    ----------
    enabled : bool
        Run the repair in the offline pass, after linking and before filling and smoothing
        (``TrackerConfig.crossings``; ``pftrack track --crossings``).
    min_iou : float
        Two tracks interact in a frame where their boxes overlap by at least this IoU, in (0, 1].
    join_gap : int
        Interaction frames of one pair at most this many frames apart form one window.
    max_window : int
        Windows longer than this many frames (people walking or standing together) are left as
        they are: a constant-velocity prediction across them says little.
    span : int
        The evidence: each track's detections in the `span` frames before the window and in
        the `span` frames after it.
    min_points : int
        Detections each of the two tracks needs on each side of the window (at least 2).
    accel, noise : float
        The centre's constant-velocity model, in box heights: the square root of the
        acceleration's spectral density (per frame^1.5) and a detection's standard deviation.
    size_accel, size_noise : float
        The same for the width and height.
    margin : float
        The tails are exchanged only when the exchanged pairing is more likely than the one
        the tracker made by at least this log-likelihood ratio (nats, >= 0).
    """

    enabled: bool = False
    min_iou: float = 0.1
    join_gap: int = 5
    max_window: int = 50
    span: int = 15
    min_points: int = 3
    accel: float = 0.01
    noise: float = 0.05
    size_accel: float = 0.003
    size_noise: float = 0.1
    margin: float = 5.0

    def __post_init__(self) -> None:
        if not isinstance(self.enabled, (bool, np.bool_)):
            raise TypeError(f"CrossingConfig: enabled is {brief(self.enabled)}, expected a bool")
        for name in ("min_iou", "margin"):  # before the comparisons ask an array for its truth
            _check.number(getattr(self, name), f"CrossingConfig: {name}", finite=False)
        if not 0.0 < self.min_iou <= 1.0:
            raise ValueError(
                f"CrossingConfig: min_iou is {self.min_iou}, expected a value in (0, 1]"
            )
        for name, lo in (("join_gap", 0), ("max_window", 1), ("span", 1), ("min_points", 2)):
            v = getattr(self, name)
            if (
                isinstance(v, bool)
                or not isinstance(v, (int, np.integer))
                or not lo <= v <= MAX_FRAME
            ):
                raise ValueError(
                    f"CrossingConfig: {name} is {brief(v)}, expected an integer >= {lo}"
                )
        _check_noise_levels("CrossingConfig", self, "box heights")
        if not 0.0 <= self.margin < np.inf:
            raise ValueError(
                f"CrossingConfig: margin is {self.margin}, expected a finite value >= 0"
            )


def repair_crossings(
    rows: ArrayLike,
    observed: ArrayLike | None = None,
    config: CrossingConfig = CrossingConfig(),  # noqa: B008 - frozen, shared safely
    measurements: ArrayLike | None = None,
) -> F64:
    """Exchange the tails of two tracks where the tracker swapped them at a crossing.

    Where two people cross, an online tracker may hand each one's detections to the other's
    track. Once the run is over, both sides of the crossing are known. For every window of
    frames in which two tracks' boxes overlap (IoU at least ``config.min_iou``, frames at
    most ``join_gap`` apart joined, windows up to ``max_window`` frames), the detections of
    each track in the ``span`` frames before the window and after it are compared under two
    pairings: as the tracker made them (each track's before with its own after), and
    exchanged. Each pairing's likelihood is that of a constant-velocity Kalman filter over the
    box centre, width and height (in the pair's median box height, so the rule is
    scale-free) run through the before detections and then scoring the after detections
    (the innovations' Gaussian log-density). When the exchanged pairing is more likely by at
    least ``margin`` nats, the two tracks' ids are exchanged from the window's frame of
    largest overlap on. Windows are taken in time order; after an exchange, the later windows
    are found again with the new ids. Both tracks need ``min_points`` detections on each side.

    Motion and size are all that is compared: two people of the same size who meet and turn
    back look, to this rule, like a crossing whose identities were swapped.

    Parameters
    ----------
    rows : (M, 6..10) array_like
        MOTChallenge rows ``frame, id, left, top, width, height, ...``, at most one per
        (frame, id) (fewer than 10 columns: completed as a file's lines,
        :func:`pftrack._check.mot_rows`). Their boxes decide which tracks overlap.
    observed : (M,) array_like of bool, optional
        Which rows are detections (the evidence); default every row.
    config : CrossingConfig
        Windows, evidence, model and margin (`enabled` is not read here).
    measurements : (M, 4) array_like, optional
        The detection boxes ``left, top, width, height`` behind observed rows, when they differ
        from the rows' own; default the rows' boxes.

    Returns
    -------
    (M, 10) ndarray
        The rows in their order, only ids changed.

    Raises
    ------
    ValueError
        Bad rows, a (frame, id) seen twice, or `observed` / `measurements` of the wrong shape.
    """
    a: F64 = check_rows(rows, "repair_crossings")
    a = a.copy()
    n = len(a)
    obs = np.ones(n, dtype=bool) if observed is None else np.asarray(observed, dtype=bool)
    if obs.shape != (n,):
        raise ValueError(f"repair_crossings: observed has shape {obs.shape}, expected ({n},)")
    z = a[:, 2:6].copy() if measurements is None else real_array(measurements, "repair_crossings")
    if z.shape != (n, 4) or not np.all(np.isfinite(z[obs])):
        raise ValueError(
            f"repair_crossings: measurements has shape {z.shape}, expected finite ({n}, 4)"
        )
    check_unique(a, who="repair_crossings")
    check_tracked(a, who="repair_crossings")
    if n < 2:
        return a
    perm = np.argsort(a[:, 0], kind="stable")  # rows by frame: every selection in time order
    fr, lab = a[perm, 0], a[perm, 1].copy()
    ob, cz = obs[perm], _to_cxcywh(z[perm])
    pairs = _overlapping_pairs(a[perm], config.min_iou)
    tracks = _Tracks(fr, lab, ob, pairs)
    # windows in time order (a heap); an exchange makes its two ids' windows stale (their
    # generation moves on) and pushes them found again, so the others are never recomputed
    heap: list[_Entry] = [(w, 0, 0) for w in _windows(pairs, lab, config.join_gap)]
    pending = list(heap)  # windows not judged yet: judged together when one is needed
    likelier: dict[_Entry, bool] = {}
    while heap:
        entry = heapq.heappop(heap)
        (cut, i, j, start, end), _, _ = entry
        if not tracks.current(entry) or end - start + 1 > config.max_window:
            continue
        if entry not in likelier:
            likelier.update(_judge([e for e in pending if tracks.current(e)], tracks, cz, config))
            pending = []
        if not likelier[entry]:
            continue
        mine = tracks.exchange(i, j, cut)
        for w in _windows(pairs[mine], lab, config.join_gap):
            if w[:3] > (cut, i, j):
                new = (w, tracks.generation(w[1]), tracks.generation(w[2]))
                heapq.heappush(heap, new)
                pending.append(new)
    a[perm, 1] = lab
    return a


def _overlapping_pairs(a: F64, min_iou: float) -> F64:
    """(P, 4) rows ``frame, row p, row q, IoU`` (p < q) of boxes of one frame overlapping enough.

    `a` is sorted by frame. Only boxes whose columns overlap can: within each frame, by left
    edge, a box is paired with the boxes after it whose left edge lies left of its right edge
    (one binary search a row; was every pair of the frame, ``sum k (k - 1) / 2`` for frames of
    k rows: 22.4 million pairs on 2000 tracks over 3000 frames), in blocks of consecutive rows
    of at most :data:`PAIR_BLOCK` pairs. A pair left out has no common column, so IoU 0. Sorted
    by p, then q.
    """
    n = len(a)
    fr, left = a[:, 0], a[:, 2]
    order = np.lexsort((left, fr))  # by frame, then left edge
    # (frame, edge) as complex numbers, which sort by real part, then imaginary part: one
    # binary search over all frames finds each box's first later box starting at or right of
    # its right edge (computed as the IoU's intersection computes it)
    key = np.empty(n, np.complex128)
    key.real, key.imag = fr[order], left[order]
    edge = np.empty(n, np.complex128)
    edge.real, edge.imag = key.real, (left + a[:, 4])[order]
    later = np.searchsorted(key, edge, side="left") - np.arange(n) - 1
    np.maximum(later, 0, out=later)  # rows after each one (in `order`) that it may meet
    del key, edge
    none = np.zeros(0, np.intp)
    found: list[tuple[NDArray[np.intp], NDArray[np.intp], F64]] = [(none, none, np.zeros(0))]
    for lo, hi in _pair_blocks(later, PAIR_BLOCK):
        m = later[lo:hi]
        u = np.repeat(np.arange(lo, hi), m)
        v = u + 1 + np.arange(len(u)) - np.repeat(np.cumsum(m) - m, m)
        p, q = np.minimum(order[u], order[v]), np.maximum(order[u], order[v])
        iou = _iou_rows(a[p, 2:6], a[q, 2:6])
        keep = iou >= min_iou
        found.append((p[keep], q[keep], iou[keep]))
    p, q, iou = (np.concatenate(c) for c in zip(*found, strict=True))
    del found
    at = np.lexsort((q, p))
    out = np.empty((len(at), 4))
    out[:, 1], out[:, 2], out[:, 3] = p[at], q[at], iou[at]
    out[:, 0] = fr[out[:, 1].astype(np.intp)]
    return out


#: A window as the repair's heap holds it: ``(cut, id_lo, id_hi, start, end)`` and the two ids'
#: generations (exchanges made so far) when it was found.
_Entry = tuple[tuple[float, float, float, float, float], int, int]

#: Steps times pairings that :func:`_after_nll` runs at a time, at most (unless one window has
#: more): about 100 bytes each, so a block is a few MB however many windows are judged.
NLL_BLOCK = 1 << 16


class _Groups:
    """Values grouped by key with one stable sort: a key's values are an index slice.

    Groups replaced later (`changed`) are kept aside, so an update costs the two groups only.
    """

    def __init__(self, keys: F64, values: NDArray[np.intp]) -> None:
        order = np.argsort(keys, kind="stable")
        self.values = values[order]
        self.keys, self.start, count = np.unique(keys[order], return_index=True, return_counts=True)
        self.end = self.start + count
        self.changed: dict[float, NDArray[np.intp]] = {}

    def __getitem__(self, key: float) -> NDArray[np.intp]:
        if key in self.changed:
            return self.changed[key]
        k = int(np.searchsorted(self.keys, key))
        if k == len(self.keys) or self.keys[k] != key:
            return self.values[:0]
        return self.values[self.start[k] : self.end[k]]


class _Tracks:
    """`repair_crossings`' tracks: each id's rows, observed rows and overlapping pairs.

    Rows are positions in frame order (each id's in increasing frame order); `lab` is the
    caller's array of ids, relabelled in place by :meth:`exchange` (was: masks of all rows for
    each track of each window, and every window found again after each exchange).
    """

    def __init__(self, fr: F64, lab: F64, ob: NDArray[np.bool_], pairs: F64) -> None:
        self.fr, self.lab = fr, lab
        self.rows = _Groups(lab, np.arange(len(lab)))
        self.observed = _Groups(lab[ob], np.flatnonzero(ob))
        self.p, self.q = pairs[:, 1].astype(np.intp), pairs[:, 2].astype(np.intp)
        k = np.arange(len(pairs))
        self.pairs = _Groups(np.r_[lab[self.p], lab[self.q]], np.r_[k, k])
        self.generations: dict[float, int] = {}

    def generation(self, key: float) -> int:
        return self.generations.get(key, 0)

    def current(self, entry: _Entry) -> bool:
        """Whether `entry` was found with its ids' rows as they are now."""
        w, g_lo, g_hi = entry
        return g_lo == self.generation(w[1]) and g_hi == self.generation(w[2])

    def exchange(self, i: float, j: float, cut: float) -> NDArray[np.intp]:
        """Give `i`'s rows from frame `cut` on to `j` and `j`'s to `i`; the pairs of either."""
        for g in (self.rows, self.observed):
            ri, rj = g[i], g[j]
            si = int(np.searchsorted(self.fr[ri], cut))  # rows before the cut
            sj = int(np.searchsorted(self.fr[rj], cut))
            if g is self.rows:
                self.lab[ri[si:]], self.lab[rj[sj:]] = j, i
            g.changed[i] = np.concatenate([ri[:si], rj[sj:]])
            g.changed[j] = np.concatenate([rj[:sj], ri[si:]])
        mine = np.union1d(self.pairs[i], self.pairs[j])
        lp, lq = self.lab[self.p[mine]], self.lab[self.q[mine]]
        self.pairs.changed[i] = mine[(lp == i) | (lq == i)]
        self.pairs.changed[j] = mine[(lp == j) | (lq == j)]
        for key in (i, j):
            self.generations[key] = self.generation(key) + 1
        return mine


def _windows(pairs: F64, lab: F64, join_gap: int) -> list[tuple[float, float, float, float, float]]:
    """Interaction windows ``(cut, id_lo, id_hi, start, end)`` of the overlapping pairs, sorted.

    `cut` is the window's first frame of largest overlap.
    """
    if not len(pairs):
        return []
    la, lb = lab[pairs[:, 1].astype(np.intp)], lab[pairs[:, 2].astype(np.intp)]
    lo, hi, f, iou = np.minimum(la, lb), np.maximum(la, lb), pairs[:, 0], pairs[:, 3]
    order = np.lexsort((f, hi, lo))
    lo, hi, f, iou = lo[order], hi[order], f[order], iou[order]
    new = np.r_[True, (lo[1:] != lo[:-1]) | (hi[1:] != hi[:-1]) | (np.diff(f) > join_gap + 1)]
    starts = np.flatnonzero(new)
    window = np.cumsum(new) - 1  # each pair's window
    top = np.flatnonzero(iou == np.maximum.reduceat(iou, starts)[window])
    first_top = top[np.r_[True, window[top[1:]] != window[top[:-1]]]]  # one per window
    ends = np.r_[starts[1:], len(f)] - 1
    out = np.column_stack([f[first_top], lo[starts], hi[starts], f[starts], f[ends]])
    out = out[np.lexsort(out.T[::-1])]  # as tuples sort (no two windows are equal)
    return [(c, i, j, s, e) for c, i, j, s, e in out.tolist()]


def _judge(
    entries: list[_Entry], tracks: _Tracks, cz: F64, config: CrossingConfig
) -> dict[_Entry, bool]:
    """Whether each window's exchanged tails beat the tracker's pairing by ``config.margin``.

    Each track's observed rows in the `span` frames before the window and after it (index
    slices); windows with fewer than `min_points` on a side, or a median box height not
    positive, are not exchanged; the others' four pairings are scored together.
    """
    fr = tracks.fr
    out: dict[_Entry, bool] = {}
    judged: list[_Entry] = []
    pairings: list[tuple[NDArray[np.intp], NDArray[np.intp]]] = []
    heights: list[float] = []
    for entry in entries:
        (_, i, j, start, end), _, _ = entry
        out[entry] = False
        if end - start + 1 > config.max_window:
            continue
        segments = []
        for t in (i, j):
            rows = tracks.observed[t]
            f = fr[rows]
            b0, b1 = np.searchsorted(f, (start - config.span, start), side="left")
            a0, a1 = np.searchsorted(f, (end, end + config.span), side="right")
            segments.append((rows[b0:b1], rows[a0:a1]))
        (bi, ai), (bj, aj) = segments
        if min(len(bi), len(ai), len(bj), len(aj)) < config.min_points:
            continue
        height = median(cz[np.concatenate([bi, ai, bj, aj]), 3])
        if not height > 0:
            continue
        judged.append(entry)
        pairings += [(bi, ai), (bj, aj), (bi, aj), (bj, ai)]  # kept, kept, exchanged, exchanged
        heights += [height] * 4
    if judged:
        nll = _after_nll(fr, cz, pairings, np.array(heights), config).reshape(-1, 4)
        better = nll[:, 0] + nll[:, 1] - nll[:, 2] - nll[:, 3] > config.margin
        out.update(zip(judged, better.tolist(), strict=True))
    return out


def _after_nll(
    fr: F64,
    cz: F64,
    pairings: list[tuple[NDArray[np.intp], NDArray[np.intp]]],
    heights: F64,
    c: CrossingConfig,
) -> F64:
    """Negative log-likelihood of each pairing's after rows given its before rows.

    The package's constant-velocity Kalman filter (:mod:`pftrack.kalman`) per axis (centre x,
    y, width, height; in the pairing's `heights`), started at the first before row with a wide
    velocity prior. The pairings run together, :data:`NLL_BLOCK` steps times pairings at a
    time, padded with steps of zero frames and no measurement (which change nothing), so each
    pairing gets the floats it gets alone (was: one window's four at a time).
    """
    n_before = np.array([len(b) for b, _ in pairings], dtype=np.intp)
    n_all = n_before + np.array([len(f) for _, f in pairings], dtype=np.intp)
    q = np.array([c.accel, c.accel, c.size_accel, c.size_accel]) ** 2
    r2 = np.array([c.noise, c.noise, c.size_noise, c.size_noise]) ** 2
    out = np.zeros(len(pairings))
    for lo, hi in _nll_blocks(n_all):
        lengths, m, length = n_all[lo:hi], hi - lo, int(n_all[lo:hi].max())
        rows = np.concatenate([s for pairing in pairings[lo:hi] for s in pairing])
        col = np.repeat(np.arange(m), lengths)
        step = np.arange(len(rows)) - np.repeat(np.cumsum(lengths) - lengths, lengths)
        dt = np.zeros((length, m))
        zs = np.zeros((length, m, 4))
        has = np.zeros((length, m), dtype=bool)
        counts = np.zeros((length, m), dtype=bool)
        later = step > 0  # dt: each row's frame minus its predecessor's in the pairing
        f = fr[rows]
        dt[step[later], col[later]] = f[1:][later[1:]] - f[:-1][later[1:]]
        zs[step, col] = cz[rows] / heights[lo:hi][col][:, None]
        has[step, col] = True
        counts[step, col] = step >= n_before[lo:hi][col]
        mean: Mean = (zs[0].copy(), np.zeros((m, 4)))
        cov: Cov = (np.broadcast_to(r2, (m, 4)).copy(), np.zeros((m, 4)), np.full((m, 4), 100.0))
        nll = out[lo:hi]  # a view: accumulated in place
        for t in range(1, length):
            mean, cov = _nll_step(mean, cov, nll, dt[t], zs[t], has[t], counts[t], q, r2)
    return out


def _nll_step(
    mean: Mean,
    cov: Cov,
    nll: F64,
    dt: F64,
    z: F64,
    has: NDArray[np.bool_],
    counts: NDArray[np.bool_],
    q: F64,
    r2: F64,
) -> tuple[Mean, Cov]:
    """One step of :func:`_after_nll` for m pairings, `nll` (m,) added to in place.

    Predict by `dt` (m,); where `counts`, add the innovation's negative log-density of `z`
    (m, 4); update where `has`.
    """
    mean, cov = _cv_predict(mean, cov, q, dt[:, None])
    s = cov[0] + r2
    e = z - mean[0]
    nll += np.where(counts, 0.5 * np.sum(e * e / s + np.log(2 * np.pi * s), axis=1), 0.0)
    return _cv_update_where(mean, cov, z, r2, has[:, None])


def _nll_blocks(lengths: NDArray[np.intp]) -> Iterator[tuple[int, int]]:
    """Blocks ``[lo, hi)`` of consecutive pairings, for :func:`_after_nll`.

    Each at most :data:`NLL_BLOCK` steps (its longest pairing's) times pairings, one at least.
    """
    lo = 0
    while lo < len(lengths):
        hi, longest = lo + 1, int(lengths[lo])
        while hi < len(lengths) and max(longest, lengths[hi]) * (hi + 1 - lo) <= NLL_BLOCK:
            longest = max(longest, int(lengths[hi]))
            hi += 1
        yield lo, hi
        lo = hi


def smoothed_copies(rows: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Which values of :func:`smooth_tracks`' `rows` (M, 10) are copies of given values.

    The ``conf`` and columns 8-10 of every row (a filled row's: a neighbour's ``conf``, then the
    filled mark); the boxes are the smoother's. ``write_mot(path, rows,
    exact=smoothed_copies(rows))`` writes the given values with all their digits, as
    ``pftrack smooth`` does.
    """
    if not isinstance(rows, np.ndarray):
        raise TypeError(f"smoothed_copies: rows must be an (M, 10) array, got {shown(rows)}")
    if rows.ndim != 2:  # was: NumPy's IndexError ("too many indices for array")
        raise ValueError(f"smoothed_copies: rows has shape {rows.shape}, expected (M, 10)")
    mask = np.zeros(rows.shape, dtype=bool)
    mask[:, 6:] = True
    return mask


def smooth_tracks(
    rows: ArrayLike,
    observed: ArrayLike | None = None,
    smoother: BoxSmoother | None = BoxSmoother(),  # noqa: B008 - frozen, shared safely
    link: LinkConfig | Literal["auto"] | None = "auto",
    measurements: ArrayLike | None = None,
    *,
    fill_method: RecoveryMethod = DEFAULT_METHOD,
    seed: int = 0,
    crossings: CrossingConfig | None = None,
    relink_coast: int | None = None,
    max_gap: IntLike | None = None,
    frames: Sequence[NDArray[np.uint8]] | None = None,
    histograms: ArrayLike | None = None,
    colour: str = "both",
) -> F64:
    """Offline pass over any tracker's MOTChallenge rows: link fragments, fill holes, smooth.

    Parameters
    ----------
    rows : (M, 6..10) array_like
        ``frame, id, left, top, width, height, conf, x, y, z`` rows, one per (frame, id).
        Rows of 6 to 9 columns get the columns a file's shorter lines get (conf 1, x, y,
        z -1: :func:`pftrack._check.mot_rows`), as ``pftrack smooth`` reads them; an empty
        array (``[]``) is no rows.
    observed : (M,) array_like of bool, optional
        Which rows are detections; the others (e.g. a tracker's coasting boxes) are
        interpolated by the smoother. Default: every row.
    smoother : BoxSmoother or None
        None links only (and fills nothing).
    link : LinkConfig, "auto" or None
        Join fragments of one object first (:func:`pftrack.recovery.linking.link_tracklets`)
        with these gates. ``"auto"`` (default): those of ``pftrack smooth``,
        ``LinkConfig(max_gap=max_gap)`` (30 when `max_gap` is None) with the 50 px gate grown
        to the frame the rows' boxes span (:func:`pftrack.recovery.linking.link_config_for`,
        :func:`~pftrack.recovery.linking.gate_for_rows`: as given up to 640x480, in proportion
        to the diagonal above), so ``smooth_tracks(rows)`` is the command's pass; a LinkConfig
        is used as given (:class:`TrackWriter` passes the tracker's, scaled by the frames it
        saw). With a smoother, frames missing inside a track (holes of at most ``link.max_gap``
        frames; longer holes stay holes, so work and memory are bounded by the number of rows)
        are added as rows recovered by `fill_method`
        (:func:`pftrack.recovery.fill.fill_rows`, the default of ``pftrack recover``), shifted
        by the smoother's correction of the boxes on each side, and flagged in column 8
        (1-based) as pftrack's filled rows are (:data:`pftrack.recovery.linking.FLAG_COLUMN`).
        None keeps ids, and holes unless `max_gap` is given.
    measurements : (M, 4) array_like, optional
        The boxes the smoother fits at observed rows, when they differ from the rows' own
        (which linking uses): e.g. raw detections behind a tracker's filtered boxes.

    fill_method : str
        Recovery method of the holes (one of :data:`pftrack.recovery.METHODS`); default
        ``"auto"``, calibrated on the rows themselves.
    seed : int
        Seed of ``"auto"``'s calibration.
    crossings : CrossingConfig or None
        When given and enabled, after linking, tracks whose identities the tracker swapped
        where they crossed get their tails exchanged back (:func:`repair_crossings`; the rows'
        boxes find the crossings, `measurements` are the evidence). None: off.
    relink_coast : int or None
        With `link`, before linking: where an observed row follows at least this many
        unobserved rows of its track, the track is cut there and those rows are left out
        (:func:`split_refound`), so that the linker decides whether the two pieces are one
        object; a kept join gets the hole filled as any other. None (default): off.
    max_gap : int or None
        With a smoother: fill the holes of at most this many frames inside each id's track,
        as `link` does (an int in ``1..MAX_GAP_LIMIT``; ``pftrack smooth --no-link`` passes
        it without `link`). None (default): ``link.max_gap``, and no filling without `link`.
        A hole longer than the filling's gap is not bridged by the smoother either: the
        track is smoothed in pieces split there (``BoxSmoother.max_hole`` at most that gap).
    frames : sequence of (H, W, 3) uint8, optional
        The video's BGR frames (index ``frame - 1``), in the rows' pixels: the linker's colour
        term (:func:`~pftrack.recovery.linking.link_tracklets`) and the fill's swap rule (a
        hole whose sides each look more like another object is left unfilled,
        :func:`pftrack.recovery.fill.swap_holes`), on the boxes the smoother fits. None
        (default): motion and size only, as the tracker's own pass (docs/recovery.md,
        "Colour in the offline pass").
    histograms : (M, B) array_like, optional
        Each row's colour histogram, instead of `frames` (not both): a tracker's own, e.g. the
        detection it matched (:class:`TrackWriter` with ``colour``); a row of zeros has none
        and is not judged. Used as `frames`' histograms would be
        (:class:`~pftrack.recovery.linking.RowColours`), for the rows' boxes and
        `measurements` alike; no frame is read.
    colour : {"both", "swap", "link"}
        What the colour of `frames` or `histograms` is given to: the linker's colour term and
        the fill's swap rule (default), the swap rule alone, or the linker alone.

    Returns
    -------
    (M', 10) ndarray
        The rows, sorted by frame then id. A smoothed track's boxes, filled ones too, are
        never narrower or shorter than half its smallest detected box (:class:`BoxSmoother`).

    Raises
    ------
    TypeError
        `link` not a LinkConfig, ``"auto"`` or None; `smoother` or `crossings` not a
        BoxSmoother or CrossingConfig or None; `observed` not of bool.
    ValueError
        Rows not ``(M, 6..10)``, a frame that is not an integer in ``1..2**31-1``, a
        non-integer id, a non-finite box, a box (of the rows or `measurements`) that
        :func:`pftrack.io.mot.read_mot` refuses (a negative width or height, a value beyond
        ±1e9 px), `observed` / `measurements` of the wrong shape, or `max_gap` outside
        ``1..MAX_GAP_LIMIT`` (TypeError: not None or an int).
    """
    if max_gap is not None:
        max_gap = _check.integer(max_gap, "smooth_tracks: max_gap", 1, MAX_GAP_LIMIT)
    _check.option(fill_method, "smooth_tracks: fill_method", METHODS)
    if fill_method not in METHODS:  # was named as fill_gaps' method, and only with holes
        raise ValueError(
            f"smooth_tracks: fill_method is {fill_method!r}, expected one of {METHODS}"
        )
    seed = _check.seed(seed, "smooth_tracks: seed")
    if not (
        link is None or isinstance(link, LinkConfig) or (isinstance(link, str) and link == "auto")
    ):
        raise TypeError(
            f"smooth_tracks: link must be a LinkConfig, 'auto' or None, got {_check.shown(link)}"
        )
    if crossings is not None and not isinstance(crossings, CrossingConfig):
        raise TypeError(
            "smooth_tracks: crossings must be a CrossingConfig or None, got "
            f"{type(crossings).__name__}"
        )
    if smoother is not None and not isinstance(smoother, BoxSmoother):
        raise TypeError(
            f"smooth_tracks: smoother must be a BoxSmoother or None, got {type(smoother).__name__}"
        )
    a: F64 = check_rows(rows, "smooth_tracks")
    check_unique(a, who="smooth_tracks")  # was: BoxSmoother.smooth's "frames must be ..."
    check_tracked(a, who="smooth_tracks")
    a = a.copy()
    obs = np.ones(len(a), dtype=bool) if observed is None else np.asarray(observed)
    if obs.dtype != np.bool_:  # 0.5 or NaN would read as True
        raise TypeError(f"smooth_tracks: observed must be an array of bool, got dtype {obs.dtype}")
    if obs.shape != (len(a),):
        raise ValueError(f"smooth_tracks: observed has shape {obs.shape}, expected ({len(a)},)")
    if len(a) == 0:
        return a
    if measurements is None:
        z = a[:, 2:6].copy()
    else:
        # was: "could not convert string to float: 'abc'", naming nothing
        z = np.array(real_array(measurements, "smooth_tracks: measurements"))
    if z.shape != (len(a), 4):
        raise ValueError(f"smooth_tracks: measurements has shape {z.shape}, expected ({len(a)}, 4)")
    check_boxes(z, a, "smooth_tracks", "measurements")  # boxes of filled rows, as the rows'
    if relink_coast is not None and (
        isinstance(relink_coast, bool)
        or not isinstance(relink_coast, (int, np.integer))
        or relink_coast < 1
    ):
        raise ValueError(
            f"smooth_tracks: relink_coast is {brief(relink_coast)}, expected None or an int >= 1"
        )
    option(colour, "smooth_tracks: colour", COLOUR_USES)
    if colour not in COLOUR_USES:
        raise ValueError(f"smooth_tracks: colour is {colour!r}, expected one of {COLOUR_USES}")
    stored: RowColours | None = None
    if histograms is not None:
        if frames is not None:
            raise ValueError("smooth_tracks: give frames or histograms, not both")
        h = np.asarray(real_array(histograms, "smooth_tracks: histograms"), dtype=np.float64)
        if h.ndim != 2 or len(h) != len(a):
            raise ValueError(
                f"smooth_tracks: histograms has shape {h.shape}, expected ({len(a)}, B)"
            )
        if not (h.min(initial=0.0) >= 0 and h.max(initial=0.0) < np.inf):
            raise ValueError("smooth_tracks: histograms must be finite and >= 0")
        stored = RowColours(a, h, z)  # looked up by box: ids change below, boxes do not
    if isinstance(link, str):  # "auto": pftrack smooth's gate, grown to the rows' frame
        link = link_config_for(a, DEFAULT_MAX_GAP if max_gap is None else max_gap)
    fill_gap = max_gap if max_gap is not None else None if link is None else link.max_gap
    if link is not None and relink_coast is not None:
        a, obs, z = split_refound(a, obs, z, relink_coast)
    if frames is not None and not isinstance(frames, BoxColours):
        # the linker's frames and the holes' sides in one decode, the boxes linked (the rows')
        # and filled (the measured ones) both binned
        wanted = set() if link is None else link_frames(a, link)
        if fill_gap is not None:
            wanted |= side_frames(a, fill_gap)
        measured = a.copy()
        measured[:, 2:6] = z
        frames = BoxColours(frames, np.vstack([a, measured]), wanted)
    if stored is not None:
        frames = stored
    link_colour = frames if colour in ("both", "link") else None
    fill_colour = frames if colour in ("both", "swap") else None
    if link is not None:
        a, _ = link_tracklets(a, link, link_colour)
    if crossings is not None and crossings.enabled:
        a = repair_crossings(a, obs, crossings, z)
    order = np.lexsort((a[:, 0], a[:, 1]))  # by id, then frame
    a, obs, z = a[order], obs[order], z[order]
    new = np.zeros(len(a), dtype=bool)
    if smoother is not None and fill_gap is not None:
        a, obs, z, new = _add_hole_rows(a, obs, z, fill_gap, fill_method, seed, fill_colour)
        # a hole left unfilled is no bridge for the smoother either: its two sides are
        # smoothed apart (was: joined through holes of up to max_hole = 300 frames, so an id a
        # tracker gave a second, still person 41 frames later bent both people's boxes by 10 px)
        smoother = replace(smoother, max_hole=min(smoother.max_hole, fill_gap))
    if smoother is not None:
        starts = np.flatnonzero(np.r_[True, a[1:, 1] != a[:-1, 1], True])
        spans = list(zip(starts[:-1], starts[1:], strict=True))
        for i, j in progress(spans, desc="smoothing", unit="track"):
            if obs[i:j].any():
                sm = smoother.smooth(a[i:j, 0], z[i:j], obs[i:j])
                nw = new[i:j]
                if nw.any() and not nw.all():  # filled rows: the recovered path, shifted as
                    # the smoother shifted the boxes on both sides of each hole
                    shift = sm[~nw] - z[i:j][~nw]
                    fr = a[i:j, 0]
                    for c in range(4):
                        sm[nw, c] = z[i:j][nw, c] + np.interp(fr[nw], fr[~nw], shift[:, c])
                    # the smoother's size floor (BoxSmoother): a size path that dips between
                    # two ends the smoother shrank could otherwise cross zero
                    floor = 0.5 * z[i:j][obs[i:j], 2:].min(axis=0)
                    sm[nw, 2:] = np.maximum(sm[nw, 2:], floor)
                a[i:j, 2:6] = sm
    out: F64 = a[np.lexsort((a[:, 1], a[:, 0]))]
    return out


def drop_nested(rows: ArrayLike, inside: float = 0.8, area_ratio: float = 1.5) -> F64:
    """Leave out every box that lies mostly inside a larger box of the same frame.

    A row is dropped when more than `inside` of its box's area lies inside the box of another
    row of the same frame whose area is more than `area_ratio` times its own. Background
    subtraction sees one silhouette per connected region, so such a box is a fragment of the
    larger object (a limb, a piece cut off by the shadow test, a track that bridged into
    what became part of another blob), not a person of its own: another detector's boxes
    inside a larger one are often partly hidden people, and are not to be dropped this way.

    Parameters
    ----------
    rows : (M, 6..10) array_like
        MOTChallenge rows ``frame, id, left, top, width, height, ...`` (fewer than 10
        columns: completed as a file's lines, :func:`pftrack._check.mot_rows`).
    inside : float
        Share of a box's area, in (0, 1].
    area_ratio : float
        How much larger the covering box must be, at least 1 (then equal boxes never drop each
        other).

    Returns
    -------
    (M', 10) ndarray
        The rows kept, in their order.

    Raises
    ------
    ValueError
        Bad rows, `inside` outside (0, 1] or `area_ratio` below 1.
    """
    _check.number(inside, "drop_nested: inside", finite=False)  # an array: ambiguous below
    _check.number(area_ratio, "drop_nested: area_ratio", finite=False)
    if not 0.0 < inside <= 1.0:
        raise ValueError(f"drop_nested: inside is {inside}, expected a value in (0, 1]")
    if not 1.0 <= area_ratio < np.inf:
        raise ValueError(f"drop_nested: area_ratio is {area_ratio}, expected a finite value >= 1")
    a: F64 = check_rows(rows, "drop_nested")
    drop = np.zeros(len(a), dtype=bool)
    box = a[:, 2:6]
    area = box[:, 2] * box[:, 3]
    # every pair of rows of one frame at once (was a loop over the frames, 16 ms of PETS09's
    # 4500 rows): the same operations on each pair
    for i, j in _frame_pairs(a[:, 0]):
        overlap = _intersection(box[i], box[j])  # area of box i inside box j
        covered = (overlap > inside * area[i]) & (area[j] > area_ratio * area[i])
        drop[i[covered]] = True
    return a[~drop]


def drop_odd_sizes(
    rows: ArrayLike,
    sizes: ArrayLike,
    ratio: float,
    frame_height: float | None = None,
    classes: Mapping[int, int] | None = None,
) -> F64:
    """Leave out every track whose boxes are far smaller or larger than the detections' people.

    A Theil-Sen line of box height against foot row (``top + height``) is fitted to the run's
    detections of each class (`sizes`; at most 1500 of them, evenly spaced in their order). A
    track whose median of ``height / expected height at its foot row`` over its rows is below
    `ratio` or above ``1 / ratio`` is left out whole: a person detector's confident false
    boxes that a track followed (a part of a person, something that is no person) are sized
    unlike the people at their row (docs/tracking.md, "Tracks sized unlike
    the scene's people"). Boxes whose foot lies within 2 px of the frame's last row (cut by
    the frame) are not used, neither for the line nor for a track's ratio; the line's expected
    height is at least 1 px. The line is not extrapolated: a row whose foot row lies outside
    the 5th-95th percentile of the foot rows the line was fitted to is not judged. A track with
    no row left to judge, and every track of a class with fewer than 30 usable detections, is
    kept. Nor is a class judged whose detections' heights the line does not explain
    (:func:`size_line`): unless the band ``[ratio, 1 / ratio]`` reaches, either side of the line,
    `SIZE_SPREADS` (2) robust spreads of ``log(height / line)`` plus half the drift of that log
    ratio over the run (`sizes` with frames), the class's tracks are all kept (people whose
    sizes do not follow their row, or a camera that zooms while the line is fitted).

    Parameters
    ----------
    rows : (M, 6..10) array_like
        MOTChallenge rows ``frame, id, left, top, width, height, ...`` of finished tracks.
    sizes : (K, 2), (K, 3) or (K, 4) array_like
        ``foot row, height[, class[, frame]]`` of the run's detection boxes, in the rows'
        pixels (without frames: no drift is measured).
    ratio : float
        In (0, 1).
    frame_height : float, optional
        The frame's height in the rows' pixels (None: no box is taken as cut by the frame).
    classes : mapping of int to int, optional
        The class of each id of `rows` (None or a missing id: class 0).

    Returns
    -------
    (M', 10) ndarray
        Every row of the tracks kept, in the order of `rows`.

    Raises
    ------
    TypeError
        `ratio` is not a number.
    ValueError
        Bad rows or sizes, or `ratio` outside (0, 1).
    """
    _check.number(ratio, "drop_odd_sizes: ratio", finite=False)
    if not 0.0 < ratio < 1.0:
        raise ValueError(f"drop_odd_sizes: ratio is {ratio}, expected a value in (0, 1)")
    a: F64 = check_rows(rows, "drop_odd_sizes")
    s = np.asarray(sizes, dtype=np.float64)
    if s.ndim != 2 or s.shape[1] not in (2, 3, 4) or not np.isfinite(s).all():
        raise ValueError(
            f"drop_odd_sizes: sizes has shape {s.shape}, expected (K, 2), (K, 3) or (K, 4) "
            "finite rows foot row, height[, class[, frame]]"
        )
    if len(a) == 0 or len(s) == 0:
        return a
    det_cls = s[:, 2] if s.shape[1] >= 3 else np.zeros(len(s))
    foot, height = a[:, 3] + a[:, 5], a[:, 5]
    usable = (s[:, 1] > 0) & (frame_height is None or s[:, 0] < frame_height - BOTTOM_EDGE)
    rows_in = np.ones(len(a), bool) if frame_height is None else foot < frame_height - BOTTOM_EDGE
    own = classes or {}
    row_cls = np.array([own.get(int(i), 0) for i in a[:, 1]], np.float64)
    drop = np.zeros(len(a), dtype=bool)
    for c in np.unique(row_cls):
        k = usable & (det_cls == c)
        if k.sum() < MIN_SIZE_SAMPLES or np.ptp(s[k, 0]) == 0:
            continue
        x, h = s[k, 0], s[k, 1]
        pick = np.linspace(0, len(x) - 1, min(len(x), SIZE_SAMPLES)).astype(np.int64)
        frame = s[k, 3][pick] if s.shape[1] == 4 else None
        slope, intercept, spread, drift = size_line(x[pick], h[pick], frame)
        if SIZE_SPREADS is not None and SIZE_SPREADS * spread + abs(drift) / 2 > -np.log(ratio):
            continue  # the line does not explain the heights: nothing of the class is judged
        expected = np.maximum(slope * foot + intercept, 1.0)
        judged = (row_cls == c) & rows_in
        if SIZE_ROWS is not None:
            lo, hi = np.percentile(x[pick], SIZE_ROWS)
            judged &= (foot >= lo) & (foot <= hi)
        ids, q = _medians_by_id(a[judged, 1], height[judged] / expected[judged])
        odd = ids[(q < ratio) | (q > 1.0 / ratio)]
        if len(odd):
            drop |= np.isin(a[:, 1], odd)
    return a[~drop]


def _medians_by_id(ids: F64, values: F64) -> tuple[F64, F64]:
    """Each distinct id of `ids` (sorted) and the median of its `values`.

    One sort for all ids (``np.median`` per id would read every row once per id): the middle
    value of an odd count, the mean ``(a + b) / 2`` of the two middle ones of an even count,
    as ``np.median`` computes them.
    """
    order = np.lexsort((values, ids))
    v = values[order]
    uid, start, count = np.unique(ids[order], return_index=True, return_counts=True)
    lo = start + (count - 1) // 2
    hi = start + count // 2
    return uid, (v[lo] + v[hi]) / 2.0


def size_line(
    foot: ArrayLike, height: ArrayLike, frame: ArrayLike | None = None
) -> tuple[float, float, float, float]:
    """The height-for-row line of detections and how well it explains their heights.

    A Theil-Sen line of `height` against `foot` row; then, of the log ratio
    ``r = log(height / line)`` (the line's height at least 1 px), its robust spread
    ``1.4826 * MAD(r)`` (a normal law's standard deviation) and its drift over the run: the
    Theil-Sen slope of ``r`` against `frame`, times the frames the detections span (0 without
    frames, or all in one frame). A still camera's view of people of one size walking on a
    ground plane gives a small spread and no drift; people whose sizes do not follow their row
    give a wide spread, and a camera that zooms during the run gives a drift.
    `drop_odd_sizes` judges a class's tracks only if ``SIZE_SPREADS * spread + |drift| / 2``
    is at most ``log(1 / ratio)``: a person following the line two spreads from it, at either
    end of the run, still lies inside the band.

    Parameters
    ----------
    foot, height : (n,) array_like of float
        Foot rows (``top + height``) and heights (> 0) of detection boxes, at least two distinct
        foot rows.
    frame : (n,) array_like of float, optional
        The frame of each box.

    Returns
    -------
    slope, intercept, spread, drift : float
        The line (height = slope * foot + intercept), the spread and the drift of the log
        ratio.

    Raises
    ------
    ValueError
        Arrays of different lengths or not finite, a height not positive, or no two distinct
        foot rows.

    References
    ----------
    .. [1] Sen, P. K. (1968). Estimates of the regression coefficient based on Kendall's tau.
       JASA 63(324).
    """
    x = np.asarray(foot, np.float64)
    h = np.asarray(height, np.float64)
    t = None if frame is None else np.asarray(frame, np.float64)
    if x.ndim != 1 or h.shape != x.shape or (t is not None and t.shape != x.shape):
        got = f"{x.shape}, {h.shape}" + ("" if t is None else f", {t.shape}")
        raise ValueError(f"size_line: foot, height[, frame] have shapes {got}, expected (n,) each")
    if not (np.isfinite(h).all() and (h > 0).all()):
        raise ValueError("size_line: height has values not finite or not positive")
    if t is not None and not np.isfinite(t).all():
        raise ValueError("size_line: frame has values not finite")
    slope, intercept = theil_sen(x, h)
    r = np.log(h / np.maximum(slope * x + intercept, 1.0))
    spread = 1.4826 * float(np.median(np.abs(r - np.median(r))))
    drift = 0.0
    if t is not None and np.ptp(t) > 0:
        drift = theil_sen(t, r)[0] * float(np.ptp(t))
    return float(slope), float(intercept), spread, float(drift)


def complete_boxes(
    rows: ArrayLike,
    lines: ArrayLike,
    share: float,
    anchor: str = "side",
    max_width: float = 1.6,
    frame_height: float | None = None,
    ill_posed: str = "complete",
) -> F64:
    """Complete the boxes of partly seen people to the expected person box (amodal boxes).

    Background subtraction boxes only what it sees of a person: one half hidden behind a nearer
    person, or cut by the shadow test, gets a box narrower and shorter than the whole person
    that ground truth (and a person detector) draws. With the person-size model's lines
    (`pftrack.detection.size_model.PersonSizeModel.coefficients`: height and width as lines in
    the foot row), each box is compared with the person whose head is at its top row ``y``:
    height ``h_e`` solving ``h = h_intercept + h_slope (y + h)`` (as
    `PersonSizeModel.extend_legs`), width ``w_e`` the width line at that person's foot row.

    * A box shorter than ``share * h_e`` gets height ``h_e``, its top kept (the head).
    * A box narrower than ``share * w_e`` gets width ``w_e`` (``w_e`` taken at the new foot
      row). With ``anchor="side"``, when exactly one of its sides lies inside another box of
      the same frame (overlapping it in rows too), that side is the hidden one: the box grows
      towards it and keeps the other edge; otherwise (and with ``anchor="centre"``) it keeps
      its centre.
    * A box wider than ``max_width * w_e`` (a group, which the detector cuts at
      ``SizeModelConfig.split_ratio``) and a box whose ``h_e`` is not positive (a head below
      the horizon; or ``h_slope = 1``) are left as they are. No box shrinks.
    * A box whose top lies at the frame's top edge (``top <= TOP_EDGE`` px) is left alone: the
      frame cut it there, its top is no head (a person walking in from above). With
      `frame_height`, so is a box whose expected person would have its feet below the frame's
      bottom row (``top + h_e > frame_height``): a person the model extrapolates to beyond the
      rows it saw (a height slope near 1 gave 2 700 px people in a 360 px frame).
    * With ``ill_posed="leave"``, a box whose ``h_e`` one pixel of its top row (or of the height
      line's intercept) moves by more than ``(1 - share)`` of its own height (by
      ``max(1, |h_slope|) / |1 - h_slope|`` px: a slope near 1) is left alone: a pixel would
      decide whether, and to what, it is completed. ``Tracker.finalize()`` asks for this when
      the size model's fits disagree (`PersonSizeModel.fits_agree`).

    Parameters
    ----------
    rows : (M, 6..10) array_like
        MOTChallenge rows ``frame, id, left, top, width, height, ...`` (fewer than 10
        columns: completed as a file's lines, :func:`pftrack._check.mot_rows`).
    lines : (2, 2) array_like
        ``[[h_slope, h_intercept], [w_slope, w_intercept]]`` in the foot row.
    share : float
        Share of the expected height (and width) below which a box is completed, in (0, 1].
    anchor : {"side", "centre"}
        Which edge a widened box keeps (see above).
    max_width : float
        Boxes wider than this many expected widths are groups, left alone (>= 1).
    frame_height : float or None
        The frame's height in pixels (> 0), when known: see above.
    ill_posed : {"complete", "leave"}
        What is done with a box whose head row cannot give a height (see above).

    Returns
    -------
    (M, 10) ndarray
        The rows in their order, only ``left``, ``width`` and ``height`` changed.

    Raises
    ------
    ValueError
        Bad rows or lines, or `share`, `anchor`, `max_width`, `frame_height` or `ill_posed`
        out of range.
    """
    _check.number(share, "complete_boxes: share", finite=False)  # an array: ambiguous below
    _check.number(max_width, "complete_boxes: max_width", finite=False)
    if not 0.0 < share <= 1.0:
        raise ValueError(f"complete_boxes: share is {share}, expected a value in (0, 1]")
    _check.option(anchor, "complete_boxes: anchor", AMODAL_ANCHORS)
    _check.option(ill_posed, "complete_boxes: ill_posed", ILL_POSED)
    if ill_posed not in ILL_POSED:
        raise ValueError(f"complete_boxes: ill_posed is {ill_posed!r}, expected one of {ILL_POSED}")
    if anchor not in AMODAL_ANCHORS:
        raise ValueError(f"complete_boxes: anchor is {anchor!r}, expected one of {AMODAL_ANCHORS}")
    if not 1.0 <= max_width < np.inf:
        raise ValueError(f"complete_boxes: max_width is {max_width}, expected a finite value >= 1")
    if frame_height is not None:
        frame_height = _check.real(frame_height, "complete_boxes: frame_height")
        if not frame_height > 0.0:
            raise ValueError(
                f"complete_boxes: frame_height is {frame_height}, expected a finite value > 0"
            )
    coef = real_array(lines, "complete_boxes: lines")
    if coef.shape != (2, 2) or not np.all(np.isfinite(coef)):
        raise ValueError(
            f"complete_boxes: lines must be a finite (2, 2) array [[h_slope, h_intercept], "
            f"[w_slope, w_intercept]], got shape {coef.shape}"
        )
    a: F64 = check_rows(rows, "complete_boxes").copy()
    if coef[0, 0] == 1.0 or len(a) == 0:  # h_slope = 1: no head row gives a height
        return a
    x, y, w, h = (a[:, c].copy() for c in range(2, 6))
    h_exp = head_height(coef, y)
    known = (h_exp > 0.0) & (y > TOP_EDGE)  # a top at the frame's edge is no head
    if frame_height is not None:  # nor is a person whose feet are below the frame
        known &= y + h_exp <= frame_height
    if ill_posed == "leave":  # nor a height one pixel of the head row would decide
        s = coef[0, 0]
        known &= max(1.0, abs(s)) / abs(1.0 - s) <= (1.0 - share) * h
    new_h = np.where(known & (h < share * h_exp), h_exp, h)
    w_exp = expected_size(coef, y + new_h)[:, 1]
    person = known & (w <= max_width * w_exp)
    new_h = np.where(person, new_h, h)
    widen = person & (w < share * w_exp)
    new_w = np.where(widen, w_exp, w)
    shift = 0.5 * (w - new_w)  # centred
    if anchor == "side" and widen.any():
        # each widened box against every other box of its frame, all pairs at once
        x1, y1 = x + w, y + h
        hid_l = np.zeros(len(a), dtype=bool)
        hid_r = np.zeros(len(a), dtype=bool)
        for i, j in _frame_pairs(a[:, 0], widen):
            rows_meet = (y[i] < y1[j]) & (y[j] < y1[i]) & (i != j)
            # box i's left (right) edge lies inside box j's columns
            hid_l[i[(x[j] < x[i]) & (x[i] < x1[j]) & rows_meet]] = True
            hid_r[i[(x[j] < x1[i]) & (x1[i] < x1[j]) & rows_meet]] = True
        grow_left = widen & hid_l & ~hid_r  # keep the right edge
        grow_right = widen & hid_r & ~hid_l  # keep the left edge
        shift[grow_left] = (w - new_w)[grow_left]
        shift[grow_right] = 0.0
    a[:, 2] = np.where(widen, x + shift, x)
    a[:, 4] = new_w
    a[:, 5] = new_h
    return a


#: Pairs of rows the offline pass's all-pairs steps make at a time (:func:`_frame_pairs`,
#: :func:`_overlapping_pairs`), at most (unless one row has more: the boxes of its frame).
#: ``drop_nested`` takes about 140 bytes of temporaries a pair, so a block is about 10 MB
#: (was 2**20 pairs in blocks of whole frames: 576 MB for 2000 boxes in one frame; and every
#: overlapping pair at once: 1.5 GB for ``repair_crossings`` on 2000 tracks over 3000
#: frames), the same rows (docs/recovery.md, "The offline pass's other pairs").
PAIR_BLOCK = 1 << 16


def _frame_pairs(
    frames: F64, rows: NDArray[np.bool_] | None = None
) -> Iterator[tuple[NDArray[np.intp], NDArray[np.intp]]]:
    """Row indices ``(i, j)`` of every pair of rows of one frame, ``i == j`` too, in blocks.

    With `rows`, only the pairs whose ``i`` is one of `rows` (a mask). Blocks of consecutive
    ``i`` (by frame, then row) of at most :data:`PAIR_BLOCK` pairs, one ``i`` at least: a
    frame's pairs may be split between blocks, one row's never.
    """
    order = np.argsort(frames, kind="stable")
    f = frames[order]
    starts = np.flatnonzero(np.r_[True, f[1:] != f[:-1]]) if len(f) else np.zeros(0, np.intp)
    sizes = np.diff(np.r_[starts, len(f)])
    first = np.repeat(starts, sizes)  # per position of `order`: its frame's first position
    p_all = np.arange(len(f)) if rows is None else np.flatnonzero(rows[order])  # positions paired
    n_all = np.repeat(sizes, sizes)[p_all]  # each one's pairs: the rows of its frame
    for lo, hi in _pair_blocks(n_all, PAIR_BLOCK):
        p, n = p_all[lo:hi], n_all[lo:hi]
        at = np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)  # 0 .. n - 1 per row
        yield order[np.repeat(p, n)], order[np.repeat(first[p], n) + at]


def split_refound(
    rows: F64, observed: NDArray[np.bool_], measurements: F64, min_unobserved: int
) -> tuple[F64, NDArray[np.bool_], F64]:
    """Cut each track where a detection re-finds it after `min_unobserved` coasted rows or more.

    A tracker's coasting rows (``observed`` False: e.g. a particle filter's boxes while no
    detection matched) may have drifted onto another object, and the detection that re-finds
    the track is then that object's. This cuts the track before such a detection and leaves
    the coasted rows out: the piece after the cut gets a new id (above every id in `rows`), and
    :func:`~pftrack.recovery.linking.link_tracklets` then joins the pieces back only where
    their motion and size say they are one object. Unobserved rows before a track's first
    observed row are kept.

    Parameters
    ----------
    rows : (M, 10) ndarray
        MOTChallenge rows, one per (frame, id).
    observed : (M,) ndarray of bool
        Which rows are detections.
    measurements : (M, 4) ndarray
        Per-row boxes carried along (the smoother's evidence).
    min_unobserved : int
        Fewest consecutive unobserved rows before a detection that cut the track (>= 1).

    Returns
    -------
    rows, observed, measurements
        The kept rows, sorted by id then frame, with the new ids; `observed` and
        `measurements` in the same order.
    """
    if isinstance(min_unobserved, bool) or not isinstance(min_unobserved, (int, np.integer)):
        raise TypeError(f"min_unobserved must be an int, got {type(min_unobserved).__name__}")
    if min_unobserved < 1:
        raise ValueError(f"min_unobserved is {min_unobserved}, expected an integer >= 1")
    order = np.lexsort((rows[:, 0], rows[:, 1]))
    a, obs, z = rows[order].copy(), observed[order], measurements[order]
    n = len(a)
    if n == 0:
        return a, obs, z
    i = np.arange(n)
    start = np.maximum.accumulate(np.where(np.r_[True, a[1:, 1] != a[:-1, 1]], i, 0))
    last_obs = np.maximum.accumulate(np.where(obs, i, -1))  # last observed row at or before i
    prev_obs = np.r_[-1, last_obs[:-1]]  # ... strictly before i
    run = i - prev_obs - 1  # unobserved rows just before row i
    cut = obs & (prev_obs >= start) & (run >= min_unobserved)
    if not cut.any():
        return a, obs, z
    drop = np.zeros(n, dtype=bool)
    for c in np.flatnonzero(cut):
        drop[c - run[c] : c] = True
    count = np.cumsum(cut)  # cuts so far, over all tracks
    piece = count - count[start]  # cuts so far within the row's track (never at its first row)
    top = float(np.max(a[:, 1]))
    if top + count[-1] > MAX_ID:
        raise ValueError(f"split_refound: ids reach {top:.0f}; no room for {count[-1]} new ids")
    a[piece > 0, 1] = top + count[piece > 0]
    keep = ~drop
    return a[keep], obs[keep], z[keep]


def _add_hole_rows(
    a: F64,
    obs: NDArray[np.bool_],
    z: F64,
    max_gap: int,
    method: RecoveryMethod,
    seed: int,
    frames: Sequence[NDArray[np.uint8]] | None = None,
) -> tuple[F64, NDArray[np.bool_], F64, NDArray[np.bool_]]:
    """Add a flagged row for every frame missing inside a track, recovered by `method`.

    Only holes of at most `max_gap` frames are filled, from the measured boxes `z` (observed
    rows) and the rows' own boxes (the others); rows must be sorted by id, then frame, and come
    back so, with a mask of the added rows.
    """
    src = a  # the rows' own boxes when they are the measured ones, bit for bit (smooth's):
    same = z.dtype == a.dtype and np.array_equal(a[:, 2:6].view(np.int64), z.view(np.int64))
    if not same:  # was: always a copy of the rows (50 MB of 630 000 rows at the peak)
        src = a.copy()
        src[:, 2:6] = z
    extra, _ = fill_rows(src, method, max_gap, seed=seed, frames=frames)
    n = len(a)
    if not len(extra):
        return a, obs, z, np.zeros(n, dtype=bool)
    a = np.vstack([a, extra])
    obs = np.concatenate([obs, np.zeros(len(extra), dtype=bool)])
    z = np.vstack([z, extra[:, 2:6]])
    new = np.r_[np.zeros(n, dtype=bool), np.ones(len(extra), dtype=bool)]
    order = np.lexsort((a[:, 0], a[:, 1]))
    return a[order], obs[order], z[order], new[order]
