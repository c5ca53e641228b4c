"""HOTA, DetA, AssA and their parts (Luiten et al. 2021), as TrackEval computes them.

The functions here reproduce TrackEval 1.3.0's ``HOTA`` metric on its ``MotChallenge2DBox``
dataset, including that dataset's preprocessing of ground truth (see :func:`prepare_mot`):
``tests/eval/test_hota.py`` holds them equal to TrackEval to 1e-9 on real sequences.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import linear_sum_assignment

from pftrack._check import option
from pftrack._progress import Report, check_report, reporting
from pftrack._typing import BenchmarkName
from pftrack.eval.rows import (  # the scored rows; here too, as before
    BENCHMARKS,
    _mot_iou,
    check_eval_rows,
    guess_benchmark,
    mot_iou,
    not_parts_message,
    prepare_mot,
    say_none_matched,
)
from pftrack.io.mot import ID, LEFT, group_by_frame

__all__ = [
    "ALPHAS",
    "BENCHMARKS",
    "HotaMetrics",
    "combine_hota",
    "evaluate_hota",
    "guess_benchmark",
    "mot_iou",
    "prepare_mot",
]

#: The 19 localisation thresholds HOTA averages over: 0.05, 0.10, ..., 0.95 (TrackEval's values).
ALPHAS: NDArray[np.float64] = np.arange(0.05, 0.99, 0.05)

_EPS = float(np.finfo(float).eps)

#: Where :func:`evaluate_hota`'s three passes over the frames (IoU; soft match counts;
#: assignment) begin and end, as fractions of its time, for its `on_progress` (before them:
#: the rows chosen and grouped; after: the thresholds). Measured on a file of 100 000 frames
#: and 5000 ids (5 December).
_PASSES = ((0.22, 0.63), (0.63, 0.77), (0.77, 0.91))


@dataclasses.dataclass(frozen=True, eq=False)  # arrays: no element-wise ==
class HotaMetrics:
    """HOTA and its parts for one sequence or several combined.

    Each array has one value per localisation threshold in :data:`ALPHAS`; the scalar
    properties are their means over the thresholds, as TrackEval reports them.

    Mind the names: the fields ``ass_a``, ``ass_re``, ``ass_pr`` and ``loc_a`` are the
    (19,) arrays, and their means (the figures TrackEval prints) are the floats
    ``ass_a_mean``, ``ass_re_mean``, ``ass_pr_mean`` and ``loc_a_mean``; the detection
    figures are the other way round: ``det_a``, ``det_re``, ``det_pr`` (and ``hota``) are
    floats, their arrays ``det_a_alpha``, ``det_re_alpha``, ``det_pr_alpha`` (and
    ``hota_alpha``).

    ================================================  ==================================
    float (mean over the 19 thresholds)               (19,) array, one per threshold
    ================================================  ==================================
    ``hota``                                          ``hota_alpha``
    ``det_a``, ``det_re``, ``det_pr``                 ``det_a_alpha``, ``det_re_alpha``,
                                                      ``det_pr_alpha``
    ``ass_a_mean``, ``ass_re_mean``, ``ass_pr_mean``  ``ass_a``, ``ass_re``, ``ass_pr``
    ``loc_a_mean``                                    ``loc_a``
    ``hota0`` (HOTA at alpha 0.05)                    ``tp``, ``fn``, ``fp`` (counts)
    ================================================  ==================================

    Attributes
    ----------
    tp, fn, fp : (19,) ndarray of float64
        Detection true positives, false negatives and false positives (counts) per threshold.
    ass_a, ass_re, ass_pr : (19,) ndarray of float64
        Association accuracy, recall and precision per threshold (arrays, unlike ``det_a``:
        their means are ``ass_a_mean``, ``ass_re_mean``, ``ass_pr_mean``).
    loc_a : (19,) ndarray of float64
        Mean IoU of the matched pairs per threshold (1 when there is no match); its mean is
        ``loc_a_mean``.
    """

    tp: NDArray[np.float64]
    fn: NDArray[np.float64]
    fp: NDArray[np.float64]
    ass_a: NDArray[np.float64]
    ass_re: NDArray[np.float64]
    ass_pr: NDArray[np.float64]
    loc_a: NDArray[np.float64]

    @property
    def det_a_alpha(self) -> NDArray[np.float64]:
        """DetA per threshold: ``TP / (TP + FN + FP)``."""
        return self.tp / np.maximum(1, self.tp + self.fn + self.fp)

    @property
    def det_re_alpha(self) -> NDArray[np.float64]:
        """Detection recall per threshold: ``TP / (TP + FN)``."""
        return self.tp / np.maximum(1, self.tp + self.fn)

    @property
    def det_pr_alpha(self) -> NDArray[np.float64]:
        """Detection precision per threshold: ``TP / (TP + FP)``."""
        return self.tp / np.maximum(1, self.tp + self.fp)

    @property
    def hota_alpha(self) -> NDArray[np.float64]:
        """HOTA per threshold: ``sqrt(DetA * AssA)``."""
        out: NDArray[np.float64] = np.sqrt(self.det_a_alpha * self.ass_a)
        return out

    @property
    def hota(self) -> float:
        """HOTA: the mean over thresholds of ``sqrt(DetA_alpha * AssA_alpha)``."""
        return float(np.mean(self.hota_alpha))

    @property
    def det_a(self) -> float:
        """DetA, mean over thresholds."""
        return float(np.mean(self.det_a_alpha))

    @property
    def ass_a_mean(self) -> float:
        """AssA, mean over thresholds."""
        return float(np.mean(self.ass_a))

    @property
    def det_re(self) -> float:
        """DetRe, mean over thresholds."""
        return float(np.mean(self.det_re_alpha))

    @property
    def det_pr(self) -> float:
        """DetPr, mean over thresholds."""
        return float(np.mean(self.det_pr_alpha))

    @property
    def ass_re_mean(self) -> float:
        """AssRe, mean over thresholds."""
        return float(np.mean(self.ass_re))

    @property
    def ass_pr_mean(self) -> float:
        """AssPr, mean over thresholds."""
        return float(np.mean(self.ass_pr))

    @property
    def loc_a_mean(self) -> float:
        """LocA, mean over thresholds."""
        return float(np.mean(self.loc_a))

    @property
    def hota0(self) -> float:
        """HOTA at the lowest threshold (0.05), TrackEval's ``HOTA(0)``."""
        return float(self.hota_alpha[0])

    def __str__(self) -> str:
        """What ``print(metrics)`` shows: :meth:`summary` as percentages (``repr``: arrays).

        Was the dataclass's every field, seven (19,) arrays of them.
        """
        names = ("HOTA", "DetA", "AssA", "DetRe", "DetPr", "AssRe", "AssPr", "LocA")
        values = [f"{100.0 * v:.1f}" for v in self.summary().values()]
        widths = [max(len(n), len(v)) for n, v in zip(names, values, strict=True)]
        return (
            "\n".join(
                "  ".join(c.rjust(w) for c, w in zip(row, widths, strict=True))
                for row in (names, values)
            )
            + "\n(TrackEval's HOTA and its parts, means over the 19 localisation thresholds)"
        )

    def summary(self) -> dict[str, float]:
        """The scalar scores (means over thresholds), keyed by metric name."""
        return {
            "hota": self.hota,
            "det_a": self.det_a,
            "ass_a": self.ass_a_mean,
            "det_re": self.det_re,
            "det_pr": self.det_pr,
            "ass_re": self.ass_re_mean,
            "ass_pr": self.ass_pr_mean,
            "loc_a": self.loc_a_mean,
        }

    def as_dict(self) -> dict[str, object]:
        """:meth:`summary`, ``hota0``, then the per-threshold arrays as lists (JSON-ready)."""
        out: dict[str, object] = dict(self.summary())
        out["hota0"] = self.hota0  # a scalar too (was left out of the JSON and CSV)
        out["alphas"] = [round(float(a), 2) for a in ALPHAS]
        for name in ("hota_alpha", "det_a_alpha", "ass_a", "loc_a", "tp", "fn", "fp"):
            out[f"{name.removesuffix('_alpha')}_per_alpha"] = [
                float(v) for v in getattr(self, name)
            ]
        return out


