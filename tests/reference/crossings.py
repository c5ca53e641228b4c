"""The crossing repair as it was before 6 December's rewrite, one window at a time (tests only).

`repair_crossings` masked every row per track of every window (``(lab == t) & ob``: about 20
passes over all rows a window), ran the Kalman scoring once per window, and found every window
again after each exchange; `pftrack.tracking.offline.repair_crossings` must give the same ids.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pftrack.boxes import _to_cxcywh
from pftrack.kalman import _cv_predict, _cv_update_where
from pftrack.recovery.linking import check_rows
from pftrack.tracking.offline import CrossingConfig, _overlapping_pairs

F64 = NDArray[np.float64]
Segments = list[tuple[NDArray[np.intp], NDArray[np.intp]]]


def repair_crossings(
    rows: F64, observed: NDArray[np.bool_], config: CrossingConfig, measurements: F64
) -> F64:
    """The old loop: checked rows in, rows with ids exchanged out."""
    a = check_rows(rows, "repair_crossings").copy()
    if len(a) < 2:
        return a
    perm = np.argsort(a[:, 0], kind="stable")
    fr, lab = a[perm, 0], a[perm, 1].copy()
    ob, cz = observed[perm], _to_cxcywh(measurements[perm])
    pairs = _overlapping_pairs(a[perm], config.min_iou)
    wins = windows(pairs, lab, config.join_gap)
    k = 0
    while k < len(wins):
        cut, i, j, start, end = wins[k]
        k += 1
        if end - start + 1 > config.max_window:
            continue
        segments = []
        for t in (i, j):
            mine = (lab == t) & ob
            before = np.flatnonzero(mine & (fr >= start - config.span) & (fr < start))
            after = np.flatnonzero(mine & (fr > end) & (fr <= end + config.span))
            segments.append((before, after))
        if min(len(s) for seg in segments for s in seg) < config.min_points:
            continue
        if not exchange_is_likelier(fr, cz, segments, config):
            continue
        late = fr >= cut
        ii, jj = (lab == i) & late, (lab == j) & late
        lab[ii], lab[jj] = j, i
        wins = [w for w in windows(pairs, lab, config.join_gap) if w[:3] > (cut, i, j)]
        k = 0
    a[perm, 1] = lab
    return a


def windows(pairs: F64, lab: F64, join_gap: int) -> list[tuple[float, float, float, float, float]]:
    """Interaction windows ``(cut, id_lo, id_hi, start, end)``, sorted; one loop step each."""
    if not len(pairs):
        return []
    la, lb = lab[pairs[:, 1].astype(np.intp)], lab[pairs[:, 2].astype(np.intp)]
    lo, hi, f, iou = np.minimum(la, lb), np.maximum(la, lb), pairs[:, 0], pairs[:, 3]
    order = np.lexsort((f, hi, lo))
    lo, hi, f, iou = lo[order], hi[order], f[order], iou[order]
    new = np.r_[True, (lo[1:] != lo[:-1]) | (hi[1:] != hi[:-1]) | (np.diff(f) > join_gap + 1)]
    starts = np.flatnonzero(new)
    out = []
    for s, e in zip(starts, np.r_[starts[1:], len(f)], strict=True):
        cut = f[s + int(np.argmax(iou[s:e]))]
        out.append((float(cut), float(lo[s]), float(hi[s]), float(f[s]), float(f[e - 1])))
    out.sort()
    return out


def exchange_is_likelier(fr: F64, cz: F64, segments: Segments, config: CrossingConfig) -> bool:
    """Whether tails exchanged beat the tracker's pairing by ``config.margin`` nats."""
    (bi, ai), (bj, aj) = segments
    height = float(np.median(cz[np.concatenate([bi, ai, bj, aj]), 3]))
    if not height > 0:
        return False
    nll = after_nll(fr, cz / height, [(bi, ai), (bj, aj), (bi, aj), (bj, ai)], config)
    return bool(nll[0] + nll[1] - nll[2] - nll[3] > config.margin)


def after_nll(fr: F64, zh: F64, pairings: Segments, c: CrossingConfig) -> F64:
    """Negative log-likelihood of each pairing's after rows given its before rows."""
    seqs = [np.concatenate([b, f]) for b, f in pairings]
    length = max(len(s) for s in seqs)
    m = len(seqs)
    dt = np.zeros((length, m))
    zs = np.zeros((length, m, 4))
    has = np.zeros((length, m), dtype=bool)
    counts = np.zeros((length, m), dtype=bool)
    for k, (s, (b, _)) in enumerate(zip(seqs, pairings, strict=True)):
        dt[1 : len(s), k] = np.diff(fr[s])
        zs[: len(s), k] = zh[s]
        has[: len(s), k] = True
        counts[len(b) : len(s), k] = True
    q = np.array([c.accel, c.accel, c.size_accel, c.size_accel]) ** 2
    r2 = np.array([c.noise, c.noise, c.size_noise, c.size_noise]) ** 2
    mean = (zs[0].copy(), np.zeros((m, 4)))
    cov = (np.broadcast_to(r2, (m, 4)).copy(), np.zeros((m, 4)), np.full((m, 4), 100.0))
    nll = np.zeros(m)
    for t in range(1, length):
        mean, cov = _cv_predict(mean, cov, q, dt[t][:, None])
        s = cov[0] + r2
        e = zs[t] - mean[0]
        nll += np.where(counts[t], 0.5 * np.sum(e * e / s + np.log(2 * np.pi * s), axis=1), 0.0)
        mean, cov = _cv_update_where(mean, cov, zs[t], r2, has[t][:, None])
    return nll
