"""The built-in detector on real and synthetic busy scenes: detection quality and tracking.

For each sequence: per-frame precision / recall of the detector's boxes (a detection matches a
ground-truth box one-to-one, Hungarian on IoU, when IoU >= the threshold) and the detector's
milliseconds per frame; with ``--track``, also MOTA / IDF1 of the whole tracker fed by that
detector (`pftrack.tracking.track_frames`, seed 0), and the longest run of one track's boxes
on empty floor in seconds (issue 14's crowd-clip goal: none over 2 s; `empty_floor_runs`).
Sequences: ``pets`` (PETS09-S2L1, ground
truth scaled by 0.625 to the 480x360 video), ``tud`` (TUD-Campus), and the synthetic busy
scenes of `pftrack.synthetic.make_busy_scene` (``present``, ``groups``, ``overhead``), which
need no data. What is printed is also written to ``detection.txt`` in ``--out`` (default
``out/eval_detection``).

Usage (from the repository root)::

    python -m experiments.eval_detection [--data ../shared/data] [--detector paper|mog2|knn]
        [--sequences pets,tud,present,groups,overhead] [--bootstrap spread|first|none]
        [--track] [--out out/eval_detection] [key=value ...]
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from scipy.optimize import linear_sum_assignment

from experiments._common import PETS, TUD, data_root, experiment_parser, frame_truth, tee_stdout
from pftrack._typing import F64
from pftrack.boxes import iou_xywh
from pftrack.detection import PaperDetector, make_detector
from pftrack.detection.bootstrap import BOOTSTRAPS, bootstrap_frames
from pftrack.io.mot import as_written, group_by_frame
from pftrack.io.video import read_frames, read_seqinfo
from pftrack.synthetic import BUSY_SCENES, make_busy_scene

REAL = {"pets": PETS, "tud": TUD}


def n_matches(det: F64, gt: F64, thr: float) -> int:
    """Detections matched one-to-one (Hungarian on IoU) to ground-truth boxes with IoU >= `thr`."""
    if len(det) == 0 or len(gt) == 0:
        return 0
    iou = iou_xywh(det, gt)
    r, c = linear_sum_assignment(-iou)
    return int((iou[r, c] >= thr).sum())


def load_sequence(name: str, data: Path) -> tuple[list[np.ndarray], F64, float] | None:
    """Frames, ground truth (scaled to the frames' pixels) and frame rate of `name`; None if
    absent."""
    if name in BUSY_SCENES:
        scene = make_busy_scene(name, rng=0)
        return scene.frames, scene.truth, scene.fps
    src = REAL[name]
    seq = data / src.name
    if not (seq / src.video).is_file():
        return None
    gt = frame_truth(src, data)
    fps = read_seqinfo(seq).frame_rate
    if fps is None:
        raise ValueError(f"{seq}: seqinfo.ini has no frameRate")
    return read_frames(seq / src.video), gt, fps


def empty_floor_runs(rows: F64, gt: F64) -> tuple[int, int]:
    """The longest run of consecutive frames in which one track's box is on empty floor.

    Two readings of "empty floor" (issue 14's crowd-clip goal: no box on empty floor for more
    than 2 s): IoU <= 0.1 with every ground-truth box of the frame, and (stricter) at most 0.1
    of the box's area inside any one ground-truth box, which does not count a fragment of a
    person (a head box inside the person's box has a small IoU but lies on the person).

    Returns
    -------
    (int, int)
        The longest runs in frames, by IoU and by covered area.
    """
    gt_by = group_by_frame(gt)
    best = [0, 0]
    for tid in np.unique(rows[:, 1]):
        track = rows[rows[:, 1] == tid]
        track = track[np.argsort(track[:, 0], kind="stable")]
        run = [0, 0]
        prev = -1
        for row in track:
            frame = int(row[0])
            g = gt_by.get(frame)
            box = row[2:6]
            if g is None or len(g) == 0:
                empty = [True, True]
            else:
                gb = g[:, 2:6]
                lo = np.maximum(box[:2], gb[:, :2])
                hi = np.minimum(box[:2] + box[2:], gb[:, :2] + gb[:, 2:])
                inter = np.prod(np.clip(hi - lo, 0.0, None), axis=1)
                covered = inter.max() / max(box[2] * box[3], 1e-9)
                empty = [bool(iou_xywh(box[None], gb).max() <= 0.1), bool(covered <= 0.1)]
            for i in range(2):
                run[i] = (run[i] + 1 if frame == prev + 1 else 1) if empty[i] else 0
                best[i] = max(best[i], run[i])
            prev = frame
    return best[0], best[1]


def detection_scores(
    frames: list[np.ndarray], gt: F64, detector: object, bootstrap: str
) -> dict[str, float]:
    """Precision and recall at IoU 0.5 and 0.3, detections a frame, ms a frame."""
    if isinstance(detector, PaperDetector):
        primer = bootstrap_frames(frames, 30, bootstrap)
        if primer:
            detector.prime(primer)
    gt_by = group_by_frame(gt)
    tp = {0.5: 0, 0.3: 0}
    n_det = 0
    t_det = 0.0
    for n, frame in enumerate(frames, start=1):
        t0 = time.perf_counter()
        d = detector.detect(frame)  # type: ignore[attr-defined]
        t_det += time.perf_counter() - t0
        g = gt_by.get(n)
        gb = g[:, 2:6] if g is not None else np.zeros((0, 4))
        n_det += len(d.boxes)
        for thr in tp:
            tp[thr] += n_matches(d.boxes, gb, thr)
    out = {"det/frame": n_det / len(frames), "ms/frame": 1e3 * t_det / len(frames)}
    for thr, t in tp.items():
        out[f"P@{thr}"] = t / max(n_det, 1)
        out[f"R@{thr}"] = t / max(len(gt), 1)
    return out


def figure(
    frames: list[np.ndarray], gt: F64, frame_no: int, path: Path, tracked: F64 | None = None
) -> None:
    """Frame `frame_no` (1-based) before | after [| tracked]: the detector as it was (first 30
    frames primed, no ghost test, fixed person aspect), as it is now (spread bootstrap, ghost
    test, learnt person size, lost legs), and with `tracked` the rows `pftrack track` writes
    (after the offline pass: fragments inside a larger box left out, partly seen people
    completed). Ground truth green, boxes red. Written as JPEG."""
    import cv2

    from pftrack.io.opencv_io import write_image

    def draw(boxes: F64, label: str) -> np.ndarray:
        img = frames[frame_no - 1].copy()
        for row in gt[gt[:, 0] == frame_no]:
            x, y, w, h = row[2:6].astype(int)
            cv2.rectangle(img, (x, y), (x + w, y + h), (0, 220, 0), 2)
        for x, y, w, h in boxes.astype(int):
            cv2.rectangle(img, (x, y), (x + w, y + h), (0, 0, 255), 2)
        cv2.putText(img, label, (8, 24), cv2.FONT_HERSHEY_SIMPLEX, 0.8, (255, 255, 255), 2)
        return img

    panels = []
    setups = (
        ("first", {"ghost_support": 0.0, "learn_size": False, "leg_height": 0.0}, "before"),
        ("spread", {}, "after"),
    )
    for boot, cfg, label in setups:
        det = make_detector("paper", **cfg)
        det.prime(bootstrap_frames(frames, 30, boot))  # type: ignore[union-attr]
        for f in frames[:frame_no]:
            d = det.detect(f)
        panels.append(draw(d.boxes, label))
    if tracked is not None:
        panels.append(draw(tracked[tracked[:, 0] == frame_no, 2:6], "tracked"))
    out = np.hstack(panels)
    scale = 320 * len(panels) / out.shape[1]
    out = cv2.resize(out, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA)
    write_image(path, out, [cv2.IMWRITE_JPEG_QUALITY, 80])  # any name (pftrack.io.opencv_io)


def main(argv: Sequence[str] | None = None) -> int:
    p = experiment_parser("eval_detection", __doc__)
    p.add_argument("--detector", default="paper", choices=("paper", "mog2", "knn"))
    p.add_argument("--sequences", default="pets,tud," + ",".join(BUSY_SCENES))
    p.add_argument("--bootstrap", default="spread", choices=BOOTSTRAPS)
    p.add_argument("--track", action="store_true", help="also track and score MOTA / IDF1")
    p.add_argument(
        "--figures",
        action="store_true",
        help="write before/after frames (paper detector; with --track also the tracked boxes)",
    )
    p.add_argument("settings", nargs="*", help="key=value detector settings")
    args = p.parse_args(argv)
    cfg: dict[str, float] = {}
    for s in args.settings:
        k, v = s.split("=")
        cfg[k] = int(v) if v.isdigit() else float(v)
    names = [s for s in args.sequences.split(",") if s]
    unknown = sorted(set(names) - set(REAL) - set(BUSY_SCENES))
    if unknown:
        p.error(f"unknown sequence(s) {', '.join(unknown)}")
    data = data_root(args.data)
    with tee_stdout(args.out / "detection.txt"):
        print(f"detector={args.detector} bootstrap={args.bootstrap} settings={cfg}")
        for name in names:
            seq = load_sequence(name, data)
            if seq is None:
                print(f"{name}: data not found, skipped")
                continue
            frames, gt, fps = seq
            sc = detection_scores(frames, gt, make_detector(args.detector, **cfg), args.bootstrap)
            line = f"{name:9s} " + " ".join(f"{k}={v:.3f}" for k, v in sc.items())
            rows = None
            if args.track:
                from pftrack.eval import evaluate_mot
                from pftrack.tracking import TrackerConfig, track_frames

                if cfg:
                    print("(tracking uses the default detector settings)")
                run = track_frames(
                    frames,
                    config=TrackerConfig(detector=args.detector),
                    rng=0,
                    bootstrap=args.bootstrap,
                    show_progress=False,
                )
                rows = as_written(run.rows)  # what pftrack track writes
                m = evaluate_mot(gt, rows)
                line += f" MOTA={100 * m.mota:.1f} IDF1={100 * m.idf1:.1f}"
                by_iou, by_area = empty_floor_runs(rows, gt)
                line += f" empty_floor_s={by_iou / fps:.1f} (area {by_area / fps:.1f})"
            print(line)
            if args.figures:
                args.out.mkdir(parents=True, exist_ok=True)
                path = args.out / f"detection_{name}.jpg"
                figure(frames, gt, min(len(frames), 60), path, rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
