"""People and fast cars in one scene: the people's scores with the drop-in tracker's classes.

A synthetic street (`pftrack.synthetic.make_scene`'s walkers, class 0) with two lanes of
cars (class 2) drawn across its top: each car a body, a window band and two wheels, 70x30
pixels, a new one every `--car-every` frames (4), moving `--car-speed` pixels a frame (16:
0.53 heights a frame, against the walkers' 0.05). Detections come from the truth of both,
jittered by 5 % of the height, 10 % missed, a false person box every other frame
(`public_detections`' `noisy_detections`, scores 0.5 to 1; `--car-scores` draws the cars'
from another range, a class the detector scores lower: the case of the per-class birth
threshold, docs/tracking.md, "Birth threshold per class"); the cars' boxes are drawn
`--car-pad` of their height loose around them, and with `--car-shadow` each car casts that
many rows of shadow below it (the case of ``RefineConfig.upright_classes``,
docs/tracking.md, "Refinement per class"). Each run goes through :class:`pftrack.Tracker`
(``update(dets, frame)``, the class in column 6), then ``finalize()``; people and cars are
scored apart, each class's rows (``Tracker.classes``) against that class's truth, with
`pftrack.eval.evaluate_sequence`.

Usage (from the repository root)::

    python -m experiments.multi_class [--seeds 0 1 2] [--no-refine] [--no-cars]
        [--car-speed 16] [--car-pad 0.15] [--car-shadow 10] [--car-every 4]
        [--car-scores 0.3 0.5] [--set SECTION.FIELD=VALUE ...]
"""

from __future__ import annotations

import argparse
import dataclasses

import cv2
import numpy as np

from experiments._common import experiment_parser
from experiments.public_detections import noisy_detections, override
from pftrack._typing import F64
from pftrack.cli._options import positive_int
from pftrack.eval import SequenceScores, evaluate_sequence
from pftrack.synthetic import Scene, make_scene
from pftrack.tracking.api import Tracker
from pftrack.tracking.config import TrackerConfig

#: The cars' class id (COCO's "car").
CAR = 2
#: Car size in pixels (width, height) and the frames between two cars.
CAR_SIZE = (70, 30)
CAR_EVERY = 4


