"""Camera-motion compensation: the camera's own motion between frames, and the tracks moved by it.

A moving camera moves every object in the image. :class:`CameraMotion` measures that motion
once per frame as a similarity transform (rotation, uniform scale, translation; a 2x3 affine
from the previous frame to this one): corners of the previous grey frame
(``cv2.goodFeaturesToTrack``), outside the boxes of the objects being tracked, followed into
this frame by pyramidal Lucas-Kanade optical flow (``cv2.calcOpticalFlowPyrLK``), and the
transform fitted to them by RANSAC (``cv2.estimateAffinePartial2D``), which leaves out the
points on anything that moves by itself. It then decides, with hysteresis, whether the camera
moves: a frame moves when a corner of the image moves by more than a share of the image
diagonal; the camera starts moving after a few such frames in a row (the transform then applied
covers them and the frames just before them that moved by more than a lower share), and stops
after more frames in a row under the lower share (a Schmitt trigger: where a moving camera
slows down, its small motion is still applied). While it does not move the transform it hands
back is None and nothing is changed, so a still camera tracks exactly as without compensation.
While it is still, the measurement is cheap: the last corners found are followed from frame to
frame (at most ``CameraConfig.still_features``, no new corner search, and on the scaled frame
alone, without the flow's image pyramid, by the core's copy of OpenCV's flow that computes the
derivatives in the corners' windows only), and a frame is measured in full only when that
finds motion near the threshold or too few inliers, or the corners are ``refresh_frames`` old.

:func:`warp_tracks` applies a transform to the tracker's state: every particle (its current and
previous centre, the AR(2) state; the scale through the filter's base size), the particle-set
means, each centre filter's position, velocity and covariance, and the box and size.

:class:`Stabiliser` chains the applied transforms over a run so that the offline pass (linking,
filling, smoothing), which assumes a still camera, works in the first frame's coordinates.

References
----------
.. [1] Shi, J. & Tomasi, C. (1994). Good features to track. CVPR 1994.
.. [2] Bouguet, J.-Y. (2001). Pyramidal implementation of the affine Lucas Kanade feature
   tracker. Intel Corporation.
.. [3] Fischler, M. A. & Bolles, R. C. (1981). Random sample consensus. CACM 24(6).
"""

from __future__ import annotations

import functools
from collections.abc import Iterable
from dataclasses import dataclass, replace
from typing import Any

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack import _core
from pftrack._check import bgr_array, option
from pftrack._typing import F64
from pftrack.tracking.config import CAMERA_MOTION, CameraConfig
from pftrack.tracking.track import LiveTrack, Track, frozen_made

__all__ = [
    "CameraMotion",
    "CameraStep",
    "estimate_motion",
    "invert_affine",
    "motion_magnitude",
    "Stabiliser",
    "warp_tracks",
]

IDENTITY: F64 = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


@dataclass(frozen=True)
class CameraStep:
    """What :meth:`CameraMotion.update` found for one frame.

    Attributes
    ----------
    affine : (2, 3) ndarray or None
        The estimated transform from the previous frame to this one (pixels), None when it
        could not be estimated (first frame, too few corners or inliers).
    magnitude : float
        Largest displacement of an image corner under `affine`, pixels (0 without one).
    moving : bool
        Whether the camera counts as moving on this frame.
    apply : (2, 3) ndarray or None
        The transform to apply to the tracker's state on this frame (None: leave it as it is).
        When the camera starts moving it covers the moving frames that led to the decision.
    background_ok : bool
        Whether a background model of the scene can be trusted on this frame (the camera is
        still and has been for ``settle_frames``).
    """

    affine: F64 | None
    magnitude: float
    moving: bool
    apply: F64 | None
    background_ok: bool


def _camera_step(affine: F64 | None, magnitude: float, moving: bool, apply: F64 | None,
                 background_ok: bool) -> CameraStep:  # fmt: skip
    """``CameraStep(affine, ...)`` by :func:`~pftrack.tracking.track.frozen_made` (every frame)."""
    return frozen_made(
        CameraStep, affine=affine, magnitude=magnitude, moving=moving, apply=apply,
        background_ok=background_ok,
    )  # fmt: skip


