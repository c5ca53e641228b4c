"""Merged people in crowds: where the built-in detector's errors come from, and the split's scores.

Two parts, each run on named sequences, with the split off (``base``) and on (``split``,
``PaperConfig(crowd_split=True)``):

* ``--coverage``: the detector alone (`PaperDetector` primed from the spread bootstrap, as the
  tracker primes it). Per frame, boxes are matched to the truth at IoU >= 0.5 (Hungarian);
  each box counts the truth boxes it covers (half or more of the truth box inside it), and
  each missed truth box is ``merged`` (covered by a box covering two or more), ``part`` (some
  box overlaps it) or ``lost`` (none does).
* otherwise the whole tracker (``track_path``/``track_frames``, seed 0, every other default),
  scored by `pftrack.eval.evaluate_sequence` (TrackEval's HOTA, CLEAR-MOT, IDF1).

Sequences: ``pets``, ``tud`` (``--data``), ``crowd:N:S`` (``--crowd DIR``/cNsS/ made by
``python -m experiments.crowd_video --out DIR/cNsS --walkers N --seed S``), ``walkers:S``
(``make_scene(n_frames=150, rng=S)``, as ``experiments.demo_seeds``), ``present:S``,
``groups:S``, ``overhead:S`` (``make_busy_scene``). One JSON line per run is appended to
``OUT/crowd_split.jsonl``.

Usage (from the repository root)::

    python -m experiments.crowd_split --crowd /tmp/crowd --seqs pets,tud,crowd:48:0 [--coverage]
        [--variants base,split] [--out out/crowd_split]
"""

from __future__ import annotations

import json
import time
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from scipy.optimize import linear_sum_assignment

from experiments._common import experiment_parser
from pftrack._typing import F64
from pftrack.detection import crowd, paper
from pftrack.detection.bootstrap import bootstrap_frames
from pftrack.detection.paper import PaperConfig, PaperDetector
from pftrack.eval import evaluate_sequence
from pftrack.io.mot import as_written, read_mot
from pftrack.io.video import FrameSource
from pftrack.synthetic import make_busy_scene, make_scene
from pftrack.tracking import TrackerConfig, track_frames
from pftrack.tracking.run import track_path

VARIANTS = {"base": False, "split": True}


def _source(name: str, data: Path, crowd: Path) -> tuple[object, F64, float]:
    """(frames: a path or a frame list, truth rows, truth scale) of a sequence name."""
    kind, _, rest = name.partition(":")
    if kind == "pets":
        return data / "pets09-s2l1/video.avi", read_mot(data / "pets09-s2l1/gt.txt"), 0.625
    if kind == "tud":
        return data / "tud-campus/video.mp4", read_mot(data / "tud-campus/gt.txt"), 1.0
    if kind == "crowd":
        n, s = rest.split(":")
        d = crowd / f"c{n}s{s}"
        return d / "crowd.avi", read_mot(d / "gt.txt"), 1.0
    seed = int(rest)
    scene = (
        make_scene(n_frames=150, rng=seed) if kind == "walkers" else make_busy_scene(kind, rng=seed)
    )
    return list(scene.frames), scene.truth, 1.0


def _known(name: str) -> bool:
    """Whether `name` is a sequence name `_source` reads."""
    kind, _, rest = name.partition(":")
    parts = rest.split(":") if rest else []
    if kind in ("pets", "tud"):
        return not parts
    want = 2 if kind == "crowd" else 1
    kinds = ("crowd", "walkers", "present", "groups", "overhead")
    return kind in kinds and len(parts) == want and all(q.isdigit() for q in parts)


def _iou(a: F64, b: F64) -> F64:
    lo = np.maximum(a[:, None, :2], b[None, :, :2])
    hi = np.minimum(a[:, None, :2] + a[:, None, 2:], b[None, :, :2] + b[None, :, 2:])
    inter = np.prod(np.clip(hi - lo, 0, None), axis=2)
    union = (a[:, 2] * a[:, 3])[:, None] + (b[:, 2] * b[:, 3])[None] - inter
    iou: F64 = inter / np.maximum(union, 1e-9)
    return iou


def _covered(dets: F64, truth: F64) -> F64:
    """(D, T): the share of each truth box inside each detection box."""
    lo = np.maximum(dets[:, None, :2], truth[None, :, :2])
    hi = np.minimum(dets[:, None, :2] + dets[:, None, 2:], truth[None, :, :2] + truth[None, :, 2:])
    inter = np.prod(np.clip(hi - lo, 0, None), axis=2)
    out: F64 = inter / np.maximum(truth[:, 2] * truth[:, 3], 1e-9)[None]
    return out


def _frames(src: object) -> Iterator[np.ndarray]:
    if isinstance(src, list):
        yield from src
    else:
        yield from FrameSource(src)  # type: ignore[arg-type]


