"""Kernel speed: the C++ core against the NumPy baselines (and filterpy) in the same groups.

Run: pytest bench --benchmark-only --benchmark-group-by=group --benchmark-columns=mean,median,ops

Each group's speed-ups over its baselines, measured in the same run (medians), are recorded in
``extra_info["x_<baseline>"]`` of the later of the two benchmarks. Where a floor is documented
(:data:`FLOORS`: far below what is measured, so that only a real regression fails, not the noise
of a shared machine) the benchmark asserts it; the other ratios are only recorded. The
histogram groups assert only on PETS09's frame, the workload the floors were measured on.
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.typing import NDArray
from pytest_benchmark.fixture import BenchmarkFixture

from bench.conftest import PETS_FRAME, label_frame, ratios
from pftrack import _core
from pftrack._typing import F64
from pftrack.particle_filter import (
    BinnedImage,
    bhattacharyya_weights,
    box_histograms,
    box_weights,
    hsv_bins,
)
from tests.reference import fused as npb

Case = tuple[str, BinnedImage, F64, F64, int, str]  # name, frame, boxes, ref, pixels, source

#: Least speed-up of pftrack's call over a baseline in the same run: (group prefix, pftrack
#: role, baseline) -> floor. Measured (README, docs/results.md#kernels): histograms + weights
#: 36-327x NumPy's per-box loop (the public two calls; 67-327x fused, core or public),
#: resampling 66-119x filterpy. A floor about a third of the least measured ratio or below.
FLOORS = {
    ("histograms+weights", "fused", "numpy"): 10.0,
    ("histograms+weights", "core", "numpy"): 10.0,
    ("histograms+weights", "public", "numpy"): 10.0,
    ("histograms+weights", "public fused", "numpy"): 10.0,
    ("systematic resample", "core", "filterpy"): 20.0,
    ("systematic resample", "api", "filterpy"): 20.0,
    ("stratified resample", "core", "filterpy"): 20.0,
    # the 1080p step on the lattice against every pixel: 8.9-9.4x measured (README, kernels.md)
    ("sis_step_batch 15x200", "lattice", "every_pixel"): 3.0,
}


def _compare(benchmark: BenchmarkFixture, role: str, *, check: bool = True) -> None:
    """Record this benchmark's ratios within its group (:func:`bench.conftest.ratios`) and,
    with `check`, assert :data:`FLOORS` on them. Nothing with ``--benchmark-disable``."""
    for (r, base), ratio in ratios(benchmark, role).items():
        floor = next(
            (f for (g, p, b), f in FLOORS.items()
             if benchmark.group.startswith(g) and p == r and b == base),
            None,
        )  # fmt: skip
        if check and floor is not None:
            assert ratio >= floor, (
                f"{benchmark.group}: {r} is {ratio:.1f}x {base}, below the floor {floor:g}x"
            )


def _boxes(
    rng: np.random.Generator,
    n_objects: int,
    n_particles: int,
    w: int,
    h: int,
    frame_shape: tuple[int, ...],
) -> F64:
    """`n_particles` boxes (cx, cy, w, h) jittered around each of `n_objects` random centres."""
    rows, cols = frame_shape[:2]
    centres = rng.uniform([w, h], [cols - w, rows - h], (n_objects, 2))
    out = []
    for c in centres:
        p = np.empty((n_particles, 4))
        p[:, :2] = c + rng.normal(0, 4, (n_particles, 2))
        p[:, 2:] = (w, h)
        out.append(p)
    return np.vstack(out)


CASES = {
    "480x360 10x200 20x50": ("frame_480", 10, 200, 20, 50),
    "480x360 1x10000 20x50": ("frame_480", 1, 10000, 20, 50),
    "1280x720 10x200 60x150": ("frame_720", 10, 200, 60, 150),
    "1280x720 1x10000 60x150": ("frame_720", 1, 10000, 60, 150),
}


@pytest.fixture(params=list(CASES), scope="module")
def case(request: pytest.FixtureRequest, frame_source: str) -> Case:
    name = request.param
    fixture, n_obj, n_part, w, h = CASES[name]
    frame = request.getfixturevalue(fixture)
    rng = np.random.default_rng(1)
    image = hsv_bins(frame)
    boxes = _boxes(rng, n_obj, n_part, w, h, frame.shape)
    ref = box_histograms(image, boxes[:1])[0] + 1e-6
    return name, image, boxes, ref, n_part * n_obj * w * h, frame_source


def _hist_group(benchmark: BenchmarkFixture, case: Case) -> None:
    name, _, _, _, pixels, source = case
    label_frame(benchmark, f"histograms+weights {name}", source)
    benchmark.extra_info["pixels"] = pixels


def _core_hist_weights(image: BinnedImage, boxes: F64, ref: F64) -> F64:
    return _core.bhattacharyya_weights(_core.box_histograms(image, boxes, "uniform"), ref, 20.0)


def _public_hist_weights(image: BinnedImage, boxes: F64, ref: F64) -> F64:
    return bhattacharyya_weights(box_histograms(image, boxes), ref, 20.0)


def test_histograms_weights_public(benchmark: BenchmarkFixture, case: Case) -> None:
    """The public calls: ``bhattacharyya_weights(box_histograms(image, boxes), ref)``."""
    _, image, boxes, ref, _, source = case
    _hist_group(benchmark, case)
    w = benchmark(_public_hist_weights, image, boxes, ref)
    np.testing.assert_allclose(
        w, npb.histograms_and_weights(image.bins, image.n_bins, boxes, ref), rtol=1e-8, atol=1e-300
    )
    _compare(benchmark, "public", check=source == PETS_FRAME)


def test_histograms_weights_core(benchmark: BenchmarkFixture, case: Case) -> None:
    """The core's two calls under the public ones (without their Python checks)."""
    _, image, boxes, ref, _, source = case
    _hist_group(benchmark, case)
    w = benchmark(_core_hist_weights, image, boxes, ref)
    np.testing.assert_allclose(
        w, npb.histograms_and_weights(image.bins, image.n_bins, boxes, ref), rtol=1e-8, atol=1e-300
    )
    _compare(benchmark, "core", check=source == PETS_FRAME)


