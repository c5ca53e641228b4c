"""pftrack with given detections on every sequence there is: MOTA, IDF1 and HOTA per sequence.

The drop-in mode (`pftrack.tracking.track_frames` with a ``det.txt``, as ``pftrack track
--detections``), seed 0, default settings, scored with `pftrack.eval.evaluate_sequence`
(TrackEval's HOTA, CLEAR-MOT and IDF1 at IoU 0.5):

``pets09-s2l1``, ``tud-campus``
    The video and its public ``det.txt`` (PETS boxes scaled by 0.625 onto the 480x360 video).
``ADL-Rundle-6``, ``ETH-Sunnyday``, ``KITTI-17`` (``mot15-gt/``)
    No video ships with them: the frames are black images of ``seqinfo.ini``'s size, so the
    colour likelihood and box refinement have nothing to use and what is measured is the rest
    of the tracker (association, motion, birth and death, the offline pass) on real detections.
``present``, ``groups``, ``overhead``
    The synthetic busy scenes of `pftrack.synthetic.make_busy_scene` with detections made from
    their truth, seeded: each box moved and resized by 5 % of its height, 10 % of the boxes
    missed, one false box every other frame.

Usage (from the repository root)::

    python -m experiments.public_detections [--data ../shared/data] [--out DIR]
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence

import numpy as np
from numpy.typing import NDArray

from experiments._common import data_root, experiment_parser, tee_stdout
from pftrack._typing import F64
from pftrack.eval import evaluate_sequence
from pftrack.io.mot import group_by_frame, read_mot
from pftrack.io.video import FrameSource, read_seqinfo
from pftrack.synthetic import BUSY_SCENES, make_busy_scene
from pftrack.tracking import TrackerConfig, load_detections, track_frames

VIDEOS = {"pets09-s2l1": ("video.avi", 0.625), "tud-campus": ("video.mp4", 1.0)}
NO_VIDEO = ("ADL-Rundle-6", "ETH-Sunnyday", "KITTI-17")


class BlackFrames(Sequence[NDArray[np.uint8]]):
    """`n` black BGR frames of one size, one array shared by all (nothing is decoded)."""

    def __init__(self, n: int, width: int, height: int) -> None:
        self._n = n
        self._frame = np.zeros((height, width, 3), np.uint8)
        self._frame.setflags(write=False)

    def __len__(self) -> int:
        return self._n

    def __getitem__(self, i: int) -> NDArray[np.uint8]:  # type: ignore[override]
        if not -self._n <= i < self._n:
            raise IndexError(i)
        return self._frame

    def __iter__(self) -> Iterator[NDArray[np.uint8]]:
        return (self._frame for _ in range(self._n))


def noisy_detections(
    truth: F64, n_frames: int, height: int, width: int, seed: int = 0
) -> dict[int, F64]:
    """Detections from truth rows: jittered, 10 % missed, a false box every other frame.

    Returns ``{frame: (k, 5) [left, top, w, h, score]}`` as `load_detections` does.
    """
    rng = np.random.default_rng(seed)
    by_frame = group_by_frame(truth)
    out: dict[int, F64] = {}
    for f in range(1, n_frames + 1):
        r = by_frame.get(f, np.zeros((0, 10)))
        r = r[rng.random(len(r)) >= 0.1]
        boxes = r[:, 2:6].copy()
        boxes += rng.normal(0.0, 0.05, boxes.shape) * boxes[:, 3:4]
        # kept inside the frame, as a detector's boxes are
        x1 = np.clip(boxes[:, 0], 0, width - 4)
        y1 = np.clip(boxes[:, 1], 0, height - 4)
        x2 = np.clip(boxes[:, 0] + boxes[:, 2], x1 + 4, width)
        y2 = np.clip(boxes[:, 1] + boxes[:, 3], y1 + 4, height)
        boxes = np.column_stack([x1, y1, x2 - x1, y2 - y1])
        if f % 2 == 0:
            h = rng.uniform(0.1, 0.3) * height
            false = [rng.uniform(0, width - h / 2), rng.uniform(0, height - h), h / 2, h]
            boxes = np.vstack([boxes, false])
        out[f] = np.column_stack([boxes, rng.uniform(0.5, 1.0, len(boxes))])
    return out


def score(name: str, gt: F64, rows: F64, scale: float = 1.0) -> str:
    s = evaluate_sequence(gt, rows, scale=scale)
    return (
        f"{name:13s} MOTA {100 * s.mot.mota:6.1f}  IDF1 {100 * s.mot.idf1:5.1f}  "
        f"HOTA {100 * s.hota.hota:5.1f}  IDsw {s.mot.num_switches:3d}"
    )


def main(argv: list[str] | None = None) -> int:
    p = experiment_parser("public_detections", __doc__)
    args = p.parse_args(argv)
    data = data_root(args.data)
    config = TrackerConfig()
    with tee_stdout(args.out / "public_detections.txt"):
        for name, (video, scale) in VIDEOS.items():
            folder = data / name
            if not folder.is_dir():
                print(f"{name}: not found under {data}, skipped")
                continue
            dets = load_detections(folder / "det.txt", scale)
            run = track_frames(FrameSource(folder / video), detections=dets, config=config, rng=0)
            print(score(name, read_mot(folder / "gt.txt"), run.rows, scale), flush=True)
        for name in NO_VIDEO:
            folder = data / "mot15-gt" / name
            if not folder.is_dir():
                print(f"{name}: not found under {data / 'mot15-gt'}, skipped")
                continue
            info = read_seqinfo(folder)
            if info.length is None or info.width is None or info.height is None:
                raise ValueError(f"{folder}/seqinfo.ini: no seqLength/imWidth/imHeight")
            frames = BlackFrames(info.length, info.width, info.height)
            dets = load_detections(folder / "det.txt")
            run = track_frames(frames, detections=dets, config=config, rng=0)
            print(score(name + " (black)", read_mot(folder / "gt.txt"), run.rows), flush=True)
        for kind in BUSY_SCENES:
            scene = make_busy_scene(kind, rng=0)
            h, w = scene.frames[0].shape[:2]
            dets = noisy_detections(scene.truth, len(scene.frames), h, w)
            run = track_frames(scene.frames, detections=dets, config=config, rng=0)
            print(score(kind, scene.truth, run.rows), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
