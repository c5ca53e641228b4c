"""Compare pftrack with the trackers people use today, on the same detections, scored alike.

Peers (``pip install -e .[peers]``): supervision's ByteTrack
(supervision < 0.27, where ``sv.ByteTrack`` still lives), norfair, motpy, and SORT from the
``sort-track`` package (a packaging of Bewley's ``sort.py``; install it with ``--no-deps``,
its metadata pins an old SciPy). A peer that is not installed is skipped with a note.

Detector modes
--------------
public
    The sequence's ``det.txt`` (Faster R-CNN boxes published with SORT), PETS boxes scaled by
    0.625 onto the 480x360 video. pftrack gets the same boxes. ADL-Rundle-6, ETH-Sunnyday and
    KITTI-17 (``mot15-gt/``) ship without video: only this mode, and pftrack sees black frames
    of their size, where its colour filters and box refinement have nothing to use.
mog2
    OpenCV MOG2 background subtraction on the video (shadows off), opening + closing, connected
    components with a minimum area; every blob is a detection with score 1. pftrack runs its own
    detector instead (``detections=None``) and is listed as detector ``own``.

All results are scored by :func:`pftrack.eval.evaluate_mot` against the ground truth (scaled the
same way) with IoU 0.5; fps counts only the trackers' update calls (not decoding or detection).

Prints one table row per run as it finishes, then the whole table; the table and the notes on
skipped peers are also written to ``trackers.md`` in ``--out`` (default ``out/compare_trackers``).

Usage (from the repository root)::

    python -m experiments.compare_trackers [--data ../shared/data] [--seq pets09-s2l1 ...]
        [--detector public mog2] [--tracker sort bytetrack norfair motpy pftrack]
        [--smooth-peers] [--out out/compare_trackers]
"""

from __future__ import annotations

import contextlib
import io
import sys
import time
import warnings
from collections.abc import Callable, Iterable
from collections.abc import Sequence as SequenceOf
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple, TypeAlias

import cv2
import numpy as np
from numpy.typing import NDArray

from experiments._common import data_folder, experiment_parser, write_text
from experiments.public_detections import black_frames
from pftrack.eval import MotMetrics, evaluate_mot
from pftrack.io.mot import as_written, group_by_frame, read_mot
from pftrack.io.video import read_frames

Boxes: TypeAlias = NDArray[np.float64]  # (K, 5) left, top, w, h, score
Frame: TypeAlias = NDArray[np.uint8]  # (H, W, 3) BGR
Frames: TypeAlias = SequenceOf[Frame]  # a video's frames, or black_frames
Track: TypeAlias = tuple[int, float, float, float, float]  # id, left, top, w, h
Step: TypeAlias = Callable[[Frame, "Boxes | None"], list[Track]]
"""One tracker: (frame, detections or None) -> the tracks it reports for that frame."""


@dataclass(frozen=True)
class Sequence:
    name: str
    video: str | None  # None: no video ships (black frames of seqinfo.ini's size)
    scale: float  # ground truth / det.txt -> video pixels
    fps: float
    mog2_history: int = 500
    mog2_var_threshold: float = 100.0
    folder: str = ""  # below the data folder (default: the name)


SEQUENCES = {
    "pets09-s2l1": Sequence("pets09-s2l1", "video.avi", 0.625, 7.0),
    # 71 frames of people in view from frame 1: a short memory and a low threshold do best.
    "tud-campus": Sequence("tud-campus", "video.mp4", 1.0, 25.0, 100, 16.0),
    # MOT15 sequences without video: public detections only; pftrack sees black frames, where
    # its colour filters and box refinement have nothing to use (as experiments.public_detections)
    "ADL-Rundle-6": Sequence("ADL-Rundle-6", None, 1.0, 30.0, folder="mot15-gt/ADL-Rundle-6"),
    "ETH-Sunnyday": Sequence("ETH-Sunnyday", None, 1.0, 14.0, folder="mot15-gt/ETH-Sunnyday"),
    "KITTI-17": Sequence("KITTI-17", None, 1.0, 10.0, folder="mot15-gt/KITTI-17"),
}


class Loaded(NamedTuple):
    """One sequence of :data:`SEQUENCES` read from the data folder."""

    seq: Sequence
    folder: Path
    frames: Frames  # the video's, or black frames of seqinfo.ini's size
    gt: NDArray[np.float64]
    size: tuple[int, int]  # width, height


