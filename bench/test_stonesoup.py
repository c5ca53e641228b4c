"""pftrack against Stone Soup (the ``peers`` extra), in the groups of the other benchmarks.

Skipped without Stone Soup. Its models are built as in ``experiments/stonesoup_models.py``.

* ``rts smooth, one track``: :func:`pftrack.kalman.rts_smooth` on one 400-frame track (centre
  and size, a quarter of the frames missed) against Stone Soup's ``KalmanPredictor`` +
  ``KalmanUpdater`` + ``KalmanSmoother`` on the same model (the same smoothed means to 1e-9,
  tests/experiments/test_stonesoup.py) and the NumPy loop ``rts_smooth_numpy``.
* ``rts smooth, 500 tracks``: the same over the 500 tracks of :mod:`bench.recovery_file`; the
  group of ``bench/test_recovery.py``, whose pftrack and NumPy rows it joins when both files run.
* ``systematic resample N=10000``: ``SystematicResampler.resample`` on a ``ParticleState`` of
  10 000 particles (state ``(x, vx, y, vy)``), the group of ``bench/test_kernels.py``.
* ``particle filter step``: one step of a constant-velocity 2D target with a Gaussian position
  likelihood. Stone Soup: ``ParticlePredictor`` + ``ParticleUpdater`` with
  ``SystematicResampler`` (resampling every step). pftrack has no Gaussian likelihood (its
  filters weigh by colour), so its row is the public kernels around a NumPy Gaussian weight:
  :func:`~pftrack.particle_filter.propagate` (the AR(2) model with ``velocity_gain=1``, constant
  velocity), the weight in NumPy, :func:`~pftrack.particle_filter.systematic_resample` and the
  gather. ``particle predict`` times the propagation alone (noise draw included on both sides).

Each group's ratios of the medians (Stone Soup's or NumPy's over pftrack's) go to
``extra_info["x_stonesoup"]`` and ``["x_numpy"]`` of the later benchmark
(:func:`bench.conftest.ratios`), across the files run together.

Locally: ``pytest bench/test_stonesoup.py bench/test_recovery.py bench/test_kernels.py
--benchmark-enable --benchmark-only --benchmark-group-by=group -k "stonesoup or rts_smooth or
resample_"``.
"""

from __future__ import annotations

import datetime
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray
from pytest_benchmark.fixture import BenchmarkFixture

from bench.conftest import ratios
from experiments.stonesoup_models import EPOCH, stonesoup_rts_smooth
from pftrack._typing import F64
from pftrack.kalman import rts_smooth
from pftrack.particle_filter import Ar2Model, propagate, systematic_resample
from tests.reference.smoothing import rts_smooth_numpy

pytest.importorskip("stonesoup")

_Q, _R = np.array([0.5, 0.5, 0.1, 0.1]), np.array([4.0, 4.0, 9.0, 9.0])  # bench/test_recovery.py
Boxes = list[tuple[F64, NDArray[np.bool_]]]


def _smooth_all(fn: Callable[..., F64], tracks: Boxes) -> list[F64]:
    return [fn(z, h, _Q, _R, velocity_sd=10.0, update_first=False) for z, h in tracks]


def _numpy(z: F64, h: NDArray[np.bool_], q: F64, r2: F64, **kw: Any) -> F64:
    out: F64 = rts_smooth_numpy(z, h, q, r2, kw["velocity_sd"], kw["update_first"])
    return out


@pytest.fixture(scope="module")
def one_track() -> Boxes:
    """One 400-frame walker (centre and size), a quarter of its frames missed."""
    rng = np.random.default_rng(0)
    steps = 400
    centre = 500 + np.cumsum(np.cumsum(rng.normal(0, 0.3, (steps, 2)), axis=0), axis=0)
    size = np.array([40.0, 100.0]) + np.cumsum(rng.normal(0, 0.2, (steps, 2)), axis=0)
    z = np.column_stack([centre, size]) + rng.normal(0, 1.0, (steps, 4))
    has = rng.random(steps) >= 0.25
    has[0] = True
    z[~has] = np.nan
    return [(z, has)]


