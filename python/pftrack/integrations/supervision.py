"""pftrack behind supervision's tracker interface (``update_with_detections``; ``update``).

supervision is imported lazily, when a tracker is first updated; install it with
``pip install "pftrack[supervision]"``. Current supervision (0.31, what that extra installs today)
needs no OpenCV, so only pftrack's ``opencv-python-headless`` is installed. Releases up to 0.26
require ``opencv-python``: pip then installs it next to the headless wheel, and both wheels of one
OpenCV release write the same ``cv2`` package, so either works (see the README); do not uninstall
one of the two afterwards, which removes ``cv2`` for both (``pip install --force-reinstall
--no-deps opencv-python-headless`` repairs it).
"""

from __future__ import annotations

import sys
from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Any, TypedDict, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack._check import check_classes, real_array
from pftrack._typing import (
    F64,
    CameraMotion,
    DetectorName,
    DynamicsName,
    FillMode,
    RealLike,
    SamplerName,
)
from pftrack.detection import KnnConfig, Mog2Config, PaperConfig
from pftrack.tracking.api import Tracker

if sys.version_info >= (3, 11):  # at run time too: typing.get_type_hints resolves it
    from typing import Unpack
elif TYPE_CHECKING:
    from typing_extensions import Unpack
if TYPE_CHECKING:
    import supervision as sv

__all__ = ["SupervisionTracker", "TrackerOptions"]


class TrackerOptions(TypedDict, total=False):
    """The keyword options of :class:`pftrack.Tracker`, typed for ``SupervisionTracker(**...)``.

    ``tests/integrations/test_supervision.py`` holds the names and types equal to the Tracker's.
    """

    seed: int | None
    detector: DetectorName | PaperConfig | Mog2Config | KnnConfig
    sampler: SamplerName
    particles: int | None
    dynamics: DynamicsName
    mh_iter: int
    mh_proposal: str
    mh_rw_sigma: Sequence[float]
    burn_in: int
    moves: Sequence[float]
    max_coast: RealLike | None
    min_conf: float
    birth_score: float
    birth_quantile: float | None
    camera_motion: CameraMotion
    refine: bool
    fill: FillMode
    smooth: bool
    link: bool
    crossings: bool
    colour: str | None
    prime: RealLike | None
    max_side: int | None
    record: bool


def _field(values: ArrayLike, name: str, shape: tuple[int, int]) -> F64:
    """The Detections field `name` as a float64 array of `shape`, its errors naming the field.

    The tracker's own checks name the columns it stacks (``detections row 1 contains NaN or
    inf`` with a class the detections may not have, ``column 6: ... cls``): a supervision user
    gave fields, not columns.
    """
    a: F64 = real_array(values, f"detections.{name}", booleans=False).reshape(shape)
    bad = ~np.isfinite(a).all(axis=1)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        if shape[1] == 1:
            raise ValueError(f"detections.{name}[{k}] is {a[k, 0]}, expected a finite number")
        raise ValueError(f"detections.{name}[{k}] is {a[k].tolist()}, expected finite numbers")
    if name == "class_id":
        check_classes(a[:, 0], "detections.class_id")
    return a


def _detections_class() -> Any:
    """``supervision.Detections``, imported on first use with a clear error when missing."""
    try:
        import supervision
    except ImportError as exc:
        raise ImportError(
            'pftrack.integrations.supervision needs supervision: pip install "pftrack[supervision]"'
        ) from exc
    return supervision.Detections


