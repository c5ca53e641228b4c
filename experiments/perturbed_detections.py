"""pftrack, SORT and ByteTrack on perturbed copies of the five sequences' public detections.

Issue 13's held-out goal is a sequence kept from us, with its own detector. These copies model
what such a sequence may differ in; they were written down (this docstring, committed) before
any of them was run. Each copy changes the public ``det.txt`` of PETS09-S2L1, TUD-Campus,
ADL-Rundle-6, ETH-Sunnyday and KITTI-17 (the last three on black frames of their size, as in
`experiments.public_detections`), seeded by ``--seed`` (default 0), the sequence and the copy:

``original``
    The boxes as they are.
``miss-random``
    20 % of the boxes left out, each on its own.
``miss-bursts``
    20 % of each person's boxes left out in bursts: each box matched to the truth (IoU >= 0.5,
    Hungarian) follows its truth id's two-state chain, a burst lasting 5 frames on average
    (stay missed 0.8, start a burst 0.05, so 20 % of the frames are missed); boxes on no truth
    are left out with probability 0.2 each.
``jitter``
    Each box's centre moved by a normal draw of 5 % of its width (x) and height (y), its width
    and height scaled by ``exp`` of a normal draw of 0.05 each.
``false-low``
    10 % false boxes added (Poisson, 0.1 times the frame's boxes on average): the size of one of
    the sequence's boxes drawn at random, anywhere in the frame, scored uniformly between the
    sequence's 5th and 50th score percentiles (low, but inside the detector's range).
``rescored``
    Every score ``s`` becomes ``s ** 8`` (the ranking kept, the scale another detector's: the
    median 0.98 becomes 0.85, 0.9 becomes 0.43, 0.5 becomes 0.004).
``half-rate``
    Every second frame (frames 1, 3, 5, ... renumbered 1, 2, 3, ...), frames, boxes and truth
    alike: a 30 fps sequence delivered at 15. ByteTrack is told the halved frame rate.
``walking``
    A hand-held camera on a still one: frames, boxes and truth shifted by ``dx = 0.08 W
    sin(2 pi t / (6 fps))`` and ``dy = 0.015 H sin(2 pi t / fps)`` (``t`` the frame index, a
    6-second sway and a step's bob), the frames moved with a black border; boxes cut by the
    frame are clipped to it, and dropped if less than half of them is left in view. ETH-Sunnyday
    and KITTI-17 are already moving cameras; they get the shift on top.

Every tracker sees the same boxes. pftrack runs as `experiments.public_detections` runs it
(`track_frames`, default settings, tracker seed 0, the offline pass); SORT (``sort-track``,
Bewley's defaults) and ByteTrack (``supervision < 0.27``, documented defaults) as
`experiments.compare_trackers` does, their online rows scored. A peer that is not installed
is skipped with a note (README "Peers"). Scores: `pftrack.eval.evaluate_sequence` (TrackEval's
MOTA, IDF1 and HOTA), one row per copy, sequence and tracker, then each copy's mean over the
five sequences and the mean over the perturbed copies (every copy but ``original``).

Usage (from the repository root)::

    python -m experiments.perturbed_detections [--data ../shared/data] [--out DIR]
        [--copies original jitter ...] [--trackers pftrack sort bytetrack] [--seed 0]
        [--set SECTION.FIELD=VALUE ...]
"""

from __future__ import annotations

import contextlib
import io
import math
import warnings
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment

from experiments._common import data_root, experiment_parser, tee_stdout, write_text
from experiments.compare_trackers import SEQUENCES, make_bytetrack, make_sort, online_rows
from experiments.compare_trackers import Sequence as PeerSequence
from experiments.public_detections import (
    add_settings,
    black_frames,
    blank_frames_expected,
    settings_config,
)
from pftrack._typing import F64
from pftrack.eval import SequenceScores, evaluate_sequence
from pftrack.io.mot import as_written, group_by_frame, read_mot
from pftrack.io.video import FrameSource
from pftrack.tracking import TrackerConfig, track_frames

