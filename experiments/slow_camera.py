"""A slowly moving camera: camera motion ``off``, ``auto`` and ``on`` on slow camera paths.

docs/tracking.md, "A slowly moving camera": ``auto`` counts a frame as moving only past
`CameraConfig.threshold` (0.2 % of the diagonal a frame), so a camera that drifts more slowly
is never compensated. This measures whether compensating it (``on``: every frame's estimate
applied) would help. Rows: PETS09-S2L1 and TUD-Campus (video; truth and public detections moved
with the frames, frames warped in memory) along `experiments.size_check`'s paths (``tilt``,
``slowpan``, ``zoomout``) and along `experiments.moving_camera`'s path four times slower
(``moving/4``: `camera_path` with period 480 frames). Each row is tracked with given
detections and/or the built-in detector, camera motion ``off``, ``auto`` and ``on``, tracker
seeds 0..N-1, and scored by `pftrack.eval.evaluate_sequence` (MOTA / IDF1 / HOTA, mean over
the seeds). Each row also gives its path's motion a frame (median and largest displacement of
an image corner, pixels) against the threshold, and how many frames ``auto`` counted as moving
(seed 0).

Usage (from the repository root)::

    python -m experiments.slow_camera [--data ../shared/data] [--out DIR]
        [--detections public builtin] [--seeds 3]
"""

from __future__ import annotations

import dataclasses
import sys
import unittest.mock
import warnings
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from experiments._common import add_detections_and_seeds, data_root, experiment_parser, tee_stdout
from experiments.size_check import PATHS, Row, _Frames, cell, figures, path_affines, video_rows
from pftrack._typing import F64
from pftrack.eval import evaluate_sequence
from pftrack.io.mot import as_written
from pftrack.synthetic import camera_path
from pftrack.tracking import TrackerConfig, track_frames
from pftrack.tracking.camera import CameraMotion, CameraStep, compose, invert_affine
from pftrack.tracking.camera import motion_magnitude as magnitude

SLOW_PATHS = (*PATHS, "moving/4")
MODES = ("off", "auto", "on")


def affines_of(kind: str, n_frames: int, size: tuple[int, int]) -> F64:
    """`size_check.path_affines`, and ``moving/4``: `camera_path` with period 480 frames."""
    if kind == "moving/4":
        return camera_path(n_frames, size, period=480.0)
    return path_affines(kind, n_frames, size)


def path_motion(kind: str, n_frames: int, size: tuple[int, int]) -> tuple[float, float]:
    """Median and largest motion a frame of path `kind` (an image corner's, pixels)."""
    a = affines_of(kind, n_frames, size)
    steps = [magnitude(compose(a[k], invert_affine(a[k - 1])), size) for k in range(1, n_frames)]
    return float(np.median(steps)), float(np.max(steps))


def run(row: Row, frames: Sequence[NDArray[np.uint8]], given: bool, mode: str, seed: int
        ) -> tuple[F64, int]:  # fmt: skip
    """`row` tracked (camera motion `mode`, tracker seed `seed`): MOTA / IDF1 / HOTA in %, and
    how many frames the tracker's camera counted as moving."""
    moving: dict[int, list[bool]] = {}  # per CameraMotion (priming has a probe of its own)
    update = CameraMotion.update

    def counted(self: CameraMotion, frame: NDArray[np.uint8], exclude_xywh: object = ()
                ) -> CameraStep:  # fmt: skip
        step = update(self, frame, exclude_xywh)  # type: ignore[arg-type]
        moving.setdefault(id(self), []).append(step.moving)
        return step

    config = dataclasses.replace(TrackerConfig(), camera_motion=mode)
    with unittest.mock.patch.object(CameraMotion, "update", counted), warnings.catch_warnings():
        # expected here: the built-in detector on a moving camera, a video the model cannot
        # follow (a warped frame's borders)
        warnings.simplefilter("ignore", UserWarning)
        done = track_frames(
            frames, detections=row.detections if given else None, config=config, rng=seed
        )
    tracker = max(moving.values(), key=len, default=[])
    return figures(evaluate_sequence(row.truth, as_written(done.rows))), sum(tracker)


def main(argv: Sequence[str] | None = None) -> int:
    p = experiment_parser("slow_camera", __doc__)
    add_detections_and_seeds(p)
    args = p.parse_args(argv)
    data: Path = data_root(args.data)
    rows = list(video_rows(data, paths=SLOW_PATHS, affines_of=affines_of))
    if not rows:
        print(f"no pets09-s2l1 or tud-campus video under {data}", file=sys.stderr)
        return 2
    with tee_stdout(args.out / "slow_camera.md"):
        print(
            "| row | detections | motion a frame, px (median, max; threshold) | off | auto "
            "(moving frames, seed 0) | on |"
        )
        print("|---|---|---|---|---|---|")
        for row in rows:
            moved: Sequence[NDArray[np.uint8]] = (
                _Frames(row.frames, row.n_frames) if callable(row.frames) else row.frames
            )
            h, w = next(iter(moved)).shape[:2]
            med, top = path_motion(row.name.rsplit(" ", 1)[1], row.n_frames, (h, w))
            motion = f"{med:.2f}, {top:.2f}; {0.002 * np.hypot(h, w):.2f}"
            for det in args.detections:
                given = det == "public"
                # the built-in detector's priming takes frames by index
                frames = moved if given else list(moved)
                cells = []
                for mode in MODES:
                    done = [run(row, frames, given, mode, seed) for seed in range(args.seeds)]
                    text = cell(np.mean([d[0] for d in done], axis=0))
                    cells.append(text + (f" ({done[0][1]})" if mode == "auto" else ""))
                print(f"| {row.name} | {det} | {motion} | " + " | ".join(cells) + " |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
