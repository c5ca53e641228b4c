"""Multi-object tracking with one colour particle filter per object (the first paper's method).

Each frame: detections come from the built-in background-subtraction detector or from any
detector the caller runs; every live track advances its own SIS colour particle filter on the
frame (foreground pixels only when a foreground mask is known); tracks and detections are paired
by the Hungarian method over overlap, centre distance and colour similarity; a matched track's
particles are re-seeded around its detection; a track without a detection goes on from its
particle filter alone (through merged blobs and occlusions) for ``max_coast`` frames, then ends;
a detection no track explains starts a new track whose reference histogram is taken from it.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import linear_sum_assignment

from pftrack._typing import RngLike
from pftrack.eval.metrics import iou_xywh
from pftrack.recovery.linking import LinkConfig
from pftrack.smoothing import BoxSmoother, cv_predict, cv_update, smooth_tracks
from pftrack.particle_filter import (
    Ar2Model,
    ColourParticleFilter,
    FilterConfig,
    HsvBinning,
    MHColourParticleFilter,
    RJMCMCConfig,
    RJMCMCFilter,
    box_histograms,
    hsv_bins,
)

__all__ = ["MultiObjectTracker", "Track", "TrackerConfig", "iou_matrix"]


@dataclass(frozen=True)
class TrackerConfig:
    """Configuration of :class:`MultiObjectTracker` (defaults are rules, not per-sequence tuning).

    Attributes
    ----------
    filter : FilterConfig
        Particles per object, AR(2) dynamics (eq. 7, or eq. 8 with ``use_means``), λ.
    binning : HsvBinning
        HSV histogram layout (110 bins by default).
    sampler : {"sis", "mh", "rjmcmc"}
        Sequential importance sampling per object (the paper's method), Metropolis-Hastings per
        object, or one joint RJ-MCMC chain over all objects (Smith et al. 2005): the paper's
        comparison samplers.
    rjmcmc : RJMCMCConfig
        Settings of the joint sampler (used with ``sampler="rjmcmc"``); its sample count and
        AR2 dynamics are set from ``filter`` so that budgets and models compare.
    detector : {"paper", "mog2", "knn"}
        Built-in detector used when :meth:`MultiObjectTracker.update` gets no detections.
    max_coast : int
        Frames a track goes on from its particle filter alone before it ends.
    min_hits : int
        Matched frames before a new track is reported (tracks born in the first `min_hits`
        frames are reported at once).
    min_score : float
        Detections with a lower score are ignored.
    match_iou : float
        Minimum overlap (IoU) for a track-detection pair, unless the centres are close.
    match_distance : float
        Maximum centre distance of a pair, in track heights (grows with the time coasted).
    colour_weight : float
        Weight of colour dissimilarity ``1 - rho`` in the association cost.
    reference_rate : float
        How fast a reference histogram adapts to a matched detection (0 keeps the first one).
    merge_ratio : float
        A detection this many times larger than a track is a merged blob: it does not re-seed
        the track's particles (the colour filter carries the track through the merge).
    coast_min_rho : float
        A coasting track is reported only while its colour match ``rho`` stays above this.
    tentative_coast : int
        Frames a not yet confirmed track may go without a detection before it is dropped.
    refine_boxes : bool
        With external detections, also run the background model and shrink each detection box
        to the rows and columns where its foreground is (static cameras: detector boxes are
        often loose). A box with too little foreground is left as it is.
    refine_fraction : float
        A row or column belongs to the object when its foreground fraction exceeds this share of
        the box's densest row or column.
    birth_score : float
        An external detection starts a track only with at least this score (a detection too
        unsure to start a track can still keep one alive, as in ByteTrack). Applied while every
        score seen lies in [0, 1], i.e. scores are confidences; a detector with other scores,
        and the built-in detector, start tracks from any detection.
    smooth_external : bool
        With external detections, report a matched track's filtered box (Kalman centre,
        smoothed size) rather than the detection's own box, which jitters from frame to frame.
        The built-in detector's boxes are the foreground's extent and are reported as they are.
    unmatched_cost : float
        What leaving a track or a detection unassigned costs in the association: a pair is made
        only when its cost is below twice this, not merely because it passed the gate. The
        default 1.5 refuses a pair that neither overlaps nor lies within two radii whatever
        its colour (those two terms alone reach 3); ``inf`` assigns every gated pair it can.
    motion_accel, detection_noise, colour_noise : float
        The constant-velocity Kalman filter of each track's centre, in track heights: the
        standard deviation of the acceleration per frame², of a detection's centre and of the
        colour filter's estimate (the measurement while the track coasts, and a second opinion
        before association).
    """

    filter: FilterConfig = field(
        default_factory=lambda: FilterConfig(
            n_particles=100, model=Ar2Model(sigma_xy=3.0, sigma_s=0.02, velocity_gain=0.5, scale_gain=0.0)
        )
    )
    binning: HsvBinning = field(default_factory=HsvBinning)
    rjmcmc: RJMCMCConfig = field(default_factory=RJMCMCConfig)
    sampler: str = "sis"
    detector: str = "paper"
    max_coast: int = 10
    min_hits: int = 4
    min_score: float = 0.0
    match_iou: float = 0.1
    match_distance: float = 0.3
    colour_weight: float = 0.5
    reference_rate: float = 0.05
    merge_ratio: float = 1.8
    coast_min_rho: float = 0.5
    tentative_coast: int = 0
    refine_boxes: bool = True
    refine_fraction: float = 0.05
    birth_score: float = 0.9
    smooth_external: bool = True
    motion_accel: float = 0.01
    detection_noise: float = 0.05
    colour_noise: float = 0.15
    unmatched_cost: float = 1.5

    def __post_init__(self) -> None:
        if self.sampler not in ("sis", "mh", "rjmcmc"):
            raise ValueError(f"sampler is {self.sampler!r}, expected 'sis', 'mh' or 'rjmcmc'")
        if self.detector not in ("paper", "mog2", "knn"):
            raise ValueError(f"detector is {self.detector!r}, expected 'paper', 'mog2' or 'knn'")
        for name in ("max_coast", "min_hits"):
            v = getattr(self, name)
            if not isinstance(v, (int, np.integer)) or v < 0:
                raise ValueError(f"{name} is {v!r}, expected an integer >= 0")
        if not self.unmatched_cost > 0:  # NaN fails too
            raise ValueError(f"unmatched_cost is {self.unmatched_cost}, expected a value > 0 (inf: off)")
        for name in ("match_iou", "reference_rate", "coast_min_rho"):
            v = getattr(self, name)
            if not 0.0 <= v <= 1.0:
                raise ValueError(f"{name} is {v}, expected a value in [0, 1]")


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
        Index of the detection (in the order given to :meth:`~MultiObjectTracker.update`)
        matched to this track, or None when it was carried by its particle filter alone.
    age : int
        Frames since birth.
    time_since_update : int
        Frames since the last matched detection (0 when matched this frame).
    history : tuple of (frame, box_xywh, score)
        On the frame a new track is first reported, the detection boxes it was matched to while
        it waited for ``min_hits`` (frame numbers count :meth:`~MultiObjectTracker.update` calls
        from 1); empty otherwise. Offline writers back-fill them; online users may ignore them.
    detection_box : (4,) ndarray or None
        The matched detection's box (after refinement) as the tracker measured it, when it
        re-seeded the track this frame; None when coasting or inside a merged blob. ``box_xywh``
        may be a filtered version of it (``smooth_external``).
    """

    id: int
    box_xywh: NDArray[np.float64]
    score: float
    detection_index: Optional[int]
    age: int
    time_since_update: int
    history: tuple[tuple[int, NDArray[np.float64], float], ...] = ()
    detection_box: Optional[NDArray[np.float64]] = None


