"""Settings, seeds and generators of the wrong type are refused naming the argument.

Each call here failed with a message that named nothing (NumPy's ``ufunc 'isfinite' not
supported``, ``'<=' not supported``, ``unrecognized seed string``, ``expected non-negative
integer``, an AttributeError, ``not enough values to unpack``), or was taken.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

import pftrack
from pftrack.batch import RecoverOptions, TrackOptions
from pftrack.detection import BlobConfig, KnnConfig, Mog2Config, PaperConfig
from pftrack.detection.bootstrap import bootstrap_frames
from pftrack.detection.ghost import edge_support
from pftrack.detection.size_model import SizeModelConfig
from pftrack.eval import prepare_mot
from pftrack.particle_filter import (
    Ar2Model,
    ColourParticleFilter,
    FilterConfig,
    HsvBinning,
    RJMCMCConfig,
    RJMCMCFilter,
    multinomial_resample,
    residual_resample,
    stratified_resample,
    systematic_resample,
)
from pftrack.recovery import (
    NoiseEstimate,
    estimate_noise,
    fill_gaps,
    goal_directed_path,
    link_tracklets,
    recover_gap,
    recover_gaps,
)
from pftrack.recovery.calibrate import calibrate
from pftrack.recovery.experiment import trajectories
from pftrack.recovery.gdt import GdtModel
from pftrack.render import draw_tracks
from pftrack.synthetic import camera_path, make_busy_scene
from pftrack.tracking import TrackWriter
from pftrack.tracking.camera import CameraMotion
from pftrack.tracking.config import (
    AssociationConfig,
    CameraConfig,
    LifecycleConfig,
    MotionConfig,
    RefineConfig,
    TrackerConfig,
)
from pftrack.tracking.offline import CrossingConfig, complete_boxes, drop_nested

ROWS = np.array(
    [[1, 1, 10, 10, 5, 5, 1, -1, -1, -1], [4, 1, 11, 10, 5, 5, 1, -1, -1, -1.0]]
)  # fmt: skip
SEG = np.array([[1.0, 10, 20], [2, 12, 21]])

CASES: dict[str, tuple[Callable[[], object], type[Exception], str]] = {
    "FilterConfig(lam='a')": (
        lambda: FilterConfig(lam="a"),
        TypeError,
        "FilterConfig: lam must be a number, got str 'a'",
    ),
    "Ar2Model(sigma_xy='4')": (
        lambda: Ar2Model(sigma_xy="4"),
        TypeError,
        "Ar2Model: sigma_xy must be a number, got str '4'",
    ),
    "HsvBinning(v_min='0.2')": (
        lambda: HsvBinning(v_min="0.2"),
        TypeError,
        "HsvBinning: v_min must be a number",
    ),
    "Tracker(birth_quantile='0.2')": (
        lambda: pftrack.Tracker(birth_quantile="0.2"),
        TypeError,
        "^birth_quantile must be a number, got str '0.2'",  # Tracker's own option, named
    ),
    "AssociationConfig(unmatched_cost='1')": (
        lambda: AssociationConfig(unmatched_cost="1"),
        TypeError,
        "AssociationConfig: unmatched_cost must be a number",
    ),
    "MotionConfig(speed_reference='x')": (
        lambda: MotionConfig(speed_reference="x"),
        TypeError,
        "MotionConfig: speed_reference must be a number",
    ),
    "RefineConfig(min_height='x')": (
        lambda: RefineConfig(min_height="x"),
        TypeError,
        "RefineConfig: min_height must be a number",
    ),
    "CameraConfig(threshold='x')": (
        lambda: CameraConfig(threshold="x"),
        TypeError,
        "CameraConfig: threshold must be a number",
    ),
    "TrackerConfig(reference_rate=None)": (
        lambda: TrackerConfig(reference_rate=None),
        TypeError,
        "TrackerConfig: reference_rate must be a number, got NoneType",
    ),
    "link_tracklets(rows, 'x')": (
        lambda: link_tracklets(ROWS, "x"),
        TypeError,
        "link_tracklets: config must be a LinkConfig, got str 'x'",
    ),
    "recover_gaps([(a,)])": (
        lambda: recover_gaps([(SEG,)]),
        ValueError,
        r"recover_gaps: gap 0 must be a pair \(segment_a, segment_b\), got 1 value$",
    ),
    "recover_gaps([(a, b, c)], 'linear')": (
        lambda: recover_gaps([(SEG, SEG + 9, SEG + 20)], "linear"),
        ValueError,
        "recover_gaps: gap 0 must be a pair .*, got 3 values",
    ),
    "MultiObjectTracker(detector='paper')": (  # was taken: AttributeError at the first frame
        lambda: pftrack.MultiObjectTracker(detector="paper"),
        TypeError,
        r"^MultiObjectTracker: detector must have a detect\(frame\) method \(or be None: the "
        r"built-in one\), got str 'paper'; a built-in detector is named by "
        r"TrackerConfig\(detector='paper'\)$",
    ),
    "MultiObjectTracker(detector=object())": (
        lambda: pftrack.MultiObjectTracker(detector=object()),
        TypeError,
        r"^MultiObjectTracker: detector must have a detect\(frame\) method .*, got object$",
    ),
    "recover_gaps(None)": (  # was: 'NoneType' object is not iterable
        lambda: recover_gaps(None),  # type: ignore[arg-type]
        TypeError,
        r"^recover_gaps: gaps must be a sequence of \(segment_a, segment_b\) pairs, got NoneType$",
    ),
    "recover_gaps([1, 2])": (  # was: object of type 'int' has no len()
        lambda: recover_gaps([1, 2]),  # type: ignore[list-item]
        ValueError,
        r"^recover_gaps: gap 0 must be a pair \(segment_a, segment_b\), got int$",
    ),
    "fill_gaps(seed='abc')": (
        lambda: fill_gaps(ROWS, seed="abc"),
        TypeError,
        "fill_gaps: seed must be an int >= 0, got str 'abc'",
    ),
    "fill_gaps(seed=-1)": (
        lambda: fill_gaps(ROWS, seed=-1),
        ValueError,
        "fill_gaps: seed is -1, expected an int >= 0",
    ),
    "fill_gaps('linear', seed=1.5)": (  # the seed was never read: taken
        lambda: fill_gaps(ROWS, "linear", seed=1.5),
        TypeError,
        "fill_gaps: seed must be an int >= 0, got float 1.5",
    ),
    "fill_gaps(noise='x')": (  # was: AttributeError: 'str' object has no attribute 'q'
        lambda: fill_gaps(ROWS, "gdt-bi", noise="x"),
        TypeError,
        r"fill_gaps: noise must be a NoiseEstimate \(pftrack.recovery.estimate_noise\) or None, "
        "got str$",
    ),
    "fill_gaps('linear', noise='x')": (  # was: taken (linear uses no noise)
        lambda: fill_gaps(ROWS, "linear", noise="x"),
        TypeError,
        "fill_gaps: noise must be a NoiseEstimate",
    ),
    "recover_gaps('gdt-mix', motion='x')": (  # was: AttributeError: ... no attribute 'is_gdt_bi'
        lambda: recover_gaps([(SEG, SEG + 9)], "gdt-mix", motion="x"),
        TypeError,
        r"recover_gaps: motion must be a MotionFit \(pftrack.recovery.fit_motion\) or None, "
        "got str$",
    ),
    "recover_gap(noise=..., method='gdt-bi')": (
        lambda: recover_gap(SEG, SEG + 9, method="gdt-bi", noise={"q": 1}),
        TypeError,
        "recover_gap: noise must be a NoiseEstimate .* got dict$",
    ),
    "recover_gaps(seed=-1)": (
        lambda: recover_gaps([(SEG, SEG + 9)], seed=-1),
        ValueError,
        "recover_gaps: seed is -1, expected an int >= 0",
    ),
    "ColourParticleFilter(rng='abc')": (
        lambda: ColourParticleFilter([5, 5, 4, 4], np.ones(110), rng="abc"),
        TypeError,
        r"rng must be a numpy.random.Generator \(or RandomState\), an int >= 0 or None, got str "
        "'abc'",
    ),
    "RJMCMCFilter(rng=-1)": (
        lambda: RJMCMCFilter(rng=-1),
        ValueError,
        r"RJMCMCFilter: rng must be a numpy.random.Generator \(or RandomState\), an int >= 0 or "
        "None, got int -1",
    ),
    # an int beyond a float's range: was NumPy's "ufunc 'isfinite' not supported for the input
    # types" (or "int too large to convert to float"), naming nothing
    "Tracker(frame_rate=10**400)": (
        lambda: pftrack.Tracker(frame_rate=10**400),
        ValueError,
        r"^frame_rate is an int beyond a float's range \(±1.8e\+308\)$",
    ),
    "Tracker(max_coast=-10**400)": (
        lambda: pftrack.Tracker(max_coast=-(10**400)),
        ValueError,
        r"^max_coast is an int beyond a float's range",
    ),
    "FilterConfig(lam=10**400)": (
        lambda: FilterConfig(lam=10**400),
        ValueError,
        r"^FilterConfig: lam is an int beyond a float's range",
    ),
}


@pytest.mark.parametrize("name", list(CASES))
def test_named_in_the_message(name: str) -> None:
    call, error, match = CASES[name]
    with pytest.raises(error, match=match):
        call()


@pytest.mark.parametrize(
    "fn", [systematic_resample, stratified_resample, multinomial_resample, residual_resample]
)
@pytest.mark.parametrize(
    ("rng", "error", "got"), [("abc", TypeError, "str 'abc'"), (-1, ValueError, "int -1")]
)
def test_resamplers_name_their_rng(
    fn: Callable[..., object], rng: object, error: type[Exception], got: str
) -> None:
    match = (
        rf"{fn.__name__}: rng must be a numpy.random.Generator \(or RandomState\), an int >= 0 "
        f"or None, got {got}"
    )
    with pytest.raises(error, match=match):
        fn([0.5, 0.5], rng=rng)


@pytest.mark.parametrize(
    ("q", "r", "error", "message"),
    [
        # each was taken, and failed later naming an internal function (wna_Q_xy,
        # gdt_recover_batch: "R is not positive definite") or was used (True as 1)
        (
            (-1, 1),
            (1, 1),
            ValueError,
            "NoiseEstimate.q[0] is -1.0, expected a finite number >= 0 (px²/frame³)",
        ),
        (
            (1, np.nan),
            (1, 1),
            ValueError,
            "NoiseEstimate.q[1] is nan, expected a finite number >= 0",
        ),
        (
            (1, 1),
            (np.inf, 1),
            ValueError,
            "NoiseEstimate.r[0] is inf, expected a finite number >= 1e-12 (px²)",
        ),
        (
            (1, 1),
            (1, 0),
            ValueError,
            "NoiseEstimate.r[1] is 0.0, expected a finite number >= 1e-12",
        ),
        # were taken, and failed in gdt_recover_batch: "Pi_T + H S H^T is not positive
        # definite" (tiny r, q = 0) and "R is not positive definite" (r 1e10 times apart)
        (
            (0, 0),
            (1e-20, 1e-20),
            ValueError,
            "NoiseEstimate.r[0] is 1e-20, expected a finite number >= 1e-12 (px²)",
        ),
        (
            (1, 1),
            (1e-5, 1e5),
            ValueError,
            "NoiseEstimate.r is (1e-05, 100000.0): its values are 1e+10 times apart, expected "
            "less than 5e+09",
        ),
        ((True, 1), (1, 1), TypeError, "NoiseEstimate.q[0] must be a number, got bool True"),
        ((1, 1), (1, "2"), TypeError, "NoiseEstimate.r[1] must be a number, got str '2'"),
        ("ab", (1, 1), TypeError, "NoiseEstimate.q must be 2 numbers (x, y), got str 'ab'"),
        (0.5, (1, 1), TypeError, "NoiseEstimate.q must be 2 numbers (x, y), got float 0.5"),
        ((1, 1), None, TypeError, "NoiseEstimate.r must be 2 numbers (x, y), got NoneType None"),
        (
            (1, 1, 1),
            (1, 1),
            ValueError,
            "NoiseEstimate.q is (1, 1, 1): 3 values, expected 2 (x, y)",
        ),
        (
            (1, 1),
            np.ones((2, 2)),
            ValueError,
            "NoiseEstimate.r is an array of shape (2, 2), expected 2 numbers",
        ),
    ],
)
def test_noise_estimate_names_the_field_its_value_and_what_is_expected(
    q: object, r: object, error: type[Exception], message: str
) -> None:
    with pytest.raises(error) as info:
        NoiseEstimate(q=q, r=r)  # type: ignore[arg-type]
    assert str(info.value).startswith(message), str(info.value)
    assert "\n" not in str(info.value)


def test_noise_estimate_takes_pairs_of_any_real_numbers_as_floats() -> None:
    n = NoiseEstimate(q=np.array([0, 2]), r=[np.float32(0.5), 3])  # type: ignore[arg-type]
    assert n == NoiseEstimate(q=(0.0, 2.0), r=(0.5, 3.0))
    assert all(type(v) is float for v in (*n.q, *n.r))
    hash(n)  # a tuple of floats, not an array


def test_generators_and_seeds_are_taken_as_before() -> None:
    w = np.array([0.1, 0.2, 0.7])
    gen = np.random.default_rng(4)
    np.testing.assert_array_equal(
        systematic_resample(w, rng=np.random.default_rng(4)), systematic_resample(w, rng=gen)
    )
    np.testing.assert_array_equal(systematic_resample(w, rng=4), systematic_resample(w, rng=4))
    a, _ = fill_gaps(ROWS, "auto", seed=np.int64(3))
    b, _ = fill_gaps(ROWS, "auto", seed=3)
    np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize(
    "call",
    [
        lambda v: pftrack.Tracker(frame_rate=v),
        lambda v: fill_gaps(ROWS, "linear", max_gap=v),
        lambda v: fill_gaps(ROWS, "linear", seed=v),
        lambda v: systematic_resample([0.5, 0.5], rng=v),
        lambda v: recover_gaps([(SEG, SEG + 9)], "linear", combine=v),
    ],
)
@pytest.mark.parametrize("value", [np.ones((2, 3)), "table"], ids=["array", "table"])
def test_an_array_for_a_setting_is_refused_in_one_line(
    call: Callable[[object], object], value: object
) -> None:
    """A defect trial: the message held the array's (or a DataFrame's) whole repr, one line of
    it per row (730 lines for a MOT table), after 'got ndarray'."""
    if isinstance(value, str):
        pd = pytest.importorskip("pandas")
        value = pd.DataFrame(np.ones((2, 3)))
    with pytest.raises(TypeError) as info:
        call(value)
    message = str(info.value)
    assert "\n" not in message, message
    assert message.endswith(f"got {type(value).__name__} of shape (2, 3)"), message


def _frame() -> np.ndarray:
    return np.zeros((48, 64, 3), np.uint8)


#: Every option taken as text, and what its refusal names first: a call with the option's
#: value `v`. Each compared `v` with its values (``v not in (...)``, ``v == "auto"``), which
#: asks a DataFrame or an array for its truth.
OPTION_SITES: dict[str, tuple[Callable[[object], object], str]] = {
    "TrackerConfig(sampler)": (lambda v: TrackerConfig(sampler=v), "sampler"),  # type: ignore[arg-type]
    "TrackerConfig(camera_motion)": (
        lambda v: TrackerConfig(camera_motion=v),  # type: ignore[arg-type]
        "camera_motion",
    ),
    "TrackerConfig(detector)": (lambda v: TrackerConfig(detector=v), "detector"),  # type: ignore[arg-type]
    "LifecycleConfig(amodal_anchor)": (
        lambda v: LifecycleConfig(amodal_anchor=v),  # type: ignore[arg-type]
        "LifecycleConfig: amodal_anchor",
    ),
    "Tracker(detector)": (lambda v: pftrack.Tracker(detector=v), "detector"),  # type: ignore[arg-type]
    "Tracker(dynamics)": (lambda v: pftrack.Tracker(dynamics=v), "dynamics"),  # type: ignore[arg-type]
    "Tracker(fill)": (lambda v: pftrack.Tracker(fill=v), "fill"),  # type: ignore[arg-type]
    "TrackWriter(coasting)": (lambda v: TrackWriter(coasting=v), "coasting"),  # type: ignore[arg-type]
    "CameraMotion(mode)": (lambda v: CameraMotion(v), "camera_motion"),  # type: ignore[arg-type]
    "track_frames(bootstrap)": (
        lambda v: pftrack.track_frames([_frame()], bootstrap=v),  # type: ignore[arg-type]
        "bootstrap",
    ),
    "bootstrap_frames(mode)": (lambda v: bootstrap_frames([_frame()], 1, v), "bootstrap mode"),  # type: ignore[arg-type]
    "smooth_tracks(fill_method)": (
        lambda v: pftrack.smooth_tracks(ROWS, fill_method=v),  # type: ignore[arg-type]
        "smooth_tracks: fill_method",
    ),
    "complete_boxes(anchor)": (
        lambda v: complete_boxes(ROWS, np.zeros((2, 2)), 0.5, anchor=v),  # type: ignore[arg-type]
        "complete_boxes: anchor",
    ),
    "make_busy_scene(kind)": (lambda v: make_busy_scene(v), "make_busy_scene: kind"),  # type: ignore[arg-type]
    "evaluate_mot(benchmark)": (
        lambda v: pftrack.evaluate_mot(ROWS, ROWS, benchmark=v),  # type: ignore[arg-type]
        "evaluate_mot: benchmark",
    ),
    "evaluate_hota(benchmark)": (
        lambda v: pftrack.evaluate_hota(ROWS, ROWS, benchmark=v),  # type: ignore[arg-type]
        "evaluate_hota: benchmark",
    ),
    "evaluate_sequence(benchmark)": (
        lambda v: pftrack.evaluate_sequence(ROWS, ROWS, benchmark=v),  # type: ignore[arg-type]
        "evaluate_sequence: benchmark",
    ),
    "prepare_mot(benchmark)": (lambda v: prepare_mot(ROWS, ROWS, benchmark=v), "benchmark"),  # type: ignore[arg-type]
    "FilterConfig(kernel)": (lambda v: FilterConfig(kernel=v), "FilterConfig: kernel"),  # type: ignore[arg-type]
    "FilterConfig(estimate)": (lambda v: FilterConfig(estimate=v), "FilterConfig: estimate"),  # type: ignore[arg-type]
    "RJMCMCConfig(kernel)": (lambda v: RJMCMCConfig(kernel=v), "RJMCMCConfig: kernel"),  # type: ignore[arg-type]
    "fill_gaps(method)": (lambda v: fill_gaps(ROWS, v), "fill_gaps: method"),  # type: ignore[arg-type]
    "recover_gap(method)": (
        lambda v: recover_gap(SEG, SEG + [5, 0, 0], method=v),  # type: ignore[arg-type]
        "recover_gap: method",
    ),
    "recover_gaps(method)": (
        lambda v: recover_gaps([(SEG, SEG + [5, 0, 0])], v),  # type: ignore[arg-type]
        "recover_gaps: method",
    ),
    "estimate_noise(method)": (
        lambda v: estimate_noise([SEG], method=v),  # type: ignore[arg-type]
        "estimate_noise: method",
    ),
    "goal_directed_path(form)": (
        lambda v: goal_directed_path(*[np.eye(2)] * 6, np.zeros(2), 3, form=v),  # type: ignore[arg-type]
        "goal_directed_path: form",
    ),
    "trajectories(point)": (lambda v: trajectories(ROWS, point=v), "trajectories: point"),  # type: ignore[arg-type]
    "calibrate(candidates)": (
        lambda v: calibrate([SEG], [3], candidates=[v]),  # type: ignore[list-item]
        "calibrate: candidate",
    ),
    "edge_support(statistic)": (
        lambda v: edge_support(
            _frame(),
            np.zeros((48, 64), np.float32),
            np.zeros((48, 64), np.uint8),
            np.zeros((0, 4)),
            statistic=v,  # type: ignore[arg-type]
        ),  # fmt: skip
        "edge_support: statistic",
    ),
    "PaperConfig(ghost_statistic)": (
        lambda v: PaperConfig(ghost_statistic=v),  # type: ignore[arg-type]
        "ghost_statistic",
    ),
    "VideoWriter(preset)": (
        lambda v: pftrack.VideoWriter("never-written.mp4", 10, preset=v),  # type: ignore[arg-type]
        "preset",
    ),
    "VideoWriter(backend)": (
        lambda v: pftrack.VideoWriter("never-written.mp4", 10, backend=v),  # type: ignore[arg-type]
        "backend",
    ),
    "TrackOptions(detections)": (lambda v: TrackOptions(detections=v), "detections"),  # type: ignore[arg-type]
    "TrackOptions(fill)": (lambda v: TrackOptions(fill=v), "fill"),  # type: ignore[arg-type]
    "TrackOptions(render)": (lambda v: TrackOptions(render=v), "render"),  # type: ignore[arg-type]
    "RecoverOptions(method)": (lambda v: RecoverOptions(method=v), "method"),  # type: ignore[arg-type]
}


@pytest.mark.parametrize("site", OPTION_SITES, ids=list(OPTION_SITES))
@pytest.mark.parametrize("value", [np.ones((2, 3)), "table"], ids=["array", "table"])
def test_an_array_for_an_option_is_refused_in_one_line(site: str, value: object) -> None:
    """A defect trial: pandas' (or NumPy's) "The truth value of a DataFrame is ambiguous",
    naming no argument, from the option's ``not in`` test."""
    if isinstance(value, str):
        pd = pytest.importorskip("pandas")
        value = pd.DataFrame(np.ones((2, 3)))
    call, what = OPTION_SITES[site]
    with pytest.raises(TypeError) as info:
        call(value)
    message = str(info.value)
    assert "\n" not in message, message
    expected = message.removeprefix(f"{what} must be ").split(", got ")[0]
    assert expected != message and expected.count("'") >= 2, message  # the accepted values
    assert message.endswith(f"got {type(value).__name__} of shape (2, 3)"), message


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: TrackWriter(fill="spline"), "fill is 'spline', expected 'linear' or 'pf'"),
        (lambda: TrackOptions(render=".mkv"), "render is '.mkv', expected None, '.mp4'"),
        (lambda: FilterConfig(kernel="gauss"), "FilterConfig: kernel is 'gauss', expected"),
    ],
)
def test_an_unknown_option_text_is_still_a_value_error(
    call: Callable[[], object], message: str
) -> None:
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(".", r"\.")):
        call()


