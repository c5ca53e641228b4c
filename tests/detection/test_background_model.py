"""The fused C++ pass (BackgroundModel, mask_bins) against the NumPy reference."""

from __future__ import annotations

import pickle
import threading

import numpy as np
import pytest

from pftrack import _core
from tests.reference.detection import BackgroundReference, hsv_bin_reference


def random_scene(rng: np.random.Generator, shape=(48, 64), steps=6) -> list[np.ndarray]:
    """A noisy static background with bright/dark/shadowed patches that move about."""
    base = rng.integers(20, 236, size=(*shape, 3), dtype=np.int32)
    frames = []
    for k in range(steps):
        f = base + rng.integers(-6, 7, size=base.shape)
        y, x = 5 + 3 * k, 4 + 5 * k
        f[y : y + 15, x : x + 10] = rng.integers(0, 256, size=3)  # an object
        f[y + 20 : y + 28, x : x + 12] = (f[y + 20 : y + 28, x : x + 12] * 0.7).astype(np.int32)
        frames.append(np.clip(f, 0, 255).astype(np.uint8))
    return frames


@pytest.fixture(params=[True, False], ids=["avx2-rows", "portable-rows"])
def avx2_rows(request: pytest.FixtureRequest):
    """Whether apply may take its hand-written AVX2 row pass (stop 71): each test runs twice.

    Without bins and without a hold row, on a CPU with AVX2, apply's rows go through
    `background_row_fused_avx2`; with the hook off, through the portable loops (the ones every
    other CPU runs). Both are held to the same NumPy reference.
    """
    before = _core._set_avx2(request.param)
    yield request.param
    _core._set_avx2(before)


def test_lut_bins_equal_hsv_bins_on_every_colour():
    v = np.arange(1 << 24, dtype=np.uint32)
    img = (
        np.stack([v & 255, (v >> 8) & 255, v >> 16], axis=-1)
        .astype(np.uint8)
        .reshape(4096, 4096, 3)
    )
    for kw in ({}, {"n_h": 8, "n_s": 4, "n_v": 3, "s_min": 0.25, "v_min": 0.05}):
        m = _core.BackgroundModel(**kw)
        bins, mask = m.apply(img)
        np.testing.assert_array_equal(bins.bins, _core.hsv_bins(img, **kw).bins)
        # both share the vectorised table indices: the NumPy reference on every colour too
        for rows in range(0, 4096, 512):
            np.testing.assert_array_equal(
                bins.bins[rows : rows + 512], hsv_bin_reference(img[rows : rows + 512], **kw)
            )
        assert bins.n_bins == _core.hsv_bins(img[:1, :1], **kw).n_bins
        assert not mask.any()  # the first frame initialises the background


def test_full_frame_bins_of_every_colour_one_by_one():
    # Four pixels a row: every pixel goes through the table look-ups' one-by-one loop, which
    # wider rows use only for their last width % 8 pixels (test above: 8 at a time).
    v = np.arange(1 << 24, dtype=np.uint32)
    img = np.stack([v & 255, (v >> 8) & 255, v >> 16], axis=-1).astype(np.uint8)
    kw = {"n_h": 8, "n_s": 4, "n_v": 3, "s_min": 0.25, "v_min": 0.05}
    bins = _core.hsv_bins(img.reshape(-1, 4, 3), **kw).bins.reshape(-1)
    for start in range(0, 1 << 24, 1 << 21):
        np.testing.assert_array_equal(
            bins[start : start + (1 << 21)],
            hsv_bin_reference(img[None, start : start + (1 << 21)], **kw)[0],
        )