def iou_matrix(a_xywh: ArrayLike, b_xywh: ArrayLike) -> NDArray[np.float64]:
    """Intersection over union of every box in `a` (M, 4) with every box in `b` (K, 4).

    The same function as :func:`pftrack.eval.iou_xywh`, so tracking and scoring never disagree.
    """
    return iou_xywh(a_xywh, b_xywh)


def refine_boxes(boxes_xywh: NDArray[np.float64], mask: NDArray[np.uint8], fraction: float = 0.1,
                 min_cover: float = 0.1) -> NDArray[np.float64]:  # fmt: skip
    """Shrink boxes to the extent of their foreground.

    Parameters
    ----------
    boxes_xywh : (K, 4) ndarray
        Boxes (left, top, width, height).
    mask : (H, W) ndarray of uint8
        Foreground mask (non-zero = foreground).
    fraction : float
        Rows and columns whose foreground share is above ``fraction`` times the densest row or
        column's are kept; the new box spans the first to the last kept one.
    min_cover : float
        Boxes whose foreground covers less than this share are returned unchanged (the
        background model has not seen the object move, or it is not there).

    Returns
    -------
    (K, 4) ndarray
        Refined boxes.
    """
    out = np.array(boxes_xywh, dtype=np.float64, copy=True).reshape(-1, 4)
    rows, cols = mask.shape
    for k, (x, y, w, h) in enumerate(out):
        x0, x1 = int(max(0, np.floor(x))), int(min(cols, np.ceil(x + w)))
        y0, y1 = int(max(0, np.floor(y))), int(min(rows, np.ceil(y + h)))
        if x1 - x0 < 3 or y1 - y0 < 3:
            continue
        patch = mask[y0:y1, x0:x1] > 0
        if patch.mean() < min_cover:
            continue
        col, row = patch.mean(axis=0), patch.mean(axis=1)
        cs = np.flatnonzero(col > fraction * col.max())
        rs = np.flatnonzero(row > fraction * row.max())
        out[k] = (x0 + cs[0], y0 + rs[0], cs[-1] + 1 - cs[0], rs[-1] + 1 - rs[0])
    return out