def load(root: Path, name: str) -> Loaded:
    """The sequence `name` under the data folder `root`: frames, ground truth and size."""
    seq = SEQUENCES[name]
    folder = root / (seq.folder or name)
    frames: Frames = black_frames(folder) if seq.video is None else read_frames(folder / seq.video)
    gt = read_mot(folder / "gt.txt", what="ground truth")
    return Loaded(seq, folder, frames, gt, (frames[0].shape[1], frames[0].shape[0]))


# ---- detectors -------------------------------------------------------------------------------


def public_detections(folder: Path, seq: Sequence, n_frames: int) -> list[Boxes]:
    det = read_mot(folder / "det.txt", what="detection file")
    by_frame = group_by_frame(det)
    out = []
    for f in range(1, n_frames + 1):
        d = by_frame.get(f, np.zeros((0, 10)))
        boxes = d[:, 2:6] * seq.scale
        out.append(np.c_[boxes, d[:, 6]])
    return out


def mog2_detections(
    frames: list[NDArray[np.uint8]], seq: Sequence, *, min_area_frac: float = 0.002
) -> list[Boxes]:
    """Foreground blobs: MOG2 (no shadows) -> open 3x3 -> close 7x21 (joins a person's body
    parts vertically) -> connected components of area >= min_area_frac of the image, not wider
    than twice their height."""
    h, w = frames[0].shape[:2]
    sub = cv2.createBackgroundSubtractorMOG2(
        history=seq.mog2_history, varThreshold=seq.mog2_var_threshold, detectShadows=False
    )
    k_open = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (3, 3))
    k_close = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (7, 21))
    min_area = min_area_frac * w * h
    out = []
    for frame in frames:
        fg = sub.apply(frame)
        _, fg = cv2.threshold(fg, 127, 255, cv2.THRESH_BINARY)
        fg = cv2.morphologyEx(fg, cv2.MORPH_OPEN, k_open)
        fg = cv2.morphologyEx(fg, cv2.MORPH_CLOSE, k_close)
        n, _, stats, _ = cv2.connectedComponentsWithStats(fg, connectivity=8)
        rows = [
            (float(x), float(y), float(bw), float(bh), 1.0)
            for x, y, bw, bh, area in stats[1:n]
            if area >= min_area and bh >= 0.5 * bw
        ]
        out.append(np.asarray(rows, dtype=np.float64).reshape(-1, 5))
    return out


# ---- trackers: each factory returns step(frame, boxes) -> [(id, left, top, w, h)] ------------


def make_sort(seq: Sequence) -> Step:
    # sort-track ships no type information; its defaults are Bewley's
    from sort.tracker import SortTracker  # type: ignore[import-untyped]

    trk = SortTracker(max_age=1, min_hits=3, iou_threshold=0.3)

    def step(frame: Frame, boxes: Boxes | None) -> list[Track]:
        d = (
            np.zeros((0, 6))
            if boxes is None or len(boxes) == 0
            else np.c_[
                boxes[:, 0],
                boxes[:, 1],
                boxes[:, 0] + boxes[:, 2],
                boxes[:, 1] + boxes[:, 3],
                boxes[:, 4],
                np.zeros(len(boxes)),
            ]
        )
        out = trk.update(d, None)
        return [(int(r[4]), r[0], r[1], r[2] - r[0], r[3] - r[1]) for r in out]

    return step


def make_bytetrack(seq: Sequence) -> Step:
    import supervision as sv

    if not hasattr(sv, "ByteTrack"):
        raise ImportError("supervision >= 0.27 has no ByteTrack: pip install 'supervision<0.27'")
    trk = sv.ByteTrack(frame_rate=int(round(seq.fps)))  # documented defaults otherwise

    def step(frame: Frame, boxes: Boxes | None) -> list[Track]:
        b = np.zeros((0, 5)) if boxes is None else boxes
        det = sv.Detections(
            xyxy=np.c_[b[:, 0], b[:, 1], b[:, 0] + b[:, 2], b[:, 1] + b[:, 3]].reshape(-1, 4),
            confidence=b[:, 4].copy(),
            class_id=np.zeros(len(b), dtype=int),
        )
        out = trk.update_with_detections(det)
        ids = out.tracker_id if out.tracker_id is not None else np.zeros(0, dtype=int)
        return [
            (int(t), x0, y0, x1 - x0, y1 - y0)
            for (x0, y0, x1, y1), t in zip(out.xyxy, ids, strict=True)
        ]

    return step


