"""Recovery of a whole MOT file and its hot parts against their NumPy references.

* ``fill 500 tracks``: :func:`pftrack.recovery.fill_gaps` on the 500-track synthetic file of
  :mod:`bench.recovery_file` (``auto``, calibration included, and ``linear``).
* ``rts gaps``: the batched Kalman/RTS smoother of the ``rts`` candidate
  (:func:`~pftrack.recovery.baselines.rts_batch`, one C++ call ``_core.rts_gaps_batch`` for all
  gaps) against its vectorised NumPy reference (``rts_batch_numpy``, one NumPy step per frame
  for all gaps) and the textbook matrix loop of ``tests/reference/smoothing.py``, one gap at a
  time.
* ``singer loglik``: the C++ likelihood behind ``fit_motion`` against
  ``tests/reference/mixture.py``.
* ``noise loglik grid``: the likelihood grid behind ``estimate_noise`` (``_core.noise_loglik_grid``,
  81 ``(q, r)`` pairs over the runs of the 500-track file's fit sample, about 1000 points)
  against its NumPy reference (``tests/reference/bridge.py``, vectorised over the pairs).
* ``state loglik, 343 models``: one level of ``fit_singer``'s grid (``_core.state_loglik_batch``,
  the models filtered 4 at a time, on one thread and on :func:`pftrack._threads.kernel_threads`)
  against the same call one model at a time.
* ``gdt-mix, 400 gaps``: :func:`~pftrack.recovery.mixture.recover_mixture_gaps` (one C++ call,
  ``_core.gap_mixture_many``, on one thread and on ``kernel_threads()``) against one
  :func:`~pftrack.recovery.mixture.recover_mixture` call per gap, the same bits.
* ``link fragments``: :func:`pftrack.recovery.link_tracklets` over the pairs within the time
  gate (8000 one-row fragments ten frames apart, the user trial's file, and 1000 of them)
  against the former dense ``(K, K)`` loop and assignment (``tests/reference/linking.py``, on
  the 1000 only: 8000 took 34 s and 1.6 GB).
* ``rts smooth, 500 tracks``: :func:`pftrack.kalman.rts_smooth` (one C++ call ``_core.rts_smooth``
  per track, what the offline pass and ``pftrack smooth`` run for every track's box) against
  the NumPy loop it replaced (``rts_smooth_numpy``), over the 500 tracks of
  :mod:`bench.recovery_file` (four axes: centre and size). The ratios of the medians go to
  ``extra_info["x_numpy"]`` (and ``x_stonesoup`` when bench/test_stonesoup.py runs too:
  :func:`bench.conftest.ratios`).
* ``region blocks, 500 tracks``: the square regions ``auto`` cuts its validation gaps with
  (:func:`~pftrack.recovery.calibrate._region_blocks`, one C++ call ``_core.region_blocks``)
  against the NumPy loop over the squares it replaced (``tests/reference/regions.py``), on the
  box centres' runs of the 500-track file, squares of 57 px as ``recover`` lays there (1700 of
  2000 within ``REGION_WORK``) and of 5 px; the same stretches; the ratio in ``x_numpy``.
* ``gdt path T=8000``: one goal-directed path 8000 steps long (``_core.gdt_solve``, path, every
  ``eps_t`` and state covariance) against the NumPy peer of its O(T) recursion
  (``tests/reference/bridge.py``'s ``gdt_numpy_fast``), the same path; the cost per step goes to
  ``extra_info["us_per_step"]``. Beyond about 2000 steps the core's cost per step rises (0.35 to
  about 0.5 us, least of 7 runs on 6 December): not the sums, which are one backward recursion,
  but the first touch of its ~544 B a step of fresh buffers, which glibc maps anew for each call
  above its mmap threshold (with ``MALLOC_MMAP_THRESHOLD_=1000000000`` the cost per step at
  T = 8000 was T = 1000's, 0.32-0.34 us; docs/recovery.md, Speed).

Locally: ``pytest bench/test_recovery.py --benchmark-only``; CI: ``--benchmark-disable``.
"""

