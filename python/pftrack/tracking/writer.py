"""Collecting a run's tracks as MOTChallenge rows, deciding what coasting becomes."""

from __future__ import annotations

from collections.abc import Collection, Mapping
from typing import Any

import numpy as np

from pftrack._check import option
from pftrack._stats import unique_values
from pftrack._typing import F64
from pftrack.recovery.linking import LinkConfig
from pftrack.tracking.offline import COLOUR_USES, BoxSmoother, CrossingConfig, smooth_tracks
from pftrack.tracking.track import Track

__all__ = ["TrackWriter"]


class _Rows:
    """Rows of 10 floats, each with an optional detection box, in float64 blocks.

    A run keeps every row it writes until its offline pass. As Python lists a row took about
    600 bytes (ten float objects, the list, the box's array); in blocks of :data:`BLOCK` rows it
    takes 10 + 4 floats and a flag, 113 bytes, and the values are the same float64 numbers.
    """

    BLOCK = 1024
    #: Colour blocks (:meth:`colours`); a store pickled before stop 74 has none.
    _cdone: list[F64] | None = None
    _col: F64 | None = None

    def __init__(self) -> None:
        self._done: list[tuple[F64, F64, np.ndarray]] = []  # full blocks: rows, boxes, has-box
        self._new()

    def _new(self) -> None:
        if self._col is not None:  # the full block's histograms, kept beside its rows
            assert self._cdone is not None
            self._cdone.append(self._col)
            # every row is written as it is kept (a row without one gets zeros): no memset of
            # the block (11.6 k instructions an update of bench.test_api)
            self._col = np.empty_like(self._col)
        self._rows = np.empty((self.BLOCK, 10))
        self._boxes = np.zeros((self.BLOCK, 4))
        self._has = np.zeros(self.BLOCK, bool)
        self._n = 0

    def append(self, row: list[float], box: F64 | None) -> None:
        """Keep one row and its detection box (None: the row has none)."""
        self.extend([row], [box])

    def extend(
        self,
        rows: list[list[float]],
        boxes: list[F64 | None],
        colours: list[F64 | None] | None = None,
    ) -> None:
        """Keep each row and its box in turn, the rows of a block in one copy.

        A frame's rows (one per track reported) were one NumPy assignment each. `colours`
        (one histogram or None a row) are kept too when given: :meth:`colours`.
        """
        if colours is not None and self._col is None:
            first = next((c for c in colours if c is not None), None)
            if first is not None:  # the first histogram sets the bins; earlier rows had none
                self._cdone = [np.zeros((self.BLOCK, len(first))) for _ in self._done]
                self._col = np.empty((self.BLOCK, len(first)))  # rows written as kept
                self._col[: self._n] = 0.0
        at = 0
        while at < len(rows):
            if self._n == self.BLOCK:
                self._done.append((self._rows, self._boxes, self._has))
                self._new()
            k = min(len(rows) - at, self.BLOCK - self._n)
            self._rows[self._n : self._n + k] = rows[at : at + k]
            for j, box in enumerate(boxes[at : at + k], start=self._n):
                if box is not None:
                    self._boxes[j] = box
                    self._has[j] = True
            if self._col is not None:
                self._keep_colours(None if colours is None else colours[at : at + k], k)
            self._n += k
            at += k

    def _keep_colours(self, colours: list[F64 | None] | None, k: int) -> None:
        """Write the histograms of the next `k` rows (zeros for None) in one copy if it can."""
        assert self._col is not None
        at = slice(self._n, self._n + k)
        if colours is None:
            self._col[at] = 0.0
            return
        if not any(c is None for c in colours):  # every row has one (the usual case)
            self._col[at] = colours  # one copy (None would be written as NaN)
            return
        for j, c in enumerate(colours, start=self._n):
            self._col[j] = 0.0 if c is None else c

    def __len__(self) -> int:
        return self.BLOCK * len(self._done) + self._n

    def arrays(self, start: int = 0) -> tuple[F64, F64, np.ndarray]:
        """Rows ``(M, 10)``, boxes ``(M, 4)`` and whether each has one, from row `start` on.

        Only those rows are copied (a live run asks for its newest rows every frame); the arrays
        returned are copies.
        """
        first = min(max(start, 0) // self.BLOCK, len(self._done))  # blocks before it: skipped
        cut = max(start, 0) - first * self.BLOCK  # rows of the first block read: from `cut` on
        parts = [*self._done[first:], (self._rows[: self._n], self._boxes[: self._n],
                                       self._has[: self._n])]  # fmt: skip
        rows, boxes, has = (
            np.concatenate([parts[0][k][cut:], *(p[k] for p in parts[1:])]) for k in range(3)
        )
        return rows, boxes, has

    def colours(self) -> F64 | None:
        """Every row's colour histogram ``(M, B)`` (zeros: none was given), or None if none was.

        A copy, in the rows' order (:meth:`arrays`).
        """
        if self._col is None:
            return None
        assert self._cdone is not None
        return np.concatenate([*self._cdone, self._col[: self._n]])


class TrackWriter:
    """Collects a run's tracks as MOTChallenge rows, deciding what coasting becomes.

    A track carried by its particle filter alone (no detection) is held back: its boxes are
    written once a detection confirms the track again, and dropped if the track ends unconfirmed.
    So an occlusion the filter bridged is filled, and a filter that lost its object adds nothing.
    :meth:`result` then hands the rows to the offline pass (:func:`~.offline.smooth_tracks`):
    linking fragments, and replacing every track's boxes by the smoother's estimates from the
    track's detection boxes before and after each frame.

    Parameters
    ----------
    coasting : {"confirmed", "all", "none"}
        Write held-back boxes when the track is re-detected (default), always, or never.
    fill : {"linear", "pf"}
        Boxes of a bridged gap: interpolated between the detections at its ends (default;
        measured better on PETS09 and TUD-Campus), or the particle filter's own estimates. A
        smoother replaces them when the track has detection boxes to fit.
    smoother : BoxSmoother or None
        Offline smoothing of each track (default on; it adds about 10 MOTA on PETS09 and
        TUD-Campus public detections, docs/results.md). None writes the boxes as reported.
    link : LinkConfig or None
        Join fragments of one object (:func:`pftrack.recovery.linking.link_tracklets`, motion
        and size terms) before smoothing, so a joined track is smoothed as one; with a smoother,
        the frames missing inside a track (up to ``link.max_gap``) are then written with the
        smoother's interpolation. None keeps every id and every hole.
    colour : {"swap", "link", "both"} or None
        Keep the colour histogram of every row written (:attr:`Track.colour`: the matched
        detection's, or the filter's reference) and hand them to the offline pass: the fill's
        swap rule, the linker's colour term, or both (:func:`~.offline.smooth_tracks`'
        ``histograms``). None (default): no colour kept or used (docs/recovery.md, "The
        tracker's own colour in the offline pass").
    """

    #: A writer pickled before stop 74 keeps no colour.
    colour: str | None = None

    def __init__(self, coasting: str = "confirmed", fill: str = "linear",
                 smoother: BoxSmoother | None = BoxSmoother(),  # noqa: B008 - frozen
                 link: LinkConfig | None = LinkConfig(),  # noqa: B008
                 colour: str | None = None) -> None:  # fmt: skip
        option(coasting, "coasting", ("confirmed", "all", "none"))
        option(fill, "fill", ("linear", "pf"))
        if coasting not in ("confirmed", "all", "none"):
            raise ValueError(f"coasting is {coasting!r}, expected 'confirmed', 'all' or 'none'")
        if fill not in ("linear", "pf"):
            raise ValueError(f"fill is {fill!r}, expected 'linear' or 'pf'")
        if smoother is not None and not isinstance(smoother, BoxSmoother):
            raise TypeError(
                f"smoother must be a BoxSmoother or None, got {type(smoother).__name__}"
            )
        if link is not None and not isinstance(link, LinkConfig):
            raise TypeError(f"link must be a LinkConfig or None, got {type(link).__name__}")
        option(colour, "colour", (*COLOUR_USES, None))
        if colour is not None and colour not in COLOUR_USES:
            raise ValueError(f"colour is {colour!r}, expected one of {COLOUR_USES} or None")
        self.colour = colour
        self.coasting = coasting
        self.fill = fill
        self.smoother = smoother
        self.link = link
        self.rows = _Rows()  # with each row's detection box, if it has one
        self._pending: dict[int, list[list[float]]] = {}
        self._last: dict[int, list[float]] = {}
        self._cls: dict[int, int] = {}  # class of each track id
        self._held: dict[int, list[F64 | None]] = {}  # with `colour`: the held-back rows'
        self.classes: dict[int, int] = {}  # class of each id of the last result()

    def __setstate__(self, state: dict[str, Any]) -> None:
        rows = state.get("rows")
        if isinstance(rows, list):  # a checkpoint made before stop 36: rows as Python lists
            store = _Rows()
            for row, box in zip(rows, state.pop("_measured"), strict=True):
                store.append(row, None if box is None else np.asarray(box, np.float64))
            state["rows"] = store
        self.__dict__.update(state)

    def add(self, frame: int, tracks: list[Track]) -> None:
        """Record the tracks reported for `frame` (1-based)."""
        rows: list[list[float]] = []  # the frame's rows in order, written at once at the end
        boxes: list[F64 | None] = []
        keep = self.colour is not None
        colours: list[F64 | None] = []  # with `colour`: each row's histogram
        for t in tracks:
            self._cls[t.id] = t.cls
            if t.history:
                for f, box, score in t.history:  # a new track's detections before confirmation
                    row = [float(f), float(t.id), *map(float, box), score, -1.0, -1.0, -1.0]
                    rows.append(row)
                    boxes.append(np.asarray(box))
                if keep:
                    colours += t.history_colours or [None] * len(t.history)
            row = [float(frame), float(t.id), *t.box_xywh.tolist(), float(t.score)]
            row += [-1.0, -1.0, -1.0]
            if t.time_since_update == 0:
                pending = self._pending.pop(t.id, [])
                if pending and self.fill == "linear" and t.id in self._last:
                    a, b = np.asarray(self._last[t.id]), np.asarray(row)
                    for p in pending:
                        u = (p[0] - a[0]) / (b[0] - a[0])
                        p[2:6] = list((1 - u) * a[2:6] + u * b[2:6])
                rows += pending
                boxes += [None] * len(pending)
                rows.append(row)
                boxes.append(t.detection_box)
                self._last[t.id] = row
                if keep:  # held-back rows: the reference each was reported with
                    if pending:
                        colours += self._held.pop(t.id, [None] * len(pending))
                    colours.append(t.colour)
            elif self.coasting == "all":
                rows.append(row)
                boxes.append(None)
                if keep:
                    colours.append(t.colour)
            elif self.coasting == "confirmed":
                self._pending.setdefault(t.id, []).append(row)
                if keep:
                    self._held.setdefault(t.id, []).append(t.colour)
        if rows:
            self.rows.extend(rows, boxes, colours if keep else None)

    def result(self, drop: Collection[int] = (), crossings: CrossingConfig | None = None,
               relink_coast: int | None = None,
               smoothers: Mapping[int, BoxSmoother] | None = None) -> F64:  # fmt: skip
        """All rows written so far, (M, 10), sorted by frame then id.

        Linked and smoothed when the writer has a link config and a smoother, each class's tracks
        apart (``Track.cls``: the linker never joins two classes); the tracks of
        the ids in `drop` are left out first. With `relink_coast`, a track re-found after at
        least that many coasted frames is cut there before linking
        (:func:`~.offline.split_refound`). With `crossings` (enabled), tracks swapped where
        they crossed are exchanged back after linking (:func:`~.offline.repair_crossings`).
        :attr:`classes` gets the class of each id of the result. `smoothers` gives a class its
        own smoother (levels grown with that class's speed,
        :meth:`~pftrack.tracking.tracker.MultiObjectTracker.motion_gain`); the others, and
        every class when None, get :attr:`smoother`.
        """
        own = {} if smoothers is None or self.smoother is None else smoothers
        self.classes = {}
        a, boxes, observed = self.rows.arrays()
        if len(drop):
            keep = ~np.isin(a[:, 1], np.fromiter(drop, np.float64))
            a, boxes, observed = a[keep], boxes[keep], observed[keep]
        if len(a) == 0:
            return np.zeros((0, 10))
        hists = None if self.colour is None else self.rows.colours()
        if hists is not None and len(drop):
            hists = hists[keep]
        z = a[:, 2:6].copy()  # the smoother fits the detection boxes, not the reported ones
        z[observed] = boxes[observed]
        use = self.colour if hists is not None else None
        cls = np.array([self._cls.get(int(i), 0) for i in a[:, 1]], np.int64)
        classes = unique_values(cls)
        if len(classes) == 1:
            smoother = own.get(int(classes[0]), self.smoother)
            rows = smooth_tracks(
                a, observed, smoother, self.link, z, crossings=crossings,
                relink_coast=relink_coast, histograms=hists, colour=use or "both",
            )  # fmt: skip
            ids = unique_values(rows[:, 1]).astype(int).tolist()
            self.classes = dict.fromkeys(ids, int(classes[0]))
            return rows
        # classes never share an identity: each class's tracks are linked among themselves, and
        # an id a pass makes (a cut piece) is renumbered above every id of the run
        parts = []
        fresh = int(a[:, 1].max()) + 1
        for c in classes:
            k = cls == c
            out = smooth_tracks(
                a[k], observed[k], own.get(int(c), self.smoother), self.link, z[k],
                crossings=crossings,
                relink_coast=relink_coast,
                histograms=None if hists is None else hists[k],
                colour=use or "both",
            )  # fmt: skip
            new = np.setdiff1d(out[:, 1], a[k, 1])
            if len(new):
                ids = out[:, 1].copy()
                for i, v in enumerate(new.tolist()):
                    ids[out[:, 1] == v] = fresh + i
                out[:, 1] = ids
                fresh += len(new)
            parts.append(out)
            self.classes.update(dict.fromkeys(np.unique(out[:, 1]).astype(int).tolist(), int(c)))
        rows = np.vstack(parts)
        return rows[np.lexsort((rows[:, 1], rows[:, 0]))]
