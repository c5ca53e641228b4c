"""The rows a MOTChallenge evaluation scores: checks, TrackEval's preprocessing and IoU.

Shared by HOTA (:mod:`pftrack.eval.hota`) and CLEAR-MOT/IDF1 (:mod:`pftrack.eval.metrics`), so
that both score the same rows.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import linear_sum_assignment

from pftrack._check import (
    MAX_FRAME,
    MOT_DEFAULTS,
    bad_id_message,
    exactly,
    first_bad_id,
    frames_from_1,
    integer,
    number,
    option,
    path_refused,
    real_array,
)
from pftrack._warn import warn
from pftrack.boxes import _box_rows
from pftrack.io.mot import CONF, FRAME, ID, LEFT, group_by_frame

__all__ = [
    "BENCHMARKS",
    "NONE_MATCHED",
    "none_matched",
    "say_none_matched",
    "check_eval_rows",
    "check_unique_ids",
    "frame_ranges_notes",
    "guess_benchmark",
    "mot_iou",
    "prepare_mot",
    "result_class_note",
]

Benchmark = Literal["MOT15", "MOT16", "MOT17", "MOT20"]
#: Ground-truth conventions :func:`prepare_mot` knows (MOT16 and MOT17 are the same).
BENCHMARKS: tuple[str, ...] = ("MOT15", "MOT16", "MOT17", "MOT20")

_EPS = float(np.finfo(float).eps)
# MOTChallenge 16/17/20 class numbers (column 8 of ground truth).
_PEDESTRIAN = 1
_DISTRACTORS = (2, 7, 8, 12)  # person_on_vehicle, static_person, distractor, reflection
_NON_MOT_VEHICLE = 6  # a distractor in MOT20 only
_N_CLASSES = 13
_CLASS, _VISIBILITY = 7, 8  # columns of MOT16+ ground truth


def check_eval_rows(rows: ArrayLike, what: str) -> NDArray[np.float64]:
    """Scored MOT rows as an ``(M, 10)`` float64 array; TypeError/ValueError named by `what`.

    Real numbers, ``(M, 6..10)``, the first 6 columns finite, frames and ids integers within
    ``MAX_FRAME`` (they are cast to int: an id 1.5 is refused, not scored as 1, the test
    ``pftrack recover`` makes), frames from 1 and no negative width or height (as
    :func:`~pftrack.io.mot.read_mot` refuses them); missing columns padded with what
    ``read_mot`` gives a shorter line (:data:`~pftrack._check.MOT_DEFAULTS`: conf 1, x, y, z
    -1), so an array and the file it was written to score the same. Shared by
    :func:`evaluate_mot` and :func:`~pftrack.eval.hota.evaluate_hota`. A path is refused,
    TypeError: ``{what} is a path ('gt.txt'); read it with pftrack.read_mot(path)``.
    """
    path_refused(rows, what, "pftrack.read_mot(path)")
    a = real_array(rows, what)
    if a.size == 0:
        return np.zeros((0, 10))
    if a.ndim != 2 or not 6 <= a.shape[1] <= 10:
        raise ValueError(f"{what} has shape {a.shape}, expected (M, 6..10) MOT rows")
    if not np.all(np.isfinite(a[:, :6])):
        raise ValueError(f"{what} has non-finite values in its first 6 columns")
    huge = np.abs(a[:, :2]) > MAX_FRAME
    if huge.any():
        k = int(np.flatnonzero(huge.any(axis=1))[0])
        raise ValueError(f"{what} row {k} has frame or id {a[k, :2].tolist()} beyond {MAX_FRAME}")
    frac = a[:, 0] != np.floor(a[:, 0])
    if frac.any():  # cast to int, 1.5 would be scored as frame 1
        k = int(np.flatnonzero(frac)[0])
        raise ValueError(f"{what} row {k} has frame {exactly(a[k, 0])}, expected an integer")
    early = a[:, 0] < 1
    if early.any():  # as read_mot refuses it: MOTChallenge frames count from 1
        k = int(np.flatnonzero(early)[0])
        raise ValueError(
            f"{what} row {k} has frame {exactly(a[k, 0])}, expected >= 1 {frames_from_1(a[k, 0])}"
        )
    negative = (a[:, 4] < 0) | (a[:, 5] < 0)
    if negative.any():  # as read_mot refuses it: such a box overlaps nothing, silently
        k = int(np.flatnonzero(negative)[0])
        raise ValueError(
            f"{what} row {k} has a negative box width or height ({a[k, 4]:g} x {a[k, 5]:g})"
        )
    k_id = first_bad_id(a[:, 1])
    if k_id is not None:  # cast to int, 1.5 and 1.7 would be one id: refused as recover does
        raise ValueError(f"{what} row {k_id}: {bad_id_message(a[k_id, 1])}")
    if a.shape[1] < 10:  # the columns a shorter line of a file is read with (read_mot)
        pad = np.tile(np.asarray(MOT_DEFAULTS[a.shape[1] - 6 :]), (a.shape[0], 1))
        a = np.hstack([a, pad])
    return a


_DETECTIONS_HINT = (
    ": is it a detections file (det.txt has id -1 on every row)? Score tracks, with one id per "
    "object"
)


def check_ids_not_negative(rows: NDArray[np.float64], name: str) -> None:
    """Refuse a negative id (ValueError naming `name`, the id and its frame), as TrackEval does.

    TrackEval fails on one (an IndexError or "negative dimensions"); pftrack scored it as any
    other id. Id -1 is what detection files hold: the message asks whether it is one.
    """
    negative = rows[:, ID] < 0
    if np.any(negative):
        k = int(np.flatnonzero(negative)[0])
        bad = int(rows[k, ID])
        hint = _DETECTIONS_HINT if bad == -1 else ""
        raise ValueError(
            f"{name} has id {bad} in frame {int(rows[k, FRAME])}: ids must be >= 0, as "
            f"TrackEval requires{hint}"
        )


#: What combines each kind of scores (named when a list holds another kind).
_COMBINERS = {
    "MotMetrics": "pftrack.eval.combine_mot",
    "HotaMetrics": "pftrack.eval.combine_hota",
    "SequenceScores": "SequenceScores.combine",
}


def not_parts_message(fn: str, k: int, value: object, expected: str) -> str:
    """Why `value`, item `k` of `fn`'s parts, is no `expected`: naming what combines it.

    Shared by :func:`~pftrack.eval.combine_mot`, :func:`~pftrack.eval.combine_hota` and
    :meth:`~pftrack.eval.SequenceScores.combine`, whose parts are easily mixed up (each raised
    an AttributeError on another kind).
    """
    kind = type(value).__name__
    hint = f"; {kind} are combined by {_COMBINERS[kind]}" if kind in _COMBINERS else ""
    if kind == "SequenceScores" and expected != kind:
        part = "mot" if expected == "MotMetrics" else "hota"
        hint += f" (or pass [s.{part} for s in scores])"
    return f"{fn}: parts[{k}] is {kind}, expected {expected}{hint}"


def check_unique_ids(frames: dict[int, NDArray[np.float64]], name: str) -> None:
    """Refuse rows of one id twice in one frame (ValueError naming `name`, the id and frame).

    `frames`: rows grouped by frame. Shared by :func:`evaluate_mot` and
    :func:`~pftrack.eval.hota.evaluate_hota`, so both refuse what ``pftrack eval`` refuses.
    """
    # all frames at once (one np.unique per frame took 6 s over 100 000 frames); the frames
    # one by one only to name the first that repeats an id
    sizes = np.fromiter((len(r) for r in frames.values()), np.int64, len(frames))
    if not sizes.sum():
        return
    ids = np.concatenate([r[:, ID] for r in frames.values()]).astype(np.int64)
    slot = np.repeat(np.arange(len(sizes)), sizes)
    order = np.lexsort((ids, slot))
    if not np.any((np.diff(ids[order]) == 0) & (np.diff(slot[order]) == 0)):
        return
    for f, r in frames.items():
        ids, counts = np.unique(r[:, ID].astype(np.int64), return_counts=True)
        if np.any(counts > 1):
            twice = int(ids[counts > 1][0])
            hint = _DETECTIONS_HINT if twice == -1 else " (ids must be unique within a frame)"
            raise ValueError(f"{name} has id {twice} more than once in frame {f}{hint}")


def mot_iou(a: ArrayLike, b: ArrayLike) -> NDArray[np.float64]:
    """IoU of every box of `a` with every box of `b`, with TrackEval's arithmetic.

    Boxes are MOTChallenge ``left, top, width, height``. The corners are formed first and areas
    taken from them (``(x1 - x0) * (y1 - y0)``), exactly as TrackEval does, so that a match at
    a threshold is decided the same way to the last bit. A box with no area overlaps nothing,
    and an empty union gives 0.

    Parameters
    ----------
    a : (n, 4) array_like of float
        Boxes ``left, top, width, height``; one box may be given as (4,).
    b : (m, 4) array_like of float
        Boxes ``left, top, width, height``; one box may be given as (4,).

    Returns
    -------
    (n, m) ndarray of float64

    Raises
    ------
    TypeError
        Boxes that are not real numbers.
    ValueError
        Boxes not of shape (n, 4) or (4,) (MOT rows: pass ``rows[:, 2:6]``), a value not finite
        or beyond ±1e9 px, a negative width or height (as :func:`~pftrack.boxes.iou_xywh`).
    """
    return _mot_iou(_box_rows(a, "mot_iou", "a"), _box_rows(b, "mot_iou", "b"))


def _mot_iou(a: ArrayLike, b: ArrayLike) -> NDArray[np.float64]:
    """:func:`mot_iou` without its checks: the scorers' per-frame call on checked rows."""
    p = np.array(a, dtype=np.float64).reshape(-1, 4)
    q = np.array(b, dtype=np.float64).reshape(-1, 4)
    p[:, 2:] += p[:, :2]
    q[:, 2:] += q[:, :2]
    # per coordinate, (n, m) at a time: the same operations as on (n, m, 4), 3x faster
    w = np.minimum(p[:, None, 2], q[None, :, 2]) - np.maximum(p[:, None, 0], q[None, :, 0])
    h = np.minimum(p[:, None, 3], q[None, :, 3]) - np.maximum(p[:, None, 1], q[None, :, 1])
    inter = np.maximum(w, 0) * np.maximum(h, 0)
    area_p = (p[:, 2] - p[:, 0]) * (p[:, 3] - p[:, 1])
    area_q = (q[:, 2] - q[:, 0]) * (q[:, 3] - q[:, 1])
    union = area_p[:, None] + area_q[None, :] - inter
    inter[area_p <= _EPS, :] = 0
    inter[:, area_q <= _EPS] = 0
    inter[union <= _EPS] = 0
    union[union <= _EPS] = 1
    out: NDArray[np.float64] = inter / union
    return out