from __future__ import annotations

import numpy as np
import pytest
from pytest_benchmark.fixture import BenchmarkFixture

from bench.conftest import ratios
from bench.recovery_file import synthetic_tracks
from pftrack import _core
from pftrack._threads import kernel_threads
from pftrack._typing import F64
from pftrack.kalman import cv_transition, cv_transition_xy, rts_smooth, wna_Q
from pftrack.recovery import LinkConfig, fill_gaps, link_tracklets
from pftrack.recovery.baselines import rts_batch
from pftrack.recovery.calibrate import _fit_sample, _flat, _region_blocks
from pftrack.recovery.mixture import (
    DIFFUSE,
    fit_motion,
    recover_mixture,
    recover_mixture_gaps,
    singer_model,
)
from pftrack.recovery.segments import distinct_runs
from tests.reference import bridge as ref_bridge
from tests.reference import mixture as ref_mix
from tests.reference.linking import dense_link_tracklets
from tests.reference.regions import region_blocks as region_blocks_numpy
from tests.reference.smoothing import dense_kalman_rts, rts_batch_numpy, rts_smooth_numpy


@pytest.fixture(scope="module")
def tracks_500() -> F64:
    return synthetic_tracks(500, seed=0)


@pytest.mark.parametrize("method", ["auto", "linear"])
def test_fill_500_tracks(benchmark: BenchmarkFixture, tracks_500: F64, method: str) -> None:
    benchmark.group = "fill 500 tracks"
    out, rep = benchmark.pedantic(fill_gaps, args=(tracks_500, method), rounds=3, iterations=1)
    assert rep.n_gaps > 400 and np.all(np.isfinite(out))


def _gaps(n: int = 400) -> list[tuple[F64, F64]]:
    rng = np.random.default_rng(0)
    out = []
    for _ in range(n):
        na, nb, L = (int(v) for v in rng.integers(5, 40, 3))
        fa, fb = np.arange(na, dtype=float), np.arange(na + L, na + L + nb, dtype=float)
        a = np.column_stack([fa, np.cumsum(rng.normal(0, 2, (na, 2)), axis=0)])
        b = np.column_stack([fb, np.cumsum(rng.normal(0, 2, (nb, 2)), axis=0)])
        out.append((a, b))
    return out


def _rts_reference(pairs: list[tuple[F64, F64]], q: float = 0.1, r: float = 1.0) -> list[F64]:
    """One textbook matrix Kalman/RTS loop per gap and axis (30 points each side)."""
    F, Q = cv_transition(), wna_Q(q)
    H, R = np.array([[1.0, 0.0]]), np.array([[r]])
    res = []
    for a, b in pairs:
        a, b = a[-30:], b[:30]
        f0 = int(a[0, 0])
        n = int(b[-1, 0]) - f0 + 1
        has = np.zeros(n, dtype=bool)
        has[(a[:, 0] - f0).astype(int)] = has[(b[:, 0] - f0).astype(int)] = True
        cols = []
        for axis in (1, 2):
            z = np.zeros((n, 1))
            z[(a[:, 0] - f0).astype(int), 0] = a[:, axis]
            z[(b[:, 0] - f0).astype(int), 0] = b[:, axis]
            m0, P0 = np.array([z[0, 0], 0.0]), np.diag([r, 100.0])
            _, sm, _ = dense_kalman_rts(z, has, F, Q, H, R, m0, P0)
            cols.append(sm[:, 0])
        lo, hi = int(a[-1, 0]) - f0 + 1, int(b[0, 0]) - f0
        res.append(np.column_stack(cols)[lo:hi])
    return res


def test_rts_batch(benchmark: BenchmarkFixture) -> None:
    benchmark.group = "rts gaps"
    pairs = _gaps()
    got = benchmark(rts_batch, pairs)
    want = _rts_reference(pairs[:20])
    for g, w in zip(got[:20], want, strict=True):
        np.testing.assert_allclose(g, w, rtol=1e-8, atol=1e-8)