@pytest.mark.parametrize("lazy", [False, True])
def test_full_frame_bins_at_every_row_tail(lazy):
    # Rows of 1-75 pixels: 8 at a time, then the last 0-7 one by one, against NumPy. Lazy, a
    # box in the last 32-column tile is read first, so that tile is binned alone (a rectangle
    # of 1-32 columns at x 32 or 64), then the rest by `.bins`.
    rng = np.random.default_rng(11)
    for cols in range(1, 76):
        img = rng.integers(0, 256, size=(5, cols, 3), dtype=np.uint8)
        img[0, : cols // 2] = rng.integers(0, 256, size=3)  # a flat run
        img[1] = img[1].min(axis=-1, keepdims=True)  # grey pixels
        want = hsv_bin_reference(img)
        got = _core.hsv_bins(img, lazy=lazy)
        if lazy:
            x0 = (cols - 1) // 32 * 32
            _core.box_histograms(got, np.array([[(x0 + cols) / 2, 2.5, cols - x0, 5]]))
            assert got.tiles_pending == (cols - 1) // 32
        np.testing.assert_array_equal(got.bins, want)


def test_hsv_reference_matches_core_on_random_pixels():
    img = np.random.default_rng(3).integers(0, 256, size=(64, 64, 3), dtype=np.uint8)
    np.testing.assert_array_equal(hsv_bin_reference(img), _core.hsv_bins(img).bins)


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize(
    "kw",
    [
        {},
        {
            "alpha": 0.3,
            "alpha_fg": 0.0,
            "k_noise": 6.0,
            "t_min": 8.0,
            "low_ratio": 0.3,
            "n_learn": 3,
        },
        {"shadow_lo": 1.0, "t_max": 25.0},
    ],
)
def test_background_model_matches_reference(seed, kw):
    rng = np.random.default_rng(seed)
    model, ref = _core.BackgroundModel(**kw), BackgroundReference(**kw)
    n_fg = n_shadow = 0
    for frame in random_scene(rng):
        bins, mask = model.apply(frame)
        rbins, rmask = ref.apply(frame)
        np.testing.assert_array_equal(bins.bins, rbins)
        np.testing.assert_array_equal(mask, rmask)
        np.testing.assert_array_equal(model.background, ref.background)
        assert model.threshold == pytest.approx(ref.threshold, abs=1e-12)
        n_fg += int((mask == 255).sum())
        n_shadow += int((mask == 127).sum())
    assert n_fg > 0  # the moving patch was foreground at some point
    assert n_shadow > 0 or kw.get("shadow_lo") == 1.0  # and shadows marked 127, when tested
    assert model.frame_count == 6


@pytest.mark.parametrize("bins", [True, False])
def test_background_model_matches_reference_at_odd_widths(bins, avx2_rows):
    # the vectorised row loops (mask and shadow test included) and their scalar remainders
    for cols in (7, 61, 133):
        rng = np.random.default_rng(cols)
        model, ref = _core.BackgroundModel(n_learn=2), BackgroundReference(n_learn=2)
        n_shadow = 0
        for k, frame in enumerate(random_scene(rng, shape=(40, cols))):
            _, mask = model.apply(frame, bins=bins)
            _, rmask = ref.apply(frame)
            np.testing.assert_array_equal(mask, rmask)
            if k > 0:  # the histogram of |frame - background| (eight pixels at a time + rest)
                np.testing.assert_array_equal(model.difference_histogram, ref.hist)
            np.testing.assert_array_equal(model.background, ref.background)
            assert model.threshold == pytest.approx(ref.threshold, abs=1e-12)
            n_shadow += int((mask == 127).sum())
        assert n_shadow > 0 or cols < 30  # the shadowed patch was marked, where it fits


@pytest.mark.parametrize("cols", [1, 15, 16, 17, 31, 32, 33, 48, 61, 480])
@pytest.mark.parametrize(
    "kw", [{"n_learn": 2}, {"n_learn": 0, "alpha_fg": 0.0, "low_ratio": 0.3, "t_min": 12.0}]
)
def test_rows_without_bins_or_hold_match_the_reference(cols, kw, avx2_rows):
    # apply(bins=False) without a hold row: the AVX2 row pass (16 pixels a step: the byte
    # shuffles of B, G and R, d_prev in bytes, the floats in registers) and its portable loops
    # for the row's last cols % 16 pixels, or the portable loops alone; every output and the
    # previous frame it keeps against the NumPy reference, bit for bit
    rng = np.random.default_rng(cols)
    model, ref = _core.BackgroundModel(**kw), BackgroundReference(**kw)
    low_ratio = kw.get("low_ratio", 0.5)
    n_fg = n_shadow = n_moved = 0
    last: tuple[np.ndarray, np.ndarray, float] | None = None  # background, frame, threshold
    for frame in random_scene(rng, shape=(23, cols), steps=8):
        none, mask = model.apply(frame, bins=False)
        _, rmask = ref.apply(frame)
        assert none is None
        np.testing.assert_array_equal(mask, rmask)
        np.testing.assert_array_equal(model.background, ref.background)
        assert model.__getstate__()[4] == frame.tobytes()  # the previous frame, as given
        if last is not None:
            np.testing.assert_array_equal(model.difference_histogram, ref.hist)
            # candidates by the frame difference alone (hysteresis: d_prev > T, d_bg in
            # (low_ratio T, T]), which the row pass decides from the previous frame's bytes
            background, previous, threshold = last
            d_bg = np.abs(frame.astype(np.float32) - background).max(axis=2)
            d_prev = np.abs(frame.astype(np.int32) - previous).max(axis=2)
            t, t_low = np.float32(threshold), np.float32(low_ratio * threshold)
            n_moved += int(((d_prev > t) & (d_bg > t_low) & (d_bg <= t)).sum())
        assert model.threshold == pytest.approx(ref.threshold, abs=1e-12)
        last = ref.background.copy(), frame.astype(np.int32), model.threshold
        n_fg += int((mask == 255).sum())
        n_shadow += int((mask == 127).sum())
    assert n_fg > 0 or cols == 1  # the moving patches start at column 4
    assert n_shadow > 0 or cols < 30
    assert n_moved > 0 or cols < 30


def _difference_counts(frame: np.ndarray, background: np.ndarray) -> np.ndarray:
    """NumPy's histogram of floor(max_c |frame_c - background_c|), clipped to 255."""
    d = np.abs(frame.astype(np.float32) - background).max(axis=2)
    return np.bincount(np.minimum(d.astype(np.int32), 255).ravel(), minlength=256)


def _difference_frames(cols: int) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """(name, frame, background) pairs whose floor(d_bg) are set value by value."""
    rng = np.random.default_rng(cols)
    rows = 37
    zero = np.zeros((rows, cols, 3), np.float32)
    flat = np.arange(rows * cols).reshape(rows, cols)

    def frame_of(d: np.ndarray) -> np.ndarray:
        f = np.zeros((rows, cols, 3), np.uint8)
        f[..., 1] = d  # d_bg is the largest channel's difference: G alone against 0
        return f

    small = rng.integers(0, 8, size=(rows, cols))
    mixed = np.where(rng.random((rows, cols)) < 0.05, rng.integers(8, 256, (rows, cols)), small)
    lanes = (flat * 7 + flat // 256) % 256  # every value at every position of a 32-value step
    quarter = np.full((rows, cols, 3), 0.25, np.float32)  # d = v - 0.25: floor v - 1 (0 at 0)
    return [
        # one value everywhere: a lane's 4-bit counter reaches 15 on every 15-step block
        *[(f"all {v}", frame_of(np.full((rows, cols), v)), zero) for v in (0, 1, 6, 7, 8, 255)],
        ("small", frame_of(small), zero),
        ("mixed", frame_of(mixed), zero),
        ("every value in every lane", frame_of(lanes), zero),
        ("fractional", frame_of(mixed), quarter),
    ]


@pytest.mark.parametrize("cols", [1, 31, 32, 33, 479, 480, 481, 512, 961, 1000])
def test_difference_histogram_counts_every_value(cols, avx2_rows):
    # apply's histogram of floor(d_bg): with AVX2, 32 values a step, values 0..7 in 4-bit
    # counters summed out every 15 steps (rows of 481 and more take two blocks or more, 961 and
    # 1000 three), the others one by one, a row's last cols % 32 by the scalar loop; without,
    # the scalar loop alone. Against NumPy's bincount, with and without bins (the fused row
    # pass and the portable loops)
    for name, frame, background in _difference_frames(cols):
        for bins in (False, True):
            model = _core.BackgroundModel()
            model.set_background(background)
            model.apply(frame, bins=bins)
            want = _difference_counts(frame, background)
            got = np.asarray(model.difference_histogram)
            assert got.sum() == frame.shape[0] * cols, name
            np.testing.assert_array_equal(got, want, err_msg=f"{name}, bins={bins}")


def test_avx2_rows_hook_gives_the_same_pass_on_a_large_frame():
    # a 360 x 487 scene (30 steps of 16 pixels and a tail of 7 a row): the two row passes
    # give the same masks, backgrounds, histograms and thresholds frame by frame
    rng = np.random.default_rng(71)
    frames = random_scene(rng, shape=(360, 487), steps=6)
    outs = []
    before = _core._set_avx2(False)
    try:
        for allowed in (True, False):
            assert _core._set_avx2(allowed) is (not allowed)  # returns the previous value
            model = _core.BackgroundModel(n_learn=2)
            out = []
            for f in frames:
                _, mask = model.apply(f, bins=False)
                out.append((mask, model.background, model.difference_histogram, model.threshold))
            outs.append(out)
    finally:
        _core._set_avx2(before)
    for (m1, b1, h1, t1), (m2, b2, h2, t2) in zip(*outs, strict=True):
        np.testing.assert_array_equal(m1, m2)
        np.testing.assert_array_equal(b1, b2)
        np.testing.assert_array_equal(h1, h2)
        assert t1 == t2
    assert any((o[0] == 255).any() for o in outs[0])


@pytest.mark.parametrize("cols", [7, 61, 133])
def test_held_candidates_are_not_learnt(cols):
    # hold: the candidates under it keep their background (rate 0, not alpha_fg); the other
    # pixels under it are learnt as usual; the reference bit for bit
    rng = np.random.default_rng(cols)
    kw = {"n_learn": 2, "alpha_fg": 0.2}
    model, ref = _core.BackgroundModel(**kw), BackgroundReference(**kw)
    hold = np.zeros((40, cols), np.uint8)
    hold[5:30, : cols // 2 + 1] = 1
    held = 0
    for frame in random_scene(rng, shape=(40, cols)):
        before = model.background
        _, mask = model.apply(frame, bins=False, hold=hold)
        _, rmask = ref.apply(frame, hold=hold)
        np.testing.assert_array_equal(mask, rmask)
        np.testing.assert_array_equal(model.background, ref.background)
        if before is not None and model.frame_count > 2:
            kept = (mask != 0) & (hold != 0)
            np.testing.assert_array_equal(model.background[kept], before[kept])
            held += int(kept.sum())
    assert held > 0 or cols < 30


def test_hold_of_the_wrong_shape_or_type_is_refused():
    model = _core.BackgroundModel()
    frame = np.zeros((10, 12, 3), np.uint8)
    model.apply(frame)
    with pytest.raises(ValueError, match="mask must have the frame's"):
        model.apply(frame, hold=np.zeros((10, 11), np.uint8))
    with pytest.raises(TypeError, match="mask dtype is float64"):
        model.apply(frame, hold=np.zeros((10, 12)))


@pytest.mark.parametrize("bins", [True, False])
@pytest.mark.parametrize("cols", [32, 64, 65, 96 + 7])
def test_shadow_test_skipped_only_in_chunks_without_candidates(bins, cols, avx2_rows):
    # The row is scanned in chunks of 16 pixels (kCandidateChunk; 32 before stop 70) and the
    # shadow test runs only in chunks with a candidate: a lone foreground or shadow pixel at
    # either end of a chunk, or in the scalar tail, is marked as the reference marks it, and
    # the chunks without any are 0. A still, noiseless background: most chunks have no
    # candidate.
    bg = np.full((8, cols, 3), (90, 110, 130), np.uint8)
    model = _core.BackgroundModel(n_learn=0, t_min=20.0, t_max=20.0)
    ref = BackgroundReference(n_learn=0, t_min=20.0, t_max=20.0)
    model.apply(bg, bins=bins)
    ref.apply(bg)
    for step in range(3):
        f = bg.copy()
        for x in (0, 15, 16, 31, 32, 63, 64, cols - 1):  # chunk ends, and the last pixel
            if x < cols:
                f[x % 8, x] = 220  # foreground
                f[(x + 3 + step) % 8, x] = (54, 66, 78)  # a shadow: 0.6 times, same colour
        _, mask = model.apply(f, bins=bins)
        _, rmask = ref.apply(f)
        np.testing.assert_array_equal(mask, rmask)
        np.testing.assert_array_equal(model.background, ref.background)
        assert (mask == 255).any() and (mask == 127).any()
        assert (mask != 0).sum() <= 16  # only the marked pixels


def test_apply_without_bins_is_the_same_pass():
    # bins=False (the built-in detector: it bins only its foreground) changes nothing else
    frames = random_scene(np.random.default_rng(3), shape=(37, 61), steps=5)
    with_bins, without = _core.BackgroundModel(n_learn=2), _core.BackgroundModel(n_learn=2)
    for frame in frames:
        bins, mask = with_bins.apply(frame)
        none, same = without.apply(frame, bins=False)
        assert none is None
        np.testing.assert_array_equal(same, mask)
        np.testing.assert_array_equal(without.background, with_bins.background)
        assert without.threshold == with_bins.threshold
        # the foreground's own bins, binned afterwards, are the fused pass's
        np.testing.assert_array_equal(
            _core.hsv_bins(frame, mask).bins, _core.mask_bins(bins, mask).bins
        )


@pytest.mark.parametrize("hold", [False, True])
def test_next_background_buffer_across_reset_restore_and_the_other_calls(hold):
    # apply writes the next frame's background into a second buffer and swaps it in (stop 70):
    # whatever reads or changes the background between frames (blend, scale, set_background,
    # a restored state, a reset onto another size) acts on the current one, as in the
    # reference, which updates one array in place
    rng = np.random.default_rng(70)
    kw = {"n_learn": 2, "alpha_fg": 0.2}
    model, ref = _core.BackgroundModel(**kw), BackgroundReference(**kw)

    def step(frame: np.ndarray) -> None:
        h = np.zeros(frame.shape[:2], np.uint8)
        if hold:
            h[: frame.shape[0] // 2] = 1
        _, mask = model.apply(frame, bins=False, hold=h if hold else None)
        _, rmask = ref.apply(frame, hold=h if hold else None)
        np.testing.assert_array_equal(mask, rmask)
        np.testing.assert_array_equal(model.background, ref.background)

    frames = random_scene(rng, shape=(24, 37), steps=6)
    for f in frames[:3]:
        step(f)
    blend = np.zeros(frames[0].shape[:2], np.uint8)
    blend[2:9, 3:20] = 1
    model.blend(frames[3], blend, 0.25)
    ref.background[blend != 0] += np.float32(0.25) * (
        frames[3][blend != 0].astype(np.float32) - ref.background[blend != 0]
    )
    np.testing.assert_array_equal(model.background, ref.background)
    step(frames[3])
    model = pickle.loads(pickle.dumps(model))  # a restored model has no second buffer yet
    step(frames[4])
    model.set_background(ref.background)  # the same values: the previous frame becomes their
    ref.previous = np.clip(ref.background + 0.5, 0, 255).astype(np.uint8)  # rounding, and
    ref.threshold = ref.bounds()[0]  # the threshold starts again from t_min
    step(frames[5])
    model.reset()  # then a video of another size: both buffers follow it
    ref = BackgroundReference(**kw)
    for f in random_scene(rng, shape=(19, 53), steps=4):
        step(f)


def test_selective_update_and_shadow_are_not_learnt():
    bg = np.full((20, 20, 3), 100, np.uint8)
    m = _core.BackgroundModel(alpha=0.5, alpha_fg=0.0, n_learn=0, t_min=20.0, t_max=20.0)
    m.apply(bg)
    f = bg.copy()
    f[:5, :5] = 200  # foreground: background stays 100 there
    f[10:15, 10:15] = 70  # a shadow: darker, same chromaticity -> background, not learnt
    f[16:, 16:] = 110  # small change below threshold -> learnt at alpha
    _, mask = m.apply(f)
    # MOG2's convention: 255 foreground, 127 shadow, 0 background
    assert (mask[:5, :5] == 255).all() and (mask == 255).sum() == 25
    assert (mask[10:15, 10:15] == 127).all() and (mask == 127).sum() == 25
    b = m.background
    assert (b[:5, :5] == 100).all() and (b[10:15, 10:15] == 100).all()
    assert (b[16:, 16:] == 105).all()


def test_set_background_and_reset():
    m = _core.BackgroundModel(t_min=10.0, t_max=10.0)
    m.set_background(np.full((8, 9, 3), 50.0, np.float32))
    assert m.shape == (8, 9) and m.initialized
    _, mask = m.apply(np.full((8, 9, 3), 90, np.uint8))
    assert (mask == 255).all()
    m.reset()
    assert m.background is None and m.shape is None and not m.initialized
    _, mask = m.apply(np.zeros((4, 4, 3), np.uint8))  # a new size is fine after reset
    assert not mask.any()


def test_mask_bins():
    rng = np.random.default_rng(5)
    img = rng.integers(0, 256, size=(30, 40, 3), dtype=np.uint8)
    binned = _core.hsv_bins(img)
    mask = (rng.random((30, 40)) > 0.5).astype(np.uint8)
    out = _core.mask_bins(binned, mask)
    np.testing.assert_array_equal(out.bins, np.where(mask > 0, binned.bins, -1))
    np.testing.assert_array_equal(out.bins, _core.hsv_bins(img, mask).bins)
    np.testing.assert_array_equal(_core.mask_bins(binned, mask > 0).bins, out.bins)  # bool mask
    wide = np.zeros((30, 80), np.uint8)
    wide[:, :40] = mask  # a view with a row stride of 80
    np.testing.assert_array_equal(_core.mask_bins(binned, wide[:, :40]).bins, out.bins)


def test_bad_input():
    m = _core.BackgroundModel()
    with pytest.raises(TypeError, match="frame dtype is float64"):  # was ValueError
        m.apply(np.zeros((4, 4, 3)))
    with pytest.raises(ValueError, match=r"frame must have shape \(H, W, 3\)"):
        m.apply(np.zeros((4, 4), np.uint8))
    m.apply(np.zeros((4, 4, 3), np.uint8))
    with pytest.raises(ValueError, match=r"frame shape is \(5, 4, 3\), expected \(4, 4, 3\)"):
        m.apply(np.zeros((5, 4, 3), np.uint8))
    with pytest.raises(ValueError, match="alpha is 0"):
        _core.BackgroundModel(alpha=0.0)
    with pytest.raises(ValueError, match="t_max is 5"):
        _core.BackgroundModel(t_min=10.0, t_max=5.0)
    with pytest.raises(ValueError, match="n_h is 0"):
        _core.BackgroundModel(n_h=0)
    with pytest.raises(ValueError, match="background value"):
        m.set_background(np.full((4, 4, 3), 300.0))
    binned = _core.hsv_bins(np.zeros((4, 4, 3), np.uint8))
    with pytest.raises(ValueError, match="mask must have the frame's"):
        _core.mask_bins(binned, np.zeros((4, 5), np.uint8))
    with pytest.raises(TypeError, match="mask dtype"):  # as hsv_bins (was ValueError)
        _core.mask_bins(binned, np.zeros((4, 4), np.float32))


def test_threads_give_serial_result():
    frames = random_scene(np.random.default_rng(9), shape=(120, 160), steps=5)

    def run():
        m = _core.BackgroundModel()
        return [m.apply(f)[1] for f in frames]

    serial = run()
    results = [None] * 4

    def work(i):
        results[i] = run()

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results:
        for a, b in zip(r, serial, strict=True):
            np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("how", ["copy", "deepcopy", "pickle"])
def test_a_copied_model_goes_on_as_the_original(how):
    import copy
    import pickle

    rng = np.random.default_rng(5)
    frames = [rng.integers(0, 256, (24, 32, 3), dtype=np.uint8) for _ in range(12)]
    clone = {"copy": copy.copy, "deepcopy": copy.deepcopy}.get(
        how, lambda m: pickle.loads(pickle.dumps(m))
    )
    a = _core.BackgroundModel(alpha=0.07, n_learn=4, shadow_lo=0.6, n_h=8)
    assert clone(a).shape is None  # before any frame too
    for f in frames[:6]:
        a.apply(f)
    a.set_threshold_scale(1.3)
    b = clone(a)
    assert (b.alpha, b.n_learn, b.shadow_lo, b.n_bins) == (0.07, 4, 0.6, a.n_bins)
    assert (b.frame_count, b.threshold, b.threshold_scale) == (
        a.frame_count, a.threshold, a.threshold_scale,
    )  # fmt: skip
    np.testing.assert_array_equal(b.background, a.background)
    for f in frames[6:]:
        (bins_a, mask_a), (bins_b, mask_b) = a.apply(f), b.apply(f)
        np.testing.assert_array_equal(mask_a, mask_b)
        np.testing.assert_array_equal(bins_a.bins, bins_b.bins)
    np.testing.assert_array_equal(a.background, b.background)
    np.testing.assert_array_equal(a.difference_histogram, b.difference_histogram)


def test_a_pickled_state_keeps_the_previous_frame_interleaved():
    # the model keeps the previous frame planar (B, G, R rows) since stop 65; its state gives
    # and takes it as the frame's BGR bytes, the layout of every pickle made before
    rng = np.random.default_rng(11)
    frames = random_scene(rng, shape=(30, 37), steps=8)
    model, reference = _core.BackgroundModel(n_learn=2), BackgroundReference(n_learn=2)
    for f in frames[:4]:
        model.apply(f)
        reference.apply(f)
    state = model.__getstate__()
    assert state[4] == frames[3].tobytes()  # as the frame: interleaved
    # a state written as an earlier model wrote it, with another frame as the previous one
    given = (*state[:4], frames[7].tobytes(), *state[5:])
    restored = _core.BackgroundModel.__new__(_core.BackgroundModel)
    restored.__setstate__(given)
    assert restored.__getstate__() == given
    reference.previous = frames[7].copy()
    masks = []
    for f in frames[4:7]:
        _, mask = restored.apply(f)
        np.testing.assert_array_equal(mask, reference.apply(f)[1])
        np.testing.assert_array_equal(restored.background, reference.background)
        masks.append(mask)
    # the previous frame given decided candidates (d_prev): not the true previous frame's masks
    assert not np.array_equal(masks[0], model.apply(frames[4])[1])


def test_a_bad_pickled_state_is_refused():
    model = _core.BackgroundModel.__new__(_core.BackgroundModel)
    with pytest.raises(ValueError, match="^BackgroundModel.__setstate__: state size is 2"):
        model.__setstate__((1, 2))
    good = _core.BackgroundModel()
    good.apply(np.zeros((4, 5, 3), np.uint8))
    state = list(good.__getstate__())
    state[3] = state[3][:-4]  # a background one float short
    with pytest.raises(ValueError, match="^BackgroundModel.__setstate__: background size is 59"):
        _core.BackgroundModel.__new__(_core.BackgroundModel).__setstate__(tuple(state))
