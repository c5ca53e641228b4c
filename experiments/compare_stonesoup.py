"""pftrack against a Stone Soup multi-target tracker on the same public detections.

Stone Soup (``pip install stonesoup``, in the ``peers`` extra) is built as its tutorials build a
tracker (:func:`experiments.stonesoup_models.box_tracker`: constant velocity on the box centre,
random walk on its size, Mahalanobis distance, global nearest neighbour, multi-measurement
initiation, deletion after missed updates). It reports the boxes of the tracks updated in each
frame, online; ``stonesoup+smooth`` is that output after pftrack's offline pass
(:func:`pftrack.tracking.smooth_tracks`), as ``compare_trackers --smooth-peers`` does.

pftrack runs as ``experiments.public_detections`` runs it (:func:`pftrack.tracking.track_frames`
with the ``det.txt``, seed 0, defaults); ``pftrack-online`` is the same without the offline
pass (``pftrack track --no-smooth --no-link``). Sequences: PETS09-S2L1 (boxes scaled by 0.625
onto the 480x360 video), TUD-Campus, and ADL-Rundle-6, ETH-Sunnyday, KITTI-17 of ``mot15-gt/``
(no video: black frames of ``seqinfo.ini``'s size, which only pftrack reads). Every row is
scored by :func:`pftrack.eval.evaluate_sequence` (TrackEval's HOTA, CLEAR-MOT and IDF1 at IoU
0.5); ``pooled`` combines the five sequences as TrackEval does.

Frames/s counts the tracker's own calls: Stone Soup's ``update_tracker`` per frame; pftrack's
whole ``track_frames`` call on frames already in memory (its offline pass included).

``--smoother`` prints how far Stone Soup's ``KalmanSmoother`` lands from the RTS smoother when
a track holds its missed frames' predictions (as its trackers append them), on the first 50
tracks of ``bench/recovery_file.py``'s 500-track file; with no state for a missed frame it is
exact (tests/experiments/test_stonesoup.py).

``--grid`` runs Stone Soup alone with each setting of a small grid and prints the pooled scores,
the tuning behind the default settings (:data:`TUNED`): chosen once by pooled HOTA over all five
sequences, not per sequence.

Usage (from the repository root)::

    python -m experiments.compare_stonesoup [--data ../shared/data] [--out DIR] [--grid]
        [--smoother]
"""

from __future__ import annotations

import dataclasses
import itertools
import time
import warnings
from collections.abc import Sequence
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
from experiments.public_detections import BlackFrames, black_frames
from experiments.stonesoup_models import BoxTrackerSettings, box_tracker
from pftrack._typing import F64
from pftrack.eval import SequenceScores, evaluate_sequence
from pftrack.io.mot import as_written, read_mot
from pftrack.io.video import read_frames
from pftrack.tracking import load_detections, smooth_tracks, track_frames

TUNED = BoxTrackerSettings(q_pos=0.3, gate=12.0, max_missed=10)
"""Stone Soup's settings in the table: the best pooled HOTA of ``--grid`` (41.7; docs/results.md),
the other fields at their defaults."""


@dataclasses.dataclass(frozen=True)
class Case:
    """One sequence: frames (only pftrack reads them), detections, truth and its scale."""

    name: str
    frames: Sequence[NDArray[np.uint8]]
    detections: dict[int, F64]
    truth: F64
    scale: float


def load_cases(data: Path, with_frames: bool = True) -> list[Case]:
    """The five sequences found under `data` (a missing one is skipped with a note)."""
    out = []
    for src, folder in video_folders(data):
        frames: Sequence[NDArray[np.uint8]] = (
            read_frames(folder / src.video) if with_frames else BlackFrames(0, 1, 1)
        )
        dets = load_detections(folder / "det.txt", src.scale)
        out.append(Case(src.name, frames, dets, read_mot(folder / "gt.txt"), src.scale))
    for name, folder in no_video_folders(data):
        frames = black_frames(folder)
        dets = load_detections(folder / "det.txt")
        out.append(Case(name, frames, dets, read_mot(folder / "gt.txt"), 1.0))
    return out


def n_frames(case: Case) -> int:
    """Frames of the sequence: its frames if loaded, else the last frame of truth or boxes."""
    if len(case.frames):
        return len(case.frames)
    return int(max(case.truth[:, 0].max(), max(case.detections, default=0)))


def run_stonesoup(case: Case, settings: BoxTrackerSettings) -> tuple[F64, float]:
    """Stone Soup's rows (MOTChallenge layout) on `case`, and its frames per second."""
    step = box_tracker(settings)
    rows = []
    elapsed = 0.0
    steps = n_frames(case)
    for f in range(1, steps + 1):
        boxes = case.detections.get(f, np.zeros((0, 5)))
        t0 = time.perf_counter()
        out = step(f, boxes)
        elapsed += time.perf_counter() - t0
        rows += [(f, k, *box, 1.0, -1.0, -1.0, -1.0) for k, box in out]
    return np.asarray(rows, dtype=np.float64).reshape(-1, 10), steps / elapsed


def run_pftrack(case: Case, offline: bool) -> tuple[F64, float]:
    """pftrack's rows on `case` (seed 0, defaults) and its frames per second."""
    kw = {} if offline else {"smoother": None, "link": None}
    t0 = time.perf_counter()
    run = track_frames(case.frames, detections=case.detections, rng=0, show_progress=False, **kw)
    fps = len(case.frames) / (time.perf_counter() - t0)
    return as_written(run.rows), fps  # the values pftrack track writes


