"""Grey video and global light changes: the rules of `pftrack.detection.light`."""

from __future__ import annotations

import re
import warnings

import cv2
import numpy as np
import pytest

import pftrack
from pftrack import _core
from pftrack.detection import PaperConfig, PaperDetector
from pftrack.detection.base import median_frame
from pftrack.detection.light import (
    channel_spread,
    frame_gain,
    is_blank,
    is_dark,
    level_frames,
    levelled_median,
    looks_grey,
)
from pftrack.detection.paper import DARK_FRAMES
from pftrack.eval import evaluate_mot
from pftrack.io.mot import group_by_frame
from pftrack.synthetic import make_scene
from pftrack.tracking import track_frames
from pftrack.tracking.api import xywh_to_xyxy_dets
from tests.detection.test_background_model import random_scene
from tests.reference.detection import (
    BackgroundReference,
    scale_reference,
)

GREY_WARNING = "ignore:the video is grey:UserWarning"


def to_grey(frame: np.ndarray) -> np.ndarray:
    return cv2.cvtColor(cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY), cv2.COLOR_GRAY2BGR)


def ramped(frames: list[np.ndarray], floor: float = 0.4) -> list[np.ndarray]:
    """Brightness times 1 at the first frame down to `floor` at the last (float32, truncated)."""
    n = len(frames)
    return [
        np.clip(f.astype(np.float32) * (1.0 - (1.0 - floor) * k / (n - 1)), 0, 255).astype(np.uint8)
        for k, f in enumerate(frames)
    ]


# -- the C++ kernels against their NumPy references (the gain's: light.frame_gain) ---------------
@pytest.mark.parametrize("step", [1, 3, 4])
def test_global_gain_equals_reference(step: int) -> None:
    rng = np.random.default_rng(step)
    for shape in ((37, 53), (48, 64)):
        bg = rng.uniform(0, 255, (*shape, 3)).astype(np.float32)
        bg[:5] = 3.0  # dark rows: below min_sum, left out
        frame = np.clip(bg * rng.uniform(0.3, 1.5) + rng.normal(0, 4, bg.shape), 0, 255)
        frame = frame.astype(np.uint8)
        m = _core.BackgroundModel()
        m.set_background(bg)
        assert m.global_gain(frame, step) == pytest.approx(
            frame_gain(frame, bg, step), rel=0, abs=1e-12
        )
    m = _core.BackgroundModel()
    m.set_background(np.zeros((8, 8, 3), np.float32))
    assert m.global_gain(np.zeros((8, 8, 3), np.uint8)) == 1.0  # no pixel qualifies


