"""Dense reference of pftrack.recovery.linking: every pair of fragments, one (K, K) assignment.

What ``link_tracklets`` did before it went sparse: a loop over all ``K * K`` pairs of
fragments (the time gate tested inside it, the start velocity recomputed per pair), a dense
cost matrix with ``inf`` for gated pairs, and one assignment of the whole matrix with 1e6 for
a forbidden join. Quadratic in time and memory: for tests on small inputs only.
"""

from __future__ import annotations

import heapq
import math

import numpy as np
from numpy.typing import NDArray

from pftrack._typing import F64
from pftrack.assignment import linear_sum_assignment
from pftrack.recovery.linking import FORBIDDEN, LinkConfig, _end_velocity, box_centres, split_tracks


def dense_link_costs(rows: np.ndarray, config: LinkConfig) -> tuple[list[int], np.ndarray]:
    """The ids and the ``(K, K)`` cost of joining the end of fragment i to the start of j."""
    tracks = split_tracks(rows)
    ids = list(tracks)
    cost = np.full((len(ids), len(ids)), np.inf)
    cent = {t: box_centres(r) for t, r in tracks.items()}
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
            area_i = tracks[ti][-1, 4] * tracks[ti][-1, 5]  # the boxes where they meet
            area_j = tracks[tj][0, 4] * tracks[tj][0, 5]
            r = config.max_area_ratio
            if r is not None and max(area_i, area_j) > r * min(area_i, area_j):
                continue  # a box without area is apart from every box with one
            c = d / config.max_distance + config.w_gap * (gap - 1) / max(config.max_gap, 1)
            hi, hj = tracks[ti][-1, 5], tracks[tj][0, 5]
            if hi > 0 and hj > 0:
                c += config.w_size * abs(float(np.log(hi / hj)))
            cost[i, j] = c
    return ids, cost


def dense_links(rows: np.ndarray, config: LinkConfig) -> list[tuple[int, int]]:
    """The joins (id of the end, id of the start) of one assignment of the whole matrix."""
    ids, cost = dense_link_costs(rows, config)
    finite = np.isfinite(cost)
    if not finite.any():
        return []
    r, c = linear_sum_assignment(np.where(finite, cost, 1e6))
    return sorted((ids[i], ids[j]) for i, j in zip(r, c, strict=True) if finite[i, j])


def dense_link_tracklets(rows: np.ndarray, config: LinkConfig) -> tuple[np.ndarray, dict[int, int]]:
    """``link_tracklets`` by the dense assignment: relabelled rows and old id -> new id."""
    out = np.array(rows, dtype=np.float64, copy=True)
    ids = list(split_tracks(out))
    nxt = dict(dense_links(out, config))
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
        out[out[:, 1] == old, 1] = new
    return out, mapping


def sparse_assignment(
    r: NDArray[np.intp], c: NDArray[np.intp], cost: F64, n_ends: int, n_starts: int
) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """``_core.sparse_assignment``, in Python: what ``linking._assign`` ran until it was C++.

    (Was 15 s of a 20000-fragment file, of 16.) :func:`_assign`'s optimum for one component,
    over its pairs only (no dense matrix).

    Shortest augmenting paths (Dijkstra on reduced costs, the dual update of
    :func:`pftrack.assignment.linear_sum_assignment`, Crouse's) over the pairs ``(r, c)``
    with their `cost`, and for every end a start of its own at :data:`FORBIDDEN` (not joined):
    the same objective as the dense matrix, the most joins, then the least cost. Time and
    memory follow the pairs an augmenting path visits, not ``n_ends * n_starts``.
    """
    out: list[list[tuple[int, float]]] = [[] for _ in range(n_ends)]
    for a, b, w in zip(r.tolist(), c.tolist(), cost.tolist(), strict=True):
        out[a].append((b, w))
    for a in range(n_ends):  # an end's own stand-in start: left unjoined
        out[a].append((n_starts + a, FORBIDDEN))
    n_cols = n_starts + n_ends
    u, v = [0.0] * n_ends, [0.0] * n_cols
    row4col, col4row = [-1] * n_cols, [-1] * n_ends
    for cur in range(n_ends):
        dist: dict[int, float] = {}  # columns reached: their path cost
        pred: dict[int, int] = {}  # and the row they were reached from
        done: dict[int, None] = {}  # columns whose path cost is final, in that order
        heap: list[tuple[float, int]] = []
        i, base = cur, 0.0
        while True:
            for j, w in out[i]:
                d = base + w - u[i] - v[j]
                if j not in done and d < dist.get(j, math.inf):
                    dist[j], pred[j] = d, i
                    heapq.heappush(heap, (d, j))
            while True:
                base, j = heapq.heappop(heap)
                if j not in done and base == dist[j]:
                    break
            done[j] = None
            if row4col[j] == -1:  # a free start: the path ends here
                break
            i = row4col[j]
        sink = j
        for j in done:  # the dual update: reduced costs stay >= 0
            if j != sink:
                u[row4col[j]] += base - dist[j]
            v[j] -= base - dist[j]
        u[cur] += base
        j = sink
        while True:  # augment along the path
            i = pred[j]
            row4col[j] = i
            col4row[i], j = j, col4row[i]
            if i == cur:
                break
    rows = [a for a in range(n_ends) if col4row[a] < n_starts]
    return np.array(rows, dtype=np.intp), np.array([col4row[a] for a in rows], dtype=np.intp)
