"""Precision / recall of a detector's boxes against PETS09-S2L1's ground truth, per frame.

Ground truth (768x576) is scaled by 0.625 to the 480x360 video; a detection matches a
ground-truth box one-to-one (Hungarian, on IoU) when their IoU is >= the threshold. Also
reports the detector's milliseconds per frame. What is printed is also written to
``detection.txt`` in ``--out`` (default ``out/eval_detection``).

Usage (from the repository root)::

    python -m experiments.eval_detection [--data ../shared/data] [--detector paper|mog2|knn]
        [--prime | --prime-first N] [--out out/eval_detection] [key=value ...]
"""

from __future__ import annotations

import time
from collections.abc import Sequence

import numpy as np
from scipy.optimize import linear_sum_assignment

from experiments._common import data_root, experiment_parser, tee_stdout
from pftrack._typing import F64
from pftrack.boxes import iou_xywh
from pftrack.detection import PaperDetector, make_detector
from pftrack.io.mot import group_by_frame, read_mot
from pftrack.io.video import FrameSource


def n_matches(det: F64, gt: F64, thr: float) -> int:
    """Detections matched one-to-one (Hungarian on IoU) to ground-truth boxes with IoU >= `thr`."""
    if len(det) == 0 or len(gt) == 0:
        return 0
    iou = iou_xywh(det, gt)
    r, c = linear_sum_assignment(-iou)
    return int((iou[r, c] >= thr).sum())


def main(argv: Sequence[str] | None = None) -> int:
    p = experiment_parser("eval_detection", __doc__)
    p.add_argument("--detector", default="paper")
    p.add_argument(
        "--prime",
        action="store_true",
        help="paper: start from the median of 30 frames spread over the video",
    )
    p.add_argument("--prime-first", type=int, default=0, help="paper: ... of the first N frames")
    p.add_argument("settings", nargs="*", help="key=value detector settings")
    args = p.parse_args(argv)
    cfg: dict[str, float] = {}
    for s in args.settings:
        k, v = s.split("=")
        cfg[k] = int(v) if v.isdigit() else float(v)
    seq = data_root(args.data) / "pets09-s2l1"
    gt = read_mot(seq / "gt.txt")
    gt_by = group_by_frame(gt[gt[:, 6] != 0])
    det = make_detector(args.detector, **cfg)
    src = FrameSource(seq / "video.avi")
    if args.prime or args.prime_first:
        if not isinstance(det, PaperDetector):
            p.error("--prime and --prime-first need --detector paper (the others learn online)")
        if args.prime:
            frames = list(src)
            det.prime(frames[:: max(1, len(frames) // 30)])
        else:
            det.prime(f for f, _ in zip(src, range(args.prime_first), strict=False))
    tp = {0.5: 0, 0.3: 0}
    n_det = n_gt = n = 0
    t_det = 0.0
    for n, frame in enumerate(src, start=1):
        t0 = time.perf_counter()
        d = det.detect(frame)
        t_det += time.perf_counter() - t0
        g = gt_by.get(n)
        gb = g[:, 2:6] * 0.625 if g is not None else np.zeros((0, 4))
        n_det += len(d.boxes)
        n_gt += len(gb)
        for thr in tp:
            tp[thr] += n_matches(d.boxes, gb, thr)
    with tee_stdout(args.out / "detection.txt"):
        print(
            f"detector={args.detector} prime={args.prime} prime_first={args.prime_first} "
            f"settings={cfg}"
        )
        print(f"frames={n} gt={n_gt} det={n_det} ms/frame={1e3 * t_det / max(n, 1):.2f}")
        for thr, t in tp.items():
            print(f"IoU>={thr}: precision={t / max(n_det, 1):.3f} recall={t / max(n_gt, 1):.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
