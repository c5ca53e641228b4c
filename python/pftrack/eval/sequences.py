"""Scoring one result or a MOTChallenge folder of sequences: HOTA, CLEAR-MOT and IDF1 together.

A MOTChallenge ground-truth folder holds one folder per sequence, ``SEQ/gt/gt.txt`` (or
``SEQ/gt.txt``) with ``SEQ/seqinfo.ini``; results are ``RESULTS/SEQ.txt``, as TrackEval reads
them. TrackEval's own tree is read too: ground truth ``gt/mot_challenge/BENCH-SPLIT/SEQ/...``
(a folder of benchmark-split folders, :func:`find_sequences`), results
``trackers/mot_challenge/BENCH-SPLIT/TRACKER/data/SEQ.txt`` (:func:`result_file`), and
``pftrack eval`` scores it by the rules of the benchmark BENCH (:func:`benchmark_of_path`).
"""

from __future__ import annotations

import configparser
import csv
import dataclasses
import io
import json
import math
import os
import re
from collections.abc import Callable, Collection, Mapping, Sequence
from pathlib import Path
from typing import cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack._check import NORMALISED_REACH, option
from pftrack._progress import Report, check_report, part
from pftrack._typing import BenchmarkName, PathLike
from pftrack.eval.hota import HotaMetrics, combine_hota, guess_benchmark, hota_scores
from pftrack.eval.metrics import MotMetrics, check_image_size, clear_scores, combine_mot
from pftrack.eval.rows import (
    BENCHMARKS,
    _mot_iou,
    check_eval_rows,
    not_parts_message,
    say_none_matched,
)
from pftrack.eval.rows import NONE_MATCHED as NONE_MATCHED  # pftrack eval's filter, from here
from pftrack.eval.rows import none_matched as none_matched  # pftrack eval's note, from here
from pftrack.io.mot import CONF, FRAME, HEIGHT, LEFT, TOP, WIDTH

__all__ = [
    "COMBINED",
    "SequenceInfo",
    "SequenceScores",
    "benchmark_of_path",
    "check_scale",
    "evaluate_sequence",
    "find_sequences",
    "format_scores",
    "read_seqinfo",
    "result_file",
    "scores_csv",
    "scores_doc",
    "scores_json",
    "seqmap_of",
]

#: Name of the combined row in tables, JSON and CSV.
COMBINED = "COMBINED"

#: The share of :func:`evaluate_sequence`'s time HOTA takes (CLEAR-MOT and IDF1 the rest), for
#: its `on_progress` (measured on a file of 100 000 frames and 5000 ids, 5 December).
HOTA_SHARE = 0.55


@dataclasses.dataclass(frozen=True)
class SequenceInfo:
    """One sequence of a MOTChallenge ground-truth folder.

    Attributes
    ----------
    name : str
        The folder's name (results are ``RESULTS/<name>.txt``).
    gt_path : pathlib.Path
        Its ground-truth file.
    length : int or None
        ``seqLength`` from ``seqinfo.ini`` (None without one).
    width, height : int or None
        ``imWidth``, ``imHeight`` from ``seqinfo.ini``.
    seqinfo : pathlib.Path or None
        The ``seqinfo.ini`` they were read from (None without one): what a refusal by its
        ``seqLength`` names (:func:`name_seqinfo`).
    """

    name: str
    gt_path: Path
    length: int | None = None
    width: int | None = None
    height: int | None = None
    seqinfo: Path | None = None


def name_seqinfo(message: str, seqinfo: PathLike | None) -> str:
    """A scorer's refusal of a frame past ``seqLength`` (:func:`prepare_mot`), naming its file.

    ``... beyond the sequence's 71 frames (seqLength)`` said neither which ``seqinfo.ini``
    nor that the mend may be there (a seqLength cut short, another sequence's file) or in the
    rows (a result of a longer video): now ``(seqLength in SEQ/seqinfo.ini)``. Any other
    message, or no file, is returned as it is.
    """
    if seqinfo is None or "(seqLength)" not in message:
        return message
    return message.replace("(seqLength)", f"(seqLength in {seqinfo})")


def read_seqinfo(path: PathLike) -> dict[str, str]:
    """The ``[Sequence]`` section of a MOTChallenge ``seqinfo.ini`` as a dict of strings.

    Read as :func:`pftrack.io.video.read_seqinfo` reads it (UTF-16 by its byte-order mark).
    """
    from pftrack.io.video import _ini_text

    parser = configparser.ConfigParser()
    try:
        parser.read_string(_ini_text(Path(path)))
    except configparser.Error as exc:
        raise ValueError(
            f"{path}: not a seqinfo.ini file ({exc.message.splitlines()[0]})"
        ) from None
    if not parser.has_section("Sequence"):
        raise ValueError(f"{path}: no [Sequence] section")
    return dict(parser["Sequence"])