@pytest.mark.benchmark(group="rts smooth, one track of 400 frames")
def test_rts_one_track_core(benchmark: BenchmarkFixture, one_track: Boxes) -> None:
    got = benchmark(_smooth_all, rts_smooth, one_track)
    want = _smooth_all(stonesoup_rts_smooth, one_track)
    h = one_track[0][1]
    np.testing.assert_allclose(got[0][h], want[0][h], rtol=1e-9, atol=1e-9)
    ratios(benchmark, "core")


@pytest.mark.benchmark(group="rts smooth, one track of 400 frames")
def test_rts_one_track_numpy(benchmark: BenchmarkFixture, one_track: Boxes) -> None:
    got = benchmark(_smooth_all, _numpy, one_track)
    np.testing.assert_array_equal(got[0], _smooth_all(rts_smooth, one_track)[0])
    ratios(benchmark, "numpy")


@pytest.mark.benchmark(group="rts smooth, one track of 400 frames")
def test_rts_one_track_stonesoup(benchmark: BenchmarkFixture, one_track: Boxes) -> None:
    benchmark.pedantic(_smooth_all, args=(stonesoup_rts_smooth, one_track), rounds=5)
    ratios(benchmark, "stonesoup")


@pytest.mark.benchmark(group="rts smooth, 500 tracks")
def test_rts_smooth_stonesoup(benchmark: BenchmarkFixture, track_boxes: Boxes) -> None:
    """Stone Soup over bench/test_recovery.py's 500 tracks: one round (about half a minute)."""
    got = benchmark.pedantic(_smooth_all, args=(stonesoup_rts_smooth, track_boxes), rounds=1)
    for (z, h), g in list(zip(track_boxes, got, strict=True))[:25]:
        want = rts_smooth(z, h, _Q, _R, velocity_sd=10.0, update_first=False)
        np.testing.assert_allclose(g[h], want[h], rtol=1e-9, atol=1e-9)
    ratios(benchmark, "stonesoup")


@pytest.fixture(scope="module")
def weights_10k() -> F64:
    w = np.random.default_rng(2).random(10_000)  # bench/test_kernels.py's
    w /= w.sum()
    return w


@pytest.mark.benchmark(group="systematic resample N=10000")
def test_resample_stonesoup(benchmark: BenchmarkFixture, weights_10k: F64) -> None:
    """``SystematicResampler.resample`` of a ``ParticleState`` (4-D states, log weights)."""
    from stonesoup.resampler.particle import SystematicResampler
    from stonesoup.types.array import StateVectors
    from stonesoup.types.state import ParticleState

    states = StateVectors(np.random.default_rng(3).normal(size=(4, len(weights_10k))))
    particles = ParticleState(states, log_weight=np.log(weights_10k), timestamp=EPOCH)
    out = benchmark(SystematicResampler().resample, particles)
    assert len(out) == len(weights_10k)
    ratios(benchmark, "stonesoup")


# ---- particle filter: a constant-velocity target in 2D, Gaussian position likelihood ---------

_PF_Q, _PF_R = 1.0, 4.0  # CV noise_diff_coeff (px²/frame³); position variance (px²)


def _truth(steps: int = 10_000) -> F64:
    t = np.arange(steps, dtype=float)
    return np.column_stack([100 + 2.0 * t, 200 + 1.0 * t])


