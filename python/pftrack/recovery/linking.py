"""Tracklet linking and gap filling of any tracker's MOTChallenge output.

Rows are ``(M, 10)`` MOTChallenge arrays ``frame,id,left,top,width,height,conf,x,y,z``.
Filled rows carry the **interpolated flag in column 8** (1-based; index 7, the world-``x``
column, which is -1 in 2D MOTChallenge files): ``1`` on every row pftrack filled, observed rows
untouched. Rows already flagged count as observed when a file is processed again, so running
the fill twice changes nothing more.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pftrack.recovery.methods import METHODS, NoiseEstimate, estimate_noise, recover_gaps
from pftrack.recovery.mixture import fit_motion

F64 = NDArray[np.float64]
FLAG_COLUMN = 7  #: 0-based index of the interpolated flag (column 8 of a MOTChallenge row)


@dataclass(frozen=True)
class LinkConfig:
    """Gates and weights of the linking cost.

    Attributes
    ----------
    max_gap : int
        Largest number of missing frames between two fragments that may be joined.
    max_distance : float
        Gate (pixels) on the distance between a fragment's motion prediction and the other
        fragment's first (or, backwards, last) box centre.
    w_gap, w_size, w_appearance : float
        Weights of the time gap (as a fraction of `max_gap`), the box-height log ratio and the
        colour-histogram Bhattacharyya distance; the motion term (mean prediction distance over
        `max_distance`) has weight 1.
    velocity_points : int
        Points used to fit each fragment's end velocity.
    """

    max_gap: int = 30
    max_distance: float = 50.0
    w_gap: float = 0.5
    w_size: float = 1.0
    w_appearance: float = 1.0
    velocity_points: int = 5


def _centres(rows: F64) -> F64:
    return np.column_stack(
        [rows[:, 0], rows[:, 2] + 0.5 * rows[:, 4], rows[:, 3] + 0.5 * rows[:, 5]]
    )


def _end_velocity(c: F64, k: int, tail: bool) -> F64:
    part = c[-k:] if tail else c[:k]
    if len(part) < 2:
        return np.zeros(2)
    t = part[:, 0] - part[:, 0].mean()
    denom = float(np.sum(t * t))
    return np.asarray((t @ (part[:, 1:3] - part[:, 1:3].mean(axis=0))) / denom, dtype=np.float64)


def split_tracks(rows: F64) -> dict[int, F64]:
    """Rows of each id, sorted by frame."""
    out: dict[int, F64] = {}
    for tid in np.unique(rows[:, 1]).astype(np.int64):
        r = rows[rows[:, 1] == tid]
        out[int(tid)] = r[np.argsort(r[:, 0], kind="stable")]
    return out


def _histogram(frame: NDArray[np.uint8], row: F64) -> NDArray[np.float32] | None:
    import cv2

    h, w = frame.shape[:2]
    x0, y0 = max(int(row[2]), 0), max(int(row[3]), 0)
    x1, y1 = min(int(row[2] + row[4]), w), min(int(row[3] + row[5]), h)
    if x1 - x0 < 2 or y1 - y0 < 2:
        return None
    hsv = cv2.cvtColor(np.ascontiguousarray(frame[y0:y1, x0:x1]), cv2.COLOR_BGR2HSV)
    hist = cv2.calcHist([hsv], [0, 1], None, [8, 8], [0, 180, 0, 256])
    total = float(hist.sum())
    return None if total <= 0 else np.asarray(hist / total, dtype=np.float32)


def link_cost_matrix(
    tracks: dict[int, F64],
    config: LinkConfig = LinkConfig(),
    frames: Sequence[NDArray[np.uint8]] | None = None,
) -> tuple[list[int], F64]:
    """Cost of joining the end of fragment i to the start of fragment j (``inf`` when gated).

    Returns the ids (row i and column j both index this list) and the ``(K, K)`` cost matrix.
    `frames`, when given, is indexable by ``frame - 1`` (BGR images) and adds a colour term.
    """
    ids = list(tracks)
    k = len(ids)
    cost = np.full((k, k), np.inf)
    cent = {t: _centres(r) for t, r in tracks.items()}
    hists: dict[tuple[int, bool], NDArray[np.float32] | None] = {}

    def hist(tid: int, last: bool) -> NDArray[np.float32] | None:
        key = (tid, last)
        if key not in hists:
            row = tracks[tid][-1 if last else 0]
            f = int(row[0]) - 1
            ok = frames is not None and 0 <= f < len(frames)
            hists[key] = _histogram(frames[f], row) if ok and frames is not None else None
        return hists[key]

    for i, ti in enumerate(ids):
        ci = cent[ti]
        end = ci[-1]
        vi = _end_velocity(ci, config.velocity_points, True)
        for j, tj in enumerate(ids):
            if i == j:
                continue
            cj = cent[tj]
            gap = cj[0, 0] - end[0]
            if gap <= 0 or gap - 1 > config.max_gap:
                continue
            vj = _end_velocity(cj, config.velocity_points, False)
            fwd = np.hypot(*(end[1:3] + vi * gap - cj[0, 1:3]))
            bwd = np.hypot(*(cj[0, 1:3] - vj * gap - end[1:3]))
            d = 0.5 * (fwd + bwd)
            if d > config.max_distance:
                continue
            c = d / config.max_distance + config.w_gap * (gap - 1) / max(config.max_gap, 1)
            hi, hj = tracks[ti][-1, 5], tracks[tj][0, 5]
            if hi > 0 and hj > 0:
                c += config.w_size * abs(float(np.log(hi / hj)))
            if frames is not None and config.w_appearance > 0:
                a, b = hist(ti, True), hist(tj, False)
                if a is not None and b is not None:
                    bc = float(np.sum(np.sqrt(a * b)))
                    c += config.w_appearance * float(np.sqrt(max(1.0 - bc, 0.0)))
            cost[i, j] = c
    return ids, cost


def link_tracklets(
    tracks: F64,
    config: LinkConfig = LinkConfig(),
    frames: Sequence[NDArray[np.uint8]] | None = None,
) -> tuple[F64, dict[int, int]]:
    """Join fragments of one object: Hungarian assignment of fragment ends to fragment starts.

    Parameters
    ----------
    tracks : (M, 10) ndarray
        MOTChallenge rows of a tracker's output.
    config : LinkConfig
        Gates and weights.
    frames : sequence of (H, W, 3) uint8, optional
        The video's frames (index ``frame - 1``) for the colour-histogram term.

    Returns
    -------
    rows : (M, 10) ndarray
        The rows with fragment ids replaced by the id of the first fragment of each chain.
    mapping : dict
        Old id -> new id for every relabelled fragment.
    """
    from scipy.optimize import linear_sum_assignment

    rows = np.array(tracks, dtype=np.float64, copy=True)
    if len(rows) == 0:
        return rows, {}
    per_id = split_tracks(rows)
    ids, cost = link_cost_matrix(per_id, config, frames)
    finite = np.isfinite(cost)
    if not finite.any():
        return rows, {}
    big = 1e6
    r, c = linear_sum_assignment(np.where(finite, cost, big))
    nxt = {ids[i]: ids[j] for i, j in zip(r, c) if finite[i, j]}
    has_prev = set(nxt.values())
    mapping: dict[int, int] = {}
    for head in ids:
        if head in has_prev:
            continue
        cur = head
        while cur in nxt:
            cur = nxt[cur]
            mapping[cur] = head
    for old, new in mapping.items():
        rows[rows[:, 1] == old, 1] = new
    return rows, mapping


@dataclass(frozen=True)
class FillReport:
    """What :func:`fill_gaps` did."""

    n_gaps: int
    n_filled_rows: int
    noise: NoiseEstimate | None


def fill_gaps(
    tracks: F64, method: str = "gdt-mix", max_gap: int = 30, noise: NoiseEstimate | None = None
) -> tuple[F64, FillReport]:
    """Fill every hole of at most `max_gap` missing frames inside each id's track.

    Filled rows get positions from `method`, sizes by linear interpolation, ``conf`` = the
    smaller of the two neighbours' and the interpolated flag (column 8) set to 1. Rows come back
    sorted by (frame, id).
    """
    if method not in METHODS:
        raise ValueError(f"fill_gaps: method is {method!r}, expected one of {METHODS}")
    if max_gap < 1:
        raise ValueError(f"fill_gaps: max_gap is {max_gap}, expected >= 1")
    rows = np.asarray(tracks, dtype=np.float64)
    if rows.ndim != 2 or rows.shape[1] != 10:
        raise ValueError(f"fill_gaps: tracks must have shape (M, 10), got {rows.shape}")
    check_unique(rows)
    per_id = split_tracks(rows)
    segs: list[tuple[F64, F64]] = []
    meta: list[tuple[int, F64, F64]] = []
    for tid, r in per_id.items():
        c = _centres(r)
        seg = np.column_stack([c, r[:, 4], r[:, 5]])
        holes = np.flatnonzero(np.diff(r[:, 0]) > 1)
        for h in holes:
            missing = int(r[h + 1, 0] - r[h, 0] - 1)
            if missing > max_gap:
                continue
            segs.append((seg[: h + 1], seg[h + 1 :]))
            meta.append((tid, r[h], r[h + 1]))
    motion = None
    if method in ("gdt-bi", "gdt-mix") and segs:
        whole = [_segment(r) for r in per_id.values()]
        if noise is None:
            noise = estimate_noise(whole)
        if method == "gdt-mix":  # one model for the file, not one per pair of segments
            motion = fit_motion(whole, noise)
    new_rows: list[F64] = []
    if segs:
        paths = recover_gaps(segs, method, noise=noise, motion=motion)
        for (tid, ra, rb), xy in zip(meta, paths):
            fr = np.arange(ra[0] + 1, rb[0])
            s = (fr - ra[0]) / (rb[0] - ra[0])
            w = (1 - s) * ra[4] + s * rb[4]
            h = (1 - s) * ra[5] + s * rb[5]
            out = np.empty((len(fr), 10))
            out[:, 0] = fr
            out[:, 1] = tid
            out[:, 2] = xy[:, 0] - 0.5 * w
            out[:, 3] = xy[:, 1] - 0.5 * h
            out[:, 4] = w
            out[:, 5] = h
            out[:, 6] = min(ra[6], rb[6])
            out[:, 7] = 1.0
            out[:, 8] = -1.0
            out[:, 9] = -1.0
            new_rows.append(out)
    filled = np.vstack([rows, *new_rows]) if new_rows else rows.copy()
    order = np.lexsort((filled[:, 1], filled[:, 0]))
    n_new = sum(len(r) for r in new_rows)
    return filled[order], FillReport(len(segs), n_new, noise)


def _segment(r: F64) -> F64:
    return _centres(r)


def check_unique(rows: F64, line_numbers: Iterable[int] | None = None) -> None:
    """Raise ValueError naming the first duplicate (frame, id) pair (and its lines if known)."""
    if len(rows) == 0:
        return
    key = rows[:, 0].astype(np.int64) * (1 << 32) + rows[:, 1].astype(np.int64)
    order = np.argsort(key, kind="stable")
    dup = np.flatnonzero(np.diff(key[order]) == 0)
    if len(dup):
        i, j = order[dup[0]], order[dup[0] + 1]
        where = ""
        if line_numbers is not None:
            ln = list(line_numbers)
            where = f" (lines {ln[i]} and {ln[j]})"
        raise ValueError(
            f"duplicate rows for frame {int(rows[i, 0])}, id {int(rows[i, 1])}{where}: "
            "each (frame, id) may appear once"
        )