def test_rts_numpy_vectorised(benchmark: BenchmarkFixture) -> None:
    benchmark.group = "rts gaps"
    pairs = _gaps()
    got = benchmark(rts_batch_numpy, pairs)
    for g, w in zip(got, rts_batch(pairs), strict=True):
        np.testing.assert_allclose(g, w, rtol=1e-10, atol=1e-8)


def test_rts_numpy_reference(benchmark: BenchmarkFixture) -> None:
    benchmark.group = "rts gaps"
    benchmark.pedantic(_rts_reference, args=(_gaps(),), rounds=3, iterations=1)


#: A constant-velocity walk in (x, y) to a goal 8000 frames on (bench/test_bridge.py's model).
GDT_T = 8000
GDT_MODEL = (
    cv_transition_xy(1.0),
    np.diag([1e-6, 1e-6, 1e-4, 1e-4]),
    np.hstack([np.eye(2), np.zeros((2, 2))]),
    1e-6 * np.eye(2),
    np.array([0.0, 0.0, 1.0, 0.5]),
    1e-3 * np.eye(4),
    np.array([1.0 * GDT_T, 0.5 * GDT_T + 3.0]),
)


def _per_step(benchmark: BenchmarkFixture) -> None:
    if benchmark.stats:  # not when untimed (--benchmark-disable)
        benchmark.extra_info["us_per_step"] = round(benchmark.stats.stats.min / GDT_T * 1e6, 3)


def test_gdt_path_8000_core(benchmark: BenchmarkFixture) -> None:
    benchmark.group = f"gdt path T={GDT_T}"
    r = benchmark(_core.gdt_solve, *GDT_MODEL, GDT_T, "general", True)
    _per_step(benchmark)
    want = ref_bridge.gdt_numpy_fast(*GDT_MODEL, GDT_T)
    np.testing.assert_allclose(r["path"], want, rtol=1e-9, atol=1e-6)
    assert r["eps"].shape == (GDT_T, 4, 4) and r["cov"].shape == (GDT_T + 1, 4, 4)


def test_gdt_path_8000_numpy_reference(benchmark: BenchmarkFixture) -> None:
    benchmark.group = f"gdt path T={GDT_T}"
    benchmark.pedantic(ref_bridge.gdt_numpy_fast, args=(*GDT_MODEL, GDT_T), rounds=3, iterations=1)
    _per_step(benchmark)


@pytest.fixture(scope="module")
def singer_runs() -> list[F64]:
    rng = np.random.default_rng(1)
    return [np.cumsum(np.cumsum(rng.normal(0, 0.3, 120))) for _ in range(8)]


def test_singer_loglik_core(benchmark: BenchmarkFixture, singer_runs: list[F64]) -> None:
    benchmark.group = "singer loglik"
    F, Q = singer_model(0.1, 3.0)
    z = np.concatenate(singer_runs)
    lengths = np.array([len(r) for r in singer_runs], dtype=np.int32)
    args = (z, lengths, np.ascontiguousarray(F.reshape(-1, 3)),
            np.ascontiguousarray(Q.reshape(-1, 3)), np.array([0.5]), DIFFUSE)  # fmt: skip
    got = benchmark(_core.state_loglik_batch, *args)
    want = ref_mix.state_loglik(singer_runs, F[0], Q[0], 0.5, DIFFUSE)
    np.testing.assert_allclose(got[0], want, rtol=1e-9)


def test_singer_loglik_numpy(benchmark: BenchmarkFixture, singer_runs: list[F64]) -> None:
    benchmark.group = "singer loglik"
    F, Q = singer_model(0.1, 3.0)
    benchmark(ref_mix.state_loglik, singer_runs, F[0], Q[0], 0.5, DIFFUSE)


@pytest.fixture(scope="module")
def fit_runs(tracks_500: F64) -> list[F64]:
    """The runs ``auto`` fits noise and motion to on the 500-track file (box centres)."""
    centres = tracks_500[:, [0, 2, 3]].copy()
    centres[:, 1:] += 0.5 * tracks_500[:, 4:6]
    ids = tracks_500[:, 1]
    runs = distinct_runs([centres[ids == i] for i in np.unique(ids)])
    return _fit_sample([r for r in runs if len(r) >= 4], 0)


