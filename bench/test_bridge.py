"""Goal-directed path: C++ core against a NumPy implementation of the same O(T) recursion,
T = 10 ... 10 000, and all gaps of a PETS mask.

The cost should grow linearly in T: each side's median at T = 10 000 over its median at
T = 1000 goes to ``extra_info["x_t1000"]`` (linear: 10; quadratic: 100). It is recorded, not
asserted: on 6 December, beside another job, the NumPy recursion gave 10.8x and the core 94x
(40x in a direct timing, least of 3), its cost per step rising from 0.3 to 1.2-1.6 us
between T = 2000 and 3000 and staying there to T = 20 000 (linear on either side; why is not
known).

Locally: ``pytest bench/test_bridge.py --benchmark-only``; CI: ``--benchmark-disable``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from pytest_benchmark.fixture import BenchmarkFixture

from pftrack import _core
from pftrack._typing import F64
from pftrack.io.mot import read_mot
from pftrack.kalman import cv_transition_xy
from pftrack.recovery import estimate_noise, fit_motion, recover_gaps
from pftrack.recovery import experiment as E
from pftrack.recovery.mixture import singer_model, stand_hypotheses
from tests.reference import bridge as ref
from tests.reference import mixture as ref_mix

A = cv_transition_xy(1.0)
Q = np.diag([1e-6, 1e-6, 1e-4, 1e-4])
H = np.hstack([np.eye(2), np.zeros((2, 2))])
R = 1e-6 * np.eye(2)
M0 = np.array([0.0, 0.0, 1.0, 0.5])
P0 = 1e-3 * np.eye(4)
SIZES = [10, 100, 1000, 10000]
_MEDIANS: dict[tuple[str, int], float] = {}  # (side, T) -> median seconds, this run


def _linear_in_t(benchmark: BenchmarkFixture, side: str, T: int) -> None:
    """Keep the median; at T = 10 000 record the growth from T = 1000 (not when untimed)."""
    if not benchmark.stats:
        return
    _MEDIANS[side, T] = benchmark.stats.stats.median
    if T == SIZES[-1] and (side, SIZES[-2]) in _MEDIANS:
        benchmark.extra_info["x_t1000"] = round(_MEDIANS[side, T] / _MEDIANS[side, SIZES[-2]], 1)


def goal(T: int) -> F64:
    return np.array([1.0 * T, 0.5 * T + 3.0])


@pytest.mark.parametrize("T", SIZES)
def test_core(benchmark: BenchmarkFixture, T: int) -> None:
    benchmark.group = f"gdt path T={T}"
    benchmark(_core.gdt_solve, A, Q, H, R, M0, P0, goal(T), T, "general", True)
    _linear_in_t(benchmark, "core", T)


@pytest.mark.parametrize("T", SIZES)
def test_numpy_reference(benchmark: BenchmarkFixture, T: int) -> None:
    benchmark.group = f"gdt path T={T}"
    if T == 10000:
        benchmark.pedantic(
            ref.gdt_numpy_fast, args=(A, Q, H, R, M0, P0, goal(T), T), rounds=3, iterations=1
        )
    else:
        benchmark(ref.gdt_numpy_fast, A, Q, H, R, M0, P0, goal(T), T)
    _linear_in_t(benchmark, "numpy", T)


@pytest.fixture(scope="module")
def pets_gaps(pets_dir: Path) -> list[tuple[F64, F64]]:
    """(segment before, segment after) of the 23 gaps of the PETS mask at (396, 224)."""
    gt = pets_dir / "gt.txt"
    if not gt.is_file():
        pytest.skip("PETS09-S2L1 ground truth not available")
    trajs = E.trajectories(read_mot(gt))
    gaps, _ = E.find_gaps(trajs, (396, 224, 100, 100))
    return [(g.segment_a, g.segment_b) for g in gaps]


@pytest.mark.benchmark(group="PETS mask 396,224: all 23 gaps")
@pytest.mark.parametrize("method", ["gdt", "gdt-bi", "gdt-mix", "linear", "cubic", "bspline"])
def test_pets_all_gaps(
    benchmark: BenchmarkFixture, pets_gaps: list[tuple[F64, F64]], method: str
) -> None:
    pairs = pets_gaps
    noise = motion = None
    if method in ("gdt-bi", "gdt-mix"):
        segments = [p for pair in pairs for p in pair]
        noise = estimate_noise(segments)
        motion = fit_motion(segments, noise) if method == "gdt-mix" else None
    benchmark(recover_gaps, pairs, method, noise=noise, motion=motion)


def _mixture_problem(T: int) -> tuple[Any, ...]:
    """A walking window (30 points each side) with a gap of T steps and every stand hypothesis
    of gdt-mix (191 for T >= 20), Singer model as fitted on PETS."""
    rng = np.random.default_rng(0)
    n = 60 + T
    z = np.cumsum(rng.normal(3.0, 0.3, n))
    z[30 : 30 + T - 1] = np.nan
    F, Qm = singer_model(0.0635, 2.99)
    t1, t2 = stand_hypotheses(T)
    return (z, 29, 29 + T, F[0], Qm[0], 0.0774, np.array([1e4, 21.9, 0.1]), t1, t2, 21.9)


@pytest.mark.parametrize("T", [10, 40, 160])
def test_gap_mixture_core(benchmark: BenchmarkFixture, T: int) -> None:
    benchmark.group = f"gdt-mix one gap, one axis, T={T}"
    benchmark(_core.gap_mixture, *_mixture_problem(T))


@pytest.mark.parametrize("T", [10, 40, 160])
def test_gap_mixture_numpy(benchmark: BenchmarkFixture, T: int) -> None:
    benchmark.group = f"gdt-mix one gap, one axis, T={T}"
    benchmark.pedantic(
        ref_mix.gap_mixture_vectorised, args=_mixture_problem(T), rounds=3, iterations=1
    )