def _empty(num_gt: int, num_res: int) -> HotaMetrics:
    n = len(ALPHAS)
    z = np.zeros(n)
    return HotaMetrics(
        tp=z.copy(),
        fn=np.full(n, float(num_gt)),
        fp=np.full(n, float(num_res)),
        ass_a=z.copy(),
        ass_re=z.copy(),
        ass_pr=z.copy(),
        loc_a=np.ones(n),
    )


def hota_scores(
    gt: ArrayLike,
    result: ArrayLike,
    *,
    benchmark: BenchmarkName = "auto",
    scale: float = 1.0,
    num_frames: int | None = None,
    on_progress: Report | None = None,
) -> HotaMetrics:
    """:func:`evaluate_hota`'s scores, without its warning of a result that matched nothing.

    :func:`~pftrack.eval.evaluate_sequence` scores with it and says that warning once itself.
    """
    check_report(on_progress, "evaluate_hota")
    option(benchmark, "evaluate_hota: benchmark", ("auto", *BENCHMARKS))
    # named as evaluate_mot names them (was: "ground truth must hold real numbers", no function)
    gt = check_eval_rows(gt, "evaluate_hota: gt")
    result = check_eval_rows(result, "evaluate_hota: result")
    if benchmark == "auto":
        benchmark = guess_benchmark(gt)
    g, r = prepare_mot(gt, result, benchmark=benchmark, scale=scale, num_frames=num_frames)
    if len(r) == 0 or len(g) == 0:
        if on_progress is not None:
            on_progress(1.0)
        return _empty(len(g), len(r))
    gf, rf = group_by_frame(g), group_by_frame(r)
    g_ids, g_idx = np.unique(g[:, ID].astype(np.int64), return_inverse=True)
    r_ids, r_idx = np.unique(r[:, ID].astype(np.int64), return_inverse=True)
    gt_count = np.bincount(g_idx, minlength=len(g_ids)).astype(np.float64)
    res_count = np.bincount(r_idx, minlength=len(r_ids)).astype(np.float64)

    # Frames with both gt and result boxes: (gt index, result index, IoU) of each.
    both: list[tuple[NDArray[np.intp], NDArray[np.intp], NDArray[np.float64]]] = []
    for f in reporting(sorted(set(gf) & set(rf)), on_progress, *_PASSES[0]):
        gi = np.searchsorted(g_ids, gf[f][:, ID].astype(np.int64))
        ri = np.searchsorted(r_ids, rf[f][:, ID].astype(np.int64))
        both.append((gi, ri, _mot_iou(gf[f][:, LEFT : LEFT + 4], rf[f][:, LEFT : LEFT + 4])))

    # Soft match counts of the id pairs that overlap somewhere, as sorted keys (gt index *
    # n_res_ids + result index): a pair that never overlaps counts 0 and aligns 0. Summed in
    # frame order, as a dense (gt ids, result ids) matrix would: the same bits, without the
    # matrix (5000 ids a side: 200 MB each, and a few of them).
    n_res_ids = len(r_ids)
    keys_f: list[NDArray[np.int64]] = []
    soft_f: list[NDArray[np.float64]] = []
    for gi, ri, sim in reporting(both, on_progress, *_PASSES[1]):
        denom = sim.sum(0)[None, :] + sim.sum(1)[:, None] - sim
        on = sim > 0  # elsewhere the soft count is 0: it adds nothing
        keys_f.append((gi[:, None] * n_res_ids + ri[None, :])[on].astype(np.int64))
        soft_f.append(np.where(denom[on] > _EPS, sim[on] / denom[on], 0.0))
    pair_keys, pair_of = np.unique(
        np.concatenate(keys_f) if keys_f else np.zeros(0, np.int64), return_inverse=True
    )
    potential = np.bincount(
        pair_of, weights=np.concatenate(soft_f) if soft_f else None, minlength=len(pair_keys)
    )
    align = potential / (
        gt_count[pair_keys // n_res_ids] + res_count[pair_keys % n_res_ids] - potential
    )

    pair_g: list[NDArray[np.intp]] = []
    pair_r: list[NDArray[np.intp]] = []
    pair_s: list[NDArray[np.float64]] = []
    for gi, ri, sim in reporting(both, on_progress, *_PASSES[2]):
        score = np.zeros_like(sim)
        on = sim > 0
        at = np.searchsorted(pair_keys, (gi[:, None] * n_res_ids + ri[None, :])[on])
        score[on] = align[at] * sim[on]
        rows_m, cols_m = linear_sum_assignment(-score)
        pair_g.append(gi[rows_m])
        pair_r.append(ri[cols_m])
        pair_s.append(sim[rows_m, cols_m])
    mg = np.concatenate(pair_g) if pair_g else np.zeros(0, dtype=np.intp)
    mr = np.concatenate(pair_r) if pair_r else np.zeros(0, dtype=np.intp)
    ms = np.concatenate(pair_s) if pair_s else np.zeros(0)

    hit = ms[None, :] >= ALPHAS[:, None] - _EPS  # (alphas, matched pairs)
    tp = hit.sum(axis=1).astype(np.float64)
    loc_sum = (hit * ms[None, :]).sum(axis=1)
    ass_a = np.zeros(len(ALPHAS))
    ass_re = np.zeros(len(ALPHAS))
    ass_pr = np.zeros(len(ALPHAS))
    for a in range(len(ALPHAS)):
        keys, tpa = np.unique(mg[hit[a]] * n_res_ids + mr[hit[a]], return_counts=True)
        c = tpa.astype(np.float64)
        gc, rc = gt_count[keys // n_res_ids], res_count[keys % n_res_ids]
        w = max(1.0, float(tp[a]))
        ass_a[a] = np.sum(c * (c / np.maximum(1, gc + rc - c))) / w
        ass_re[a] = np.sum(c * (c / np.maximum(1, gc))) / w
        ass_pr[a] = np.sum(c * (c / np.maximum(1, rc))) / w
    if on_progress is not None:
        on_progress(1.0)
    return HotaMetrics(
        tp=tp,
        fn=len(g) - tp,
        fp=len(r) - tp,
        ass_a=ass_a,
        ass_re=ass_re,
        ass_pr=ass_pr,
        loc_a=np.maximum(1e-10, loc_sum) / np.maximum(1e-10, tp),
    )


def evaluate_hota(
    gt: ArrayLike,
    result: ArrayLike,
    *,
    benchmark: BenchmarkName = "auto",
    scale: float = 1.0,
    num_frames: int | None = None,
    on_progress: Report | None = None,
) -> HotaMetrics:
    """HOTA, DetA, AssA, LocA and their recall/precision parts of one sequence.

    Parameters
    ----------
    gt, result : (M, 6..10) array_like of float
        Ground-truth and result MOT rows, as read by :func:`pftrack.io.mot.read_mot`.
    benchmark : {"auto", "MOT15", "MOT16", "MOT17", "MOT20"}
        Passed to :func:`prepare_mot`; ``"auto"`` (the default, as :func:`evaluate_sequence`)
        guesses MOT15 or MOT17 from the columns (:func:`guess_benchmark`; ``pftrack eval``
        first takes the benchmark a TrackEval folder names, ``MOT20-train``).
    scale, num_frames
        Passed to :func:`prepare_mot`, which chooses the rows that are scored.
    on_progress : callable, optional
        Called now and then as ``on_progress(f)``, `f` the fraction of the work done (from 0
        to 1, ending with 1), as the frames are scored: ``pftrack eval``'s bar.

    Returns
    -------
    HotaMetrics

    Warns
    -----
    UserWarning
        A result of some rows none of whose boxes matches a scored ground-truth box at any
        threshold (IoU 0.05 or more; HOTA 0): frames numbered otherwise, or another sequence's
        tracks, as :func:`evaluate_mot` says at its `iou_threshold`. The scores are returned
        as computed. An empty result says nothing.

    Notes
    -----
    Similarity is :func:`mot_iou`. First, over the whole sequence, every (gt id, result id)
    pair accumulates ``sum_t IoU_t / (rowsum + colsum - IoU_t)`` (its soft match count), giving a
    global alignment score ``A = count / (n_gt + n_res - count)``. Then, in each frame, boxes are
    matched by the Hungarian algorithm maximising ``A * IoU``; for each threshold alpha a match
    with ``IoU >= alpha`` is a TP. AssA at alpha is the TP-weighted mean over matched pairs of
    ``TPA / (TPA + FNA + FPA)`` (TPA: frames the pair is matched; FNA, FPA: the rest of the
    gt's and the result track's boxes). Everything is TrackEval 1.3.0's arithmetic, vectorised
    over thresholds.

    References
    ----------
    .. [1] Luiten, J. et al. (2021). HOTA: a higher order metric for evaluating multi-object
       tracking. International Journal of Computer Vision 129, 548-578.
    .. [2] Luiten, J. & Hoffhues, A. (2020). TrackEval. (``trackeval.metrics.HOTA``)
    """
    h = hota_scores(
        gt, result, benchmark=benchmark, scale=scale, num_frames=num_frames,
        on_progress=on_progress,
    )  # fmt: skip
    # matched nothing at the lowest threshold: at none (was: HOTA 0 without a word)
    say_none_matched(
        "evaluate_hota", gt, result, truth=int(h.tp[0] + h.fn[0]), matches=int(h.tp[0]),
        iou_threshold=float(ALPHAS[0]), scored=f"HOTA {h.hota:.3f}",
    )  # fmt: skip
    return h


def combine_hota(parts: Iterable[HotaMetrics] | Sequence[HotaMetrics]) -> HotaMetrics:
    """Several sequences as one, as TrackEval combines them.

    TP, FN and FP are summed per threshold; AssA, AssRe, AssPr and LocA are the TP-weighted
    means of the sequences' values, so DetA and HOTA are those of the summed counts.
    """
    if isinstance(parts, HotaMetrics):
        raise TypeError("combine_hota: parts is HotaMetrics, expected a list of HotaMetrics")
    items = list(parts)
    if not items:
        raise ValueError("combine_hota: no sequences to combine")
    for k, p in enumerate(items):
        if not isinstance(p, HotaMetrics):
            raise TypeError(not_parts_message("combine_hota", k, p, "HotaMetrics"))
    tp = np.sum([p.tp for p in items], axis=0)
    w = np.maximum(1.0, tp)

    def weighted(name: str) -> NDArray[np.float64]:
        out: NDArray[np.float64] = sum(getattr(p, name) * p.tp for p in items) / w
        return out

    loc = sum(p.loc_a * p.tp for p in items)
    return HotaMetrics(
        tp=tp,
        fn=np.sum([p.fn for p in items], axis=0),
        fp=np.sum([p.fp for p in items], axis=0),
        ass_a=weighted("ass_a"),
        ass_re=weighted("ass_re"),
        ass_pr=weighted("ass_pr"),
        loc_a=np.maximum(1e-10, loc) / np.maximum(1e-10, tp),
    )
