"""Speed of the comparison samplers' C++ kernels on PETS09-S2L1 frames 101-140 (480x360).

* the RJ-MCMC joint tracker (``_core.RJMCMCTracker``): ms per frame, frames/s and mean objects
  per sample for 200 kept samples (burn-in 50 and 0) and 1000 (burn-in 200), best of three runs;
  public detections x 0.625 as birth candidates, MOG2 foreground (history 200, threshold 25,
  3x3 opening);
* its rough quality on PETS: recall and precision of the estimates (existence >= 1/2) against
  the ground truth at IoU >= 0.4 (not the experiment: ``experiments.sampler_experiment`` scores
  the samplers with :mod:`pftrack.eval`);
* one object's filter: SIS with 400 particles against MH with 200 particles and one chain step
  (the same 400 likelihoods a frame), and SIS 200 against MH 100 x 3 steps, ms per frame.

Falls back to a synthetic 480x360 scene with six objects when the data is absent. The printed
lines also go to ``rjmcmc_speed.txt`` in ``--out`` (default ``out/rjmcmc_speed``). The same
workloads are pytest-benchmark groups in ``bench/test_rjmcmc.py``.

Usage (from the repository root)::

    python -m experiments.rjmcmc_speed [--data ../shared/data] [--out out/rjmcmc_speed]
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any, TypeAlias

import cv2
import numpy as np
from numpy.typing import NDArray

from experiments._common import data_root, experiment_parser, tee_stdout
from pftrack import _core
from pftrack._typing import F64
from pftrack.io.opencv_io import opencv_name

FIRST, N_FRAMES = 100, 40

Frames: TypeAlias = tuple[list[_core.BinnedImage], list[NDArray[np.uint8]], list[F64], str]
"""(binned frames, foreground masks, birth candidates (K, 4) cx, cy, w, h per frame, source)."""


def pets_sequence(data: Path, first: int = FIRST, n: int = N_FRAMES) -> Frames:
    """`n` frames of PETS09-S2L1 after frame `first`, or :func:`synthetic_sequence` without it."""
    video = data / "pets09-s2l1" / "video.avi"
    if not video.is_file():
        return synthetic_sequence(n)
    with opencv_name(video) as name:  # any name (pftrack.io.opencv_io)
        cap = cv2.VideoCapture(name)
    mog = cv2.createBackgroundSubtractorMOG2(history=200, varThreshold=25, detectShadows=False)
    det = np.loadtxt(data / "pets09-s2l1" / "det.txt", delimiter=",")
    kernel = np.ones((3, 3), np.uint8)
    out_b: list[_core.BinnedImage] = []
    out_m: list[NDArray[np.uint8]] = []
    out_c: list[F64] = []
    frame_no = 0
    while frame_no < first + n:
        ok, frame = cap.read()
        if not ok:
            break
        frame_no += 1
        fg = mog.apply(frame)
        if frame_no <= first:
            continue
        mask = np.asarray(
            cv2.morphologyEx((fg > 0).astype(np.uint8), cv2.MORPH_OPEN, kernel), dtype=np.uint8
        )
        d = det[det[:, 0] == frame_no, 2:6] * 0.625
        cands = np.column_stack([d[:, 0] + d[:, 2] / 2, d[:, 1] + d[:, 3] / 2, d[:, 2], d[:, 3]])
        out_b.append(_core.hsv_bins(np.asarray(frame, dtype=np.uint8), mask))
        out_m.append(mask)
        out_c.append(np.ascontiguousarray(cands))
    cap.release()
    return out_b, out_m, out_c, "PETS09-S2L1"


def synthetic_sequence(n: int) -> Frames:
    """Six coloured blocks moving right over noise, 480x360, for `n` frames."""
    g = np.random.default_rng(0)
    colours = g.integers(0, 256, (6, 3))
    out_b: list[_core.BinnedImage] = []
    out_m: list[NDArray[np.uint8]] = []
    out_c: list[F64] = []
    for t in range(n):
        frame = g.integers(0, 256, (360, 480, 3), dtype=np.uint8)
        mask = np.zeros((360, 480), np.uint8)
        cands = []
        for i in range(6):
            cx, cy = 50 + 70 * i + t, 120 + 40 * (i % 3)
            frame[cy - 40 : cy + 40, cx - 15 : cx + 15] = colours[i]
            mask[cy - 40 : cy + 40, cx - 15 : cx + 15] = 1
            cands.append((cx, cy, 30.0, 80.0))
        out_b.append(_core.hsv_bins(frame, mask))
        out_m.append(mask)
        out_c.append(np.array(cands))
    return out_b, out_m, out_c, "synthetic"


def run_rjmcmc(seq: Frames, n_samples: int = 200, burn_in: int = 50) -> tuple[float, float]:
    """(seconds per frame, mean objects per sample) of the RJ-MCMC tracker over a sequence."""
    binned, masks, cands, _ = seq
    t = _core.RJMCMCTracker(n_samples=n_samples, burn_in=burn_in)
    objs = []
    start = time.perf_counter()
    for k, (b, m, c) in enumerate(zip(binned, masks, cands, strict=True)):
        objs.append(t.step(b, m, c, None, seed=1, step=k)["mean_objects"])
    return (time.perf_counter() - start) / len(binned), float(np.mean(objs))


def box_iou(a: F64, b: F64) -> float:
    """IoU of two (cx, cy, w, h) boxes."""
    iw = max(0.0, min(a[0] + a[2] / 2, b[0] + b[2] / 2) - max(a[0] - a[2] / 2, b[0] - b[2] / 2))
    ih = max(0.0, min(a[1] + a[3] / 2, b[1] + b[3] / 2) - max(a[1] - a[3] / 2, b[1] - b[3] / 2))
    inter = iw * ih
    return float(inter / (a[2] * a[3] + b[2] * b[3] - inter))


def rjmcmc_quality(
    seq: Frames, data: Path, first: int = FIRST, threshold: float = 0.4, **kw: Any
) -> tuple[float, float]:
    """(recall, precision) of the RJ-MCMC estimates (existence >= 1/2) against PETS ground truth.

    A box counts when it overlaps one of the other side with IoU >= `threshold`. A rough check,
    not the experiment (``experiments.sampler_experiment`` scores with :mod:`pftrack.eval`).
    """
    gt = np.loadtxt(data / "pets09-s2l1" / "gt.txt", delimiter=",")
    t = _core.RJMCMCTracker(**kw)
    hit_g = n_g = hit_e = n_e = 0
    for k, (b, m, c) in enumerate(zip(*seq[:3], strict=True)):
        est = [e[1:5] for e in t.step(b, m, c, None, seed=1, step=k)["estimates"] if e[5] >= 0.5]
        xywh = gt[gt[:, 0] == first + 1 + k, 2:6] * 0.625
        g = [np.array([x + w / 2, y + h / 2, w, h]) for x, y, w, h in xywh]
        hit_g += sum(any(box_iou(a, e) >= threshold for e in est) for a in g)
        hit_e += sum(any(box_iou(a, e) >= threshold for a in g) for e in est)
        n_g, n_e = n_g + len(g), n_e + len(est)
    return hit_g / max(n_g, 1), hit_e / max(n_e, 1)


def one_object(seq: Frames) -> tuple[list[_core.BinnedImage], F64, F64]:
    """(binned frames, the first frame's first candidate box, its reference histogram)."""
    binned, _, cands, _ = seq
    box = cands[0][0]
    ref = _core.box_histograms(binned[0], box[None], "uniform")[0]
    return binned, box, ref


def run_filter(
    binned: list[_core.BinnedImage], box: F64, ref: F64, kind: str, n: int, n_iter: int = 1
) -> None:
    """Track one object over every frame with the C++ SIS (`kind` "sis") or MH ("mh") step."""
    p = np.ascontiguousarray(np.tile([box[0], box[1], 1.0, box[0], box[1], 1.0], (n, 1)))
    w = np.full(n, 1.0 / n)
    m = np.ascontiguousarray(np.tile([box[0], box[1], 1.0], (2, 1)))
    args: dict[str, Any] = dict(
        a=[2.0, 2, 2],
        b=[-1.0, -1, -1],
        sigma=[4.0, 4, 0.02],
        s_min=0.2,
        s_max=5.0,
        use_means=False,
        lam=20.0,
        kernel="uniform",
        resample=True,
        seed=1,
    )
    for k, img in enumerate(binned):
        if kind == "sis":
            _core.sis_step(p, w, m, img, ref, box[2], box[3], step=k, **args)
        else:
            _core.mh_step(p, w, m, img, ref, box[2], box[3], step=k, n_iter=n_iter, **args)


def report(data: Path) -> None:
    """Print the frames/s table, the quality lines and the per-object filter costs."""
    s = pets_sequence(data)
    print(
        f"source: {s[3]}, {len(s[0])} frames of {s[0][0].shape[1]}x{s[0][0].shape[0]}, "
        f"{np.mean([len(c) for c in s[2]]):.1f} candidates/frame"
    )
    print("| kept samples | burn-in | ms/frame | frames/s | objects/sample |")
    print("|---|---|---|---|---|")
    for n_samples, burn_in in [(200, 50), (200, 0), (1000, 200)]:
        best = min(run_rjmcmc(s, n_samples, burn_in) for _ in range(3))
        print(
            f"| {n_samples} | {burn_in} | {1e3 * best[0]:.2f} | {1 / best[0]:.0f} | {best[1]:.2f} |"
        )
    if s[3] == "PETS09-S2L1":
        for n_samples, burn_in in [(200, 50), (1000, 200)]:
            rec, prec = rjmcmc_quality(s, data, n_samples=n_samples, burn_in=burn_in)
            print(
                f"RJ-MCMC {n_samples}+{burn_in}: recall {rec:.2f}, precision {prec:.2f} "
                "(IoU >= 0.4)"
            )
    b, box, ref = one_object(s)
    for kind, n, it in [("sis", 400, 1), ("mh", 200, 1), ("sis", 200, 1), ("mh", 100, 3)]:
        t0 = time.perf_counter()
        run_filter(b, box, ref, kind, n, it)
        dt = (time.perf_counter() - t0) / len(b)
        label = f"{kind} N={n}" + (f" n_iter={it}" if kind == "mh" else "")
        print(f"{label}: {1e3 * dt:.3f} ms/frame")


def main(argv: Sequence[str] | None = None) -> int:
    ap = experiment_parser("rjmcmc_speed", __doc__)
    args = ap.parse_args(argv)
    with tee_stdout(args.out / "rjmcmc_speed.txt"):
        report(data_root(args.data))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
