"""CLEAR-MOT, identity (IDF1) and Smith et al.'s per-object measures of a tracking result.

Everything works on ``(M, 10)`` MOTChallenge arrays as returned by
:func:`pftrack.io.mot.read_mot`: ``frame, id, left, top, width, height, conf, x, y, z``.
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Callable, Mapping, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import linear_sum_assignment
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from pftrack._check import brief, number, option, shown
from pftrack._progress import Report, check_report, reporting
from pftrack._typing import BenchmarkName
from pftrack.boxes import iou_xywh
from pftrack.eval.rows import (
    BENCHMARKS,
    _mot_iou,
    check_eval_rows,
    guess_benchmark,
    not_parts_message,
    prepare_mot,
    say_none_matched,
)
from pftrack.io.mot import FRAME, ID, LEFT

__all__ = ["MotMetrics", "combine_mot", "evaluate_mot", "format_metrics", "iou_xywh"]

# TrackEval's np.finfo(float).eps: how far below the threshold CLEAR still takes a pair, and
# the score a pair of the assignment must exceed to be a match.
_EPS = float(np.finfo(np.float64).eps)

#: Where :func:`evaluate_mot`'s passes (over the frames: CLEAR-MOT and the pairs that overlap;
#: over the objects: Smith et al.'s measures) begin and end, as fractions of its time, for its
#: `on_progress` (before them: the rows chosen and sorted; between: IDF1's assignment).
#: Measured on a file of 100 000 frames and 5000 ids (5 December).
_PASSES = ((0.22, 0.97), (0.975, 0.995))


@dataclasses.dataclass(frozen=True)
class MotMetrics:
    """Scores of one tracking result against one ground truth.

    CLEAR-MOT (Bernardin & Stiefelhagen 2008) with IoU matching, identity measures (Ristani et
    al. 2016) and the per-object measures of Smith et al. (2005) used by the first paper.

    Attributes
    ----------
    mota : float
        ``1 - (FN + FP + IDSW) / num_objects`` (a fraction; can be negative), computed as
        TrackEval's ``(TP - FP - IDSW) / num_objects`` (the same bits); 0 without any
        ground-truth box, as TrackEval scores such a sequence.
    motp_iou : float
        Mean IoU of the matched pairs (0 without a match, as TrackEval's MOTP). This is "MOTP
        as overlap" (higher is better); py-motmetrics reports the mean distance ``1 - IoU``
        instead, i.e. ``1 - motp_iou``.
    iou_sum : float
        Sum of the matched pairs' IoU, added up as TrackEval's ``MOTP_sum`` (each frame's sum,
        then over frames): ``motp_iou = iou_sum / num_matches``. :func:`combine_mot` sums it,
        so that a combined MOTP is TrackEval's to the last bit.
    idf1, idp, idr : float
        Identity F1, precision and recall after the global one-to-one assignment of ground-truth
        trajectories to result trajectories that maximises the identity true positives (0,
        not NaN, over no box: TrackEval's ``max(1, denominator)``).
    idtp, idfp, idfn : int
        Identity true positives, false positives and false negatives (boxes).
    num_switches : int
        Identity switches: a ground-truth object matched to a different result id than at its
        last match.
    num_fragmentations : int
        Tracked runs of an object after its first (TrackEval's Frag), a run being its matches
        in consecutive scored frames (frames holding both ground truth and results): a scored
        frame without the object ends one, as a miss does (py-motmetrics counts only the misses
        between its first and last match).
    mostly_tracked, partially_tracked, mostly_lost : int
        Objects tracked in more than 80 %, in [20 %, 80 %], and in under 20 % of their frames
        (TrackEval's rule; py-motmetrics counts exactly 80 % as mostly tracked).
    false_positives, misses, num_matches : int
        CLEAR-MOT FP, FN and matches (switches included in the matches).
    num_objects, num_predictions : int
        Scored ground-truth boxes and scored result boxes.
    num_unique_objects, num_frames : int
        Scored ground-truth ids; frames seen in either input.
    num_ignored_gt, num_ignored_predictions : int
        Ground-truth rows left out by MOTChallenge's rules (``conf`` 0, and for MOT16/17/20 other
        classes than pedestrian) and result boxes left out (MOT16/17/20 only: those on a
        distractor); :func:`pftrack.eval.prepare_mot`.
    precision, recall : float
        ``matches / num_predictions`` and ``matches / num_objects`` (0 over no box, as
        TrackEval's CLR_Pr and CLR_Re).
    success_rate : float
        Smith et al.'s tracking success rate, mean over objects: for each ground-truth object,
        the fraction of its frames in which its assigned result track overlaps it (IoU > 0). The
        assigned track is the result id that overlaps the object in the most frames.
    success_rate_strict : float
        The same with "overlaps" meaning IoU >= `iou_threshold` (assignment by the same rule).
    success_per_object : tuple of (int, float, float)
        ``(gt id, success, strict success)`` per object, in id order; empty in a combination
        (:func:`combine_mot`: ids repeat across sequences), so the ``combined`` object of
        ``pftrack eval --json`` has ``"success_per_object": []``.
    centroid_distance_px : float
        Mean Euclidean distance (pixels, after `scale`) between the centroid of each ground-truth
        box and that of its assigned result track (loose assignment), over the frames where both
        exist. NaN when no such frame.
    centroid_distance_ratio : float
        `centroid_distance_px` divided by the image's pixel count ``width * height`` (the first
        paper's normalisation). NaN when the image size is not given.
    iou_threshold, scale : float
        The settings used.
    """

    mota: float
    motp_iou: float
    iou_sum: float
    idf1: float
    idp: float
    idr: float
    idtp: int
    idfp: int
    idfn: int
    num_switches: int
    num_fragmentations: int
    mostly_tracked: int
    partially_tracked: int
    mostly_lost: int
    false_positives: int
    misses: int
    num_matches: int
    num_objects: int
    num_predictions: int
    num_unique_objects: int
    num_frames: int
    num_ignored_gt: int
    num_ignored_predictions: int
    precision: float
    recall: float
    success_rate: float
    success_rate_strict: float
    success_per_object: tuple[tuple[int, float, float], ...]
    centroid_distance_px: float
    centroid_distance_ratio: float
    iou_threshold: float
    scale: float

    def as_dict(self) -> dict[str, object]:
        """Plain ``dict`` (JSON-ready: NaN becomes None)."""
        out: dict[str, object] = {}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if isinstance(v, float) and not math.isfinite(v):
                v = None
            if f.name == "success_per_object":
                v = [{"id": i, "success": s, "success_strict": t} for i, s, t in v]
            out[f.name] = v
        return out

    def to_json(self) -> str:
        """JSON text of :meth:`as_dict`."""
        return json.dumps(self.as_dict(), indent=2)

    def table(self) -> str:
        """Human-readable text table (see :func:`format_metrics`)."""
        return format_metrics(self)

    def __str__(self) -> str:
        """:meth:`table`, what ``print(metrics)`` shows (``repr``: every field)."""
        return format_metrics(self)


def _pct(x: float) -> str:
    return "-" if not math.isfinite(x) else f"{100.0 * x:.1f}"  # "-": no value (JSON: null)


def format_metrics(m: MotMetrics | Mapping[str, MotMetrics]) -> str:
    """Text table of one result, or of several results keyed by name (one row each).

    Percentages for MOTA, MOTP (mean IoU of matches), IDF1, IDP, IDR, precision, recall and the
    success rates; counts for the rest. This is the table of :class:`MotMetrics`
    (:func:`evaluate_mot`); the one ``pftrack eval`` prints, of
    :func:`~pftrack.eval.evaluate_sequence`'s :class:`~pftrack.eval.SequenceScores` (HOTA
    first), is :func:`~pftrack.eval.format_scores`'s.

    Raises
    ------
    TypeError
        `m` is not a MotMetrics or a mapping of names to MotMetrics (a SequenceScores: the
        message names :func:`~pftrack.eval.format_scores`).
    ValueError
        An empty mapping.
    """
    fn = "format_metrics"
    if isinstance(m, MotMetrics):
        rows = {"result": m}
    elif isinstance(m, Mapping):
        rows = dict(m)
    else:
        raise TypeError(_not_mot_metrics(fn, "m", m))
    if not rows:
        raise ValueError(f"{fn}: no result to format")
    for name, r in rows.items():
        if not isinstance(r, MotMetrics):
            raise TypeError(_not_mot_metrics(fn, f"m[{name!r}]", r))
    cols: list[tuple[str, Callable[[MotMetrics], str]]] = [
        ("MOTA", lambda r: _pct(r.mota)),
        ("MOTP(IoU)", lambda r: _pct(r.motp_iou)),
        ("IDF1", lambda r: _pct(r.idf1)),
        ("IDP", lambda r: _pct(r.idp)),
        ("IDR", lambda r: _pct(r.idr)),
        ("Prec", lambda r: _pct(r.precision)),
        ("Rec", lambda r: _pct(r.recall)),
        ("FP", lambda r: str(r.false_positives)),
        ("FN", lambda r: str(r.misses)),
        ("IDSW", lambda r: str(r.num_switches)),
        ("Frag", lambda r: str(r.num_fragmentations)),
        ("GT", lambda r: str(r.num_unique_objects)),
        ("MT", lambda r: str(r.mostly_tracked)),
        ("PT", lambda r: str(r.partially_tracked)),
        ("ML", lambda r: str(r.mostly_lost)),
        ("Succ", lambda r: _pct(r.success_rate)),
        ("Succ@IoU", lambda r: _pct(r.success_rate_strict)),
        (
            "CD(px)",
            lambda r: (
                "-"
                if not math.isfinite(r.centroid_distance_px)
                else f"{r.centroid_distance_px:.1f}"
            ),
        ),
        (
            "CD/px",
            lambda r: (
                "-"
                if not math.isfinite(r.centroid_distance_ratio)
                else f"{r.centroid_distance_ratio:.2e}"
            ),
        ),
    ]
    header = ["name"] + [c for c, _ in cols]
    body = [[name] + [fn(r) for _, fn in cols] for name, r in rows.items()]
    widths = [max(len(str(x[i])) for x in [header] + body) for i in range(len(header))]
    lines = ["  ".join(h.rjust(w) for h, w in zip(header, widths, strict=True))]
    lines += ["  ".join(v.rjust(w) for v, w in zip(row, widths, strict=True)) for row in body]
    first = next(iter(rows.values()))
    lines.append(
        f"(IoU threshold {first.iou_threshold:g}; MOTP = mean IoU of matches; "
        f"Succ: IoU > 0 with the assigned track, Succ@IoU: IoU >= threshold; "
        f"CD = mean centroid distance in px, CD/px: over the image's pixel count)"
    )
    return "\n".join(lines)


def _not_mot_metrics(fn: str, what: str, value: object) -> str:
    """Why `value` is no MotMetrics, saying what formats evaluate_sequence's scores."""
    hint = "pass a MotMetrics (evaluate_mot) or a dict {name: MotMetrics}"
    scores = hasattr(value, "mot") and hasattr(value, "hota")  # a SequenceScores, or a list
    if scores or (isinstance(value, (list, tuple)) and any(hasattr(v, "mot") for v in value)):
        hint = (
            "evaluate_sequence's SequenceScores are formatted by pftrack.eval.format_scores "
            "({name: scores}), the table `pftrack eval` prints; or pass scores.mot"
        )
    return f"{fn}: {what} is {type(value).__name__}, expected MotMetrics: {hint}"


def check_image_size(image_size: object, fn: str) -> tuple[float, float] | None:
    """`image_size` as ``(width, height)`` floats, or None; errors name `fn` and the argument.

    Raises
    ------
    TypeError
        Not a pair (an int, a string), or a side that is not a number (None, text, a bool).
    ValueError
        Not two values, or a side not finite or not > 0.
    """
    if image_size is None:
        return None
    what = f"{fn}: image_size"
    # an array other than 1-d too: was "len() of unsized object" (0-d), or its repr over lines
    if (
        isinstance(image_size, (str, bytes))
        or not isinstance(image_size, (Sequence, np.ndarray))
        or (isinstance(image_size, np.ndarray) and image_size.ndim != 1)
    ):
        raise TypeError(f"{what} is {shown(image_size)}, expected (width, height)")
    if len(image_size) != 2:
        raise ValueError(f"{what} is {brief(image_size)}, expected (width, height), 2 values")
    w, h = (number(v, f"{what}[{k}]", finite=False) for k, v in enumerate(image_size))
    if not (math.isfinite(w) and math.isfinite(h) and w > 0 and h > 0):
        raise ValueError(f"{what} is {brief(image_size)}, expected (width, height) finite and > 0")
    return w, h


def _concat(parts: list[NDArray[np.int64]]) -> NDArray[np.int64]:
    out: NDArray[np.int64] = np.concatenate(parts) if parts else np.zeros(0, dtype=np.int64)
    return out


def _identity_tp(
    obj: NDArray[np.int64],
    res: NDArray[np.int64],
    frames: NDArray[np.int64],
    n_o: int,
    n_h: int,
) -> int:
    """IDTP: the most frames a one-to-one pairing of objects and result ids matches.

    `obj`, `res`, `frames`: each pair that matches somewhere, and in how many frames. The
    pairing is the Hungarian assignment of IDF1 (Ristani et al.), made in each group of ids
    that pairs link (connected components): ids of different groups never share a frame's
    match, so the groups' best totals add up to the whole best total, the same integer. One
    (objects, result ids) matrix over every id would grow as their product (5000 a side: 200
    MB and seconds of assignment; 20 000: 3.2 GB).
    """
    if len(obj) == 0:
        return 0
    graph = coo_matrix((np.ones(len(obj)), (obj, n_o + res)), shape=(n_o + n_h, n_o + n_h))
    _, label = connected_components(graph, directed=False)
    group = label[obj]
    order = np.argsort(group, kind="stable")
    total = 0
    for part in np.split(order, np.flatnonzero(np.diff(group[order])) + 1):
        if len(part) == 1:  # one pair alone: its frames
            total += int(frames[part[0]])
            continue
        o_ids, o_at = np.unique(obj[part], return_inverse=True)
        r_ids, r_at = np.unique(res[part], return_inverse=True)
        w = np.zeros((len(o_ids), len(r_ids)))
        w[o_at, r_at] = frames[part]
        a, b = linear_sum_assignment(-w)
        total += int(w[a, b].sum())
    return total


def clear_scores(
    gt: ArrayLike,
    result: ArrayLike,
    *,
    iou_threshold: float = 0.5,
    scale: float = 1.0,
    image_size: tuple[int, int] | None = None,
    benchmark: BenchmarkName = "auto",
    num_frames: int | None = None,
    on_progress: Report | None = None,
) -> MotMetrics:
    """:func:`evaluate_mot`'s scores, without its warning of a result that matched nothing.

    :func:`~pftrack.eval.evaluate_sequence` scores with it and says that warning once itself.
    """
    iou_threshold = number(iou_threshold, "evaluate_mot: iou_threshold", finite=False)
    if not (math.isfinite(iou_threshold) and 0.0 < iou_threshold <= 1.0):
        raise ValueError(f"evaluate_mot: iou_threshold is {iou_threshold}, expected in (0, 1]")
    scale = number(scale, "evaluate_mot: scale", finite=False)
    if not (math.isfinite(scale) and scale > 0):
        raise ValueError(f"evaluate_mot: scale is {scale}, expected a finite value > 0")
    # TrackEval's two rules, to the last bit: CLEAR takes a pair unless its IoU is below the
    # threshold by more than eps, Identity (and here Smith's strict success) needs IoU >= it.
    # (Identical boxes have IoU exactly 1 in mot_iou's arithmetic: a threshold of 1 matches them.)
    clear_reach = iou_threshold - _EPS
    size = check_image_size(image_size, "evaluate_mot")
    check_report(on_progress, "evaluate_mot")
    option(benchmark, "evaluate_mot: benchmark", ("auto", *BENCHMARKS))
    if benchmark != "auto" and benchmark not in BENCHMARKS:
        raise ValueError(
            f"evaluate_mot: benchmark is {benchmark!r}, expected 'auto' or one of "
            f"{', '.join(BENCHMARKS)}"
        )
    g0 = check_eval_rows(gt, "evaluate_mot: gt")
    r0 = check_eval_rows(result, "evaluate_mot: result")
    mark = guess_benchmark(g0) if benchmark == "auto" else benchmark
    g, r = prepare_mot(g0, r0, benchmark=mark, scale=scale, num_frames=num_frames)  # ids too
    n_ign_gt, n_ign_res = len(g0) - len(g), len(r0) - len(r)
    # each frame's rows in file order, as TrackEval reads them: on exact ties (two result boxes
    # equally good for an object) the assignment goes by that order (was sorted by id, which
    # scored other switches than TrackEval's)
    g = g[np.argsort(g[:, FRAME], kind="stable")]  # prepare_mot's order already
    r = r[np.argsort(r[:, FRAME], kind="stable")]
    n_frames = len(set(g0[:, FRAME].tolist()) | set(r0[:, FRAME].tolist()))
    oids, g_idx = np.unique(g[:, ID].astype(np.int64), return_inverse=True)
    hids, r_idx = np.unique(r[:, ID].astype(np.int64), return_inverse=True)
    n_o, n_h = len(oids), len(hids)
    gt_count = np.bincount(g_idx, minlength=n_o)  # frames each object is scored in
    g_frame = g[:, FRAME].astype(np.int64)
    r_frame = r[:, FRAME].astype(np.int64)
    g_box, r_box = g[:, LEFT : LEFT + 4], r[:, LEFT : LEFT + 4]
    frames = np.union1d(g_frame, r_frame)
    g_lo, g_hi = np.searchsorted(g_frame, frames), np.searchsorted(g_frame, frames, "right")
    r_lo, r_hi = np.searchsorted(r_frame, frames), np.searchsorted(r_frame, frames, "right")

    # CLEAR-MOT state, TrackEval's, per object index (NaN: none)
    last_match = np.full(n_o, np.nan)  # result index of its latest match (switches)
    previous = np.full(n_o, np.nan)  # result index matched at the last scored frame
    matched_count = np.zeros(n_o, dtype=np.int64)  # frames matched (MT/PT/ML)
    runs = np.zeros(n_o, dtype=np.int64)  # tracked runs begun (fragmentations)
    touch_keys: list[NDArray[np.int64]] = []  # object * n_h + result: a frame with IoU > 0
    hit_keys: list[NDArray[np.int64]] = []  # ... with IoU >= threshold (Identity, Smith)
    n_fp = n_fn = n_sw = n_match = 0
    iou_sum = 0.0

    for k in reporting(range(len(frames)), on_progress, *_PASSES[0]):
        gs, rs = slice(g_lo[k], g_hi[k]), slice(r_lo[k], r_hi[k])
        gi, ri = g_idx[gs], r_idx[rs]
        if len(gi) == 0 or len(ri) == 0:
            n_fp += len(ri)
            n_fn += len(gi)
            continue  # no frame to go on from: `previous` stays as it was
        iou = _mot_iou(g_box[gs], r_box[rs])  # TrackEval's IoU
        # Identity and Smith measures count every (gt, result) pair overlapping in a frame
        a, b = np.nonzero(iou > 0)
        touch_keys.append(gi[a] * n_h + ri[b])
        a, b = np.nonzero(iou >= iou_threshold)  # Identity's and Smith's strict rule
        hit_keys.append(gi[a] * n_h + ri[b])

        # CLEAR-MOT, TrackEval's arithmetic: one assignment maximising 1000 per pair that goes
        # on from the last scored frame, plus its IoU, among pairs that reach the threshold
        goes_on = previous[gi][:, None] == ri[None, :]  # NaN: no pair goes on
        score = np.where(iou >= clear_reach, 1000.0 * goes_on + iou, 0.0)
        rows_m, cols_m = linear_sum_assignment(-score)
        hit = score[rows_m, cols_m] > _EPS
        rows_m, cols_m = rows_m[hit], cols_m[hit]
        mo, mh = gi[rows_m], ri[cols_m]
        if len(mo):  # TrackEval's MOTP_sum: the frame's sum, then added (the same bits)
            iou_sum += float(sum(iou[rows_m, cols_m]))
        before = last_match[mo]
        n_sw += int(np.count_nonzero(~np.isnan(before) & (before != mh)))
        last_match[mo] = mh
        matched_count[mo] += 1
        runs[mo] += np.isnan(previous[mo])
        previous[:] = np.nan
        previous[mo] = mh
        n_match += len(mo)
        n_fn += len(gi) - len(mo)
        n_fp += len(ri) - len(mo)
    n_gt, n_res = len(g), len(r)

    # Mostly tracked (above 80 % of its frames) / lost (below 20 %), fragmentations (tracked
    # runs after the first), as TrackEval counts them
    tracked = matched_count / np.maximum(gt_count, 1)
    mt = int(np.count_nonzero(tracked > 0.8))
    ml = int(np.count_nonzero(tracked < 0.2))
    pt = n_o - mt - ml
    frag = int(np.sum(np.maximum(runs - 1, 0)))

    # pairs that overlap: (object, result) index and frames, as sorted keys
    touch_k, touch_n = np.unique(_concat(touch_keys), return_counts=True)
    hit_k, hit_n = np.unique(_concat(hit_keys), return_counts=True)

    # Identity: global assignment maximising the frames where a pair overlaps >= threshold.
    idtp = _identity_tp(hit_k // n_h, hit_k % n_h, hit_n, n_o, n_h) if n_h else 0
    idfn = n_gt - idtp
    idfp = n_res - idtp
    # TrackEval's max(1, denominator): 0, not NaN, without ground truth or results
    idf1 = 2 * idtp / (2 * idtp + idfp + idfn) if (2 * idtp + idfp + idfn) else 0.0
    idp = idtp / (idtp + idfp) if (idtp + idfp) else 0.0
    idr = idtp / (idtp + idfn) if (idtp + idfn) else 0.0

    # Smith et al.: per object, the result id overlapping it most often; ties go to the id
    # matching it (IoU >= threshold) more often, then to the nearer one (a neighbour touching
    # the object in as many frames is not its track: was the smaller id, so a result equal to
    # the truth had a centroid distance above 0). Centroid distances only for the pairs that
    # overlap somewhere (each over every frame holding both), not for every pair of every frame.
    centre_g = g_box[:, :2] + 0.5 * g_box[:, 2:]
    centre_r = r_box[:, :2] + 0.5 * r_box[:, 2:]
    by_o = np.argsort(g_idx, kind="stable")  # each object's rows, in frame order
    by_h = np.argsort(r_idx, kind="stable")
    o_lo = np.searchsorted(g_idx[by_o], np.arange(n_o + 1))
    h_lo = np.searchsorted(r_idx[by_h], np.arange(n_h + 1))

    def distances(o: int, h: int) -> list[float]:
        """Centroid distance of object `o` and result `h` in each frame holding both."""
        ga, rb = by_o[o_lo[o] : o_lo[o + 1]], by_h[h_lo[h] : h_lo[h + 1]]
        _, i, j = np.intersect1d(g_frame[ga], r_frame[rb], assume_unique=True, return_indices=True)
        d = centre_g[ga[i]] - centre_r[rb[j]]
        out: list[float] = np.hypot(d[:, 0], d[:, 1]).tolist()
        return out

    t_lo = np.searchsorted(touch_k // n_h, np.arange(n_o + 1)) if n_h else np.zeros(n_o + 1, int)
    hit_of = dict(zip(hit_k.tolist(), hit_n.tolist(), strict=True))
    per_object: list[tuple[int, float, float]] = []
    dists: list[float] = []
    for o in reporting(range(n_o), on_progress, *_PASSES[1]):
        keys = touch_k[t_lo[o] : t_lo[o + 1]].tolist()
        touch = {
            key % n_h: int(c) for key, c in zip(keys, touch_n[t_lo[o] : t_lo[o + 1]], strict=True)
        }
        hits = {h: hit_of[o * n_h + h] for h in touch if o * n_h + h in hit_of}
        near = {h: distances(o, h) for h in touch}
        far = {h: sum(near[h]) for h in touch}
        loose = 0.0
        strict = 0.0
        if touch:
            best = max(touch, key=lambda h: (touch[h], hits.get(h, 0), -far[h], -int(hids[h])))
            loose = touch[best] / int(gt_count[o])
            dists.extend(near[best])
        if hits:
            best_s = max(hits, key=lambda h: (hits[h], touch[h], -far[h], -int(hids[h])))
            strict = hits[best_s] / int(gt_count[o])
        per_object.append((int(oids[o]), loose, strict))
    cd = float(np.mean(dists)) if dists else float("nan")
    ratio = cd / (size[0] * size[1]) if size is not None else float("nan")

    nan = float("nan")
    if on_progress is not None:
        on_progress(1.0)
    return MotMetrics(
        # TrackEval's CLEAR scores a sequence without ground truth (or results) as all 0
        # TrackEval's (TP - FP - IDSW) / GT, not 1 - (FN + FP + IDSW) / GT: the last bit differs
        mota=(n_match - n_fp - n_sw) / n_gt if n_gt else 0.0,
        motp_iou=iou_sum / n_match if n_match else 0.0,
        iou_sum=iou_sum,
        idf1=idf1,
        idp=idp,
        idr=idr,
        idtp=idtp,
        idfp=idfp,
        idfn=idfn,
        num_switches=n_sw,
        num_fragmentations=frag,
        mostly_tracked=mt,
        partially_tracked=pt,
        mostly_lost=ml,
        false_positives=n_fp,
        misses=n_fn,
        num_matches=n_match,
        num_objects=n_gt,
        num_predictions=n_res,
        num_unique_objects=n_o,
        num_frames=n_frames,
        num_ignored_gt=n_ign_gt,
        num_ignored_predictions=n_ign_res,
        precision=n_match / n_res if n_res else 0.0,
        recall=n_match / n_gt if n_gt else 0.0,
        success_rate=float(np.mean([p[1] for p in per_object])) if per_object else nan,
        success_rate_strict=float(np.mean([p[2] for p in per_object])) if per_object else nan,
        success_per_object=tuple(per_object),
        centroid_distance_px=cd,
        centroid_distance_ratio=ratio,
        iou_threshold=float(iou_threshold),
        scale=float(scale),
    )


def evaluate_mot(
    gt: ArrayLike,
    result: ArrayLike,
    *,
    iou_threshold: float = 0.5,
    scale: float = 1.0,
    image_size: tuple[int, int] | None = None,
    benchmark: BenchmarkName = "auto",
    num_frames: int | None = None,
    on_progress: Report | None = None,
) -> MotMetrics:
    """Score a tracking result against ground truth.

    Parameters
    ----------
    gt : (M, 6..10) array_like of float
        Ground truth MOT rows. Rows with ``conf == 0`` are not scored (see Notes).
    result : (R, 6..10) array_like of float
        Result MOT rows (one id per track; ``conf`` is ignored).
    iou_threshold : float
        A result box can match a ground-truth box when their IoU is >= this, in (0, 1].
    scale : float
        Multiplies the ground-truth boxes (left, top, width, height) before scoring, e.g. 0.625
        for PETS09 ground truth (768x576) against a tracker run on the 480x360 video.
    image_size : (width, height), optional
        Image size for the centroid-distance ratio (NaN without it): two finite numbers > 0.
    benchmark : {"auto", "MOT15", "MOT16", "MOT17", "MOT20"}
        Which MOTChallenge rules choose the scored rows (:func:`pftrack.eval.prepare_mot`);
        ``"auto"`` guesses MOT15 or MOT17 from the columns (:func:`pftrack.eval.guess_benchmark`).
    num_frames : int, optional
        The sequence length (``seqLength``); a row in a later frame is an error.
    on_progress : callable, optional
        Called now and then as ``on_progress(f)``, `f` the fraction of the work done (from 0
        to 1, ending with 1), as the frames are scored: ``pftrack eval``'s bar.

    Returns
    -------
    MotMetrics

    Warns
    -----
    UserWarning
        A result of some rows none of whose boxes matches a scored ground-truth box at
        `iou_threshold` (MOTA at or below 0): frames numbered otherwise, or another sequence's
        tracks. The warning names the two spans of frames; the scores are returned as
        computed. An empty result says nothing.

    Notes
    -----
    Per-frame matching is TrackEval's ``CLEAR`` (the MOTChallenge server's): in each frame
    holding both ground-truth and result boxes, one Hungarian assignment maximises, over the
    pairs whose IoU reaches `iou_threshold` (less ``eps``, 2.2e-16, as TrackEval), 1000 for each
    pair that goes on from the last such frame (the object was matched to that result id there)
    plus the pair's IoU: a track goes on where it can, and IoU decides the rest. Exact ties go
    by the order of the rows in the frame, as TrackEval reads them from the file. A match to a
    different id than the object's last match, however long ago, is an identity switch.
    (py-motmetrics differs: it keeps a match after any gap and pairs the rest separately, for
    the most matches: below an `iou_threshold` of 0.5 the largest IoU sum can be fewer.)
    Identity (IDF1) counts the frames where a pair's IoU is >= `iou_threshold`, as TrackEval's
    ``Identity``.

    The rows scored are those HOTA scores, chosen by TrackEval's MOTChallenge preprocessing
    (:func:`pftrack.eval.prepare_mot`): ground-truth rows whose ``conf`` (the "consider" flag)
    truncates to 0 are left out; for MOT16/17/20 also other classes than pedestrian, and result
    boxes matched to a distractor (a static person, a reflection, ...). Under MOT15 rules a
    result box on a left-out ground-truth box stays, as a false positive. The figures are
    TrackEval's ``CLEAR`` and ``Identity`` on the same files
    (``tests/eval/test_hota.py``); IDF1, IDP and IDR are py-motmetrics' too on the rows scored
    (its CLEAR-MOT differs in five details: ``docs/eval.md``).

    References
    ----------
    .. [1] Bernardin, K. & Stiefelhagen, R. (2008). Evaluating multiple object tracking
       performance: the CLEAR MOT metrics. EURASIP J. Image and Video Processing.
    .. [2] Ristani, E. et al. (2016). Performance measures and a data set for multi-target,
       multi-camera tracking. ECCV workshops.
    .. [3] Smith, K., Gatica-Perez, D., Odobez, J.-M. & Ba, S. (2005). Evaluating multi-object
       tracking. CVPR workshop on empirical evaluation methods in computer vision.
    """
    m = clear_scores(
        gt, result, iou_threshold=iou_threshold, scale=scale, image_size=image_size,
        benchmark=benchmark, num_frames=num_frames, on_progress=on_progress,
    )  # fmt: skip
    # was: MOTA -1.0 without a word for results numbered from frame 101 against a truth of
    # frames 1-71 (evaluate_sequence and pftrack eval said it)
    say_none_matched(
        "evaluate_mot", gt, result, truth=m.num_objects, matches=m.num_matches,
        iou_threshold=m.iou_threshold, scored=f"MOTA {m.mota:.3f}",
    )  # fmt: skip
    return m


def combine_mot(parts: Sequence[MotMetrics]) -> MotMetrics:
    """Several sequences' scores as one, as TrackEval and py-motmetrics combine them.

    Counts (FP, FN, IDSW, Frag, MT/PT/ML, IDTP/IDFP/IDFN, matches, boxes, objects) are summed and
    the ratios recomputed from the sums: MOTA from summed FN + FP + IDSW over summed ground-truth
    boxes, MOTP as the mean IoU of all matches, IDF1/IDP/IDR from summed IDTP/IDFP/IDFN.
    Smith et al.'s success rates are the means over all objects of all sequences. The centroid
    distances are NaN (a mean over pairs that is not kept per sequence) and
    `success_per_object` is empty (ids repeat across sequences).

    Ratios over no box are 0, as TrackEval's ``combine_sequences`` computes them (``x / max(1,
    n)``); so is MOTA's, ``(TP - FP - IDSW) / max(1, TP + FN)``, which is ``-(FP + IDSW)``
    when no sequence has a ground-truth box (while each such sequence's own MOTA is 0: TrackEval
    scores an empty sequence before its formulas).

    Parameters
    ----------
    parts : sequence of MotMetrics
        One per sequence, all with the same IoU threshold.

    Returns
    -------
    MotMetrics
    """
    if isinstance(parts, MotMetrics) or not isinstance(parts, Sequence):
        raise TypeError(
            f"combine_mot: parts is {type(parts).__name__}, expected a list of MotMetrics"
        )
    if not parts:
        raise ValueError("combine_mot: no sequences to combine")
    for k, p in enumerate(parts):
        if not isinstance(p, MotMetrics):
            raise TypeError(not_parts_message("combine_mot", k, p, "MotMetrics"))
    thresholds = {p.iou_threshold for p in parts}
    if len(thresholds) != 1:
        raise ValueError(f"combine_mot: IoU thresholds differ: {sorted(thresholds)}")

    def total(name: str) -> int:
        return sum(int(getattr(p, name)) for p in parts)

    n_gt, n_res, n_match = total("num_objects"), total("num_predictions"), total("num_matches")
    fn, fp, sw = total("misses"), total("false_positives"), total("num_switches")
    idtp, idfp, idfn = total("idtp"), total("idfp"), total("idfn")
    n_obj = total("num_unique_objects")
    iou_sum = 0.0
    for p in parts:  # TrackEval's sum of MOTP_sum over sequences, term by term
        iou_sum += p.iou_sum
    scales = {p.scale for p in parts}
    nan = float("nan")

    def ratio(num: float, den: float) -> float:
        """TrackEval's ``num / max(1, den)`` (den is a count: 0 or >= 1)."""
        return num / den if den else 0.0

    def over_objects(name: str) -> float:
        weighted = [(getattr(p, name), p.num_unique_objects) for p in parts if p.num_unique_objects]
        return sum(v * n for v, n in weighted) / n_obj if n_obj else nan

    return MotMetrics(
        # TrackEval's (TP - FP - IDSW) / max(1, TP + FN): -(FP + IDSW) without ground truth
        mota=(n_match - fp - sw) / max(1, n_gt),
        motp_iou=ratio(iou_sum, n_match),
        iou_sum=iou_sum,
        idf1=ratio(2 * idtp, 2 * idtp + idfp + idfn),
        idp=ratio(idtp, idtp + idfp),
        idr=ratio(idtp, idtp + idfn),
        idtp=idtp,
        idfp=idfp,
        idfn=idfn,
        num_switches=sw,
        num_fragmentations=total("num_fragmentations"),
        mostly_tracked=total("mostly_tracked"),
        partially_tracked=total("partially_tracked"),
        mostly_lost=total("mostly_lost"),
        false_positives=fp,
        misses=fn,
        num_matches=n_match,
        num_objects=n_gt,
        num_predictions=n_res,
        num_unique_objects=n_obj,
        num_frames=total("num_frames"),
        num_ignored_gt=total("num_ignored_gt"),
        num_ignored_predictions=total("num_ignored_predictions"),
        precision=ratio(n_match, n_res),
        recall=ratio(n_match, n_gt),
        success_rate=over_objects("success_rate"),
        success_rate_strict=over_objects("success_rate_strict"),
        success_per_object=(),
        centroid_distance_px=nan,
        centroid_distance_ratio=nan,
        iou_threshold=parts[0].iou_threshold,
        scale=parts[0].scale if len(scales) == 1 else nan,
    )
