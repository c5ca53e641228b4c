"""Precision / recall of a detector's boxes against PETS09-S2L1's ground truth, per frame.

    python bench/eval_detection.py [--detector paper|mog2|knn] [--prime] [key=value ...]

Ground truth (768x576) is scaled by 0.625 to the 480x360 video; a detection matches a
ground-truth box one-to-one (Hungarian, on IoU) when their IoU is >= the threshold.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np
from pftrack.detection import make_detector
from pftrack.io.mot import group_by_frame, read_mot
from pftrack.io.video import FrameSource
from scipy.optimize import linear_sum_assignment


def iou_matrix(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ax2, ay2 = a[:, 0] + a[:, 2], a[:, 1] + a[:, 3]
    bx2, by2 = b[:, 0] + b[:, 2], b[:, 1] + b[:, 3]
    iw = np.clip(np.minimum(ax2[:, None], bx2) - np.maximum(a[:, None, 0], b[:, 0]), 0, None)
    ih = np.clip(np.minimum(ay2[:, None], by2) - np.maximum(a[:, None, 1], b[:, 1]), 0, None)
    inter = iw * ih
    union = (a[:, 2] * a[:, 3])[:, None] + b[:, 2] * b[:, 3] - inter
    return inter / np.maximum(union, 1e-9)


def n_matches(det: np.ndarray, gt: np.ndarray, thr: float) -> int:
    if len(det) == 0 or len(gt) == 0:
        return 0
    iou = iou_matrix(det, gt)
    r, c = linear_sum_assignment(-iou)
    return int((iou[r, c] >= thr).sum())


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("--detector", default="paper")
    p.add_argument(
        "--prime",
        action="store_true",
        help="paper: start from the median of 30 frames spread over the video",
    )
    p.add_argument("--prime-first", type=int, default=0, help="paper: ... of the first N frames")
    p.add_argument("settings", nargs="*", help="key=value detector settings")
    args = p.parse_args()
    cfg: dict[str, float] = {}
    for s in args.settings:
        k, v = s.split("=")
        cfg[k] = int(v) if v.isdigit() else float(v)
    root = Path(__file__).resolve().parents[1] / ".." / "shared" / "data"
    seq = Path(os.environ.get("PFTRACK_DATA", root)) / "pets09-s2l1"
    gt = read_mot(seq / "gt.txt")
    gt_by = group_by_frame(gt[gt[:, 6] != 0])
    det = make_detector(args.detector, **cfg)
    src = FrameSource(seq / "video.avi")
    if args.prime:
        frames = list(src)
        det.prime(frames[:: max(1, len(frames) // 30)])  # type: ignore[union-attr]
    elif args.prime_first:
        det.prime(f for f, _ in zip(src, range(args.prime_first)))  # type: ignore[union-attr]
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
    print(
        f"detector={args.detector} prime={args.prime} prime_first={args.prime_first} settings={cfg}"
    )
    print(f"frames={n} gt={n_gt} det={n_det} ms/frame={1e3 * t_det / max(n, 1):.2f}")
    for thr, t in tp.items():
        print(f"IoU>={thr}: precision={t / max(n_det, 1):.3f} recall={t / max(n_gt, 1):.3f}")


if __name__ == "__main__":
    main()
