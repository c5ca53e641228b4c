"""How much the offline pass's and the association's defaults matter, on public detections.

Runs ``pftrack track`` (as :func:`pftrack.run.track_frames`) on PETS09-S2L1 and TUD-Campus with
their ``det.txt`` for each setting and seed, and on synthetic scenes with the built-in detector
(held out: never used to choose anything but checked), and prints mean MOTA / IDF1 (scored by
:func:`pftrack.eval.evaluate_mot`). Not a pytest benchmark: a script.

Usage::

    python -m bench.offline_sensitivity [--data ../shared/data] [--seeds 3] [--scenes 6]
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace

import numpy as np

from bench.compare_trackers import data_root
from pftrack.eval import evaluate_mot
from pftrack.io.mot import read_mot
from pftrack.io.video import read_frames
from pftrack.run import load_detections, track_frames
from pftrack.smoothing import BoxSmoother
from pftrack.synthetic import make_scene
from pftrack.tracker import TrackerConfig

SEQUENCES = {"pets09-s2l1": ("video.avi", 0.625), "tud-campus": ("video.mp4", 1.0)}

SETTINGS: dict[str, tuple[dict[str, float], dict[str, float]]] = {
    # name: (TrackerConfig fields, BoxSmoother fields)
    "default": ({}, {}),
    "unmatched_cost 1.0": ({"unmatched_cost": 1.0}, {}),
    "unmatched_cost 1.25": ({"unmatched_cost": 1.25}, {}),
    "unmatched_cost 1.75": ({"unmatched_cost": 1.75}, {}),
    "unmatched_cost inf": ({"unmatched_cost": float("inf")}, {}),
    "accel x 0.5": ({}, {"accel": 0.00125}),
    "accel x 2": ({}, {"accel": 0.005}),
    "size_accel x 0.5": ({}, {"size_accel": 0.0015}),
    "size_accel x 2": ({}, {"size_accel": 0.006}),
}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", default=None, help="folder with pets09-s2l1/ and tud-campus/")
    ap.add_argument("--seeds", type=int, default=3, help="tracker seeds 0..N-1 (default 3)")
    ap.add_argument("--scenes", type=int, default=6, help="synthetic scenes 0..N-1, 120 frames (default 6)")
    ap.add_argument("--setting", nargs="+", default=list(SETTINGS), choices=list(SETTINGS))
    args = ap.parse_args(argv)
    root = data_root(args.data)
    if not root.is_dir():
        print(f"data folder not found: {root} (set --data or PFTRACK_DATA)", file=sys.stderr)
        return 2
    data = {}
    for name, (video, scale) in SEQUENCES.items():
        folder = root / name
        data[name] = (read_frames(folder / video), load_detections(folder / "det.txt", scale),
                      read_mot(folder / "gt.txt", what="ground truth"), scale)  # fmt: skip
    scenes = [make_scene(n_frames=120, rng=k) for k in range(args.scenes)]
    print("| setting | " + " | ".join(f"{n} MOTA / IDF1" for n in SEQUENCES) + f" | synthetic x{len(scenes)} |")
    print("|---|" + "---|" * (len(SEQUENCES) + 1))
    for setting in args.setting:
        tracker_kw, smoother_kw = SETTINGS[setting]
        cells = []
        for frames, dets, gt, scale in data.values():
            scores = []
            for seed in range(args.seeds):
                run = track_frames(frames, detections=dets, config=replace(TrackerConfig(), **tracker_kw),
                                   rng=seed, show_progress=False, smoother=BoxSmoother(**smoother_kw))  # fmt: skip
                m = evaluate_mot(gt, run.rows, scale=scale)
                scores.append((m.mota, m.idf1))
            a = 100 * np.asarray(scores)
            cells.append(f"{a[:, 0].mean():.1f} ± {a[:, 0].std():.1f} / {a[:, 1].mean():.1f} ± {a[:, 1].std():.1f}")
        syn = []
        for sc in scenes:
            run = track_frames(sc.frames, config=replace(TrackerConfig(), **tracker_kw), rng=0,
                               show_progress=False, smoother=BoxSmoother(**smoother_kw))  # fmt: skip
            m = evaluate_mot(sc.truth, run.rows)
            syn.append((m.mota, m.idf1))
        b = 100 * np.asarray(syn).reshape(-1, 2)
        cells.append(f"{b[:, 0].mean():.1f} / {b[:, 1].mean():.1f}" if len(b) else "-")
        print(f"| {setting} | " + " | ".join(cells) + " |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