def make_norfair(seq: Sequence) -> Step:
    from norfair.tracker import Detection, Tracker

    # norfair's bounding-box demos: IoU distance, threshold 0.7; other settings default.
    trk = Tracker(distance_function="iou", distance_threshold=0.7)

    def step(frame: Frame, boxes: Boxes | None) -> list[Track]:
        dets = (
            []
            if boxes is None
            else [
                Detection(points=np.array([[x, y], [x + w, y + h]]), scores=np.array([s, s]))
                for x, y, w, h, s in boxes
            ]
        )
        objs = trk.update(detections=dets)
        out = []
        for o in objs:
            # the two corners are filtered apart: early in a track they may cross (a box of
            # negative width, which evaluate_mot refuses); a user takes the box they span
            (x0, x1), (y0, y1) = sorted(o.estimate[:, 0]), sorted(o.estimate[:, 1])
            out.append((int(o.id or 0), x0, y0, x1 - x0, y1 - y0))  # id is set once initialised
        return out

    return step


def make_motpy(seq: Sequence) -> Step:
    # motpy ships no type information
    from motpy import Detection, MultiObjectTracker  # type: ignore[import-untyped]

    trk = MultiObjectTracker(dt=1.0 / seq.fps)  # defaults: constant velocity, IoU matching
    ids: dict[str, int] = {}

    def step(frame: Frame, boxes: Boxes | None) -> list[Track]:
        dets = (
            []
            if boxes is None
            else [Detection(box=np.array([x, y, x + w, y + h]), score=s) for x, y, w, h, s in boxes]
        )
        trk.step(detections=dets)
        out = []
        for t in trk.active_tracks(min_steps_alive=3):
            k = ids.setdefault(t.id, len(ids) + 1)
            x0, y0, x1, y1 = t.box
            out.append((k, x0, y0, x1 - x0, y1 - y0))
        return out

    return step


class PftrackStep:
    """pftrack as ``pftrack track`` runs it: each frame, what ``Tracker.update`` returns; at the
    end (:meth:`result`), what the command writes.

    The public :class:`pftrack.Tracker` with the command's defaults and seed 0, primed as
    :func:`~pftrack.tracking.track_frames` primes it (:meth:`prime`): the built-in detector's
    background from 30 frames spread over the whole video, box refinement's from the first 30
    frames. Its :meth:`~pftrack.Tracker.finalize` links fragments and smooths each track over
    the whole run, so the rows are those ``pftrack track`` writes for the same video and
    detections; ``offline=False`` (``pftrack-online``, ``pftrack track --no-smooth --no-link``)
    keeps each frame's boxes as reported. :func:`run_one` scores :meth:`result`; a step's own
    returns are BoxMOT's online rows (confirmed tracks matched to a detection that frame).
    """

    def __init__(self, offline: bool = True) -> None:
        import pftrack

        self._trk = pftrack.Tracker(smooth=offline, link=offline)

    def __call__(self, frame: Frame, boxes: Boxes | None) -> list[Track]:
        if boxes is None:
            out = self._trk.update(None, frame)
        else:  # left, top, w, h, score -> x1, y1, x2, y2, score
            b = np.asarray(boxes, dtype=np.float64).reshape(-1, 5)
            xyxy = np.column_stack([b[:, :2], b[:, :2] + b[:, 2:4], b[:, 4]])
            out = self._trk.update(xyxy, frame)
        # (M, 8) x1, y1, x2, y2, id, conf, cls, det_ind
        return [(int(r[4]), r[0], r[1], r[2] - r[0], r[3] - r[1]) for r in out]

    def prime(self, frames: Frames, own: bool) -> None:
        """Start the background as ``pftrack track`` does (`own`: the built-in detector)."""
        from pftrack.detection.bootstrap import bootstrap_frames

        self._trk.prime(bootstrap_frames(frames, 30, "spread" if own else "first"))

    def result(self) -> NDArray[np.float64]:
        """Every row after the offline pass (``Tracker.finalize()``), with the values ``pftrack
        track`` writes (rounded to 2 decimals): ``pftrack eval`` of its file scores the same
        (was: the unrounded rows, 2 FP apart on PETS09, 83.0 against 82.9 MOTA)."""
        return as_written(self._trk.finalize())


def make_pftrack(seq: Sequence, offline: bool = True) -> Step:
    return PftrackStep(offline)


TRACKERS: dict[str, Callable[[Sequence], Step]] = {
    "sort": make_sort,
    "bytetrack": make_bytetrack,
    "norfair": make_norfair,
    "motpy": make_motpy,
    "pftrack": make_pftrack,
    "pftrack-online": lambda seq: make_pftrack(seq, offline=False),
}


