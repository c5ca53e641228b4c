"""The Python share of ``pftrack.Tracker.update``'s time per frame (issues 13 and 17).

The scene and loop of ``bench/test_api.py`` (the synthetic 480x360 scene of 10 walkers, their
true boxes given as ``x1, y1, x2, y2, conf``, frames 21-80 timed, each a fresh tracker with
seed 0): every function and method of ``pftrack._core`` and the OpenCV functions on the path
are wrapped in a timer, and the Python time of a frame is ``update``'s wall time less the time
spent inside those compiled calls (the outermost one only, when they nest). Each frame's least
Python time over the rounds is kept, as the bench keeps each frame's least CPU time, and the
means over frames are printed for the defaults and without box refinement.

The wrappers add a little to the Python time (the same for any version of the tracker): the
figure is for comparing two versions run alternately, not an absolute cost.

Usage (from the repository root)::

    python -m experiments.python_share [--rounds 7]
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from typing import Any

import cv2
import numpy as np

from experiments.cost_per_object import new_tracker
from pftrack import _core
from pftrack.io.mot import group_by_frame
from pftrack.synthetic import make_scene

WARM = 20  # untimed frames, as in bench/test_api.py
OPENCV = (
    "calcOpticalFlowPyrLK",
    "estimateAffinePartial2D",
    "cvtColor",
    "resize",
    "goodFeaturesToTrack",
    "morphologyEx",
)


class CompiledTimer:
    """Seconds spent inside the wrapped compiled calls since the last :meth:`reset`."""

    def __init__(self) -> None:
        self.seconds = 0.0
        self._depth = 0

    def reset(self) -> None:
        self.seconds = 0.0

    def wrap(self, fn: Callable[..., Any]) -> Callable[..., Any]:
        """`fn` timed (only the outermost of nested compiled calls counts)."""

        def timed(*args: Any, **kwargs: Any) -> Any:
            if self._depth:
                return fn(*args, **kwargs)
            self._depth += 1
            start = time.perf_counter()
            try:
                return fn(*args, **kwargs)
            finally:
                self.seconds += time.perf_counter() - start
                self._depth -= 1

        return timed

    def install(self) -> None:
        """Wrap ``pftrack._core``'s functions and classes' methods, and :data:`OPENCV`."""
        for name in dir(_core):
            obj = getattr(_core, name)
            if callable(obj) and not isinstance(obj, type) and not name.startswith("_"):
                setattr(_core, name, self.wrap(obj))
            elif isinstance(obj, type):
                for meth in dir(obj):
                    fn = getattr(obj, meth, None)
                    if meth.startswith("_") or not callable(fn) or isinstance(fn, type):
                        continue
                    try:
                        setattr(obj, meth, self._method(fn))
                    except (AttributeError, TypeError):  # read-only attributes
                        pass
        for name in OPENCV:
            setattr(cv2, name, self.wrap(getattr(cv2, name)))

    def _method(self, fn: Callable[..., Any]) -> Callable[..., Any]:
        timed = self.wrap(fn)

        def method(obj: Any, *args: Any, **kwargs: Any) -> Any:
            return timed(obj, *args, **kwargs)

        return method


def scene_dets() -> tuple[list[np.ndarray], list[np.ndarray]]:
    """The bench's frames and detections (``x1, y1, x2, y2, conf``)."""
    scene = make_scene(n_frames=80, n_walkers=10, rng=0, occluder=False)
    by_frame = group_by_frame(scene.truth)
    dets = []
    for n in range(1, len(scene.frames) + 1):
        r = by_frame.get(n, np.zeros((0, 10)))
        dets.append(np.column_stack([r[:, 2:4], r[:, 2:4] + r[:, 4:6], np.full(len(r), 0.9)]))
    return scene.frames, dets


def one_round(
    timer: CompiledTimer, frames: list[np.ndarray], dets: list[np.ndarray], refine: bool
) -> tuple[list[float], list[float]]:
    """Wall and Python seconds of each timed ``update`` of one fresh tracker."""
    tracker = new_tracker(refine=refine)
    for k in range(WARM):
        tracker.update(dets[k], frames[k])
    wall, python = [], []
    for k in range(WARM, len(frames)):
        timer.reset()
        start = time.perf_counter()
        tracker.update(dets[k], frames[k])
        took = time.perf_counter() - start
        wall.append(took)
        python.append(took - timer.seconds)
    return wall, python


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(
        prog="python -m experiments.python_share",
        description=__doc__.splitlines()[0],
        allow_abbrev=False,
    )
    ap.add_argument("--rounds", type=int, default=7, help="rounds per case (default 7)")
    args = ap.parse_args(argv)
    if args.rounds < 1:
        ap.error(f"--rounds is {args.rounds}, expected at least 1")
    frames, dets = scene_dets()
    timer = CompiledTimer()
    timer.install()
    for refine, label in ((True, "default"), (False, "no refine")):
        runs = [one_round(timer, frames, dets, refine) for _ in range(args.rounds)]
        wall = 1000 * float(np.mean(np.min([r[0] for r in runs], axis=0)))
        python = 1000 * float(np.mean(np.min([r[1] for r in runs], axis=0)))
        compiled = wall - python
        print(f"{label}: wall {wall:.3f} ms, Python {python:.3f} ms, compiled {compiled:.3f} ms")


if __name__ == "__main__":
    main()