@pytest.mark.parametrize("value", [None, ".mp4", ".avi"])
def test_the_options_none_accepts_are_taken(value: str | None) -> None:
    assert TrackOptions(render=value).render == value
    assert TrackOptions(detections=None).detections is None


#: Settings whose refusal printed the value's repr: an array's or a DataFrame's took a line
#: of the message per row. A call with the setting's value `v`, and the setting's name.
REPR_SITES: dict[str, tuple[Callable[[object], object], str]] = {
    "LinkConfig(max_gap)": (lambda v: pftrack.LinkConfig(max_gap=v), "LinkConfig.max_gap"),  # type: ignore[arg-type]
    "LinkConfig(max_distance)": (
        lambda v: pftrack.LinkConfig(max_distance=v),  # type: ignore[arg-type]
        "LinkConfig.max_distance",
    ),
    "LinkConfig(max_area_ratio)": (
        lambda v: pftrack.LinkConfig(max_area_ratio=v),  # type: ignore[arg-type]
        "LinkConfig.max_area_ratio",
    ),
    "link_tracklets(config)": (lambda v: link_tracklets(ROWS, v), "link_tracklets: config"),  # type: ignore[arg-type]
    "Tracker(max_side)": (lambda v: pftrack.Tracker(max_side=v), "max_side"),  # type: ignore[arg-type]
    "TrackerConfig(open_size)": (
        lambda v: TrackerConfig(open_size=v),  # type: ignore[arg-type]
        "TrackerConfig: open_size",
    ),  # type: ignore[arg-type]
    "TrackerConfig(pixel_diagonal)": (
        lambda v: TrackerConfig(pixel_diagonal=v),  # type: ignore[arg-type]
        "TrackerConfig: pixel_diagonal",
    ),
    "CameraConfig(max_side)": (lambda v: CameraConfig(max_side=v), "CameraConfig: max_side"),  # type: ignore[arg-type]
    "MotionConfig(speed_span)": (
        lambda v: MotionConfig(speed_span=v),  # type: ignore[arg-type]
        "MotionConfig: speed_span",
    ),
    "RefineConfig(upright_classes)": (
        lambda v: RefineConfig(upright_classes=v),  # type: ignore[arg-type]
        "RefineConfig: upright_classes",
    ),
    "CrossingConfig(enabled)": (lambda v: CrossingConfig(enabled=v), "CrossingConfig: enabled"),  # type: ignore[arg-type]
    "CrossingConfig(join_gap)": (
        lambda v: CrossingConfig(join_gap=v),  # type: ignore[arg-type]
        "CrossingConfig: join_gap",
    ),
    "smooth_tracks(link)": (lambda v: pftrack.smooth_tracks(ROWS, link=v), "smooth_tracks: link"),  # type: ignore[arg-type]
    "smooth_tracks(relink_coast)": (
        lambda v: pftrack.smooth_tracks(ROWS, relink_coast=v),  # type: ignore[arg-type]
        "smooth_tracks: relink_coast",
    ),
    "make_scene(n_frames)": (lambda v: pftrack.make_scene(n_frames=v), "make_scene: n_frames"),  # type: ignore[arg-type]
    "make_scene(width)": (lambda v: pftrack.make_scene(width=v), "make_scene: width"),  # type: ignore[arg-type]
    "make_scene(n_walkers)": (
        lambda v: pftrack.make_scene(n_walkers=v),  # type: ignore[arg-type]
        "make_scene: n_walkers",
    ),
    "plot_trajectories(size)": (
        lambda v: pftrack.plot_trajectories("never-written.png", ROWS, size=v),  # type: ignore[arg-type]
        "plot_trajectories: size",
    ),
    "plot_trajectories(title)": (
        lambda v: pftrack.plot_trajectories("never-written.png", ROWS, title=v),  # type: ignore[arg-type]
        "plot_trajectories: title",
    ),
    "draw_tracks(label)": (
        lambda v: draw_tracks(_frame(), ROWS, label=v),  # type: ignore[arg-type]
        "draw_tracks: label",
    ),
    "hsv_bins(binning)": (lambda v: pftrack.hsv_bins(_frame(), binning=v), "hsv_bins: binning"),  # type: ignore[arg-type]
    "RJMCMCFilter(config)": (lambda v: RJMCMCFilter(config=v), "RJMCMCFilter: config"),  # type: ignore[arg-type]
    "BlobConfig(open_size)": (lambda v: BlobConfig(open_size=v), "BlobConfig: open_size"),  # type: ignore[arg-type]
    "RecoverOptions(max_gap)": (
        lambda v: RecoverOptions(max_gap=v),  # type: ignore[arg-type]
        "RecoverOptions: max_gap",
    ),  # type: ignore[arg-type]
    "TrackOptions(seed)": (lambda v: TrackOptions(seed=v), "TrackOptions: seed"),  # type: ignore[arg-type]
    "track_many(options)": (
        lambda v: pftrack.batch.track_many([], "never-written", options=v),  # type: ignore[arg-type]
        "track_many: options",
    ),
}