class SupervisionTracker:
    """:class:`pftrack.Tracker` with supervision's ``update_with_detections``.

    Parameters
    ----------
    frame_rate : float
        Frames per second of the video.
    **options
        Any other option of :class:`pftrack.Tracker` (``seed``, ``min_conf``, ...).

    Examples
    --------
    >>> tracker = SupervisionTracker(frame_rate=25.0)                 # doctest: +SKIP
    >>> tracker.prime(first_frames)   # the background behind box refinement  # doctest: +SKIP
    >>> for frame in frames:                                           # doctest: +SKIP
    ...     detections = sv.Detections.from_ultralytics(model(frame)[0])
    ...     detections = tracker.update_with_detections(detections, frame)
    ...     print(detections.tracker_id)
    """

    def __init__(self, frame_rate: RealLike = 25.0, **options: Unpack[TrackerOptions]) -> None:
        unknown = sorted(set(options) - set(TrackerOptions.__annotations__))
        if unknown:  # was: "Tracker.__init__() got an unexpected keyword argument"
            raise TypeError(
                f"SupervisionTracker got an unknown option {unknown[0]!r} (its options are "
                "pftrack.Tracker's)"
            )
        self.tracker = Tracker(frame_rate, **options)
        # supervision's boxes are always x1, y1, x2, y2: messages name them, without the hint
        # that the rows look like x, y, w, h
        self.tracker._box_source = "detections"
        self.tracker._caller_depth = 1  # warnings name the caller's line, not this module's

    def update_with_detections(
        self, detections: sv.Detections, frame: NDArray[np.uint8]
    ) -> sv.Detections:
        """Track one frame's detections; return those that belong to a track, with its id.

        :meth:`update` returns every detection, -1 on the untracked ones, as the ``trackers``
        package's trackers do (``trackers.ByteTrackTracker``, which replaced supervision's
        ByteTrack in supervision 0.28).

        Parameters
        ----------
        detections : supervision.Detections
            This frame's detections (``xyxy``; ``confidence`` and ``class_id`` when present).
        frame : (H, W, 3) ndarray of uint8
            The BGR frame: pftrack follows each object's colour, so unlike supervision's
            ByteTrack it needs the image.

        Returns
        -------
        supervision.Detections
            As supervision's ByteTrack does: the detections matched to a confirmed track this
            frame, in their input order, with ``tracker_id`` set and every other field (boxes,
            masks, data, the boxes' dtype) taken from the input. Tracks sharing one detection
            (a blob of people who merged) each get a row with that track's own box: the
            filter's estimate, not clipped to the frame, which may reach past its edge by a
            few pixels, as ground-truth boxes do (clip ``xyxy`` before cropping, e.g. x1, x2
            with ``np.clip(..., 0, W)`` and y1, y2 with ``np.clip(..., 0, H)``).

        Raises
        ------
        TypeError
            Not a ``supervision.Detections``, a field that does not hold real numbers (class
            names in ``class_id``), or a bad frame (:meth:`pftrack.Tracker.update`).
        ValueError
            NaN or inf in ``xyxy`` or ``confidence``, a ``class_id`` that is not an integer
            (each named by its field and row), or what :meth:`pftrack.Tracker.update` refuses.
        """
        dets = self._dets(detections)
        return self._detections(detections, self.tracker.update(dets, frame), every=False)

    def update(self, detections: sv.Detections, frame: NDArray[np.uint8]) -> sv.Detections:
        """Track one frame's detections as the ``trackers`` package's trackers do: return all.

        supervision 0.28 deprecated its ByteTrack for ``trackers.ByteTrackTracker``, whose
        ``update(detections, frame=None)`` returns every detection, ``tracker_id`` -1 on those
        no track follows; this is that method (pftrack needs the frame: it follows colour).
        :meth:`update_with_detections` returns the tracked ones only, as supervision's
        ByteTrack did.

        Parameters
        ----------
        detections : supervision.Detections
            This frame's detections (``xyxy``; ``confidence`` and ``class_id`` when present).
        frame : (H, W, 3) ndarray of uint8
            The BGR frame.

        Returns
        -------
        supervision.Detections
            Every detection, in the input's order, with ``tracker_id`` set: the id of the
            confirmed track matched to it this frame, else -1 (a detection that started no
            track, or whose track is not yet confirmed). A detection that tracks share (a blob
            of people who merged) comes once per track, with that track's box, as in
            :meth:`update_with_detections` (whose rows are those with an id here); filters'
            boxes are not clipped to the frame.

        Raises
        ------
        TypeError, ValueError
            As :meth:`update_with_detections`.
        """
        dets = self._dets(detections)
        return self._detections(detections, self.tracker.update(dets, frame), every=True)

    @staticmethod
    def _dets(detections: sv.Detections) -> F64:
        """`detections` as :meth:`pftrack.Tracker.update`'s (N, 6) x1, y1, x2, y2, conf, cls.

        The tracker is called from :meth:`update` and :meth:`update_with_detections`
        themselves, so its warnings name the user's line one method up (``_caller_depth``).
        """
        detections_cls = _detections_class()
        if not isinstance(detections, detections_cls):
            raise TypeError(
                f"detections must be a supervision.Detections, got {type(detections).__name__}"
            )
        n = len(detections)
        conf, cls = detections.confidence, detections.class_id
        dets = np.column_stack([
            _field(detections.xyxy, "xyxy", (n, 4)),
            np.ones(n) if conf is None else _field(conf, "confidence", (n, 1)),
            np.zeros(n) if cls is None else _field(cls, "class_id", (n, 1)),
        ])  # fmt: skip
        return dets

    @staticmethod
    def _detections(detections: sv.Detections, tracks: F64, every: bool) -> sv.Detections:
        """`detections` with the ids of `tracks` (:meth:`pftrack.Tracker.update`'s rows).

        The tracked ones (`every` False: :meth:`update_with_detections`) or all, -1 on the
        untracked (`every` True: :meth:`update`).
        """
        n = len(detections)
        # the input's order, as ByteTrack keeps it (a blob's tracks in track order)
        tracks = tracks[np.argsort(tracks[:, 7], kind="stable")]
        rows = tracks[:, 7].astype(np.int64)
        ids = tracks[:, 4].astype(int)
        boxes = tracks[:, :4]
        shared = np.bincount(rows, minlength=n)[rows] > 1 if len(rows) else np.zeros(0, bool)
        if every:  # the detections no confirmed track follows too, tracker_id -1, in order
            rest = np.setdiff1d(np.arange(n), rows)
            order = np.argsort(np.concatenate([rows, rest]), kind="stable")
            rows = np.concatenate([rows, rest])[order]
            ids = np.concatenate([ids, np.full(len(rest), -1)])[order]
            shared = np.concatenate([shared, np.zeros(len(rest), bool)])[order]
            boxes = np.concatenate([boxes, np.zeros((len(rest), 4))])[order]
        out = cast("sv.Detections", detections[rows])  # an index array: a Detections
        if shared.any():  # each track its own box, in the input's dtype
            out.xyxy = np.array(out.xyxy, copy=True)
            out.xyxy[shared] = boxes[shared].astype(out.xyxy.dtype)
        out.tracker_id = ids
        return out

    def prime(self, frames: Iterable[NDArray[np.uint8]]) -> None:
        """Start the background behind box refinement from `frames` (:meth:`pftrack.Tracker.prime`).

        Before the first update, with the video's first frames (``tracker.prime_frames`` of
        them are read), as ``pftrack track`` does: then the adapter's rows are the command's,
        as the plain loop's are (unprimed, the background learns the first frames' running
        mean, people walking through them included, and the boxes after are refined against
        their ghosts: TUD-Campus 76.9 / 77.7 MOTA / IDF1 against the command's 79.4 / 85.4).
        """
        self.tracker.prime(frames)

    def finalize(self) -> F64:
        """The run's MOTChallenge rows after the offline pass (:meth:`pftrack.Tracker.finalize`).

        Their boxes are the filters' estimates, not clipped to the frame: near an edge they may
        reach past it by a few pixels (clip them before cropping).
        """
        return self.tracker.finalize()

    def reset(self) -> None:
        """Forget every track (:meth:`pftrack.Tracker.reset`)."""
        self.tracker.reset()

    def __copy__(self) -> SupervisionTracker:
        """Refused: a shallow copy would share the run's :class:`pftrack.Tracker`."""
        raise TypeError(
            "copy.copy(SupervisionTracker) would share the run's state with the original; use "
            "copy.deepcopy(tracker) for an independent copy"
        )