def _sequence(folder: Path, only: Collection[str] | None = None) -> SequenceInfo | None:
    """The sequence of `folder`, None without a ground-truth file.

    Its ``seqinfo.ini`` is read only when `only` is None or names it.
    """
    gt = next((p for p in (folder / "gt" / "gt.txt", folder / "gt.txt") if p.is_file()), None)
    if gt is None:
        return None
    ini = folder / "seqinfo.ini"
    if not ini.is_file() or (only is not None and folder.name not in only):
        return SequenceInfo(folder.name, gt)
    from pftrack.io.video import read_seqinfo as read_info  # track's and batch's reader

    # its errors name the file, key and value, as theirs do; only the keys scoring uses are
    # read (an invalid frameRate, which no score uses, does not refuse the sequence)
    info = read_info(ini, keys=("seqLength", "imWidth", "imHeight"))
    return SequenceInfo(
        folder.name, gt, length=info.length, width=info.width, height=info.height, seqinfo=ini
    )


def sequence_of_file(gt_file: PathLike, name: str) -> SequenceInfo:
    """A ground-truth file as sequence `name`, with the ``seqinfo.ini`` of its folder if any.

    ``SEQ/gt/gt.txt`` and ``SEQ/gt.txt`` read ``SEQ/seqinfo.ini`` (length and image size), as
    :func:`find_sequences` does for the folder, so that a sequence scores the same whether its
    folder or its file is given; any other file has no length or size.
    """
    path = Path(gt_file)
    parent = path.parent
    for folder in (parent.parent, parent) if parent.name == "gt" else (parent,):
        seq = _sequence(folder)
        if seq is not None and os.path.realpath(seq.gt_path) == os.path.realpath(path):
            return dataclasses.replace(seq, name=name)
    return SequenceInfo(name, path)


def find_sequences(root: PathLike, only: Collection[str] | None = None) -> list[SequenceInfo]:
    """The sequences of a MOTChallenge ground-truth folder, by name.

    `root` is one sequence folder (it has ``gt/gt.txt`` or ``gt.txt``), a folder of them, or
    a folder of such folders (TrackEval's ``gt/mot_challenge/`` with ``MOT17-train/``, ...:
    the sequences of all of them); folders without a ground-truth file are skipped. A
    benchmark-split folder with TrackEval's list of its sequences beside it
    (``seqmaps/MOT17-train.txt``, :func:`seqmap_of`) gives the sequences listed, as TrackEval
    evaluates them (was: every folder, so the combined row held sequences TrackEval leaves
    out). With `only` (``pftrack eval --seqs``), the sequences are the folders (whatever the
    list), and the ``seqinfo.ini`` of those it does not name is not read: a malformed one of
    a sequence not scored stopped the run.

    Raises
    ------
    FileNotFoundError
        `root` is not a folder.
    ValueError
        No sequence was found, two folders of `root` hold a sequence of the same name, a
        ``seqinfo.ini`` is malformed, or a seqmap lists no sequence or one without a folder.
    """
    base = Path(root)
    if not base.is_dir():
        raise FileNotFoundError(f"ground-truth folder not found: {base}")
    own = _sequence(base)
    if own is not None and base.name == "gt" and own.gt_path == base / "gt.txt":
        # SEQ/gt given: the sequence is SEQ, as when SEQ/gt/gt.txt is given (was named "gt",
        # and a results folder was searched for gt.txt)
        return [sequence_of_file(own.gt_path, base.resolve().parent.name)]
    if own is not None:
        return [own]
    found = _sequences_in(base, only)
    if not found:  # TrackEval: gt/mot_challenge/BENCH-SPLIT/SEQ
        found = [s for d in _folders(base) for s in _sequences_in(d, only)]
        seen: dict[str, Path] = {}
        for s in found:
            if s.name in seen:
                raise ValueError(
                    f"sequence {s.name} is both in {seen[s.name]} and in {s.gt_path}: give one "
                    f"benchmark-split folder of {base} as the ground truth"
                )
            seen[s.name] = s.gt_path
    if not found:
        raise ValueError(
            f"no sequence in {base}: expected folders SEQ/ with SEQ/gt/gt.txt (or SEQ/gt.txt) "
            "and SEQ/seqinfo.ini, or folders of them (TrackEval's gt/mot_challenge/BENCH-SPLIT/)"
        )
    return found