@pytest.mark.parametrize("site", REPR_SITES, ids=list(REPR_SITES))
@pytest.mark.parametrize("value", [np.ones((2, 3)), "table"], ids=["array", "table"])
def test_an_array_for_a_setting_is_named_in_one_line(site: str, value: object) -> None:
    """A defect trial: these messages held the value's whole repr, one line of it per row (a
    DataFrame's header too), after the setting's name."""
    if isinstance(value, str):
        pd = pytest.importorskip("pandas")
        value = pd.DataFrame(np.ones((2, 3)))
    call, what = REPR_SITES[site]
    with pytest.raises((TypeError, ValueError)) as info:
        call(value)
    message = str(info.value)
    assert "\n" not in message, message
    assert message.startswith(f"{what} "), message
    assert f"{type(value).__name__} of shape (2, 3)" in message, message


def test_a_repr_of_one_line_is_kept() -> None:
    with pytest.raises(ValueError, match=r"^LinkConfig\.max_gap is 0, expected an int in 1\.\."):
        pftrack.LinkConfig(max_gap=0)
    with pytest.raises(TypeError, match=r"^link_tracklets: config must be a LinkConfig, got "):
        link_tracklets(ROWS, "tight")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"^plot_trajectories: size is \(0, 4\), expected"):
        pftrack.plot_trajectories("never-written.png", ROWS, size=(0, 4))