def _xywh_to_cxcywh(b: NDArray[np.float64]) -> NDArray[np.float64]:
    b = np.asarray(b, dtype=np.float64)
    return np.concatenate([b[..., :2] + b[..., 2:] / 2, b[..., 2:]], axis=-1)


def _cxcywh_to_xywh(b: NDArray[np.float64]) -> NDArray[np.float64]:
    b = np.asarray(b, dtype=np.float64)
    return np.concatenate([b[..., :2] - b[..., 2:] / 2, b[..., 2:]], axis=-1)


class _CentreKalman:
    """Constant-velocity Kalman filter of a track's centre, both axes sharing one covariance.

    Noise levels are in units of the track's height ``h`` so that one rule fits any image scale:
    white-noise acceleration ``σ_a = accel·h`` per frame², and a measurement standard deviation
    of ``detection_noise·h`` for a detection and ``colour_noise·h`` for a colour-filter estimate.
    The equations are those of the offline smoother (:func:`pftrack.smoothing.cv_predict`,
    :func:`~pftrack.smoothing.cv_update`), run on both axes at once.
    """

    def __init__(self, centre: NDArray[np.float64], height: float, accel: float) -> None:
        self.p = np.array(centre, dtype=np.float64)
        self.v = np.zeros(2)
        self.accel = accel
        # unknown initial velocity: about a third of a height per frame (a fast walker at 5 fps)
        self.cov = ((0.05 * height) ** 2, 0.0, (0.3 * height) ** 2)  # p00, p01, p11

    @property
    def P(self) -> NDArray[np.float64]:  # noqa: N802 - the usual name
        """The (position, velocity) covariance of one axis, 2x2."""
        p00, p01, p11 = self.cov
        return np.array([[p00, p01], [p01, p11]])

    def predict(self, height: float) -> None:
        (self.p, self.v), self.cov = cv_predict((self.p, self.v), self.cov, (self.accel * height) ** 2)

    def update(self, z: NDArray[np.float64], sigma: float) -> None:
        (self.p, self.v), self.cov = cv_update((self.p, self.v), self.cov, np.asarray(z, dtype=np.float64), sigma**2)