def _folders(base: Path) -> list[Path]:
    return [d for d in sorted(base.iterdir()) if d.is_dir()]


def _sequences_in(base: Path, only: Collection[str] | None = None) -> list[SequenceInfo]:
    listed = seqmap_of(base) if only is None else None  # --seqs picks any folder
    if listed is None:
        return [s for d in _folders(base) if (s := _sequence(d, only)) is not None]
    seqmap, names = listed
    if not names:
        raise ValueError(f"{seqmap} lists no sequence: TrackEval evaluates none of {base}")
    # the seqinfo.ini of a folder not listed is not read, as with --seqs
    found = [s for d in _folders(base) if (s := _sequence(d, names)) is not None]
    have = {s.name for s in found}
    absent = [n for n in names if n not in have]
    if absent:  # TrackEval stops too ("ini file does not exist")
        raise ValueError(
            f"{seqmap} lists sequence {absent[0]}, which has no folder with gt/gt.txt in {base}"
        )
    return [s for s in found if s.name in names]


def seqmap_of(split: PathLike) -> tuple[Path, list[str]] | None:
    """TrackEval's list of the sequences of benchmark-split folder `split`, or None.

    TrackEval evaluates ``gt/mot_challenge/BENCH-SPLIT`` on the sequences that
    ``gt/mot_challenge/seqmaps/BENCH-SPLIT.txt`` lists (a header line, then one name a line),
    not on every folder: `split` named ``BENCH-SPLIT`` (``MOT17-train``) with that file beside
    it gives ``(seqmap path, names)``; any other folder None.
    """
    folder = Path(split).absolute()
    seqmap = folder.parent / "seqmaps" / f"{folder.name}.txt"
    if not _BENCH_SPLIT.fullmatch(folder.name) or not seqmap.is_file():
        return None
    text = seqmap.read_text(encoding="utf-8-sig", errors="replace")
    rows = list(csv.reader(io.StringIO(text)))[1:]  # TrackEval's reader: row 0 is "name"
    return seqmap, [r[0].strip() for r in rows if r and r[0].strip()]


#: TrackEval's benchmark-split folder: BENCHMARK + "-" + SPLIT_TO_EVAL (``MOT17-train``,
#: ``MOT20-test``, ``MOT15-all``, ``MOT17-train_half``); a split starts with a letter, so that
#: sequence names (``MOT17-02-FRCNN``, ``MOT20-01``) are not read as one.
_BENCH_SPLIT = re.compile(r"(MOT15|MOT16|MOT17|MOT20)-[A-Za-z]\w*")


def benchmark_of_path(gt_file: PathLike) -> tuple[BenchmarkName, str] | None:
    """The benchmark a TrackEval folder holding `gt_file` names, and that folder's name, or None.

    TrackEval reads ground truth from ``gt/mot_challenge/BENCH-SPLIT/SEQ/gt/gt.txt`` and scores
    it by BENCH's rules: ``("MOT20", "MOT20-train")`` for
    ``.../MOT20-train/MOT20-01/gt/gt.txt``. The folders of `gt_file` (made absolute, so that a
    relative path given from inside the tree counts) are looked at from the nearest one up; the
    first named ``MOT15``, ``MOT16``, ``MOT17`` or ``MOT20``, a hyphen and a split (a word
    starting with a letter: ``train``, ``test``, ``all``, ...) gives the benchmark.
    ``pftrack eval --benchmark auto`` takes it before guessing from the columns
    (:func:`~pftrack.eval.guess_benchmark`).
    """
    for folder in reversed(Path(gt_file).absolute().parent.parts):
        match = _BENCH_SPLIT.fullmatch(folder)
        if match:
            return cast("BenchmarkName", match.group(1)), folder
    return None


def result_file(results: PathLike, name: str) -> Path | None:
    """The result file of sequence `name` in folder `results`, or None.

    ``RESULTS/NAME.txt``, or TrackEval's ``RESULTS/data/NAME.txt`` (`results` is then
    ``trackers/mot_challenge/BENCH-SPLIT/TRACKER``).
    """
    base = Path(results)
    for path in (base / f"{name}.txt", base / "data" / f"{name}.txt"):
        if path.is_file():
            return path
    return None


# Factors tried around the box-height ratio by check_scale.
_AROUND = np.geomspace(1 / 1.3, 1.3, 27)
_AROUND_AXIS = np.geomspace(1 / 1.15, 1.15, 9)
# Factors tried around the best of _AROUND (2 % apart) for the factor the message names.
_NEAR = np.geomspace(1 / 1.02, 1.02, 17)