COPIES = (
    "original",
    "miss-random",
    "miss-bursts",
    "jitter",
    "false-low",
    "rescored",
    "half-rate",
    "walking",
)
TRACKERS = ("pftrack", "sort", "bytetrack")
NAMES = ("pets09-s2l1", "tud-campus", "ADL-Rundle-6", "ETH-Sunnyday", "KITTI-17")

Frame = NDArray[np.uint8]
Dets = dict[int, F64]  # {frame: (k, 5) left, top, w, h, score}, video pixels


@dataclass
class Copy:
    """One perturbed copy of a sequence: its frames (lazy), boxes and truth, ready to track."""

    frames: Sequence[Frame]
    dets: Dets
    gt: F64  # in the truth file's pixels: times `scale` in the video's
    scale: float
    fps: float
    size: tuple[int, int]  # width, height


class MappedFrames(Sequence[Frame]):
    """The frames of `frames` whose 1-based index is in `keep`, each through ``fn(new_index,
    frame)``, read in order as they are iterated (a video is not held in memory)."""

    def __init__(
        self,
        frames: Iterable[Frame],
        keep: Sequence[int],
        fn: Callable[[int, Frame], Frame] | None = None,
    ) -> None:
        self._frames = frames
        self._keep = list(keep)
        self._fn = fn

    def __len__(self) -> int:
        return len(self._keep)

    def __getitem__(self, i: int) -> Frame:  # type: ignore[override]
        raise TypeError("these frames are read in order, not by index")

    def __iter__(self) -> Iterator[Frame]:
        wanted = set(self._keep)
        new = 0
        for f, frame in enumerate(self._frames, start=1):
            if f in wanted:
                new += 1
                yield frame if self._fn is None else self._fn(new, frame)
            if new == len(self._keep):
                return


def iou_matrix(a: F64, b: F64) -> F64:
    """IoU of every box of `a` with every box of `b` (``[left, top, w, h, ...]`` rows)."""
    ax1, ay1 = a[:, 0:1], a[:, 1:2]
    ax2, ay2 = ax1 + a[:, 2:3], ay1 + a[:, 3:4]
    bx1, by1 = b[:, 0], b[:, 1]
    bx2, by2 = bx1 + b[:, 2], by1 + b[:, 3]
    iw = np.clip(np.minimum(ax2, bx2) - np.maximum(ax1, bx1), 0, None)
    ih = np.clip(np.minimum(ay2, by2) - np.maximum(ay1, by1), 0, None)
    inter = iw * ih
    union = a[:, 2:3] * a[:, 3:4] + b[:, 2] * b[:, 3] - inter
    return np.asarray(inter / np.maximum(union, 1e-9), np.float64)


def truth_ids(dets: Dets, gt: F64, scale: float) -> dict[int, NDArray[np.int64]]:
    """Each frame's boxes' truth ids (Hungarian at IoU >= 0.5; -1 for a box on no truth)."""
    by_frame = group_by_frame(gt)
    out = {}
    for f, d in dets.items():
        ids = np.full(len(d), -1, np.int64)
        g = by_frame.get(f)
        if g is not None and len(d):
            boxes = g[:, 2:6] * scale
            iou = iou_matrix(d, boxes)
            r, c = linear_sum_assignment(-iou)
            ok = iou[r, c] >= 0.5
            ids[r[ok]] = g[c[ok], 1].astype(np.int64)
        out[f] = ids
    return out


def miss_random(dets: Dets, rng: np.random.Generator) -> Dets:
    """20 % of the boxes left out, each on its own."""
    return {f: d[rng.random(len(d)) >= 0.2] for f, d in dets.items()}