def test_histograms_weights_core_fused(benchmark: BenchmarkFixture, case: Case) -> None:
    """The same weights from one private call (``_core.box_weights``, the filters' path) that
    never builds the (K, B) histogram matrix."""
    _, image, boxes, ref, _, source = case
    _hist_group(benchmark, case)
    w = benchmark(_core.box_weights, image, boxes, ref, 20.0)
    want = npb.histograms_and_weights(image.bins, image.n_bins, boxes, ref)
    np.testing.assert_allclose(w, want, rtol=1e-8, atol=1e-300)
    _compare(benchmark, "fused", check=source == PETS_FRAME)


def test_histograms_weights_public_fused(benchmark: BenchmarkFixture, case: Case) -> None:
    """The public fused call, ``box_weights(image, boxes, ref)``: the core's, with its checks."""
    _, image, boxes, ref, _, source = case
    _hist_group(benchmark, case)
    w = benchmark(box_weights, image, boxes, ref, 20.0)
    want = npb.histograms_and_weights(image.bins, image.n_bins, boxes, ref)
    np.testing.assert_allclose(w, want, rtol=1e-8, atol=1e-300)
    _compare(benchmark, "public fused", check=source == PETS_FRAME)


def test_histograms_weights_numpy(benchmark: BenchmarkFixture, case: Case) -> None:
    """NumPy's fastest formulation found (tests/reference/fused.py): a Python loop over the
    boxes with one ``np.bincount`` each, then the weights of all boxes vectorised."""
    _, image, boxes, ref, _, source = case
    _hist_group(benchmark, case)
    args = (image.bins, image.n_bins, boxes, ref)
    if len(boxes) > 2000:
        benchmark.pedantic(npb.histograms_and_weights, args=args, rounds=2, iterations=1)
    else:
        benchmark(npb.histograms_and_weights, *args)
    _compare(benchmark, "numpy", check=source == PETS_FRAME)


@pytest.mark.parametrize("size", ["frame_480", "frame_720"])
def test_hsv_bins_core(
    benchmark: BenchmarkFixture, request: pytest.FixtureRequest, size: str, frame_source: str
) -> None:
    frame = request.getfixturevalue(size)
    label_frame(benchmark, f"hsv bins {frame.shape[1]}x{frame.shape[0]}", frame_source)
    image = benchmark(_core.hsv_bins, frame)
    np.testing.assert_array_equal(image.bins, npb.hsv_bins(frame))
    _compare(benchmark, "core")


@pytest.mark.parametrize("size", ["frame_480", "frame_720"])
def test_hsv_bins_numpy(
    benchmark: BenchmarkFixture, request: pytest.FixtureRequest, size: str, frame_source: str
) -> None:
    """The same bins in NumPy (tests/reference/fused.py says why not ``cv2.cvtColor``'s)."""
    frame = request.getfixturevalue(size)
    label_frame(benchmark, f"hsv bins {frame.shape[1]}x{frame.shape[0]}", frame_source)
    bins = benchmark.pedantic(npb.hsv_bins, args=(frame,), rounds=5, iterations=1)
    np.testing.assert_array_equal(bins, _core.hsv_bins(frame).bins)
    _compare(benchmark, "numpy")