@pytest.mark.parametrize("step", [1, 3, 4, 8, 100])
def test_mean_and_gain_are_sampled_mean_and_global_gain(step: int) -> None:
    # one read of the sampled pixels for both (the detector's every frame): the same doubles
    # as the two calls, and as NumPy's mean and the gain's reference
    rng = np.random.default_rng(step)
    for shape in ((37, 53), (48, 64), (1, 9)):
        bg = rng.uniform(0, 255, (*shape, 3)).astype(np.float32)
        bg[: shape[0] // 4] = 3.0  # dark rows: below min_sum, left out of the gain only
        frame = np.clip(bg * rng.uniform(0.3, 1.5) + rng.normal(0, 4, bg.shape), 0, 255)
        frame = frame.astype(np.uint8)
        m = _core.BackgroundModel()
        m.set_background(bg)
        mean, gain = m.mean_and_gain(frame, step)
        assert mean == _core.sampled_mean(frame, step) == frame[::step, ::step].mean()
        assert gain == m.global_gain(frame, step)
        assert gain == pytest.approx(frame_gain(frame, bg, step), rel=0, abs=1e-12)
        left = frame[:, : shape[1] // 2 + 1]  # columns of a larger frame: its row stride
        m.set_background(np.ascontiguousarray(bg[:, : left.shape[1]]))
        assert m.mean_and_gain(left, step) == (left[::step, ::step].mean(),
                                               m.global_gain(left, step))  # fmt: skip
    m = _core.BackgroundModel()
    m.set_background(np.zeros((8, 8, 3), np.float32))
    assert m.mean_and_gain(np.full((8, 8, 3), 7, np.uint8)) == (7.0, 1.0)  # no pixel qualifies
    with pytest.raises(ValueError, match="^BackgroundModel.mean_and_gain: step is 0"):
        m.mean_and_gain(np.zeros((8, 8, 3), np.uint8), 0)
    with pytest.raises(ValueError, match="no background yet"):
        _core.BackgroundModel().mean_and_gain(np.zeros((8, 8, 3), np.uint8))


def gain_reference(
    frame: np.ndarray, bg: np.ndarray, step: int, min_sum: float
) -> tuple[float, float]:
    """(sampled mean, global gain) as ``BackgroundModel.mean_and_gain`` defines them, bit for bit.

    The background sum in double in the kernel's order ((B + G) + R), the ratios as one
    division of doubles, kept where not (sum < min_sum) and not (sum <= 0) (a NaN `min_sum`
    keeps every positive sum, as the C++ test does), and the median of the kept ones (the mean
    of the two middle ones for an even count); 1 when none is kept.
    """
    f = frame[::step, ::step].astype(np.int64)
    b = bg[::step, ::step].astype(np.float64)
    si = (f[..., 0] + f[..., 1] + f[..., 2]).ravel()
    sb = ((b[..., 0] + b[..., 1]) + b[..., 2]).ravel()
    with np.errstate(invalid="ignore"):
        keep = ~(sb < min_sum) & ~(sb <= 0.0)
    r = np.sort(si[keep] / sb[keep])
    mean = si.sum() / (3 * si.size)
    if r.size == 0:
        return mean, 1.0
    k = r.size // 2
    return mean, float(r[k] if r.size % 2 else 0.5 * (r[k - 1] + r[k]))


@pytest.mark.parametrize("allowed", [True, False], ids=["avx2", "portable"])
@pytest.mark.parametrize("step", [1, 2, 3, 4, 8])
def test_gain_samples_alike_with_and_without_avx2(step: int, allowed: bool) -> None:
    # the sampled pixels 4 a step by AVX2 gathers with a left-pack of the kept ratios (stop 74),
    # or one by one (`_set_avx2(False)`, other CPUs): widths around every 4-pixel step and its
    # tail (a step's last pixel at most cols - 2), dark pixels scattered so that every pattern
    # of kept lanes occurs, background sums of exactly 0 (dropped even at min_sum 0), a NaN and
    # an infinite min_sum, and a frame that is columns of a wider one (its row stride)
    rng = np.random.default_rng(step)
    before = _core._set_avx2(allowed)
    try:
        for cols in (1, 2, 3, 5, 8, 9, 12, 13, 14, 33, 64, 65, 130, 480):
            bg = rng.uniform(0, 120, (23, cols, 3)).astype(np.float32)
            bg[rng.random((23, cols)) < 0.3] = 2.0  # below min_sum 30
            bg[rng.random((23, cols)) < 0.1] = 0.0
            wide = rng.integers(0, 256, (23, cols + 7, 3), dtype=np.uint8)
            for frame in (np.ascontiguousarray(wide[:, :cols]), wide[:, 3 : 3 + cols]):
                m = _core.BackgroundModel()
                m.set_background(bg)
                for min_sum in (30.0, 0.0, float("nan"), float("inf")):
                    want = gain_reference(frame, bg, step, min_sum)
                    assert m.mean_and_gain(frame, step, min_sum) == want, (cols, min_sum)
                    assert m.global_gain(frame, step, min_sum) == want[1]
    finally:
        _core._set_avx2(before)


def test_frame_gain_of_uint8_frames_is_numpys_reduction_bit_for_bit() -> None:
    """The sums of uint8 channels are added as slices (exact integers): the same floats."""
    from pftrack.detection.light import _pixel_sums

    rng = np.random.default_rng(7)
    for shape in ((37, 53, 3), (360, 480, 3)):
        a = rng.integers(0, 256, shape, dtype=np.uint8)
        a[:3] = 255  # the largest sums
        b = np.clip(a * rng.uniform(0.5, 1.5) + rng.normal(0, 9, shape), 0, 255).astype(np.uint8)
        for step in (1, 4, 7):
            want = a[::step, ::step].astype(np.float64).sum(axis=2)
            got = _pixel_sums(a[::step, ::step])
            assert got.dtype == np.float64 and np.array_equal(got, want)
            si, sr = (x[::step, ::step].astype(np.float64).sum(axis=2) for x in (b, a))
            keep = (sr >= 30.0) & (sr > 0)
            assert frame_gain(b, a, step) == float(np.median(si[keep] / sr[keep]))
    bg = rng.uniform(0, 255, (20, 30, 3)).astype(np.float32)  # a background: NumPy's own sums
    np.testing.assert_array_equal(_pixel_sums(bg), bg.astype(np.float64).sum(axis=2))


def test_scale_equals_reference_and_clips() -> None:
    rng = np.random.default_rng(1)
    bg = rng.uniform(0, 255, (20, 30, 3)).astype(np.float32)
    for gain in (0.4, 1.07, 1.9):
        m = _core.BackgroundModel()
        m.set_background(bg)
        m.scale(gain)
        np.testing.assert_array_equal(m.background, scale_reference(bg, gain))
    assert m.background.max() == 255.0


@pytest.mark.parametrize("kw", [{}, {"t_min": 8.0, "t_max": 200.0, "k_noise": 30.0}])
def test_threshold_scale_equals_reference(kw: dict[str, float]) -> None:
    # the gain rule's loop (gain, scale, threshold scale) on a darkening then brightening scene
    frames = random_scene(np.random.default_rng(5), steps=8)
    light = [1.0, 0.8, 0.6, 0.5, 0.5, 0.9, 1.4, 2.0]
    frames = [np.clip(f * g, 0, 255).astype(np.uint8) for f, g in zip(frames, light, strict=True)]
    model, ref = _core.BackgroundModel(n_learn=2, **kw), BackgroundReference(n_learn=2, **kw)
    for k, frame in enumerate(frames):
        if k > 0:
            gain = model.global_gain(frame)
            assert gain == frame_gain(frame, ref.background, 4)
            model.scale(gain)
            ref.background = scale_reference(ref.background, gain)
            model.set_threshold_scale(model.threshold_scale * gain)
            ref.set_threshold_scale(ref.threshold_scale * gain)
            assert model.threshold == pytest.approx(ref.threshold, abs=1e-12)
        _, mask = model.apply(frame)
        _, rmask = ref.apply(frame)
        np.testing.assert_array_equal(mask, rmask)
        np.testing.assert_array_equal(model.background, ref.background)
        assert model.threshold == pytest.approx(ref.threshold, abs=1e-12)
    lo = min(model.threshold_scale * model.t_min, 255.0)
    assert lo <= model.threshold <= min(model.threshold_scale * model.t_max, 255.0)
    model.reset()
    assert model.threshold_scale == 1.0 and model.threshold == model.t_min


def test_threshold_scale_bounds_the_threshold() -> None:
    m = _core.BackgroundModel(t_min=25.0, t_max=60.0)
    m.set_background(np.full((4, 4, 3), 100, np.float32))
    assert m.threshold == 25.0
    m.set_threshold_scale(0.4)
    assert m.threshold == pytest.approx(10.0)  # 25 * 0.4, in the new bounds [10, 24]
    m.set_threshold_scale(20.0)
    assert m.threshold == 255.0  # 10 * 50 = 500, clamped to 255 (t_min * 20 = 500 > 255)
    for bad in (0.0, -1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="s"):
            m.set_threshold_scale(bad)


def test_gain_errors() -> None:
    m = _core.BackgroundModel()
    with pytest.raises(ValueError, match="no background"):
        m.global_gain(np.zeros((4, 4, 3), np.uint8))
    with pytest.raises(ValueError, match="no background"):
        m.scale(1.1)
    m.set_background(np.full((4, 4, 3), 100, np.float32))
    with pytest.raises(ValueError, match="gain"):
        m.scale(0.0)
    with pytest.raises(ValueError, match="frame shape"):
        m.global_gain(np.zeros((5, 4, 3), np.uint8))
    with pytest.raises(ValueError, match="step"):
        m.global_gain(np.zeros((4, 4, 3), np.uint8), 0)


# -- the grey test ---------------------------------------------------------------------------------
def test_looks_grey() -> None:
    scene = make_scene(n_frames=3, rng=0)
    colour = scene.frames
    assert not looks_grey(colour)
    grey = [to_grey(f) for f in colour]
    assert looks_grey(grey)
    assert channel_spread(grey[0]).max() == 0
    # a compressed grey video keeps a level or two of colour
    noisy = [np.clip(g.astype(int) + np.random.default_rng(0).integers(-1, 2, g.shape), 0, 255)
             .astype(np.uint8) for g in grey]  # fmt: skip
    assert looks_grey(noisy)
    assert not looks_grey([])
    assert not looks_grey(grey, tolerance=0) or channel_spread(grey[0]).max() == 0


def dark_walker(n: int = 40, colour: tuple[int, int, int] = (150, 60, 50)) -> list[np.ndarray]:
    """A textured grey-stone background with one walker of `colour` (BGR): in grey, the walker
    is 0.56 of the background's brightness, which the shadow test (bound 0.5) calls shadow."""
    rng = np.random.default_rng(0)
    base = np.clip(rng.normal(120, 6, (120, 160, 3)), 0, 255)
    frames = []
    for k in range(n):
        f = base + rng.normal(0, 2, base.shape)
        x = 10 + 3 * k
        f[30:90, x : x + 20] = colour
        frames.append(np.clip(f, 0, 255).astype(np.uint8))
    return frames


@pytest.mark.filterwarnings(GREY_WARNING)
def test_grey_video_keeps_dark_clothes() -> None:
    colour = dark_walker()
    grey = [to_grey(f) for f in colour]
    found = {}
    for name, frames, cfg in (
        ("colour", colour, PaperConfig()),
        ("grey", grey, PaperConfig()),
        ("grey, test kept", grey, PaperConfig(grey_shadow_lo=0.5)),
    ):
        det = PaperDetector(cfg)
        det.prime(frames[:: len(frames) // 10])
        found[name] = sum((det.detect(f).mask[30:90] == 255).mean() for f in frames[5:])
        assert det.grey == (name != "colour")
        assert det.model.shadow_lo == (0.5 if name != "grey" else 1.0)
    assert found["grey"] > 0.8 * found["colour"]
    assert found["grey, test kept"] < 0.2 * found["colour"]  # the defect: dark clothes = shadow


def test_grey_warns_once_and_decides_on_the_first_frame() -> None:
    grey = [to_grey(f) for f in dark_walker(4)]
    det = PaperDetector()
    with pytest.warns(UserWarning, match="the video is grey"):
        det.detect(grey[0])
    assert det.grey is True and det.model.shadow_lo == 1.0
    det.detect(grey[1])  # no second warning (filterwarnings = error would raise on another)
    det.reset()
    assert det.grey is None
    det = PaperDetector(PaperConfig(grey_tolerance=0))
    det.detect(grey[0])
    assert det.grey is False and det.model.shadow_lo == 0.5


DETECTOR_GREY = (
    "the video is grey (its colour channels are equal): the shadow test is off (every darker "
    "pixel has the background's grey chromaticity, dark clothes too), real shadows may be "
    "detected; without colour, people as bright as the background are missed and the trackers "
    "tell people apart by brightness alone"
)
REFINE_GREY = (
    "the video is grey (its colour channels are equal): box refinement's shadow test is off, "
    "and the trackers tell people apart by brightness alone"
)


def _said(caught: list[warnings.WarningMessage]) -> list[str]:
    return [str(w.message) for w in caught if "the video is grey" in str(w.message)]


def test_grey_warning_says_what_the_background_model_is_for() -> None:
    """Was: with given detections (the model only refines their boxes) the detector's warning,
    'people as bright as the background are missed', which is not so: nobody is missed."""
    grey = [to_grey(f) for f in dark_walker(4)]
    for call, expected in (("detect", DETECTOR_GREY), ("foreground", REFINE_GREY)):
        det = PaperDetector()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            det.prime(grey)  # decides, says nothing yet: it cannot tell what it is for
            assert _said(caught) == []
            getattr(det, call)(grey[0])
            getattr(det, call)(grey[1])
        assert _said(caught) == [expected]  # once
        det.reset()  # a new video: said again
        with pytest.warns(UserWarning, match=re.escape(expected)):
            getattr(det, call)(grey[0])


def test_grey_warning_of_a_run_with_and_without_detections() -> None:
    """The same words from ``track_frames`` (the detector on its thread ahead) and a loop."""
    scene = make_scene(n_frames=8, rng=0)
    frames = [to_grey(f) for f in scene.frames]
    dets = {f: r[:, 2:7] for f, r in group_by_frame(scene.truth).items()}
    for given, expected in ((None, DETECTOR_GREY), (dets, REFINE_GREY)):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            track_frames(frames, detections=given)
        assert _said(caught) == [expected]
        tracker = pftrack.Tracker()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            tracker.prime(frames)
            for k, frame in enumerate(frames, start=1):
                boxes = None if given is None else xywh_to_xyxy_dets(given.get(k, np.zeros((0, 5))))
                tracker.update(boxes, frame)
        assert _said(caught) == [expected]


def test_config_checks() -> None:
    for bad in (
        {"grey_tolerance": -1},
        {"grey_shadow_lo": 1.5},
        {"gain_band": 1.0},
        {"grey_t_min": -1.0},
        {"grey_t_min": 61.0},  # above t_max (60)
    ):
        with pytest.raises(ValueError, match=next(iter(bad))):
            PaperConfig(**bad)  # type: ignore[arg-type]


# -- tracking: grey and ramped synthetic scenes against the colour one ----------------------------
def mota(frames: list[np.ndarray], truth: np.ndarray) -> float:
    run = track_frames(frames, rng=0, bootstrap="auto", show_progress=False)
    return float(evaluate_mot(truth, run.rows).mota)


def dark_clothes(scene_rng: int = 3, n: int = 80) -> tuple[list[np.ndarray], np.ndarray]:
    """`make_scene` with every walker's pixels made dark bluish clothes (B, G, R times 0.9,
    0.5, 0.45 of the ground behind): in colour not shadow-like, in grey 0.53 of the ground's
    brightness, which the shadow test (bound 0.5) took for shadow."""
    scene = make_scene(n_frames=n, rng=scene_rng, occluder=False)
    bg = scene.background.astype(np.float32)
    dark = np.clip(bg * np.array([0.9, 0.5, 0.45], np.float32), 0, 255).astype(np.uint8)
    frames = []
    for f in scene.frames:
        walker = np.abs(f.astype(np.int16) - scene.background).max(axis=2) > 40
        g = f.copy()
        g[walker] = dark[walker]
        frames.append(g)
    return frames, scene.truth


@pytest.mark.filterwarnings(GREY_WARNING)
@pytest.mark.xfail(
    reason="known gap (stop 67): the grey detector finds fewer of these walkers (R@0.5 0.84 "
    "against 0.93, P 0.88 against 0.93; MOTA 0.74 against 0.82): a grey pixel's difference "
    "|Y - Y_B| is below the colour test's max_c |I_c - B_c| (0.90 of the walkers' pixels pass "
    "25 in grey, 0.97 in colour) and opening removes more of the thinner masks; with the same "
    "boxes the tracker scores grey and colour alike (the test below)",
    strict=True,
)
def test_grey_scene_tracks_about_as_well_as_its_colour_version() -> None:
    frames, truth = dark_clothes()
    colour_score = mota(frames, truth)
    grey_score = mota([to_grey(f) for f in frames], truth)
    assert colour_score > 0.3
    assert grey_score >= colour_score - 0.05, (colour_score, grey_score)


def detector_boxes(frames: list[np.ndarray]) -> dict[int, np.ndarray]:
    """The built-in detector's boxes and scores of each frame (1-based), primed as the tests'."""
    det = PaperDetector()
    det.prime(frames[::2])
    boxes = {}
    for k, f in enumerate(frames, start=1):
        d = det.detect(f)
        boxes[k] = np.column_stack([d.boxes, d.scores]) if len(d) else np.zeros((0, 5))
    return boxes


def mota_of_boxes(frames: list[np.ndarray], truth: np.ndarray, boxes, refine: bool) -> float:
    tracker = pftrack.Tracker(10.0, refine=refine, seed=0)
    tracker.prime(frames[::2])
    for k, frame in enumerate(frames, start=1):
        tracker.update(xywh_to_xyxy_dets(boxes[k]), frame)
    return float(evaluate_mot(truth, tracker.finalize()).mota)


@pytest.mark.filterwarnings(GREY_WARNING)
def test_grey_video_is_tracked_as_colour_from_the_same_boxes() -> None:
    """Stop 67's split of the grey loss: given the colour video's own detector boxes (box
    refinement off), the grey video is tracked as well as the colour one, so the trackers'
    grey-only histograms (V bins alone) are not where the grey scene loses (0.880 both)."""
    frames, truth = dark_clothes()
    boxes = detector_boxes(frames)
    colour = mota_of_boxes(frames, truth, boxes, refine=False)
    grey = mota_of_boxes([to_grey(f) for f in frames], truth, boxes, refine=False)
    assert colour > 0.8 and grey >= colour - 0.02, (colour, grey)


@pytest.mark.filterwarnings(GREY_WARNING)
@pytest.mark.xfail(
    reason="known gap (stop 67): box refinement shrinks given boxes to the grey foreground, "
    "which has fewer of the walkers' pixels than colour's (MOTA 0.70 against 0.86); "
    "PaperConfig(grey_refine_texture=0.7) closes it (test_grey_texture.py) but is not the "
    "default (stop 68: it costs grey PETS09-S2L1 and groups IDF1)",
    strict=True,
)
def test_given_boxes_refined_on_grey_video_track_as_on_colour() -> None:
    frames, truth = dark_clothes()
    boxes = detector_boxes(frames)
    colour = mota_of_boxes(frames, truth, boxes, refine=True)
    grey = mota_of_boxes([to_grey(f) for f in frames], truth, boxes, refine=True)
    assert grey >= colour - 0.05, (colour, grey)


def grey_walker_found(config: PaperConfig, grey: bool) -> float:
    """Share of a walker 20 levels brighter than the ground (in every channel) found as
    foreground, by `config`'s detector, on the grey or the colour video."""
    rng = np.random.default_rng(0)
    # textured ground (a standard deviation of 15, so that the grey test can decide), tinted
    # blue-red in colour; the walker is the ground brightened by 20 in every channel
    base = rng.normal(120, 15, (120, 160, 1)) + np.array([10.0, 0.0, -10.0])
    frames = []
    for k in range(20):
        f = base + rng.normal(0, 2, base.shape)
        f[30:90, 10 + 3 * k : 30 + 3 * k] += 20.0
        frame = np.clip(f, 0, 255).astype(np.uint8)
        frames.append(to_grey(frame) if grey else frame)
    det = PaperDetector(config)
    det.prime(frames[::2])
    assert det.grey == grey
    return float(np.mean([(det.detect(f).mask[30:90] == 255).mean() for f in frames[5:]]))


@pytest.mark.filterwarnings(GREY_WARNING)
def test_grey_t_min_lowers_the_bound_of_grey_video_only() -> None:
    """``PaperConfig.grey_t_min`` is the threshold's lower bound on grey video; colour video
    keeps `t_min` (25 here: the walker's contrast of 20 is missed)."""
    low = PaperConfig(grey_t_min=12.0)
    assert grey_walker_found(PaperConfig(), grey=True) < 0.01  # 20 < 25: missed
    assert grey_walker_found(low, grey=True) > 0.1  # 20 > 12: found
    assert grey_walker_found(low, grey=False) < 0.01  # colour keeps t_min
    det = PaperDetector(low)
    assert det.model.t_min == 25.0  # before the video is seen
    det.detect(to_grey(dark_walker(1)[0]))
    assert det.model.t_min == 12.0 and det.model.shadow_lo == 1.0


# gain_band=0: foreground almost everywhere, which the noise warning says
@pytest.mark.filterwarnings("ignore:noisy or changing video:UserWarning")
def test_ramped_scene_with_the_auto_bootstrap() -> None:
    scene = make_scene(n_frames=100, rng=0)
    frames = ramped(scene.frames, 0.7)
    plain = mota(scene.frames, scene.truth)
    ramp = mota(frames, scene.truth)
    assert ramp >= plain - 0.05, (plain, ramp)
    det = PaperDetector(PaperConfig(gain_band=0))  # the defect without the gain: frames darker
    # than the spread median read as foreground almost everywhere
    frames = ramped(scene.frames)  # down to 0.4
    det.prime(frames[:: len(frames) // 30])
    worst = max((det.detect(f).mask > 0).mean() for f in frames[:10])
    det = PaperDetector()
    det.prime(frames[:: len(frames) // 30])
    fixed = max((det.detect(f).mask > 0).mean() for f in frames[:10])
    assert worst > 0.5 and fixed < 0.1, (worst, fixed)


def faded_in(frames: list[np.ndarray], frames_to_full: int, start: float = 0.0) -> list[np.ndarray]:
    """Brightness from `start` at the first frame up to 1 at `frames_to_full` and after."""
    gains = [start + (1 - start) * min(1.0, k / frames_to_full) for k in range(len(frames))]
    return [(f.astype(np.float32) * g).astype(np.uint8) for f, g in zip(frames, gains, strict=True)]


@pytest.mark.slow
def test_a_video_that_fades_in_is_tracked() -> None:
    """A 2 s fade-in (10 fps): tracked nearly as the video without it.

    Were: the thresholds followed the gain since the dim first frame up, to 12 times t_min,
    and nothing was foreground again (0 tracks); without that, the size model learnt the
    dim frames' fragments of people and cut everyone in two afterwards (MOTA -67)."""
    scene = make_scene(150, 480, 360, rng=1)
    plain = mota(scene.frames, scene.truth)
    faded = mota(faded_in(scene.frames, 20, start=0.05), scene.truth)
    assert plain > 0.9 and faded > 0.6, (plain, faded)


def test_thresholds_do_not_rise_past_the_given_bounds_as_the_light_rises() -> None:
    """The threshold scale follows the light down, never above 1 (the fade-in's defect)."""
    scene = make_scene(40, 240, 180, rng=1)
    det = PaperDetector()
    scales = []
    for f in faded_in(scene.frames, 20, start=0.1):
        det.detect(f)
        scales.append(det.model.threshold_scale)
    assert max(scales) == 1.0
    det = PaperDetector()
    for f in ramped(scene.frames, 0.4):  # dimming: down with the light, as before
        det.detect(f)
    assert det.model.threshold_scale < 0.5


def test_the_size_model_pauses_while_the_light_changes() -> None:
    scene = make_scene(60, 240, 180, rng=1)
    frames = faded_in(scene.frames, 20, start=0.1)
    det = PaperDetector()
    for f in frames[:25]:  # through the fade and a few frames after
        det.detect(f)
    assert det.size_model.n_samples == 0
    for f in frames[25:]:
        det.detect(f)
    assert det.size_model.n_samples > 0


# -- the priming median under a light change ------------------------------------------------------
def test_level_frames_leaves_steady_video_alone_and_levels_a_ramp() -> None:
    scene = make_scene(n_frames=30, rng=0)
    steady = scene.frames[::3]
    assert all(a is b for a, b in zip(level_frames(steady, 0.03), steady, strict=True))
    assert level_frames(steady, 0.0) is steady
    dark = ramped(steady)
    levelled = level_frames(dark, 0.03)
    assert levelled[0] is dark[0]
    for f in levelled[1:]:
        assert abs(frame_gain(f, dark[0]) - 1.0) <= 0.03


def test_prime_is_not_biased_by_a_person_standing_under_a_ramp() -> None:
    # a bright person stands in 40 % of the priming frames while the light falls to 0.4: the
    # median of the frames as they are takes the upper end of the ground's values there
    rng = np.random.default_rng(0)
    ground = rng.integers(60, 120, (60, 80, 3)).astype(np.float32)
    frames = []
    for k in range(30):
        f = ground.copy()
        if k % 5 < 2:
            f[10:50, 30:45] = 250.0
        frames.append(f)
    frames = ramped([np.clip(f, 0, 255).astype(np.uint8) for f in frames])
    box = (slice(10, 50), slice(30, 45))
    for band, ok in ((0.0, False), (0.03, True)):
        det = PaperDetector(PaperConfig(gain_band=band))
        det.prime(frames)
        bg = det.model.background
        # the first frame's light (the ground is at the first frame's brightness outside)
        ratio = bg[box].sum() / ground[box].sum()
        outside = bg[:10].sum() / ground[:10].sum()
        assert (abs(ratio - 1.0) < 0.05) == ok, (band, ratio)
        assert (abs(ratio - outside) < 0.05) == ok, (band, ratio, outside)


def _saturating_step(n: int = 30, gain: float = 1.4) -> tuple[list[np.ndarray], np.ndarray]:
    """Frames of a ground (60-149) with a bright third (200-249) that a light multiplies by
    `gain` from n // 3 on: the bright third saturates, the rest measures the gain."""
    rng = np.random.default_rng(3)
    ground = rng.integers(60, 150, (48, 64, 3)).astype(np.float32)
    ground[:16] = rng.integers(200, 250, (16, 64, 3))
    frames = [
        np.clip(ground * (gain if k >= n // 3 else 1.0), 0, 255).astype(np.uint8) for k in range(n)
    ]
    return frames, ground


def masked_median_reference(frames, band):
    """NumPy: levelled frames, a brighter frame's saturated pixels left out of the median, never
    below the median of all levelled frames."""
    levelled = level_frames(frames, band)
    stack = np.stack(levelled).astype(np.float64)
    for k, (a, b) in enumerate(zip(frames, levelled, strict=True)):
        if a is not b and frame_gain(a, frames[0]) > 1.0:
            stack[k][(a == 255).any(axis=2)] = np.nan
    whole = np.median(np.stack(levelled).astype(np.float64), axis=0)  # a lower bound
    kept = np.nanmedian(stack, axis=0)
    return np.where(np.isnan(kept), whole, np.maximum(whole, kept))


def test_levelled_median_leaves_out_the_saturated_pixels_of_brighter_frames() -> None:
    # was: 255 / 1.4 = 182 where the ground is 200-249: the frames before the light came on
    # read as foreground at every saturated pixel
    frames, ground = _saturating_step()
    got = levelled_median(frames, 0.03, "test")
    np.testing.assert_allclose(got, masked_median_reference(frames, 0.03), atol=1e-4)
    np.testing.assert_allclose(got, ground, atol=1.0)  # the first frames' light
    plain = median_frame(level_frames(frames, 0.03), "test")
    assert np.abs(plain - ground).max() > 60  # what the levelled frames alone give: 255 / 1.4
    # more rows than one chunk, a person in some frames: the same as the reference
    big = [np.repeat(f, 3, axis=0) for f in frames]
    for k in range(0, 30, 4):
        big[k][20:90, 10:20] = 30
    np.testing.assert_allclose(
        levelled_median(big, 0.03, "test"), masked_median_reference(big, 0.03), atol=1e-4
    )


def test_levelled_median_of_steady_or_darkening_video_is_the_median() -> None:
    scene = make_scene(n_frames=30, rng=0)
    for frames in (scene.frames[::3], ramped(scene.frames[::3])):
        np.testing.assert_array_equal(
            levelled_median(frames, 0.03, "test"),
            median_frame(level_frames(frames, 0.03), "test"),
        )


def test_a_light_switched_on_leaves_the_first_frames_clean() -> None:
    # was: a third of the first frame foreground (the levelled median alone)
    frames, _ = _saturating_step()
    det = PaperDetector()
    det.prime(frames)
    assert (det.detect(frames[0]).mask > 0).mean() < 0.01


def test_detector_thresholds_follow_the_light() -> None:
    scene = make_scene(n_frames=60, rng=0)
    frames = ramped(scene.frames)
    det = PaperDetector()
    det.prime(frames[:: len(frames) // 30])
    for f in frames:
        det.detect(f)
    # relative to the first frame's light (0.4 at the last frame; the band lets it lag 3 %)
    assert 0.38 <= det.model.threshold_scale <= 0.43, det.model.threshold_scale
    assert det.model.threshold <= 0.43 * 60.0
    off = PaperDetector(PaperConfig(gain_thresholds=False))
    off.prime(frames[:: len(frames) // 30])
    for f in frames:
        off.detect(f)
    assert off.model.threshold_scale == 1.0


def test_sample_step_keeps_4_up_to_vga_and_the_sample_count_above() -> None:
    from pftrack.detection.light import sample_step

    assert [sample_step((h, w)) for h, w in ((360, 480), (480, 640), (64, 64))] == [4, 4, 4]
    assert sample_step((720, 1280)) == 7 and sample_step((1080, 1920)) == 10
    assert sample_step((360, 480), 8) == 8 and sample_step((720, 1280), 8) == 14  # the gain's
    for h, w in ((720, 1280), (1080, 1920), (2160, 3840)):
        n = len(range(0, h, sample_step((h, w)))) * len(range(0, w, sample_step((h, w))))
        assert 0.7 * 120 * 160 <= n <= 1.3 * 120 * 160  # about 640x480's 19 200 samples


def test_a_colour_video_is_told_from_its_first_frame() -> None:
    rng = np.random.default_rng(0)
    colour = rng.integers(0, 255, (48, 64, 3), dtype=np.uint8)
    grey = np.repeat(rng.integers(0, 255, (48, 64, 1), dtype=np.uint8), 3, axis=2)
    assert not looks_grey([colour, grey, grey])
    assert looks_grey([grey, grey]) and not looks_grey([grey, colour])


# -- dark frames: a dropout or a fade to black (a trial find: "gain is 0" ended the run) --------
def test_is_dark() -> None:
    frame = np.full((36, 48, 3), 9, np.uint8)
    assert not is_dark(frame)
    assert is_dark(frame // 2) and is_dark(np.zeros((36, 48, 3), np.uint8))


@pytest.mark.parametrize("shape", [(1, 1), (36, 48), (37, 53), (360, 480)])
def test_sampled_mean_is_numpys_strided_mean_bit_for_bit(shape: tuple[int, int]) -> None:
    """`_core.sampled_mean` (is_dark's mean) against ``frame[::step, ::step].mean()``: the same
    double, at every step and over views of any strides (reversed channels, rows, columns)."""
    rng = np.random.default_rng(sum(shape))
    frame = rng.integers(0, 256, (*shape, 3), dtype=np.uint8)
    bright = np.full((*shape, 3), 255, np.uint8)  # the largest sums
    for f in (frame, frame[:, :, ::-1], frame[::-1], frame[:, ::-3], bright):
        for step in (1, 2, 3, 4, 7, 8, 1000):
            assert _core.sampled_mean(f, step) == float(f[::step, ::step].mean())
    assert is_dark(frame, 2**31 - 1) == (float(frame[0, 0].mean()) <= 8.0)
    with pytest.raises(ValueError, match="is_dark: step is 0"):
        is_dark(frame, 0)
    with pytest.raises(ValueError, match="sampled_mean: step"):
        _core.sampled_mean(frame, 0)
    with pytest.raises(TypeError, match="sampled_mean: frame dtype"):
        _core.sampled_mean(frame.astype(np.uint16), 1)


def test_is_blank_is_one_flat_level_not_a_dark_picture() -> None:
    zeros = np.zeros((36, 48, 3), np.uint8)
    assert is_blank(zeros) and is_blank(np.full_like(zeros, 255))  # white is blank, not dark
    step = zeros.copy()
    step[18:, :, 2] = 2
    assert is_blank(step)  # within BLANK_LEVELS: an encoded black frame's noise
    step[18:, :, 2] = 3
    assert not is_blank(step) and is_dark(step)  # a dark picture: dark, not blank
    assert not is_blank(make_scene(n_frames=1, rng=0).frames[0])


@pytest.mark.parametrize("where", [0, 20, 39])
def test_black_frames_are_tracked_through(where: int) -> None:
    """A black frame at the start, in the middle or at the end: no error, no foreground on
    it, and the other frames detected as without it (the background is left as it was)."""
    scene = make_scene(n_frames=40, rng=2)
    black = np.zeros_like(scene.frames[0])
    frames = list(scene.frames)
    frames[where] = black
    plain, dropped = PaperDetector(), PaperDetector()
    plain.prime(scene.frames[::4])
    dropped.prime(scene.frames[::4])
    for k, (f, g) in enumerate(zip(scene.frames, frames, strict=True)):
        got = dropped.detect(g)
        if k == where:
            assert not got.mask.any() and len(got.boxes) == 0
            continue
        want = plain.detect(f)
        if k < where:
            np.testing.assert_array_equal(got.mask, want.mask)
    # the whole run, with box refinement of given detections too; a run that opens on a black
    # frame says so (pftrack.Tracker.update), one that meets it later does not
    dets = {k: scene.truth[scene.truth[:, 0] == k][:, 2:7] for k in range(1, 41)}
    for given in (None, dets):
        with warnings.catch_warnings(record=True) as record:
            warnings.simplefilter("always")
            assert len(track_frames(frames, detections=given, rng=0, show_progress=False).rows)
        blank = [w for w in record if "frame 1 is blank" in str(w.message)]
        assert len(blank) == (where == 0)


def test_dark_frames_neither_prime_nor_start_the_background() -> None:
    scene = make_scene(n_frames=20, rng=3)
    black = np.zeros_like(scene.frames[0])
    det = PaperDetector()
    det.prime([black, *scene.frames[::5], black])
    ref = PaperDetector()
    ref.prime(scene.frames[::5])
    np.testing.assert_array_equal(det.model.background, ref.model.background)
    # all dark: no background yet; the first lit frame starts it, as without priming
    det, ref = PaperDetector(), PaperDetector()
    det.prime([black, black])
    assert not det.model.initialized
    det.detect(black)
    assert not det.model.initialized
    for f in scene.frames[:5]:
        np.testing.assert_array_equal(det.detect(f).mask, ref.detect(f).mask)


def _dark_said(caught: list[warnings.WarningMessage]) -> list[str]:
    return [str(w.message) for w in caught if "are dark" in str(w.message)]


def test_lights_switched_off_are_said_once() -> None:
    """A user trial: a scene whose lights go off (x0.05) from frame 60 of 150 gave tracks until
    then and nothing after, 309 people-frames missed, without a word."""
    scene = make_scene(n_frames=12 + DARK_FRAMES + 3, rng=1)
    frames = [f if k < 12 else (f * 0.05).astype(np.uint8) for k, f in enumerate(scene.frames)]
    det = PaperDetector()
    for _ in range(2):  # reset(): a new video, said again
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            for k, frame in enumerate(frames, start=1):
                det.detect(frame)
                if k < 12 + DARK_FRAMES:
                    assert _dark_said(caught) == []
        assert _dark_said(caught) == [
            "the frames from 13 on are dark (10 in a row so far at mean level 8 or less: "
            "lights switched off, a fade to black, a covered lens?): the detector finds "
            "nothing on a dark frame, so tracks coast and end until the light returns"
        ]
        det.reset()
    # a dropout (a few black frames) is not said; nor, with given detections, dark frames
    # (refinement keeps the boxes as given where there is no foreground)
    short = frames[:12] + frames[12 : 12 + DARK_FRAMES - 1] + frames[:3]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        det = PaperDetector()
        for frame in short:
            det.detect(frame)
        det = PaperDetector()
        for frame in frames:
            det.foreground(frame)
    assert _dark_said(caught) == []
