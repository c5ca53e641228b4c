"""Benchmarks of the comparison samplers.

RJ-MCMC joint tracker at 200 and 1000 kept samples per frame on PETS09-S2L1 (480x360, public
detections as birth candidates, MOG2 foreground), and the per-object MH filter against the SIS
filter at an equal likelihood budget; a synthetic 480x360 scene with six objects when the data
is absent. The workloads are those of ``python -m experiments.rjmcmc_speed`` (a frames/s table).

Locally: ``pytest bench/test_rjmcmc.py --benchmark-only``.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from pytest_benchmark.fixture import BenchmarkFixture

from experiments.rjmcmc_speed import Frames, one_object, pets_sequence, run_filter, run_rjmcmc


@pytest.fixture(scope="module")
def seq(data_dir: Path) -> Frames:
    return pets_sequence(data_dir)


@pytest.mark.benchmark(group="rjmcmc 480x360 per frame")
@pytest.mark.parametrize("n_samples", [200, 1000])
def test_rjmcmc_sequence(benchmark: BenchmarkFixture, seq: Frames, n_samples: int) -> None:
    per_frame, _ = benchmark.pedantic(run_rjmcmc, args=(seq, n_samples), rounds=3, iterations=1)
    benchmark.extra_info["frames_per_s"] = 1.0 / per_frame


# Equal likelihood budget: SIS with 2N particles evaluates 2N boxes a frame, MH with N particles
# and one iteration evaluates N chain starts + N proposals.
@pytest.mark.benchmark(group="one object, 400 likelihoods a frame")
def test_sis_400(benchmark: BenchmarkFixture, seq: Frames) -> None:
    benchmark(run_filter, *one_object(seq), "sis", 400)


@pytest.mark.benchmark(group="one object, 400 likelihoods a frame")
def test_mh_200x1(benchmark: BenchmarkFixture, seq: Frames) -> None:
    benchmark(run_filter, *one_object(seq), "mh", 200, 1)
