"""The association's dense steps as they were on main at stop 69 (92c34271), before stop 70's
sparse ones: the (candidates, boxes) and (unmatched, tracks) IoU matrices of ``first_of_twins``
and ``MultiObjectTracker._beside``, and ``associate``'s padded (T + D, D + T) cost matrix given
to ``linear_sum_assignment``. The tests hold the sparse steps to these, result for result
(tests/tracking/test_association_scale.py); bench/test_association.py times both."""

from __future__ import annotations

import math

import numpy as np

from pftrack import _core
from pftrack.boxes import _iou_matrix
from pftrack.tracking import association
from pftrack.tracking.association import FORBIDDEN, _padding, colour_product


def first_of_twins(boxes, labels, candidates, explained, overlap):  # type: ignore[no-untyped-def]
    if overlap is None or len(boxes) < 2 or not len(candidates):
        return list(candidates)
    rows = np.asarray(candidates, dtype=np.intp)
    twins = (_iou_matrix(boxes[rows, :4], boxes[:, :4]) > overlap) & (
        labels[rows][:, None] == labels[None, :]
    )
    explained = explained.copy()
    kept = []
    for k, di in enumerate(candidates):
        if twins[k, explained].any():
            continue
        explained[di] = True
        kept.append(di)
    return kept


def beside(tracks, boxes, labels, unmatched, overlap):  # type: ignore[no-untyped-def]
    if not len(unmatched) or not tracks:
        return set()
    rows = np.asarray(unmatched, dtype=np.intp)
    iou = _iou_matrix(boxes[rows, :4], np.array([t.box for t in tracks]))
    same = labels[rows][:, None] == np.array([t.cls for t in tracks])[None, :]
    hit = ((iou > overlap) & same).any(axis=1)
    return set(rows[hit].tolist())


def associate(track_boxes, heights, coasted, references, boxes, hists, config, allowed):  # type: ignore[no-untyped-def]
    nt, nd = len(track_boxes), len(boxes)
    if nt == 0 or nd == 0:
        return association.Association([], list(range(nt)), list(range(nd)))
    rho = colour_product(np.sqrt(references), np.sqrt(hists).T)
    cost = _core.association_cost(
        track_boxes, heights, coasted, rho, boxes, config.match_distance,
        config.colour_weight, config.match_iou, FORBIDDEN,
    )  # fmt: skip
    if allowed is not None:
        cost = np.where(allowed, cost, FORBIDDEN)
    if math.isfinite(config.unmatched_cost):
        padded = _padding(nt, nd, config.unmatched_cost).copy()
        padded[:nt, :nd] = cost
        cost_in = padded
    else:
        cost_in = np.ascontiguousarray(cost)
    rows, cols = _core.linear_sum_assignment(cost_in)
    matches = [
        (r, c)
        for r, c in zip(rows.tolist(), cols.tolist(), strict=True)
        if r < nt and c < nd and cost[r, c] < FORBIDDEN
    ]
    taken_t = {r for r, _ in matches}
    taken_d = {c for _, c in matches}
    return association.Association(
        matches,
        [i for i in range(nt) if i not in taken_t],
        [j for j in range(nd) if j not in taken_d],
    )
