"""The crossing repair as it was before 6 December's rewrite, one window at a time (tests only).

`repair_crossings` masked every row per track of every window (``(lab == t) & ob``: about 20
passes over all rows a window), ran the Kalman scoring once per window, and found every window
again after each exchange; `pftrack.tracking.offline.repair_crossings` must give the same ids.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pftrack.boxes import _to_cxcywh
from pftrack.recovery.linking import check_rows
from pftrack.tracking.offline import CrossingConfig, _nll_step, _overlapping_pairs

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
    """Interaction windows ``(cut, id_lo, id_hi, start, end)``, sorted: each pair of ids' overlap
    frames in order, cut where more than ``join_gap`` frames lie between two; `cut` the first
    frame of largest IoU."""
    by_ids: dict[tuple[float, float], list[tuple[float, float]]] = {}
    for f, p, q, iou in pairs.tolist():
        a, b = float(lab[int(p)]), float(lab[int(q)])
        by_ids.setdefault((min(a, b), max(a, b)), []).append((f, iou))
    out = []
    for (lo, hi), seen in by_ids.items():
        seen.sort()  # by frame: one pair of these ids a frame
        run = [seen[0]]
        for k in range(1, len(seen) + 1):
            if k < len(seen) and seen[k][0] - run[-1][0] <= join_gap + 1:
                run.append(seen[k])
                continue
            cut = max(run, key=lambda x: x[1])[0]  # max: the first of equal IoUs
            out.append((cut, lo, hi, run[0][0], run[-1][0]))
            if k < len(seen):
                run = [seen[k]]
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
    for t in range(1, length):  # the Kalman step itself is the package's
        mean, cov = _nll_step(mean, cov, nll, dt[t], zs[t], has[t], counts[t], q, r2)
    return nll
