"""A track: what the tracker reports for one frame, and the live state behind it.

Lifecycle of a live track: born from a detection no track explains; each frame its colour
particle filter looks at the frame and its centre filter predicts (:meth:`LiveTrack.predict`);
a matched detection re-seeds it (:meth:`LiveTrack.follow`), otherwise it coasts
(:meth:`LiveTrack.coast`); it ends when it has coasted too long (:meth:`LiveTrack.alive`);
it is reported once confirmed, and while coasting only as long as its colour still matches
(:meth:`LiveTrack.report`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TypeVar, overload

import numpy as np
from numpy.typing import NDArray

from pftrack import _core
from pftrack._core import BinnedImage
from pftrack._typing import F64
from pftrack.boxes import _to_cxcywh
from pftrack.particle_filter import ColourParticleFilter, MHColourParticleFilter
from pftrack.particle_filter.filter import reinitialise_filters, step_filters_summary
from pftrack.tracking.config import LifecycleConfig, TrackerConfig
from pftrack.tracking.motion import CentreKalman

_T = TypeVar("_T")

__all__ = [
    "LiveTrack",
    "Track",
    "colour_evidence",
    "follow_tracks_motion",
    "predict_tracks",
    "reseed_tracks",
]

#: Largest spread between the best and the mean colour match of a particle set that still
#: counts as no spread at all (round-off): the colour likelihood is flat.
FLAT_RHO = 1e-9


@overload
def colour_evidence(rho: float, rho_max: float) -> bool: ...
@overload
def colour_evidence(rho: F64, rho_max: F64) -> NDArray[np.bool_]: ...
def colour_evidence(rho: float | F64, rho_max: float | F64) -> bool | NDArray[np.bool_]:
    """Tell whether a colour filter's step carried evidence about where the object is.

    When every particle's colour match ``rho`` is the same (the best one, `rho_max`, equals the
    weighted mean `rho` to :data:`FLAT_RHO`), the likelihood is flat: a frame of one colour
    (e.g. black), or boxes with no counted pixel. The filter's estimate is then only its own
    motion prediction, not a measurement, and the centre filter must not take it as one.
    Arrays of several filters' values give one answer per filter.
    """
    return rho_max - rho > FLAT_RHO


@dataclass(frozen=True)
class Track:
    """A track as reported for one frame.

    Attributes
    ----------
    id : int
        Identity, unique within one tracker (from 1).
    box_xywh : (4,) ndarray
        Left, top, width, height in pixels.
    score : float
        Confidence: the matched detection's score, or the colour match ``rho`` when coasting.
    detection_index : int or None
        Index of the detection (in the order given to
        :meth:`~pftrack.tracking.MultiObjectTracker.update`) matched to this track (also a
        merged blob's, which several tracks share), or None when it was carried by its particle
        filter alone.
    age : int
        Frames since birth.
    time_since_update : int
        Frames since the last matched detection (0 when matched this frame).
    history : tuple of (frame, box_xywh, score)
        On the frame a new track is first reported, the detection boxes it was matched to while
        it waited for ``min_hits`` (frame numbers count ``update`` calls from 1); empty
        otherwise. Offline writers back-fill them; online users may ignore them.
    detection_box : (4,) ndarray or None
        The matched detection's box (after refinement) as the tracker measured it, when it
        re-seeded the track this frame; None when coasting or inside a merged blob. ``box_xywh``
        may be a filtered version of it (``MotionConfig.smooth_external``).
    cls : int
        Class id: that of the detection the track was born from (0 when none is given). A
        track is only ever matched to detections of its own class.
    colour : (B,) ndarray or None
        The colour histogram the tracker holds for this row: the matched detection's (the one
        the association compared) when `detection_box` is given, else the particle filter's
        reference. The offline pass may judge its holes by it (:class:`~.writer.TrackWriter`'s
        ``colour``); None from a tracker that has none (the joint sampler).
    history_colours : tuple of (B,) ndarray or None
        The detections' histograms of `history`, one per entry.
    """

    id: int
    box_xywh: F64
    score: float
    detection_index: int | None
    age: int
    time_since_update: int
    history: tuple[tuple[int, F64, float], ...] = ()
    detection_box: F64 | None = None
    cls: int = 0
    colour: F64 | None = None
    history_colours: tuple[F64 | None, ...] = ()


class LiveTrack:
    """A live track: its particle filter, centre filter and bookkeeping.

    Parameters
    ----------
    track_id : int
        Identity.
    box_xywh : (4,) ndarray
        The detection it is born from.
    reference : (B,) ndarray
        Reference colour histogram (the detection's).
    config : TrackerConfig
        Settings (sampler, particle filter, centre filter).
    seed : int
        Seed of its particle filter.
    score : float
        The detection's score.
    """

    #: Coasted frames in a row whose colour likelihood was flat (:attr:`blind`), and whether
    #: this frame's was (:attr:`flat`). Class defaults: a checkpoint pickled before them has none.
    blind = 0
    flat = False
    #: The last followed detection's histogram (:attr:`Track.colour`), kept when the tracker
    #: keeps colour (:attr:`~.tracker.MultiObjectTracker.keep_colour`); a checkpoint pickled
    #: before stop 74 has none. The histograms of :attr:`unreported`'s boxes are ``unseen``.
    seen: F64 | None = None

    def __init__(self, track_id: int, box_xywh: F64, reference: F64, config: TrackerConfig,
                 seed: int, score: float) -> None:  # fmt: skip
        self.id = track_id
        box = _to_cxcywh(box_xywh)
        self.filter: ColourParticleFilter = (
            MHColourParticleFilter(
                box,
                reference,
                config.filter,
                rng=seed,
                n_iter=config.mh_iter,
                proposal=config.mh_proposal,
                rw_sigma=config.mh_rw_sigma,
            )
            if config.sampler == "mh"
            else ColourParticleFilter(box, reference, config.filter, rng=seed)
        )
        self.box = box_xywh.copy()
        self.size = box_xywh[2:].copy()  # smoothed detection size
        self.motion = CentreKalman(
            box_xywh[:2] + box_xywh[2:] / 2, box_xywh[3], config.motion.accel
        )
        self.hits = 1
        self.age = 1
        self.time_since_update = 0
        self.missed = 0  # frames with detections since the last match (see alive)
        # the last matched detections' (frame, centre x, centre y, height): see speed
        self.trail: list[tuple[int, float, float, float]] = []
        self.score = score
        self.rho = 1.0
        self.det_index: int | None = None
        self.cls = 0  # class id, set by the tracker at birth
        self.measured: F64 | None = box_xywh.copy()  # this frame's detection box
        self.unreported: list[tuple[int, F64, float]] = []
        self.reported = False
        # coasted frames with detections in a row whose colour likelihood was flat (a blind
        # coast: the centre filter's extrapolation alone), and whether this frame's was
        self.blind = 0
        self.flat = False

    def predict(self, binned: BinnedImage, colour_noise: float, accel_gain: float = 1.0) -> None:
        """Step the particle filter on the frame and the centre filter by one frame.

        The particle filter's estimate is a noisy measurement of the centre filter's
        prediction (standard deviation `colour_noise` heights), when the frame's colour
        carried evidence (:func:`colour_evidence`); otherwise the prediction stands alone.
        `accel_gain` multiplies the centre filter's acceleration (see :func:`predict_tracks`).
        """
        self.measured = None
        state = self.filter.step(binned)
        self.rho = state.rho
        self.motion.predict(self.size[1], accel_gain)
        self.flat = not colour_evidence(state.rho, state.rho_max)
        if not self.flat:
            self.motion.update(state.box_cxcywh[:2], colour_noise * self.size[1])
        cx, cy = self.motion.p
        self.box = np.array(
            [cx - self.size[0] / 2, cy - self.size[1] / 2, self.size[0], self.size[1]]
        )
        self.age += 1

    def follow(self, box_xywh: F64, hist: F64, config: TrackerConfig, smooth: bool) -> None:
        """Follow a matched detection (not a merged blob).

        Update the centre filter and the size, re-seed the particles around the detection and
        blend its colour into the reference (:meth:`follow_motion`, then :func:`reseed_tracks`).
        """
        self.follow_motion(box_xywh, config, smooth)
        reseed_tracks([self], box_xywh[None], hist[None], config)

    def follow_motion(self, box_xywh: F64, config: TrackerConfig, smooth: bool) -> None:
        """The first half of :meth:`follow`: the centre filter, the size and the box.

        The particles and the reference still have to be re-seeded (:func:`reseed_tracks`,
        which does it for many tracks at once).
        """
        b = box_xywh
        self.measured = b.copy()
        centre = b[:2] + b[2:] / 2
        self.motion.update(centre, config.motion.detection_noise * self.size[1])
        self.size = 0.7 * self.size + 0.3 * b[2:]
        self.box = (
            np.concatenate([self.motion.p - self.size / 2, self.size]) if smooth else b.copy()
        )

    def matched(self, score: float, det_index: int | None) -> None:
        """Count a match (also a merged blob's, which does not re-seed the track)."""
        self.score = score
        self.hits += 1
        self.time_since_update = 0
        self.missed = 0
        self.blind = 0
        self.det_index = det_index

    def coast(self, detected: bool = True) -> None:
        """A frame without a detection: the particle filter alone carries the track.

        `detected`: whether the frame had any detection at all. A frame without one (the
        detector did not run, or saw nothing) is not counted in :attr:`missed`, nor in
        :attr:`blind` (which a frame whose colour carried evidence resets).
        """
        self.time_since_update += 1
        self.missed += int(detected)
        if not self.flat:
            self.blind = 0
        elif detected:
            self.blind += 1
        self.det_index = None
        self.score = self.rho

    def alive(self, rules: LifecycleConfig) -> bool:
        """Tell whether the track has coasted no longer than it may (less if unconfirmed).

        A confirmed track may coast `max_coast` frames. A tentative one may miss
        `tentative_coast` frames that had detections (frames without any detection do not count:
        a detector run every other frame, or one that saw nothing), and coast no more than
        `max_coast` frames in all. Any track, of given detections or of the built-in
        detector's, ends after more than `blind_coast` frames with detections in a row coasted
        blind, its colour likelihood flat (:attr:`blind`): on frames of one colour, or, with the
        built-in detector's foreground-only bins, with no foreground pixel under any particle.
        """
        if rules.blind_coast is not None and self.blind > rules.blind_coast:
            return False
        if self.hits >= rules.min_hits:
            return self.time_since_update <= rules.max_coast
        return self.missed <= rules.tentative_coast and self.time_since_update <= rules.max_coast

    def speed(
        self, frame_index: int, centre: Sequence[float], height: float, span: int
    ) -> float | None:
        """Record a matched detection; return the track's speed over `span` frames or more.

        In heights per frame: the distance from the newest recorded detection at least `span`
        frames back to this one, over the mean height and the frames between (None while there
        is none). Over several frames, the detections' jitter counts for little. Detections
        older than that one are forgotten.
        """
        cx, cy = float(centre[0]), float(centre[1])
        trail = self.trail
        trail.append((frame_index, cx, cy, height))
        k = -1
        for i, entry in enumerate(trail):  # by frame: the last one `span` or more back
            if frame_index - entry[0] < span:
                break
            k = i
        if k < 0:
            return None
        f, x, y, h = trail[k]
        del trail[:k]
        return math.hypot(cx - x, cy - y) / (0.5 * (h + height)) / (frame_index - f)

    def report(
        self, frame_index: int, early: bool, rules: LifecycleConfig, colour: bool = False
    ) -> Track | None:
        """What to report for frame `frame_index` (None: nothing yet, or not any more).

        An unconfirmed track (outside the start-up frames, `early`) keeps its detection boxes
        to hand over with its first report, as :attr:`Track.history`. With `colour`, the
        report carries the histograms of its boxes (:attr:`Track.colour`); without it (the
        default) nothing more is done than before they were kept.
        """
        if self.hits < rules.min_hits and not early and not self.reported:
            if self.measured is not None:
                self.unreported.append((frame_index, self.measured.copy(), float(self.score)))
                if colour:
                    self.__dict__.setdefault("unseen", []).append(self.seen)
            return None
        if self.time_since_update > 0 and self.rho < rules.coast_min_rho:
            return None
        history, self.unreported, self.reported = tuple(self.unreported), [], True
        seen: F64 | None = None
        colours: tuple[F64 | None, ...] = ()
        if colour:  # the matched detection's histogram, or the reference it coasts on
            seen = self.filter.reference if self.measured is None else self.seen
            if history:  # none kept: a checkpoint from before stop 74
                unseen = self.__dict__.pop("unseen", None)
                colours = tuple(unseen) if unseen else (None,) * len(history)
        return _new_track(
            self.id,
            self.box.copy(),
            float(self.score),
            self.det_index,
            self.age,
            self.time_since_update,
            history,
            None if self.measured is None else self.measured.copy(),
            self.cls,
            seen,
            colours,
        )


def frozen_made(kind: type[_T], /, **fields: object) -> _T:
    """``kind(**fields)`` for a frozen dataclass, made without its ``__init__``.

    A frozen dataclass sets each field through ``object.__setattr__`` (3.6 us a Track; 0.9
    this way), and the tracker makes a Track for every live track and a camera step
    (:class:`~pftrack.tracking.camera.CameraStep`) on every frame. The same object when
    `fields` are all of them in their order: its ``__dict__`` in the same order, equal, and
    pickled to the same bytes (tests/tracking/test_tracker.py, test_camera.py). Only for a
    class without ``__post_init__``.
    """
    made = object.__new__(kind)
    made.__dict__.update(fields)
    return made


def _new_track(id: int, box_xywh: F64, score: float, detection_index: int | None, age: int,
               time_since_update: int, history: tuple[tuple[int, F64, float], ...],
               detection_box: F64 | None, cls: int, colour: F64 | None = None,
               history_colours: tuple[F64 | None, ...] = ()) -> Track:  # fmt: skip
    """``Track(id, box_xywh, ...)`` by :func:`frozen_made`."""
    return frozen_made(
        Track, id=id, box_xywh=box_xywh, score=score, detection_index=detection_index, age=age,
        time_since_update=time_since_update, history=history, detection_box=detection_box,
        cls=cls, colour=colour, history_colours=history_colours,
    )  # fmt: skip


def predict_tracks(
    tracks: Sequence[LiveTrack],
    binned: BinnedImage,
    colour_noise: float,
    accel_gain: float | Sequence[float] = 1.0,
) -> F64:
    """:meth:`LiveTrack.predict` for every track at once.

    One C++ call steps all the particle filters (:func:`~pftrack.particle_filter.filter.
    step_filters`), and one more the centre filters' predict and update
    (``_core.centre_predict_tracks``, on the tracks' own attributes): the same numbers as
    calling ``t.predict(binned, colour_noise)`` for each track in turn.

    Parameters
    ----------
    tracks : sequence of LiveTrack
        Updated in place, each at most once.
    binned : pftrack._core.BinnedImage
        This frame's bins.
    colour_noise : float
        Standard deviation of the colour filter's centre, in heights.
    accel_gain : float or sequence of float
        Multiplies each centre filter's `accel` (:meth:`MultiObjectTracker.motion_gain`): one
        factor for every track, or one per track (each track's class's).

    Returns
    -------
    (K, 8) ndarray
        Per track: the centre filter's position and velocity and the box (xywh), the rows the
        tracks' ``motion.p``, ``motion.v`` and ``box`` are views of.
    """
    if not tracks:
        return np.empty((0, 8))
    listed = tracks if isinstance(tracks, list) else list(tracks)
    # a list (the tracker's) first: isinstance against the Sequence ABC takes about 0.5 us
    if isinstance(accel_gain, (list, tuple)):
        gains = accel_gain
    elif isinstance(accel_gain, Sequence):
        gains = list(accel_gain)
    else:
        gains = [accel_gain] * len(listed)
    summary = step_filters_summary([t.filter for t in listed], binned)
    # was a loop over the tracks on plain floats (about 3 us a track): the same floats
    rows: F64 = _core.centre_predict_tracks(listed, summary, gains, colour_noise, FLAT_RHO)
    return rows


def follow_tracks_motion(
    tracks: Sequence[LiveTrack], boxes_xywh: F64, config: TrackerConfig, smooth: bool
) -> None:
    """:meth:`LiveTrack.follow_motion` for many tracks (the same numbers), in one core call.

    ``_core.centre_follow_tracks`` updates the centre filters and sets the sizes and boxes on
    the tracks' own attributes (was a loop over them on plain floats: the same floats).

    Parameters
    ----------
    tracks : sequence of LiveTrack
        Tracks that follow a detection each, updated in place, each at most once.
    boxes_xywh : (K, 4) ndarray
        Their detections' boxes.
    config : TrackerConfig
        Settings (the detection's noise level).
    smooth : bool
        Report the filtered box rather than the detection's (see :meth:`LiveTrack.follow`).
    """
    if not tracks:
        return
    listed = tracks if isinstance(tracks, list) else list(tracks)
    b = np.asarray(boxes_xywh, dtype=np.float64).reshape(-1, 4)
    _core.centre_follow_tracks(listed, b, config.motion.detection_noise, bool(smooth))


def reseed_tracks(
    tracks: Sequence[LiveTrack], boxes_xywh: F64, hists: F64, config: TrackerConfig
) -> None:
    """The second half of :meth:`LiveTrack.follow` for many tracks, as arrays over them.

    Each track's particles are re-seeded around its detection with its centre filter's
    velocity (:func:`~pftrack.particle_filter.filter.reinitialise_filters`), and the
    detection's colour is blended into its reference at ``config.reference_rate`` (unless the
    detection has no colour). The same numbers as one track at a time.

    Parameters
    ----------
    tracks : sequence of LiveTrack
        Tracks that followed a detection (:meth:`LiveTrack.follow_motion`), updated in place.
    boxes_xywh : (K, 4) ndarray
        Their detections' boxes.
    hists : (K, B) ndarray
        Their detections' histograms.
    config : TrackerConfig
        Settings.
    """
    if not tracks:
        return
    filters = [t.filter for t in tracks]
    reinitialise_filters(filters, _to_cxcywh(boxes_xywh), np.array([t.motion.v for t in tracks]))
    rate = config.reference_rate
    if rate <= 0:
        return
    has = hists.sum(axis=1) > 0
    if has.all():  # the usual case: every detection has colour
        idx: list[int] = list(range(len(filters)))
        blend = (1 - rate) * np.array([f.reference for f in filters]) + rate * hists
    else:
        idx = has.nonzero()[0].tolist()
        if not idx:
            return
        blend = (1 - rate) * np.array([filters[i].reference for i in idx]) + rate * hists[idx]
    # finite and >= 0 everywhere: the least value >= 0 (NaN fails) and the largest below inf
    if not (blend.min() >= 0 and blend.max() < np.inf):
        raise ValueError("reference histogram must be finite, >= 0 and not all zero")
    # each row over its own sum (the same floats as row / row.sum(), row by row)
    blend /= blend.sum(axis=1, keepdims=True)
    for i, row in zip(idx, blend, strict=True):
        filters[i].reference = row