def compose(second: F64, first: F64) -> F64:
    """The affine doing `first`, then `second` (both (2, 3))."""
    return np.hstack([second[:, :2] @ first[:, :2], second[:, :2] @ first[:, 2:] + second[:, 2:]])


def invert_affine(affine: ArrayLike) -> F64:
    """The inverse of a (2, 3) affine transform."""
    a = _affine(affine)
    lin = np.linalg.inv(a[:, :2])
    return np.hstack([lin, -lin @ a[:, 2:]])


def _affine(affine: ArrayLike) -> F64:
    a = np.asarray(affine, dtype=np.float64)
    if a.shape != (2, 3) or not np.all(np.isfinite(a)):
        raise ValueError(f"affine has shape {a.shape}, expected a finite (2, 3) array")
    if abs(np.linalg.det(a[:, :2])) < 1e-9:
        raise ValueError("affine is singular (its 2x2 part has determinant 0)")
    return a


def motion_magnitude(affine: ArrayLike, size: tuple[int, int]) -> float:
    """Largest displacement (pixels) of the corners of a `size` = (height, width) image."""
    a = np.asarray(affine, dtype=np.float64)
    corners = _image_corners(size[0], size[1])
    moved = corners @ a[:, :2].T + a[:, 2]
    return float(np.hypot(*(moved - corners).T).max())


@functools.lru_cache(maxsize=16)
def _diagonal(h: int, w: int) -> float:
    """``float(np.hypot(h, w))``, the diagonal of an `h` x `w` image, once per size.

    The same float (NumPy's ``hypot``, not ``math.hypot``, which may round otherwise); NumPy's
    scalar call on two ints took about 1.5 us of every :meth:`CameraMotion.update`.
    """
    return float(np.hypot(h, w))


@functools.lru_cache(maxsize=16)
def _image_corners(h: int, w: int) -> F64:
    """The corners (4, 2) of an `h` x `w` image (read-only: one array for every frame)."""
    corners = np.array([[0.0, 0.0], [w, 0.0], [0.0, h], [w, h]])
    corners.flags.writeable = False
    return corners


def _grey(frame: NDArray[np.uint8], factor: float) -> NDArray[np.uint8]:
    """The frame in grey, scaled by `factor` (pixel areas averaged).

    While the target is at most a quarter of the frame's size in both directions, the frame is
    first halved (2x2 means, a last odd row or column left out): OpenCV's area resize is slow at
    factors that are not 1/2 (1.4 ms for 1280x720 to 240x135, 0.33 ms halved first; the grey
    levels differ by 0.3 on average). A frame under four times the target's size (under 960
    pixels with the default ``max_side`` of 240) is scaled in one step. A side is at least 1
    pixel (a 1x500 frame scales to 1x240, not 0x240, which OpenCV refuses).
    """
    if factor == 1.0:
        return np.asarray(cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY), dtype=np.uint8)
    h, w = frame.shape[:2]
    size = (max(1, round(w * factor)), max(1, round(h * factor)))
    # the first halving, or a scale of exactly 1/2, fused with the grey conversion
    # (_core.grey_halved: OpenCV's two calls to the bit, without the full-size grey frame)
    halves = (w >= 4 * size[0] and h >= 4 * size[1]) or (w, h) == (2 * size[0], 2 * size[1])
    packed = frame.strides[1:] == (3, 1) and frame.strides[0] > 0  # the kernel's layout
    g: NDArray[Any]  # uint8; cv2's stubs say MatLike
    if halves and packed and _fused_grey():
        g = _core.grey_halved(frame)
    else:
        g = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY)
    if g.shape[:2] != (size[1], size[0]):
        while g.shape[1] >= 4 * size[0] and g.shape[0] >= 4 * size[1]:
            half = (g.shape[1] // 2, g.shape[0] // 2)
            g = cv2.resize(g[: 2 * half[1], : 2 * half[0]], half, interpolation=cv2.INTER_AREA)
        g = cv2.resize(g, size, interpolation=cv2.INTER_AREA)
    return np.asarray(g, dtype=np.uint8)


@functools.cache
def _fused_grey() -> bool:
    """Whether ``_core.grey_halved`` gives this OpenCV's grey halving to the bit.

    Its grey is OpenCV 5's fixed-point formula; another OpenCV rounding otherwise (OpenCV 4's
    14-bit weights differ on 0.26 % of colours) keeps its own two calls. Checked once a process
    on 128 x 128 seeded random colours, about 0.3 ms.
    """
    frame = np.random.default_rng(0).integers(0, 256, (128, 128, 3), dtype=np.uint8)
    grey = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY)
    want = cv2.resize(grey, (64, 64), interpolation=cv2.INTER_AREA)
    return bool(np.array_equal(_core.grey_halved(frame), want))