def _in_frames(rows: NDArray[np.float64], frames: NDArray[np.int64]) -> NDArray[np.float64]:
    """The rows of `rows` in `frames`, in their order: what :func:`_matched_fraction` scores."""
    return rows[np.isin(rows[:, FRAME], frames)]


def _matched_fraction(
    gt: NDArray[np.float64],
    res: NDArray[np.float64],
    scale: float | tuple[float, float],
    frames: NDArray[np.int64],
) -> float:
    """Fraction of the gt boxes of `frames` that some result box overlaps with IoU >= 0.5.

    The ground truth is scaled by `scale`, one factor or (across, down).
    """
    sx, sy = (scale, scale) if isinstance(scale, (int, float)) else scale
    factor = np.array([sx, sy, sx, sy])
    hit = total = 0
    for f in frames:
        g = gt[gt[:, FRAME] == f, LEFT : LEFT + 4] * factor
        r = res[res[:, FRAME] == f, LEFT : LEFT + 4]
        total += len(g)
        if len(g) and len(r):
            hit += int(np.count_nonzero(_mot_iou(g, r).max(axis=1) >= 0.5))
    return hit / total if total else 0.0


#: Ratios of image sizes that :func:`check_scale` names in place of a fit near them (PETS09's
#: 768x576 ground truth on its 480x360 video is 0.625; the same size, 1; half, double, ...).
ROUND_SCALES = (1.0, 0.5, 2.0, 0.25, 4.0, 0.625, 1.6, 0.75, 1.5, 0.8, 1.25)
#: How far (as a share of the fit) a round ratio may lie from it, and the share of the fit's
#: matched boxes it must match.
ROUND_REACH = 0.05
ROUND_SHARE = 0.9