def guess_benchmark(gt: ArrayLike) -> Literal["MOT15", "MOT17"]:
    """``"MOT17"`` if `gt` looks like MOT16/17/20 ground truth, else ``"MOT15"``.

    MOT16+ ground truth has ``frame, id, left, top, w, h, flag, class, visibility``: the class
    column holds integers 1-13 on every row and the visibility column values in [0, 1] on every
    row, or -1 on every row (no visibility column: 8-column files, which TrackEval scores as
    MOT17 too). MOT15 ground truth has world coordinates there, normally -1 -1 -1. MOT20's one
    extra distractor class is not guessed: name ``"MOT20"`` explicitly (``pftrack eval`` takes
    it from TrackEval's folder name, ``MOT20-train``:
    :func:`~pftrack.eval.sequences.benchmark_of_path`).
    """
    g = check_eval_rows(gt, "ground truth")
    if len(g) == 0:
        return "MOT15"
    cls, vis = g[:, _CLASS], g[:, _VISIBILITY]
    integral = np.all(cls == np.round(cls)) and np.all((cls >= 1) & (cls <= _N_CLASSES))
    visibility = np.all((vis >= 0) & (vis <= 1)) or np.all(vis == -1)  # -1: column missing
    return "MOT17" if integral and visibility else "MOT15"