def _exclusion_mask(shape: tuple[int, int], boxes_xywh: F64, factor: float) -> NDArray[np.uint8]:
    """255 where corners may be taken: outside every box (grown by a quarter of its size)."""
    mask = np.full(shape, 255, np.uint8)
    for x, y, w, h in boxes_xywh * factor:
        x0, y0 = int(np.floor(x - 0.25 * w)), int(np.floor(y - 0.25 * h))
        x1, y1 = int(np.ceil(x + 1.25 * w)), int(np.ceil(y + 1.25 * h))
        mask[max(y0, 0) : max(y1, 0), max(x0, 0) : max(x1, 0)] = 0
    return mask


def estimate_motion(
    previous: NDArray[np.uint8],
    current: NDArray[np.uint8],
    exclude_xywh: ArrayLike = (),
    config: CameraConfig | None = None,
) -> F64 | None:
    """The similarity transform from frame `previous` to frame `current`.

    Parameters
    ----------
    previous, current : (H, W, 3) ndarray of uint8
        BGR frames of one size.
    exclude_xywh : (K, 4) array_like
        Boxes (left, top, width, height) of objects that move by themselves: no corner is
        taken inside them.
    config : CameraConfig, optional
        Scaling, corners, RANSAC threshold and inlier count.

    Returns
    -------
    (2, 3) ndarray or None
        ``[[a, -b, tx], [b, a, ty]]`` mapping a pixel of `previous` to `current`; None when
        there are too few corners or inliers.
    """
    measure = _Measure(config if config is not None else CameraConfig())
    _, prev = measure.grey(previous)
    factor, cur = measure.grey(current)
    if prev.shape != cur.shape:
        raise ValueError(f"frames differ in size: {previous.shape} and {current.shape}")
    return measure.fit_corners(prev, cur, factor, np.asarray(exclude_xywh, np.float64))[0]


def _flow(prev: NDArray[np.uint8], cur: NDArray[np.uint8], pts: NDArray[np.float32],
          start: F64 | None = None, levels: int = 2
          ) -> tuple[NDArray[np.float32], NDArray[np.bool_]]:  # fmt: skip
    """Corners `pts` (N, 1, 2) of `prev` followed into `cur` by pyramidal Lucas-Kanade flow.

    The flow starts at `start` (N, 2) when given, else at the corners themselves, and uses
    `levels` pyramid levels above the frames themselves. Returns every corner's place in `cur`
    (N, 2) and which were followed.
    """
    nxt, status, _ = cv2.calcOpticalFlowPyrLK(
        prev, cur, pts,
        np.empty_like(pts) if start is None
        else np.ascontiguousarray(start.reshape(-1, 1, 2), dtype=np.float32),
        winSize=(11, 11), maxLevel=levels,
        criteria=(cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 30, 0.01),
        flags=0 if start is None else cv2.OPTFLOW_USE_INITIAL_FLOW,
    )  # fmt: skip
    return np.asarray(nxt, np.float32).reshape(-1, 2), status.reshape(-1) == 1


