"""Tracking at a working resolution: accuracy and time at full size against ``max_side``.

`pftrack.TrackerConfig.max_side` scales frames whose longer side is larger down to it before
detection and tracking (boxes go back to the frame's pixels). This experiment measures what
that costs in accuracy, and saves in time, on sources larger than the sequences the defaults
were tuned on, all made here from the real data and from synthetic crowds:

``pets768``
    PETS09-S2L1 at the ground truth's own 768x576 (the 480x360 video upscaled, all 795
    frames); public detections unscaled.
``pets720``
    Its first 300 frames stretched to 1280x720 (as ``bench/test_pipeline.py``), ground truth
    and detections scaled to it.
``tud1280``
    TUD-Campus upscaled twice, 1280x960.
``crowd10``, ``crowd30``
    Synthetic 1280x720 crowds of 10 and 30 walkers (:func:`experiments.cost_per_object.
    make_crowd`, 150 frames), the walkers' true boxes as ground truth and, in ``public``
    mode, as detections.

Every source is written once as an MJPG video in the output folder and tracked from the file
by :func:`pftrack.tracking.track_frames` (built-in detector and given detections), seed by
seed, for each ``max_side`` (``full``: no scaling). Scores: `pftrack.eval.evaluate_sequence`
(TrackEval's HOTA, CLEAR-MOT and IDF1 at IoU 0.5). Time: the run's wall seconds.

Usage (from the repository root)::

    python -m experiments.working_resolution [--data ../shared/data] [--out DIR]
        [--seeds 0 1] [--sides full 640 960] [--sources pets768,pets720,...]
"""

from __future__ import annotations

import contextlib
import dataclasses
import itertools
from collections.abc import Iterable
from pathlib import Path

import cv2
import numpy as np
from numpy.typing import NDArray

from experiments._common import data_root, experiment_parser, tee_stdout
from experiments.cost_per_object import make_crowd
from pftrack._typing import F64
from pftrack.eval import evaluate_sequence
from pftrack.io.mot import as_written, group_by_frame, read_mot
from pftrack.io.opencv_io import opencv_name
from pftrack.io.video import FrameSource
from pftrack.tracking import TrackerConfig, track_frames

SOURCES = ("pets768", "pets720", "tud1280", "crowd10", "crowd30")


@dataclasses.dataclass(frozen=True)
class Made:
    """A source written to disk: its video, ground truth and detections in its pixels."""

    video: Path
    gt: F64
    dets: dict[int, F64]  # frame -> (k, 5) left, top, w, h, score


def _write(path: Path, frames: Iterable[NDArray[np.uint8]], fps: float = 25.0) -> None:
    """MJPG at quality 95 (`pftrack.io.video_writer.VideoWriter` writes .avi at OpenCV's
    default quality, which would blur the sources this experiment scales)."""
    writer: cv2.VideoWriter | None = None
    for f in frames:
        if writer is None:
            fourcc = cv2.VideoWriter.fourcc(*"MJPG")
            with opencv_name(path) as name:  # any name (pftrack.io.opencv_io)
                writer = cv2.VideoWriter(name, fourcc, fps, (f.shape[1], f.shape[0]))
            writer.set(cv2.VIDEOWRITER_PROP_QUALITY, 95)
        writer.write(f)
    if writer is not None:
        writer.release()


def _resized(video: Path, size: tuple[int, int], n: int | None) -> Iterable[NDArray[np.uint8]]:
    with contextlib.closing(iter(FrameSource(video))) as frames:
        for f in itertools.islice(frames, n):
            yield cv2.resize(f, size, interpolation=cv2.INTER_LINEAR)


def _scaled(rows: F64, sx: float, sy: float, last: int | None = None) -> F64:
    out = rows.copy()
    if last is not None:
        out = out[out[:, 0] <= last]
    out[:, [2, 4]] *= sx
    out[:, [3, 5]] *= sy
    return out


def _dets(rows: F64) -> dict[int, F64]:
    return {f: np.column_stack([r[:, 2:6], r[:, 6]]) for f, r in group_by_frame(rows).items()}


def make_source(name: str, data: Path, folder: Path) -> Made:
    """Write source `name` as ``folder/name.avi`` (once) and return it."""
    video = folder / f"{name}.avi"
    if name.startswith("pets"):
        seq = data / "pets09-s2l1"
        gt, det = read_mot(seq / "gt.txt"), read_mot(seq / "det.txt")
        size, n = ((768, 576), None) if name == "pets768" else ((1280, 720), 300)
        if not video.exists():
            _write(video, _resized(seq / "video.avi", size, n))
        sx, sy = size[0] / 768, size[1] / 576
        return Made(video, _scaled(gt, sx, sy, n), _dets(_scaled(det, sx, sy, n)))
    if name == "tud1280":
        seq = data / "tud-campus"
        gt, det = read_mot(seq / "gt.txt"), read_mot(seq / "det.txt")
        if not video.exists():
            _write(video, _resized(seq / "video.mp4", (1280, 960), None))
        return Made(video, _scaled(gt, 2.0, 2.0), _dets(_scaled(det, 2.0, 2.0)))
    walkers = int(name.removeprefix("crowd"))
    frames, boxes = make_crowd(walkers, 150, seed=walkers)
    if not video.exists():
        _write(video, frames)
    rows = []
    for k, b in enumerate(boxes, start=1):
        for i, (x1, y1, x2, y2, s) in enumerate(b):
            rows.append([k, i + 1, x1, y1, x2 - x1, y2 - y1, s, -1, -1, -1])
    gt = np.asarray(rows, np.float64)
    return Made(video, gt, _dets(gt))


def main(argv: list[str] | None = None) -> int:
    """Run the experiment; print one line per source, mode, side and seed."""
    parser = experiment_parser("working_resolution", __doc__)
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    parser.add_argument("--sides", nargs="+", default=["full", "640", "960"])
    parser.add_argument("--sources", default=",".join(SOURCES))
    args = parser.parse_args(argv)
    data = data_root(args.data)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    sides = [None if s == "full" else int(s) for s in args.sides]
    with tee_stdout(out / "working_resolution.txt"):
        print("source   mode     side   seed   MOTA   IDF1   HOTA  seconds")
        for name in args.sources.split(","):
            made = make_source(name, data, out)
            for mode in ("builtin", "public"):
                for side in sides:
                    for seed in args.seeds:
                        config = TrackerConfig(max_side=side)
                        run = track_frames(
                            made.video,
                            detections=made.dets if mode == "public" else None,
                            config=config,
                            rng=seed,
                            show_progress=False,
                        )
                        s = evaluate_sequence(made.gt, as_written(run.rows))
                        print(
                            f"{name:8s} {mode:8s} {side or 'full'!s:6s} {seed:4d} "
                            f"{100 * s.mot.mota:6.1f} {100 * s.mot.idf1:6.1f} "
                            f"{100 * s.hota.hota:6.1f} {run.seconds:8.2f}",
                            flush=True,
                        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