@pytest.mark.parametrize("lazy", [False, True], ids=["eager", "lazy"])
@pytest.mark.parametrize("size", ["frame_480", "frame_720"])
def test_frame_bins_and_weights_10_objects(
    benchmark: BenchmarkFixture,
    request: pytest.FixtureRequest,
    size: str,
    lazy: bool,
    frame_source: str,
) -> None:
    """A tracker's frame: full-frame bins, then the weights of 10 objects' particles.

    Eager bins every pixel first; lazy (``hsv_bins(..., lazy=True)``) bins only the tiles
    the particles' boxes read. The weights are the same.
    """
    frame = request.getfixturevalue(size)
    rows, cols = frame.shape[:2]
    w, h = (20, 50) if cols < 1000 else (60, 150)
    boxes = _boxes(np.random.default_rng(1), 10, 200, w, h, frame.shape)
    ref = box_histograms(hsv_bins(frame), boxes[:1])[0] + 1e-6
    label_frame(
        benchmark, f"frame bins + weights, 10 objects x 200 particles, {cols}x{rows}", frame_source
    )

    def one_frame() -> list[F64]:
        image = hsv_bins(frame, lazy=lazy)
        return [_core.box_weights(image, boxes[200 * k : 200 * (k + 1)], ref) for k in range(10)]

    eager = [
        _core.box_weights(hsv_bins(frame), boxes[200 * k : 200 * (k + 1)], ref) for k in range(10)
    ]
    for got, want in zip(one_frame(), eager, strict=True):
        np.testing.assert_array_equal(got, want)
    benchmark(one_frame)


@pytest.fixture(scope="module")
def weights_10k() -> F64:
    w = np.random.default_rng(2).random(10_000)
    w /= w.sum()
    return w


@pytest.mark.benchmark(group="systematic resample N=10000")
def test_resample_core(benchmark: BenchmarkFixture, weights_10k: F64) -> None:
    idx = benchmark(_core.systematic_resample, weights_10k, 0.37)
    np.testing.assert_array_equal(idx, npb.systematic_resample(weights_10k, 0.37))
    _compare(benchmark, "core")


@pytest.mark.benchmark(group="systematic resample N=10000")
def test_resample_python_api(benchmark: BenchmarkFixture, weights_10k: F64) -> None:
    """The public function with a Generator: a new offset each call, Python checks included."""
    from pftrack.particle_filter import systematic_resample

    rng = np.random.default_rng(4)
    benchmark(systematic_resample, weights_10k, rng)
    _compare(benchmark, "api")


@pytest.mark.benchmark(group="systematic resample N=10000")
def test_resample_numpy(benchmark: BenchmarkFixture, weights_10k: F64) -> None:
    benchmark(npb.systematic_resample, weights_10k, 0.37)
    _compare(benchmark, "numpy")


@pytest.mark.benchmark(group="systematic resample N=10000")
def test_resample_filterpy(benchmark: BenchmarkFixture, weights_10k: F64) -> None:
    mc = pytest.importorskip("filterpy.monte_carlo")
    benchmark(mc.systematic_resample, weights_10k)
    _compare(benchmark, "filterpy")


@pytest.mark.benchmark(group="normals N=6000")
def test_normals_core(benchmark: BenchmarkFixture) -> None:
    # sis_step's propagation noise of 10 objects x 200 particles x 3 (rng.hpp's Box-Muller)
    z = benchmark(_core.counter_normals, 3, 17, 6000)
    assert z.shape == (6000,)
    _compare(benchmark, "core")


@pytest.mark.benchmark(group="normals N=6000")
def test_normals_numpy(benchmark: BenchmarkFixture) -> None:
    gen = np.random.default_rng(3)
    benchmark(gen.standard_normal, 6000)
    _compare(benchmark, "numpy", check=False)


@pytest.fixture(scope="module")
def uniforms_10k() -> F64:
    return np.random.default_rng(5).random(10_000)


@pytest.mark.benchmark(group="stratified resample N=10000")
def test_stratified_core(benchmark: BenchmarkFixture, weights_10k: F64, uniforms_10k: F64) -> None:
    idx = benchmark(_core.stratified_resample, weights_10k, uniforms_10k)
    np.testing.assert_array_equal(idx, npb.stratified_resample(weights_10k, uniforms_10k))
    _compare(benchmark, "core")


@pytest.mark.benchmark(group="stratified resample N=10000")
def test_stratified_numpy(benchmark: BenchmarkFixture, weights_10k: F64, uniforms_10k: F64) -> None:
    benchmark(npb.stratified_resample, weights_10k, uniforms_10k)
    _compare(benchmark, "numpy")