class _Measure:
    """The estimation steps, shared by :func:`estimate_motion` and :class:`CameraMotion`."""

    def __init__(self, config: CameraConfig) -> None:
        self.config = config

    def grey(self, frame: NDArray[np.uint8]) -> tuple[float, NDArray[np.uint8]]:
        f = bgr_array(frame)
        factor = min(1.0, self.config.max_side / max(f.shape[:2]))
        return factor, _grey(f, factor)

    def fit_corners(self, prev: NDArray[np.uint8], cur: NDArray[np.uint8], factor: float,
                    exclude: F64) -> tuple[F64 | None, NDArray[np.float32] | None]:  # fmt: skip
        """The transform from new corners of `prev`, and its inlier corners moved into `cur`."""
        pts = self.corners(prev, factor, exclude)
        if pts is None:
            return None, None
        return self.follow(prev, cur, pts, factor)

    def corners(self, grey: NDArray[np.uint8], factor: float,
                exclude: F64) -> NDArray[np.float32] | None:  # fmt: skip
        """Corners (N, 1, 2) of `grey` outside the boxes, strongest first (None: too few)."""
        cfg = self.config
        mask = _exclusion_mask(grey.shape, exclude.reshape(-1, 4), factor)
        spacing = max(4.0, min(grey.shape) / 40)
        pts = cv2.goodFeaturesToTrack(grey, cfg.max_features, 0.01, spacing, mask=mask)
        if pts is None or len(pts) < cfg.min_inliers:
            return None
        return np.asarray(pts, np.float32)

    def follow(self, prev: NDArray[np.uint8], cur: NDArray[np.uint8], pts: NDArray[np.float32],
               factor: float, levels: int = 2
               ) -> tuple[F64 | None, NDArray[np.float32] | None]:  # fmt: skip
        """The transform that moves corners `pts` (N, 1, 2) of `prev` into `cur`.

        The flow uses `levels` pyramid levels (:func:`_flow`). Returns the transform (None: too
        few corners followed or inliers) and the inlier corners' places in `cur` (in the order
        of `pts`: strongest first, as ``goodFeaturesToTrack`` gives them).
        """
        nxt, ok = _flow(prev, cur, pts, levels=levels)
        dst = nxt[ok]
        a, inliers = self.fit(pts.reshape(-1, 2)[ok], dst)
        if a is None:
            return None, None
        a[:, 2] /= factor  # scaled pixels -> frame pixels (the linear part is the same)
        return a, np.ascontiguousarray(dst[inliers].reshape(-1, 1, 2))

    def follow_still(
        self, prev: NDArray[np.uint8], cur: NDArray[np.uint8], pts: NDArray[np.float32],
        factor: float, size: tuple[int, int], below: float,
    ) -> tuple[F64, float, NDArray[np.float32]] | None:  # fmt: skip
        """:meth:`follow` on the scaled frames alone (:data:`STILL_LEVELS`), for a still camera.

        The corners are followed by ``_core.still_flow``, OpenCV's Lucas-Kanade of
        :func:`_flow` at one level to the bit, computing the image derivatives only in the
        corners' windows (OpenCV makes them for the whole frame). RANSAC chooses the inliers as
        in :meth:`fit`; when the transform of its inliers' least squares, in closed form
        (``_core.similarity_fit``), moves the image by less than `below` pixels (less a margin,
        :data:`STILL_MARGIN`), it is taken instead of OpenCV's Levenberg-Marquardt refinement
        of the same least squares, which stops short of that minimum (by up to 3e-5 px of the
        image corners' motion on PETS09 and TUD-Campus). Otherwise (a frame near or over
        `below`, or a degenerate fit) the transform is :meth:`fit`'s, refined as before. So
        every decision taken on a still frame and every transform applied is as before; only
        the reported ``CameraStep.affine`` and
        ``magnitude`` of a frame that stays under `below` differ: they are the least squares'
        minimum itself, where OpenCV's were a few 1e-5 px short of it.

        Returns the transform (frame pixels), its :func:`motion_magnitude` and the inlier
        corners' places in `cur` (N, 1, 2), or None (too few corners followed or inliers).
        """
        cfg = self.config
        nxt, ok = _core.still_flow(prev, cur, pts)
        src, dst = pts.reshape(-1, 2)[ok], nxt[ok]
        if len(src) < cfg.min_inliers:
            return None
        m, inliers = cv2.estimateAffinePartial2D(
            src, dst, method=cv2.RANSAC, ransacReprojThreshold=cfg.ransac_threshold,
            maxIters=2000, confidence=0.995, refineIters=0,
        )  # fmt: skip
        if m is None or inliers is None or np.count_nonzero(inliers) < cfg.min_inliers:
            return None
        kept = inliers.reshape(-1) == 1
        a: F64 | None = _core.similarity_fit(src[kept], dst[kept])
        magnitude = 0.0
        if a is not None:
            a[:, 2] /= factor  # scaled pixels -> frame pixels (the linear part is the same)
            magnitude = motion_magnitude(a, size)
        if a is None or magnitude >= below - STILL_MARGIN:
            a, _ = self.fit(src, dst)  # the same RANSAC draws: the same inliers
            if a is None:
                return None
            a[:, 2] /= factor
            magnitude = motion_magnitude(a, size)
        return a, magnitude, np.ascontiguousarray(dst[kept].reshape(-1, 1, 2))

    def follow_key(
        self, key: NDArray[np.uint8], cur: NDArray[np.uint8], pts: NDArray[np.float32], guess: F64
    ) -> tuple[F64, NDArray[np.float32], NDArray[np.bool_]] | None:
        """Corners `pts` (N, 1, 2) of key frame `key` followed into `cur`, scaled pixels.

        The flow starts where `guess` (a transform) puts each corner. Returns the transform
        from `key` fitted to them (RANSAC), every corner's place in `cur` (N, 2) and which are
        its inliers, or None (too few corners followed or inliers).
        """
        start = _map_points(pts.reshape(-1, 2).astype(np.float64), guess)
        places, ok = _flow(key, cur, pts, start)
        m, inliers = self.fit(pts.reshape(-1, 2)[ok], places[ok])
        if m is None:
            return None
        ok[ok] = inliers
        return m, places, ok

    def fit(self, src: NDArray[np.float32], dst: NDArray[np.float32]
             ) -> tuple[F64 | None, NDArray[np.bool_]]:  # fmt: skip
        """The similarity from `src` to `dst` (N, 2) by RANSAC, and its inliers (None: too few)."""
        cfg = self.config
        if len(src) < cfg.min_inliers:
            return None, np.zeros(len(src), bool)
        m, inliers = cv2.estimateAffinePartial2D(
            src, dst, method=cv2.RANSAC, ransacReprojThreshold=cfg.ransac_threshold,
            maxIters=2000, confidence=0.995, refineIters=10,
        )  # fmt: skip
        if m is None or inliers is None or np.count_nonzero(inliers) < cfg.min_inliers:
            return None, np.zeros(len(src), bool)
        return np.asarray(m, dtype=np.float64), inliers.reshape(-1) == 1