#: Number settings compared with their range (``0 <= v <= 1``) without being checked as
#: numbers first: an array or a DataFrame was asked for its truth ("The truth value ... is
#: ambiguous", naming nothing), and a str failed with "'<=' not supported".
NUMBER_SITES: dict[str, tuple[Callable[[object], object], str]] = {
    **{
        f"{cls.__name__}({name})": (
            (lambda c, n: lambda v: c(**{n: v}))(cls, name),
            f"{cls.__name__}: {name}",
        )
        for cls, name in (
            (BlobConfig, "min_area"),
            (BlobConfig, "split_valley"),
            (PaperConfig, "ghost_support"),
            (PaperConfig, "gain_band"),
        )
    },
    "CrossingConfig(min_iou)": (lambda v: CrossingConfig(min_iou=v), "CrossingConfig: min_iou"),  # type: ignore[arg-type]
    "CrossingConfig(margin)": (lambda v: CrossingConfig(margin=v), "CrossingConfig: margin"),  # type: ignore[arg-type]
    "drop_nested(inside)": (lambda v: drop_nested(ROWS, inside=v), "drop_nested: inside"),  # type: ignore[arg-type]
    "drop_nested(area_ratio)": (
        lambda v: drop_nested(ROWS, area_ratio=v),  # type: ignore[arg-type]
        "drop_nested: area_ratio",
    ),
    "complete_boxes(share)": (
        lambda v: complete_boxes(ROWS, np.zeros((2, 2)), v),  # type: ignore[arg-type]
        "complete_boxes: share",
    ),
    "complete_boxes(max_width)": (
        lambda v: complete_boxes(ROWS, np.zeros((2, 2)), 0.5, max_width=v),  # type: ignore[arg-type]
        "complete_boxes: max_width",
    ),
    "camera_path(zoom)": (lambda v: camera_path(5, (48, 64), zoom=v), "camera_path: zoom"),  # type: ignore[arg-type]
    "camera_path(period)": (lambda v: camera_path(5, (48, 64), period=v), "camera_path: period"),  # type: ignore[arg-type]
    # these took an array or a DataFrame without a word (PaperConfig's went to the C++
    # background model, GdtModel's to the recovery), or asked it for its truth
    **{
        f"PaperConfig({name})": (
            (lambda n: lambda v: PaperConfig(**{n: v}))(name),
            f"PaperConfig: {name}",
        )
        for name in "alpha alpha_fg k_noise t_min t_max low_ratio shadow_lo shadow_chroma".split()
    },
    **{
        f"SizeModelConfig({name})": (
            (lambda n: lambda v: SizeModelConfig(**{n: v}))(name),
            f"SizeModelConfig: {name}",
        )
        for name in ("split_ratio", "split_max_height", "merge_slack", "max_cut_share")
    },
    "GdtModel(dt)": (lambda v: GdtModel(dt=v), "GdtModel: dt"),  # type: ignore[arg-type]
    "GdtModel(p_init_velocity)": (
        lambda v: GdtModel(p_init_velocity=v),  # type: ignore[arg-type]
        "GdtModel: p_init_velocity",
    ),
}


