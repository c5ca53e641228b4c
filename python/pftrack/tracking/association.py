"""Pairing tracks with detections: a gated cost matrix and a padded Hungarian assignment.

The cost of a (track, detection) pair adds three dissimilarities: ``1 - IoU``, the colour term
``colour_weight (1 - rho)`` (``rho`` the Bhattacharyya coefficient of the track's reference
histogram and the detection's), and the centre distance in units of a radius that grows with
the time the track has coasted (capped at 2). A pair is admissible (gated) when the boxes
overlap enough or the centres lie within the radius. Leaving a track or a detection unassigned
costs ``unmatched_cost`` each, so a gated pair is only made when it is cheaper than that.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pftrack import _core
from pftrack._threads import blas_on_one_thread
from pftrack._typing import F64
from pftrack.boxes import _iou_rows, _overlap_pairs
from pftrack.tracking.config import AssociationConfig

__all__ = ["Association", "associate", "colour_product", "covers_another", "first_of_twins"]

#: Cost of a pair the gate forbids: larger than any sum of admissible costs.
FORBIDDEN = 1e6


@dataclass(frozen=True)
class Association:
    """Result of :func:`associate`: pairs ``(track, detection)`` and what is left alone."""

    matches: list[tuple[int, int]]
    unmatched_tracks: list[int]
    unmatched_detections: list[int]


def associate(
    track_boxes: F64,
    heights: F64,
    coasted: NDArray[np.int_],
    references: F64,
    boxes: F64,
    hists: F64,
    config: AssociationConfig,
    allowed: NDArray[np.bool_] | None = None,
) -> Association:
    """Pair tracks with detections.

    Parameters
    ----------
    track_boxes : (T, 4) ndarray
        The tracks' predicted boxes (xywh).
    heights : (T,) ndarray
        The tracks' smoothed heights (the unit of the distance gate).
    coasted : (T,) ndarray of int
        Frames since each track's last detection.
    references : (T, B) ndarray
        The tracks' reference histograms (normalised).
    boxes : (D, 4) ndarray
        Detection boxes (xywh).
    hists : (D, B) ndarray
        Detection histograms (rows sum to 1, or 0 when empty).
    config : AssociationConfig
        Gates, weights and the cost of leaving things unmatched.
    allowed : (T, D) ndarray of bool, optional
        Pairs that may be made at all (e.g. same class); None allows every pair.

    Returns
    -------
    Association
    """
    nt, nd = len(track_boxes), len(boxes)
    if nt == 0 or nd == 0:
        return Association([], list(range(nt)), list(range(nd)))
    # Bhattacharyya coefficients of every (track reference, detection) pair in one product;
    # the rest of the cost and the gate in one core pass over the pairs (the module's rules)
    rho = colour_product(np.sqrt(references), np.sqrt(hists).T)
    cost = _core.association_cost(
        track_boxes, heights, coasted, rho, boxes, config.match_distance,
        config.colour_weight, config.match_iou, FORBIDDEN,
    )  # fmt: skip
    if allowed is not None:
        cost = np.where(allowed, cost, FORBIDDEN)
    if math.isfinite(config.unmatched_cost):
        # leaving a track or a detection unmatched costs `unmatched_cost` each, so a pair is
        # only made when it is cheaper than leaving both alone (not just because it is gated):
        # the assignment of the (T + D, D + T) matrix of _padding with `cost` written in, each
        # row made as the search reads it (the same pairs, ties and all; was: the matrix made
        # twice, 2.2 GB for 10 000 detections and 1 800 tracks)
        rows, cols = _core.padded_assignment(cost, config.unmatched_cost, FORBIDDEN)
    else:
        # pftrack.assignment.linear_sum_assignment without its checks of the argument (a
        # finite float64 matrix made here)
        rows, cols = _core.linear_sum_assignment(np.ascontiguousarray(cost))
    # the pairs as lists from here on: a few tens of them, cheaper than NumPy's calls on tiny
    # arrays
    # pairs of a track and a detection that the gate allows (a pair with a padding row or
    # column leaves its track or detection unmatched)
    matches = [
        (r, c)
        for r, c in zip(rows.tolist(), cols.tolist(), strict=True)
        if r < nt and c < nd and cost[r, c] < FORBIDDEN
    ]
    taken_t = {r for r, _ in matches}
    taken_d = {c for _, c in matches}
    return Association(
        matches,
        [i for i in range(nt) if i not in taken_t],
        [j for j in range(nd) if j not in taken_d],
    )


#: Products of at most this many multiply-adds (rows x columns x bins) are left as they are:
#: OpenBLAS runs any product below 4 x 65536 of them on one thread (``interface/gemm.c``,
#: ``SMP_THRESHOLD_MIN`` x ``GEMM_MULTITHREAD_THRESHOLD``); this bound is a quarter of that, so a
#: build with a lower threshold is still held to one thread from here on. 10 tracks and 10
#: detections of 110 bins: 11,000.
ONE_THREAD_PRODUCT = 65536


def colour_product(a: F64, b: F64) -> F64:
    """``a @ b`` on one BLAS thread: the bits of ``OPENBLAS_NUM_THREADS=1``, the pool's never.

    The association's colour product, ``sqrt(references) @ sqrt(hists).T``, (T, B) by (B, D),
    goes to OpenBLAS's ``dgemm``, which from about 70 x 70 (B = 110) splits it over its thread
    pool: 0.24-2.6 ms of CPU for a 100 x 100 product against 0.06-0.09 ms on one thread (at
    load 10-20; the pool's threads spin on the cores the tracker needs). The split's sums also
    differ from one thread's in their last bits (10 of 18 shapes from 70 x 70 on), so a
    library tracker of 70+ tracks weighed its pairs otherwise than ``pftrack track`` (one BLAS
    thread from its start, :func:`pftrack._threads.one_blas_thread`) and than itself on a
    machine of another core count. Above :data:`ONE_THREAD_PRODUCT` multiply-adds the product
    runs inside :func:`pftrack._threads.blas_on_one_thread`: one thread's, the same bits as
    ``pftrack track``'s (tests/tracking/test_association.py).
    """
    if a.shape[0] * a.shape[1] * b.shape[1] <= ONE_THREAD_PRODUCT:
        out: F64 = a @ b
        return out
    with blas_on_one_thread():
        out = a @ b
    return out


#: Padded cost matrices made so far, by (tracks, detections, unmatched cost): a frame's
#: matrix is a copy of its template with the pairs' costs written in (one NumPy call instead
#: of seven; a run sees a few shapes, the number of objects in view). Shared by every tracker
#: of the process, at most :data:`_PADDING_KEPT` of at most :data:`_PADDING_LARGEST` bytes each
#: (16 MB in all).
_PADDING: dict[tuple[int, int, float], F64] = {}
_PADDING_KEPT = 256
#: The largest matrix kept (64 KiB: tracks + detections up to 90). A larger one is made anew
#: each frame, at little cost beside its assignment (a 400 x 400 matrix: 117 us made, 29 us
#: copied, against milliseconds for the assignment); was: every shape kept, and a service
#: tracking crowds of 150-180 people held 213 MB of them (32 MB for each 1000 + 1000 shape).
_PADDING_LARGEST = 2**16


def _padding(nt: int, nd: int, tau: float) -> F64:
    """The padded matrix of :func:`associate` with every pair forbidden (read-only, kept if small).

    ``[[pairs, tau on the diagonal], [tau on the diagonal, 0]]``: leaving a track or a
    detection unmatched costs `tau`, two padding entries nothing. Since stop 70
    :func:`associate` no longer makes it (``_core.padded_assignment`` writes its rows one at a
    time); it is the dense layout that kernel is held to (tests/tracking/test_association_scale.py).
    """
    key = (nt, nd, tau)
    padded = _PADDING.get(key)
    if padded is None:
        padded = np.full((nt + nd, nd + nt), FORBIDDEN)
        k = np.arange(max(nt, nd))
        padded[k[:nt], nd + k[:nt]] = tau  # the diagonal of padded[:nt, nd:]
        padded[nt + k[:nd], k[:nd]] = tau  # the diagonal of padded[nt:, :nd]
        padded[nt:, nd:] = 0.0
        padded.flags.writeable = False
        if padded.nbytes <= _PADDING_LARGEST:
            if len(_PADDING) >= _PADDING_KEPT:  # a long run of varied crowds: start afresh
                _PADDING.clear()
            _PADDING[key] = padded
    return padded


def covers_another(
    box_xywh: Sequence[float] | F64, others_xywh: Iterable[Sequence[float]] | F64
) -> bool:
    """Tell whether `box_xywh` contains the centre of any of `others_xywh` (a merged blob).

    Plain floats or float64 arrays alike (the same comparisons of the same floats): the
    tracker asks once per large detection, against a few to tens of tracks, with lists, as
    NumPy's calls on such tiny arrays cost more than the loop.
    """
    x, y, w, h = box_xywh
    right, bottom = x + w, y + h
    for ox, oy, ow, oh in others_xywh:
        cx, cy = ox + ow / 2, oy + oh / 2
        if x < cx < right and y < cy < bottom:
            return True
    return False


def first_of_twins(boxes: F64, labels: NDArray[np.int64], candidates: Sequence[int],
                   explained: NDArray[np.bool_], overlap: float | None) -> list[int]:  # fmt: skip
    """The `candidates` that start an object: none on an object another detection explains.

    A greedy non-maximum suppression among a frame's births, the one rule of every sampler
    (``sampler="sis"`` and ``"mh"`` for the tracks they start, ``"rjmcmc"`` for the joint
    chain's newborn slots). `candidates`, rows of `boxes` (``left, top, w, h``, the frame's
    detections in :func:`~pftrack.tracking.tracker.canonical_order`), are taken in the order
    given, highest score first; each that passes is kept and then explains its object. A
    candidate is refused when it overlaps, by an IoU above `overlap`
    (``LifecycleConfig.birth_overlap``, in (0, 1]: only boxes that meet are compared; None:
    every candidate is kept), a detection of its class that `explained` marks (e.g. one
    matched to a track) or a candidate kept before it: the same box twice, from a detector
    without non-maximum suppression or from two detectors' outputs concatenated. `explained`
    is not changed.
    """
    if overlap is None or len(boxes) < 2 or not len(candidates):
        return list(candidates)
    rows = np.asarray(candidates, dtype=np.intp)
    # the twins of each candidate from the pairs of boxes that overlap at all (an IoU above
    # `overlap` > 0 needs an intersection), not a dense (candidates, boxes) IoU matrix: 1.9 GB
    # and 10 s for 10 000 boxes in one frame (stop 69); the same IoUs of the same pairs
    k, j = _overlap_pairs(boxes[rows, :4], boxes[:, :4])
    twin = (_iou_rows(boxes[rows[k], :4], boxes[j, :4]) > overlap) & (labels[rows[k]] == labels[j])
    k, j = k[twin], j[twin]
    starts = np.searchsorted(k, np.arange(len(rows) + 1)).tolist()  # k ascending
    others = j.tolist()
    seen = explained.tolist()  # a copy: `explained` is not changed
    kept = []
    for c, di in enumerate(candidates):
        if any(seen[o] for o in others[starts[c] : starts[c + 1]]):
            continue
        seen[di] = True
        kept.append(di)
    return kept