def miss_bursts(dets: Dets, gt: F64, scale: float, rng: np.random.Generator) -> Dets:
    """20 % of each truth id's boxes left out in bursts of 5 frames on average (the docstring)."""
    ids = truth_ids(dets, gt, scale)
    missed: dict[int, bool] = {}
    out = {}
    for f in sorted(dets):
        # every truth id's chain steps once a frame, whether or not it has a box
        for k in np.unique(group_by_frame(gt).get(f, np.zeros((0, 10)))[:, 1]).astype(int):
            was = missed.get(int(k), False)
            missed[int(k)] = bool(rng.random() < (0.8 if was else 0.05))
        d = dets[f]
        keep = np.array(
            [not missed.get(int(k), False) if k >= 0 else rng.random() >= 0.2 for k in ids[f]],
            bool,
        )
        out[f] = d[keep] if len(d) else d
    return out


def jitter(dets: Dets, rng: np.random.Generator) -> Dets:
    """Centres moved by 5 % of the size, widths and heights scaled by ``exp(N(0, 0.05))``."""
    out = {}
    for f, d in dets.items():
        d = d.copy()
        n = len(d)
        cx = d[:, 0] + d[:, 2] / 2 + rng.normal(0.0, 0.05, n) * d[:, 2]
        cy = d[:, 1] + d[:, 3] / 2 + rng.normal(0.0, 0.05, n) * d[:, 3]
        d[:, 2] *= np.exp(rng.normal(0.0, 0.05, n))
        d[:, 3] *= np.exp(rng.normal(0.0, 0.05, n))
        d[:, 0], d[:, 1] = cx - d[:, 2] / 2, cy - d[:, 3] / 2
        out[f] = d
    return out


def false_low(dets: Dets, size: tuple[int, int], rng: np.random.Generator) -> Dets:
    """10 % false boxes (Poisson), sized as a random box of the sequence, scored low."""
    every = np.concatenate([d for d in dets.values() if len(d)])
    lo, hi = np.percentile(every[:, 4], [5, 50])
    w, h = size
    out = {}
    for f, d in dets.items():
        k = int(rng.poisson(0.1 * len(d)))
        if k == 0:
            out[f] = d
            continue
        wh = every[rng.integers(0, len(every), k), 2:4]
        left = rng.uniform(0, 1, k) * np.maximum(w - wh[:, 0], 1)
        top = rng.uniform(0, 1, k) * np.maximum(h - wh[:, 1], 1)
        false = np.column_stack([left, top, wh, rng.uniform(lo, hi, k)])
        out[f] = np.vstack([d, false])
    return out


def rescored(dets: Dets) -> Dets:
    """Every score ``s`` becomes ``s ** 8``."""
    return {f: np.column_stack([d[:, :4], d[:, 4] ** 8]) for f, d in dets.items()}


def walking_shift(t: int, fps: float, size: tuple[int, int]) -> tuple[float, float]:
    """The hand-held camera's shift of frame `t` (1-based), in video pixels."""
    w, h = size
    return (
        0.08 * w * math.sin(2 * math.pi * t / (6 * fps)),
        0.015 * h * math.sin(2 * math.pi * t / fps),
    )


def walking(c: Copy) -> Copy:
    """`c` seen by a walking camera: frames, boxes and truth shifted (the docstring)."""
    w, h = c.size

    def shift_frame(t: int, frame: Frame) -> Frame:
        dx, dy = walking_shift(t, c.fps, c.size)
        m = np.array([[1.0, 0.0, dx], [0.0, 1.0, dy]])
        return np.asarray(cv2.warpAffine(frame, m, (frame.shape[1], frame.shape[0])), np.uint8)

    dets = {}
    for f, d in c.dets.items():
        dx, dy = walking_shift(f, c.fps, c.size)
        x1, y1 = d[:, 0] + dx, d[:, 1] + dy
        x2, y2 = x1 + d[:, 2], y1 + d[:, 3]
        cx1, cy1 = np.clip(x1, 0, w), np.clip(y1, 0, h)
        cx2, cy2 = np.clip(x2, 0, w), np.clip(y2, 0, h)
        seen = (cx2 - cx1) * (cy2 - cy1) >= 0.5 * d[:, 2] * d[:, 3]
        dets[f] = np.column_stack([cx1, cy1, cx2 - cx1, cy2 - cy1, d[:, 4]])[seen]
    gt = c.gt.copy()
    for i, f in enumerate(gt[:, 0].astype(int)):
        dx, dy = walking_shift(f, c.fps, c.size)
        gt[i, 2] += dx / c.scale
        gt[i, 3] += dy / c.scale
    frames = MappedFrames(c.frames, range(1, len(c.frames) + 1), shift_frame)
    return Copy(frames, dets, gt, c.scale, c.fps, c.size)