# ---- running ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class Row:
    tracker: str
    sequence: str
    detector: str
    metrics: MotMetrics
    fps: float


def online_rows(
    step: Step, frames: Frames, dets: Iterable[Boxes | None]
) -> tuple[NDArray[np.float64], float]:
    """What `step` returned frame by frame (MOTChallenge rows), and its frames per second."""
    rows = []
    elapsed = 0.0
    for f, (frame, boxes) in enumerate(zip(frames, dets, strict=True), start=1):
        t0 = time.perf_counter()
        out = step(frame, boxes)
        elapsed += time.perf_counter() - t0
        rows += [(f, i, x, y, w, h, 1.0, -1.0, -1.0, -1.0) for i, x, y, w, h in out]
    res = np.asarray(rows, dtype=np.float64).reshape(-1, 10)
    return res, len(frames) / elapsed if elapsed > 0 else float("inf")


def run_one(
    step: Step, frames: Frames, dets: Iterable[Boxes | None]
) -> tuple[NDArray[np.float64], float]:
    """The rows a tracker gives a user: its online rows, pftrack's after its offline pass."""
    res, fps = online_rows(step, frames, dets)
    if isinstance(step, PftrackStep):  # writes its rows at the end
        res = step.result()
    return res, fps


def markdown(rows: list[Row]) -> str:
    head = (
        "| tracker | sequence | detector | MOTA | IDF1 | MOTP(IoU) | IDSW | Frag | FP | FN "
        "| MT | ML | GT | fps |"
    )
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        m = r.metrics
        lines.append(
            f"| {r.tracker} | {r.sequence} | {r.detector} "
            f"| {100 * m.mota:.1f} | {100 * m.idf1:.1f} "
            f"| {100 * m.motp_iou:.1f} | {m.num_switches} | {m.num_fragmentations} "
            f"| {m.false_positives} | {m.misses} | {m.mostly_tracked} | {m.mostly_lost} "
            f"| {m.num_unique_objects} | {r.fps:.0f} |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = experiment_parser("compare_trackers", __doc__)
    ap.add_argument("--seq", nargs="+", default=list(SEQUENCES), choices=list(SEQUENCES))
    ap.add_argument("--detector", nargs="+", default=["public", "mog2"], choices=["public", "mog2"])
    ap.add_argument("--tracker", nargs="+", default=list(TRACKERS), choices=list(TRACKERS))
    ap.add_argument(
        "--smooth-peers",
        action="store_true",
        help="also score every peer's output after pftrack's offline pass "
        "(pftrack.tracking.smooth_tracks: link, fill, smooth) as '<peer>+smooth'",
    )
    args = ap.parse_args(argv)

    root = data_folder(args.data)
    if root is None:
        return 2
    rows: list[Row] = []
    notes: list[str] = []
    for name in args.seq:
        seq, folder, frames, gt, size = load(root, name)
        for detector in args.detector:
            dets: list[Boxes] | None = None
            if detector == "mog2" and seq.video is None:
                notes.append(f"{name}: no video, so no mog2 detections")
                continue
            if detector == "public":
                dets = public_detections(folder, seq, len(frames))
            else:
                dets = mog2_detections(list(frames), seq)
            for tname in args.tracker:
                own = tname == "pftrack" and detector == "mog2"
                try:
                    step = TRACKERS[tname](seq)
                except ImportError as exc:
                    note = f"{tname}: skipped ({exc})"
                    if note not in notes:
                        notes.append(note)
                    continue
                feed: Iterable[Boxes | None] = [None] * len(frames) if own else dets
                if isinstance(step, PftrackStep):
                    step.prime(frames, own)
                with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
                    warnings.simplefilter("ignore")
                    res, fps = run_one(step, frames, feed)
                m = evaluate_mot(gt, res, scale=seq.scale, image_size=size)
                row = Row(tname, name, "own" if own else detector, m, fps)
                rows.append(row)
                print(markdown([row]).splitlines()[-1], flush=True)
                if args.smooth_peers and not tname.startswith("pftrack"):
                    from pftrack.tracking import smooth_tracks

                    m = evaluate_mot(gt, smooth_tracks(res), scale=seq.scale, image_size=size)
                    row = Row(f"{tname}+smooth", name, detector, m, fps)
                    rows.append(row)
                    print(markdown([row]).splitlines()[-1], flush=True)
    table = markdown(rows)
    print()
    print(table)
    for n in notes:
        print(f"- {n}")
    write_text(args.out / "trackers.md", table + "\n" + "".join(f"\n- {n}" for n in notes) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