class _Timed:
    """`split_crowds` as the detector calls it, its process CPU time summed."""

    def __init__(self) -> None:
        self.seconds = 0.0

    def __call__(self, *args: Any) -> tuple[F64, F64]:
        t0 = time.process_time()
        out = crowd.split_crowds(*args)
        self.seconds += time.process_time() - t0
        return out


def coverage(src: object, truth: F64, scale: float, split: bool) -> dict[str, object]:
    """The detector alone: matches, boxes per number of people covered, misses by kind.

    Also the process CPU time of `split_crowds` per frame (``split_ms``; 0 with it off).
    """
    timed = _Timed()
    paper.split_crowds = timed  # type: ignore[assignment]  # the detector's own call, timed
    try:
        return _count(src, truth, scale, split, timed)
    finally:
        paper.split_crowds = crowd.split_crowds


def _count(src: object, truth: F64, scale: float, split: bool, timed: _Timed) -> dict[str, object]:
    det = PaperDetector(PaperConfig(crowd_split=split))
    frames = src if isinstance(src, list) else FrameSource(src)  # type: ignore[arg-type]
    det.prime(bootstrap_frames(frames))
    covers = np.zeros(5, np.int64)
    tp = fp = merged = part = lost = f = 0
    t0 = time.process_time()
    for f, frame in enumerate(_frames(src), start=1):
        boxes = det.detect(frame).boxes
        gt = truth[truth[:, 0] == f, 2:6] * scale
        if not len(boxes):
            lost += len(gt)
            continue
        if not len(gt):
            fp += len(boxes)
            continue
        iou = _iou(boxes, gt)
        r, c = linear_sum_assignment(-iou)
        ok = iou[r, c] >= 0.5
        tp += int(ok.sum())
        fp += len(boxes) - int(ok.sum())
        cov = _covered(boxes, gt) >= 0.5
        n_cov = cov.sum(axis=1)
        covers += np.bincount(np.minimum(n_cov, 4), minlength=5)
        hit = np.zeros(len(gt), bool)
        hit[c[ok]] = True
        for t in np.flatnonzero(~hit):
            if np.any(cov[:, t] & (n_cov >= 2)):
                merged += 1
            elif np.any(iou[:, t] > 0):
                part += 1
            else:
                lost += 1
    return {
        "tp": tp, "fp": fp, "fn_merged": merged, "fn_part": part, "fn_lost": lost,
        "boxes_covering_0_1_2_3_4+": covers.tolist(),
        "cpu_s": round(time.process_time() - t0, 2),
        "split_ms": round(1000 * timed.seconds / max(f, 1), 3),
    }  # fmt: skip


def tracked(src: object, truth: F64, scale: float, split: bool) -> dict[str, object]:
    """The whole tracker, seed 0: HOTA, MOTA, IDF1 (%), FP, FN, IDSW."""
    cfg = TrackerConfig(detector=PaperConfig(crowd_split=split))
    t0 = time.process_time()
    if isinstance(src, list):
        run = track_frames(src, config=cfg, rng=0, show_progress=False)
    else:
        run = track_path(src, config=cfg, seed=0, show_progress=False)  # type: ignore[arg-type]
    s = evaluate_sequence(truth, as_written(run.rows), scale=scale)
    return {
        "hota": round(100 * s.hota.hota, 2), "mota": round(100 * s.mot.mota, 2),
        "idf1": round(100 * s.mot.idf1, 2), "fp": s.mot.false_positives,
        "fn": s.mot.misses, "idsw": s.mot.num_switches,
        "cpu_s": round(time.process_time() - t0, 2),
    }  # fmt: skip


def main(argv: Sequence[str] | None = None) -> None:
    """Run the named sequences and append one JSON line per run."""
    p = experiment_parser("crowd_split", __doc__)
    p.add_argument("--crowd", type=Path, default=Path("out/crowd"), help="crowd clips' folder")
    p.add_argument("--seqs", required=True, help="comma-separated sequence names")
    p.add_argument("--variants", default="base,split", help="base, split or both")
    p.add_argument("--coverage", action="store_true", help="the detector alone")
    args = p.parse_args(argv)
    names = args.seqs.split(",")
    for name in names:
        if not _known(name):
            p.error(f"--seqs: {name!r} is not pets, tud, crowd:N:S or KIND:SEED")
    variants = args.variants.split(",")
    if any(v not in VARIANTS for v in variants):
        p.error(f"--variants: {args.variants!r}, expected base, split or base,split")
    args.out.mkdir(parents=True, exist_ok=True)
    log = args.out / "crowd_split.jsonl"
    for name in names:
        src, truth, scale = _source(name, args.data, args.crowd)
        for v in variants:
            fn = coverage if args.coverage else tracked
            row = {"seq": name, "variant": v, "coverage": args.coverage}
            row.update(fn(src, truth, scale, VARIANTS[v]))
            print(json.dumps(row), flush=True)
            with open(log, "a") as fh:
                fh.write(json.dumps(row) + "\n")


if __name__ == "__main__":
    main()