@pytest.fixture(scope="module")
def centre_runs(tracks_500: F64) -> list[F64]:
    """The box centres' runs of the 500-track file, every one (what ``auto`` lays squares on)."""
    centres = tracks_500[:, [0, 2, 3]].copy()
    centres[:, 1:] += 0.5 * tracks_500[:, 4:6]
    ids = tracks_500[:, 1]
    return distinct_runs([centres[ids == i] for i in np.unique(ids)])


@pytest.mark.parametrize("impl", ["core", "numpy"])
@pytest.mark.parametrize("side", [57.0, 5.0])
def test_region_blocks(
    benchmark: BenchmarkFixture, centre_runs: list[F64], side: float, impl: str
) -> None:
    benchmark.group = f"region blocks, 500 tracks, side {side:g} px"
    flat = _flat(centre_runs)
    fn = _region_blocks if impl == "core" else region_blocks_numpy
    got = benchmark(lambda: fn(flat, side, np.random.default_rng(0)))
    want = (region_blocks_numpy if impl == "core" else _region_blocks)(
        flat, side, np.random.default_rng(0)
    )
    assert len(want.run) > 0
    for g, w in zip(got, want, strict=True):
        np.testing.assert_array_equal(g, w)
    ratios(benchmark, impl)  # the README's "8 ms against 92 ms": x_numpy


_GRID_Q, _GRID_R = (
    10.0 ** g.ravel() for g in np.meshgrid(np.linspace(-5, 2, 9), np.linspace(-3, 2, 9))
)


def test_noise_loglik_grid_core(benchmark: BenchmarkFixture, fit_runs: list[F64]) -> None:
    benchmark.group = "noise loglik grid"
    z = np.ascontiguousarray(np.concatenate([r[:, 1] for r in fit_runs]))
    lengths = np.array([len(r) for r in fit_runs], dtype=np.int32)
    got = benchmark(_core.noise_loglik_grid, z, lengths, _GRID_Q, _GRID_R)
    want = ref_bridge.loglik_grid(fit_runs, 0, _GRID_Q, _GRID_R)
    np.testing.assert_allclose(got, want, rtol=1e-12)


def test_noise_loglik_grid_numpy(benchmark: BenchmarkFixture, fit_runs: list[F64]) -> None:
    benchmark.group = "noise loglik grid"
    benchmark.pedantic(
        ref_bridge.loglik_grid, args=(fit_runs, 0, _GRID_Q, _GRID_R), rounds=3, iterations=1
    )


def _singer_grid() -> tuple[F64, F64, F64]:
    """fit_singer's first grid: log10 q, r, tau."""
    axes = [np.linspace(lo, hi, 7) for lo, hi in ((-5.0, 3.0), (-3.0, 3.0), (-1.5, 2.5))]
    g = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
    F, Q = singer_model(10.0 ** g[:, 0], 10.0 ** g[:, 2])
    return F, Q, 10.0 ** g[:, 1]


@pytest.mark.parametrize("threads", [1, kernel_threads()])
@pytest.mark.parametrize("method", ["batch", "per gap"])
def test_gdt_mix_400_gaps(benchmark: BenchmarkFixture, method: str, threads: int) -> None:
    benchmark.group = "gdt-mix, 400 gaps"
    pairs = _gaps()
    fit = fit_motion([seg for pair in pairs for seg in pair])
    assert not fit.is_gdt_bi  # the mixture itself runs, not gdt-bi's smoother

    def per_gap() -> list[F64]:
        return [recover_mixture(a, b, fit) for a, b in pairs]

    if method == "per gap" and threads > 1:
        pytest.skip("one call per gap runs on one thread")
    run = per_gap if method == "per gap" else (lambda: recover_mixture_gaps(pairs, fit, threads))
    got = benchmark(run)
    want = per_gap() if method == "batch" else recover_mixture_gaps(pairs, fit)
    for g, w in zip(got, want, strict=True):
        np.testing.assert_array_equal(g, w)


