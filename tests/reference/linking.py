"""Dense reference of pftrack.recovery.linking: every pair of fragments, one (K, K) assignment.

What ``link_tracklets`` did before it went sparse: a loop over all ``K * K`` pairs of
fragments (the time gate tested inside it, the start velocity recomputed per pair), a dense
cost matrix with ``inf`` for gated pairs, and one assignment of the whole matrix with 1e6 for
a forbidden join. Quadratic in time and memory: for tests on small inputs only.
"""

from __future__ import annotations

import numpy as np

from pftrack.assignment import linear_sum_assignment
from pftrack.recovery.linking import LinkConfig, _end_velocity, box_centres, split_tracks


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
            if (
                r is not None
                and area_i > 0
                and area_j > 0
                and max(area_i, area_j) > r * min(area_i, area_j)
            ):
                continue
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
