"""pftrack with given detections at lower frame rates and with a detector run on odd frames only.

Every sequence of `experiments.public_detections` (PETS09-S2L1 and TUD-Campus with their
videos; ADL-Rundle-6, ETH-Sunnyday and KITTI-17 of ``mot15-gt/`` on black frames; the
synthetic busy scenes ``present``, ``groups`` and ``overhead``) is tracked in four versions:

``full``
    As it is (`experiments.public_detections`' rows).
``half``, ``third``
    Every second (third) frame kept, from frame 1: video frames, ``det.txt`` and ``gt.txt``
    rows of frames 1, 3, 5, ... (1, 4, 7, ...) renumbered 1, 2, 3, ...: the same scene filmed at
    a half (third) of the frame rate. The synthetic scenes' detections are made from the kept
    truth (jittered, 10 % missed, a false box every other kept frame), as at full rate.
``odd``
    Every frame of the video, detections on the odd frames only (the ``half`` detections put
    back on frames 1, 3, 5, ...): a detector run every other frame, scored on every frame.

Each version is tracked with the drop-in mode (`pftrack.tracking.track_frames`, default
settings unless ``--set``) for each seed and scored with `pftrack.eval.evaluate_sequence`
(TrackEval's MOTA, IDF1 and HOTA at IoU 0.5). The table gives the mean over the seeds per
sequence and version, and a ``pooled`` row per version: the sequences scored together
(TrackEval's combination), mean over seeds.

Usage (from the repository root)::

    python -m experiments.frame_rate [--data ../shared/data] [--out DIR] [--seeds 0 1 2]
        [--versions full half third odd] [--sequences NAME ...] [--set SECTION.FIELD=VALUE]
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from experiments._common import (
    data_root,
    experiment_parser,
    no_video_folders,
    tee_stdout,
    video_folders,
)
from experiments.public_detections import (
    BlackFrames,
    add_settings,
    noisy_detections,
    settings_config,
)
from pftrack._typing import F64
from pftrack.eval import SequenceScores, evaluate_sequence
from pftrack.io.mot import as_written, read_mot
from pftrack.io.video import FrameSource, read_seqinfo
from pftrack.synthetic import BUSY_SCENES, make_busy_scene
from pftrack.tracking import load_detections, track_frames

VERSIONS = ("full", "half", "third", "odd")
STRIDE = {"full": 1, "half": 2, "third": 3, "odd": 2}


class Strided:
    """Every `stride`-th frame of `frames` from the first, read in order (decoded once)."""

    def __init__(self, frames: Iterable[NDArray[np.uint8]], n: int, stride: int) -> None:
        self._frames, self._n, self._stride = frames, n, stride

    def __len__(self) -> int:
        return (self._n + self._stride - 1) // self._stride

    def __iter__(self) -> Iterator[NDArray[np.uint8]]:
        return itertools.islice(iter(self._frames), 0, None, self._stride)


def keep_rows(rows: F64, stride: int) -> F64:
    """MOTChallenge rows of frames 1, 1 + stride, ... renumbered 1, 2, ..."""
    r = rows[(rows[:, 0].astype(np.int64) - 1) % stride == 0].copy()
    r[:, 0] = (r[:, 0].astype(np.int64) - 1) // stride + 1
    return r


def keep_dets(dets: dict[int, F64], stride: int) -> dict[int, F64]:
    """Detections ``{frame: rows}`` of frames 1, 1 + stride, ... renumbered 1, 2, ..."""
    return {(f - 1) // stride + 1: d for f, d in dets.items() if (f - 1) % stride == 0}


def spread_dets(dets: dict[int, F64], stride: int) -> dict[int, F64]:
    """The inverse of `keep_dets`: frame k's detections put back on frame 1 + (k - 1) stride."""
    return {1 + (f - 1) * stride: d for f, d in dets.items()}


#: A sequence: name, and for a version its frames, detections, truth and truth scale.
Case = tuple[Iterable[NDArray[np.uint8]], dict[int, F64], F64, float]