@pytest.mark.parametrize("threads", [1, kernel_threads()])
@pytest.mark.parametrize("batched", [True, False])
def test_state_loglik_343_models(
    benchmark: BenchmarkFixture, fit_runs: list[F64], batched: bool, threads: int
) -> None:
    benchmark.group = "state loglik, 343 models"
    F, Q, r = _singer_grid()
    z = np.ascontiguousarray(np.concatenate([v[:, 1] for v in fit_runs]))
    lengths = np.array([len(v) for v in fit_runs], dtype=np.int32)
    Fs = [np.ascontiguousarray(f) for f in F]
    Qs = [np.ascontiguousarray(q) for q in Q]

    def one_by_one() -> F64:
        return np.array(
            [
                _core.state_loglik_batch(z, lengths, Fs[k], Qs[k], r[k : k + 1], DIFFUSE)[0]
                for k in range(len(r))
            ]
        )

    def batch() -> F64:
        out: F64 = _core.state_loglik_batch(
            z, lengths, np.ascontiguousarray(F.reshape(-1, 3)),
            np.ascontiguousarray(Q.reshape(-1, 3)), r, DIFFUSE, threads,
        )  # fmt: skip
        return out

    if not batched and threads > 1:
        pytest.skip("one call per model runs on one thread")
    got = benchmark(batch if batched else one_by_one)
    np.testing.assert_array_equal(got, (one_by_one if batched else batch)())


_Q, _R = np.array([0.5, 0.5, 0.1, 0.1]), np.array([4.0, 4.0, 9.0, 9.0])


def test_rts_smooth_core(
    benchmark: BenchmarkFixture, track_boxes: list[tuple[F64, np.ndarray]]
) -> None:
    benchmark.group = "rts smooth, 500 tracks"

    def run() -> list[F64]:
        return [
            rts_smooth(z, h, _Q, _R, velocity_sd=10.0, update_first=False) for z, h in track_boxes
        ]

    got = benchmark(run)
    for (z, h), g in list(zip(track_boxes, got, strict=True))[:25]:
        np.testing.assert_array_equal(g, rts_smooth_numpy(z, h, _Q, _R, 10.0, False))
    ratios(benchmark, "core")


def test_rts_smooth_numpy(
    benchmark: BenchmarkFixture, track_boxes: list[tuple[F64, np.ndarray]]
) -> None:
    benchmark.group = "rts smooth, 500 tracks"
    benchmark.pedantic(
        lambda: [rts_smooth_numpy(z, h, _Q, _R, 10.0, False) for z, h in track_boxes],
        rounds=3,
        iterations=1,
    )
    ratios(benchmark, "numpy")


def _sparse_fragments(k: int) -> F64:
    """`k` one-row fragments, one every 10 frames, cycling through 50 places 5 px apart."""
    i = np.arange(k, dtype=np.float64)
    return np.column_stack([1 + 10 * i, i + 1, 100 + (i % 50) * 5, np.full(k, 100.0),
                            np.full((k, 2), (20.0, 40.0)), np.full(k, 0.9),
                            -np.ones((k, 3))])  # fmt: skip


@pytest.mark.parametrize("k", [1000, 8000])
def test_link_fragments(benchmark: BenchmarkFixture, k: int) -> None:
    benchmark.group = "link fragments"
    rows = _sparse_fragments(k)
    _, mapping = benchmark.pedantic(link_tracklets, args=(rows, LinkConfig()), rounds=3)
    assert len(mapping) == k - k // 50


def test_link_fragments_dense_reference(benchmark: BenchmarkFixture) -> None:
    benchmark.group = "link fragments"
    rows = _sparse_fragments(1000)
    out, mapping = benchmark.pedantic(dense_link_tracklets, args=(rows, LinkConfig()), rounds=1)
    assert len(mapping) == 980
    np.testing.assert_array_equal(out, link_tracklets(rows, LinkConfig())[0])
