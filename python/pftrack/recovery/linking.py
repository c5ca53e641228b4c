"""Tracklet linking: join the fragments of one object in any tracker's MOTChallenge output.

Rows are ``(M, 10)`` MOTChallenge arrays ``frame,id,left,top,width,height,conf,x,y,z``.
Rows pftrack fills (:mod:`pftrack.recovery.fill`, the offline tracker) carry the
**interpolated flag in column 8** (1-based; index :data:`FLAG_COLUMN` = 7, the world-``x``
column, which is -1 in 2D MOTChallenge files): ``1`` on every filled row, with columns 9-10
``-1``; observed rows untouched. Column 8 alone can hold 1 in an observed row (class 1,
pedestrian, in MOT16+ ground truth; a world ``x`` in MOT15's): :func:`filled_mask` tests all
three columns.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, replace
from typing import Any, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

import pftrack._core as _core
from pftrack._check import (
    BOX_VALUES,
    MAX_FRAME,
    MAX_ID,
    NORMALISED_REACH,
    bad_id_message,
    brief,
    exactly,
    first_bad_box,
    first_bad_id,
    frames_from_1,
    mot_rows,
    shown,
)
from pftrack._text import counted
from pftrack._typing import F64, PathLike
from pftrack._warn import warn
from pftrack.boxes import _to_cxcywh
from pftrack.particle_filter.colour import (
    bhattacharyya_distance,
    box_histograms,
    hsv_bins,
)

__all__ = [
    "FILLED_MARK",
    "FLAG_COLUMN",
    "MAX_ID",
    "BoxColours",
    "RowColours",
    "LinkConfig",
    "box_centres",
    "check_boxes",
    "check_file_ids",
    "check_rows",
    "check_unique",
    "filled_mask",
    "frame_histograms",
    "gate_for_rows",
    "link_cost_matrix",
    "link_frames",
    "link_costs",
    "link_tracklets",
    "pixel_scale",
    "read_tracks",
    "sorted_tracks",
    "split_tracks",
]

FLAG_COLUMN = 7  #: 0-based index of the interpolated flag (column 8 of a MOTChallenge row)
#: Columns 8-10 (1-based) of every row pftrack filled: the flag, then no world ``y``, ``z``.
FILLED_MARK = (1.0, -1.0, -1.0)
#: Frames up to this diagonal (640x480) take pixel settings as given; larger ones scale them.
REFERENCE_DIAGONAL = 800.0


@dataclass(frozen=True)
class LinkConfig:
    """Gates and weights of the linking cost.

    Attributes
    ----------
    max_gap : int
        Largest number of missing frames between two fragments that may be joined.
    max_distance : float
        Gate (pixels) on the distance between a fragment's motion prediction and the other
        fragment's first (or, backwards, last) box centre.
    w_gap, w_size, w_appearance : float
        Weights of the time gap (as a fraction of `max_gap`), the box-height log ratio and the
        Bhattacharyya distance between the HSV colour histograms
        (:mod:`pftrack.particle_filter.colour`, default binning) of the two boxes that meet;
        the motion term (mean prediction distance over `max_distance`) has weight 1.
    velocity_points : int
        Points used to fit each fragment's end velocity.
    max_area_ratio : float or None
        Gate on the boxes that meet: their areas may differ by at most this factor (None: no
        gate); a box without area meets only another without. Two one-row fragments of
        ByteTrack's false positives on TUD-Campus, 4.1 times apart in area, were joined
        across 30 frames and the hole filled. Chosen on the
        outputs of four trackers (SORT, ByteTrack, norfair, motpy) on five sequences
        smoothed by ``pftrack smooth`` (docs/results.md), among a factor of 2, 2.5 or 3 on each
        side and 3 or 4 on the area: the highest sums of MOTA and IDF1 gains with no row
        losing more than 0.1 MOTA.
    """

    max_gap: int = 30
    max_distance: float = 50.0
    w_gap: float = 0.5
    w_size: float = 1.0
    w_appearance: float = 1.0
    velocity_points: int = 5
    max_area_ratio: float | None = 4.0

    def __post_init__(self) -> None:
        for name, hi in (("max_gap", 100_000), ("velocity_points", 1_000)):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not 1 <= v <= hi:
                raise ValueError(f"LinkConfig.{name} is {brief(v)}, expected an int in 1..{hi}")
        for name in ("max_distance", "w_gap", "w_size", "w_appearance"):
            v = getattr(self, name)
            ok = isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, bool)
            if not ok or not np.isfinite(v) or v < 0 or (name == "max_distance" and v == 0):
                raise ValueError(
                    f"LinkConfig.{name} is {brief(v)}, expected a finite number "
                    + ("> 0" if name == "max_distance" else ">= 0")
                )
        v = self.max_area_ratio
        if v is not None and (
            isinstance(v, bool)
            or not isinstance(v, (int, float, np.integer, np.floating))
            or not (np.isfinite(v) and v >= 1)
        ):
            raise ValueError(
                f"LinkConfig.max_area_ratio is {brief(v)}, expected None or a number >= 1"
            )


def pixel_scale(width: float, height: float, diagonal: float = REFERENCE_DIAGONAL) -> float:
    """``max(1, hypot(width, height) / diagonal)``: how much pixel settings grow on a frame."""
    return max(1.0, float(np.hypot(width, height)) / float(diagonal))


def gate_for_rows(config: LinkConfig, rows: ArrayLike) -> LinkConfig:
    """`config` with its pixel gate grown to the frame the rows' boxes span.

    The frame is taken to reach the rightmost and lowest box edge of `rows` (MOTChallenge rows;
    a lower bound of the frame the tracker saw), and ``max_distance`` is multiplied by
    :func:`pixel_scale` of it: as given up to 640x480, in proportion to the diagonal above, as
    :class:`pftrack.Tracker` scales it by its frames (``TrackerConfig.pixel_diagonal``). What
    ``pftrack smooth`` and ``pftrack recover --link`` (without ``--max-distance``) use.

    A few stray rows cannot widen the gate: edges more than :data:`STRAY_REACH` times the
    edge that 99 % of the rows stay within are left out of the extent, with a warning (one box
    at x = 2500 in a 768x576 file made the gate 3.6 times wider, and fragments of different
    people were joined). On the files we have every edge lies within 1.03 times that one.
    """
    a = mot_rows(rows, "gate_for_rows")
    if len(a) == 0:
        return config
    edges = (a[:, 2] + a[:, 4], a[:, 3] + a[:, 5])  # right, bottom
    bulk = [float(np.quantile(e, 0.99, method="higher")) for e in edges]
    stray = (edges[0] > STRAY_REACH * max(bulk[0], 1.0)) | (
        edges[1] > STRAY_REACH * max(bulk[1], 1.0)
    )
    if stray.any():
        k = int(np.flatnonzero(stray)[0])
        warn(
            f"{int(stray.sum())} row(s) reach far past the others (the first: frame "
            f"{a[k, 0]:g}, id {a[k, 1]:g}, right and bottom edges {edges[0][k]:g}, "
            f"{edges[1][k]:g} px; 99 % of the rows within {bulk[0]:g}, {bulk[1]:g}): left out "
            "of the frame extent that sizes the linking gate",
            stacklevel=2,
        )
    extent = [float(np.max(e[~stray])) for e in edges]
    scale = pixel_scale(max(extent[0], 0.0), max(extent[1], 0.0))
    return replace(config, max_distance=config.max_distance * scale)


def link_config_for(rows: ArrayLike, max_gap: int, max_distance: float | None = None) -> LinkConfig:
    """The linking settings of ``pftrack recover --link`` and ``pftrack smooth`` for `rows`.

    ``LinkConfig(max_gap=max_gap)`` with the gate `max_distance` (pixels) when given, else
    50 px grown to the frame the rows span (:func:`gate_for_rows`).
    """
    cfg = LinkConfig(max_gap=max_gap)
    if max_distance is None:
        return gate_for_rows(cfg, rows)
    return replace(cfg, max_distance=max_distance)


#: How far past the edge 99 % of a file's boxes stay within a box edge may reach and still
#: count for the frame's extent in :func:`gate_for_rows` (farther: a stray row).
STRAY_REACH = 1.25


def filled_mask(rows: ArrayLike) -> NDArray[np.bool_]:
    """Which MOTChallenge rows pftrack filled: columns 8-10 (1-based) are ``1, -1, -1``.

    Parameters
    ----------
    rows : (M, 6..10) array_like
        MOTChallenge rows, e.g. :func:`pftrack.io.mot.read_mot` of a ``pftrack recover`` or
        ``pftrack smooth`` output (fewer than 10 columns: no row is filled, as in a file).

    Returns
    -------
    (M,) ndarray of bool
        True where the interpolated flag (column 8, :data:`FLAG_COLUMN`) is 1 and columns 9-10
        are -1 (:data:`FILLED_MARK`). An observed row of a tracker's output (``-1, -1, -1``),
        of MOT16+ ground truth (class, visibility in 0..1, ``-1``) or of MOT15 ground truth
        (world coordinates) never matches unless it holds those three values exactly.

    Raises
    ------
    TypeError
        Not real numbers.
    ValueError
        If `rows` is not ``(M, 6..10)`` (:func:`pftrack._check.mot_rows`).
    """
    a = mot_rows(rows, "filled_mask")
    mark = np.asarray(FILLED_MARK)
    out: NDArray[np.bool_] = np.all(a[:, FLAG_COLUMN : FLAG_COLUMN + 3] == mark, axis=1)
    return out


def box_centres(rows: F64) -> F64:
    """Rows ``(frame, cx, cy)`` of the box centres of MOTChallenge rows."""
    return np.column_stack(
        [rows[:, 0], rows[:, 2] + 0.5 * rows[:, 4], rows[:, 3] + 0.5 * rows[:, 5]]
    )


def _end_velocity(c: F64, k: int, tail: bool) -> F64:
    part = c[-k:] if tail else c[:k]
    if len(part) < 2:
        return np.zeros(2)
    t = part[:, 0] - part[:, 0].mean()
    denom = float(np.sum(t * t))
    return np.asarray((t @ (part[:, 1:3] - part[:, 1:3].mean(axis=0))) / denom, dtype=np.float64)


def sorted_tracks(rows: F64, *, share: bool = False) -> tuple[F64, NDArray[np.int64]]:
    """`rows` sorted by id, then frame (one copy), and the end of each id's rows in it.

    The rows of the ``k``-th id are ``sorted[ends[k - 1]:ends[k]]`` (``ends[-1]`` is 0): the
    tracks of :func:`split_tracks`, in its order, without a dict of views. With `share`, rows
    already in that order, each (id, frame) once, come back themselves, not copied (for a
    caller that only reads them: ``pftrack smooth`` fills holes in rows it sorted).
    """
    if share and len(rows) > 1:
        step_id, step_frame = np.diff(rows[:, 1]), np.diff(rows[:, 0])
        if np.all((step_id > 0) | ((step_id == 0) & (step_frame > 0))):
            return rows, np.r_[np.flatnonzero(step_id != 0) + 1, len(rows)]
    r = rows[np.lexsort((rows[:, 0], rows[:, 1]))]  # by id, then frame (stable)
    if len(r) == 0:
        return r, np.zeros(0, dtype=np.int64)
    return r, np.r_[np.flatnonzero(r[1:, 1] != r[:-1, 1]) + 1, len(r)]


def split_tracks(rows: F64) -> dict[int, F64]:
    """Rows of each id, sorted by frame."""
    if len(rows) == 0:
        return {}
    r, ends = sorted_tracks(rows)
    starts = np.r_[0, ends[:-1]]
    return {int(r[i, 1]): r[i:j] for i, j in zip(starts, ends, strict=True)}


def frame_histograms(
    boxes: dict[int, F64], frames: Sequence[NDArray[np.uint8]]
) -> dict[int, F64 | None]:
    """Colour histograms of boxes ``(K, 4)`` ``left, top, width, height`` at 0-based frames.

    Returns, per frame index of `boxes`, the ``(K, B)`` histograms of its boxes
    (:func:`pftrack.particle_filter.colour.box_histograms`, the particle filters' binning; a
    box with nothing to count gets a row of zeros), or None where `frames` has no such frame.
    The frames are asked for in increasing order, each once, and binned one at a time: a
    sequence that reads a video on demand (:class:`pftrack.io.video.FrameSequence`) decodes it
    in one pass, holding one frame. The linker's colour term (:func:`link_costs`) and the
    fill's swap rule (:func:`pftrack.recovery.fill.swap_holes`) read frames through it.
    """
    if isinstance(frames, BoxColours):  # read already, in the pass that served every reader
        return frames.histograms(boxes)
    out: dict[int, F64 | None] = {}
    n = len(frames)
    for f in sorted(boxes):
        if not 0 <= f < n:
            out[f] = None
            continue
        b = boxes[f]
        out[f] = box_histograms(hsv_bins(frames[f]), _to_cxcywh(b)) if len(b) else np.zeros((0, 0))
    return out


class BoxColours(Sequence[NDArray[np.uint8]]):
    """The colour histograms of every box of `rows` at chosen frames, read in one pass.

    Stands for `frames` where several readers need colour at frames known beforehand:
    ``pftrack recover --link --video`` gives it to :func:`link_tracklets` (the fragment ends'
    frames, :func:`link_frames`) and then to :func:`pftrack.recovery.fill.fill_gaps` (the
    holes' sides, :func:`pftrack.recovery.fill.side_frames`), so the video is decoded once,
    not once per reader. :func:`frame_histograms` answers from it: each box's histogram is
    the one a reader binning that frame would compute (the same call on the same frame), so
    the readers' results are those of reading `frames` themselves.

    Parameters
    ----------
    frames : sequence of (H, W, 3) uint8
        The video's BGR frames (index ``frame - 1``), e.g. a
        :class:`pftrack.io.video.FrameSequence`; read here, in increasing order, each once.
    rows : (M, >=6) ndarray
        Rows ``frame, id, left, top, width, height, ...``; only their boxes are used (ids may
        change afterwards, as linking changes them).
    wanted : iterable of int
        0-based frames to read; each box of `rows` at these frames is binned.
    """

    def __init__(self, frames: Sequence[NDArray[np.uint8]], rows: F64, wanted: Iterable[int]):
        self.frames = frames
        fr = rows[:, 0].astype(np.int64) - 1
        want = np.unique(np.fromiter(wanted, dtype=np.int64))
        at = np.flatnonzero(np.isin(fr, want))
        at = at[np.argsort(fr[at], kind="stable")]
        cuts = np.flatnonzero(np.diff(fr[at])) + 1
        boxes = {
            int(fr[g[0]]): np.unique(rows[g, 2:6], axis=0) for g in np.split(at, cuts) if len(g)
        }
        self._boxes = boxes
        self._hists = frame_histograms(boxes, frames)
        # each frame's boxes by value: a reader asks for a box by its four numbers
        self._index = {f: {_key(b): k for k, b in enumerate(v)} for f, v in boxes.items()}

    def __len__(self) -> int:
        return len(self.frames)

    @overload
    def __getitem__(self, k: int) -> NDArray[np.uint8]: ...
    @overload
    def __getitem__(self, k: slice) -> Sequence[NDArray[np.uint8]]: ...
    def __getitem__(self, k: int | slice) -> Any:
        """The underlying frame (a reader that bins its own frames reads them again)."""
        return self.frames[k]

    def histograms(self, boxes: dict[int, F64]) -> dict[int, F64 | None]:
        """What :func:`frame_histograms` returns for `boxes` on the frames; read already.

        A frame or box that was not read beforehand is read now (another pass: a caller's
        `wanted` missed it), so the answer never depends on what was read.
        """
        out: dict[int, F64 | None] = {}
        missing: dict[int, F64] = {}  # frame_histograms' own answer (no box or no frame: no read)
        for f, b in boxes.items():
            h, index = self._hists.get(f), self._index.get(f)
            if h is not None and index is not None and len(b):
                at = [index.get(_key(x)) for x in b]
                if None not in at:
                    out[f] = h[np.array(at, dtype=np.intp)]
                    continue
            missing[f] = b
        if missing:
            out.update(frame_histograms(missing, self.frames))
        return out


class RowColours(BoxColours):
    """Colour histograms given per row (a tracker's own), answered as :class:`BoxColours` does.

    Stands for `frames` in the readers of :func:`frame_histograms` (the linker's colour term,
    the fill's swap rule) when the histograms are known already: each row's histogram is the
    answer for its boxes at its frame, so no frame is decoded. A box of no row, or a row whose
    histogram is all zeros, gets a row of zeros: nothing to count, which the readers do not
    judge (a hole side without colour, a fragment end without colour cost).

    Parameters
    ----------
    rows : (M, >=6) ndarray
        Rows ``frame, id, left, top, width, height, ...``.
    histograms : (M, B) ndarray
        Each row's histogram (zeros: none).
    boxes : (M, 4) ndarray, optional
        Other boxes of the same rows with the same histograms (e.g. the measured ones the
        fill reads, where the rows hold filtered boxes).
    """

    def __init__(self, rows: F64, histograms: F64, boxes: F64 | None = None) -> None:
        self.frames: Sequence[NDArray[np.uint8]] = ()
        self._bins = histograms.shape[1]
        fr = rows[:, 0].astype(np.int64) - 1
        self._last = int(fr.max()) + 1 if len(fr) else 0
        index: dict[int, dict[bytes, int]] = {}
        sets = [rows[:, 2:6]] if boxes is None else [rows[:, 2:6], boxes]
        for b in sets:
            for k, (f, x) in enumerate(zip(fr.tolist(), b, strict=True)):
                index.setdefault(f, {}).setdefault(_key(x), k)  # a box's first row answers
        self._index = index
        self._rows_hists = histograms

    def __len__(self) -> int:
        return self._last

    def __getitem__(self, k: int | slice) -> Any:
        """No frame is held: the histograms are the rows'."""
        raise IndexError("RowColours holds histograms, not frames")

    def histograms(self, boxes: dict[int, F64]) -> dict[int, F64 | None]:
        """Each box's row's histogram at its 0-based frame (zeros where no row has it)."""
        out: dict[int, F64 | None] = {}
        for f, b in boxes.items():
            index = self._index.get(f, {})
            h = np.zeros((len(b), self._bins))
            for k, x in enumerate(b):
                at = index.get(_key(x))
                if at is not None:
                    h[k] = self._rows_hists[at]
            out[f] = h
        return out


def _key(box: F64) -> bytes:
    """A box's four numbers as :class:`BoxColours` looks it up."""
    return np.ascontiguousarray(box, dtype=np.float64).tobytes()


def link_frames(rows: ArrayLike, config: LinkConfig) -> set[int]:
    """The 0-based frames whose colour :func:`link_tracklets` reads for `rows` and `config`.

    The frames of the fragment ends of the pairs within the gates (:func:`link_costs`), none
    when ``config.w_appearance`` is 0: what a :class:`BoxColours` must hold to serve the
    linker without reading the video again.
    """
    a = check_rows(rows, "link_frames", "tracks")
    check_unique(a, who="link_frames")  # as link_tracklets refuses them
    check_tracked(a, who="link_frames")
    if not len(a) or config.w_appearance <= 0:
        return set()
    tracks = split_tracks(a)
    ids, i, j, _ = link_costs(tracks, config)
    ends = [int(tracks[ids[k]][-1, 0]) - 1 for k in np.unique(i).tolist()]
    starts = [int(tracks[ids[k]][0, 0]) - 1 for k in np.unique(j).tolist()]
    return set(ends) | set(starts)


def _end_histograms(
    tracks: dict[int, F64], ends: Iterable[tuple[int, bool]], frames: Sequence[NDArray[np.uint8]]
) -> dict[tuple[int, bool], F64 | None]:
    """Colour histogram of the box at each fragment end of `ends` (id, last row or first).

    None where there is no frame or nothing to count (:func:`frame_histograms`, one pass).
    """
    at: dict[int, list[tuple[int, bool]]] = {}
    for key in ends:
        tid, last = key
        at.setdefault(int(tracks[tid][-1 if last else 0, 0]) - 1, []).append(key)
    boxes = {
        f: np.array([tracks[tid][-1 if last else 0, 2:6] for tid, last in keys])
        for f, keys in at.items()
    }
    hists = frame_histograms(boxes, frames)
    out: dict[tuple[int, bool], F64 | None] = {}
    for f, keys in at.items():
        h = hists[f]
        for k, key in enumerate(keys):
            out[key] = None if h is None or h[k].sum() <= 0 else h[k]
    return out


def _fragment_ends(tracks: dict[int, F64], points: int) -> tuple[F64, F64]:
    """Per fragment (in `tracks` order): its last and first rows' data, velocities once each.

    Returns ``(K, 7)`` arrays: ``frame, cx, cy, vx, vy, height, width`` of each fragment's
    last row (with its tail velocity, :func:`_end_velocity`) and of its first row (head
    velocity).
    """
    k = len(tracks)
    tail, head = np.empty((k, 7)), np.empty((k, 7))
    for n, r in enumerate(tracks.values()):
        c = box_centres(r)
        tail[n, :3], tail[n, 3:5], tail[n, 5] = c[-1], _end_velocity(c, points, True), r[-1, 5]
        head[n, :3], head[n, 3:5], head[n, 5] = c[0], _end_velocity(c, points, False), r[0, 5]
        tail[n, 6], head[n, 6] = r[-1, 4], r[0, 4]
    return tail, head


def _sizes_apart(a: F64, b: F64, ratio: float | None) -> NDArray[np.bool_]:
    """Whether boxes of sizes `a` and `b` differ in area by more than `ratio`.

    `a`, `b`: ``(n, 2)`` heights and widths. A box without area (a width or height of 0) is
    apart from every box with one, and not from another without (was: not compared, so a
    fragment ending in a 0 x 46 px box was joined to one starting 68 x 86 px).
    """
    if ratio is None:
        return np.zeros(len(a), bool)
    area_a, area_b = a[:, 0] * a[:, 1], b[:, 0] * b[:, 1]
    return np.maximum(area_a, area_b) > ratio * np.minimum(area_a, area_b)


#: Candidate pairs gated at once by :func:`link_costs`: memory stays bounded by the pairs that
#: pass the gates, not by all those within the time gate (a file of 50000 one-row fragments,
#: 10 a frame, has 15 million: 2.8 GB; a user trial). Gating takes about 210 bytes a pair in
#: temporaries, so a block of 65536 pairs about 14 MB (was 2**20 pairs, 220 MB: the peak of
#: ``pftrack smooth`` on a crowded file, whose pairs within the time gate grow with the square
#: of the fragments a frame; the same pairs and costs, no slower).
PAIR_BLOCK = 1 << 16


def _pair_blocks(counts: NDArray[np.intp], block: int) -> Iterator[tuple[int, int]]:
    """Ranges ``lo, hi`` of consecutive entries whose `counts` (pairs) add up to `block` at most.

    Each range holds one entry at least (an entry of more than `block` pairs is never split),
    so a range's pairs are at most ``max(block, counts.max())``; together the ranges cover
    ``0 .. len(counts)`` in order. The pairs of :func:`_candidate_pairs`, and those of the
    offline pass's all-pairs steps (:mod:`pftrack.tracking.offline`), are made a range at a
    time: memory follows the block, not the pairs.
    """
    ends = np.cumsum(counts)
    lo = 0
    while lo < len(counts):
        done = int(ends[lo - 1]) if lo else 0
        hi = max(int(np.searchsorted(ends, done + block, side="right")), lo + 1)
        yield lo, hi
        lo = hi


def _candidate_pairs(
    last: F64, first: F64, max_gap: int
) -> Iterator[tuple[NDArray[np.intp], NDArray[np.intp]]]:
    """Pairs ``(i, j)`` where fragment j starts 1 to ``max_gap + 1`` frames after i ends.

    `last`, `first`: each fragment's last and first frame. Yielded in blocks of consecutive
    i of about :data:`PAIR_BLOCK` pairs (one i's pairs are never split), each sorted by i,
    then j: the blocks in turn are sorted by i, then j. Found by a binary search over the
    sorted first frames, so the work follows the number of pairs within the time gate, not
    the square of the number of fragments.
    """
    order = np.argsort(first, kind="stable")
    starts = first[order]
    lo = np.searchsorted(starts, last, side="right")  # starts after the end
    hi = np.searchsorted(starts, last + (max_gap + 1), side="right")  # at most max_gap missing
    counts = hi - lo
    for a, b in _pair_blocks(counts, PAIR_BLOCK):  # the i of this block, one at least
        n = counts[a:b]
        i = np.repeat(np.arange(a, b), n)
        offset = np.arange(len(i)) - np.repeat(np.cumsum(n) - n, n)
        j = order[np.repeat(lo[a:b], n) + offset]
        keep = np.lexsort((j, i))
        yield i[keep], j[keep]


def link_costs(
    tracks: dict[int, F64],
    config: LinkConfig = LinkConfig(),
    frames: Sequence[NDArray[np.uint8]] | None = None,
) -> tuple[list[int], NDArray[np.intp], NDArray[np.intp], F64]:
    """The pairs of fragments within the gates and the cost of joining each (sparse).

    What :func:`link_cost_matrix` holds, without its ``(K, K)`` matrix: the ids, and for each
    pair within the gates (the end of fragment ``ids[i]`` to the start of ``ids[j]``) ``i``,
    ``j`` and the cost, sorted by ``i`` then ``j``. Time and memory follow the number of
    pairs within the time gate (`config.max_gap`), not the square of the number of fragments.
    """
    ids = list(tracks)
    if not ids:
        empty = np.zeros(0, dtype=np.intp)
        return ids, empty, empty, np.zeros(0)
    tail, head = _fragment_ends(tracks, config.velocity_points)
    kept: list[tuple[NDArray[np.intp], NDArray[np.intp], F64, F64]] = []
    for i, j in _candidate_pairs(tail[:, 0], head[:, 0], config.max_gap):
        end, vi, start, vj = tail[i, 1:3], tail[i, 3:5], head[j, 1:3], head[j, 3:5]
        gap = head[j, 0] - tail[i, 0]
        g = gap[:, None]
        fwd = np.hypot(*(end + vi * g - start).T)
        bwd = np.hypot(*(start - vj * g - end).T)
        d = 0.5 * (fwd + bwd)
        near = ~(d > config.max_distance) & ~_sizes_apart(
            tail[i, 5:7], head[j, 5:7], config.max_area_ratio
        )
        kept.append((i[near], j[near], d[near], gap[near]))
    i, j, d, gap = (np.concatenate(parts) for parts in zip(*kept, strict=True))
    cost = d / config.max_distance + config.w_gap * (gap - 1) / max(config.max_gap, 1)
    hi, hj = tail[i, 5], head[j, 5]
    sized = (hi > 0) & (hj > 0)
    cost[sized] += config.w_size * np.abs(np.log(hi[sized] / hj[sized]))
    if frames is not None and config.w_appearance > 0 and len(i):
        ends = {(ids[a], True) for a in i.tolist()} | {(ids[b], False) for b in j.tolist()}
        hists = _end_histograms(tracks, sorted(ends), frames)
        for n, (a, b) in enumerate(zip(i.tolist(), j.tolist(), strict=True)):
            ha, hb = hists.get((ids[a], True)), hists.get((ids[b], False))
            if ha is not None and hb is not None:
                cost[n] += config.w_appearance * float(bhattacharyya_distance(ha, hb)[0])
    return ids, i, j, cost


def link_cost_matrix(
    tracks: dict[int, F64],
    config: LinkConfig = LinkConfig(),
    frames: Sequence[NDArray[np.uint8]] | None = None,
) -> tuple[list[int], F64]:
    """Cost of joining the end of fragment i to the start of fragment j (``inf`` when gated).

    Returns the ids (row i and column j both index this list) and the ``(K, K)`` cost matrix:
    :func:`link_costs`' pairs, every other cell ``inf``. `frames`, when given, is indexable by
    ``frame - 1`` (BGR images) and adds a colour term: only the frames of the fragment ends of
    pairs within the gates are read, in increasing order, each once (a
    :class:`pftrack.io.video.FrameSequence` reads them from the video in one pass).
    :func:`link_tracklets` does not build this matrix (its memory is the square of the number
    of fragments).
    """
    ids, i, j, cost = link_costs(tracks, config, frames)
    out = np.full((len(ids), len(ids)), np.inf)
    out[i, j] = cost
    return ids, out


#: Cost standing for a forbidden join in the assignment (each component's unmatched ends).
FORBIDDEN = 1e6
#: Components of the candidate pairs up to this many (ends x starts) cells are solved as a
#: dense matrix by :func:`pftrack.assignment.linear_sum_assignment` (32 MB at most); larger
#: ones by shortest augmenting paths over their pairs (``_core.sparse_assignment``, C++; its
#: NumPy reference is ``tests/reference/linking.py``'s), so memory follows the candidate pairs
#: whatever a component's size.
DENSE_CELLS = 1 << 22


def _components(i: NDArray[np.intp], j: NDArray[np.intp], k: int) -> NDArray[np.intp]:
    """Label of the connected component of every pair ``(i, j)`` (ends ``i``, starts ``k + j``)."""
    parent = list(range(2 * k))

    def root(a: int) -> int:
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for a, b in zip(i.tolist(), (j + k).tolist(), strict=True):
        ra, rb = root(a), root(b)
        if ra != rb:
            parent[max(ra, rb)] = min(ra, rb)
    return np.array([root(a) for a in i.tolist()], dtype=np.intp)


def _assign(i: NDArray[np.intp], j: NDArray[np.intp], cost: F64) -> list[tuple[int, int]]:
    """The joins ``(i, j)`` of a least-cost assignment of ends to starts over the given pairs.

    The most joins, then the least total cost: what a ``(K, K)`` matrix with
    :data:`FORBIDDEN` outside the pairs gives. Each connected component of the pairs is solved
    on its own (a pair outside the candidates is forbidden, so the optimum is the union of the
    components' optima), its ends and starts in the same relative order as in the whole
    matrix.
    """
    from pftrack.assignment import linear_sum_assignment  # SciPy's pairs, without SciPy

    if len(i) == 0:
        return []
    k = int(max(i.max(), j.max())) + 1
    label = _components(i, j, k)
    by = np.argsort(label, kind="stable")  # each component's pairs, still by i then j
    cuts = np.flatnonzero(np.diff(label[by])) + 1
    joins: list[tuple[int, int]] = []
    for part in np.split(by, cuts):
        ci, cj, cc = i[part], j[part], cost[part]
        ends, r = np.unique(ci, return_inverse=True)
        starts, c = np.unique(cj, return_inverse=True)
        if len(ends) * len(starts) > DENSE_CELLS:
            rows, cols = _core.sparse_assignment(r, c, cc, len(ends), len(starts), FORBIDDEN)
        else:
            m = np.full((len(ends), len(starts)), FORBIDDEN)
            m[r, c] = cc
            ok = np.zeros(m.shape, dtype=bool)
            ok[r, c] = True
            rows, cols = linear_sum_assignment(m)
            keep = ok[rows, cols]
            rows, cols = rows[keep], cols[keep]
        joins += zip(ends[rows].tolist(), starts[cols].tolist(), strict=True)
    return sorted(joins)


def link_tracklets(
    tracks: ArrayLike,
    config: LinkConfig = LinkConfig(),
    frames: Sequence[NDArray[np.uint8]] | None = None,
) -> tuple[F64, dict[int, int]]:
    """Join fragments of one object: Hungarian assignment of fragment ends to fragment starts.

    Only the pairs within the gates are scored (:func:`link_costs`: fragments whose start is
    at most ``config.max_gap`` missing frames after the other's end, found by a binary search),
    and each connected component of those pairs is assigned on its own (:func:`_assign`), so
    time and memory follow the pairs within the time gate, not the square of the number of
    fragments (8000 one-row fragments ten frames apart: under a second, where the ``(K, K)``
    matrix took 34 s and 1.6 GB). The joins are those of the whole ``(K, K)`` assignment: the
    most joins, then the least total cost (on exact ties between equally good assignments the
    components may pick another of them).

    Parameters
    ----------
    tracks : (M, 6..10) array_like
        MOTChallenge rows of a tracker's output (fewer than 10 columns: those of a file's
        shorter lines added, conf 1, x, y, z -1, :func:`pftrack._check.mot_rows`).
    config : LinkConfig
        Gates and weights.
    frames : sequence of (H, W, 3) uint8, optional
        The video's BGR frames (index ``frame - 1``) for the colour-histogram term.

    Returns
    -------
    rows : (M, 10) ndarray
        The rows with fragment ids replaced by the id of the first fragment of each chain.
    mapping : dict
        Old id -> new id for every relabelled fragment.

    Raises
    ------
    TypeError
        `config` is not a :class:`LinkConfig`.
    ValueError
        Bad rows (:func:`check_rows`: a box :func:`pftrack.io.mot.read_mot` refuses too) or a
        (frame, id) seen twice.
    """
    if not isinstance(config, LinkConfig):  # a string failed on a missing attribute
        raise TypeError(f"link_tracklets: config must be a LinkConfig, got {shown(config)}")
    if frames is not None and not (hasattr(frames, "__len__") and hasattr(frames, "__getitem__")):
        raise TypeError(
            "link_tracklets: frames must be a sequence indexable by frame - 1 (a list, an "
            f"array, a FrameSequence) or None, got {type(frames).__name__}"
        )
    rows = np.array(check_rows(tracks, "link_tracklets", "tracks"), dtype=np.float64, copy=True)
    check_unique(rows, who="link_tracklets")  # a track seen twice has no velocity to link
    check_tracked(rows, who="link_tracklets")
    if len(rows) == 0:
        return rows, {}
    if frames is not None and len(frames) < rows[:, 0].max():
        warn(
            f"link_tracklets: frames holds {len(frames)} frames, the rows reach frame "
            f"{int(rows[:, 0].max())}: fragment ends after frame {len(frames)} are linked "
            "without the colour term",
            stacklevel=2,
        )
    per_id = split_tracks(rows)
    ids, i, j, cost = link_costs(per_id, config, frames)
    nxt = {ids[a]: ids[b] for a, b in _assign(i, j, cost)}
    if not nxt:
        return rows, {}
    has_prev = set(nxt.values())
    mapping: dict[int, int] = {}
    for head in ids:
        if head in has_prev:
            continue
        cur = head
        while cur in nxt:
            cur = nxt[cur]
            mapping[cur] = head
    old = np.array(list(mapping), dtype=np.float64)
    order = np.argsort(old)
    new = np.array(list(mapping.values()), dtype=np.float64)[order]
    at = np.minimum(np.searchsorted(old[order], rows[:, 1]), len(old) - 1)
    hit = old[order][at] == rows[:, 1]  # each id at once: a head is never relabelled
    rows[hit, 1] = new[at[hit]]
    return rows, mapping


def check_rows(rows: ArrayLike, what: str, name: str = "rows") -> F64:
    """The rows as an ``(M, 10)`` float64 array, checked; ValueError/TypeError naming the problem.

    Their layout first, as every function taking rows checks it (:func:`pftrack._check.
    mot_rows`): ``(M, 6..10)``, the missing columns as a file's (conf 1, x, y, z -1), and any
    array without values (``[]``) no rows; then the values.
    Frames must be integers in ``1..MAX_FRAME``, ids integers with ``|id| <= MAX_ID``, every
    value finite, and the boxes what :func:`pftrack.io.mot.read_mot` reads (:func:`check_boxes`:
    no negative width or height, no value beyond ±1e9 px). `what` names the caller in messages,
    `name` the argument whose layout or type is wrong (``link_tracklets``' ``tracks``).
    """
    a = mot_rows(rows, what, name)
    f, i = a[:, 0], a[:, 1]
    finite = np.isfinite(a)
    if not finite.all():
        r, c = np.argwhere(~finite)[0]
        names = ("frame", "id", "left", "top", "width", "height", "conf", "x", "y", "z")
        raise ValueError(f"{what}: row {r} has a non-finite {names[c]} ({a[r, c]}): NaN or inf")
    bad = (f < 1) | (f > MAX_FRAME) | (f != np.floor(f))
    if bad.any():
        r = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"{what}: row {r} has frame {exactly(f[r])}, not an integer in 1..{MAX_FRAME} "
            f"{frames_from_1(f[r])}"
        )
    k = first_bad_id(i)
    if k is not None:
        raise ValueError(f"{what}: {bad_id_message(i[k])}")
    check_boxes(a[:, 2:6], a, what)
    return a


def check_boxes(boxes: F64, rows: F64, what: str, name: str = "") -> None:
    """Refuse the boxes a MOTChallenge file may not hold, as :func:`pftrack.io.mot.read_mot` does.

    Parameters
    ----------
    boxes : (M, 4) ndarray
        ``left, top, width, height`` per row; the rule is :func:`pftrack._check.first_bad_box`'s
        (no negative width or height, 0 allowed; no value beyond ±1e9 px).
    rows : (M, 10) ndarray
        The rows the boxes belong to, whose frame and id the message names.
    what, name : str
        The caller and, for boxes other than the rows' own, the argument (``"measurements"``).

    Raises
    ------
    ValueError
        ``what: [name ]row R (frame F, id I) has width -5: negative box width or height``.
    """
    bad = first_bad_box(boxes)
    if bad is not None:
        r, c, problem = bad
        raise ValueError(
            f"{what}: {name + ' ' if name else ''}row {r} (frame {rows[r, 0]:g}, id "
            f"{rows[r, 1]:g}) has {BOX_VALUES[c]} {boxes[r, c]:g}: {problem}"
        )


def check_file_ids(rows: F64, path: PathLike) -> None:
    """Refuse rows read from file `path` whose ids are not integers: ``FILE:LINE: track id ...``.

    :func:`check_rows`' test of the ids (:func:`pftrack._check.first_bad_id`), named by the
    file's line, which is quoted (an id past 2**53 is read as another number): what ``pftrack
    recover``, ``smooth``, ``experiment gaps`` and ``eval`` read.
    """
    from pftrack.io.mot import data_line

    k = first_bad_id(rows[:, 1])
    if k is not None:
        lineno, text = data_line(path, k)
        raise ValueError(f"{path}:{lineno}: {bad_id_message(rows[k, 1])}: {text[:80]!r}")


def check_scored_ids(rows: F64, path: PathLike) -> None:
    """Refuse the ids of a file to score: not integers, or below -1 (``FILE:LINE: ...``).

    :func:`check_file_ids`, then :func:`check_negative_ids` named by the file's line: what
    ``pftrack eval`` and ``pftrack batch`` check of the files they score (id -1 is the
    scorers' to refuse, with its hint of a detections file).
    """
    from pftrack.io.mot import data_line_numbers

    check_file_ids(rows, path)
    if np.any(rows[:, 1] < -1):
        check_negative_ids(rows, data_line_numbers(path), path)


def check_unique(
    rows: ArrayLike,
    line_numbers: Iterable[int] | None = None,
    path: PathLike | None = None,
    *,
    who: str | None = None,
) -> None:
    """Raise ValueError naming the first duplicate (frame, id) pair (and its lines if known).

    With `line_numbers` (the file's line of each row) and `path`, the message starts with
    ``FILE:LINE:`` (the pair's second line) and names both lines; else with ``WHO:`` when
    `who` (the function checking) is given. When every id is -1 (a MOTChallenge detection
    file: untracked boxes), it says so: tracks are needed.
    """
    rows = mot_rows(rows, who or "check_unique")
    if len(rows) == 0:
        return
    key = rows[:, 0].astype(np.int64) * (1 << 32) + rows[:, 1].astype(np.int64)
    order = np.argsort(key, kind="stable")
    dup = np.flatnonzero(np.diff(key[order]) == 0)
    if len(dup):
        i, j = order[dup[0]], order[dup[0] + 1]
        where = ""
        head = "" if who is None else f"{who}: "
        if line_numbers is not None:
            ln = list(line_numbers)
            where = f" (lines {ln[i]} and {ln[j]})"
            head = head if path is None else f"{path}:{ln[j]}: "
        hint = ""
        if np.all(rows[:, 1] == -1):  # was: only the duplicate, for a whole det.txt
            hint = (
                "; every id is -1: this looks like untracked detections (a det.txt), not "
                "tracks (pftrack track SOURCE --detections FILE makes tracks of them)"
            )
        raise ValueError(
            f"{head}duplicate rows for frame {int(rows[i, 0])}, id {int(rows[i, 1])}{where}: "
            f"each (frame, id) may appear once{hint}"
        )


def check_tracked(
    rows: F64,
    line_numbers: Iterable[int] | None = None,
    path: PathLike | None = None,
    *,
    who: str | None = None,
) -> None:
    """Refuse rows of id -1, then of other negative ids (ValueError naming the first row).

    Id -1 is MOTChallenge's id of a box no track holds (a detection file's every row, the
    unassociated boxes some trackers write beside their tracks): taken as one track, its rows
    had their holes filled, their boxes smoothed and linked to other tracks, each across
    unrelated objects. As ``pftrack eval`` refuses them (TrackEval cannot score them). Other
    negative ids are refused next (:func:`check_negative_ids`). With `line_numbers` and `path`
    the message starts with ``FILE:LINE:``; else with ``WHO:``. `rows` are checked (M, 10) rows.
    """
    loose = rows[:, 1] == -1
    if not loose.any():
        check_negative_ids(rows, line_numbers, path, who=who)
        return
    k, n = int(np.argmax(loose)), int(loose.sum())
    frame, many = int(rows[k, 0]), f"{counted(n, 'row')} {'has' if n == 1 else 'have'} it"
    if line_numbers is not None and path is not None:
        head = f"{path}:{list(line_numbers)[k]}: id -1 in frame {frame} ({many})"
    else:
        head = f"{who or 'check_tracked'}: row {k} has id -1 (frame {frame}; {many})"
    raise ValueError(
        f"{head}: -1 is MOTChallenge's id of a box no track holds (an unassociated detection), "
        "not a track; drop those rows, or make tracks of them (pftrack track SOURCE "
        "--detections FILE)"
    )


def check_negative_ids(
    rows: F64,
    line_numbers: Iterable[int] | None = None,
    path: PathLike | None = None,
    *,
    who: str | None = None,
) -> None:
    """Refuse ids below -1 (ValueError naming the first, its frame and how many rows have it).

    ``pftrack eval`` refuses a negative id, on which TrackEval fails (an IndexError, or "the
    same ID more than once" of another id): a track of id -5 was filled, smoothed and linked
    by ``recover`` and ``smooth``, then could not be scored. Id -1 is :func:`check_tracked`'s.
    With `line_numbers` and `path` the message starts with ``FILE:LINE:``; else with
    ``WHO:``. `rows` are checked (M, 10) rows.
    """
    negative = rows[:, 1] < -1
    if not negative.any():
        return
    k = int(np.argmax(negative))
    bad = rows[k, 1]
    n = int(np.sum(rows[:, 1] == bad))
    frame, many = int(rows[k, 0]), f"{counted(n, 'row')} {'has' if n == 1 else 'have'} it"
    if line_numbers is not None and path is not None:
        head = f"{path}:{list(line_numbers)[k]}: id {bad:.0f} in frame {frame} ({many})"
    else:
        head = f"{who or 'check_negative_ids'}: row {k} has id {bad:.0f} (frame {frame}; {many})"
    raise ValueError(
        f"{head}: track ids must be >= 0, as pftrack eval and TrackEval require them (-1 alone "
        "has a meaning: a box no track holds); renumber the tracks"
    )


def read_tracks(path: PathLike, what: str = "tracks file", *, tracks_only: bool = True) -> F64:
    """Read a tracks file whose ids are integers and (frame, id) pairs unique (errors name lines).

    :func:`pftrack.io.mot.read_mot` (`what` names the file in its errors), the ids' check
    (``FILE:LINE``), then :func:`check_unique` (``FILE:LINE: duplicate rows ...``); the file
    is read a second time, for its line numbers, only when a pair repeats. Rows of id -1
    (unassociated boxes) and of other negative ids are refused by :func:`check_tracked`
    unless `tracks_only` is False
    (``pftrack render`` draws them). What ``pftrack
    recover`` and ``pftrack smooth`` read, one file or many, and ``pftrack experiment gaps``
    its ground truth (``what="ground truth"``). Lines of more than 10 columns give one
    UserWarning naming the file: columns past 10 are not kept.
    """
    from pftrack.io.mot import data_line_numbers, read_mot

    rows = read_mot(path, what=what, warn_extra=True)  # columns past 10 are not written back
    check_file_ids(rows, path)  # check_rows' test, with the file's line, as read_mot's own
    try:
        check_unique(rows)
    except ValueError:
        check_unique(rows, data_line_numbers(path), path)
    if tracks_only and np.any(rows[:, 1] < 0):
        check_tracked(rows, data_line_numbers(path), path)
    _warn_padded_flags(rows, path)
    _warn_normalised(rows, path)
    return rows


def _warn_normalised(rows: F64, path: PathLike) -> None:
    """Warn when every box of a file ends within 2 x 2 units: normalised coordinates.

    pftrack works in pixels: the linking gate (50 px) would span 50 frames' widths, and the
    filled and smoothed boxes are written with 2 decimals (``pftrack.io.mot``), 6 % of a
    width of 0.08 (was: silent; the tracker's API warns alike of a detector's normalised boxes).
    :data:`pftrack._check.NORMALISED_REACH`: boxes may reach a little past the frame.
    """
    if not len(rows):
        return
    right, bottom = np.max(rows[:, 2] + rows[:, 4]), np.max(rows[:, 3] + rows[:, 5])
    if max(right, bottom) <= NORMALISED_REACH:
        warn(
            f"{path}: every box lies within {right:.3g} x {bottom:.3g} (its rightmost and lowest "
            "edges): normalised coordinates? pftrack works in pixels (its linking gate, boxes "
            "written with 2 decimals): give pixels (x times the image width, y times its height)",
            stacklevel=3,
        )


def _warn_padded_flags(rows: F64, path: PathLike) -> None:
    """Warn when a file's missing columns, padded with -1, make its rows look filled.

    An 8- or 9-column file whose column 8 is 1 (a class, as MOT17's ground truth has) reads
    as ``1, -1, -1``: pftrack's mark of a filled row, so the output's filled rows could not be
    told from those by the flag.
    """
    from pftrack.io.mot import first_row_fields

    n = int(filled_mask(rows).sum()) if len(rows) else 0
    fields = first_row_fields(path) if n else 10
    if n and fields < 10:
        warn(
            f"{path}: {n} row(s) have 1 in column 8 and {fields} columns (the missing ones "
            "padded with -1): they carry pftrack's mark of a filled row (column 8 = 1, columns "
            "9-10 = -1), so in the output the filled rows cannot be told from them by that mark",
            stacklevel=3,
        )
