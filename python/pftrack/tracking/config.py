"""Settings of :class:`~pftrack.tracking.MultiObjectTracker`, one small dataclass per concern.

Every default is a rule, not a per-sequence tuning (measured in docs/results.md).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace

import numpy as np

from pftrack._check import (
    MAX_FRAME,
    brief,
    flag,
    instance,
    integer,
    listed,
    number,
    option,
    real_array,
    shown,
)
from pftrack._limits import (
    DEFAULT_MH_ITER,
    DEFAULT_MH_PROPOSAL,
    DEFAULT_MH_RW_SIGMA,
    MAX_BURN_IN,
    MAX_MH_ITER,
    MAX_MH_RW_SIGMA,
    MAX_PARTICLES,
    MH_PROPOSALS,
    joint_samples_error,
    proposal_error,
)
from pftrack._typing import CameraMotion, DetectorName, SamplerName
from pftrack.detection import DETECTOR_CONFIGS, DETECTORS, KnnConfig, Mog2Config, PaperConfig
from pftrack.particle_filter import Ar2Model, FilterConfig, HsvBinning, RJMCMCConfig
from pftrack.recovery.linking import REFERENCE_DIAGONAL, pixel_scale
from pftrack.tracking.offline import AMODAL_ANCHORS, NOISE_MAX, NOISE_MIN, CrossingConfig

__all__ = [
    "AssociationConfig",
    "CameraConfig",
    "LifecycleConfig",
    "MotionConfig",
    "RefineConfig",
    "TrackerConfig",
]

SAMPLERS = ("sis", "mh", "rjmcmc")
#: Values of :attr:`TrackerConfig.camera_motion`.
CAMERA_MOTION = ("auto", "on", "off")
#: Bounds of :attr:`TrackerConfig.max_side` (pixels).
MIN_SIDE, MAX_SIDE = 64, 100_000
#: Largest :attr:`TrackerConfig.open_size` (pixels).
MAX_OPEN_SIZE = 255
#: Default of :attr:`TrackerConfig.pixel_diagonal`: a 640x480 frame's diagonal (pixels).
PIXEL_DIAGONAL = REFERENCE_DIAGONAL
#: The particle filter's position noise holds down to frames of this diagonal (480x360) and
#: shrinks in proportion on smaller ones (:meth:`TrackerConfig.noise_scale`).
SMALL_DIAGONAL = 600.0
#: Default of :attr:`TrackerConfig.given_particles`: particles per object with given detections.
GIVEN_PARTICLES = 200


def _numbers(owner: str, config: object, *names: str) -> None:
    """Refuse the named settings unless numbers, with a TypeError naming them.

    None passes only for a field whose annotation takes it (``float | None``: off). Text
    failed at a comparison without a name (``'<=' not supported``), or was taken; None for a
    plain ``float`` field (``MotionConfig(accel=None)``) failed likewise (developer trial).
    """
    optional = {f.name for f in fields(config) if "None" in str(f.type)}  # type: ignore[arg-type]
    for name in names:
        v = getattr(config, name)
        if v is not None or name not in optional:
            number(v, f"{owner}: {name}", finite=False)


def _in_unit_interval(owner: str, **values: float) -> None:
    for name, v in values.items():
        if not 0.0 <= number(v, f"{owner}: {name}", finite=False) <= 1.0:
            raise ValueError(f"{owner}: {name} is {v}, expected a value in [0, 1]")


def _integers_at_least(owner: str, lo: int, config: object, *names: str) -> None:
    """Each field an int >= `lo`: TypeError for another type (as ``_check.integer``).

    Raises
    ------
    TypeError
        A field that is not an int (a float, a string, a bool).
    ValueError
        An int < `lo`.
    """
    for name in names:
        v = getattr(config, name)
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)):
            raise TypeError(f"{owner}: {name} must be an integer >= {lo}, got {shown(v)}")
        if v < lo:
            raise ValueError(f"{owner}: {name} is {brief(v)}, expected an integer >= {lo}")


def _in_range(
    owner: str, name: str, v: float, lo: float, hi: float = np.inf, *, low_open: bool = False
) -> None:
    """Refuse `v` (a number, checked by :func:`_numbers`) outside ``[lo, hi]`` (``(lo, hi]``).

    NaN fails; an infinite `hi` is excluded (``hi=np.inf``: a finite value >= (>) `lo`).
    """
    above = lo < v if low_open else lo <= v
    if not (above and v <= hi and np.isfinite(v)):
        bound = f"> {lo:g}" if low_open else f">= {lo:g}"
        expected = (
            f"a finite value {bound}"
            if hi == np.inf
            else (f"a value in {'(' if low_open else '['}{lo:g}, {hi:g}]")
        )
        raise ValueError(f"{owner}: {name} is {v}, expected {expected}")


#: ``RJMCMCConfig`` settings the tracker replaces with its per-object filters' (``joint_config``),
#: with the ``FilterConfig`` setting that gives each.
_JOINT_FROM_FILTER = {
    "n_samples": "filter.n_particles (Tracker's particles)",
    "a": "filter.model (Ar2Model's velocity_gain)",
    "b": "filter.model (Ar2Model's velocity_gain)",
    "sigma": "filter.model (Ar2Model's sigma_xy, sigma_s)",
    "s_min": "filter.model.s_min",
    "s_max": "filter.model.s_max",
}


def _joint_settings_used(config: TrackerConfig) -> None:
    """Refuse an ``rjmcmc`` setting the tracker would replace with its filter's, so do nothing.

    The joint sampler takes its sample count and AR(2) dynamics from ``filter`` (so that only
    the sampler differs between sis, mh and rjmcmc); any other value than RJMCMCConfig's default
    was dropped without a word (``RJMCMCConfig(n_samples=500)`` ran 100 samples).
    """
    default = RJMCMCConfig()
    for name, where in _JOINT_FROM_FILTER.items():
        v = getattr(config.rjmcmc, name)
        if np.array_equal(v, getattr(default, name)):
            continue
        shown_v = list(np.asarray(v, float).tolist()) if name in ("a", "b", "sigma") else v
        raise ValueError(
            f"TrackerConfig: rjmcmc.{name} is {shown_v}, but the joint sampler takes it from "
            f"{where}, so it would do nothing: set it there (the same budget and dynamics for "
            "every sampler)"
        )


#: The name of each built-in detector's settings class (:attr:`TrackerConfig.detector_name`).
_DETECTOR_NAMES: dict[type, DetectorName] = {
    cls: name  # type: ignore[misc]
    for name, cls in DETECTOR_CONFIGS.items()
}


def hsv_disagrees(detector: PaperConfig | Mog2Config | KnnConfig, binning: HsvBinning) -> bool:
    """Whether settings given as a detector bin colour unlike a tracker of `binning`.

    The foreground bins and the histograms share one layout: the detector's `hsv` must be
    ``HsvBinning()`` (replaced by `binning`) or `binning` itself. ``TrackerConfig`` and
    ``Tracker`` test this one condition, each saying what its caller can set.
    """
    return detector.hsv != HsvBinning() and detector.hsv != binning


def _detector_settings_agree(config: TrackerConfig) -> None:
    """Refuse settings given as `config.detector` that `config`'s own would contradict.

    Its `hsv` is the tracker's `binning` (the foreground bins and the histograms share one
    layout): ``HsvBinning()`` (replaced) or `binning` itself. `open_size` and `hold_frames`,
    when set on `config`, apply on top: the settings must leave them unset or agree.
    """
    d = config.detector
    assert not isinstance(d, str)
    kind = type(d).__name__
    if hsv_disagrees(d, config.binning):
        raise ValueError(
            f"TrackerConfig: detector's hsv is {d.hsv}, but the detector bins colour as the "
            f"tracker does: set binning={d.hsv} and leave the {kind}'s hsv at its default"
        )
    size = config.open_size
    if size is not None and d.blobs.open_size not in (None, size):
        raise ValueError(
            f"TrackerConfig: open_size is {size} and detector's blobs.open_size is "
            f"{d.blobs.open_size}: give it once"
        )
    hold = getattr(d, "hold_frames", 0)
    if config.hold_frames and hold not in (0, config.hold_frames):
        raise ValueError(
            f"TrackerConfig: hold_frames is {config.hold_frames} and detector's hold_frames is "
            f"{hold}: give it once"
        )


def _none_or_int_in(
    owner: str, config: object, name: str, lo: int, hi: int, none: str = "None"
) -> None:
    """`config.name` must be None or an int (not a bool) in [lo, hi] (`none`: None's name)."""
    v = getattr(config, name)
    if v is not None and (
        isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not lo <= v <= hi
    ):
        raise ValueError(
            f"{owner}: {name} is {brief(v)}, expected {none} or an int in [{lo}, {hi}]"
        )


@dataclass(frozen=True)
class AssociationConfig:
    """How tracks and detections are paired (Hungarian method over a gated cost).

    Attributes
    ----------
    match_iou : float
        Minimum overlap (IoU) for a track-detection pair, unless the centres are close.
    match_distance : float
        Maximum centre distance of a pair, in track heights (grows with the time coasted); finite
        and > 0 (the cost divides by it).
    colour_weight : float
        Weight of colour dissimilarity ``1 - rho`` in the association cost; finite and >= 0.
    unmatched_cost : float
        What leaving a track or a detection unassigned costs: a pair is made only when its cost
        is below twice this, not merely because it passed the gate. The default 1.5 refuses a
        pair that neither overlaps nor lies within two radii whatever its colour (those two
        terms alone reach 3); ``inf`` assigns every gated pair it can.
    merge_ratio : float
        A matched detection this many times larger than its track, that also covers another
        track of its class (the centre of its box), is a merged blob: it does not re-seed the
        track's particles (the colour filter carries the track through the merge). At least 1
        (a smaller detection is no merge); ``inf``: off.

    Raises
    ------
    TypeError
        A setting that is not a number.
    ValueError
        A setting out of its range above (NaN included).
    """

    match_iou: float = 0.1
    match_distance: float = 0.3
    colour_weight: float = 0.5
    unmatched_cost: float = 1.5
    merge_ratio: float = 1.8

    def __post_init__(self) -> None:
        names = ("match_iou", "match_distance", "colour_weight", "unmatched_cost", "merge_ratio")
        _numbers("AssociationConfig", self, *names)
        if not self.unmatched_cost > 0:  # NaN fails too
            raise ValueError(
                f"AssociationConfig: unmatched_cost is {self.unmatched_cost}, expected a value > 0 "
                "(inf: off)"
            )
        _in_unit_interval("AssociationConfig", match_iou=self.match_iou)
        _in_range("AssociationConfig", "match_distance", self.match_distance, 0.0, low_open=True)
        _in_range("AssociationConfig", "colour_weight", self.colour_weight, 0.0)
        if not (self.merge_ratio >= 1.0):  # NaN fails too; inf: off
            raise ValueError(
                f"AssociationConfig: merge_ratio is {self.merge_ratio}, expected a value >= 1 "
                "(inf: off)"
            )


@dataclass(frozen=True)
class LifecycleConfig:
    """When tracks are born, reported and ended.

    Attributes
    ----------
    min_score : float
        Detections with a lower score are ignored (``min_conf`` of :class:`pftrack.Tracker`,
        ``--min-conf``).
    min_area : float
        A detection smaller than this many pixels (width x height, in the tracker's pixels)
        and clear of the frame's border is ignored, as one below `min_score`: a colour
        reference of 110 bins from fewer pixels than an 8x8 box says little, and a detector's
        speckle of tiny boxes otherwise starts tracks and pulls others (PETS09-S2L1 with 60
        random boxes of 2-6 px a frame added to its public detections: MOTA 31.3, and 77.9
        with this rule, as without the speckle; docs/tracking.md). A small box touching the
        border is kept: an object entering or leaving the frame. 0 keeps every box.
    birth_score : float
        In [0, 1]. An external detection starts a track only with at least this score (a
        detection too unsure to start a track can still keep one alive, as in ByteTrack). Applied
        while every score kept (at least `min_score`) lies in [0, 1], i.e. scores are
        confidences (a warning says when they stop being: from then on a detector with other
        scores starts tracks from any detection it keeps, as the built-in detector does). With
        `birth_quantile` this is a cap: the threshold is relative to the detector (see there).
    birth_quantile : float or None
        Make the birth threshold relative to the detector: ``min(birth_score, q)`` where ``q``
        is this quantile of the scores (at least `min_score`) seen over `birth_window` frames
        from the first with such a score (a scene empty at first, a street before anyone walks
        in, learns from its first detections; was: the run's first frames, after which a
        detector scoring below `birth_score` started no track at all), updated each frame
        until then and fixed afterwards. The default
        0.25 (the lower quartile) keeps 0.9 for a detector whose scores mostly lie above it
        (PETS09 and TUD-Campus public detections: the quartile of their first 50 frames never
        falls below 0.96 and 0.91) and lets a detector whose scores all lie in [0.2, 0.5] start
        tracks from its upper three quarters (measured in docs/tracking.md; 0.25 scored better
        than the median on both sequences). With classes (``classes`` of
        :meth:`MultiObjectTracker.update`) each class with
        :data:`~pftrack.tracking.tracker.MIN_CLASS_BIRTH_SCORES` scores over the window takes
        the quantile of its own (a detector may score bicycles at 0.3-0.5 beside people at
        0.8-0.95), a class with fewer the quantile of every class's until it has that many,
        whenever that is (when the window held another class's scores: a run of one class
        keeps the window's level). None: `birth_score` as is.
    birth_window : int
        Frames over which the score distribution is learned (2 s at 25 frames/s), >= 1,
        from the first frame with a score of at least `min_score`.
    min_hits : int
        Matched frames before a new track is reported (tracks born in the first `min_hits`
        frames are reported at once), >= 0.
    max_coast : int
        Frames a track goes on from its particle filter alone before it ends, >= 0.
    tentative_coast : int
        Frames with detections a not yet confirmed track may go without one of them before it
        is dropped. A frame without any detection (the detector did not run, or saw nothing)
        does not count: with a detector run every other frame, no track was confirmed before
        (docs/tracking.md, "Lower frame rates and sparse detections"). It still ends after
        `max_coast` frames without a match. At least 0.
    coast_min_rho : float
        A coasting track is reported only while its colour match ``rho`` stays above this.
    relink_coast : int or None
        With given detections, the offline pass (with linking) cuts a track where a detection
        re-finds it after at least this many frames carried by its particle filter alone,
        leaves those frames out, and lets the linker decide whether the two pieces are one
        object (:func:`pftrack.tracking.offline.split_refound`): a filter that coasted that
        long may have drifted onto another person, whose detection then re-found the track. A
        kept join gets the frames back, filled as any hole. The built-in detector's tracks are
        left alone: they coast through merged blobs, where the colour filter is what carries
        them. None: off; else at least 1.
    nested_inside, nested_area : float or None
        With the built-in detector, the offline pass leaves out every box that lies by more than
        `nested_inside` of its area inside a box of the same frame more than `nested_area`
        times larger (:func:`pftrack.tracking.offline.drop_nested`): background subtraction
        gives one box per silhouette, so such a box is a fragment of the larger one. Given
        detections are left alone (a box inside a larger one is then often a partly hidden
        person). None: off. The defaults are the best of a grid over every scene with ground
        truth (docs/detection.md).
    amodal_share : float or None
        With the built-in detector, after `nested_inside`, the offline pass completes every
        box shorter (narrower) than `amodal_share` of the person the detector's size model
        expects with its head at the box's top to that person's height (width)
        (:func:`pftrack.tracking.offline.complete_boxes`): background subtraction boxes only
        the visible part of a partly hidden person, ground truth the whole person. Groups
        (wider than 1.6 persons), boxes at the frame's top edge (their top is no head),
        persons whose feet would be below the frame, and given detections are left alone.
        None: off. The default (0.8, ``"side"``) is the best of a grid over every scene with
        ground truth (docs/detection.md).
    amodal_anchor : {"side", "centre"}
        Which edge a widened box keeps: ``"side"`` grows it towards the one side that lies
        inside another box (the hidden side), else about its centre; ``"centre"`` always about
        its centre.
    blind_coast : int or None
        A track ends after more than this many frames with detections in a row coasted blind:
        its colour filter's likelihood flat on each (every particle matching the reference
        alike). With given detections that is a black or one-colour frame (a loop with only
        boxes passes black frames) or a box with no counted pixel: the track's box is then the
        centre filter's constant-velocity extrapolation alone, which the camera's own motion (a
        walker's camera, a car's) carries off the person while the association radius grows;
        the detection that re-finds it is then often another person's, and its coasted rows
        filled between the two are false positives. With the built-in detector, whose colour
        bins count foreground pixels only, it is a coast with no foreground pixel under any
        particle: the object has left the foreground (gone, or hidden whole), and the track
        drifts over background. The offline linker, which sees both pieces, decides whether
        the detection that re-finds the object continues it. A coast on which the colour
        carried evidence is not blind and keeps `max_coast`. At least 0; None: off. The default
        3 passed the adoption rule over every sequence with public detections, and then over
        every sequence and scene of the built-in detector (docs/tracking.md, "Blind coasts end
        after 3 frames").
    birth_overlap : float or None
        With given detections, a detection left unmatched that overlaps by an IoU above this a
        track of its class (confirmed or tentative), a detection of its class matched to a
        track on this frame, or one of its class that started a track on this frame (higher
        scored: births go highest score first) starts no track: it is a second box on a person
        already followed (a duplicate the detector's non-maximum suppression let through, the
        same box twice from a detector without it or from two detectors' outputs
        concatenated, or a part of the person), which otherwise became a second track beside
        the first and, where the two then swapped, an identity switch (until 6 December only
        confirmed tracks counted, and each duplicated box started two tracks). The built-in
        detector's objects are left alone. Every sampler follows it (``"rjmcmc"``: no newborn
        slot; since 6 December). A row given twice exactly (the same box and class) is one
        detection whatever this is. In (0, 1]; None: off. The default 0.3 was chosen
        over every sequence with public detections (docs/tracking.md, "Births beside a
        tracked person"); 0.5 and above change nothing there, since a detection that overlaps
        a track that much is matched to it.
    size_ratio : float or None
        With given detections, the offline pass (with the smoother on) leaves out every track
        whose median box height is below `size_ratio`, or above ``1 / size_ratio``, times the
        height the run's detections of its class have at its foot row (a Theil-Sen line of
        height against foot row; :func:`pftrack.tracking.offline.drop_odd_sizes`): tracks that
        followed a detector's confident false boxes (a part of a person, something that is no
        person) are often sized unlike the scene's people. So are a child, a seated person, a
        person on stairs, and every person of a scene whose people's sizes do not follow their
        row. Rows outside the 5th-95th percentile of the detections' foot rows are not judged
        (no extrapolation), the rule does not run once the camera was found moving (the line
        is a still camera's), and a class is judged only if the line explains its detections'
        heights: two robust spreads of ``log(height / line)`` plus half its drift over the run
        within ``log(1 / size_ratio)`` (:func:`pftrack.tracking.offline.size_line`; people whose
        sizes do not follow the row, a camera that zooms). In (0, 1); None: off. The default
        0.8 (6 December) passed two check sets fixed before measuring (no row below off by more
        than 0.3; ``experiments.size_check``) and every sequence with public detections (none
        below off): TUD-Campus 75.2 -> 79.4 MOTA, pooled 63.8 -> 63.9; the guard leaves
        ADL-Rundle-6 and ETH-Sunnyday, whose people's sizes spread about the line, alone
        (docs/tracking.md, "Tracks sized unlike the scene's people").

    Raises
    ------
    TypeError
        A number setting that is not a number.
    ValueError
        A setting out of its range above; a frame count that is not an int (not a bool) in
        [lo, 2147483647].
    """

    min_score: float = 0.0
    min_area: float = 64.0
    birth_score: float = 0.9
    birth_quantile: float | None = 0.25
    birth_window: int = 50
    min_hits: int = 4
    max_coast: int = 10
    tentative_coast: int = 0
    coast_min_rho: float = 0.5
    relink_coast: int | None = 7
    nested_inside: float | None = 0.7
    nested_area: float = 1.5
    amodal_share: float | None = 0.8
    amodal_anchor: str = "side"
    birth_overlap: float | None = 0.3
    blind_coast: int | None = 3
    size_ratio: float | None = 0.8

    def __post_init__(self) -> None:
        _numbers("LifecycleConfig", self, "min_score", "min_area", "birth_score", "birth_quantile")
        _numbers("LifecycleConfig", self, "coast_min_rho", "nested_inside", "nested_area")
        _numbers("LifecycleConfig", self, "amodal_share", "birth_overlap", "size_ratio")
        for name, lo in (("max_coast", 0), ("min_hits", 0), ("tentative_coast", 0),
                         ("birth_window", 1)):  # fmt: skip
            integer(getattr(self, name), f"LifecycleConfig: {name}", lo, MAX_FRAME)
        if self.relink_coast is not None:
            integer(self.relink_coast, "LifecycleConfig: relink_coast", 1, MAX_FRAME)
        if self.blind_coast is not None:
            integer(self.blind_coast, "LifecycleConfig: blind_coast", 0, MAX_FRAME)
        _in_unit_interval(
            "LifecycleConfig", coast_min_rho=self.coast_min_rho, birth_score=self.birth_score
        )
        if self.nested_inside is not None and not 0.0 < self.nested_inside <= 1.0:
            raise ValueError(
                f"LifecycleConfig: nested_inside is {self.nested_inside}, expected a value in "
                "(0, 1] or None"
            )
        if not 1.0 <= self.nested_area < np.inf:
            raise ValueError(
                f"LifecycleConfig: nested_area is {self.nested_area}, expected a finite value >= 1"
            )
        if self.amodal_share is not None and not 0.0 < self.amodal_share <= 1.0:
            raise ValueError(
                f"LifecycleConfig: amodal_share is {self.amodal_share}, expected a value in "
                "(0, 1] or None"
            )
        option(self.amodal_anchor, "LifecycleConfig: amodal_anchor", AMODAL_ANCHORS)
        if self.amodal_anchor not in AMODAL_ANCHORS:
            raise ValueError(
                f"LifecycleConfig: amodal_anchor is {self.amodal_anchor!r}, expected one of "
                f"{AMODAL_ANCHORS}"
            )
        if self.birth_quantile is not None:
            _in_unit_interval("LifecycleConfig", birth_quantile=self.birth_quantile)
        if self.size_ratio is not None and not 0.0 < self.size_ratio < 1.0:
            raise ValueError(
                f"LifecycleConfig: size_ratio is {self.size_ratio}, expected a value in (0, 1) "
                "or None"
            )
        if self.birth_overlap is not None and not 0.0 < self.birth_overlap <= 1.0:
            raise ValueError(
                f"LifecycleConfig: birth_overlap is {self.birth_overlap}, expected a value in "
                "(0, 1] or None"
            )
        for name in ("min_score", "birth_score"):
            if not np.isfinite(getattr(self, name)):
                raise ValueError(
                    f"LifecycleConfig: {name} is {getattr(self, name)}, expected a finite number"
                )
        if not (np.isfinite(self.min_area) and self.min_area >= 0):
            raise ValueError(
                f"LifecycleConfig: min_area is {self.min_area}, expected a finite value >= 0"
            )


@dataclass(frozen=True)
class MotionConfig:
    """The constant-velocity Kalman filter of each track's centre (:mod:`.motion`).

    Attributes
    ----------
    accel, detection_noise, colour_noise : float
        In track heights: the square root of the acceleration's spectral density (white-noise
        acceleration, per frame^1.5), and the standard deviations of a detection's centre and of
        the colour filter's estimate (the measurement while the track
        coasts, and a second opinion before association; not a measurement when the frame's
        colour carries no evidence, :func:`pftrack.tracking.track.colour_evidence`). `accel` lies
        in [0, 1e6] (0: a constant velocity), the two noises in [1e-6, 1e6] (the Kalman
        update divides by their variance; :class:`~pftrack.tracking.offline.BoxSmoother`'s
        range).
    smooth_external : bool
        With external detections, report a matched track's filtered box (Kalman centre,
        smoothed size) rather than the detection's own box, which jitters from frame to frame.
        The built-in detector's boxes are the foreground's extent and are reported as they are.
    speed_reference : float or None
        The per-frame acceleration levels (`accel` here, and the offline smoother's ``accel``
        and ``size_accel``) hold for objects moving up to this speed, in heights per frame (the
        median speed of the confirmed tracks of a class, measured over `speed_span` frames or
        more: each class its own). For
        faster footage, such as a video at a lower frame rate, they grow as ``(speed /
        speed_reference) ** 1.5``: white-noise acceleration over a frame that lasts `k` times
        longer has `k` cubed the position variance (:meth:`MultiObjectTracker.motion_gain`).
        The default 0.065 lies just above the fastest footage the levels were set on
        (PETS09-S2L1 0.058, KITTI-17 0.062 at their own rates); PETS09-S2L1 at half its rate
        measures 0.11 and tracks at 72.3 MOTA with the rule against 52.8 without
        (docs/tracking.md, "Lower frame rates and sparse detections"). None: the levels as
        given at any speed.
    speed_span : int
        Frames over which a track's speed is measured (the detections' jitter counts less over
        more frames).

    Raises
    ------
    TypeError
        A number setting that is not a number; `smooth_external` not a bool.
    ValueError
        A setting out of its range above (NaN included).
    """

    accel: float = 0.01
    detection_noise: float = 0.05
    colour_noise: float = 0.15
    smooth_external: bool = True
    speed_reference: float | None = 0.065
    speed_span: int = 4

    def __post_init__(self) -> None:
        names = ("accel", "detection_noise", "colour_noise", "speed_reference")
        _numbers("MotionConfig", self, *names)
        flag(self.smooth_external, "MotionConfig: smooth_external")
        _integers_at_least("MotionConfig", 1, self, "speed_span")
        _in_range("MotionConfig", "accel", self.accel, 0.0, NOISE_MAX)
        for name in ("detection_noise", "colour_noise"):
            _in_range("MotionConfig", name, getattr(self, name), NOISE_MIN, NOISE_MAX)
        v = self.speed_reference
        if v is not None and not (np.isfinite(v) and v > 0):
            raise ValueError(
                f"MotionConfig: speed_reference is {v}, expected a finite value > 0 or None"
            )


@dataclass(frozen=True)
class RefineConfig:
    """Shrinking external detection boxes to their foreground.

    See :func:`pftrack.detection.refine_boxes`.

    Attributes
    ----------
    enabled : bool
        With external detections, also run the background model and shrink each detection box
        to the rows and columns where its foreground is (static cameras: detector boxes are
        often loose). A box with too little foreground is left as it is. The boxes of
        `upright_classes` get an upright person's prior (legs grow downwards, `leg_fill`,
        `min_height`): turn it off for sideways or overhead-rotated footage of people.
    fraction : float
        A row or column belongs to the object when its foreground fraction exceeds this share of
        the box's densest row or column; in [0, 1) (``refine_boxes``' range).
    leg_fill : float or None
        Shadow pixels are not foreground, but a refined box grows down through rows where
        foreground or shadow fills at least this share of its columns, no further than the
        detection's box: legs that the shadow test took for shadow come back, a shadow cast
        beside the feet does not widen the box (``refine_boxes``' `leg_fill`). None: shadows
        are background and boxes do not grow.
    min_height : float
        A box refined to less than this share of the detection's height keeps the detection's
        top and height; only its columns are refined (``refine_boxes``' `min_height`). Such a
        cut is a fragment of the object: legs the colour of the ground, a standing person the
        background model has absorbed, a ghost. 0.6: a detector's box up to 1.67 times its
        object's height is still refined. Over seeds 0-2 it lifts the synthetic busy scenes
        from 42.2 / 66.3 / 96.6 MOTA to 85.5 / 78.8 / 96.6 and leaves PETS09-S2L1 and
        TUD-Campus as they were (docs/tracking.md, "Refined height kept above 0.6").
    upright_classes : tuple of int or None
        Class ids (the ``cls`` column of :meth:`pftrack.Tracker.update`) whose boxes are
        upright people: `leg_fill` and `min_height` apply to them. Default ``(0,)``: COCO's
        and BoxMOT's person, and every box of a run without classes. The boxes of other
        classes are shrunk to their foreground alone, shadows as background, with no growing
        and no height rule: a car's shadow below it fills its columns, and `leg_fill` grew its
        box down through it (5 December; docs/tracking.md, "Refinement per class"). None: every
        class as a person (as before). `enabled` False still turns refinement off for all.

    Raises
    ------
    TypeError
        A setting that is not a number (`enabled`: not a bool; `upright_classes`: not a tuple
        of ints or None).
    ValueError
        A setting out of its range (NaN included).
    """

    enabled: bool = True
    fraction: float = 0.05
    leg_fill: float | None = 0.5
    min_height: float = 0.6
    upright_classes: tuple[int, ...] | None = (0,)

    def __post_init__(self) -> None:
        flag(self.enabled, "RefineConfig: enabled")
        _numbers("RefineConfig", self, "fraction", "leg_fill", "min_height")
        if not 0.0 <= self.fraction < 1.0:  # NaN fails too
            raise ValueError(
                f"RefineConfig: fraction is {self.fraction}, expected a value in [0, 1)"
            )
        if self.leg_fill is not None:
            _in_unit_interval("RefineConfig", leg_fill=self.leg_fill)
        _in_unit_interval("RefineConfig", min_height=self.min_height)
        classes = self.upright_classes
        if classes is not None and (
            not isinstance(classes, tuple)
            or not all(
                isinstance(c, (int, np.integer)) and not isinstance(c, (bool, np.bool_))
                for c in classes
            )
        ):
            raise TypeError(
                f"RefineConfig: upright_classes must be a tuple of int class ids or None, got "
                f"{brief(classes)}"
            )


@dataclass(frozen=True)
class CameraConfig:
    """How the camera's own motion is measured and when the camera counts as moving.

    See :mod:`pftrack.tracking.camera`.

    Attributes
    ----------
    max_side : int
        Frames are measured in grey, scaled down so that their longer side is at most this.
    max_features : int
        Corners tracked from one frame to the next (``cv2.goodFeaturesToTrack``).
    ransac_threshold : float
        RANSAC inlier distance of ``cv2.estimateAffinePartial2D``, pixels of the scaled frame.
    min_inliers : int
        Fewer inliers than this: no estimate for the frame (taken as no motion).
    threshold : float
        A frame moves when a corner of the image moves by more than this share of the image
        diagonal (0.002: 1.2 px on 480x360; the still PETS09 and TUD-Campus videos measure at
        most 0.4 and 0.6 px). A camera drifting by less a frame is never found moving; measured,
        compensating it did not help (docs/tracking.md, "A slowly moving camera").
    still_threshold : float
        The lower threshold of the hysteresis (a share of the image diagonal, at most
        `threshold`): once the camera moves, a frame counts as still only when no corner of
        the image moves by more than this, and the transform applied when the camera starts to
        move covers every frame over it just before (0.001: 0.6 px on 480x360, above the still
        PETS09's 0.4 px and TUD-Campus's 0.6 px of 800; the slowest frame of the moving
        versions of experiments/moving_camera.py moves 0.00083). Was `threshold` itself: the
        moving versions counted as still where their sinusoids turn, and frames of up to
        1.4 px went uncompensated.
    on_frames : int
        Consecutive moving frames before the camera counts as moving (``"auto"``).
    off_frames : int
        Consecutive still frames (under `still_threshold`) before it counts as still again.
    settle_frames : int
        Frames after the camera stops during which the background model is still not trusted
        (it learns the new view).
    still_features : int
        While the camera is still (``"auto"``), the motion is measured on at most this many of
        the last corners found, followed from frame to frame, with no new corner search; a frame
        whose motion reaches half of `threshold`, or that keeps too few inliers, is measured in
        full. 0: every frame in full.
    refresh_frames : int
        The corners followed while still are found anew after this many frames.
    key_frames : int
        While the camera moves, corners found on a key frame are followed into each later
        frame directly, and the transform from the previous frame is fitted to the corners
        that were inliers in both frames: each corner's place carries the error of one flow,
        so the estimate's errors no longer add up frame after frame along the camera's path.
        The previous frame becomes the key frame after this many frames, when fewer than 3/4
        of the key frame's corners stay inliers (``camera.KEY_INLIERS``), or when a fit fails.
        1: every moving frame is measured against the previous one with new corners (as
        before 5 December).
    """

    max_side: int = 240
    max_features: int = 100
    ransac_threshold: float = 1.0
    min_inliers: int = 20
    threshold: float = 0.002
    still_threshold: float = 0.001
    on_frames: int = 3
    off_frames: int = 10
    settle_frames: int = 25
    still_features: int = 40
    refresh_frames: int = 25
    key_frames: int = 10

    def __post_init__(self) -> None:
        names = ("max_side", "max_features", "min_inliers", "on_frames", "off_frames")
        _integers_at_least("CameraConfig", 1, self, *names, "refresh_frames", "key_frames")
        _integers_at_least("CameraConfig", 0, self, "settle_frames", "still_features")
        for name in ("ransac_threshold", "threshold", "still_threshold"):
            v = number(getattr(self, name), f"CameraConfig: {name}", finite=False)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"CameraConfig: {name} is {v}, expected a finite value > 0")
        if self.still_threshold > self.threshold:
            raise ValueError(
                f"CameraConfig: still_threshold is {self.still_threshold}, expected at most "
                f"threshold ({self.threshold})"
            )


