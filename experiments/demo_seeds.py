"""The built-in detector on synthetic scenes of many seeds: held-out robustness of ``pftrack demo``.

``pftrack demo`` tracks ``pftrack.synthetic.make_scene(n_frames=150, rng=seed)`` with the
built-in detector. Scenes of other seeds are data the detector was never tuned on. Each scene
is made in memory, tracked by ``pftrack.tracking.track_frames(scene.frames, rng=TRACKER_SEED)``
(every default: the built-in detector, ``spread`` bootstrap) and scored with
``pftrack.eval.evaluate_sequence`` (HOTA, MOTA, IDF1, FP, FN, IDSW). Scenes: ``make_scene``
seeds ``--seeds`` (150 frames, 5 walkers), and ``make_busy_scene``'s ``present``, ``groups``
and ``overhead`` seeds ``--busy-seeds`` (100 frames). One line is printed per scene, then each
kind's mean and worst; the table is also written to ``OUT/demo_seeds.txt`` and every row to
``OUT/demo_seeds.json``.

Usage (from the repository root)::

    python -m experiments.demo_seeds [--seeds 0-29] [--busy-seeds 0-4]
        [--kinds walkers,present,groups,overhead] [--tracker-seed 0] [--out out/demo_seeds]
"""

from __future__ import annotations

import json
import time
from collections.abc import Sequence

import numpy as np

from experiments._common import experiment_parser, tee_stdout, write_text
from pftrack.synthetic import BUSY_SCENES, Scene, make_busy_scene, make_scene

KINDS = ("walkers", *BUSY_SCENES)


def seed_range(text: str) -> list[int]:
    """``"0-29"`` or ``"0,3,7"`` (or both, comma-separated) as a list of seeds."""
    out: list[int] = []
    for part in text.split(","):
        part = part.strip()
        if not part:
            continue
        lo, sep, hi = part.partition("-")
        try:
            out.extend(range(int(lo), int(hi) + 1) if sep else [int(lo)])
        except ValueError:
            raise ValueError(f"seeds: {part!r} is not N or N-M") from None
    return out


def scene_of(kind: str, seed: int) -> Scene:
    """The scene ``pftrack demo --seed SEED`` tracks (``walkers``), or a busy scene."""
    if kind == "walkers":
        return make_scene(n_frames=150, rng=seed)
    return make_busy_scene(kind, rng=seed)


def main(argv: Sequence[str] | None = None) -> int:
    p = experiment_parser("demo_seeds", __doc__)
    p.add_argument("--seeds", default="0-29", help="make_scene seeds, e.g. 0-29 or 2,7")
    p.add_argument("--busy-seeds", default="0-4", help="make_busy_scene seeds")
    p.add_argument("--kinds", default=",".join(KINDS), help="of " + ", ".join(KINDS))
    p.add_argument("--tracker-seed", type=int, default=0)
    args = p.parse_args(argv)
    kinds = [k for k in args.kinds.split(",") if k]
    bad = sorted(set(kinds) - set(KINDS))
    if bad:
        p.error(f"unknown kind(s): {', '.join(bad)}")
    try:
        seeds = {k: seed_range(args.seeds if k == "walkers" else args.busy_seeds) for k in kinds}
    except ValueError as exc:
        p.error(str(exc))
    from pftrack.eval import evaluate_sequence
    from pftrack.io.mot import as_written
    from pftrack.tracking import track_frames

    rows: list[dict[str, object]] = []
    with tee_stdout(args.out / "demo_seeds.txt"):
        print(f"tracker seed {args.tracker_seed}; MOTA, IDF1, HOTA in %")
        print(f"{'scene':8s} {'seed':>4s} {'HOTA':>6s} {'MOTA':>6s} {'IDF1':>6s} "
              f"{'FP':>5s} {'FN':>5s} {'IDSW':>4s} {'s':>5s}")  # fmt: skip
        for kind in kinds:
            for seed in seeds[kind]:
                scene = scene_of(kind, seed)
                t0 = time.perf_counter()
                run = track_frames(scene.frames, rng=args.tracker_seed, show_progress=False)
                s = evaluate_sequence(scene.truth, as_written(run.rows))
                row = {
                    "scene": kind, "seed": seed, "hota": 100 * s.hota.hota,
                    "mota": 100 * s.mot.mota, "idf1": 100 * s.mot.idf1,
                    "fp": s.mot.false_positives, "fn": s.mot.misses,
                    "idsw": s.mot.num_switches,
                }  # fmt: skip
                rows.append(row)
                print(
                    f"{kind:8s} {seed:4d} {row['hota']:6.1f} {row['mota']:6.1f} "
                    f"{row['idf1']:6.1f} {row['fp']:5d} {row['fn']:5d} {row['idsw']:4d} "
                    f"{time.perf_counter() - t0:5.1f}",
                    flush=True,
                )
        print()
        print(f"{'scene':8s} {'n':>3s}  mean HOTA / MOTA / IDF1   worst HOTA / MOTA / IDF1")
        for kind in kinds:
            mine = [r for r in rows if r["scene"] == kind]
            if not mine:
                continue
            v = np.array([[r["hota"], r["mota"], r["idf1"]] for r in mine], np.float64)
            mean, worst = v.mean(axis=0), v.min(axis=0)
            print(
                f"{kind:8s} {len(mine):3d}  {mean[0]:5.1f} / {mean[1]:5.1f} / {mean[2]:5.1f}"
                f"      {worst[0]:5.1f} / {worst[1]:5.1f} / {worst[2]:5.1f}"
            )
    write_text(args.out / "demo_seeds.json", json.dumps(rows, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