def line(tracker: str, name: str, s: SequenceScores, fps: float | None) -> str:
    """One row of the table."""
    m = s.mot
    rate = "" if fps is None else f"{fps:.0f}"
    return (
        f"| {tracker} | {name} | {100 * m.mota:.1f} | {100 * m.idf1:.1f} | {100 * s.hota.hota:.1f} "
        f"| {m.num_switches} | {m.false_positives} | {m.misses} | {rate} |"
    )


HEAD = (
    "| tracker | sequence | MOTA | IDF1 | HOTA | IDSW | FP | FN | frames/s |\n" + "|---" * 9 + "|"
)

GRID = {
    "q_pos": [0.3, 1.0, 3.0],
    "gate": [8.0, 12.0, 20.0],
    "max_missed": [10, 20],
}
"""The tuning grid: every combination, the other fields at :class:`BoxTrackerSettings`'s
defaults. A first grid (q_pos 0.3; r_pos 9 and 25; gate 3, 5 and 8; max_missed 3, 5 and 10:
18 settings) found the widest gate and the longest memory best, r_pos 25 and 9 alike; this one
goes on from there with r_pos 25."""


def grid(cases: list[Case]) -> None:
    """Pooled scores of Stone Soup with every setting of :data:`GRID`, best HOTA last."""
    results = []
    keys = list(GRID)
    for values in itertools.product(*GRID.values()):
        settings = dataclasses.replace(BoxTrackerSettings(), **dict(zip(keys, values, strict=True)))
        scores = [evaluate_sequence(c.truth, run_stonesoup(c, settings)[0], scale=c.scale)
                  for c in cases]  # fmt: skip
        pooled = SequenceScores.combine(scores)
        text = " ".join(f"{k}={v}" for k, v in zip(keys, values, strict=True))
        per = " ".join(f"{100 * s.hota.hota:.1f}" for s in scores)
        print(
            f"{text}: pooled MOTA {100 * pooled.mot.mota:.1f} IDF1 {100 * pooled.mot.idf1:.1f} "
            f"HOTA {100 * pooled.hota.hota:.1f} (per sequence HOTA {per})",
            flush=True,
        )
        results.append((pooled.hota.hota, text))
    best = max(results)
    print(f"best pooled HOTA {100 * best[0]:.1f}: {best[1]}")


def smoother_check(n_tracks: int = 50) -> None:
    """Largest centre difference per track, Stone Soup's smoother through missed-frame
    predictions against :func:`pftrack.kalman.rts_smooth` (and the exact form's)."""
    from bench.recovery_file import synthetic_tracks
    from experiments.stonesoup_models import stonesoup_rts_smooth
    from pftrack.kalman import rts_smooth

    rows = synthetic_tracks(500, seed=0)
    q, r2 = np.array([0.5, 0.5, 0.1, 0.1]), np.array([4.0, 4.0, 9.0, 9.0])
    exact, through = [], []
    for tid in np.unique(rows[:, 1])[:n_tracks]:
        r = rows[rows[:, 1] == tid]
        f = (r[:, 0] - r[0, 0]).astype(int)
        z = np.full((f[-1] + 1, 4), np.nan)
        z[f] = np.column_stack([r[:, 2:4] + r[:, 4:6] / 2, r[:, 4:6]])
        has = ~np.isnan(z[:, 0])
        ours = rts_smooth(z, has, q, r2, velocity_sd=10.0, update_first=False)
        kw = {"velocity_sd": 10.0, "update_first": False}
        skip = stonesoup_rts_smooth(z, has, q, r2, **kw)
        pred = stonesoup_rts_smooth(z, has, q, r2, missed="predict", **kw)
        exact.append(np.abs(skip - ours)[has].max())
        through.append(np.abs(pred - ours)[:, :2].max())
    print(f"{n_tracks} tracks; largest difference per track, px:")
    print(f"  no state for missed frames (measured frames): max {max(exact):.2g}")
    print(
        f"  missed frames' predictions in the track (centre, every frame): median "
        f"{np.median(through):.1f}, max {max(through):.1f}"
    )


def main(argv: list[str] | None = None) -> int:
    p = experiment_parser("compare_stonesoup", __doc__)
    p.add_argument(
        "--grid", action="store_true",
        help="run Stone Soup over the tuning grid instead of the table",
    )  # fmt: skip
    p.add_argument(
        "--smoother", action="store_true",
        help="print Stone Soup's smoother against rts_smooth through missed frames, then stop",
    )  # fmt: skip
    args = p.parse_args(argv)
    try:
        import stonesoup  # noqa: F401
    except ImportError:
        p.error("Stone Soup is not installed: pip install stonesoup (or '.[peers]')")
    if args.smoother:
        with tee_stdout(args.out / "smoother.txt"):
            smoother_check()
        return 0
    data = data_root(args.data)
    with tee_stdout(args.out / ("grid.txt" if args.grid else "stonesoup.md")):
        cases = load_cases(data, with_frames=not args.grid)
        if args.grid:
            grid(cases)
            return 0
        print(f"Stone Soup settings: {TUNED}")
        print(HEAD)
        pooled: dict[str, list[SequenceScores]] = {}
        for case in cases:
            rows_ss, fps_ss = run_stonesoup(case, TUNED)
            runs = {
                "stonesoup": (rows_ss, fps_ss),
                "stonesoup+smooth": (smooth_tracks(rows_ss), None),
            }
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                runs["pftrack"] = run_pftrack(case, offline=True)
                runs["pftrack-online"] = run_pftrack(case, offline=False)
            for tracker, (rows, fps) in runs.items():
                s = evaluate_sequence(case.truth, rows, scale=case.scale)
                pooled.setdefault(tracker, []).append(s)
                print(line(tracker, case.name, s, fps), flush=True)
        for tracker, scores in pooled.items():
            print(line(tracker, "pooled", SequenceScores.combine(scores), None))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