def _stonesoup_filter(n: int) -> tuple[Callable[[], Any], Callable[[], Any]]:
    """Stone Soup's particle filter on :func:`_truth`: (one full step, one prediction)."""
    from stonesoup.models.measurement.linear import LinearGaussian
    from stonesoup.models.transition.linear import (
        CombinedLinearGaussianTransitionModel,
        ConstantVelocity,
    )
    from stonesoup.predictor.particle import ParticlePredictor
    from stonesoup.resampler.particle import SystematicResampler
    from stonesoup.types.array import StateVectors
    from stonesoup.types.detection import Detection
    from stonesoup.types.hypothesis import SingleHypothesis
    from stonesoup.types.state import ParticleState
    from stonesoup.updater.particle import ParticleUpdater

    transition = CombinedLinearGaussianTransitionModel([ConstantVelocity(_PF_Q)] * 2)
    measurement = LinearGaussian(ndim_state=4, mapping=(0, 2), noise_covar=np.eye(2) * _PF_R)
    predictor = ParticlePredictor(transition)
    updater = ParticleUpdater(measurement, resampler=SystematicResampler())
    rng = np.random.default_rng(0)
    start = np.array([[100.0], [2.0], [200.0], [1.0]]) + rng.normal(0, 1, (4, n))
    state = [ParticleState(StateVectors(start), log_weight=np.full(n, -np.log(n)), timestamp=EPOCH)]
    truth = _truth()
    k = [0]

    def step() -> Any:
        k[0] += 1
        when = EPOCH + datetime.timedelta(seconds=k[0])
        pred = predictor.predict(state[0], timestamp=when)
        z = truth[k[0] % len(truth)].reshape(2, 1)
        det = Detection(z, timestamp=when, measurement_model=measurement)
        state[0] = updater.update(SingleHypothesis(pred, det))
        est = np.asarray(state[0].state_vector, float)[[0, 2]].mean(axis=1)
        return est, z[:, 0]

    def predict() -> Any:
        k[0] += 1  # a new timestamp each call: predict is lru-cached on (prior, timestamp)
        return predictor.predict(state[0], timestamp=EPOCH + datetime.timedelta(seconds=k[0]))

    return step, predict


def _pftrack_filter(n: int) -> tuple[Callable[[], tuple[F64, F64]], Callable[[], F64]]:
    """The same target with pftrack's kernels: (one full step, one propagation).

    A particle is ``[cx, cy, s, cx', cy', s']`` (this frame and the last); ``velocity_gain=1``
    is constant velocity on the centre, the scale stays 1.
    """
    model = Ar2Model(sigma_xy=float(np.sqrt(_PF_Q)), sigma_s=0.0, scale_gain=0.0)
    rng = np.random.default_rng(0)
    p = np.zeros((n, 6))
    p[:, 0:2] = np.array([100.0, 200.0]) + rng.normal(0, 1, (n, 2))
    p[:, 3:5] = p[:, 0:2] - np.array([2.0, 1.0]) + rng.normal(0, 1, (n, 2))
    p[:, 2] = p[:, 5] = 1.0
    state = [p]
    truth = _truth()
    k = [0]

    def step() -> F64:
        k[0] += 1
        p = state[0]
        propagate(p, rng.standard_normal((n, 3)), model)
        d = p[:, 0:2] - truth[k[0] % len(truth)]
        log_w = -0.5 * np.einsum("ij,ij->i", d, d) / _PF_R
        idx = systematic_resample(np.exp(log_w - log_w.max()), rng)
        state[0] = np.ascontiguousarray(p[idx])
        return state[0][:, 0:2].mean(axis=0), truth[k[0] % len(truth)]

    def predict() -> F64:
        propagate(state[0], rng.standard_normal((n, 3)), model)
        return state[0]

    return step, predict


@pytest.mark.parametrize("n", [1000, 10_000])
def test_pf_step_stonesoup(benchmark: BenchmarkFixture, n: int) -> None:
    benchmark.group = f"particle filter step N={n}"
    step, _ = _stonesoup_filter(n)
    estimate, truth = benchmark(step)
    assert np.all(np.abs(estimate - truth) < 3.0)  # it follows the target
    ratios(benchmark, "stonesoup")


@pytest.mark.parametrize("n", [1000, 10_000])
def test_pf_step_pftrack(benchmark: BenchmarkFixture, n: int) -> None:
    benchmark.group = f"particle filter step N={n}"
    step, _ = _pftrack_filter(n)
    estimate, truth = benchmark(step)
    assert np.all(np.abs(estimate - truth) < 3.0)  # it follows the target
    ratios(benchmark, "pftrack")


@pytest.mark.benchmark(group="particle predict N=10000")
def test_pf_predict_stonesoup(benchmark: BenchmarkFixture) -> None:
    _, predict = _stonesoup_filter(10_000)
    benchmark(predict)
    ratios(benchmark, "stonesoup")


@pytest.mark.benchmark(group="particle predict N=10000")
def test_pf_predict_pftrack(benchmark: BenchmarkFixture) -> None:
    _, predict = _pftrack_filter(10_000)
    benchmark(predict)
    ratios(benchmark, "pftrack")
