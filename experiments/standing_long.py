"""A walker who stops for hundreds of frames on ``make_scene``: the built-in detector's hold.

Each scene is ``pftrack.synthetic.make_scene(n_frames, n_walkers=5, rng=seed)`` with one more
walker (id 99, drawn from a generator seeded ``1000 + seed``) who walks in from the left at
3 px a frame for 50 frames, stands ``--stand`` frames (legs still), then walks out; the video
runs on ``stand + 200`` frames after, so the stander is in under half of the frames the
``spread`` bootstrap's median reads. Tracked by ``track_frames`` (every default but
``TrackerConfig.hold_frames``: ``--hold-frames``, 1000; 0 is the default detector; seed 0),
scored with ``evaluate_sequence``; the last column counts the standing frames whose truth box
a written row matches at IoU >= 0.5.

Usage (from the repository root)::

    python -m experiments.standing_long [--seeds 0-5] [--stand 300,600]
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from experiments._common import experiment_parser, tee_stdout
from experiments.demo_seeds import seed_range
from pftrack._typing import F64
from pftrack.boxes import iou_xywh
from pftrack.synthetic import _SHIRTS, _SKIN, _TROUSERS, Scene, _paste, _sprite, make_scene

STANDER = 99


def stand_scene(seed: int, stand: int, walk_in: int = 50) -> tuple[Scene, tuple[int, int]]:
    """The scene, and the first and last frame (1-based) of the stander's standing."""
    scene = make_scene(n_frames=walk_in + 2 * stand + 200, n_walkers=5, rng=seed)
    gen = np.random.default_rng(1000 + seed)
    w, h = int(gen.uniform(24, 36)), int(gen.uniform(70, 95))
    look = (
        _SHIRTS[int(gen.integers(len(_SHIRTS)))],
        _TROUSERS[int(gen.integers(len(_TROUSERS)))],
        _SKIN[int(gen.integers(len(_SKIN)))],
    )
    sprites = [_sprite(w, h, *look, ph, gen) for ph in (0, 1)]
    y = float(gen.uniform(0.55, 0.7) * scene.height)
    rows = []
    x = -w / 2.0
    for f, frame in enumerate(scene.frames, start=1):
        standing = walk_in < f <= walk_in + stand
        if not standing and f > 1:
            x += 3.0
        box = _paste(frame, *sprites[0 if standing else (f // 3) % 2], x, y)
        if box is not None:
            rows.append((f, STANDER, *box, 1.0, -1, -1, -1))
    truth = np.vstack([scene.truth, np.array(rows, np.float64)])
    scene.truth = truth[np.lexsort((truth[:, 1], truth[:, 0]))]
    return scene, (walk_in + 1, walk_in + stand)


def stander_found(rows: F64, truth: F64, span: tuple[int, int]) -> int:
    """Standing frames whose truth box a row matches at IoU >= 0.5."""
    t = truth[(truth[:, 1] == STANDER) & (truth[:, 0] >= span[0]) & (truth[:, 0] <= span[1])]
    found = 0
    for r in t:
        mine = rows[rows[:, 0] == r[0]]
        found += bool(len(mine)) and float(iou_xywh(r[2:6], mine[:, 2:6]).max()) >= 0.5
    return found


def main(argv: Sequence[str] | None = None) -> int:
    p = experiment_parser("standing_long", __doc__)
    p.add_argument("--seeds", default="0-5", help="make_scene seeds, e.g. 0-5 or 2,7")
    p.add_argument("--stand", default="300,600", help="standing lengths in frames")
    p.add_argument(
        "--hold-frames", type=int, default=1000, help="TrackerConfig.hold_frames (0: off)"
    )
    args = p.parse_args(argv)
    try:
        seeds, stands = seed_range(args.seeds), seed_range(args.stand)
    except ValueError as exc:
        p.error(str(exc))
    from pftrack.eval import evaluate_sequence
    from pftrack.io.mot import as_written
    from pftrack.tracking import TrackerConfig, track_frames

    config = TrackerConfig(hold_frames=args.hold_frames)
    scores, found, total = [], 0, 0
    with tee_stdout(args.out / "standing_long.txt"):
        print("stand seed frames   MOTA   IDF1   HOTA  stander found")
        for stand in stands:
            for seed in seeds:
                scene, span = stand_scene(seed, stand)
                run = track_frames(scene.frames, config=config, show_progress=False)
                rows = np.asarray(as_written(run.rows))
                s = evaluate_sequence(scene.truth, rows)
                v = (100 * s.mot.mota, 100 * s.mot.idf1, 100 * s.hota.hota)
                k = stander_found(rows, scene.truth, span)
                scores.append(v)
                found, total = found + k, total + stand
                line = f"{stand:5d} {seed:4d} {len(scene.frames):6d} "
                line += f"{v[0]:6.1f} {v[1]:6.1f} {v[2]:6.1f}  {k:5d} / {stand}"
                print(line, flush=True)
        m = np.mean(scores, axis=0)
        print(f"mean MOTA / IDF1 / HOTA {m[0]:.1f} / {m[1]:.1f} / {m[2]:.1f}; "
              f"stander found {found} / {total}")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