def add_cars(scene: Scene, speed: float, rng: np.random.Generator, shadow: int = 0,
             every: int = CAR_EVERY) -> F64:  # fmt: skip
    """Draw two lanes of cars over `scene`'s frames (in place); their MOT truth rows.

    A new car every `every` frames, the lanes in turn.
    Each car casts a shadow `shadow` rows tall below its body, the ground at 0.65 of its
    brightness over the car's columns (the truth box is the car's, without it).
    """
    w, h = CAR_SIZE
    width = scene.width
    rows = []
    lanes = (0.08 * scene.height, 0.2 * scene.height)  # tops of the lanes
    n = len(scene.frames)
    car_id = 1
    for start in range(1, n + 1, every):
        lane = (start // every) % 2
        ltr = lane == 0
        colour = tuple(int(c) for c in rng.integers(40, 230, 3))
        top = lanes[lane] + rng.uniform(-3, 3)
        v = speed * rng.uniform(0.9, 1.1)
        for f in range(start, n + 1):
            x = -w + v * (f - start) if ltr else width + v * (f - start) * -1.0
            if x + w <= 0 or x >= width:
                if f > start:
                    break
                continue
            frame = scene.frames[f - 1]
            x0, y0 = int(round(x)), int(round(top))
            if shadow:
                below = frame[y0 + h : y0 + h + shadow, max(x0, 0) : max(x0 + w, 0)]
                below[:] = (below * 0.65).astype(np.uint8)
            cv2.rectangle(frame, (x0, y0 + 6), (x0 + w - 1, y0 + h - 8), colour, -1)
            cv2.rectangle(frame, (x0 + 12, y0), (x0 + w - 13, y0 + 8), colour, -1)
            cv2.rectangle(frame, (x0 + 16, y0 + 2), (x0 + w - 17, y0 + 7), (60, 50, 40), -1)
            for cx in (x0 + 14, x0 + w - 15):
                cv2.circle(frame, (cx, y0 + h - 6), 6, (20, 20, 20), -1)
            xa, xb = max(x0, 0), min(x0 + w, width)
            rows.append((f, car_id, xa, y0, xb - xa, h, 1.0, -1.0, -1.0, -1.0))
        car_id += 1
    return np.array(rows, dtype=np.float64).reshape(-1, 10)


def loosen(dets: dict[int, F64], pad: float, width: int, height: int) -> dict[int, F64]:
    """Boxes grown by `pad` of their height on every side, clipped to the frame."""
    out = {}
    for f, d in dets.items():
        b = d.copy()
        p = pad * b[:, 3:4]
        x1 = np.clip(b[:, 0:1] - p, 0, width)
        y1 = np.clip(b[:, 1:2] - p, 0, height)
        x2 = np.clip(b[:, 0:1] + b[:, 2:3] + p, 0, width)
        y2 = np.clip(b[:, 1:2] + b[:, 3:4] + p, 0, height)
        b[:, :4] = np.hstack([x1, y1, x2 - x1, y2 - y1])
        out[f] = b
    return out


def run(seed: int, config: TrackerConfig, cars: bool, speed: float, pad: float, shadow: int,
        car_scores: tuple[float, float] | None = None, car_every: int = CAR_EVERY
        ) -> tuple[SequenceScores, SequenceScores | None]:  # fmt: skip
    """People's and cars' scores of one seeded scene.

    `car_scores` ``(low, high)``: the cars' detection scores drawn uniformly from that range
    (a class the detector scores lower than people); None: as the people's, 0.5 to 1.
    """
    scene = make_scene(150, n_walkers=8, rng=seed)
    rng = np.random.default_rng(100 + seed)
    car_truth = add_cars(scene, speed, rng, shadow, car_every) if cars else np.zeros((0, 10))
    n, h, w = len(scene.frames), scene.height, scene.width
    people = noisy_detections(scene.truth, n, h, w, seed)
    car_dets = loosen(noisy_detections(car_truth, n, h, w, 50 + seed), pad, w, h)
    if car_scores is not None:
        draw = np.random.default_rng(200 + seed)
        for d in car_dets.values():
            d[:, 4] = draw.uniform(*car_scores, len(d))
    tracker = Tracker.from_config(config, seed, frame_rate=scene.fps)
    for f, frame in enumerate(scene.frames, start=1):
        p = people[f]
        c = car_dets[f][: len(car_dets[f]) - (f % 2 == 0)] if cars else np.zeros((0, 5))
        d = np.vstack([p, c])
        cls = np.r_[np.zeros(len(p)), np.full(len(c), CAR)]
        xyxy = np.column_stack([d[:, :2], d[:, :2] + d[:, 2:4], d[:, 4], cls])
        tracker.update(xyxy, frame)
    rows = tracker.finalize()
    of = np.array([tracker.classes.get(int(i), 0) for i in rows[:, 1]], np.int64)
    s_people = evaluate_sequence(scene.truth, rows[of == 0], num_frames=n)
    s_cars = evaluate_sequence(car_truth, rows[of == CAR], num_frames=n) if cars else None
    return s_people, s_cars


def line(name: str, s: SequenceScores) -> str:
    """One row of the table."""
    m = s.mot
    return (
        f"{name:<12} MOTA {100 * m.mota:5.1f}  IDF1 {100 * m.idf1:5.1f}  "
        f"HOTA {100 * s.hota.hota:5.1f}  IDsw {m.num_switches:3d}"
    )


def main(argv: list[str] | None = None) -> int:
    """Run the scenes and print the table."""
    p = experiment_parser("multi_class", __doc__)
    p.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2], help="scene seeds")
    p.add_argument("--no-cars", action="store_true", help="the walkers alone")
    p.add_argument("--no-refine", action="store_true", help="box refinement off")
    p.add_argument("--car-speed", type=float, default=16.0, help="pixels a frame")
    p.add_argument("--car-pad", type=float, default=0.15, help="car boxes' looseness")
    p.add_argument("--car-shadow", type=int, default=0, help="rows of shadow below a car")
    p.add_argument(
        "--car-every", type=positive_int, default=CAR_EVERY, help="frames between two cars"
    )
    p.add_argument("--car-scores", type=float, nargs=2, default=None, metavar=("LOW", "HIGH"),
                   help="cars' detection scores drawn from [LOW, HIGH) (default: as the "
                   "people's, 0.5 to 1)")  # fmt: skip
    p.add_argument("--set", nargs="*", default=[], metavar="SECTION.FIELD=VALUE",
                   help="TrackerConfig fields changed for a trial")  # fmt: skip
    args: argparse.Namespace = p.parse_args(argv)
    config = TrackerConfig()
    if args.no_refine:
        config = dataclasses.replace(
            config, refine=dataclasses.replace(config.refine, enabled=False)
        )
    for setting in args.set:
        config = override(config, setting)
    people, cars = [], []
    for seed in args.seeds:
        sp, sc = run(seed, config, not args.no_cars, args.car_speed, args.car_pad,
                     args.car_shadow, args.car_scores, args.car_every)  # fmt: skip
        print(line(f"seed {seed} people", sp))
        people.append(sp)
        if sc is not None:
            print(line(f"seed {seed} cars", sc))
            cars.append(sc)
    print(line("pooled people", SequenceScores.combine(people)))
    if cars:
        print(line("pooled cars", SequenceScores.combine(cars)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
