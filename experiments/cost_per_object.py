"""Cost of ``pftrack.Tracker.update`` per frame against the number of objects in view (1-100).

A synthetic 1280x720 crowd (:func:`make_crowd`): N two-colour walkers that stay in view on
every frame, bouncing off the borders, on a smooth textured background with sensor noise; the
detections given to ``update`` are their true boxes, so no detector is timed. For each N, a
fresh tracker (seed 0, 100 particles) runs 10 untimed frames (births, start-up), then
``update`` is timed on 40 frames, best of 3 runs:

* ``batched``: the tracker as it is (all filters' steps in one C++ call, ``sis_step_batch``);
* ``per object``: the same tracker with the older loop, one ``LiveTrack.predict`` (one C++
  ``sis_step`` call) per track; same tracks, bit for bit;
* ``no refine``: batched without box refinement, so without the background pass (a fixed
  cost of the frame size) -- the tracker alone.

Wall and this process's CPU time per frame are both given: the machine may be shared. Run it
with ``OPENBLAS_NUM_THREADS=1``, as ``pftrack track`` runs (``_threads.one_blas_thread``): from
about 70 objects on, the association's colour product, (T, 110) by (D, 110), is large enough for
OpenBLAS to wake its thread pool, whose spinning threads then add 2-3 ms of CPU a frame (stop 65,
docs/results.md "A crowd of 40+ at 1280x720"), a break in the line that is not the tracker's. Writes
``cost_per_object.md`` (table), ``cost_per_object.csv`` and ``cost_per_object.png`` (plot drawn
with OpenCV) to ``--out``.

Usage (from the repository root)::

    OPENBLAS_NUM_THREADS=1 python -m experiments.cost_per_object [--out out/cost_per_object] \
        [--counts 1,10,100]
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

import pftrack
from experiments._common import experiment_parser, scene_size, tee_stdout, write_text
from pftrack._typing import F64
from pftrack.io.opencv_io import write_image
from pftrack.tracking import tracker as tracker_module
from pftrack.tracking.track import LiveTrack

COUNTS = (1, 2, 5, 10, 20, 30, 50, 75, 100)
WARM, TIMED, REPEATS = 10, 40, 3
SIZE = (1280, 720)

Frame = NDArray[np.uint8]


def make_crowd(
    n_objects: int, n_frames: int, size: tuple[int, int] = SIZE, seed: int = 0
) -> tuple[list[Frame], list[F64]]:
    """A seeded crowd of `n_objects` walkers, all in view on every frame.

    Parameters
    ----------
    n_objects : int
        Walkers (>= 1).
    n_frames : int
        Frames (>= 1).
    size : (int, int)
        Frame width and height (>= 160 x 120).
    seed : int
        Same seed, same frames.

    Returns
    -------
    frames : list of (H, W, 3) uint8
        BGR frames.
    detections : list of (N, 5) float64
        Per frame, the walkers' boxes ``x1, y1, x2, y2, 1.0``.
    """
    width, height = scene_size("n_objects", n_objects, n_frames, size)
    rng = np.random.default_rng(seed)
    small = rng.integers(70, 150, (height // 24 + 1, width // 24 + 1, 3)).astype(np.uint8)
    background = cv2.resize(small, (width, height), interpolation=cv2.INTER_CUBIC)
    h = np.round(rng.uniform(0.1, 0.16, n_objects) * height)
    w = np.round(h * rng.uniform(0.35, 0.5, n_objects))
    x = rng.uniform(0, width - w)
    y = rng.uniform(0, height - h)
    v = rng.uniform(-3, 3, (n_objects, 2))
    hues = rng.integers(0, 180, (n_objects, 2))
    hsv = np.stack([hues, np.full_like(hues, 200), np.full_like(hues, 210)], axis=-1)
    colours = cv2.cvtColor(hsv.astype(np.uint8), cv2.COLOR_HSV2BGR).astype(int)  # (N, 2, 3)
    frames, dets = [], []
    for _ in range(n_frames):
        noise = rng.integers(-4, 5, (height, width, 3), dtype=np.int16)
        frame = np.clip(background + noise, 0, 255).astype(np.uint8)
        for k in np.argsort(y + h):  # farther (higher) walkers first
            x0, y0, wk, hk = int(x[k]), int(y[k]), int(w[k]), int(h[k])
            top = tuple(int(c) for c in colours[k, 0])
            bottom = tuple(int(c) for c in colours[k, 1])
            cv2.rectangle(frame, (x0, y0), (x0 + wk - 1, y0 + hk // 2), top, -1)
            cv2.rectangle(frame, (x0, y0 + hk // 2), (x0 + wk - 1, y0 + hk - 1), bottom, -1)
        frames.append(frame)
        dets.append(np.column_stack([x, y, x + w, y + h, np.ones(n_objects)]).astype(np.float64))
        x, y = x + v[:, 0], y + v[:, 1]
        for pos, extent, axis in ((x, w, 0), (y, h, 1)):
            out = (pos < 0) | (pos > (width, height)[axis] - extent)
            v[out, axis] *= -1
            np.clip(pos, 0, (width, height)[axis] - extent, out=pos)
    return frames, dets


@contextmanager
def per_object_loop() -> Iterator[None]:
    """Within the block, trackers step one filter per C++ call (the older loop)."""

    def loop(
        tracks: Sequence[LiveTrack], binned: Any, noise: float, gains: Sequence[float]
    ) -> None:  # each track's class's gain (MultiObjectTracker.motion_gain)
        for t, gain in zip(tracks, gains, strict=True):
            t.predict(binned, noise, gain)

    saved = tracker_module.predict_tracks
    tracker_module.predict_tracks = loop  # type: ignore[assignment]
    try:
        yield
    finally:
        tracker_module.predict_tracks = saved


def new_tracker(*, refine: bool = True) -> pftrack.Tracker:
    """A fresh ``pftrack.Tracker`` (seed 0, no priming); ``refine=False`` turns box refinement,
    and so the background model behind it, off."""
    tracker = pftrack.Tracker(seed=0, prime=0)
    if refine:
        return tracker
    cfg = tracker.config
    cfg = replace(cfg, refine=replace(cfg.refine, enabled=False))
    return pftrack.Tracker.from_config(cfg, 0, prime_frames=0)


def time_updates(frames: list[Frame], dets: list[F64], *, refine: bool) -> tuple[float, float]:
    """Best-of-REPEATS (wall, CPU) ms per ``update`` over the timed frames."""
    best_wall, best_cpu = np.inf, np.inf
    for _ in range(REPEATS):
        tracker = new_tracker(refine=refine)
        for k in range(WARM):
            tracker.update(dets[k], frames[k])
        wall0, cpu0 = time.perf_counter(), time.process_time()
        for k in range(WARM, WARM + TIMED):
            tracker.update(dets[k], frames[k])
        best_wall = min(best_wall, (time.perf_counter() - wall0) * 1000 / TIMED)
        best_cpu = min(best_cpu, (time.process_time() - cpu0) * 1000 / TIMED)
    return best_wall, best_cpu


def measure(counts: Sequence[int]) -> list[dict[str, float]]:
    """One row per object count: ms per frame of each variant, wall and CPU."""
    rows = []
    for n in counts:
        frames, dets = make_crowd(n, WARM + TIMED, seed=n)
        row: dict[str, float] = {"objects": n}
        row["batched_wall"], row["batched_cpu"] = time_updates(frames, dets, refine=True)
        with per_object_loop():
            row["per_object_wall"], row["per_object_cpu"] = time_updates(frames, dets, refine=True)
        row["no_refine_wall"], row["no_refine_cpu"] = time_updates(frames, dets, refine=False)
        rows.append(row)
        print(
            f"{n:4d} objects: batched {row['batched_wall']:.2f} ms ({row['batched_cpu']:.2f} CPU), "
            f"per object {row['per_object_wall']:.2f} ({row['per_object_cpu']:.2f}), "
            f"no refine {row['no_refine_wall']:.2f} ({row['no_refine_cpu']:.2f})",
            flush=True,
        )
    return rows


def table(rows: list[dict[str, float]]) -> str:
    """The rows as a Markdown table, with a least-squares line through the batched CPU cost."""
    head = (
        "| objects | batched, wall | batched, CPU | per object, wall | per object, CPU "
        "| no refine, wall | no refine, CPU |\n|---:|---:|---:|---:|---:|---:|---:|\n"
    )
    lines = [
        f"| {r['objects']:.0f} | {r['batched_wall']:.2f} | {r['batched_cpu']:.2f} "
        f"| {r['per_object_wall']:.2f} | {r['per_object_cpu']:.2f} "
        f"| {r['no_refine_wall']:.2f} | {r['no_refine_cpu']:.2f} |"
        for r in rows
    ]
    n = np.array([r["objects"] for r in rows])
    text = (
        head + "\n".join(lines) + "\n\nms per frame of `Tracker.update`, 1280x720, 100 particles.\n"
    )
    if len(rows) >= 2:
        for key in ("batched_cpu", "no_refine_cpu"):
            slope, intercept = np.polyfit(n, [r[key] for r in rows], 1)
            fit = np.polyval([slope, intercept], n)
            resid = np.max(np.abs(fit - [r[key] for r in rows]))
            text += (
                f"\nLeast-squares line through `{key}`: {intercept:.2f} ms + {slope * 1000:.1f} "
                f"µs per object (largest residual {resid:.2f} ms).\n"
            )
    return text


def plot(rows: list[dict[str, float]], path: Path) -> None:
    """CPU ms per frame against objects, one polyline per variant, drawn with OpenCV."""
    width, height, margin = 900, 560, 70
    img = np.full((height, width, 3), 255, np.uint8)
    n = np.array([r["objects"] for r in rows], float)
    series: list[tuple[str, str, tuple[int, int, int]]] = [
        ("per object", "per_object_cpu", (40, 40, 200)),
        ("batched", "batched_cpu", (180, 90, 20)),
        ("no refine", "no_refine_cpu", (40, 150, 40)),
    ]
    y_max = max(max(r[key] for r in rows) for _, key, _ in series) * 1.1
    x_max = max(n.max(), 1.0)

    def to_px(xv: float, yv: float) -> tuple[int, int]:
        px = margin + (width - 2 * margin) * xv / x_max
        py = height - margin - (height - 2 * margin) * yv / y_max
        return int(round(px)), int(round(py))

    font = cv2.FONT_HERSHEY_SIMPLEX
    cv2.line(img, to_px(0, 0), to_px(x_max, 0), (0, 0, 0), 1, cv2.LINE_AA)
    cv2.line(img, to_px(0, 0), to_px(0, y_max), (0, 0, 0), 1, cv2.LINE_AA)
    for xv in np.linspace(0, x_max, 6):
        p = to_px(xv, 0)
        cv2.line(img, p, (p[0], p[1] + 5), (0, 0, 0), 1)
        cv2.putText(img, f"{xv:.0f}", (p[0] - 10, p[1] + 22), font, 0.45, (0, 0, 0), 1, cv2.LINE_AA)
    for yv in np.linspace(0, y_max, 6):
        p = to_px(0, yv)
        cv2.line(img, (p[0] - 5, p[1]), p, (0, 0, 0), 1)
        cv2.putText(img, f"{yv:.1f}", (p[0] - 50, p[1] + 5), font, 0.45, (0, 0, 0), 1, cv2.LINE_AA)
    cv2.putText(img, "objects in view", (width // 2 - 60, height - 20), font, 0.55, (0, 0, 0), 1,
                cv2.LINE_AA)  # fmt: skip
    cv2.putText(img, "CPU ms per frame of Tracker.update (1280x720, 100 particles)",
                (margin, 30), font, 0.55, (0, 0, 0), 1, cv2.LINE_AA)  # fmt: skip
    for k, (label, key, colour) in enumerate(series):
        pts = np.array([to_px(xv, r[key]) for xv, r in zip(n, rows, strict=True)], np.int32)
        cv2.polylines(img, [pts], False, colour, 2, cv2.LINE_AA)
        for p in pts:
            cv2.circle(img, (int(p[0]), int(p[1])), 4, colour, -1, cv2.LINE_AA)
        cv2.line(img, (margin + 20, 55 + 22 * k), (margin + 50, 55 + 22 * k), colour, 2)
        cv2.putText(img, label, (margin + 58, 60 + 22 * k), font, 0.5, colour, 1, cv2.LINE_AA)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_image(path, img)  # any name, atomically (pftrack.io.opencv_io)


def main(argv: Sequence[str] | None = None, measure_fn: Callable[..., list] = measure) -> None:
    """Run the experiment and write its table, CSV and plot to ``--out``."""
    parser = experiment_parser("cost_per_object", __doc__)
    parser.add_argument(
        "--counts",
        default=",".join(map(str, COUNTS)),
        help=f"object counts, comma-separated (default: {','.join(map(str, COUNTS))})",
    )
    args = parser.parse_args(argv)
    try:
        counts = [int(c) for c in args.counts.split(",")]
    except ValueError:
        parser.error(f"--counts is {args.counts!r}, expected integers separated by commas")
    if not counts or min(counts) < 1:
        parser.error(f"--counts is {args.counts!r}, expected integers >= 1")
    out: Path = args.out
    with tee_stdout(out / "cost_per_object.txt"):
        rows = measure_fn(counts)
    write_text(out / "cost_per_object.md", table(rows))
    keys = list(rows[0])
    csv = ",".join(keys) + "\n" + "\n".join(",".join(f"{r[k]:g}" for k in keys) for r in rows)
    write_text(out / "cost_per_object.csv", csv + "\n")
    plot(rows, out / "cost_per_object.png")
    print(f"-> {out}/cost_per_object.{{md,csv,png}}")


if __name__ == "__main__":
    main()
