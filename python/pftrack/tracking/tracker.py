"""Multi-object tracking with one colour particle filter per object (the first paper's method).

Each frame: detections come from the built-in background-subtraction detector or from any
detector the caller runs (refined to their foreground, :mod:`pftrack.detection.refine`);
every live track advances its own colour particle filter on the frame (foreground pixels only
when a foreground mask is known) and its centre filter (:mod:`.motion`); tracks and detections
are paired by the Hungarian method over overlap, centre distance and colour similarity
(:mod:`.association`); a matched track's particles are re-seeded around its detection; a track
without a detection goes on from its particle filter alone (through merged blobs and
occlusions) for ``max_coast`` frames, then ends; a detection no track explains starts a new
track whose reference histogram is taken from it (:mod:`.track`). With ``sampler="rjmcmc"``
one joint sampler replaces all of this (:mod:`.joint`).
"""

from __future__ import annotations

import bisect
import copy
import dataclasses
import inspect
import itertools
import math
import threading
from collections import deque
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack._check import (
    bgr_frame,
    check_classes,
    frames_iterator,
    generator,
    not_an_image,
    real_array,
)
from pftrack._core import BinnedImage
from pftrack._typing import F64, RngLike
from pftrack._warn import Held, warn
from pftrack.boxes import _iou_rows, _overlap_pairs, _to_cxcywh
from pftrack.detection import (
    FrameDetector,
    check_detections,
    detector_from,
    make_detector,
    refine_boxes,
)
from pftrack.detection.paper import PaperDetector, foreground_only
from pftrack.particle_filter import box_histograms, hsv_bins
from pftrack.particle_filter.filter import _in_use
from pftrack.tracking.association import associate, covers_another, first_of_twins
from pftrack.tracking.camera import CameraMotion, CameraStep, warp_tracks
from pftrack.tracking.config import TrackerConfig
from pftrack.tracking.joint import JointTracker
from pftrack.tracking.track import (
    LiveTrack,
    Track,
    follow_tracks_motion,
    predict_tracks,
    reseed_tracks,
)

__all__ = ["MultiObjectTracker"]

#: The built-in detectors that draw random numbers: each gets a seed from the tracker's own.
SEEDED_DETECTORS = ("knn",)
#: Speed samples before :meth:`MultiObjectTracker.motion_gain` leaves 1.
MIN_SPEED_SAMPLES = 20
#: The most recent speed samples kept.
MAX_SPEED_SAMPLES = 5000
#: Scores of a class over the birth window before its own birth threshold replaces the
#: pooled one (:meth:`MultiObjectTracker.birth_threshold`).
MIN_CLASS_BIRTH_SCORES = 20
#: How far above 1 a confidence may lie (float rounding, e.g. a float32 1.0 summed) before the
#: scores count as a detector's own scale rather than confidences.
CONFIDENCE_SLACK = 1e-6