#: A key frame is replaced when fewer than this share of its corners stay inliers.
KEY_INLIERS = 0.75
#: Pyramid levels above the scaled frame of the flow that follows a still camera's corners
#: (the full measurement uses 2). A still frame moves them by well under a pixel, which the
#: scaled frame alone follows as closely (PETS09's first frame shifted by 0.3-3 px of the scaled
#: frame: the same estimate to 0.001 px; tested to 0.01 px); from about 8 px the corners are
#: lost and the frame is measured in full, with the pyramid, so a jump is never taken for a
#: still frame. The flow takes 0.06 instead of 0.15 ms on 40 corners (one OpenCV thread).
STILL_LEVELS = 0
#: Pixels below the still camera's thresholds under which a still frame's transform may be the
#: closed-form least squares instead of OpenCV's refined one (:meth:`_Measure.follow_still`).
#: OpenCV's Levenberg-Marquardt stops short of the minimum: the two motions differed by at most
#: 2.9e-5 px over the still frames of PETS09 and TUD-Campus (docs/results.md, stop 72), 1/350
#: of this margin.
STILL_MARGIN = 0.01


@dataclass
class _KeyFrame:
    """The key frame a moving camera is measured against (scaled pixels)."""

    grey: NDArray[np.uint8]
    points: NDArray[np.float32]  # its corners, (N, 1, 2)
    to_prev: F64  # key frame -> previous frame (fitted)
    places: NDArray[np.float32]  # the corners in the previous frame, (N, 2)
    inliers: NDArray[np.bool_]  # which of them were inliers there
    step: F64  # previous frame's own transform (repeated: the guess for this one)
    age: int = 0  # frames measured against it


