"""Common interface of the detectors: `Detections`, the `Detector` protocol, box extraction."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack import _core
from pftrack._check import MAX_COORD, bgr_array, brief, flag, number, real_array
from pftrack._threads import kernel_threads
from pftrack._typing import F64
from pftrack._warn import warn_outside
from pftrack.boxes import _iou_matrix
from pftrack.detection.hold import HOLD_IOU
from pftrack.detection.size_model import PersonSizeModel


@dataclass(frozen=True)
class Detections:
    """What a detector found in one frame.

    Attributes
    ----------
    boxes : (K, 4) ndarray of float64
        ``left, top, width, height`` in pixels, one row per detected object.
    scores : (K,) ndarray of float64
        Confidence in [0, 1] (fraction of foreground pixels in the box).
    mask : (H, W) ndarray of uint8
        Cleaned foreground mask, 255 = foreground, 0 = background.
    binned : pftrack._core.BinnedImage
        HSV bins of the frame with background pixels set to -1 (foreground only), for the
        particles' colour histograms.
    frame_bins : pftrack._core.BinnedImage or None
        HSV bins of every pixel, when the detector computed them anyway, so a caller needing
        them never bins the frame twice. None from the built-in detectors' ``detect``: the
        paper's pass bins only the kept foreground (its ``foreground``, for box refinement,
        still bins every pixel in the same pass); MOG2 and KNN bin none.
    """

    boxes: NDArray[np.float64]
    scores: NDArray[np.float64]
    mask: NDArray[np.uint8]
    binned: _core.BinnedImage
    frame_bins: _core.BinnedImage | None = None

    def __len__(self) -> int:
        return int(self.boxes.shape[0])


@runtime_checkable
class FrameDetector(Protocol):
    """What :class:`~pftrack.tracking.MultiObjectTracker` needs of its `detector`: ``detect``.

    ``detect(frame)`` takes one BGR uint8 (H, W, 3) frame and returns its :class:`Detections`;
    the tracker reads their `boxes`, `scores`, `mask`, `binned` and `frame_bins`. It also
    uses, when the detector has them (pftrack's detectors do):

    * ``foreground(frame, shadows=False) -> (mask, frame_bins)``: the mask alone (no blob
      pass), for box refinement when the caller gives the detections; `shadows` marks shadow
      pixels 127 (:func:`~pftrack.tracking.tracker.takes_shadows`);
    * ``prime(frames)``: the background from frames read ahead
      (:meth:`~pftrack.tracking.MultiObjectTracker.prime`).
    """

    def detect(self, frame: NDArray[np.uint8]) -> Detections:
        """Detect the moving objects of one BGR uint8 frame (H, W, 3)."""
        ...


@runtime_checkable
class Detector(FrameDetector, Protocol):
    """Anything with ``detect(frame) -> Detections`` and ``reset()`` (every built-in detector)."""

    def reset(self) -> None:
        """Forget the background model (before a new video)."""
        ...


#: BlobConfig's settings that are numbers (a range checked for each).
_BLOB_NUMBERS = (
    "min_area",
    "max_area",
    "min_aspect",
    "max_aspect",
    "min_fill",
    "person_aspect",
    "split_valley",
)


@dataclass(frozen=True)
class BlobConfig:
    """Mask cleaning and blob filtering shared by all detectors.

    Attributes
    ----------
    open_size : int or None
        Side of the square structuring element of the opening (removes speckle). None: odd
        size ``max(3, round(H / 120))`` rounded up to odd, i.e. 3 at 360 rows, 5 at 576.
    close_size : int or None
        Side of the (elliptic) closing element (fills holes, joins a body's parts). None: odd
        ``round(H / 72)``, i.e. 5 at 360 rows, 9 at 576.
    min_area : float
        Smallest blob, as a fraction of the frame's area (0.0015: 259 px at 480x360, about a
        third of a far pedestrian).
    max_area : float
        Largest blob, as a fraction of the frame's area (a sudden light change covers more).
        A larger blob no wider than tall is kept only while it moves: when it overlaps one of
        the previous frame's (IoU >= `LARGE_IOU`) and its box moved by `LARGE_MOVE` px or more
        since, as that one's had (a person close to the camera; `BlobExtractor.boxes`); once
        its box moved as a whole, also while it stays (the person stops).
    min_aspect, max_aspect : float
        Allowed height / width of a blob's box: 0.25 keeps groups of several people walking
        side by side, 6 drops thin vertical streaks.
    min_fill : float
        Smallest fraction of foreground pixels in a blob's box.
    person_aspect : float
        Group splitting (0 = off): a blob wider than 1.5 objects of height / width
        `person_aspect` (2.8 for standing people) is cut into ``round(w * person_aspect / h)``
        parts at the minima of its column profile (people walking side by side merge into one
        blob); each part gets its own tight box. Used until the person-size model is fitted
        (and always when `learn_size` is off).
    learn_size : bool
        Learn a person-size model from the scene (`pftrack.detection.size_model`: box height
        and width as lines in the foot row, fitted to isolated blobs) and, once it is fitted,
        use it instead of `person_aspect`: join stacked fragments of one person, cut a group's
        blob into ``round(w / expected width)`` people.
    split_valley : float
        Either rule cuts a group's blob only at a valley of its column profile (foreground
        pixels per column): where the profile falls to at most this share of the lower of the
        two sides' peaks. One person wider than the rules expect (arms, a bag, a broad coat)
        has no valley and stays whole; people side by side have one between them. 1 or more
        cuts at every minimum (the behaviour before). 0.85 lies in the middle of the values
        that did well on every sequence (0.8-0.9; 0.7 lost the `groups` scene, 1 most rows)
        and had the largest sums of MOTA, IDF1 and HOTA over PETS09-S2L1, TUD-Campus, the busy
        scenes (each also darkening and brightened) and six `make_scene` seeds with the
        built-in detector (docs/detection.md).
    """

    open_size: int | None = None
    close_size: int | None = None
    min_area: float = 0.0015
    max_area: float = 0.25
    min_aspect: float = 0.25
    max_aspect: float = 6.0
    min_fill: float = 0.2
    person_aspect: float = 2.8
    learn_size: bool = True
    split_valley: float = 0.85

    def __post_init__(self) -> None:
        own = "BlobConfig"  # every message names the class, as the other configs' do
        for name in ("open_size", "close_size"):
            v = getattr(self, name)
            if v is not None and not (isinstance(v, (int, np.integer)) and v >= 1):
                raise ValueError(f"{own}: {name} is {brief(v)}, expected None or an int >= 1")
        for name in _BLOB_NUMBERS:  # before the comparisons below ask an array for its truth
            number(getattr(self, name), f"{own}: {name}", finite=False)
        flag(self.learn_size, f"{own}: learn_size")  # was taken: "no" or an array turned it on
        if not (0.0 <= self.min_area <= self.max_area <= 1.0):
            raise ValueError(
                f"{own}: min_area, max_area are {self.min_area}, {self.max_area}, "
                "expected 0 <= min_area <= max_area <= 1"
            )
        if not (0.0 < self.min_aspect <= self.max_aspect):
            raise ValueError(
                f"{own}: min_aspect, max_aspect are {self.min_aspect}, {self.max_aspect}, "
                "expected 0 < min_aspect <= max_aspect"
            )
        if not (0.0 <= self.min_fill <= 1.0):
            raise ValueError(f"{own}: min_fill is {self.min_fill}, expected in [0, 1]")
        if not (self.person_aspect >= 0.0 and np.isfinite(self.person_aspect)):
            raise ValueError(
                f"{own}: person_aspect is {self.person_aspect}, expected a finite value >= 0"
            )
        if not (self.split_valley >= 0.0 and np.isfinite(self.split_valley)):
            raise ValueError(
                f"{own}: split_valley is {self.split_valley}, expected a finite value >= 0"
            )

    def kernel_sizes(self, rows: int) -> tuple[int, int]:
        """(open, close) element sides for a frame of `rows` rows."""
        o = self.open_size if self.open_size is not None else max(3, round(rows / 120)) | 1
        c = self.close_size if self.close_size is not None else max(3, round(rows / 72)) | 1
        return int(o), int(c)


def _count_nonzero(mask: NDArray[Any]) -> int:
    """``np.count_nonzero(mask)``, the same count.

    Of a C-contiguous (H, W) uint8 mask by OpenCV: a third of NumPy's instructions at 480x360
    (callgrind, 0.045 against 0.145 M a call).
    """
    if mask.dtype == np.uint8 and mask.ndim == 2 and mask.flags.c_contiguous:
        return int(cv2.countNonZero(mask))
    return int(np.count_nonzero(mask))


def check_frame(frame: object, fn: str) -> NDArray[np.uint8]:
    """Return `frame` as a (H, W, 3) uint8 array, or raise naming the argument.

    TypeError for what is not a uint8 array, ValueError for a wrong shape (:func:`bgr_array`);
    TypeError when `fn`, the caller's name its messages begin with, is not a str.
    """
    if not isinstance(fn, str):  # was: an array's repr over several lines, at a bad frame only
        raise TypeError(f"check_frame: fn must be a str (the caller's name), got {brief(fn)}")
    if not isinstance(frame, np.ndarray):
        raise TypeError(f"{fn}: frame is {type(frame).__name__}, expected a numpy.ndarray")
    f = bgr_array(frame, f"{fn}: frame")  # the same array
    if f.shape[0] == 0 or f.shape[1] == 0:
        raise ValueError(f"{fn}: frame shape is {f.shape}, expected (H, W, 3) with H, W > 0")
    return f


def median_frame(frames: Iterable[NDArray[np.uint8]], fn: str) -> NDArray[np.float32]:
    """Per-pixel median (H, W, 3) float32 of `frames` (numpy.median's values), checked.

    The start of a background (the detectors' ``prime``): computed in C++ without stacking
    the frames, in bands of rows on :func:`pftrack._threads.kernel_threads` threads. Raises
    naming `fn` when `frames` is empty, or holds a frame that is not (H, W, 3) uint8 or not of
    the first one's size.
    """
    stack = [check_frame(f, fn) for f in frames]
    if not stack:
        raise ValueError(f"{fn}: frames is empty, expected at least one frame")
    if any(f.shape != stack[0].shape for f in stack):
        raise ValueError(f"{fn}: frames differ in shape, expected one size")
    median: NDArray[np.float32] = _core.median_frames(stack, kernel_threads())
    return median


def check_detections(detections: ArrayLike, shape: tuple[int, int]) -> tuple[F64, F64]:
    """Check external detections against a frame of `shape` (rows, cols).

    Parameters
    ----------
    detections : (K, 4) or (K, 5) array_like
        ``[left, top, width, height(, score)]``; a missing score is 1.
    shape : (int, int)
        The frame's rows and columns.

    Returns
    -------
    boxes : (K, 4) ndarray
    scores : (K,) ndarray

    Raises
    ------
    TypeError
        Values that are not real numbers (complex, text).
    ValueError
        Wrong shape, NaN or inf, a box with no area, or a value beyond ±1e9 px.

    Warns
    -----
    UserWarning
        Boxes wholly outside the frame (usually a wrong coordinate scale) are dropped.
    """
    d = real_array(detections, "detections")
    if d.shape == (0,) or (d.ndim == 2 and d.shape[0] == 0 and d.shape[1] in (4, 5)):
        return np.zeros((0, 4)), np.zeros(0)
    if d.ndim != 2 or d.shape[1] not in (4, 5):
        raise ValueError(
            f"detections must have shape (K, 4) or (K, 5) [left, top, w, h(, score)], got {d.shape}"
        )
    if not np.all(np.isfinite(d)):
        raise ValueError("detections contain NaN or inf")
    if np.any(d[:, 2] <= 0) or np.any(d[:, 3] <= 0):
        k = int(np.flatnonzero((d[:, 2] <= 0) | (d[:, 3] <= 0))[0])
        raise ValueError(f"detection {k} has width or height <= 0: {d[k].tolist()}")
    far = np.abs(d[:, :4]) > MAX_COORD
    if far.any():  # the kernels' bound on pixels (their message would name a converted box)
        k = int(np.flatnonzero(far.any(axis=1))[0])
        raise ValueError(f"detection {k} has a value beyond +-{MAX_COORD:g} px: {d[k].tolist()}")
    rows, cols = shape
    outside = (
        (d[:, 0] >= cols) | (d[:, 1] >= rows) | (d[:, 0] + d[:, 2] <= 0) | (d[:, 1] + d[:, 3] <= 0)
    )
    if np.any(outside):  # nothing to track there: dropped, and said so once per call site
        k = int(np.flatnonzero(outside)[0])
        warn_outside(  # the user's line, or held inside update() (given from the user's)
            f"{int(outside.sum())} detection(s) wholly outside the {cols}x{rows} frame dropped, "
            f"e.g. {d[k, :4].tolist()} (wrong coordinate scale? PETS boxes need "
            "--det-scale 0.625)",
            UserWarning,
        )
        d = d[~outside]
    scores = d[:, 4] if d.shape[1] == 5 else np.ones(len(d))
    return d[:, :4].copy(), scores.copy()


#: A blob over `BlobConfig.max_area` is kept when a blob over it in the previous frame overlaps
#: it by at least this IoU ...
LARGE_IOU = 0.5
#: ... and one of its box's edges moved by at least this many pixels since, as that one's had
#: from a blob of the frame before (a person close to the camera walks; a patch of changed
#: light keeps its box, after a first frame where it may have merged with a passer-by).
LARGE_MOVE = 2.0


def _translated(boxes: NDArray[np.float64], prev: NDArray[np.float64]) -> NDArray[np.bool_]:
    """(K, P): whether box k is box p moved as a whole.

    Both edges of one axis moved by `LARGE_MOVE` or more, the same way: a walker. A patch of
    light merged with a passer-by keeps an edge of its own in each axis, and only the
    passer-by's side moves.
    """
    d = _edges(boxes)[:, None] - _edges(prev)[None]  # (K, P, 4): left, top, right, bottom
    near, far = d[..., :2], d[..., 2:]  # (K, P, 2): left/top and right/bottom of each axis
    same_way = near * far > 0
    both = np.minimum(np.abs(near), np.abs(far)) >= LARGE_MOVE
    out: NDArray[np.bool_] = np.any(same_way & both, axis=2)
    return out


class BlobExtractor:
    """Raw mask -> cleaned mask (opening, then closing) -> filtered 8-connected blobs."""

    #: the boxes of the previous frame's blobs over `max_area`, whether each had moved, and
    #: whether each is a walker's (kept once it moved as a whole, then while it overlaps)
    #: (class defaults: a checkpoint pickled before they were kept)
    _large: NDArray[np.float64] = np.zeros((0, 4))
    _large_moved: NDArray[np.bool_] = np.zeros(0, dtype=bool)
    _large_walked: NDArray[np.bool_] = np.zeros(0, dtype=bool)

    def __init__(self, config: BlobConfig) -> None:
        self.config = config
        self._rows = -1
        self._open: NDArray[np.uint8] = np.ones((1, 1), np.uint8)
        self._close: NDArray[np.uint8] = np.ones((1, 1), np.uint8)
        self.size_model = PersonSizeModel()
        self._large = np.zeros((0, 4))
        self._large_moved = np.zeros(0, dtype=bool)
        self._large_walked = np.zeros(0, dtype=bool)

    def reset(self) -> None:
        """Forget the learnt person size and the last large blobs (before a new video)."""
        self.size_model.reset()
        self._large = np.zeros((0, 4))
        self._large_moved = np.zeros(0, dtype=bool)
        self._large_walked = np.zeros(0, dtype=bool)

    def _elements(self, rows: int) -> tuple[NDArray[np.uint8], NDArray[np.uint8]]:
        if self._rows != rows:
            o, c = self.config.kernel_sizes(rows)
            self._open = np.asarray(cv2.getStructuringElement(cv2.MORPH_RECT, (o, o)), np.uint8)
            self._close = np.asarray(cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (c, c)), np.uint8)
            self._rows = rows
        return self._open, self._close

    def clean(self, raw: NDArray[np.uint8]) -> NDArray[np.uint8]:
        """Clean the raw mask: opening, then closing (grey-level: 127 shadows are cleaned too).

        One C++ call (``pftrack._core.clean_mask``, the GIL released): the values of
        ``cv2.morphologyEx(MORPH_OPEN)``, then ``(MORPH_CLOSE)``, bit for bit
        (tests/detection/test_morphology.py). A mask of 0 and at most two levels, 255 the upper
        (the detectors' 0/255 and 0/127/255), is cleaned as bit planes, 64 pixels a word: the
        cleaned planes of ``mask != 0`` and ``mask == 255``, since flat erosion and dilation
        commute with a threshold; any other mask byte by byte. Only the blocks of rows within
        the passes' summed reach of a non-zero row are cleaned; the other rows are 0.
        """
        k_open, k_close = self._elements(raw.shape[0])
        closed: NDArray[np.uint8] = _core.clean_mask(raw, k_open, k_close)
        return closed

    def boxes(
        self, mask: NDArray[np.uint8], *, learn: bool = True, still: F64 | None = None
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Boxes (K, 4) left, top, w, h and scores (K,) of the blobs that pass the filters.

        A blob is an 8-connected foreground region that lies in no hole of another one (the
        regions whose outer borders ``cv2.findContours`` with ``RETR_EXTERNAL`` follows). Its
        area is the number of foreground pixels in its box. Blobs outside the area, aspect and
        fill limits are dropped; then, once the person-size model is fitted, the fragments of
        one person are joined (`PersonSizeModel.merge_fragments`) and groups cut
        (`PersonSizeModel.split_count`), else groups are cut by `BlobConfig.person_aspect`: a
        blob is cut into ``counts`` people at the minima of its column profile, each part with
        its own tight box, and parts under ``min_area`` foreground pixels are dropped.

        The whole pass is one C++ call (``pftrack._core.blob_boxes``, the GIL released;
        ``tests/reference/blobs.py`` is the OpenCV/NumPy statement it equals bit for bit).
        With `learn` False the person-size model does not learn from this mask's blobs; it
        never learns from a blob whose box overlaps one of `still` (K, 4) by IoU
        ``hold.HOLD_IOU`` or more (the previous frame's boxes of people standing still,
        `pftrack.detection.hold.StopMemory.still`).
        """
        cfg = self.config
        model = self.size_model
        lines = model.coefficients if cfg.learn_size else None
        sc = model.config
        rects, fill = _core.blob_boxes(
            mask,
            cfg.min_area,
            cfg.max_area,
            cfg.min_aspect,
            cfg.max_aspect,
            cfg.min_fill,
            cfg.person_aspect,
            lines,
            sc.split_ratio,
            sc.split_max_height,
            sc.merge_slack,
            cfg.split_valley,
        )
        if cfg.learn_size and learn:
            skip: NDArray[np.bool_] | None = None
            if still is not None and len(still) and len(rects):
                skip = np.any(_iou_matrix(rects, still) >= HOLD_IOU, axis=1)
            model.observe(rects, skip)
        big, big_fill = self._moving_large(mask)
        if len(big):  # never learnt from, never cut: one person close to the camera
            rects, fill = np.vstack([rects, big]), np.concatenate([fill, big_fill])
        order = np.lexsort((rects[:, 1], rects[:, 0]))  # deterministic: by left, then top
        return np.ascontiguousarray(rects[order]), np.ascontiguousarray(fill[order])

    def _moving_large(
        self, mask: NDArray[np.uint8]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Blobs over `max_area` that persist and move: boxes (K, 4) and fills (K,).

        A person close to the camera can fill more of the frame than `max_area` (a person
        filling 43 % of it was missed on 75 of 101 frames); so can a patch of changed light,
        which `max_area` is there to refuse, and a group walking side by side. Such a blob
        passing the other filters and no wider than tall is kept when a blob over
        `max_area` in the previous frame overlaps it (IoU >= `LARGE_IOU`),
        one of its box's edges moved by `LARGE_MOVE` px or more since, and that blob had
        moved so from one of the frame before: light stays put. A walker who stops stays kept:
        a kept blob whose box moved as a whole (`_translated`) carries a walker's mark, and a
        large blob overlapping one with the mark in the previous frame (IoU >= `LARGE_IOU`)
        takes it and is kept, moving or not (the close walker standing 150 frames: found on
        150 of them, against 11). Light never earns the mark: a patch merged with a passer-by
        keeps an edge of its own in each axis.
        The blob pass runs a second time only on frames whose foreground exceeds `max_area`.
        """
        cfg = self.config
        prev, prev_moved, prev_walked = self._large, self._large_moved, self._large_walked
        self._large, self._large_moved = np.zeros((0, 4)), np.zeros(0, dtype=bool)
        self._large_walked = np.zeros(0, dtype=bool)
        if cfg.max_area >= 1.0 or _count_nonzero(mask) <= cfg.max_area * mask.size:
            return self._large, np.zeros(0)
        sc = self.size_model.config
        rects, fill = _core.blob_boxes(
            mask, cfg.max_area, 1.0, cfg.min_aspect, cfg.max_aspect, cfg.min_fill, 0.0, None,
            sc.split_ratio, sc.split_max_height, sc.merge_slack, cfg.split_valley,
        )  # fmt: skip
        large = fill * rects[:, 2] * rects[:, 3] > cfg.max_area * mask.size  # not the kept ones
        large &= rects[:, 3] >= rects[:, 2]  # upright: not a group walking side by side
        rects, fill = rects[large], fill[large]
        # (K, P): overlaps a previous large blob, and its box moved since
        moved = np.abs(_edges(rects)[:, None] - _edges(prev)[None]).max(axis=2) >= LARGE_MOVE
        near = _iou_matrix(rects, prev) >= LARGE_IOU
        moved &= near
        keep = np.any(moved & prev_moved[None], axis=1)
        # a walker who stops stays kept: once kept while its box moved as a whole, a blob
        # keeps the walker's mark while it overlaps the previous frame's, moving or not
        walked = np.any(
            near & (prev_walked[None] | (_translated(rects, prev) & prev_moved[None])), axis=1
        )
        self._large, self._large_moved, self._large_walked = rects, moved.any(axis=1), walked
        keep |= walked
        return rects[keep], fill[keep]


def _edges(boxes: NDArray[np.float64]) -> NDArray[np.float64]:
    """Left, top, right and bottom of (K, 4) ``left, top, w, h`` boxes."""
    return np.column_stack([boxes[:, :2], boxes[:, :2] + boxes[:, 2:]])