def sequences(data: Path) -> list[tuple[str, Callable[[str], Case]]]:
    """Every sequence found under `data` and the synthetic scenes, each as a maker of versions."""
    out: list[tuple[str, Callable[[str], Case]]] = []
    for src, folder in video_folders(data):

        def video(version: str, folder: Path = folder, scale: float = src.scale,
                  name: str = src.video) -> Case:  # fmt: skip
            k = STRIDE[version]
            source = FrameSource(folder / name)
            dets = keep_dets(load_detections(folder / "det.txt", scale), k)
            gt = read_mot(folder / "gt.txt")
            if version == "odd":
                return source, spread_dets(dets, k), gt, scale
            return Strided(source, len(source), k), dets, keep_rows(gt, k), scale

        out.append((src.name, video))
    for name, folder in no_video_folders(data):

        def black(version: str, folder: Path = folder) -> Case:
            info = read_seqinfo(folder)
            if info.length is None or info.width is None or info.height is None:
                raise ValueError(f"{folder}/seqinfo.ini: no seqLength/imWidth/imHeight")
            k = STRIDE[version]
            dets = keep_dets(load_detections(folder / "det.txt"), k)
            gt = read_mot(folder / "gt.txt")
            if version == "odd":
                frames = BlackFrames(info.length, info.width, info.height)
                return frames, spread_dets(dets, k), gt, 1.0
            n = (info.length + k - 1) // k
            return BlackFrames(n, info.width, info.height), dets, keep_rows(gt, k), 1.0

        out.append((name, black))
    for kind in BUSY_SCENES:

        def busy(version: str, kind: str = kind) -> Case:
            scene = make_busy_scene(kind, rng=0)
            h, w = scene.frames[0].shape[:2]
            k = STRIDE[version]
            truth = keep_rows(scene.truth, k)
            n = (len(scene.frames) + k - 1) // k
            dets = noisy_detections(truth, n, h, w)
            if version == "odd":
                return scene.frames, spread_dets(dets, k), scene.truth, 1.0
            return scene.frames[::k], dets, truth, 1.0

        out.append((kind, busy))
    return out


def main(argv: list[str] | None = None) -> int:
    p = experiment_parser("frame_rate", __doc__)
    p.add_argument(
        "--seeds", type=int, nargs="+", default=[0, 1, 2], metavar="SEED",
        help="tracker seeds, one run of every sequence and version each (default: 0 1 2)",
    )  # fmt: skip
    p.add_argument(
        "--versions", nargs="+", default=list(VERSIONS), choices=VERSIONS, metavar="VERSION",
        help="versions to run: full, half, third, odd (default: all four)",
    )  # fmt: skip
    p.add_argument(
        "--sequences", nargs="+", default=[], metavar="NAME",
        help="run only these sequences (default: every one found, and the synthetic scenes)",
    )  # fmt: skip
    add_settings(p, "lifecycle.min_hits=3")
    args = p.parse_args(argv)
    config = settings_config(p, args.settings)
    data = data_root(args.data)
    table: list[str] = []
    with tee_stdout(args.out / "frame_rate.txt"):
        settings = " ".join(args.settings) or "defaults"
        print(f"seeds {' '.join(map(str, args.seeds))}; settings: {settings}")
        pooled: dict[str, list[list[SequenceScores]]] = {
            v: [[] for _ in args.seeds] for v in args.versions
        }
        for name, make in sequences(data):
            if args.sequences and name not in args.sequences:
                continue
            for version in args.versions:
                frames, dets, gt, scale = make(version)
                scores = []
                for i, seed in enumerate(args.seeds):
                    run = track_frames(frames, detections=dets, config=config, rng=seed)
                    s = evaluate_sequence(gt, as_written(run.rows), scale=scale)
                    scores.append(s)
                    pooled[version][i].append(s)
                row = _row(f"{name} {version}", scores)
                table.append(row)
                print(row, flush=True)
        print()
        print(f"{'sequence version':26s}  MOTA   IDF1   HOTA  (mean over seeds)")
        for row in table:
            print(row)
        for version in args.versions:
            per_seed = [SequenceScores.combine(s) for s in pooled[version] if s]
            if per_seed:
                print(_row(f"pooled {version}", per_seed))
    return 0


def _row(label: str, scores: list[SequenceScores]) -> str:
    """MOTA, IDF1 and HOTA (percent), each the mean over `scores`."""
    mota = 100 * np.mean([s.mot.mota for s in scores])
    idf1 = 100 * np.mean([s.mot.idf1 for s in scores])
    hota = 100 * np.mean([s.hota.hota for s in scores])
    return f"{label:26s} {mota:5.1f}  {idf1:5.1f}  {hota:5.1f}"


if __name__ == "__main__":
    raise SystemExit(main())