def result_class_note(result: ArrayLike, benchmark: str) -> str | None:
    """What is odd in the class column (8) of `result` under `benchmark`'s rules, or None.

    Under MOT16/17/20 rules TrackEval refuses a result with a class above 1 (pedestrian) in
    column 8 ("Evaluation is only valid for pedestrian class"); pftrack scores every result box
    as a pedestrian, and says so when some rows hold integers other than 1 and -1 there (-1:
    no class, what most results hold; values that are not integers are world coordinates, of
    MOT15-style rows). The note names the count and the classes, most frequent first:
    ``"12 result boxes have class 3 in column 8: scored as pedestrians; TrackEval refuses such
    a file"``. MOT15 rules have no classes: None.
    """
    if benchmark == "MOT15":
        return None
    r = check_eval_rows(result, "result")
    cls = r[:, _CLASS]
    other = (cls == np.round(cls)) & (cls != _PEDESTRIAN) & (cls != -1)
    if not np.any(other):
        return None
    values, counts = np.unique(cls[other], return_counts=True)  # floats: 1e20 is no int64
    order = np.argsort(-counts, kind="stable")
    values, counts = values[order], counts[order]
    n = int(counts.sum())
    if len(values) == 1:
        which = f"class {values[0]:.15g}"
    else:
        which = "classes " + ", ".join(
            f"{v:.15g} ({c})" for v, c in zip(values, counts, strict=True)
        )
    refused = "; TrackEval refuses such a file" if np.any(values > _PEDESTRIAN) else ""
    boxes = "1 result box has" if n == 1 else f"{n} result boxes have"
    return f"{boxes} {which} in column 8: scored as pedestrians{refused}"


