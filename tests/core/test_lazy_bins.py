"""Lazy bins (``hsv_bins(..., lazy=True)``): each tile binned when a reader first needs it.

Every reader must see the bins the eager image holds, bit for bit, whatever it reads first and
in whatever order: box histograms and weights (every kernel and counting path), the filter
steps, ``.bins``, ``mask_bins`` and copies. The bins themselves are held to the NumPy reference
(tests/reference/kernels.py).
"""

from __future__ import annotations

import copy
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pftrack import _core
from pftrack.particle_filter import Ar2Model, HsvBinning, hsv_bins
from pftrack.particle_filter.rjmcmc import RJMCMCConfig, RJMCMCFilter
from tests.reference import kernels as ref

KERNELS = ("uniform", "epanechnikov")
METHODS = ("auto", "direct", "integral")
TILE = (16, 32)  # rows, cols of a tile


def _frame(rng: np.random.Generator, rows: int, cols: int) -> np.ndarray:
    """A blocky random frame (runs of equal colours, as in real frames) with noisy pixels."""
    coarse = rng.integers(0, 256, (rows // 4 + 1, cols // 4 + 1, 3), dtype=np.uint8)
    frame = np.repeat(np.repeat(coarse, 4, axis=0), 4, axis=1)[:rows, :cols].copy()
    noisy = rng.random((rows, cols)) < 0.3
    frame[noisy] = rng.integers(0, 256, (int(noisy.sum()), 3), dtype=np.uint8)
    return frame


def _tiles(rows: int, cols: int) -> int:
    return -(-rows // TILE[0]) * -(-cols // TILE[1])


def _boxes(rng: np.random.Generator, rows: int, cols: int, n: int) -> np.ndarray:
    """Boxes anywhere: inside, partly and wholly outside, empty, tiny and larger than the frame."""
    b = np.empty((n, 4))
    b[:, 0] = rng.uniform(-0.3 * cols, 1.3 * cols, n)
    b[:, 1] = rng.uniform(-0.3 * rows, 1.3 * rows, n)
    size = rng.choice([0.0, 0.7, 3.0, 20.0, 60.0, 3.0 * max(rows, cols)], (n, 2))
    b[:, 2:] = size * rng.uniform(0.8, 1.25, (n, 2))
    return b


def _cloud(rng: np.random.Generator, centre: tuple[float, float], n: int) -> np.ndarray:
    """Overlapping boxes of one object: grouped into integral histograms by 'auto'."""
    b = np.empty((n, 4))
    b[:, :2] = np.asarray(centre) + rng.normal(0.0, 4.0, (n, 2))
    b[:, 2:] = np.array([14.0, 30.0]) * rng.uniform(0.8, 1.25, (n, 1))
    return b


@settings(max_examples=40, deadline=None)
@given(
    st.integers(0, 2**32 - 1),
    st.integers(1, 90),
    st.integers(1, 130),
    st.booleans(),
    st.lists(st.tuples(st.sampled_from(KERNELS), st.sampled_from(METHODS), st.integers(1, 6)),
             min_size=1, max_size=6),
)  # fmt: skip
def test_lazy_reads_equal_eager_in_any_order(seed, rows, cols, masked, calls):
    rng = np.random.default_rng(seed)
    frame = _frame(rng, rows, cols)
    mask = (rng.random((rows, cols)) < 0.7).astype(np.uint8) if masked else None
    eager = hsv_bins(frame, mask)
    lazy = hsv_bins(frame, mask, lazy=True)
    r = rng.random(eager.n_bins) + 0.05
    for kernel, method, n in calls:  # partial ensures, one call after another
        b = _boxes(rng, rows, cols, n)
        if method == "direct" or kernel == "epanechnikov":
            b = np.vstack([b, _cloud(rng, (cols / 2, rows / 2), 3)])
        np.testing.assert_array_equal(
            _core.box_histograms(lazy, b, kernel, method),
            _core.box_histograms(eager, b, kernel, method),
        )
        np.testing.assert_array_equal(
            _core.box_weights(lazy, b, r, 20.0, kernel, method),
            _core.box_weights(eager, b, r, 20.0, kernel, method),
        )
    np.testing.assert_array_equal(lazy.bins, eager.bins)
    assert lazy.tiles_pending == 0
    want = ref.hsv_bins(frame, mask)
    np.testing.assert_array_equal(lazy.bins, want)


def test_lazy_matches_numpy_reference_histograms(rng):
    frame = _frame(rng, 120, 160)
    lazy = hsv_bins(frame, lazy=True)
    bins = ref.hsv_bins(frame, None)  # the reference binning, of every pixel
    boxes = np.vstack([_boxes(rng, 120, 160, 12), _cloud(rng, (50.0, 40.0), 40)])
    for kernel in KERNELS:
        got = _core.box_histograms(lazy, boxes, kernel, "auto")
        want = ref.box_histograms(bins, lazy.n_bins, boxes, kernel)
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-15)
    assert lazy.tiles_pending > 0  # the boxes read part of the frame only


def test_lazy_bins_only_the_tiles_read(rng):
    frame = _frame(rng, 100, 200)
    lazy = hsv_bins(frame, lazy=True)
    total = _tiles(100, 200)
    assert lazy.tiles_pending == total
    # outside the frame and empty: nothing to bin
    _core.box_histograms(lazy, np.array([[-50.0, -50.0, 20.0, 20.0], [50.0, 50.0, 0.0, 0.0]]))
    assert lazy.tiles_pending == total
    # pixels x 40..59, y 20..39: tile columns 1 (32..63), tile rows 1 and 2 (16..47)
    _core.box_histograms(lazy, np.array([[50.0, 30.0, 20.0, 20.0]]), "uniform", "direct")
    assert lazy.tiles_pending == total - 2
    _core.box_histograms(lazy, np.array([[50.0, 30.0, 10.0, 10.0]]))  # the same tiles again
    assert lazy.tiles_pending == total - 2
    np.testing.assert_array_equal(lazy.bins, hsv_bins(frame).bins)
    assert lazy.tiles_pending == 0
    assert hsv_bins(frame).tiles_pending == 0


def test_lazy_is_its_own_copy_of_the_frame(rng):
    frame = _frame(rng, 60, 80)
    want = hsv_bins(frame).bins.copy()
    lazy = hsv_bins(frame, lazy=True)
    frame[:] = 0  # the caller reuses its buffer before any tile is read
    np.testing.assert_array_equal(lazy.bins, want)


def test_copies_and_masked_bins_of_a_lazy_image(rng):
    frame = _frame(rng, 70, 90)
    eager = hsv_bins(frame)
    lazy = hsv_bins(frame, lazy=True)
    _core.box_histograms(lazy, np.array([[20.0, 20.0, 10.0, 10.0]]))
    mask = (rng.random((70, 90)) < 0.5).astype(np.uint8)
    np.testing.assert_array_equal(
        _core.mask_bins(lazy, mask).bins, _core.mask_bins(eager, mask).bins
    )
    # the RJ-MCMC tracker's prepared frame keeps a copy of the image: a copy of a lazy image
    # that nothing read yet holds every bin
    lazy2 = hsv_bins(frame, lazy=True)
    cands = np.array([[20.0, 20.0, 10.0, 16.0], [60.0, 40.0, 12.0, 20.0]])
    full = np.full((70, 90), 255, np.uint8)
    states = np.array([[20.0, 20.0, 1.0, 20.0, 20.0, 1.0], [60.0, 40.0, 1.0, 60.0, 40.0, 1.0]])
    got = []
    for image in (eager, lazy2):
        t = _core.RJMCMCTracker(n_samples=50, burn_in=10)
        t.prepare(image, full, cands)
        refs = [s["ref"] for s in t.slots()]
        got.append((refs, t.log_target(np.array([0, 1], np.int32), states)))
    for a, b in zip(got[0][0], got[1][0], strict=True):
        np.testing.assert_array_equal(a, b)
    assert got[0][1] == got[1][1]


def test_rjmcmc_steps_on_lazy_bins_equal_eager(rng):
    frame = _frame(rng, 60, 120)
    mask = np.full((60, 120), 255, np.uint8)
    cands = np.array([[30.0, 24.0, 12.0, 20.0], [90.0, 30.0, 14.0, 22.0]])
    outs = []
    for lazy in (False, True):
        f = RJMCMCFilter(RJMCMCConfig(n_samples=60, burn_in=10), rng=3)
        out = [f.step(hsv_bins(frame, lazy=lazy), mask, cands) for _ in range(2)]
        outs.append([(tr.id, *tr.box_cxcywh) for step in out for tr in step])
    assert outs[0] == outs[1]


@pytest.mark.parametrize("kernel", KERNELS)
@pytest.mark.parametrize("sampler", ["sis", "sis_batch", "mh"])
def test_filter_steps_on_lazy_bins_equal_eager(rng, kernel, sampler):
    frame = _frame(rng, 120, 160)
    eager = hsv_bins(frame)
    model = Ar2Model(sigma_xy=3.0, sigma_s=0.05)
    objs = []
    for i in range(4):
        cx, cy = 20.0 + 40 * i, 30.0 + 20 * i
        p = np.zeros((50, 6))
        p[:, 0], p[:, 1] = cx + rng.normal(0, 3, 50), cy + rng.normal(0, 3, 50)
        p[:, 2] = rng.uniform(0.9, 1.1, 50)
        p[:, 3:] = p[:, :3]
        ref_hist = _core.box_histograms(eager, np.array([[cx, cy, 16.0, 30.0]]))[0] + 1e-3
        objs.append([p, np.full(50, 1 / 50), np.tile([cx, cy, 1.0], (2, 1)), ref_hist])
    args = (model.a, model.b, model.sigma, model.s_min, model.s_max, False, 20.0, kernel, True)
    results = []
    for image in (eager, hsv_bins(frame, lazy=True)):
        os_ = copy.deepcopy(objs)
        if sampler == "sis_batch":
            out = _core.sis_step_batch(
                [o[0] for o in os_], [o[1] for o in os_], [o[2] for o in os_], image,
                [o[3] for o in os_], np.full(4, 16.0), np.full(4, 30.0), *args,
                [7 + i for i in range(4)], [3] * 4,
            )  # fmt: skip
            rows = [out]
        else:
            step = _core.sis_step if sampler == "sis" else _core.mh_step
            rows = []
            for i, o in enumerate(os_):
                r = step(o[0], o[1], o[2], image, o[3], 16.0, 30.0, *args, 7 + i, 3)
                rows.append(np.array([*r["mean"], r["ess"]]))
        results.append((os_, rows))
        if image is not eager:
            assert image.tiles_pending > 0  # the particles read part of the frame only
    (a_objs, a_rows), (b_objs, b_rows) = results
    for oa, ob in zip(a_objs, b_objs, strict=True):
        for xa, xb in zip(oa[:3], ob[:3], strict=True):
            np.testing.assert_array_equal(xa, xb)
    for ra, rb in zip(a_rows, b_rows, strict=True):
        np.testing.assert_array_equal(ra, rb)


def test_lazy_readers_from_threads_equal_serial(rng):
    frame = _frame(rng, 240, 320)
    eager = hsv_bins(frame)
    r = rng.random(eager.n_bins) + 0.05
    batches = [np.vstack([_boxes(rng, 240, 320, 30), _cloud(rng, (160.0, 120.0), 60)])
               for _ in range(16)]  # fmt: skip
    want = [_core.box_weights(eager, b, r) for b in batches]
    for _ in range(3):
        lazy = hsv_bins(frame, lazy=True)
        with ThreadPoolExecutor(4) as pool:
            got = list(pool.map(lambda b: _core.box_weights(lazy, b, r), batches))  # noqa: B023
        for g, w in zip(got, want, strict=True):
            np.testing.assert_array_equal(g, w)
        np.testing.assert_array_equal(lazy.bins, eager.bins)


def test_lazy_with_other_binnings(rng):
    frame = _frame(rng, 50, 70)
    binning = HsvBinning(n_h=6, n_s=4, n_v=3, s_min=0.2, v_min=0.3)
    lazy = hsv_bins(frame, binning=binning, lazy=True)
    assert lazy.n_bins == 27
    np.testing.assert_array_equal(lazy.bins, ref.hsv_bins(frame, None, 6, 4, 3, 0.2, 0.3))


def test_lazy_must_be_a_bool(rng):
    with pytest.raises(TypeError, match="lazy must be a bool"):
        hsv_bins(_frame(rng, 8, 8), lazy="yes")  # type: ignore[arg-type]


def test_lazy_bins_of_strided_views_and_masks(rng):
    frame = _frame(rng, 90, 140)
    mask = (rng.random((90, 140)) < 0.6).astype(np.uint8)
    view, mview = frame[5:80, 10:120], mask[5:80, 10:120]  # rows strided, pixels packed
    flipped = frame[:, ::-1]  # pixels not packed: copied once by the wrapper
    for f, m in ((view, None), (view, mview), (flipped, None), (flipped, mask)):
        lazy = hsv_bins(f, m, lazy=True)
        b = _boxes(rng, f.shape[0], f.shape[1], 8)
        got = _core.box_histograms(lazy, b)
        np.testing.assert_array_equal(got, _core.box_histograms(hsv_bins(f, m), b))
        want = ref.box_histograms(ref.hsv_bins(f, m), lazy.n_bins, b)
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-15)
        np.testing.assert_array_equal(lazy.bins, ref.hsv_bins(f, m))