@pytest.mark.benchmark(group="stratified resample N=10000")
def test_stratified_filterpy(benchmark: BenchmarkFixture, weights_10k: F64) -> None:
    mc = pytest.importorskip("filterpy.monte_carlo")
    benchmark(mc.stratified_resample, weights_10k)
    _compare(benchmark, "filterpy")


def test_sis_step_10x200(
    benchmark: BenchmarkFixture, frame_480: NDArray[np.uint8], frame_source: str
) -> None:
    from pftrack.particle_filter import ColourParticleFilter, FilterConfig

    label_frame(benchmark, "sis_step 10 objects x 200 particles, 20x50, 480x360", frame_source)
    image = hsv_bins(frame_480)
    rng = np.random.default_rng(3)
    boxes = _boxes(rng, 10, 1, 20, 50, frame_480.shape)
    filters = [
        ColourParticleFilter(
            b, box_histograms(image, [b])[0] + 1e-6, FilterConfig(n_particles=200), rng=k
        )
        for k, b in enumerate(boxes)
    ]

    def frame_step() -> None:
        for f in filters:
            f.step(image)

    benchmark(frame_step)


def _large_box_filters(
    image: BinnedImage, min_samples: int, black: bool
) -> list[tuple[F64, F64, F64]]:
    """15 objects x 200 particles with 100x250 base boxes on a 1920x1080 frame, as the arrays
    sis_step_batch steps; on a black frame after 25 steps, once the particles, without colour
    evidence, have spread and grown (the state of a track on a frame that tells nothing)."""
    rng = np.random.default_rng(4)
    out = []
    for k in range(15):
        c = (120 + 120 * k, 540 + rng.normal(0, 40))
        p = np.empty((200, 6))
        p[:, :2] = c + rng.normal(0, 4, (200, 2))
        p[:, 2] = 1.0
        p[:, 3:] = p[:, :3]
        out.append((p, np.full(200, 1 / 200), np.array([[*c, 1.0], [*c, 1.0]])))
    if black:
        for s in range(25):
            _sis_batch(image, out, min_samples, s)
    return out


def _sis_batch(
    image: BinnedImage, filters: list[tuple[F64, F64, F64]], min_samples: int, step: int
) -> None:
    k = len(filters)
    ref = np.full(image.n_bins, 1.0 / image.n_bins)
    _core.sis_step_batch(
        [f[0] for f in filters], [f[1] for f in filters], [f[2] for f in filters], image,
        [ref] * k, np.full(k, 100.0), np.full(k, 250.0), np.full(3, 2.0), np.full(3, -1.0),
        np.array([6.0, 6.0, 0.03]), 0.2, 3.0, False, 20.0, "uniform", True, list(range(k)),
        [step] * k, float(min_samples),
    )  # fmt: skip


@pytest.mark.parametrize("min_samples", [0, 2048], ids=["every pixel", "lattice 2048"])
@pytest.mark.parametrize("scene", ["PETS09 upscaled", "black"])
def test_sis_batch_1080p_large_boxes(
    benchmark: BenchmarkFixture,
    frame_480: NDArray[np.uint8],
    frame_source: str,
    scene: str,
    min_samples: int,
) -> None:
    """FilterConfig.min_samples: one step of 15 objects x 200 particles, 100x250 boxes, at
    1920x1080 (the PETS09 frame upscaled, or black), counting every pixel or on the lattice.

    The lattice's ``extra_info["x_every_pixel"]`` is the ratio of the medians, the README's
    kernel table's; it must reach :data:`FLOORS`' on a black or PETS09 frame."""
    import cv2

    if scene == "black":
        frame = np.zeros((1080, 1920, 3), np.uint8)
    else:
        frame = cv2.resize(frame_480, (1920, 1080), interpolation=cv2.INTER_LINEAR)
    image = hsv_bins(frame)
    start = _large_box_filters(image, min_samples, scene == "black")
    group = f"sis_step_batch 15x200, 100x250 boxes, 1920x1080 {scene}"
    if scene == "black":
        benchmark.group = group
    else:
        label_frame(benchmark, group, frame_source)

    def setup() -> tuple[tuple[list[tuple[F64, F64, F64]]], dict[str, object]]:
        return ([tuple(a.copy() for a in f) for f in start],), {}  # type: ignore[misc]

    benchmark.pedantic(
        lambda filters: _sis_batch(image, filters, min_samples, 25),
        setup=setup, rounds=20, iterations=1,
    )  # fmt: skip
    role = "lattice" if min_samples else "every_pixel"
    _compare(benchmark, role, check=scene == "black" or frame_source == PETS_FRAME)