@pytest.mark.parametrize("site", NUMBER_SITES, ids=list(NUMBER_SITES))
@pytest.mark.parametrize("value", [np.ones((2, 3)), "table", "0.5"], ids=["array", "table", "text"])
def test_a_number_setting_refuses_what_is_no_number_in_one_line(site: str, value: object) -> None:
    if isinstance(value, str) and value == "table":
        pd = pytest.importorskip("pandas")
        value = pd.DataFrame(np.ones((2, 3)))
    call, what = NUMBER_SITES[site]
    with pytest.raises(TypeError) as info:
        call(value)
    message = str(info.value)
    assert "\n" not in message, message
    assert message.startswith(f"{what} must be a number, got "), message


def test_the_threaded_flag_of_a_renderer_is_checked() -> None:
    for value in (np.ones((2, 3)), "no"):
        with pytest.raises(TypeError, match=r"^threaded must be True or False, got "):
            pftrack.TrackRenderer("never-written.mp4", 10, threaded=value)  # type: ignore[arg-type]


#: Settings that are configs of their own: an array, a DataFrame or a name given for one was
#: taken, and failed at the first frame on a missing attribute naming no setting.
SUB_CONFIG_SITES: dict[str, tuple[Callable[[object], object], str, str]] = {
    **{
        f"TrackerConfig({name})": (
            (lambda n: lambda v: TrackerConfig(**{n: v}))(name),
            f"TrackerConfig: {name}",
            type(getattr(TrackerConfig(), name)).__name__,
        )
        for name in (
            "filter",
            "binning",
            "rjmcmc",
            "refine",
            "association",
            "motion",
            "lifecycle",
            "camera",
            "crossings",
        )  # fmt: skip
    },
    "FilterConfig(model)": (lambda v: FilterConfig(model=v), "FilterConfig: model", "Ar2Model"),  # type: ignore[arg-type]
    "PaperConfig(blobs)": (lambda v: PaperConfig(blobs=v), "PaperConfig: blobs", "BlobConfig"),  # type: ignore[arg-type]
    "PaperConfig(hsv)": (lambda v: PaperConfig(hsv=v), "PaperConfig: hsv", "HsvBinning"),  # type: ignore[arg-type]
    "Mog2Config(blobs)": (lambda v: Mog2Config(blobs=v), "Mog2Config: blobs", "BlobConfig"),  # type: ignore[arg-type]
    "KnnConfig(hsv)": (lambda v: KnnConfig(hsv=v), "KnnConfig: hsv", "HsvBinning"),  # type: ignore[arg-type]
}