class CameraMotion:
    """Measure the camera's motion frame by frame and decide when it moves.

    Parameters
    ----------
    mode : {"auto", "on", "off"}
        ``"auto"``: decide with hysteresis; ``"on"``: the camera always counts as moving (every
        estimate is applied, the background is never trusted); ``"off"``: measure nothing.
    config : CameraConfig, optional
        Estimation and decision settings.

    Examples
    --------
    >>> camera = CameraMotion("auto")                                  # doctest: +SKIP
    >>> step = camera.update(frame, exclude_xywh=boxes)                # doctest: +SKIP
    >>> if step.apply is not None:                                     # doctest: +SKIP
    ...     warp_tracks(tracks, step.apply)
    """

    def __init__(self, mode: str = "auto", config: CameraConfig | None = None) -> None:
        option(mode, "camera_motion", CAMERA_MOTION)
        if mode not in CAMERA_MOTION:
            raise ValueError(f"camera_motion is {mode!r}, expected 'auto', 'on' or 'off'")
        self.mode = mode
        self.config = config if config is not None else CameraConfig()
        self._measure = _Measure(self.config)
        self.reset()

    def reset(self) -> None:
        """Forget the previous frame and the moving state (before a new video)."""
        self._prev: NDArray[np.uint8] | None = None
        self.moving = self.mode == "on"
        self._pending: F64 | None = None  # moving frames before the camera counts as moving
        self._run = 0  # consecutive moving (while still) or still (while moving) frames
        self._since_moving = self.config.settle_frames if self.mode == "auto" else 0
        self._corners: NDArray[np.float32] | None = None  # followed while still ("auto")
        self._corner_age = 0
        self._key: _KeyFrame | None = None  # measured against while moving
        # the next frame and its grey(), made elsewhere (hand_over)
        self._handed: tuple[NDArray[np.uint8], tuple[float, NDArray[np.uint8]]] | None = None

    def grey(self, frame: NDArray[np.uint8]) -> tuple[float, NDArray[np.uint8]]:
        """What :meth:`update` measures `frame` on: the scale factor and the scaled grey frame.

        A pure function of `frame` (and the config), safe on any thread.
        """
        return self._measure.grey(frame)

    def hand_over(self, frame: NDArray[np.uint8], grey: tuple[float, NDArray[np.uint8]]) -> None:
        """Give the next :meth:`update` of `frame` its :meth:`grey`, made elsewhere.

        :class:`~pftrack.tracking.ahead.DetectAhead` makes it on its thread; ``update`` takes
        it for that very array only (another frame is measured as without it).
        """
        self._handed = (frame, grey)

    def update(self, frame: NDArray[np.uint8], exclude_xywh: ArrayLike = ()) -> CameraStep:
        """Measure the motion from the previous frame to `frame` and decide.

        Parameters
        ----------
        frame : (H, W, 3) ndarray of uint8
            This BGR frame.
        exclude_xywh : (K, 4) array_like
            Boxes of the objects being tracked or detected (corners inside are not used).
        """
        handed, self._handed = self._handed, None
        if self.mode == "off":
            return CameraStep(None, 0.0, False, None, True)
        cfg = self.config
        if handed is not None and handed[0] is frame:
            factor, grey = handed[1]
        else:
            factor, grey = self._measure.grey(frame)
        prev, self._prev = self._prev, grey
        affine = None
        magnitude = 0.0
        size = (frame.shape[0], frame.shape[1])
        diagonal = _diagonal(*size)
        if prev is not None and prev.shape == grey.shape:
            still = self._still(prev, grey, factor, size, diagonal)
            if still is not None:
                affine, magnitude = still
            else:  # in full: against the key frame while moving, else new corners
                exclude = np.asarray(exclude_xywh, dtype=np.float64).reshape(-1, 4)
                keyed = self._keyed(prev, grey, factor, exclude) if self.moving else None
                found: tuple[F64 | None, NDArray[np.float32] | None] = (
                    keyed
                    if keyed is not None
                    else self._measure.fit_corners(prev, grey, factor, exclude)
                )
                affine, corners = found
                self._corners = None if corners is None else corners[: cfg.still_features]
                self._corner_age = 0
                if affine is not None:
                    magnitude = motion_magnitude(affine, size)
        if self.mode == "on":
            return CameraStep(affine, magnitude, True, affine, False)

        moves = affine is not None and magnitude > cfg.threshold * diagonal
        stirs = affine is not None and magnitude > cfg.still_threshold * diagonal
        apply = None
        if not self.moving:
            if stirs and affine is not None:  # pending: the frames over the lower threshold
                self._pending = affine if self._pending is None else compose(affine, self._pending)
                self._run = self._run + 1 if moves else 0
                if self._run >= cfg.on_frames:
                    self.moving, apply, self._pending, self._run = True, self._pending, None, 0
            else:
                self._pending, self._run = None, 0
        else:
            apply = affine
            self._run = 0 if stirs else self._run + 1
            if self._run >= cfg.off_frames:
                self.moving, self._run, self._since_moving = False, 0, 0
        if self.moving:
            self._since_moving = 0
        else:
            self._key = None  # a new key frame when it moves again
            if self._since_moving < cfg.settle_frames:
                self._since_moving += 1
        background_ok = not self.moving and self._since_moving >= cfg.settle_frames
        return _camera_step(affine, magnitude, self.moving, apply, background_ok)

    def _keyed(self, prev: NDArray[np.uint8], grey: NDArray[np.uint8], factor: float,
               exclude: F64) -> tuple[F64, NDArray[np.float32]] | None:  # fmt: skip
        """The moving camera's transform from the previous frame, measured against a key frame.

        The key frame's corners are followed into this frame directly (the flow starting where
        the last frame's transform, repeated, puts them), not from the previous frame: each
        corner's place carries the error of one flow, not of every frame since it was found,
        so the errors do not add up along the camera's path. The transform is fitted (RANSAC)
        to the corners that were inliers of the key-to-frame fit in both frames. The previous
        frame becomes the key frame after ``key_frames`` frames, when fewer than
        :data:`KEY_INLIERS` of its corners stay inliers, or when a fit fails. Returns the
        transform (frame pixels) and its inlier corners in this frame, or None (measure in full).
        """
        cfg = self.config
        key = self._key
        if (
            key is None
            or key.age >= cfg.key_frames
            or key.inliers.sum() < KEY_INLIERS * len(key.points)
        ):
            if cfg.key_frames <= 1:
                return None
            pts = self._measure.corners(prev, factor, exclude)
            if pts is None:
                self._key = None
                return None
            step = IDENTITY if key is None else key.step
            every = np.ones(len(pts), bool)
            key = self._key = _KeyFrame(prev, pts, IDENTITY, pts.reshape(-1, 2), every, step)
        followed = self._measure.follow_key(
            key.grey, grey, key.points, compose(key.step, key.to_prev)
        )
        if followed is None:
            self._key = None
            return None
        to_cur, places, inliers = followed
        both = key.inliers & inliers
        fitted, kept = self._measure.fit(key.places[both], places[both])
        if fitted is None:
            self._key = None
            return None
        step = fitted
        key.to_prev, key.places, key.inliers, key.step = to_cur, places, inliers, step
        key.age += 1
        affine = step.copy()
        affine[:, 2] /= factor  # scaled pixels -> frame pixels (the linear part is the same)
        corners = np.ascontiguousarray(places[both][kept].reshape(-1, 1, 2))
        return affine, corners

    def _still(self, prev: NDArray[np.uint8], grey: NDArray[np.uint8], factor: float,
               size: tuple[int, int], diagonal: float) -> tuple[F64, float] | None:  # fmt: skip
        """The cheap measurement of a still camera ("auto"): None when it must be done in full.

        The corners kept from earlier frames are followed into this one, on the scaled frame
        alone (:data:`STILL_LEVELS`: no pyramid); the estimate stands when enough of them are
        inliers and it moves the image by under half the threshold.
        Returns the estimate and its :func:`motion_magnitude`.
        """
        cfg = self.config
        corners = self._corners
        if (
            self.mode != "auto"
            or self.moving
            or self._pending is not None
            or corners is None
            or len(corners) < cfg.min_inliers
            or self._corner_age >= cfg.refresh_frames
        ):
            return None
        below = min(cfg.still_threshold, 0.5 * cfg.threshold) * diagonal
        followed = self._measure.follow_still(prev, grey, corners, factor, size, below)
        if followed is None:
            return None
        affine, magnitude, kept = followed
        if magnitude >= 0.5 * cfg.threshold * diagonal:
            return None
        self._corners, self._corner_age = kept, self._corner_age + 1
        return affine, magnitude

    def check_frames(self, frames: Iterable[NDArray[np.uint8]]) -> bool:
        """Tell whether the camera moves anywhere in `frames` (the moving state is not kept)."""
        probe = CameraMotion(self.mode, self.config)
        return any(probe.update(f).moving for f in frames)