class RollingMedian:
    """The median of the last `size` values added, exactly ``np.median``'s, in O(log n + n/w).

    A sorted list beside the values in arrival order: adding one is a binary search and a
    list insert (and the oldest's removal once full), the median one or two reads. The
    tracker asks for its speed median every frame: ``np.median`` of 5000 samples took about
    0.1 ms a frame.
    """

    def __init__(self, size: int) -> None:
        self.size = int(size)
        self._order: deque[float] = deque()
        self._sorted: list[float] = []

    def add(self, value: float) -> None:
        """Add `value`; the oldest value leaves once there are more than `size`."""
        v = float(value)
        self._order.append(v)
        bisect.insort(self._sorted, v)
        if len(self._order) > self.size:
            old = self._order.popleft()
            del self._sorted[bisect.bisect_left(self._sorted, old)]

    def __len__(self) -> int:
        return len(self._sorted)

    def median(self) -> float | None:
        """``float(np.median(values))`` of the values held, None when there is none."""
        n = len(self._sorted)
        if n == 0:
            return None
        if n % 2:
            return self._sorted[n // 2]
        return (self._sorted[n // 2 - 1] + self._sorted[n // 2]) / 2


class MultiObjectTracker:
    """Track many objects with one colour particle filter each.

    Parameters
    ----------
    config : TrackerConfig
        All settings.
    rng : numpy.random.Generator, int or None
        Seed: the same seed and input give the same tracks.
    detector : FrameDetector, optional
        Any object with ``detect(frame) -> Detections`` (:class:`pftrack.detection.FrameDetector`
        says what else the tracker uses when it is there); by default the one named by
        ``config.detector``, created on first use. Anything else (a name such as ``"paper"``,
        which goes in ``TrackerConfig(detector=...)``) is a TypeError.

    Notes
    -----
    One tracker is one run, stepped by one thread at a time: while a thread is inside
    :meth:`update` or :meth:`prime`, another thread's ``update``, ``prime``, ``copy.deepcopy``
    or pickle of the same tracker raises RuntimeError (``MultiObjectTracker.update: this
    MultiObjectTracker is in use by another thread ...``). Different trackers run in parallel.

    Attributes
    ----------
    pixel_scale : float
        The factor of the pixel settings on this run's frames
        (:meth:`TrackerConfig.pixel_scale` of the first frame's size; 1 before it).
    noise_scale : float
        The factor of the particle filter's position noise on this run's frames
        (:meth:`TrackerConfig.noise_scale` of the first frame's size; 1 before it).

    Examples
    --------
    >>> tracker = MultiObjectTracker(rng=0)                       # doctest: +SKIP
    >>> for frame in frames:                                       # doctest: +SKIP
    ...     for t in tracker.update(frame, detections=boxes_xywh_score):
    ...         print(t.id, t.box_xywh)
    """

    #: Calls between ``update``'s caller and the code whose line a warning names: a wrapper
    #: that calls ``update`` sets one more (:class:`pftrack.Tracker`, each frame, its own).
    caller_depth = 0
    #: The built-in detector's objects kept (see ``__init__``): a class default for a
    #: checkpoint pickled before it was kept.
    kept_own = 0
    #: Whether each report carries the histograms of its boxes (:attr:`.track.Track.colour`,
    #: for an offline pass that uses them: :class:`~.writer.TrackWriter`'s ``colour``). Off,
    #: nothing is stored (stop 74); a class default for checkpoints pickled before it.
    keep_colour = False

    def __init__(self, config: TrackerConfig | None = None, rng: RngLike = None,
                 detector: FrameDetector | None = None) -> None:  # fmt: skip
        if config is not None and not isinstance(config, TrackerConfig):
            raise TypeError(
                f"MultiObjectTracker: config must be a TrackerConfig, got {type(config).__name__}"
            )
        self.config = config if config is not None else TrackerConfig()
        self._busy = threading.Lock()  # held by update and prime (see _take)
        self._rng = generator(rng, "MultiObjectTracker: rng")
        self._ids = itertools.count(1)
        if detector is not None and not callable(getattr(detector, "detect", None)):
            # was taken, and the first frame failed: 'str' object has no attribute 'detect'
            shown = f"str {detector!r}" if isinstance(detector, str) else type(detector).__name__
            hint = f"; a built-in detector is named by TrackerConfig(detector={detector!r})"
            raise TypeError(
                "MultiObjectTracker: detector must have a detect(frame) method (or be None: the "
                f"built-in one), got {shown}{hint if isinstance(detector, str) else ''}"
            )
        self._detector: FrameDetector | None = detector
        self.tracks: list[LiveTrack] = []
        self._ended_unconfirmed: set[int] = set()
        self._n_started = 0  # tracks started so far (see tracks_started)
        #: Given detections left out for their size (under ``LifecycleConfig.min_area`` pixels
        #: clear of the frame's border), and given ones kept, over the run: why no track, said.
        self.tiny_given = 0
        self.kept_given = 0
        #: Whether the last update's given detections held a row given twice (the same box
        #: and class, :func:`first_copies`): the caller's own bookkeeping of the rows (the size
        #: samples of :class:`~pftrack.tracking.api.Tracker`) looks for copies only then.
        self.copies_given = False
        #: The built-in detector's objects over the run, those kept (``min_score`` and
        #: ``min_area``), and the highest score among them: a run whose objects ``min_score``
        #: or ``min_area`` left out says which (not "found no object").
        self.found_own = 0
        self.kept_own = 0
        self.best_own_score = -np.inf
        #: Frames whose built-in foreground mask held pixels but gave no box (the blob filters
        #: left every region out: people too small?), and the most such pixels in one frame.
        self.unboxed_own = 0
        self.unboxed_own_pixels = 0
        self.frame_index = 0
        self._mask: NDArray[np.uint8] | None = None  # the last frame's, see last_mask
        self._mask_shaded = False  # whether _mask still has its shadow pixels (127)
        # (detector, shadows_of(detector))
        self._shadows: tuple[FrameDetector, bool] | None = None
        self._joint = JointTracker(self.config, self._rng)
        # the configuration the tracks run with: `config` with its pixel settings scaled to the
        # first frame's size (TrackerConfig.pixel_diagonal), set by the first update
        self._effective: TrackerConfig | None = None
        self._frame_shape: tuple[int, ...] = ()  # the first frame's, set with _effective
        self._given_config = self.config  # tracks of given detections (given_particles), too
        self.pixel_scale = 1.0
        self.noise_scale = 1.0
        self._scores_are_confidences = True
        self._negative_warned = False  # scores below 0 and min_score were said
        self._joint_class: int | None = None  # sampler "rjmcmc": the run's one class id
        self._primed_shape: tuple[int, ...] = ()  # of the frames given to prime()
        self._birth_scores: F64 = np.zeros(0)  # scores of the first frames, sorted
        # the frame the birth window starts at: the first with a kept score (see _learn_birth)
        self._birth_start: int | None = None
        self._birth_level = np.inf
        # the same per class, and the level of each class with MIN_CLASS_BIRTH_SCORES of them
        self._class_birth_scores: dict[int, F64] = {}
        self._class_birth_levels: dict[int, float] = {}
        self._late_birth_scores: dict[int, F64] = {}  # after the window (_learn_late_birth)
        self.camera = CameraMotion(self.config.camera_motion, self.config.camera)
        self._background_ok = True  # False while the camera moves (see .camera)
        self.camera_step = CameraStep(None, 0.0, False, None, True)  # this frame's
        # confirmed tracks' speeds and the gain they give, per class (see motion_gain): fast
        # cars never raise the people's noise; the most recent samples of each class
        self._speeds: dict[int, RollingMedian] = {}
        self._gains: dict[int, float] = {}

    def _take(self, method: str) -> None:
        """Hold the tracker for one call, without waiting (RuntimeError naming `method`).

        Two threads' frames would otherwise go in one after the other's, until an object
        inside (a colour filter, the background model) refused the second thread halfway
        through a frame, the run torn.
        """
        if not self._busy.acquire(blocking=False):
            raise _in_use(self, f"MultiObjectTracker.{method}")

    def __getstate__(self) -> dict[str, Any]:
        """The run's state for pickle and ``copy`` (not while another thread is inside)."""
        self._take("__getstate__")
        try:
            state = self.__dict__.copy()
        finally:
            self._busy.release()
        del state["_busy"]  # a lock is not copied or pickled: a copy is free
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        speeds = state.get("_speeds")
        if isinstance(speeds, RollingMedian):  # a checkpoint made when every class shared one
            classes = {0} | {t.cls for t in state.get("tracks", [])}
            gain = state.pop("_gain", 1.0)
            state["_speeds"] = {c: copy.deepcopy(speeds) for c in classes}
            state["_gains"] = dict.fromkeys(classes, gain)
        if "_class_birth_scores" not in state:  # made when every class shared one threshold:
            # its scores go to class 0 (a run without classes goes on as it would have), other
            # classes start learning their own from here
            pooled = state.get("_birth_scores", np.zeros(0))
            state["_class_birth_scores"] = {0: pooled}
            enough = len(pooled) >= MIN_CLASS_BIRTH_SCORES
            state["_class_birth_levels"] = {0: state.get("_birth_level", np.inf)} if enough else {}
        state.setdefault("_late_birth_scores", {})  # made when late classes took the pooled
        # made when the window started at frame 1: it goes on doing so
        state.setdefault("_birth_start", 1)
        state.setdefault("copies_given", False)  # set by every update before it is read
        self.__dict__.update(state)
        self._busy = threading.Lock()  # a checkpoint pickled before the lock had none

    @property
    def frame_shape(self) -> tuple[int, ...]:
        """The run's frame shape ``(H, W, 3)`` (of its first frame; empty before it)."""
        return self._frame_shape

    # -- detections -------------------------------------------------------------------------
    def prime(self, frames: Iterable[NDArray[np.uint8]]) -> None:
        """Start the built-in detector's background from the median of `frames`.

        Reading ahead (e.g. the first 30 frames) gives the background model a picture of the
        empty scene before frame 1 is tracked; detectors without ``prime`` ignore it. The
        arrays of an iterable other than a list, a tuple or an array are copied as they come
        (a generator may refill one buffer with each frame). What is not an iterable (None),
        and one frame alone (``prime([frame])`` primes with it), are a TypeError, as
        :meth:`pftrack.Tracker.prime` says (were: "'NoneType' object is not iterable", and one
        frame's rows taken for frames).
        """
        frames_iterator(frames, "MultiObjectTracker.prime")
        self._take("prime")
        try:
            self._prime(frames)
        finally:
            self._busy.release()

    def _prime(self, frames: Iterable[NDArray[np.uint8]]) -> None:
        """:meth:`prime`, holding the tracker."""
        detector = self._ensure_detector()
        if hasattr(detector, "prime"):
            if isinstance(frames, (list, tuple, np.ndarray)):
                frames = list(frames)
            else:  # an iterator may refill one buffer with each frame: its arrays are copied
                frames = [f.copy() if isinstance(f, np.ndarray) else f for f in frames]
            if frames:
                self._primed_shape = np.shape(frames[0])
            if self.config.camera_motion != "off" and self.camera.check_frames(frames):
                return  # a moving camera has no empty scene
            detector.prime(frames)

    @property
    def detector(self) -> FrameDetector:
        """The detector: the one given, or the built-in ``config.detector`` (made on first use).

        Assignable: :class:`~pftrack.tracking.ahead.DetectAhead` puts a stand-in here for the
        length of a run, whose results a thread computed ahead with this detector.
        """
        return self._ensure_detector()

    @detector.setter
    def detector(self, detector: FrameDetector) -> None:
        self._detector = detector

    def _ensure_detector(self) -> FrameDetector:
        """Return the detector, made on first use.

        It gets the tracker's own HSV binning, so that its foreground bins and the tracker's
        histograms always share one layout. KNN, whose OpenCV model draws random numbers,
        gets its seed from the tracker's generator (one draw, when it is made); the other
        built-in detectors draw none, and take nothing from it.
        """
        if self._detector is None:
            name, settings = self.config.detector_name, self.config.detector_settings()
            size = self.config.open_size
            extra: dict[str, Any] = {} if size is None else {"open_size": size}
            if self.config.hold_frames:
                extra["hold_frames"] = self.config.hold_frames
            seed = int(self._rng.integers(2**63)) if name in SEEDED_DETECTORS else None
            if settings is not None:  # TrackerConfig(detector=PaperConfig(...)): every setting
                self._detector = detector_from(settings, seed=0 if seed is None else seed)
                return self._detector
            if seed is not None:
                extra["seed"] = seed
            self._detector = make_detector(name, hsv=self.config.binning, **extra)
        return self._detector

    def _check_given(self, frame: NDArray[np.uint8], detections: ArrayLike | None,
                     classes: ArrayLike | None, checked: bool
                     ) -> tuple[F64, F64, NDArray[np.int64]] | None:  # fmt: skip
        """The caller's boxes, scores and class ids, checked (None: the built-in detector).

        Raises what :meth:`update` raises for bad detections or classes, before any state
        changes (`checked`: see :meth:`update`).
        """
        if detections is None:
            return None
        if checked:  # what check_detections returns for them (views: never written to)
            d = np.asarray(detections)
            boxes, scores = d[:, :4], d[:, 4]
        else:
            boxes, scores = check_detections(detections, (frame.shape[0], frame.shape[1]))
        labels = np.zeros(len(boxes), np.int64)
        if classes is not None:
            if checked:  # integers in range (check_boxes_xyxy's)
                labels = np.asarray(classes).astype(np.int64, casting="unsafe").reshape(-1)
            else:  # refused, never truncated (was: 1.5 taken as class 1, NaN as -2**63)
                c = real_array(classes, "classes").reshape(-1)
                check_classes(c, "classes")
                labels = c.astype(np.int64)
            if len(labels) != len(boxes):
                raise ValueError(f"classes has {len(labels)} entries, expected {len(boxes)}")
        if self.config.sampler == "rjmcmc" and len(labels):
            # one class a run, not only a frame: the joint sampler's objects have no class, and
            # classes must never share an identity (was: a class per frame was taken, and the
            # rows said class 0)
            seen = np.unique(labels)
            if len(seen) > 1:
                raise ValueError("sampler 'rjmcmc' tracks one class; got several class ids")
            if self._joint_class is not None and int(seen[0]) != self._joint_class:
                raise ValueError(
                    f"sampler 'rjmcmc' tracks one class a run: class {int(seen[0])} after class "
                    f"{self._joint_class} in earlier frames (track each class with its own "
                    "tracker, or use sampler 'sis' or 'mh')"
                )
        return boxes, scores, labels

    def _detections(self, frame: NDArray[np.uint8],
                    given: tuple[F64, F64, NDArray[np.int64]] | None
                    ) -> tuple[F64, F64, BinnedImage]:  # fmt: skip
        """Return this frame's boxes, scores and bins.

        The built-in detector's (with foreground-only bins), or the caller's checked boxes,
        scores and classes (`given`), refined (:meth:`_refine`), with full-frame bins.
        """
        cfg = self.config
        if given is None:
            det = self._ensure_detector().detect(frame)
            self._mask, self._mask_shaded = det.mask, False
            boxes = np.asarray(det.boxes, dtype=np.float64).reshape(-1, 4)
            if not len(boxes):  # foreground but no box: said if the run has no track
                pixels = int(np.count_nonzero(det.mask))
                if pixels:
                    self.unboxed_own += 1
                    self.unboxed_own_pixels = max(self.unboxed_own_pixels, pixels)
            own_scores = np.asarray(det.scores, dtype=np.float64)
            if self._background_ok:
                return boxes, own_scores, det.binned
            # moving camera: colour of every pixel, not foreground
            everywhere = det.frame_bins
            if everywhere is None:  # binned on demand: only the pixels the boxes read
                everywhere = hsv_bins(frame, None, cfg.binning, lazy=self._lazy)
            return boxes, own_scores, everywhere
        boxes, scores, labels = given
        mask, binned, shaded = None, None, False
        if cfg.refine.enabled or cfg.sampler == "rjmcmc":
            mask, binned, shaded = self._foreground(frame)
        if binned is None:  # full-frame bins: the detector's fused pass made them, or lazy ones
            binned = hsv_bins(frame, None, cfg.binning, lazy=self._lazy)  # (only pixels read)
        # kept while the camera moves: the detector's noise-adaptive threshold keeps the mask
        # useful (measured in experiments/moving_camera.py)
        if cfg.refine.enabled and mask is not None and len(boxes):
            boxes = self._refine(boxes, labels, mask, shaded)
        return boxes, scores, binned

    def _refine(
        self, boxes: F64, labels: NDArray[np.int64], mask: NDArray[np.uint8], shaded: bool
    ) -> F64:
        """`boxes` shrunk to their foreground in `mask` (with shadows, 127, when `shaded`).

        The boxes of an upright class (:attr:`RefineConfig.upright_classes`) get the upright
        person's prior: legs the shadow test took grow back down (`leg_fill`), a cut to less
        than `min_height` keeps the box's rows. Other classes' boxes are shrunk to their
        foreground alone, shadows as background: a car's shadow below it fills its columns, and
        the person's prior grew the car's box down through it.
        """
        refine = self.config.refine
        upright = refine.upright_classes
        fill = refine.leg_fill if shaded else None
        person = None
        if upright is not None and (0 not in upright or labels.any()):  # else: the usual frame
            person = np.isin(labels, upright)
        if person is None or person.all():  # every box upright (people, or every class)
            return refine_boxes(
                boxes, mask, refine.fraction, leg_fill=fill, min_height=refine.min_height
            )
        out: F64 = boxes.copy()
        if person.any():
            out[person] = refine_boxes(
                boxes[person], mask, refine.fraction, leg_fill=fill, min_height=refine.min_height
            )
        plain = foreground_only(mask) if shaded else mask
        out[~person] = refine_boxes(boxes[~person], plain, refine.fraction)
        return out

    @property
    def last_mask(self) -> NDArray[np.uint8] | None:
        """The last frame's foreground mask (0 / 255), None before any background model ran.

        A mask with shadows (refinement's, :meth:`shadows_of`) is thresholded here, on demand:
        only the joint sampler reads it on every frame.
        """
        if self._mask_shaded and self._mask is not None:
            self._mask, self._mask_shaded = foreground_only(self._mask), False
        return self._mask

    def shadows_of(self, detector: FrameDetector) -> bool:
        """Whether box refinement asks `detector`'s ``foreground`` for shadows (127).

        With :attr:`RefineConfig.leg_fill` set and a ``foreground`` that takes `shadows`
        (:func:`takes_shadows`; otherwise the plain mask, and boxes do not grow). Decided once
        per detector object (the detector is swapped for a stand-in during a run).
        """
        cached = self._shadows
        if cached is None or cached[0] is not detector:
            cfg = self.config.refine
            wants = cfg.enabled and cfg.leg_fill is not None
            cached = self._shadows = (detector, wants and takes_shadows(detector))
        return cached[1]

    def _foreground(self, frame: NDArray[np.uint8]) -> tuple[NDArray[np.uint8], Any, bool]:
        """Return the mask, full-frame bins (or None) and whether the mask has shadows (127).

        From the detector's ``foreground`` when it has one (no blob pass), with shadows when
        :meth:`shadows_of` says so, else its ``detect``.
        """
        detector = self._ensure_detector()
        shaded = False
        if hasattr(detector, "foreground"):
            shaded = self.shadows_of(detector)
            # In this thread, the paper's detector leaves the bins to the tracker's lazy ones
            # (binned where the boxes read: cheaper than its fused pass binning every pixel);
            # a detector on its own thread (DetectAhead's stand-in), or RJ-MCMC (which reads
            # every pixel), keeps the fused bins.
            kw = {"bins": False} if self._lazy_bins_from(detector) else {}
            if shaded:
                mask, frame_bins = detector.foreground(frame, shadows=True, **kw)
            else:
                mask, frame_bins = detector.foreground(frame, **kw)
        else:
            det = detector.detect(frame)
            mask, frame_bins = det.mask, det.frame_bins
        self._mask, self._mask_shaded = mask, shaded
        return mask, frame_bins, shaded

    @property
    def _lazy(self) -> bool:
        """Whether full-frame bins made here are lazy: not for RJ-MCMC, which reads every pixel."""
        return self.config.sampler != "rjmcmc"

    def _lazy_bins_from(self, detector: FrameDetector) -> bool:
        """Whether ``detector.foreground`` should skip its bins for the tracker's lazy ones."""
        return self._lazy and isinstance(detector, PaperDetector)

    def _learn_birth(self, scores: F64, labels: NDArray[np.int64]) -> None:
        """Add a frame's kept scores to the birth threshold's (``LifecycleConfig.birth_quantile``).

        Over ``birth_window`` frames from the first with a kept score, pooled and per class
        (`labels`); fixed after. The window starts there, not at the run's first frame: a
        scene empty for its first 50 frames (a camera watching an empty street) learned
        nothing, and a detector whose scores stay below ``birth_score`` started no track at
        all (was: ``frame_index > birth_window``).
        """
        rules = self.config.lifecycle
        q = rules.birth_quantile
        if q is None or not len(scores):
            return
        if self._birth_start is None:
            self._birth_start = self.frame_index
        if self.frame_index - self._birth_start >= rules.birth_window:
            self._learn_late_birth(scores, labels, q)
            return
        self._birth_scores = np.sort(np.concatenate([self._birth_scores, scores]))
        self._birth_level = sorted_quantile(self._birth_scores, q)
        for c in _classes(labels):
            seen = self._class_birth_scores.get(c, np.zeros(0))
            seen = self._class_birth_scores[c] = np.sort(
                np.concatenate([seen, scores[labels == c]])
            )
            if len(seen) >= MIN_CLASS_BIRTH_SCORES:
                self._class_birth_levels[c] = sorted_quantile(seen, q)

    def _learn_late_birth(self, scores: F64, labels: NDArray[np.int64], q: float) -> None:
        """After the birth window: a class short of its own level learns it from later scores.

        A class with fewer than :data:`MIN_CLASS_BIRTH_SCORES` scores over the window, when
        the window's scores included another class's, keeps adding its scores (to those of
        the window) until it has that many, then takes their quantile `q`, fixed from then
        on. A run of one class never gets here with another class's scores in the window:
        its level stays the window's, as before.
        """
        for c in _classes(labels):
            if c in self._class_birth_levels:
                continue
            own = self._class_birth_scores.get(c, np.zeros(0))
            if len(self._birth_scores) <= len(own):  # the window saw no other class
                continue
            seen = self._late_birth_scores.get(c, own)
            seen = self._late_birth_scores[c] = np.sort(np.concatenate([seen, scores[labels == c]]))
            if len(seen) >= MIN_CLASS_BIRTH_SCORES:
                self._class_birth_levels[c] = sorted_quantile(seen, q)
                del self._late_birth_scores[c]  # fixed from here

    def birth_threshold(self, cls: int = 0) -> float:
        """The score a detection of class `cls` needs to start a track.

        ``min(birth_score, q)``, ``q`` the ``LifecycleConfig.birth_quantile`` of the scores of
        ``birth_window`` frames from the first with a kept score (updated each frame until then,
        fixed after): of
        class `cls`'s scores once there are :data:`MIN_CLASS_BIRTH_SCORES` of them, else of
        every class's (a class short of them over the window, beside another class, goes on
        learning after it: `_learn_late_birth`). A class
        the detector scores lower (bicycles at 0.3-0.5 beside people at 0.8-0.95) so starts
        tracks from its own upper three quarters (was: the pooled quartile for every class).
        ``birth_score`` alone with ``birth_quantile=None`` and before any score.
        """
        rules = self.config.lifecycle
        if rules.birth_quantile is None:
            return rules.birth_score
        return min(rules.birth_score, self._class_birth_levels.get(cls, self._birth_level))

    @property
    def speed(self) -> float | None:
        """Class 0's :meth:`speed_of` (a run without classes: every track's)."""
        return self.speed_of(0)

    def speed_of(self, cls: int = 0) -> float | None:
        """The median speed of class `cls`'s confirmed tracks so far, heights per frame.

        Each sample is a confirmed track's distance between two of its matched detections
        ``MotionConfig.speed_span`` or more frames apart, over its height and the frames between.
        None: no sample of that class.
        """
        speeds = self._speeds.get(cls)
        return None if speeds is None else speeds.median()

    def motion_gain(self, cls: int = 0) -> float:
        """The factor of class `cls`'s per-frame acceleration levels for its measured speed.

        ``max(1, speed / speed_reference) ** 1.5`` (``MotionConfig.speed_reference``; 1 when it is
        None or before 20 speed samples of the class). Continuous white-noise acceleration of
        density ``q`` gives a position variance of ``q dt^3 / 3`` over a step ``dt``: footage
        whose objects move `k` times further per frame (a `k` times lower frame rate) needs
        ``k^1.5`` times the acceleration's standard level per frame. Each class (the
        ``classes`` of :meth:`update`) has its own speed and gain: fast cars in a scene leave
        the people's levels as they are (was: one median over every class, so cars at 0.5
        heights a frame raised the walkers' noise 14-fold).
        """
        ref = self.config.motion.speed_reference
        speeds = self._speeds.get(cls)
        median = None if speeds is None else speeds.median()
        if ref is None or speeds is None or median is None or len(speeds) < MIN_SPEED_SAMPLES:
            return 1.0
        return float(max(1.0, median / ref) ** 1.5)

    @property
    def motion_gains(self) -> dict[int, float]:
        """:meth:`motion_gain` of each class that has speed samples."""
        return {c: self.motion_gain(c) for c in self._speeds}

    @property
    def tracks_started(self) -> int:
        """Tracks started so far, confirmed or not (each with a new id)."""
        return self._n_started + self._joint.started

    def never_confirmed(self) -> set[int]:
        """Ids of start-up tracks that never reached ``min_hits`` matches.

        SORT's convention reports the tracks born in the first ``min_hits`` frames at once;
        those that end (or the run ends) before ``min_hits`` matches are dropped by the
        offline pass (:meth:`pftrack.Tracker.finalize`).
        """
        n = self.config.lifecycle.min_hits
        return self._ended_unconfirmed | {t.id for t in self.tracks if t.reported and t.hits < n}

    # -- the per-frame step -----------------------------------------------------------------
    def update(self, frame: ArrayLike, detections: ArrayLike | None = None,
               classes: ArrayLike | None = None, *, checked: bool = False
               ) -> list[Track]:  # fmt: skip
        """Advance the tracker by one frame.

        Parameters
        ----------
        frame : (H, W, 3) array_like of uint8
            BGR frame.
        detections : (K, 4) or (K, 5) array_like, optional
            ``[left, top, width, height(, score)]`` from any detector; None runs the built-in
            background-subtraction detector. Their order does not matter
            (:func:`canonical_order`).
        classes : (K,) array_like of int, optional
            Class id of each detection: a track is only matched to detections of the class it
            was born with, so classes never share an identity (default: one class).
        checked : bool
            The caller vouches that `detections` is a (K, 5) float64 array of finite boxes
            with width and height > 0, each inside `frame` (what
            :func:`pftrack.tracking.api.check_boxes_xyxy` returns): the checks of
            :func:`~pftrack.detection.check_detections` are skipped.

        Returns
        -------
        list of Track
            The tracks reported for this frame (confirmed, and coasting ones the colour filter
            still holds), with the index of the detection each was matched to.

        Raises
        ------
        TypeError
            `detections` is a uint8 image (``update(dets, frame)``, :class:`Tracker`'s order:
            the message says the arguments look swapped), or `frame` is not a uint8 array,
            or `classes` are not numbers.
        ValueError
            A class id that is not an integer in ``[-2**31, 2**31 - 1]`` (NaN too), or not as
            many class ids as detections.
        RuntimeError
            Another thread is inside this tracker's ``update`` or ``prime`` (one thread at a
            time; nothing of this call went in).

        Warns
        -----
        UserWarning
            Once a run each: a confidence below 0 and `min_score`, a score above 1. Given once
            the frame is taken whole: a warning made an error (``python -W error``) leaves the
            tracker at the end of this frame, ready for the next one.
        """
        self._take("update")
        try:
            with Held() as held:
                reports = self._update(frame, detections, classes, checked)
            held.release(2 + self.caller_depth)  # update's caller, or the wrapper's
        finally:
            self._busy.release()
        return reports

    def _update(self, frame: ArrayLike, detections: ArrayLike | None, classes: ArrayLike | None,
                checked: bool) -> list[Track]:  # fmt: skip
        """:meth:`update`'s step; its warnings are held (:class:`pftrack._warn.Held`)."""
        not_an_image(  # update(dets, frame), Tracker's and BoxMOT's order
            detections, "MultiObjectTracker.update(frame, detections)", "detections",
            "Tracker.update takes (dets, frame), BoxMOT's order",
        )  # fmt: skip
        f = bgr_frame(frame)
        cfg = self._effective
        if cfg is not None and f.shape != self._frame_shape:
            h, w = self._frame_shape[:2]
            raise ValueError(
                f"frame is {f.shape[1]}x{f.shape[0]}, the run's earlier frames {w}x{h} (one "
                "size per run: a new tracker for a new video)"
            )
        if cfg is None and self._primed_shape and f.shape != self._primed_shape:
            h, w = self._primed_shape[:2]
            raise ValueError(
                f"frame is {f.shape[1]}x{f.shape[0]}, the frames given to prime() {w}x{h} (one "
                "size per run)"
            )
        # every check before the state changes: an update that raises leaves the tracker as
        # it was, so a caller may skip the frame and go on
        given = self._check_given(f, detections, classes, checked)
        # the caller's rows in one order whatever order they came in (a detector's rows in
        # another order give the same tracks): `rank` maps it back to the caller's rows
        rank = None
        self.copies_given = False
        if given is not None and len(given[1]) > 1:
            rank = canonical_order(*given)
            given = (given[0][rank], given[1][rank], given[2][rank])
            # a row given again (the same box and class) is one detection; the copy is in no
            # output row, as a duplicate refused a birth is in none (first_of_twins)
            once = first_copies(given[0], given[2])
            if once is not None:
                self.copies_given = True
                rank = rank[once]
                given = (given[0][once], given[1][once], given[2][once])
        if cfg is None:
            self._frame_shape = f.shape
            self.pixel_scale = self.config.pixel_scale(f.shape[1], f.shape[0])
            self.noise_scale = self.config.noise_scale(f.shape[1], f.shape[0])
            cfg = self._effective = self.config.scaled_pixels(self.noise_scale)
            self._given_config = cfg.for_given()  # one object: the filters' configs compare by id
            self._joint.config = cfg
        self.frame_index += 1
        # camera motion: move the tracks into this frame; no background model while it moves
        # the objects' own corners are no evidence of the camera's motion: the tracks', or the
        # joint sampler's objects' (it has no tracks: every frame of a still camera over moving
        # objects was taken for a moving one)
        objects = self._joint.boxes if cfg.sampler == "rjmcmc" else [t.box for t in self.tracks]
        step = self.camera.update(f, objects)
        if step.apply is not None:
            warp_tracks(self.tracks, step.apply)
            self._joint.warp(step.apply)  # until 5 December the joint sampler's were not moved
        self._background_ok = step.background_ok
        self.camera_step = step
        boxes, scores, binned = self._detections(f, given)
        labels = np.zeros(len(boxes), np.int64) if given is None else given[2]
        tiny = tiny_inside(boxes, f.shape, cfg.lifecycle.min_area)
        index = ((scores >= cfg.lifecycle.min_score) & ~tiny).nonzero()[0]
        scores_all = scores
        boxes, scores, labels = boxes[index], scores[index], labels[index]
        if rank is not None:
            index = rank[index]  # the caller's row of each box
        if given is not None:
            self.tiny_given += np.count_nonzero(tiny)  # (ndarray.sum: a Python wrapper)
            self.kept_given += len(index)
        elif len(tiny):  # the built-in detector's boxes, before min_score
            self.found_own += len(tiny)
            self.kept_own += len(index)
            self.best_own_score = max(self.best_own_score, float(scores_all.max()))
        if given is not None and len(given[1]) and not self._negative_warned:
            low = float(given[1].min())
            if low < 0.0 and low < cfg.lifecycle.min_score:  # said once a run
                self._negative_warned = True
                warn(
                    f"a detection confidence is {low:.3g}: confidences below min_conf "
                    f"{cfg.lifecycle.min_score:.3g} are ignored (logits? give probabilities in "
                    "[0, 1], or set min_conf)"
                )
        if given is not None and len(scores) and self._scores_are_confidences:
            # kept scores outside [0, 1] are a detector's own scale, not confidences: below 0
            # only with a min_score the caller set below 0; above 1 is said once
            high = float(scores.max())
            if scores.min() < 0.0 or high > 1.0 + CONFIDENCE_SLACK:
                self._scores_are_confidences = False
            if high > 1.0 + CONFIDENCE_SLACK:
                warn(
                    f"a detection score is {high:.3g} (frame {self.frame_index}): scores above "
                    "1 are taken as a detector's own scale, not confidences, so birth_score no "
                    "longer applies (min_conf still does)"
                )
        if cfg.sampler == "rjmcmc":
            mask = self.last_mask
            if mask is None or mask.shape != f.shape[:2] or not self._background_ok:
                mask = np.full(f.shape[:2], 255, np.uint8)  # no background model: all foreground
            if given is not None and len(given[2]) and self._joint_class is None:
                self._joint_class = int(given[2][0])
            joint = self._joint.step(
                self.frame_index, binned, mask, boxes, scores, index, labels, given is not None
            )
            if self._joint_class:  # the run's class on every row (the sampler's objects have none)
                joint = [dataclasses.replace(t, cls=self._joint_class) for t in joint]
            return joint

        # 1. every track's particle filter looks at this frame, its centre filter predicts
        gains = [self._gains.get(t.cls, 1.0) for t in self.tracks]  # each class's own
        predict_tracks(self.tracks, binned, cfg.motion.colour_noise, gains)

        # 2. association
        if len(boxes):
            hists = box_histograms(binned, _to_cxcywh(boxes), "uniform")
        else:
            hists = np.zeros((0, binned.n_bins))
        tracks = self.tracks
        classes_t = [t.cls for t in tracks]
        # one class everywhere (the usual case): every pair is allowed
        one_class = not any(classes_t) and not labels.any()
        result = associate(
            np.array([t.box for t in tracks]).reshape(-1, 4),
            np.array([t.size[1] for t in tracks]),
            np.array([t.time_since_update for t in tracks]),
            np.array([t.filter.reference for t in tracks]),
            boxes,
            hists,
            cfg.association,
            None if one_class else np.array(classes_t, np.int64)[:, None] == labels[None, :],
        )

        # 3. matched tracks follow their detection, unless it is a blob of several tracks
        #    (the particles and references of all of them re-seeded at once, at the end)
        smooth = cfg.motion.smooth_external and detections is not None
        followed: list[tuple[int, int]] = []
        # a detection larger than merge_ratio times its track's size may be a merged blob (on
        # plain floats, the same products as over arrays; sizes from before the tracks follow)
        box_list = boxes.tolist()
        ratio = cfg.association.merge_ratio
        large = []
        for ti, di in result.matches:
            w, h = tracks[ti].size.tolist()
            large.append(box_list[di][2] * box_list[di][3] > ratio * w * h)
        score_list, index_list = scores.tolist(), index.tolist()
        for ti, di in result.matches:
            tracks[ti].matched(score_list[di], index_list[di])
        # A large detection is tested against the boxes of the tracks followed before it, so
        # the tracks followed so far move (at once, in one call) before each such test; with
        # no large detection, every matched track follows in one call.
        moved = 0  # followed[:moved] have moved

        def follow_pending() -> None:
            nonlocal moved
            if moved < len(followed):
                pending = followed[moved:]
                follow_tracks_motion(
                    [tracks[k] for k, _ in pending], boxes[[d for _, d in pending]], cfg, smooth
                )
                moved = len(followed)

        for (ti, di), big in zip(result.matches, large, strict=True):
            if big:
                follow_pending()
                # a blob of the detection's class: a car's box holding a person is no blob
                # (was: any track's centre held it, whatever its class)
                cls = tracks[ti].cls
                others = (o.box.tolist() for k, o in enumerate(tracks) if k != ti and o.cls == cls)
                if covers_another(box_list[di], others):
                    continue  # a merged blob: the track keeps its own prediction
            followed.append((ti, di))
        follow_pending()
        if followed:
            dis = [di for _, di in followed]
            reseed_tracks([self.tracks[ti] for ti, _ in followed], boxes[dis], hists[dis], cfg)
            if self.keep_colour:  # the histogram each followed track was matched by
                for ti, di in followed:
                    self.tracks[ti].seen = hists[di]
        detected = len(boxes) > 0  # a frame without detections: not a miss (LiveTrack.coast)
        for ti in result.unmatched_tracks:
            self.tracks[ti].coast(detected)
        self._measure_speeds(followed, boxes, cfg)

        # 4. tracks that coasted too long end; 5. unexplained detections start tracks
        alive = [t.alive(cfg.lifecycle) for t in self.tracks]
        self._ended_unconfirmed.update(
            t.id
            for t, a in zip(self.tracks, alive, strict=True)
            if not a and t.reported and t.hits < cfg.lifecycle.min_hits
        )
        self.tracks = [t for t, a in zip(self.tracks, alive, strict=True) if a]
        confidences = detections is not None and self._scores_are_confidences
        gates: dict[int, float] = {}  # the birth threshold of each class (none: -inf)
        if confidences:
            self._learn_birth(scores, labels)
            gates = {c: self.birth_threshold(c) for c in _classes(labels)}
        born = cfg if detections is None else self._given_config  # given_particles
        unmatched = result.unmatched_detections
        beside = set() if detections is None else self._beside(boxes, labels, unmatched, cfg)
        # not born: no foreground colour to build a reference from, too unsure, or a second
        # box on a person already followed (LifecycleConfig.birth_overlap)
        candidates = [
            di
            for di in unmatched
            if not (
                hists[di].sum() <= 0
                or scores[di] < gates.get(int(labels[di]), -np.inf)
                or di in beside
            )
        ]
        # nor a second box on an object another detection of this frame explains: one matched
        # to a track, or a higher-scored box that started one (the rows are in
        # canonical_order, highest score first), e.g. the same box twice; the joint sampler's
        # births follow the same rule (JointTracker.step)
        explained = np.zeros(len(boxes), np.bool_)
        explained[[di for _, di in result.matches]] = True
        overlap = None if detections is None else cfg.lifecycle.birth_overlap
        for di in first_of_twins(boxes, labels, candidates, explained, overlap):
            seed = int(self._rng.integers(2**63))
            t = LiveTrack(
                next(self._ids), boxes[di].copy(), hists[di], born, seed, float(scores[di])
            )
            t.det_index = int(index[di])
            t.cls = int(labels[di])
            if self.keep_colour:
                t.seen = hists[di]
            self.tracks.append(t)
            self._n_started += 1

        # 6. report
        early = self.frame_index <= cfg.lifecycle.min_hits
        keep = self.keep_colour
        reports = (t.report(self.frame_index, early, cfg.lifecycle, keep) for t in self.tracks)
        return [r for r in reports if r is not None]

    def _beside(self, boxes: F64, labels: NDArray[np.int64], unmatched: Sequence[int],
                cfg: TrackerConfig) -> set[int]:  # fmt: skip
        """Unmatched detections on a track of their class: they start no track.

        Those that overlap a live track, confirmed or tentative, by an IoU above
        ``LifecycleConfig.birth_overlap`` (given detections only; the caller skips the
        built-in detector's). A tentative track counts too: a detector's duplicate of a box
        that started a track a frame before is left unmatched beside it (was: confirmed
        tracks only, and every duplicated box started two tracks that both lived on).
        """
        life = cfg.lifecycle
        if life.birth_overlap is None or not len(unmatched) or not self.tracks:
            return set()
        rows = np.asarray(unmatched, dtype=np.intp)
        # over the pairs that overlap at all (an IoU above birth_overlap > 0 needs an
        # intersection), not a dense (unmatched, tracks) IoU matrix: the same IoUs of the same
        # pairs, in memory that grows with the pairs (10 000 boxes in a frame, stop 70)
        track_boxes = np.array([t.box for t in self.tracks])
        k, j = _overlap_pairs(boxes[rows, :4], track_boxes)
        same = labels[rows[k]] == np.array([t.cls for t in self.tracks], np.int64)[j]
        hit = (_iou_rows(boxes[rows[k], :4], track_boxes[j]) > life.birth_overlap) & same
        return set(rows[k[hit]].tolist())

    def _measure_speeds(
        self, followed: list[tuple[int, int]], boxes: F64, cfg: TrackerConfig
    ) -> None:
        """Speed samples of the confirmed tracks that followed a detection; the new gains."""
        n = cfg.lifecycle.min_hits
        span = cfg.motion.speed_span
        dis = [di for _, di in followed]
        b = boxes[dis]
        centres = (b[:, :2] + b[:, 2:4] / 2).tolist()
        heights = b[:, 3].tolist()
        sampled = set()
        for (ti, _), centre, h in zip(followed, centres, heights, strict=True):
            t = self.tracks[ti]
            v = t.speed(self.frame_index, centre, h, span)
            if v is not None and t.hits >= n:
                speeds = self._speeds.get(t.cls)
                if speeds is None:
                    speeds = self._speeds[t.cls] = RollingMedian(MAX_SPEED_SAMPLES)
                speeds.add(v)
                sampled.add(t.cls)
        for c in sampled:
            self._gains[c] = self.motion_gain(c)


def _classes(labels: NDArray[np.int64]) -> list[int]:
    """The class ids of a frame's detections in increasing order, as plain ints.

    ``np.unique(labels).tolist()``, on plain ints: about 1 us for a frame's few rows,
    ``np.unique`` about 6 (the tracker asks twice a frame).
    """
    return sorted(set(labels.tolist()))


def first_copies(boxes: F64, labels: NDArray[np.int64] | F64) -> NDArray[np.intp] | None:
    """The rows of a frame's detections that repeat no earlier row; None: none repeats one.

    A repeat has the box (``left, top, w, h``) and class of an earlier row, whatever its
    score: the same detection given twice (a detector without non-maximum suppression, two
    detectors' outputs concatenated, a det.txt holding its rows twice). In
    :func:`canonical_order` the earlier row is the higher-scored one, so that one is kept.
    Until 6 December both copies went to the association, and a second track on one person,
    which alone coasts and ends, took the spare copy every frame and lived on beside the
    first (PETS09-S2L1's public det.txt given twice: 30 tracks for 22, MOTA 80.7 -> 32.4).
    """
    # on plain floats: a set of a frame's few rows costs about 7 us, np.unique's rows 110
    keys = list(zip(*boxes[:, :4].T.tolist(), labels.tolist(), strict=True))
    if len(set(keys)) == len(keys):
        return None
    seen: set[tuple[float, ...]] = set()
    first = []
    for k, key in enumerate(keys):
        if key not in seen:
            seen.add(key)
            first.append(k)
    return np.array(first, dtype=np.intp)


def canonical_order(boxes: F64, scores: F64, labels: NDArray[np.int64]) -> NDArray[np.intp]:
    """The order in which a frame's detections are taken, whatever order they were given in.

    Highest score first (the order of a detector's output after non-maximum suppression, and
    of MOTChallenge's detection files: for those the order is the file's), then by ``left``,
    ``top``, ``w``, ``h`` and class id. Rows equal in all of these are alike to the tracker;
    among them the given order is kept (a stable sort).
    """
    out: NDArray[np.intp] = np.lexsort(
        (labels, boxes[:, 3], boxes[:, 2], boxes[:, 1], boxes[:, 0], -scores)
    )
    return out


def tiny_inside(boxes: F64, shape: tuple[int, ...], min_area: float) -> NDArray[np.bool_]:
    """Which `boxes` (``left, top, w, h``) are small and clear of the frame's border.

    Small: under `min_area` pixels (``LifecycleConfig.min_area``). A small box that touches
    the border is kept: the visible part of an object entering or leaving the frame.
    """
    rows, cols = shape[0], shape[1]
    small = boxes[:, 2] * boxes[:, 3] < min_area
    if not small.any():  # the usual frame: no small box, none to test against the border
        return small
    clear = (
        (boxes[:, 0] > 0.5)
        & (boxes[:, 1] > 0.5)
        & (boxes[:, 0] + boxes[:, 2] < cols - 0.5)
        & (boxes[:, 1] + boxes[:, 3] < rows - 0.5)
    )
    out: NDArray[np.bool_] = small & clear
    return out


def sorted_quantile(values: F64, q: float) -> float:
    """``float(np.quantile(values, q))`` of sorted, finite, non-empty `values`, the same float.

    NumPy's default ("linear") method step for step, without its general machinery (about
    30 us a call): the order statistics at ``floor((n - 1) q)`` and the next one, and NumPy's
    interpolation between them (from the upper one when the weight is at least 1/2).
    """
    n = len(values)
    v = (n - 1) * q
    if not isinstance(v, float):  # an integer index: NumPy takes the value itself
        return float(values[v])
    if v >= n - 1:
        return float(values[n - 1])
    below = math.floor(v)
    gamma = v - below
    a, b = float(values[below]), float(values[below + 1])
    diff = b - a
    return b - diff * (1 - gamma) if gamma >= 0.5 else a + diff * gamma


def takes_shadows(detector: FrameDetector) -> bool:
    """Whether `detector`'s ``foreground`` takes a `shadows` argument (pftrack's detectors do).

    A detector may say so itself with a boolean ``foreground_shadows`` attribute (the stand-in
    of :class:`~pftrack.tracking.ahead.DetectAhead` says whether its thread computed the mask
    with shadows).
    """
    said = getattr(detector, "foreground_shadows", None)
    if isinstance(said, bool):
        return said
    try:
        foreground = getattr(detector, "foreground", None)  # optional (FrameDetector)
        return callable(foreground) and "shadows" in inspect.signature(foreground).parameters
    except (TypeError, ValueError):  # no signature (a C extension's method)
        return False