def check_scale(
    gt: ArrayLike,
    result: ArrayLike,
    *,
    scale: float = 1.0,
    name: str = "result",
    sequence: str | None = None,
) -> None:
    """Refuse a result whose boxes are in another pixel scale than the (scaled) ground truth.

    The share of ground-truth boxes (times `scale`) that a result box overlaps with IoU >= 0.5
    is measured on up to 40 frames, as given and, unless half of them match already, with the
    ground truth rescaled by factors within 30 % of the ratio of the median box heights, and
    (when the median widths' ratio differs from the heights' by more than 10 %) by factors
    across and down within 15 % of the two ratios. If the best of them more than doubles that
    share (and reaches 30 %), the coordinate systems differ: typically PETS09 ground truth
    (768x576) against results on its 480x360 video, which needs ``scale=0.625``, or results
    on a video of another shape (a 4:3 sequence stretched to 16:9), which one factor cannot fix.

    `name` leads the message (``pftrack eval`` gives the result file); with `sequence`, one of
    several sequences scored, the fix it names is ``--scale SEQUENCE=S`` (``--scale S`` would
    scale every sequence's ground truth). The factors it names are absolute, against the ground
    truth as stored: ``S`` is what to pass, in place of `scale` (the best of the factors of
    three digits within 2 % of the best fit), whatever `scale` was (was: the boxes' size
    relative to the ground truth already scaled by `scale`, "look 1.26 times" with
    ``scale=0.5`` where 0.631 was meant).

    Before the factors, a result in normalised coordinates (every box within
    :data:`~pftrack._check.NORMALISED_REACH` units, the ground truth's in pixels) and one
    whose columns 5-6 hold the boxes' right and bottom edges (``x1, y1, x2, y2``,
    :func:`_check_corners`) are refused as such.

    Raises
    ------
    ValueError
        On such a mismatch, with the scale that fits; on normalised or corner boxes.
    """
    g = np.asarray(gt, dtype=np.float64)
    r = np.asarray(result, dtype=np.float64)
    for a, what in ((g, "ground truth"), (r, "result")):
        if a.size and (a.ndim != 2 or a.shape[1] < 6):
            raise ValueError(f"{what} has shape {a.shape}, expected (M, 6..10) MOT rows")
    if g.size == 0 or r.size == 0 or len(g) < 10 or len(r) < 10:
        return
    if g.shape[1] > CONF:
        g = g[g[:, CONF] != 0]
    g_h0 = float(np.median(g[:, HEIGHT]))  # the ground truth as stored, for the message
    g_h = g_h0 * scale
    r_h = float(np.median(r[:, HEIGHT]))
    g_w = float(np.median(g[:, WIDTH])) * scale
    r_w = float(np.median(r[:, WIDTH]))
    if g_h <= 0 or r_h <= 0 or g_w <= 0 or r_w <= 0:
        return
    ratio = r_h / g_h
    common = np.intersect1d(g[:, FRAME], r[:, FRAME]).astype(np.int64)
    if len(common) == 0:
        return
    sample = common[np.linspace(0, len(common) - 1, min(40, len(common))).astype(np.int64)]
    # the rows of the sampled frames, taken once: each factor tried went through every row once
    # per frame (46 factors, 30 s of CPU for a result of 1.9 million rows at 0.625)
    g_all, r_all = g, r
    g, r = _in_frames(g, sample), _in_frames(r, sample)
    as_given = _matched_fraction(g, r, scale, sample)
    if as_given >= 0.5:
        return
    # the rightmost and lowest edges: normalised boxes (was: "a video of another shape")
    rx, ry, gx, gy = (
        float(np.max(a[:, c] + a[:, c + 2])) for a in (r_all, g_all) for c in (LEFT, TOP)
    )
    gx, gy = gx * scale, gy * scale
    if max(rx, ry) <= NORMALISED_REACH < min(gx, gy):
        raise ValueError(
            f"{name}: every box lies within {rx:.3g} x {ry:.3g}, the ground truth's within "
            f"{gx:.0f} x {gy:.0f} px: normalised coordinates? give pixels (x times the image "
            "width, y times its height), or --no-scale-check"
        )
    _check_corners(g, r, r_all, scale, sample, as_given, name)
    # Box heights give the ratio roughly; positions need it closer (a 5 % error moves a box
    # at x = 600 by 30 px), so try factors around it and keep the best.
    best, fit = max(
        ((_matched_fraction(g, r, scale * k, sample), scale * k) for k in ratio * _AROUND),
        key=lambda t: t[0],
    )
    across = r_w / g_w
    if abs(across / ratio - 1) > 0.1:  # another shape: a factor across and one down
        stretched, (fx, fy) = max(
            (
                (_matched_fraction(g, r, (scale * a, scale * d), sample), (scale * a, scale * d))
                for a in across * _AROUND_AXIS
                for d in ratio * _AROUND_AXIS
            ),
            key=lambda t: t[0],
        )
        if stretched >= 0.3 and stretched > 2 * max(as_given, best):
            not_given = "" if scale == 1 else f", not {scale:g} both ways"
            raise ValueError(
                f"{name}: its boxes look {fx:.3g} times the ground truth's across and {fy:.3g} "
                f"times down{not_given} ({as_given:.0%} of ground-truth boxes matched"
                f"{_scaled_by(scale)}, {stretched:.0%} with the ground truth so stretched): the "
                "result is of a video of another shape than the ground truth's images, which "
                "no --scale fixes; rescale one of them per axis, or --no-scale-check"
            )
    if best >= 0.3 and best > 2 * as_given:
        # the factor named is one to type (three digits), the best of those near the fit (of a
        # tie, the shortest, 1 before 0.999, then the middle one): the grid above is 2 % coarse,
        # and 1 % off costs PETS09 MOTA 18
        near = sorted({float(f"{fit * k:.3g}") for k in _NEAR})
        matched = [_matched_fraction(g, r, k, sample) for k in near]
        best = max(matched)
        ties = [k for k, m in zip(near, matched, strict=True) if m == best]
        middle = ties[(len(ties) - 1) // 2]
        fit = min(ties, key=lambda k: (len(f"{k:g}"), abs(k - middle), k))
        # a round ratio of image sizes near the fit that matches nearly as well is the one
        # meant: boxes a tracker drew 2 % smaller than the truth's made TUD-Campus's 1 a
        # "0.984", which changes its scores (HOTA 66.8 -> 63.8)
        rounds = [k for k in ROUND_SCALES if abs(k / fit - 1) <= ROUND_REACH]
        if rounds:
            m, k = max(
                ((_matched_fraction(g, r, k, sample), k) for k in rounds),
                key=lambda t: (t[0], -abs(t[1] / fit - 1)),
            )
            if m >= ROUND_SHARE * best:
                best, fit = m, k
        option = f"--scale {fit:g}" if sequence is None else f"--scale {sequence}={fit:g}"
        not_given, instead = (
            ("", "") if scale == 1 else (f", not {scale:g}", f" instead of {scale:g}")
        )
        raise ValueError(
            f"{name}: its boxes look {fit:g} times the ground truth's{not_given} (median height "
            f"{r_h:.0f} vs {g_h0:.0f} px; {as_given:.0%} of ground-truth boxes matched"
            f"{_scaled_by(scale)}, {best:.0%} with it scaled by {fit:g}): pass {option}"
            f"{instead}, the ratio of the image sizes (0.625 for PETS09 ground truth on its "
            "480x360 video), or --no-scale-check"
        )


def _check_corners(
    g: NDArray[np.float64],
    r: NDArray[np.float64],
    r_all: NDArray[np.float64],
    scale: float,
    sample: NDArray[np.int64],
    as_given: float,
    name: str,
) -> None:
    """Refuse a result whose columns 5-6 hold the boxes' right and bottom edges (x2, y2).

    A detector's ``x1, y1, x2, y2`` written where MOTChallenge holds ``left, top, width,
    height``: when every row's "width" and "height" reach at least its left and top, and the
    boxes read as corners more than double the share of ground-truth boxes matched as given
    (and reach 30 %), as :func:`check_scale` tests a scale (was: scored as given, MOTA -94.5
    for ADL-Rundle-6's ground truth so written). `g` and `r` are the rows of the `sample`
    frames (:func:`_in_frames`), `r_all` every row of the result.
    """
    if np.any(r_all[:, WIDTH] - r_all[:, LEFT] < 0) or np.any(r_all[:, HEIGHT] - r_all[:, TOP] < 0):
        return  # a right edge left of its left edge (on any row): no corners
    corners = r.copy()
    corners[:, WIDTH] -= r[:, LEFT]
    corners[:, HEIGHT] -= r[:, TOP]
    as_corners = _matched_fraction(g, corners, scale, sample)
    if as_corners >= 0.3 and as_corners > 2 * as_given:
        raise ValueError(
            f"{name}: its columns 5-6 look like the boxes' right and bottom edges (x2, y2), "
            f"not their width and height ({as_given:.0%} of ground-truth boxes matched"
            f"{_scaled_by(scale)}, {as_corners:.0%} with width = x2 - x1 and height = y2 - y1): "
            "write left, top, width, height, as MOTChallenge files hold them (awk -F, -v OFS=, "
            "'{$5-=$3; $6-=$4} 1' for a comma-separated file), or --no-scale-check"
        )


def _scaled_by(scale: float) -> str:
    """`` with it scaled by S`` for a ground truth scaled by `scale`; nothing for 1."""
    return "" if scale == 1 else f" with it scaled by {scale:g}"


@dataclasses.dataclass(frozen=True)
class SequenceScores:
    """HOTA and CLEAR-MOT/identity scores of one sequence (or of several combined).

    Attributes
    ----------
    mot : MotMetrics
        CLEAR-MOT, IDF1 and Smith et al.'s measures (:func:`~pftrack.eval.evaluate_mot`).
    hota : HotaMetrics
        HOTA and its parts (:func:`~pftrack.eval.evaluate_hota`).
    benchmark : str
        The ground-truth conventions HOTA used ("MOT15", "MOT17", ...).
    """

    mot: MotMetrics
    hota: HotaMetrics
    benchmark: str

    def __str__(self) -> str:
        """:func:`format_scores` of this row, what ``print(scores)`` shows (``repr``: fields)."""
        return format_scores({"result": self})

    def as_dict(self) -> dict[str, object]:
        """Flat JSON-ready dict: HOTA's scores, then CLEAR-MOT's, per-alpha arrays nested."""
        h = self.hota.as_dict()
        scalars = {k: v for k, v in h.items() if not isinstance(v, list)}
        arrays = {k: v for k, v in h.items() if isinstance(v, list)}
        return {**scalars, **self.mot.as_dict(), "benchmark": self.benchmark, "per_alpha": arrays}

    @staticmethod
    def combine(parts: Sequence[SequenceScores]) -> SequenceScores:
        """Sequences combined as TrackEval combines them (see :func:`combine_hota`).

        Raises
        ------
        TypeError
            `parts` is not a list of SequenceScores (the message names what combines
            MotMetrics, :func:`~pftrack.eval.combine_mot`, or HotaMetrics).
        ValueError
            No parts.
        """
        fn = "SequenceScores.combine"
        if isinstance(parts, SequenceScores) or not isinstance(parts, Sequence):
            raise TypeError(
                f"{fn}: parts is {type(parts).__name__}, expected a list of SequenceScores"
            )
        if not parts:
            raise ValueError(f"{fn}: no sequences to combine")
        for k, p in enumerate(parts):
            if not isinstance(p, SequenceScores):
                raise TypeError(not_parts_message(fn, k, p, "SequenceScores"))
        marks = {p.benchmark for p in parts}
        return SequenceScores(
            mot=combine_mot([p.mot for p in parts]),
            hota=combine_hota([p.hota for p in parts]),
            benchmark=marks.pop() if len(marks) == 1 else "mixed",
        )


def evaluate_sequence(
    gt: ArrayLike,
    result: ArrayLike,
    *,
    iou_threshold: float = 0.5,
    scale: float = 1.0,
    image_size: tuple[int, int] | None = None,
    benchmark: BenchmarkName = "auto",
    num_frames: int | None = None,
    on_progress: Report | None = None,
) -> SequenceScores:
    """Score one result against its ground truth: HOTA family and CLEAR-MOT/IDF1.

    Parameters
    ----------
    gt, result : (M, 6..10) array_like of float
        MOT rows.
    iou_threshold, scale, image_size
        As in :func:`~pftrack.eval.evaluate_mot` (HOTA has no IoU threshold: it averages
        over 0.05...0.95).
    benchmark : {"auto", "MOT15", "MOT16", "MOT17", "MOT20"}
        Ground-truth conventions (:func:`~pftrack.eval.prepare_mot`), the same for HOTA and
        CLEAR-MOT/IDF1; ``"auto"``
        guesses MOT15 or MOT17 from the columns (:func:`~pftrack.eval.guess_benchmark`).
    num_frames : int, optional
        The sequence length; later frames are an error.
    on_progress : callable, optional
        Called now and then as ``on_progress(f)``, `f` the fraction of the work done (from 0
        to 1, ending with 1): HOTA's frames, then CLEAR-MOT's (``pftrack eval``'s bar).

    Warns
    -----
    UserWarning
        A result of some rows none of whose boxes matches a ground-truth box (MOTA at or below
        0): the warning, as ``pftrack eval``'s, names the two spans of frames and says when
        they have no frame in common (:func:`none_matched`). The scores are returned as
        computed.
    """
    check_image_size(image_size, "evaluate_sequence")  # before HOTA's work
    check_report(on_progress, "evaluate_sequence")
    option(benchmark, "evaluate_sequence: benchmark", ("auto", *BENCHMARKS))
    # named as evaluate_mot names them (was: "ground truth must hold real numbers", no function)
    gt = check_eval_rows(gt, "evaluate_sequence: gt")
    result = check_eval_rows(result, "evaluate_sequence: result")
    mark = guess_benchmark(gt) if benchmark == "auto" else benchmark
    # the scorers' unsaid forms: the one warning below is CLEAR-MOT's, this function's name
    h = hota_scores(
        gt, result, benchmark=mark, scale=scale, num_frames=num_frames,
        on_progress=part(on_progress, 0.0, HOTA_SHARE),
    )  # fmt: skip
    m = clear_scores(
        gt, result, iou_threshold=iou_threshold, scale=scale, image_size=image_size,
        benchmark=mark, num_frames=num_frames, on_progress=part(on_progress, HOTA_SHARE, 1.0),
    )  # fmt: skip
    say_none_matched(  # one warning, CLEAR-MOT's (as pftrack eval says it)
        "evaluate_sequence", gt, result, truth=m.num_objects, matches=m.num_matches,
        iou_threshold=iou_threshold, scored=f"MOTA {m.mota:.3f}",
    )  # fmt: skip
    return SequenceScores(mot=m, hota=h, benchmark=mark)


def _pct(x: float) -> str:
    if not math.isfinite(x):
        return "-"  # no value (JSON: null)
    text = f"{100.0 * x:.1f}"
    return "0.0" if text == "-0.0" else text  # a MOTA of -0.0001 %: was "-0.0"


_COLUMNS: list[tuple[str, Callable[[SequenceScores], str]]] = [
    ("HOTA", lambda s: _pct(s.hota.hota)),
    ("DetA", lambda s: _pct(s.hota.det_a)),
    ("AssA", lambda s: _pct(s.hota.ass_a_mean)),
    ("LocA", lambda s: _pct(s.hota.loc_a_mean)),
    ("MOTA", lambda s: _pct(s.mot.mota)),
    ("IDF1", lambda s: _pct(s.mot.idf1)),
    ("IDP", lambda s: _pct(s.mot.idp)),
    ("IDR", lambda s: _pct(s.mot.idr)),
    ("MOTP(IoU)", lambda s: _pct(s.mot.motp_iou)),
    ("FP", lambda s: str(s.mot.false_positives)),
    ("FN", lambda s: str(s.mot.misses)),
    ("IDSW", lambda s: str(s.mot.num_switches)),
    ("Frag", lambda s: str(s.mot.num_fragmentations)),
    ("GT", lambda s: str(s.mot.num_unique_objects)),
    ("MT", lambda s: str(s.mot.mostly_tracked)),
    ("PT", lambda s: str(s.mot.partially_tracked)),
    ("ML", lambda s: str(s.mot.mostly_lost)),
    ("Succ", lambda s: _pct(s.mot.success_rate)),
]


def _named_scores(fn: str, rows: object, combined: object) -> dict[str, SequenceScores]:
    """`rows`, then `combined` as ``COMBINED``, checked: TypeError/ValueError naming `fn`.

    (``format_scores({})`` raised a bare StopIteration, ``format_scores([scores])`` Python's
    "dictionary update sequence element #0 ...".)
    """
    if not isinstance(rows, Mapping):
        hint = "pass {name: scores}"
        if isinstance(rows, SequenceScores):
            hint = 'pass {"name": scores}'
        elif isinstance(rows, MotMetrics):
            hint = "evaluate_mot's MotMetrics are formatted by pftrack.eval.format_metrics"
        raise TypeError(
            f"{fn}: rows is {type(rows).__name__}, expected a mapping of names to "
            f"SequenceScores (evaluate_sequence): {hint}"
        )
    named: dict[str, SequenceScores] = {}
    for name, s in rows.items():
        if not isinstance(s, SequenceScores):
            hint = (
                ": evaluate_mot's MotMetrics are formatted by pftrack.eval.format_metrics"
                if isinstance(s, MotMetrics)
                else ""
            )
            raise TypeError(
                f"{fn}: rows[{name!r}] is {type(s).__name__}, expected SequenceScores{hint}"
            )
        named[str(name)] = s
    if combined is not None:
        if not isinstance(combined, SequenceScores):
            raise TypeError(
                f"{fn}: combined is {type(combined).__name__}, expected SequenceScores "
                "(SequenceScores.combine) or None"
            )
        named[COMBINED] = combined
    if not named:
        raise ValueError(f"{fn}: no sequence to format")
    return named


def format_scores(
    rows: Mapping[str, SequenceScores], combined: SequenceScores | None = None
) -> str:
    """Text table: one row per sequence, then the combined row if given.

    Percentages for HOTA, DetA, AssA, LocA (means over the 19 HOTA thresholds), MOTA, IDF1, IDP,
    IDR, MOTP (mean IoU of matches) and Smith et al.'s success rate; counts for the rest.

    Raises
    ------
    TypeError
        `rows` is not a mapping of names to SequenceScores (a list, MotMetrics: the message
        names :func:`~pftrack.eval.format_metrics`), or `combined` is not a SequenceScores.
    ValueError
        Nothing to format.
    """
    named = _named_scores("format_scores", rows, combined)
    header = ["sequence"] + [c for c, _ in _COLUMNS]
    body = [[name] + [fn(s) for _, fn in _COLUMNS] for name, s in named.items()]
    widths = [max(len(r[i]) for r in [header, *body]) for i in range(len(header))]
    lines = ["  ".join(v.rjust(w) for v, w in zip(r, widths, strict=True)) for r in [header, *body]]
    first = next(iter(named.values()))
    marks = sorted({s.benchmark for s in named.values()})
    lines.append(
        f"(HOTA/DetA/AssA/LocA: TrackEval's, {'/'.join(marks)} ground-truth rules; CLEAR-MOT and "
        f"IDF1 at IoU {first.mot.iou_threshold:g}; MOTP = mean IoU of matches; Succ: Smith et "
        "al.'s success rate)"
    )
    return "\n".join(lines)


def scores_doc(
    rows: Mapping[str, SequenceScores], combined: SequenceScores | None, *, fn: str = "scores_doc"
) -> dict[str, object]:
    """``{"sequences": {name: scores}, "combined": scores}``, what :func:`scores_json` writes.

    The combined scores' ``success_per_object`` is ``[]``: per-object rates are per sequence.
    """
    _named_scores(fn, rows, combined)
    doc: dict[str, object] = {"sequences": {k: v.as_dict() for k, v in rows.items()}}
    if combined is not None:
        doc["combined"] = combined.as_dict()
    return doc


def scores_json(rows: Mapping[str, SequenceScores], combined: SequenceScores | None) -> str:
    """JSON text of :func:`scores_doc` (NaN as null)."""
    return json.dumps(scores_doc(rows, combined, fn="scores_json"), indent=2)


def scores_csv(rows: Mapping[str, SequenceScores], combined: SequenceScores | None) -> str:
    """CSV text: a header, one line per sequence, then ``COMBINED``; scalar scores only."""
    named = _named_scores("scores_csv", rows, combined)
    flat = {
        name: {k: v for k, v in s.as_dict().items() if not isinstance(v, (list, dict))}
        for name, s in named.items()
    }
    fields = list(next(iter(flat.values())))
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["sequence", *fields])
    for name, values in flat.items():
        writer.writerow([name, *("" if values[f] is None else values[f] for f in fields)])
    return out.getvalue()