#: MOT16/17/20's ground-truth classes (column 8), as their papers and TrackEval name them.
CLASS_NAMES = {
    1: "pedestrian", 2: "person on vehicle", 3: "car", 4: "bicycle", 5: "motorbike",
    6: "non-motorized vehicle", 7: "static person", 8: "distractor", 9: "occluder",
    10: "occluder on the ground", 11: "occluder full", 12: "reflection", 13: "crowd",
}  # fmt: skip


def gt_rules_note(
    gt: ArrayLike, result: ArrayLike, benchmark: str, *, scale: float = 1.0
) -> str | None:
    """What `benchmark`'s rules leave out of `gt` and `result`, or None when they score it all.

    :func:`prepare_mot`'s rules were said only as "MOT17 ground-truth rules" below the table:
    a truth of 5 people, one a static person, one a distractor, one flagged 0, scored GT 2, and
    a result equal to the truth scored 55 false positives (its boxes on the flagged person, as
    TrackEval counts them), without a word of either. The note counts the ground-truth rows
    not scored, by class (MOT16/17/20) and by the consider flag (column 7), the result boxes
    left out (matched to a distractor), says that boxes on the other rows not scored count
    as false positives, and that visibility (column 9) is not thresholded (MOT16/17/20: MOT15's
    columns 8-10 are world coordinates). None when every ground-truth row is scored.

    Parameters
    ----------
    gt, result : (M, 6..10) array_like of float
        MOT rows, as :func:`prepare_mot` takes them.
    benchmark : {"MOT15", "MOT16", "MOT17", "MOT20"}
        The rules they were scored by.
    scale : float
        The ground truth's scale (:func:`prepare_mot`'s).
    """
    g = check_eval_rows(gt, "ground truth")
    flagged = np.trunc(g[:, CONF]) == 0
    with_classes = benchmark != "MOT15"
    other = g[:, _CLASS] != _PEDESTRIAN if with_classes else np.zeros(len(g), dtype=bool)
    left = int(np.sum(flagged | other))
    if not left:
        return None
    parts = []
    if other.any():
        values, counts = np.unique(g[other, _CLASS].astype(np.int64), return_counts=True)
        order = np.argsort(-counts, kind="stable")
        parts = [
            f"{counts[k]} of class {values[k]} ({CLASS_NAMES.get(int(values[k]), 'unknown')})"
            for k in order
        ]
    flagged_scored = int(np.sum(flagged & ~other))
    if flagged_scored:
        kind = "pedestrians" if with_classes else "rows"
        parts.append(f"{flagged_scored} {kind} flagged 0 (column 7)")
    kept = "pedestrians, class 1, flagged 1" if with_classes else "flagged 1 in column 7"
    said = (
        f"{benchmark} rules, as TrackEval: {len(g) - left} of its {len(g)} rows scored "
        f"({kept}); not scored: {', '.join(parts)}"
    )
    if with_classes:
        r = check_eval_rows(result, "result")
        dropped = len(r) - len(prepare_mot(g, r, benchmark=benchmark, scale=scale)[1])
        distractors = _DISTRACTORS + ((_NON_MOT_VEHICLE,) if benchmark == "MOT20" else ())
        said += (
            f"; {dropped} result boxes matched to a distractor (classes "
            f"{', '.join(map(str, distractors))}) left out, boxes on the other rows not "
            "scored count as false positives"
        )
        return said + "; visibility (column 9) is not thresholded"
    return said + "; result boxes on them count as false positives"  # MOT15: no visibility