class _TrackState:
    """A live track: its particle filter and bookkeeping (internal)."""

    def __init__(self, track_id: int, box_xywh: NDArray[np.float64], reference: NDArray[np.float64],
                 config: TrackerConfig, seed: int, score: float) -> None:  # fmt: skip
        self.id = track_id
        cls = MHColourParticleFilter if config.sampler == "mh" else ColourParticleFilter
        self.filter = cls(_xywh_to_cxcywh(box_xywh), reference, config.filter, rng=seed)
        self.box = box_xywh.copy()
        self.size = box_xywh[2:].copy()  # smoothed detection size
        self.motion = _CentreKalman(box_xywh[:2] + box_xywh[2:] / 2, box_xywh[3], config.motion_accel)
        self.hits = 1
        self.age = 1
        self.time_since_update = 0
        self.score = score
        self.rho = 1.0
        self.det_index: int | None = None
        self.measured: NDArray[np.float64] | None = box_xywh.copy()  # this frame's detection box
        self.unreported: list[tuple[int, NDArray[np.float64], float]] = []
        self.reported = False


class MultiObjectTracker:
    """Track many objects with one colour particle filter each.

    Parameters
    ----------
    config : TrackerConfig
        All settings.
    rng : numpy.random.Generator, int or None
        Seed: the same seed and input give the same tracks.
    detector : object, optional
        Any object with ``detect(frame) -> Detections`` (see :mod:`pftrack.detection`); by
        default the one named by ``config.detector``, created on first use.

    Examples
    --------
    >>> tracker = MultiObjectTracker(rng=0)                       # doctest: +SKIP
    >>> for frame in frames:                                       # doctest: +SKIP
    ...     for t in tracker.update(frame, detections=boxes_xywh_score):
    ...         print(t.id, t.box_xywh)
    """

    def __init__(self, config: TrackerConfig = TrackerConfig(), rng: RngLike = None,
                 detector: Any = None) -> None:  # fmt: skip
        self.config = config
        self._rng = np.random.default_rng(rng)
        self._ids = itertools.count(1)
        self._detector = detector
        self.tracks: list[_TrackState] = []
        self.frame_index = 0
        self.last_mask: NDArray[np.uint8] | None = None
        self._joint: RJMCMCFilter | None = None
        self._scores_are_confidences = True

    # -- detections -------------------------------------------------------------------------
    def prime(self, frames: Iterable[NDArray[np.uint8]]) -> None:
        """Start the built-in detector's background from the median of `frames`.

        Reading ahead (e.g. the first 30 frames) gives the background model a picture of the
        empty scene before frame 1 is tracked; detectors without ``prime`` ignore it.
        """
        detector = self._ensure_detector()
        if hasattr(detector, "prime"):
            detector.prime(frames)

    def _ensure_detector(self) -> Any:
        """The detector, made on first use with the tracker's own HSV binning, so that its
        foreground bins and the tracker's histograms always share one layout."""
        if self._detector is None:
            from pftrack.detection import make_detector

            self._detector = make_detector(self.config.detector, hsv=self.config.binning)
        return self._detector

    def _detect(self, frame: NDArray[np.uint8]) -> Any:
        det = self._ensure_detector().detect(frame)
        self.last_mask = det.mask
        return det

    def _foreground(self, frame: NDArray[np.uint8]) -> tuple[NDArray[np.uint8], Any]:
        """Foreground mask and full-frame bins (or None) for external detections: the
        detector's ``foreground`` when it has one (no blob pass), else its ``detect``."""
        detector = self._ensure_detector()
        if hasattr(detector, "foreground"):
            mask, frame_bins = detector.foreground(frame)
        else:
            det = detector.detect(frame)
            mask, frame_bins = det.mask, det.frame_bins
        self.last_mask = mask
        return mask, frame_bins

    @staticmethod
    def _check_detections(detections: ArrayLike, shape: tuple[int, int]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        d = np.asarray(detections, dtype=np.float64)
        if d.size == 0:
            return np.zeros((0, 4)), np.zeros(0)
        if d.ndim != 2 or d.shape[1] not in (4, 5):
            raise ValueError(f"detections must have shape (K, 4) or (K, 5) [left, top, w, h(, score)], got {d.shape}")
        if not np.all(np.isfinite(d)):
            raise ValueError("detections contain NaN or inf")
        if np.any(d[:, 2] <= 0) or np.any(d[:, 3] <= 0):
            k = int(np.flatnonzero((d[:, 2] <= 0) | (d[:, 3] <= 0))[0])
            raise ValueError(f"detection {k} has width or height <= 0: {d[k].tolist()}")
        rows, cols = shape
        outside = (d[:, 0] >= cols) | (d[:, 1] >= rows) | (d[:, 0] + d[:, 2] <= 0) | (d[:, 1] + d[:, 3] <= 0)
        if np.any(outside):
            k = int(np.flatnonzero(outside)[0])
            raise ValueError(
                f"detection {k} {d[k, :4].tolist()} lies outside the {cols}x{rows} frame "
                "(wrong coordinate scale? PETS boxes need --det-scale 0.625)"
            )
        scores = d[:, 4] if d.shape[1] == 5 else np.ones(len(d))
        return d[:, :4].copy(), scores.copy()

    # -- the per-frame step -----------------------------------------------------------------
    def update(self, frame: ArrayLike, detections: ArrayLike | None = None) -> list[Track]:
        """Advance the tracker by one frame.

        Parameters
        ----------
        frame : (H, W, 3) array_like of uint8
            BGR frame.
        detections : (K, 4) or (K, 5) array_like, optional
            ``[left, top, width, height(, score)]`` from any detector; None runs the built-in
            background-subtraction detector.

        Returns
        -------
        list of Track
            The tracks reported for this frame (confirmed, and coasting ones the colour filter
            still holds), with the index of the detection each was matched to.
        """
        f = np.asarray(frame)
        if f.dtype != np.uint8 or f.ndim != 3 or f.shape[2] != 3:
            raise TypeError(f"frame must be a (H, W, 3) uint8 BGR array, got {f.dtype} {f.shape}")
        cfg = self.config
        self.frame_index += 1
        if detections is None:
            det = self._detect(f)
            boxes = np.asarray(det.boxes, dtype=np.float64).reshape(-1, 4)
            scores = np.asarray(det.scores, dtype=np.float64)
            binned = det.binned
        else:
            boxes, scores = self._check_detections(detections, f.shape[:2])
            if np.any((scores < 0) | (scores > 1)):
                self._scores_are_confidences = False
            mask, binned = self._foreground(f) if cfg.refine_boxes or cfg.sampler == "rjmcmc" else (None, None)
            if binned is None:  # full-frame bins: the detector's fused pass made them, or one pass here
                binned = hsv_bins(f, None, cfg.binning)
            if cfg.refine_boxes and mask is not None and len(boxes):
                boxes = refine_boxes(boxes, mask, cfg.refine_fraction)
        keep = scores >= cfg.min_score
        index = np.flatnonzero(keep)
        boxes, scores = boxes[keep], scores[keep]
        if cfg.sampler == "rjmcmc":
            return self._update_joint(f, binned, boxes, scores, index)

        # 1. every track's particle filter looks at this frame
        for t in self.tracks:
            t.measured = None
            state = t.filter.step(binned)
            t.rho = state.rho
            # the motion model predicts, the colour filter's estimate is a noisy measurement of it
            t.motion.predict(t.size[1])
            t.motion.update(state.box_cxcywh[:2], cfg.colour_noise * t.size[1])
            cx, cy = t.motion.p
            t.box = np.array([cx - t.size[0] / 2, cy - t.size[1] / 2, t.size[0], t.size[1]])
            t.age += 1

        # 2. association
        det_hists = box_histograms(binned, _xywh_to_cxcywh(boxes), "uniform") if len(boxes) else np.zeros((0, binned.n_bins))
        matches, unmatched_t, unmatched_d = self._associate(boxes, det_hists)

        # 3. matched tracks follow their detection
        smooth = cfg.smooth_external and detections is not None
        for ti, di in matches:
            t = self.tracks[ti]
            b = boxes[di]
            merged = b[2] * b[3] > cfg.merge_ratio * t.size[0] * t.size[1] and self._shared(di, boxes, ti)
            t.score = float(scores[di])
            t.hits += 1
            t.time_since_update = 0
            t.det_index = int(index[di])
            if merged:
                t.det_index = None
                continue
            t.measured = b.copy()
            centre = b[:2] + b[2:] / 2
            t.motion.update(centre, cfg.detection_noise * t.size[1])
            t.size = 0.7 * t.size + 0.3 * b[2:]
            t.box = np.concatenate([t.motion.p - t.size / 2, t.size]) if smooth else b.copy()
            t.filter.reinitialise(_xywh_to_cxcywh(b), velocity=t.motion.v)
            hist = det_hists[di]
            if cfg.reference_rate > 0 and hist.sum() > 0:
                t.filter.set_reference((1 - cfg.reference_rate) * t.filter.reference + cfg.reference_rate * hist)

        for ti in unmatched_t:
            t = self.tracks[ti]
            t.time_since_update += 1
            t.det_index = None
            t.score = t.rho

        # 4. tracks that coasted too long end; 5. unexplained detections start tracks
        self.tracks = [
            t for t in self.tracks
            if t.time_since_update <= (cfg.max_coast if t.hits >= cfg.min_hits else min(cfg.max_coast, cfg.tentative_coast))
        ]  # fmt: skip
        birth_score = cfg.birth_score if detections is not None and self._scores_are_confidences else -np.inf
        for di in unmatched_d:
            hist = det_hists[di]
            if hist.sum() <= 0 or scores[di] < birth_score:
                continue  # no foreground colour to build a reference from, or too unsure
            t = _TrackState(next(self._ids), boxes[di].copy(), hist, cfg, int(self._rng.integers(2**63)), float(scores[di]))
            t.det_index = int(index[di])
            self.tracks.append(t)

        return self._report()

    def _update_joint(self, frame: NDArray[np.uint8], binned: Any, boxes: NDArray[np.float64],
                      scores: NDArray[np.float64], index: NDArray[np.intp]) -> list[Track]:  # fmt: skip
        """One frame of the joint RJ-MCMC sampler: detections are its birth candidates."""
        if self._joint is None:
            from dataclasses import replace

            # same budget and the same AR2 dynamics as the per-object filters, so that only the
            # sampler differs between sampler="sis" | "mh" | "rjmcmc"
            m = self.config.filter.model
            rj = replace(self.config.rjmcmc, n_samples=self.config.filter.n_particles,
                         a=tuple(m.a), b=tuple(m.b), sigma=tuple(m.sigma), s_min=m.s_min, s_max=m.s_max)
            self._joint = RJMCMCFilter(rj, rng=self._rng)
        mask = self.last_mask
        if mask is None or mask.shape != frame.shape[:2]:
            mask = np.full(frame.shape[:2], 255, np.uint8)  # no background model: all foreground
        estimates = self._joint.step(binned, mask, _xywh_to_cxcywh(boxes))
        out = []
        ebox = np.array([_cxcywh_to_xywh(e.box_cxcywh) for e in estimates]).reshape(-1, 4)
        iou = iou_matrix(ebox, boxes) if len(boxes) else np.zeros((len(estimates), 0))
        for k, e in enumerate(estimates):
            j = int(np.argmax(iou[k])) if iou.shape[1] else -1
            matched = j >= 0 and iou[k, j] >= 0.5
            out.append(Track(id=int(e.id), box_xywh=ebox[k].copy(),
                             score=float(scores[j]) if matched else float(e.score),
                             detection_index=int(index[j]) if matched else None,
                             age=self.frame_index, time_since_update=0 if matched else 1))  # fmt: skip
        return out

    def _shared(self, di: int, boxes: NDArray[np.float64], ti: int) -> bool:
        """Does detection `di` also cover another live track (a merged blob)?"""
        others = [t.box for k, t in enumerate(self.tracks) if k != ti]
        if not others:
            return False
        b = boxes[di]
        o = np.asarray(others)
        inside_x = (o[:, 0] + o[:, 2] / 2 > b[0]) & (o[:, 0] + o[:, 2] / 2 < b[0] + b[2])
        inside_y = (o[:, 1] + o[:, 3] / 2 > b[1]) & (o[:, 1] + o[:, 3] / 2 < b[1] + b[3])
        return bool(np.any(inside_x & inside_y))

    def _associate(self, boxes: NDArray[np.float64], det_hists: NDArray[np.float64]
                   ) -> tuple[list[tuple[int, int]], list[int], list[int]]:  # fmt: skip
        cfg = self.config
        nt, nd = len(self.tracks), len(boxes)
        if nt == 0 or nd == 0:
            return [], list(range(nt)), list(range(nd))
        tboxes = np.array([t.box for t in self.tracks])
        iou = iou_matrix(tboxes, boxes)
        tc = tboxes[:, :2] + tboxes[:, 2:] / 2
        dc = boxes[:, :2] + boxes[:, 2:] / 2
        dist = np.linalg.norm(tc[:, None, :] - dc[None, :, :], axis=2)
        heights = np.array([t.size[1] for t in self.tracks])
        coast = np.array([t.time_since_update for t in self.tracks])
        radius = cfg.match_distance * heights * (1.0 + 0.25 * np.minimum(coast, 8))
        # Bhattacharyya coefficients of every (track reference, detection) pair in one product;
        # references are kept normalised by the filters, detection rows sum to 1 (or 0: empty)
        refs = np.array([t.filter.reference for t in self.tracks])
        rho = np.sqrt(refs) @ np.sqrt(det_hists).T
        cost = (1.0 - iou) + cfg.colour_weight * (1.0 - rho) + np.minimum(dist / radius[:, None], 2.0)
        gate = (iou >= cfg.match_iou) | (dist <= radius[:, None])
        big = 1e6
        cost = np.where(gate, cost, big)
        if np.isfinite(cfg.unmatched_cost):
            # leaving a track or a detection unmatched costs `unmatched_cost` each, so a pair is
            # only made when it is cheaper than leaving both alone (not just because it is gated)
            tau = cfg.unmatched_cost
            padded = np.full((nt + nd, nd + nt), big)
            padded[:nt, :nd] = cost
            padded[:nt, nd:][np.diag_indices(nt)] = tau
            padded[nt:, :nd][np.diag_indices(nd)] = tau
            padded[nt:, nd:] = 0.0
            rows, cols = linear_sum_assignment(padded)
            keep = (rows < nt) & (cols < nd)
            rows, cols = rows[keep], cols[keep]
        else:
            rows, cols = linear_sum_assignment(cost)
        matches = [(int(r), int(c)) for r, c in zip(rows, cols) if cost[r, c] < big]
        mt = {r for r, _ in matches}
        md = {c for _, c in matches}
        return matches, [i for i in range(nt) if i not in mt], [j for j in range(nd) if j not in md]

    def _report(self) -> list[Track]:
        cfg = self.config
        early = self.frame_index <= cfg.min_hits
        out = []
        for t in self.tracks:
            if t.hits < cfg.min_hits and not early and not t.reported:
                if t.measured is not None:
                    t.unreported.append((self.frame_index, t.measured.copy(), float(t.score)))
                continue
            if t.time_since_update > 0 and t.rho < cfg.coast_min_rho:
                continue
            history, t.unreported, t.reported = tuple(t.unreported), [], True
            out.append(Track(id=t.id, box_xywh=t.box.copy(), score=float(t.score),
                             detection_index=t.det_index, age=t.age,
                             time_since_update=t.time_since_update, history=history,
                             detection_box=None if t.measured is None else t.measured.copy()))  # fmt: skip
        return out


class TrackWriter:
    """Collects a run's tracks as MOTChallenge rows, deciding what coasting becomes.

    A track carried by its particle filter alone (no detection) is held back: its boxes are
    written once a detection confirms the track again, and dropped if the track ends unconfirmed.
    So an occlusion the filter bridged is filled, and a filter that lost its object adds nothing.
    With a `smoother`, :meth:`result` replaces every track's boxes by the smoother's estimates
    from the track's detection boxes before and after each frame (offline: the whole run).

    Parameters
    ----------
    coasting : {"confirmed", "all", "none"}
        Write held-back boxes when the track is re-detected (default), always, or never.
    fill : {"linear", "pf"}
        Boxes of a bridged gap: interpolated between the detections at its ends (default;
        measured better on PETS09 and TUD-Campus), or the particle filter's own estimates. A
        smoother replaces them when the track has detection boxes to fit.
    smoother : BoxSmoother or None
        Offline smoothing of each track (default on; measured +7 MOTA on PETS09 and +5 on
        TUD-Campus public detections, README). None writes the boxes as reported.
    link : LinkConfig or None
        Join fragments of one object (:func:`pftrack.recovery.link_tracklets`, motion and size
        terms) before smoothing, so a joined track is smoothed as one; with a smoother, the
        frames missing inside a track (up to ``link.max_gap``) are then written with the
        smoother's interpolation. None keeps every id and every hole.
    """

    def __init__(self, coasting: str = "confirmed", fill: str = "linear",
                 smoother: BoxSmoother | None = BoxSmoother(),
                 link: LinkConfig | None = LinkConfig()) -> None:  # fmt: skip
        if coasting not in ("confirmed", "all", "none"):
            raise ValueError(f"coasting is {coasting!r}, expected 'confirmed', 'all' or 'none'")
        if fill not in ("linear", "pf"):
            raise ValueError(f"fill is {fill!r}, expected 'linear' or 'pf'")
        self.coasting = coasting
        self.fill = fill
        self.smoother = smoother
        self.link = link
        self.rows: list[list[float]] = []
        self._measured: list[Optional[NDArray[np.float64]]] = []  # per row: the detection box
        self._pending: dict[int, list[list[float]]] = {}
        self._last: dict[int, list[float]] = {}

    def _append(self, row: list[float], measured: Optional[NDArray[np.float64]]) -> None:
        self.rows.append(row)
        self._measured.append(measured)

    def add(self, frame: int, tracks: list[Track]) -> None:
        """Record the tracks reported for `frame` (1-based)."""
        for t in tracks:
            for f, box, score in t.history:  # a new track's detections from before it was confirmed
                self._append([float(f), float(t.id), *map(float, box), score, -1.0, -1.0, -1.0], np.asarray(box))
            row = [float(frame), float(t.id), *map(float, t.box_xywh), float(t.score), -1.0, -1.0, -1.0]
            if t.time_since_update == 0:
                pending = self._pending.pop(t.id, [])
                if pending and self.fill == "linear" and t.id in self._last:
                    a, b = np.asarray(self._last[t.id]), np.asarray(row)
                    for p in pending:
                        u = (p[0] - a[0]) / (b[0] - a[0])
                        p[2:6] = list((1 - u) * a[2:6] + u * b[2:6])
                for p in pending:
                    self._append(p, None)
                self._append(row, t.detection_box)
                self._last[t.id] = row
            elif self.coasting == "all":
                self._append(row, None)
            elif self.coasting == "confirmed":
                self._pending.setdefault(t.id, []).append(row)

    def result(self) -> NDArray[np.float64]:
        """All rows written so far, (M, 10), sorted by frame then id (linked and smoothed when
        the writer has a link config and a smoother)."""
        if not self.rows:
            return np.zeros((0, 10))
        a = np.asarray(self.rows)
        observed = np.array([m is not None for m in self._measured])
        z = a[:, 2:6].copy()  # the smoother fits the detection boxes, not the reported ones
        if observed.any():
            z[observed] = [m for m in self._measured if m is not None]
        return smooth_tracks(a, observed, self.smoother, self.link, z)
