"""Particles per object with given detections (``TrackerConfig.given_particles``) over many seeds.

PETS09-S2L1 and TUD-Campus, each with its video and public ``det.txt`` (the drop-in mode, as
``pftrack track --detections``), tracked once per seed and particle count; every other setting
is the default. The sequences without video (``mot15-gt/``) and the synthetic busy scenes are
left out: their tracks do not depend on the particle count (``experiments.public_detections
--set given_particles=100`` gives them the same figures to the digit). Prints MOTA / IDF1 /
HOTA per seed and their means and standard deviations per count: PETS09's IDF1 moves by
several points from one seed to the next, so counts are compared over many seeds.

Usage (from the repository root)::

    python -m experiments.given_particles [--data ../shared/data] [--seeds 25]
        [--counts 100 200] [--out out/given_particles]
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from experiments._common import PETS, TUD, data_root, experiment_parser, tee_stdout, video_folders
from pftrack.eval import evaluate_sequence
from pftrack.io.mot import as_written, read_mot
from pftrack.io.video import FrameSource
from pftrack.tracking import TrackerConfig, load_detections, track_frames


def scores(folder: Path, video: str, scale: float, count: int, seed: int) -> tuple[float, ...]:
    """MOTA, IDF1 and HOTA (percent) of one run of the sequence in `folder`."""
    config = replace(TrackerConfig(), given_particles=count)
    run = track_frames(
        FrameSource(folder / video),
        detections=load_detections(folder / "det.txt", scale),
        config=config,
        rng=seed,
    )
    s = evaluate_sequence(read_mot(folder / "gt.txt"), as_written(run.rows), scale=scale)
    return 100 * s.mot.mota, 100 * s.mot.idf1, 100 * s.hota.hota


def main(argv: list[str] | None = None) -> int:
    p = experiment_parser("given_particles", __doc__)
    p.add_argument("--seeds", type=int, default=25, help="seeds 0..N-1 (default: 25)")
    p.add_argument(
        "--counts", type=int, nargs="+", default=[100, 200], metavar="N",
        help="particle counts compared (default: 100 200)",
    )  # fmt: skip
    args = p.parse_args(argv)
    if args.seeds < 1 or any(n < 1 for n in args.counts):
        p.error("--seeds and --counts must be >= 1")
    data = data_root(args.data)
    with tee_stdout(args.out / "given_particles.txt"):
        for src, folder in video_folders(data, (PETS, TUD)):
            for n in args.counts:
                rows = []
                for seed in range(args.seeds):
                    rows.append(scores(folder, src.video, src.scale, n, seed))
                    m, i, h = rows[-1]
                    print(
                        f"{src.name} particles {n:4d} seed {seed:2d}  {m:5.1f} / {i:5.1f} / "
                        f"{h:5.1f}"
                    )
                mean, sd = (
                    np.mean(rows, axis=0),
                    np.std(rows, axis=0, ddof=1 if len(rows) > 1 else 0),
                )
                print(
                    f"{src.name} particles {n:4d} MEAN over {args.seeds} seeds  MOTA {mean[0]:.1f} "
                    f"± {sd[0]:.1f} / IDF1 {mean[1]:.1f} ± {sd[1]:.1f} / HOTA {mean[2]:.1f} "
                    f"± {sd[2]:.1f}",
                    flush=True,
                )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