def gt_conf_note(gt: ArrayLike) -> str | None:
    """What is odd in the "consider" flag (column 7) of ground truth `gt`, or None.

    MOTChallenge's ground truth holds 0 (not scored) or 1 there; TrackEval truncates the value
    to an integer, so a score in (0, 1), what a tracker's output holds (another tracker's
    tracks given as the ground truth), drops its row, and a file of them scores nothing (was:
    silently, every result box a false positive). The note names how many rows hold a value
    that is not an integer, the first, and how many of the rows are not scored.
    """
    g = check_eval_rows(gt, "ground truth")
    conf = g[:, CONF]
    odd = np.isfinite(conf) & (conf != np.trunc(conf))
    if not np.any(odd):
        return None
    k = int(np.argmax(odd))
    dropped = int(np.sum(np.trunc(conf) == 0))
    return (
        f"{int(odd.sum())} of {len(g)} ground-truth rows have a conf (column 7, the consider "
        f"flag: 0 or 1) that is not an integer (the first {conf[k]:.15g}, in frame "
        f"{int(g[k, FRAME])}): TrackEval truncates it, so {dropped} of the rows are 0 and not "
        "scored; a tracker's scores? set column 7 to 1 to score every row"
    )


def prepare_mot(
    gt: ArrayLike,
    result: ArrayLike,
    *,
    benchmark: str = "MOT15",
    scale: float = 1.0,
    num_frames: int | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The ground-truth and result rows that are scored, by MOTChallenge's rules.

    This is TrackEval's ``MotChallenge2DBox`` preprocessing (``DO_PREPROC`` on):

    * Ground-truth rows whose ``conf`` column (the "consider" flag), truncated to an integer,
      is 0 are removed ("zero-marked").
    * MOT16/17/20 only: ground-truth rows of another class than pedestrian (1) are removed,
      and, in each frame first, result boxes matched to a *distractor* ground-truth box are
      removed. The match is the Hungarian assignment maximising IoU among pairs with
      IoU >= 0.5; distractors are person on vehicle (2), static person (7), distractor (8),
      reflection (12) and, for MOT20, non-MOT vehicle (6). Every class must be 1-13.
    * MOT15 has no classes: result boxes on zero-marked boxes stay, and are false positives.
    * No visibility threshold is applied (TrackEval applies none).

    Parameters
    ----------
    gt, result : (M, 6..10) array_like of float
        MOT rows. Ids must be unique within a frame and >= 0 (TrackEval's rules). The class of
        result rows is not looked at.
    benchmark : {"MOT15", "MOT16", "MOT17", "MOT20"}
        Which conventions (see :func:`guess_benchmark`).
    scale : float
        Multiplies the ground-truth boxes first (e.g. 0.625 for PETS09 ground truth against
        results on the 480x360 video).
    num_frames : int, optional
        The sequence length (``seqLength``); a row in a later frame is an error, as in TrackEval.

    Returns
    -------
    gt, result : ndarray of float64
        The scored rows, each sorted by frame (file order within a frame), gt boxes scaled.
    """
    option(benchmark, "benchmark", BENCHMARKS)
    if benchmark not in BENCHMARKS:
        raise ValueError(f"benchmark is {benchmark!r}, expected one of {', '.join(BENCHMARKS)}")
    scale = number(scale, "scale", finite=False)
    if not (math.isfinite(scale) and scale > 0):
        raise ValueError(f"scale is {scale}, expected a finite value > 0")
    if num_frames is not None:
        num_frames = integer(num_frames, "num_frames", 1, MAX_FRAME)
    g = check_eval_rows(gt, "ground truth").copy()
    r = check_eval_rows(result, "result")
    g[:, LEFT : LEFT + 4] *= scale
    for rows, name in ((g, "ground truth"), (r, "result")):
        if num_frames is not None and len(rows) and rows[:, FRAME].max() > num_frames:
            raise ValueError(
                f"{name} has frame {int(rows[:, FRAME].max())}, beyond the sequence's "
                f"{num_frames} frames (seqLength)"
            )
    gf, rf = group_by_frame(g), group_by_frame(r)
    check_unique_ids(gf, "ground truth")
    check_unique_ids(rf, "result")
    check_ids_not_negative(g, "ground truth")  # after: det.txt has id -1 twice in a frame
    check_ids_not_negative(r, "result")
    with_classes = benchmark != "MOT15"
    if with_classes and len(g):
        cls = g[:, _CLASS]
        bad = (cls != np.round(cls)) | (cls < 1) | (cls > _N_CLASSES)
        if np.any(bad):
            raise ValueError(
                f"ground truth has class {g[bad][0, _CLASS]:g} (frame {int(g[bad][0, FRAME])}), "
                f"expected 1-13 for {benchmark}; MOT15-style files need benchmark MOT15"
            )
    distractors = _DISTRACTORS + ((_NON_MOT_VEHICLE,) if benchmark == "MOT20" else ())
    keep_g: list[NDArray[np.float64]] = []
    keep_r: list[NDArray[np.float64]] = []
    empty = np.zeros((0, 10))
    for f in sorted(set(gf) | set(rf)):
        gt_f, res_f = gf.get(f, empty), rf.get(f, empty)
        if with_classes and len(gt_f) and len(res_f):
            score = _mot_iou(gt_f[:, LEFT : LEFT + 4], res_f[:, LEFT : LEFT + 4])
            score[score < 0.5 - _EPS] = 0
            rows_m, cols_m = linear_sum_assignment(-score)
            hit = score[rows_m, cols_m] > _EPS
            rows_m, cols_m = rows_m[hit], cols_m[hit]
            drop = cols_m[np.isin(gt_f[rows_m, _CLASS].astype(np.int64), distractors)]
            res_f = np.delete(res_f, drop, axis=0)
        # TrackEval's astype(int) != 0, without the cast: a flag of NaN (an array) or beyond
        # int64 (1e20) is not 0 and is kept, as there, with no "invalid value encountered in
        # cast" warning
        keep = np.trunc(gt_f[:, CONF]) != 0
        if with_classes:
            keep &= gt_f[:, _CLASS].astype(np.int64) == _PEDESTRIAN
        keep_g.append(gt_f[keep])
        keep_r.append(res_f)
    if not keep_g:
        return np.zeros((0, 10)), np.zeros((0, 10))
    return np.concatenate(keep_g), np.concatenate(keep_r)


#: What :func:`~pftrack.eval.evaluate_sequence`'s warning of a result that matched nothing
#: begins with: a caller that says it otherwise filters it by this (``pftrack eval`` names the
#: files, once its outputs are written).
NONE_MATCHED = "evaluate_sequence: none of the result's "
#: How that warning names the result.
RESULTS = "the result's"


def _span(frames: NDArray[np.float64]) -> str:
    """``frame F`` or ``frames F-L`` of a column of frame numbers."""
    first, last = int(frames.min()), int(frames.max())
    return f"frame {first}" if first == last else f"frames {first}-{last}"


#: The fewest frames with boxes of one file outside the other's frames that
#: :func:`frame_ranges_notes` says: a tracker's few boxes after the last person left, or a
#: truth that starts when the first one comes in, are scored as they are without a word.
APART_FRAMES = 10


def frame_ranges_notes(
    gt: NDArray[np.float64], result: NDArray[np.float64], *, gt_name: str, res_name: str
) -> list[str]:
    """What to say of a result and a ground truth that cover different frames: 0 to 2 notes.

    Boxes of the result on frames before the truth's first or after its last are all false
    positives, and truth boxes outside the result's frames all misses: right when nobody was
    there or the tracker stopped early, wrong when one file covers part of the video (a truth
    annotated over frames 1-40 of 71 scored 133 false positives, MOTA 21.4 against 81.4 on the
    frames both cover, without a word). Said, with the count and the frames, when one file has
    boxes on :data:`APART_FRAMES` frames or more outside the other's first..last frame. Empty
    files say nothing here (their own notes do).
    """
    if not len(gt) or not len(result):
        return []
    notes: list[str] = []
    pairs = (
        (result, gt, res_name, gt_name, "false positives", "cover only part of the video"),
        (gt, result, gt_name, res_name, "misses", "track only part of the video"),
    )
    for rows, other, name, other_name, scored, why in pairs:
        first, last = int(other[:, FRAME].min()), int(other[:, FRAME].max())
        outside = (rows[:, FRAME] < first) | (rows[:, FRAME] > last)
        frames = np.unique(rows[outside, FRAME])
        if len(frames) < APART_FRAMES:
            continue
        n, share = int(outside.sum()), 100.0 * outside.mean()
        cut = f"awk -F, '$1>={first} && $1<={last}' {name} > cut.txt"
        notes.append(
            f"{name}: {n} of its {len(rows)} boxes ({share:.0f} %) lie on {len(frames)} frames "
            f"outside {other_name}'s {_span(other[:, FRAME])} ({_span(frames)}), all scored "
            f"as {scored}: does {other_name} {why}? If so, score the frames both cover ({cut})"
        )
    return notes


def none_matched(
    result: NDArray[np.float64],
    gt: NDArray[np.float64],
    iou_threshold: float,
    *,
    whose: str,
    gt_name: str = "",
) -> str:
    """Why a non-empty `result` none of whose boxes matched a box of `gt` looks mistaken.

    Almost always a pair of rows that do not belong together: the tracks of another sequence
    or video, or frames numbered otherwise. When no frame of the result is a frame of the
    ground truth, that is said instead (the frames' numbering, not the boxes, is at fault).
    `whose` names the result's boxes (``"the result's"``; ``"its"`` after a file's name),
    `gt_name` the ground truth's file, if any.
    """
    n = len(result)
    of = f" of {gt_name}" if gt_name else ""
    disjoint = not np.isin(result[:, FRAME], gt[:, FRAME]).any()
    why = (
        "no frame of it is a frame of the ground truth: frames numbered otherwise (shifted?), "
        "or the tracks of another sequence?"
        if disjoint
        else "the tracks of another sequence or video, or frames numbered otherwise?"
    )
    return (
        f"none of {whose} {n} box{'es' * (n != 1)} ({_span(result[:, FRAME])}) matches a "
        f"ground-truth box{of} ({_span(gt[:, FRAME])}) with IoU {iou_threshold:g} or more, on "
        f"any frame: {why}"
    )


def say_none_matched(
    fn: str,
    gt: ArrayLike,
    result: ArrayLike,
    *,
    truth: int,
    matches: int,
    iou_threshold: float,
    scored: str,
) -> None:
    """Warn, from the caller of `fn`, when a non-empty `result` matched no scored truth box.

    The one rule of :func:`~pftrack.eval.evaluate_mot`, :func:`~pftrack.eval.evaluate_hota`
    and :func:`~pftrack.eval.evaluate_sequence` (which says it once, for CLEAR-MOT): `truth`
    ground-truth boxes were scored and `matches` of them matched at `iou_threshold`; `scored`
    is the figure returned as computed (``"MOTA -1.000"``). An empty result is a finding (the
    tracker found nothing), not a mix-up, and says nothing; so does a truth with nothing
    scored. `gt` and `result` are the caller's rows, already accepted by
    :func:`check_eval_rows`: read again only when the warning is given.
    """
    if not truth or matches:
        return
    res = check_eval_rows(result, f"{fn}: result")
    if not len(res):
        return
    said = none_matched(res, check_eval_rows(gt, f"{fn}: gt"), iou_threshold, whose=RESULTS)
    # stacklevel 3: warn's caller is this function, then `fn`, then the line that called it
    warn(f"{fn}: {said} (scored as given: {scored})", UserWarning, stacklevel=3)