def _map_points(xy: F64, affine: F64) -> F64:
    out: F64 = xy @ affine[:, :2].T + affine[:, 2]
    return out


def warp_tracks(tracks: Iterable[LiveTrack], affine: ArrayLike) -> None:
    """Move every track's state by a similarity transform, in place.

    Parameters
    ----------
    tracks : iterable of LiveTrack
        The tracker's live tracks.
    affine : (2, 3) array_like
        From the previous frame's pixels to this frame's (rotation, uniform scale ``z``,
        translation).

    Notes
    -----
    Positions (particles' current and previous centres, particle-set means, the centre filter's
    position and the box's centre) are mapped by the transform, velocities by its linear part;
    sizes (the box, the smoothed size and the filter's base size, which the particles' scales
    multiply) are multiplied by ``z = sqrt(det)``, and the centre filter's covariance (one per
    axis, shared) by ``z²``. The box stays axis-aligned: a roll changes its centre, not its size.
    """
    a = _affine(affine)
    lin = a[:, :2]
    z = float(np.sqrt(abs(np.linalg.det(lin))))
    for t in tracks:
        f = t.filter
        p = f.particles
        p[:, 0:2] = _map_points(p[:, 0:2], a)
        p[:, 3:5] = _map_points(p[:, 3:5], a)
        f.means[:, :2] = _map_points(f.means[:, :2], a)
        f.w0 *= z
        f.h0 *= z
        k = t.motion
        k.p = _map_points(k.p[None], a)[0]
        k.v = lin @ k.v
        k.cov = (k.cov[0] * z * z, k.cov[1] * z * z, k.cov[2] * z * z)
        centre = _map_points((t.box[:2] + t.box[2:] / 2)[None], a)[0]
        t.size = t.size * z
        t.box = np.concatenate([centre - t.box[2:] * z / 2, t.box[2:] * z])