#: TrackerConfig's fields that are configs of their own, and their classes.
_SUB_CONFIGS: tuple[tuple[str, type], ...] = (
    ("filter", FilterConfig),
    ("binning", HsvBinning),
    ("rjmcmc", RJMCMCConfig),
    ("refine", RefineConfig),
    ("association", AssociationConfig),
    ("motion", MotionConfig),
    ("lifecycle", LifecycleConfig),
    ("camera", CameraConfig),
    ("crossings", CrossingConfig),
)


@dataclass(frozen=True)
class TrackerConfig:
    """Configuration of :class:`~pftrack.tracking.MultiObjectTracker`.

    Attributes
    ----------
    filter : FilterConfig
        Particles per object, AR(2) dynamics (eq. 7, or eq. 8 with ``use_means``), λ.
    given_particles : int or None
        Particles per object of a track born from a given detection (the drop-in mode:
        ``detections`` passed to :meth:`MultiObjectTracker.update`); None: ``filter``'s count
        there too. The built-in detector's tracks keep ``filter.n_particles``. With given
        detections a filter holds its object through the detector's misses on colour alone,
        and 200 particles drift onto a neighbour less often than 100: over 25 seeds PETS09-S2L1
        with its public detections scores IDF1 78.6 against 76.4 (docs/tracking.md,
        "Particles with given detections"); the built-in detector's runs gain nothing from
        them and keep the cost of 100.
    binning : HsvBinning
        HSV histogram layout (110 bins by default).
    sampler : {"sis", "mh", "rjmcmc"}
        Sequential importance sampling per object (the paper's method), Metropolis-Hastings per
        object, or one joint RJ-MCMC chain over all objects (Smith et al. 2005): the paper's
        comparison samplers. With ``"rjmcmc"``, ``filter.n_particles`` (the chain's kept
        samples N) is at most 10000 (:data:`pftrack._limits.MAX_JOINT_SAMPLES`, as
        ``pftrack.Tracker`` and ``pftrack track`` take): the chain's cost per frame grows as N².
    rjmcmc : RJMCMCConfig
        Settings of the joint sampler (used with ``sampler="rjmcmc"``); its sample count and
        AR2 dynamics are set from ``filter`` so that budgets and models compare: its
        `n_samples`, `a`, `b`, `sigma`, `s_min` and `s_max` must keep RJMCMCConfig's defaults
        (ValueError naming the ``filter`` setting to use instead). Its `burn_in` is at most
        100000 here (``Tracker(burn_in=...)``, ``--burn-in``); its move probabilities are
        ``Tracker(moves=...)`` and ``--moves``.
    detector : {"paper", "mog2", "knn"}, PaperConfig, Mog2Config or KnnConfig
        Built-in detector used when :meth:`MultiObjectTracker.update` gets no detections: by
        name, with its settings' defaults, or as its settings
        (``detector=PaperConfig(alpha_fg=0.01)``), every one of them (:attr:`detector_name`
        gives the name). The detector bins colour as the tracker does: the settings' `hsv`
        must be ``HsvBinning()`` (replaced by `binning`) or `binning` itself. `open_size` and
        `hold_frames` below, when set, apply on top of the settings, which must then leave
        them unset (``blobs.open_size=None``, ``hold_frames=0``) or give the same value.
    reference_rate : float
        How fast a reference histogram adapts to a matched detection (0 keeps the first one).
    refine, association, motion, lifecycle
        Box refinement, pairing, centre filter, and birth/report/end rules.
    camera_motion : {"auto", "on", "off"}
        Camera-motion compensation (:mod:`pftrack.tracking.camera`): ``"auto"`` measures the
        camera's motion every frame and, once the camera is found to move, maps the tracks'
        state into each new frame and stops using the background model (box refinement,
        foreground-only colour); a still camera is left exactly as with ``"off"``. ``"on"``
        treats the camera as moving on every frame.
    camera : CameraConfig
        How the motion is measured and decided.
    crossings : CrossingConfig
        The offline pass's repair of identities swapped where two tracks cross
        (:func:`~pftrack.tracking.offline.repair_crossings`), run by
        :meth:`pftrack.Tracker.finalize` when the smoother is on and ``crossings.enabled``.
    max_side : int or None
        Working resolution: a frame whose longer side is larger is scaled down (OpenCV's
        ``INTER_AREA``) to this longer side before detection and tracking, and every box the
        tracker reports is scaled back to the frame's pixels (:class:`~pftrack.Tracker`; the
        inner :class:`~pftrack.tracking.MultiObjectTracker` works in the scaled pixels). None
        tracks at the frame's own size; 0 means the same (``--max-side 0``) and is stored as
        None, so ``TrackerConfig(max_side=0) == TrackerConfig()``. Else an int in [64, 100000].
    open_size : int or None
        Side (pixels) of the built-in detector's opening element (``BlobConfig.open_size``).
        None: from the frame's rows, ``max(3, round(rows / 120))`` made odd (3 at 360 rows, 5
        at 480). The element that works follows the people's size and the video's noise, not
        the rows: PETS09-S2L1 upscaled to 480 rows tracks best with 3 and TUD-Campus at its own
        480 rows with 5 (docs/detection.md, "Known limit"), so set it for your footage when
        the default blobs split thin people or join touching ones.
    hold_frames : int
        The built-in detector's hold of people who walked and stopped
        (``PaperConfig.hold_frames``, passed on top of `detector`'s settings; ``"paper"``
        only): how many frames after its
        last move a stopped walker's box stays out of the background's update. 0 (the default)
        turns it off; 1000 keeps a person standing 300-600 frames tracked, at a cost measured
        on a real sequence (docs/detection.md, "A person who stands for hundreds of frames").
    pixel_diagonal : float or None
        The settings given in pixels (the particle filter's ``filter.model.sigma_xy`` and the
        offline linker's ``max_distance``) hold for frames whose diagonal is at most this
        (default 800: 640x480), and grow in proportion to the diagonal of larger (working)
        frames, so that a video tracks the same at 1280x720 as at 640x360
        (:meth:`pixel_scale`). They were set on 480x360 and 640x480 videos, which track with
        the same values. On frames smaller than 480x360 the filter's noise shrinks in
        proportion to the diagonal (:meth:`noise_scale`). None: the settings are in the frame's
        own pixels at every size.
    mh_iter : int
        Metropolis-Hastings iterations per particle and frame with ``sampler="mh"``
        (:class:`~pftrack.particle_filter.MHColourParticleFilter`'s `n_iter`), in [1, 1000]:
        a step evaluates the likelihood ``n_particles * (mh_iter + 1)`` times per object.
        ``Tracker(mh_iter=...)``, ``--mh-iter``; the other samplers do not read it.
    mh_proposal : {"dynamics", "random_walk"}
        The MH chain's proposal with ``sampler="mh"``
        (:class:`~pftrack.particle_filter.MHColourParticleFilter`'s `proposal`): a fresh draw
        of the AR(2) dynamics (the default, the paper's) or a Gaussian random walk of
        `mh_rw_sigma` from the chain's state. ``Tracker(mh_proposal=...)``,
        ``--mh-proposal``.
    mh_rw_sigma : tuple of 3 float
        Standard deviations of the random-walk step (cx, cy in pixels, scale), each in [0,
        10000], default ``(2.0, 2.0, 0.01)``; read only with ``mh_proposal="random_walk"``
        (other values with ``"dynamics"`` are refused: they would do nothing). Its cx, cy are
        pixel settings: they grow and shrink with the frame as ``filter.model.sigma_xy``
        (:meth:`scaled_pixels`). ``Tracker(mh_rw_sigma=...)``, ``--mh-rw-sigma``.
    """

    filter: FilterConfig = field(
        default_factory=lambda: FilterConfig(
            n_particles=100,
            model=Ar2Model(sigma_xy=3.0, sigma_s=0.02, velocity_gain=0.5, scale_gain=0.0),
        )
    )
    binning: HsvBinning = field(default_factory=HsvBinning)
    sampler: SamplerName = "sis"
    rjmcmc: RJMCMCConfig = field(default_factory=RJMCMCConfig)
    detector: DetectorName | PaperConfig | Mog2Config | KnnConfig = "paper"
    reference_rate: float = 0.05
    refine: RefineConfig = field(default_factory=RefineConfig)
    association: AssociationConfig = field(default_factory=AssociationConfig)
    motion: MotionConfig = field(default_factory=MotionConfig)
    lifecycle: LifecycleConfig = field(default_factory=LifecycleConfig)
    camera_motion: CameraMotion = "auto"
    camera: CameraConfig = field(default_factory=CameraConfig)
    crossings: CrossingConfig = field(default_factory=CrossingConfig)
    max_side: int | None = None
    open_size: int | None = None
    hold_frames: int = 0
    pixel_diagonal: float | None = PIXEL_DIAGONAL
    given_particles: int | None = GIVEN_PARTICLES
    mh_iter: int = DEFAULT_MH_ITER
    mh_proposal: str = DEFAULT_MH_PROPOSAL
    mh_rw_sigma: tuple[float, float, float] = DEFAULT_MH_RW_SIGMA

    def __post_init__(self) -> None:
        for name, cls in _SUB_CONFIGS:  # were taken, and failed at a frame naming no setting
            instance(getattr(self, name), f"TrackerConfig: {name}", cls)
        option(self.sampler, "TrackerConfig: sampler", SAMPLERS)  # before it is compared below
        option(self.camera_motion, "TrackerConfig: camera_motion", CAMERA_MOTION)
        if not isinstance(self.detector, tuple(DETECTOR_CONFIGS.values())):
            if not isinstance(self.detector, str):
                raise TypeError(
                    f"TrackerConfig: detector must be {listed(DETECTORS)}, or a PaperConfig, "
                    f"Mog2Config or KnnConfig, got {shown(self.detector)}"
                )
            if self.detector not in DETECTORS:
                raise ValueError(
                    f"TrackerConfig: detector is {self.detector!r}, expected 'paper', 'mog2' or "
                    "'knn' (or the settings of one: PaperConfig, Mog2Config, KnnConfig)"
                )
        _none_or_int_in("TrackerConfig", self, "given_particles", 1, MAX_PARTICLES)
        integer(self.mh_iter, "TrackerConfig: mh_iter", 1, MAX_MH_ITER)
        option(self.mh_proposal, "TrackerConfig: mh_proposal", MH_PROPOSALS)
        tau = real_array(self.mh_rw_sigma, "TrackerConfig: mh_rw_sigma", booleans=False)
        if tau.ndim != 1:
            raise ValueError(f"TrackerConfig: mh_rw_sigma has shape {tau.shape}, expected (3,)")
        object.__setattr__(self, "mh_rw_sigma", tuple(float(v) for v in tau))
        what = ("TrackerConfig: mh_proposal", "TrackerConfig: mh_rw_sigma")
        refused = proposal_error(self.mh_proposal, self.mh_rw_sigma, what, cli=False)
        if refused:
            raise ValueError(refused)
        integer(self.rjmcmc.burn_in, "TrackerConfig: rjmcmc.burn_in", 0, MAX_BURN_IN)
        if self.sampler == "rjmcmc":  # the tracker's cap; RJMCMCConfig alone takes more
            too_many = joint_samples_error(
                self.filter.n_particles, "TrackerConfig: filter.n_particles", "sampler 'rjmcmc'"
            )
            if too_many:
                raise ValueError(too_many)
        _none_or_int_in("TrackerConfig", self, "open_size", 1, MAX_OPEN_SIZE)
        integer(self.hold_frames, "TrackerConfig: hold_frames", 0, 2**31 - 1)
        if self.hold_frames and self.detector_name != "paper":
            raise ValueError(
                f"TrackerConfig: hold_frames {self.hold_frames} needs detector 'paper' (the hold"
                f" is its own), got detector {self.detector_name!r}"
            )
        if not isinstance(self.detector, str):  # its settings, once open_size and hold checked
            _detector_settings_agree(self)
        side = self.max_side
        if isinstance(side, (int, np.integer)) and not isinstance(side, bool) and side == 0:
            object.__setattr__(self, "max_side", None)  # 0 is off, as --max-side 0: stored None
        _none_or_int_in("TrackerConfig", self, "max_side", MIN_SIDE, MAX_SIDE, "None (or 0: off)")
        if self.pixel_diagonal is not None and not (
            isinstance(self.pixel_diagonal, (int, float, np.integer, np.floating))
            and not isinstance(self.pixel_diagonal, bool)
            and np.isfinite(self.pixel_diagonal)
            and self.pixel_diagonal > 0
        ):
            raise ValueError(
                f"TrackerConfig: pixel_diagonal is {brief(self.pixel_diagonal)}, expected None or "
                "a finite value > 0"
            )
        if self.sampler == "rjmcmc" and self.filter.model.use_means:
            raise ValueError(
                "TrackerConfig: the AR(2) model on the particle-set means (use_means; --dynamics "
                "ar2-mean) needs a per-object sampler ('sis' or 'mh'; --sampler): the joint "
                "'rjmcmc' sampler moves each object on its own state"
            )
        _joint_settings_used(self)
        if self.camera_motion not in CAMERA_MOTION:
            raise ValueError(
                f"TrackerConfig: camera_motion is {self.camera_motion!r}, expected 'auto', 'on' "
                "or 'off'"
            )
        if self.sampler not in SAMPLERS:
            raise ValueError(
                f"TrackerConfig: sampler is {self.sampler!r}, expected 'sis', 'mh' or 'rjmcmc'"
            )
        _in_unit_interval("TrackerConfig", reference_rate=self.reference_rate)

    @property
    def detector_name(self) -> DetectorName:
        """The built-in detector's name: `detector`, or the name of the settings given there."""
        if isinstance(self.detector, str):
            return self.detector
        return _DETECTOR_NAMES[type(self.detector)]

    def detector_settings(self) -> PaperConfig | Mog2Config | KnnConfig | None:
        """The settings given as `detector`, with `binning`, `open_size` and `hold_frames`.

        None when `detector` is a name (:func:`~pftrack.detection.make_detector` builds it
        from the name, `binning`, `open_size` and `hold_frames`).
        """
        d = self.detector
        if isinstance(d, str):
            return None
        d = replace(d, hsv=self.binning)
        if self.open_size is not None:
            d = replace(d, blobs=replace(d.blobs, open_size=self.open_size))
        if self.hold_frames and isinstance(d, PaperConfig):
            d = replace(d, hold_frames=self.hold_frames)
        return d

    def pixel_scale(self, width: int, height: int) -> float:
        """How much the pixel settings grow on a (working) frame of `width` x `height` pixels.

        ``max(1, diagonal / pixel_diagonal)``; 1 with ``pixel_diagonal=None``. The offline
        linker's ``max_distance`` grows by it.
        """
        if self.pixel_diagonal is None:
            return 1.0
        return pixel_scale(width, height, self.pixel_diagonal)

    def noise_scale(self, width: int, height: int) -> float:
        """How much the particle filter's position noise (``sigma_xy``) changes on a frame.

        As :meth:`pixel_scale` on large frames, and in proportion to the diagonal on frames
        smaller than 480x360 (:data:`SMALL_DIAGONAL`, or `pixel_diagonal` if smaller): the
        noise was set on 480x360 and 640x480 videos, and a person who is half as big moves half
        as many pixels. PETS09-S2L1 at 360x270 with its public detections, seeds 0-2: IDF1
        75.5-78.2 against 66.4-67.5 with the noise of 480x360 (docs/tracking.md, "Pixel
        settings on small frames").
        """
        if self.pixel_diagonal is None:
            return 1.0
        small = min(SMALL_DIAGONAL, float(self.pixel_diagonal))
        shrink = min(1.0, float(np.hypot(width, height)) / small)
        return shrink * self.pixel_scale(width, height)

    def for_given(self) -> TrackerConfig:
        """The configuration of tracks born from given detections (``given_particles``)."""
        n = self.given_particles
        if n is None or n == self.filter.n_particles:
            return self
        return replace(self, filter=replace(self.filter, n_particles=int(n)))

    def scaled_pixels(self, scale: float) -> TrackerConfig:
        """The configuration with its pixel settings times `scale`.

        The pixel settings are ``filter.model.sigma_xy`` and, with the random-walk proposal,
        the cx, cy of ``mh_rw_sigma``. The offline linker's ``max_distance`` is not part of
        it: :class:`pftrack.Tracker` scales its :class:`~pftrack.recovery.LinkConfig` with the
        same factor.
        """
        if scale == 1.0:
            return self
        model = replace(self.filter.model, sigma_xy=self.filter.model.sigma_xy * scale)
        tau = self.mh_rw_sigma
        if self.mh_proposal == "random_walk":  # read only then (refused otherwise if moved)
            cx, cy = (min(v * scale, MAX_MH_RW_SIGMA) for v in tau[:2])
            tau = (cx, cy, tau[2])
        return replace(self, filter=replace(self.filter, model=model), mh_rw_sigma=tau)
