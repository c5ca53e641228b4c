"""How much the offline pass's and the association's defaults matter, on public detections.

Runs ``pftrack track`` (as :func:`pftrack.tracking.track_frames`) on PETS09-S2L1 and TUD-Campus with
their ``det.txt`` for each setting and seed, and on synthetic scenes with the built-in detector
(held out: never used to choose anything but checked), and prints mean MOTA / IDF1 (scored by
:func:`pftrack.eval.evaluate_mot`). The table is also written to ``sensitivity.md`` in ``--out``
(default ``out/offline_sensitivity``).

Usage (from the repository root)::

    python -m experiments.offline_sensitivity [--data ../shared/data] [--seeds 3] [--scenes 6]
        [--setting NAME ...] [--out out/offline_sensitivity]
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from experiments._common import data_folder, experiment_parser, tee_stdout
from pftrack._typing import F64
from pftrack.eval import evaluate_mot
from pftrack.io.mot import as_written, read_mot
from pftrack.io.video import read_frames
from pftrack.synthetic import Scene, make_scene
from pftrack.tracking import (
    AssociationConfig,
    BoxSmoother,
    TrackerConfig,
    load_detections,
    track_frames,
)

U8 = NDArray[np.uint8]

SEQUENCES = {"pets09-s2l1": ("video.avi", 0.625), "tud-campus": ("video.mp4", 1.0)}

SETTINGS: dict[str, tuple[AssociationConfig, BoxSmoother]] = {
    # name: (the tracker's association settings, the offline pass's smoother)
    "default": (AssociationConfig(), BoxSmoother()),
    "unmatched_cost 1.0": (AssociationConfig(unmatched_cost=1.0), BoxSmoother()),
    "unmatched_cost 1.25": (AssociationConfig(unmatched_cost=1.25), BoxSmoother()),
    "unmatched_cost 1.75": (AssociationConfig(unmatched_cost=1.75), BoxSmoother()),
    "unmatched_cost inf": (AssociationConfig(unmatched_cost=float("inf")), BoxSmoother()),
    "accel x 0.5": (AssociationConfig(), BoxSmoother(accel=0.00125)),
    "accel x 2": (AssociationConfig(), BoxSmoother(accel=0.005)),
    "size_accel x 0.5": (AssociationConfig(), BoxSmoother(size_accel=0.0015)),
    "size_accel x 2": (AssociationConfig(), BoxSmoother(size_accel=0.006)),
}


def setting_row(
    setting: str,
    data: dict[str, tuple[list[U8], dict[int, F64], F64, float]],
    scenes: list[Scene],
    seeds: int,
) -> str:
    """One table row: mean ± std over seeds per sequence, mean over the synthetic scenes."""
    association, smoother = SETTINGS[setting]
    config = replace(TrackerConfig(), association=association)
    cells = []
    for frames, dets, gt, scale in data.values():
        scores = []
        for seed in range(seeds):
            run = track_frames(
                frames,
                detections=dets,
                config=config,
                rng=seed,
                show_progress=False,
                smoother=smoother,
            )
            m = evaluate_mot(gt, as_written(run.rows), scale=scale)
            scores.append((m.mota, m.idf1))
        a = 100 * np.asarray(scores)
        mota, idf1 = a[:, 0], a[:, 1]
        cells.append(f"{mota.mean():.1f} ± {mota.std():.1f} / {idf1.mean():.1f} ± {idf1.std():.1f}")
    syn = []
    for sc in scenes:
        run = track_frames(
            sc.frames,
            config=config,
            rng=0,
            show_progress=False,
            smoother=smoother,
        )
        m = evaluate_mot(sc.truth, as_written(run.rows))
        syn.append((m.mota, m.idf1))
    b = 100 * np.asarray(syn).reshape(-1, 2)
    cells.append(f"{b[:, 0].mean():.1f} / {b[:, 1].mean():.1f}" if len(b) else "-")
    return f"| {setting} | " + " | ".join(cells) + " |"


def main(argv: Sequence[str] | None = None) -> int:
    ap = experiment_parser("offline_sensitivity", __doc__)
    ap.add_argument("--seeds", type=int, default=3, help="tracker seeds 0..N-1 (default 3)")
    ap.add_argument(
        "--scenes", type=int, default=6, help="synthetic scenes 0..N-1, 120 frames (default 6)"
    )
    ap.add_argument("--setting", nargs="+", default=list(SETTINGS), choices=list(SETTINGS))
    args = ap.parse_args(argv)
    root = data_folder(args.data)
    if root is None:
        return 2
    data = {}
    for name, (video, scale) in SEQUENCES.items():
        folder = root / name
        data[name] = (
            read_frames(folder / video),
            load_detections(folder / "det.txt", scale),
            read_mot(folder / "gt.txt", what="ground truth"),
            scale,
        )
    scenes = [make_scene(n_frames=120, rng=k) for k in range(args.scenes)]
    with tee_stdout(args.out / "sensitivity.md"):
        seqs = " | ".join(f"{n} MOTA / IDF1" for n in SEQUENCES)
        print(f"| setting | {seqs} | synthetic x{len(scenes)} |")
        print("|---|" + "---|" * (len(SEQUENCES) + 1))
        for setting in args.setting:
            print(setting_row(setting, data, scenes, args.seeds), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
