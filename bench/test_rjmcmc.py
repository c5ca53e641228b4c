"""Benchmarks of the comparison samplers.

RJ-MCMC joint tracker at 200 and 1000 kept samples per frame on PETS09-S2L1 (480x360, public
detections as birth candidates, MOG2 foreground), and the per-object MH filter against the SIS
filter at an equal likelihood budget; a synthetic 480x360 scene with six objects when the data
is absent (another workload: the group's name then ends in ``[synthetic]``, and
``extra_info["sequence"]`` says which ran). The workloads are those of ``python -m
experiments.rjmcmc_speed`` (a frames/s table).

Locally: ``pytest bench/test_rjmcmc.py --benchmark-only``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray
from pytest_benchmark.fixture import BenchmarkFixture

from experiments.rjmcmc_speed import Frames, one_object, pets_sequence, run_filter, run_rjmcmc
from pftrack import _core


@pytest.fixture(scope="module")
def seq(data_dir: Path) -> Frames:
    return pets_sequence(data_dir)


def _label(benchmark: BenchmarkFixture, seq: Frames) -> None:
    """Name the sequence in ``extra_info``, and in the group when it is not PETS09's."""
    benchmark.extra_info["sequence"] = seq[3]
    if seq[3] != "PETS09-S2L1":
        benchmark.group = f"{benchmark.group} [{seq[3]}]"


@pytest.mark.benchmark(group="rjmcmc 480x360 per frame")
@pytest.mark.parametrize("n_samples", [200, 1000])
def test_rjmcmc_sequence(benchmark: BenchmarkFixture, seq: Frames, n_samples: int) -> None:
    _label(benchmark, seq)
    per_frame, _ = benchmark.pedantic(run_rjmcmc, args=(seq, n_samples), rounds=3, iterations=1)
    benchmark.extra_info["frames_per_s"] = 1.0 / per_frame


# Equal likelihood budget: SIS with 2N particles evaluates 2N boxes a frame, MH with N particles
# and one iteration evaluates N chain starts + N proposals.
@pytest.mark.benchmark(group="one object, 400 likelihoods a frame")
def test_sis_400(benchmark: BenchmarkFixture, seq: Frames) -> None:
    _label(benchmark, seq)
    benchmark(run_filter, *one_object(seq), "sis", 400)


@pytest.mark.benchmark(group="one object, 400 likelihoods a frame")
def test_mh_200x1(benchmark: BenchmarkFixture, seq: Frames) -> None:
    _label(benchmark, seq)
    benchmark(run_filter, *one_object(seq), "mh", 200, 1)


# ---- large boxes (1920x1080, 100x250 people): every pixel against the lattice ----------------


@pytest.fixture(scope="module")
def large() -> tuple[_core.BinnedImage, NDArray[np.uint8], NDArray[np.float64]]:
    """Five 100x250 people on a 1920x1080 noise frame: the bins, the foreground, the boxes."""
    g = np.random.default_rng(0)
    frame = g.integers(0, 256, (1080, 1920, 3), dtype=np.uint8)
    mask = np.zeros((1080, 1920), np.uint8)
    boxes = []
    for k in range(5):
        cx, cy = 200 + 350 * k, 540
        frame[cy - 125 : cy + 125, cx - 50 : cx + 50] = (40 * k, 200 - 30 * k, 90)
        mask[cy - 130 : cy + 130, cx - 55 : cx + 55] = 1
        boxes.append([cx, cy, 100.0, 250.0])
    return _core.hsv_bins(frame, mask), mask, np.array(boxes)


def _rj_frames(large: Any, min_samples: float) -> None:
    img, mask, boxes = large
    t = _core.RJMCMCTracker(min_samples=min_samples)
    for s in range(6):
        t.step(img, mask, boxes, seed=1, step=s)


@pytest.mark.benchmark(group="rjmcmc 1920x1080, 5 people 100x250, 6 frames")
@pytest.mark.parametrize("min_samples", [0, 2048], ids=["every pixel", "lattice 2048"])
def test_rjmcmc_large_boxes(benchmark: BenchmarkFixture, large: Any, min_samples: int) -> None:
    """RJMCMCConfig.min_samples (default 2048) against counting every pixel (0; was the only
    way until 4 December 2026)."""
    benchmark.pedantic(_rj_frames, args=(large, float(min_samples)), rounds=3, iterations=1)


def _mh_steps(large: Any, min_samples: float) -> None:
    img, _, boxes = large
    cx, cy, w, h = boxes[0]
    ref = np.asarray(_core.box_histograms(img, boxes[:1]))[0] + 1e-3
    n = 200
    p = np.tile([cx, cy, 1.0, cx, cy, 1.0], (n, 1))
    wts = np.full(n, 1.0 / n)
    m = np.array([[cx, cy, 1.0], [cx, cy, 1.0]])
    a, b = np.array([2.0, 2.0, 2.0]), np.array([-1.0, -1.0, -1.0])
    for s in range(5):
        _core.mh_step(
            p, wts, m, img, ref, w, h, a, b, np.array([3.0, 3.0, 0.02]), 0.5, 2.0, False, 20.0,
            "uniform", True, 11, s, n_iter=5, burn_in=2, min_samples=min_samples,
        )  # fmt: skip


@pytest.mark.benchmark(group="mh 1920x1080, one 100x250 person, 200 particles x 6, 5 steps")
@pytest.mark.parametrize("min_samples", [0, 2048], ids=["every pixel", "lattice 2048"])
def test_mh_large_boxes(benchmark: BenchmarkFixture, large: Any, min_samples: int) -> None:
    """mh_step counts a lattice's points in place (4 December 2026: it gathered them into an
    image of their own for every evaluation first)."""
    benchmark.pedantic(_mh_steps, args=(large, float(min_samples)), rounds=3, iterations=1)