def _map_box(box: F64, affine: F64) -> F64:
    """An xywh box moved by `affine`: centre through it, size times its zoom."""
    b = np.asarray(box, dtype=np.float64)
    z = float(np.sqrt(abs(np.linalg.det(affine[:, :2]))))
    centre = affine[:, :2] @ (b[:2] + b[2:] / 2) + affine[:, 2]
    return np.concatenate([centre - b[2:] * z / 2, b[2:] * z])


class Stabiliser:
    """The camera's path over a run: each frame's pixels in the first frame's coordinates.

    The offline pass (linking, filling, smoothing) assumes a still camera; with the tracks'
    boxes in these stabilised coordinates it sees the objects' own motion, and its rows are
    mapped back to each frame after it. Frames where the tracker applied no transform count
    as still, so a still camera gives exactly the boxes it was given.
    """

    def __init__(self) -> None:
        self.to_first: list[F64] = []  # per frame (from 1): frame pixels -> first-frame pixels
        self._moved = False

    @property
    def moved(self) -> bool:
        """Whether any transform was applied so far."""
        return self._moved

    def add(self, applied: F64 | None) -> None:
        """Record the next frame's transform from the previous frame (None: still)."""
        last = self.to_first[-1] if self.to_first else IDENTITY
        if applied is None:
            self.to_first.append(last)
            return
        self.to_first.append(compose(last, invert_affine(applied)))
        self._moved = self._moved or not np.array_equal(self.to_first[-1], IDENTITY)

    def stabilise(self, tracks: list[Track]) -> list[Track]:
        """The tracks of the last frame added, boxes in first-frame coordinates."""
        if not self.moved:
            return tracks
        s = self.to_first[-1]
        out = []
        for t in tracks:
            history = tuple((f, _map_box(b, self.to_first[f - 1]), sc) for f, b, sc in t.history)
            det = None if t.detection_box is None else _map_box(t.detection_box, s)
            out.append(
                replace(t, box_xywh=_map_box(t.box_xywh, s), history=history, detection_box=det)
            )
        return out

    def restore(self, rows: F64) -> F64:
        """MOT rows in first-frame coordinates mapped back to their frames' pixels."""
        if not self.moved or not len(rows):
            return rows
        out = np.array(rows, dtype=np.float64, copy=True)
        for k, row in enumerate(out):
            back = invert_affine(self.to_first[int(row[0]) - 1])
            out[k, 2:6] = _map_box(row[2:6], back)
        return out