def half_rate(c: Copy) -> Copy:
    """Frames 1, 3, 5, ... of `c`, renumbered 1, 2, 3, ...; ByteTrack's frame rate halved."""
    keep = range(1, len(c.frames) + 1, 2)
    dets = {(f + 1) // 2: d for f, d in c.dets.items() if f % 2 == 1}
    gt = c.gt[c.gt[:, 0].astype(int) % 2 == 1].copy()
    gt[:, 0] = (gt[:, 0] + 1) // 2
    return Copy(MappedFrames(c.frames, keep), dets, gt, c.scale, c.fps / 2, c.size)


def load_sequence(data: Path, name: str) -> Copy:
    """The sequence `name` as it is: lazily read frames (black without video), boxes, truth."""
    seq = SEQUENCES[name]
    folder = data / (seq.folder or name)
    gt = read_mot(folder / "gt.txt", what="ground truth")
    frames: Sequence[Frame]
    if seq.video is None:
        frames = black_frames(folder)
    else:
        n = len(FrameSource(folder / seq.video))
        frames = MappedFrames(_Reopen(folder / seq.video), range(1, n + 1))
    first = next(iter(frames))
    size = (first.shape[1], first.shape[0])
    det = read_mot(folder / "det.txt", what="detection file")
    by_frame = group_by_frame(det)
    dets = {
        f: np.column_stack([r[:, 2:6] * seq.scale, r[:, 6]]).astype(np.float64)
        for f, r in by_frame.items()
    }
    for f in range(1, len(frames) + 1):
        dets.setdefault(f, np.zeros((0, 5)))
    return Copy(frames, dets, gt, seq.scale, seq.fps, size)


class _Reopen(Iterable[Frame]):
    """A video opened anew each time it is iterated."""

    def __init__(self, path: Path) -> None:
        self._path = path

    def __iter__(self) -> Iterator[Frame]:
        return iter(FrameSource(self._path))


def make_copy(base: Copy, kind: str, rng: np.random.Generator) -> Copy:
    """The copy `kind` of `base` (one of :data:`COPIES`), drawn with `rng`."""
    c = Copy(base.frames, base.dets, base.gt, base.scale, base.fps, base.size)
    if kind == "miss-random":
        c.dets = miss_random(c.dets, rng)
    elif kind == "miss-bursts":
        c.dets = miss_bursts(c.dets, c.gt, c.scale, rng)
    elif kind == "jitter":
        c.dets = jitter(c.dets, rng)
    elif kind == "false-low":
        c.dets = false_low(c.dets, c.size, rng)
    elif kind == "rescored":
        c.dets = rescored(c.dets)
    elif kind == "half-rate":
        c = half_rate(c)
    elif kind == "walking":
        c = walking(c)
    elif kind != "original":
        raise ValueError(f"unknown copy {kind!r}")
    return c


def run_tracker(tracker: str, c: Copy, config: TrackerConfig, seed: int) -> F64:
    """The rows `tracker` gives a user for copy `c` (pftrack's after its offline pass)."""
    if tracker == "pftrack":
        dets = {f: d for f, d in c.dets.items() if len(d)}
        with blank_frames_expected():
            run = track_frames(c.frames, detections=dets, config=config, rng=seed)
        return as_written(run.rows)
    peer = PeerSequence(tracker, None, 1.0, c.fps)
    step = make_sort(peer) if tracker == "sort" else make_bytetrack(peer)
    n = len(c.frames)
    blank = np.zeros((1, 1, 3), np.uint8)  # the peers do not look at the frames
    boxes = [c.dets.get(f, np.zeros((0, 5))) for f in range(1, n + 1)]
    with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
        warnings.simplefilter("ignore")
        rows, _ = online_rows(step, [blank] * n, boxes)
    return rows


def line(copy: str, name: str, tracker: str, s: SequenceScores) -> str:
    """One row of the table (markdown): MOTA, IDF1, HOTA, FP, FN, IDSW."""
    m = s.mot
    return (
        f"| {copy} | {name} | {tracker} | {100 * m.mota:.1f} | {100 * m.idf1:.1f} "
        f"| {100 * s.hota.hota:.1f} | {m.false_positives} | {m.misses} | {m.num_switches} |"
    )


def main(argv: list[str] | None = None) -> int:
    p = experiment_parser("perturbed_detections", __doc__)
    p.add_argument("--copies", nargs="+", default=list(COPIES), choices=COPIES)
    p.add_argument("--trackers", nargs="+", default=list(TRACKERS), choices=TRACKERS)
    p.add_argument("--seq", nargs="+", default=list(NAMES), choices=NAMES)
    p.add_argument("--seed", type=int, default=0, help="seed of the copies (default: 0)")
    add_settings(p, "lifecycle.birth_overlap=0.3")
    args = p.parse_args(argv)
    if args.seed < 0:
        p.error(f"--seed is {args.seed}, expected a seed >= 0")
    config = settings_config(p, args.settings)
    data = data_root(args.data)
    trackers = list(args.trackers)
    notes = []
    for t, probe in (("sort", "sort.tracker"), ("bytetrack", "supervision")):
        if t in trackers:
            try:
                __import__(probe)
                if t == "bytetrack":
                    import supervision as sv

                    if not hasattr(sv, "ByteTrack"):
                        raise ImportError("supervision >= 0.27 has no ByteTrack")
            except ImportError as exc:
                trackers.remove(t)
                notes.append(f"{t}: skipped ({exc})")
    scores: dict[tuple[str, str], list[tuple[float, float, float]]] = {}
    head = "| copy | sequence | tracker | MOTA | IDF1 | HOTA | FP | FN | IDSW |\n" + (
        "|---" * 9 + "|"
    )
    lines = [head]
    with tee_stdout(args.out / "perturbed_detections.txt"):
        for n in notes:
            print(f"- {n}")
        print(head, flush=True)
        for name in args.seq:
            si = NAMES.index(name)  # the same draw whichever sequences are run
            base = load_sequence(data, name)
            for ci, kind in enumerate(COPIES):
                if kind not in args.copies:
                    continue
                c = make_copy(base, kind, np.random.default_rng([args.seed, si, ci]))
                for tracker in trackers:
                    rows = run_tracker(tracker, c, config, 0)
                    s = evaluate_sequence(c.gt, rows, scale=c.scale)
                    m = (100 * s.mot.mota, 100 * s.mot.idf1, 100 * s.hota.hota)
                    scores.setdefault((kind, tracker), []).append(m)
                    lines.append(line(kind, name, tracker, s))
                    print(lines[-1], flush=True)
        print()
        summary = [
            "| copy | tracker | mean MOTA | mean IDF1 | mean HOTA |",
            "|---|---|---|---|---|",
        ]
        for kind in [k for k in COPIES if k in args.copies] + ["perturbed"]:
            for tracker in trackers:
                if kind == "perturbed":
                    vals = [
                        v
                        for k in COPIES
                        if k != "original" and k in args.copies
                        for v in scores.get((k, tracker), [])
                    ]
                else:
                    vals = scores.get((kind, tracker), [])
                if not vals:
                    continue
                mean = np.mean(np.asarray(vals), axis=0)
                summary.append(
                    f"| {kind} | {tracker} | {mean[0]:.2f} | {mean[1]:.2f} | {mean[2]:.2f} |"
                )
        print("\n".join(summary))
    write_text(
        args.out / "perturbed_detections.md",
        "\n".join(lines) + "\n\n" + "\n".join(summary) + "\n" + "".join(f"\n- {n}" for n in notes),
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
