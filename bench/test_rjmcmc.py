"""Benchmarks of the comparison samplers.

RJ-MCMC joint tracker at 200 kept samples per frame on PETS09-S2L1 (480x360, public detections as
birth candidates, MOG2 foreground), and the per-object MH filter against the SIS filter at an equal
likelihood budget. Run ``python bench/test_rjmcmc.py`` for a frames/s table, or
``pytest bench/test_rjmcmc.py --benchmark-only``. Falls back to a synthetic 480x360 scene with six
objects when ../shared/data is absent.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import cv2
import numpy as np
import pytest

from pftrack import _core

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(os.environ.get("PFTRACK_DATA", ROOT.parent / "shared" / "data"))
FIRST, N_FRAMES = 100, 40


def pets_sequence(first: int = FIRST, n: int = N_FRAMES):
    """(binned frames, masks, candidates per frame, source) for n frames from `first`."""
    video = DATA / "pets09-s2l1" / "video.avi"
    if not video.is_file():
        return synthetic_sequence(n)
    cap = cv2.VideoCapture(str(video))
    mog = cv2.createBackgroundSubtractorMOG2(history=200, varThreshold=25, detectShadows=False)
    det = np.loadtxt(DATA / "pets09-s2l1" / "det.txt", delimiter=",")
    kernel = np.ones((3, 3), np.uint8)
    out_b, out_m, out_c = [], [], []
    frame_no = 0
    while frame_no < first + n:
        ok, frame = cap.read()
        if not ok:
            break
        frame_no += 1
        fg = mog.apply(frame)
        if frame_no <= first:
            continue
        mask = cv2.morphologyEx((fg > 0).astype(np.uint8), cv2.MORPH_OPEN, kernel)
        d = det[det[:, 0] == frame_no, 2:6] * 0.625
        cands = np.column_stack([d[:, 0] + d[:, 2] / 2, d[:, 1] + d[:, 3] / 2, d[:, 2], d[:, 3]])
        out_b.append(_core.hsv_bins(frame, mask))
        out_m.append(mask)
        out_c.append(np.ascontiguousarray(cands))
    cap.release()
    return out_b, out_m, out_c, "PETS09-S2L1"


def synthetic_sequence(n: int):
    g = np.random.default_rng(0)
    colours = g.integers(0, 256, (6, 3))
    out_b, out_m, out_c = [], [], []
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


def run_rjmcmc(seq, n_samples: int = 200, burn_in: int = 50) -> tuple[float, float]:
    """(seconds per frame, mean objects per sample) of the RJ-MCMC tracker over a sequence."""
    binned, masks, cands, _ = seq
    t = _core.RJMCMCTracker(n_samples=n_samples, burn_in=burn_in)
    objs = []
    start = time.perf_counter()
    for k, (b, m, c) in enumerate(zip(binned, masks, cands)):
        objs.append(t.step(b, m, c, None, seed=1, step=k)["mean_objects"])
    return (time.perf_counter() - start) / len(binned), float(np.mean(objs))


@pytest.fixture(scope="module")
def seq():
    return pets_sequence()


@pytest.mark.benchmark(group="rjmcmc 480x360 per frame")
@pytest.mark.parametrize("n_samples", [200, 1000])
def test_rjmcmc_sequence(benchmark, seq, n_samples):
    per_frame, _ = benchmark.pedantic(run_rjmcmc, args=(seq, n_samples), rounds=3, iterations=1)
    benchmark.extra_info["frames_per_s"] = 1.0 / per_frame


def box_iou(a, b) -> float:
    """IoU of two (cx, cy, w, h) boxes."""
    iw = max(0.0, min(a[0] + a[2] / 2, b[0] + b[2] / 2) - max(a[0] - a[2] / 2, b[0] - b[2] / 2))
    ih = max(0.0, min(a[1] + a[3] / 2, b[1] + b[3] / 2) - max(a[1] - a[3] / 2, b[1] - b[3] / 2))
    inter = iw * ih
    return inter / (a[2] * a[3] + b[2] * b[3] - inter)


def rjmcmc_quality(seq, first: int = FIRST, threshold: float = 0.4, **kw) -> tuple[float, float]:
    """(recall, precision) of the RJ-MCMC estimates (existence >= 1/2) against PETS ground truth:
    a box counts when it overlaps one of the other side with IoU >= threshold. A rough check, not
    the experiment (the lead's evaluation uses pftrack.eval)."""
    gt = np.loadtxt(DATA / "pets09-s2l1" / "gt.txt", delimiter=",")
    t = _core.RJMCMCTracker(**kw)
    hit_g = n_g = hit_e = n_e = 0
    for k, (b, m, c) in enumerate(zip(*seq[:3])):
        est = [e[1:5] for e in t.step(b, m, c, None, seed=1, step=k)["estimates"] if e[5] >= 0.5]
        g = gt[gt[:, 0] == first + 1 + k, 2:6] * 0.625
        g = [np.array([x + w / 2, y + h / 2, w, h]) for x, y, w, h in g]
        hit_g += sum(any(box_iou(a, e) >= threshold for e in est) for a in g)
        hit_e += sum(any(box_iou(a, e) >= threshold for a in g) for e in est)
        n_g, n_e = n_g + len(g), n_e + len(est)
    return hit_g / max(n_g, 1), hit_e / max(n_e, 1)


def one_object(seq):
    binned, _, cands, _ = seq
    box = cands[0][0]
    ref = _core.box_histograms(binned[0], box[None], "uniform")[0]
    return binned, box, ref


def run_filter(binned, box, ref, kind: str, n: int, n_iter: int = 1) -> None:
    p = np.ascontiguousarray(np.tile([box[0], box[1], 1.0, box[0], box[1], 1.0], (n, 1)))
    w = np.full(n, 1.0 / n)
    m = np.ascontiguousarray(np.tile([box[0], box[1], 1.0], (2, 1)))
    args = dict(a=[2.0, 2, 2], b=[-1.0, -1, -1], sigma=[4.0, 4, 0.02], s_min=0.2, s_max=5.0,
                use_means=False, lam=20.0, kernel="uniform", resample=True, seed=1)
    for k, img in enumerate(binned):
        if kind == "sis":
            _core.sis_step(p, w, m, img, ref, box[2], box[3], step=k, **args)
        else:
            _core.mh_step(p, w, m, img, ref, box[2], box[3], step=k, n_iter=n_iter, **args)


# Equal likelihood budget: SIS with 2N particles evaluates 2N boxes a frame, MH with N particles
# and one iteration evaluates N chain starts + N proposals.
@pytest.mark.benchmark(group="one object, 400 likelihoods a frame")
def test_sis_400(benchmark, seq):
    benchmark(run_filter, *one_object(seq), "sis", 400)


@pytest.mark.benchmark(group="one object, 400 likelihoods a frame")
def test_mh_200x1(benchmark, seq):
    benchmark(run_filter, *one_object(seq), "mh", 200, 1)


if __name__ == "__main__":
    s = pets_sequence()
    print(f"source: {s[3]}, {len(s[0])} frames of {s[0][0].shape[1]}x{s[0][0].shape[0]}, "
          f"{np.mean([len(c) for c in s[2]]):.1f} candidates/frame")
    print("| kept samples | burn-in | ms/frame | frames/s | objects/sample |")
    print("|---|---|---|---|---|")
    for n_samples, burn_in in [(200, 50), (200, 0), (1000, 200)]:
        best = min(run_rjmcmc(s, n_samples, burn_in) for _ in range(3))
        print(f"| {n_samples} | {burn_in} | {1e3 * best[0]:.2f} | {1 / best[0]:.0f} | {best[1]:.2f} |")
    if s[3] == "PETS09-S2L1":
        for n_samples, burn_in in [(200, 50), (1000, 200)]:
            rec, prec = rjmcmc_quality(s, n_samples=n_samples, burn_in=burn_in)
            print(f"RJ-MCMC {n_samples}+{burn_in}: recall {rec:.2f}, precision {prec:.2f} (IoU >= 0.4)")
    b, box, ref = one_object(s)
    for kind, n, it in [("sis", 400, 1), ("mh", 200, 1), ("sis", 200, 1), ("mh", 100, 3)]:
        t0 = time.perf_counter()
        run_filter(b, box, ref, kind, n, it)
        dt = (time.perf_counter() - t0) / len(b)
        label = f"{kind} N={n}" + (f" n_iter={it}" if kind == "mh" else "")
        print(f"{label}: {1e3 * dt:.3f} ms/frame")
    sys.exit(0)