@pytest.mark.parametrize("site", SUB_CONFIG_SITES, ids=list(SUB_CONFIG_SITES))
@pytest.mark.parametrize(
    "value", [np.ones((2, 3)), "table", "tight"], ids=["array", "table", "text"]
)
def test_a_sub_config_refuses_what_is_not_its_class(site: str, value: object) -> None:
    if isinstance(value, str) and value == "table":
        pd = pytest.importorskip("pandas")
        value = pd.DataFrame(np.ones((2, 3)))
    call, what, cls = SUB_CONFIG_SITES[site]
    with pytest.raises(TypeError) as info:
        call(value)
    message = str(info.value)
    assert "\n" not in message, message
    assert message.startswith(f"{what} must be a {cls}, got "), message


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda v: BlobConfig(learn_size=v), "BlobConfig: learn_size must be True or False, got "),
        (
            lambda v: PaperConfig(gain_thresholds=v),
            "PaperConfig: gain_thresholds must be True or False, got ",
        ),
        (
            lambda v: PaperConfig(n_learn=v),
            r"PaperConfig: n_learn must be an integer in \[0, 2147483647\], got ",
        ),
        (
            lambda v: pftrack.read_mot("never-read.txt", what=v),
            "read_mot: what must be a str, got ",
        ),
    ],
)
@pytest.mark.parametrize("value", [np.ones((2, 3)), "table"], ids=["array", "table"])
def test_flags_counts_and_labels_once_taken_are_refused(
    call: Callable[[object], object], message: str, value: object
) -> None:
    """These took an array or a DataFrame (a flag on, a count for the C++ model, a label
    written into every message about the file)."""
    if isinstance(value, str):
        pd = pytest.importorskip("pandas")
        value = pd.DataFrame(np.ones((2, 3)))
    with pytest.raises(TypeError, match=f"^{message}") as info:
        call(value)
    assert str(info.value).endswith(f"got {type(value).__name__} of shape (2, 3)")


def test_the_gdt_model_takes_any_sequence_of_its_noises_and_refuses_other_shapes() -> None:
    model = GdtModel(q=np.array([1e-6, 1e-6, 1e-4, 1e-4]), r=[1e-6, 1e-6])  # type: ignore[arg-type]
    assert model == GdtModel() and model.q == (1e-6, 1e-6, 1e-4, 1e-4) and hash(model)
    with pytest.raises(ValueError, match=r"^GdtModel: q has shape \(2, 3\), expected \(4,\)$"):
        GdtModel(q=np.ones((2, 3)))  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"^GdtModel: r has shape \(3,\), expected \(2,\)$"):
        GdtModel(r=(1.0, 1.0, 1.0))  # type: ignore[arg-type]
    with pytest.raises(TypeError, match=r"^GdtModel: r must hold real numbers, got dtype <U"):
        GdtModel(r=("a", "b"))  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"^GdtModel: q is \(nan, 1.0, 1.0, 1.0\), expected"):
        GdtModel(q=(np.nan, 1.0, 1.0, 1.0))
