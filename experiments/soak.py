"""Soak: memory of a long tracking run (PETS09-S2L1 looped) and of a 100-object frame.

* ``video``: the PETS09-S2L1 video (795 frames, 480x360) played again and again into one
  :class:`~pftrack.tracking.MultiObjectTracker` (built-in detector, default configuration, seed
  0) through ``update``, for ``--frames`` frames (default 10 000). The resident set size (RSS,
  ``/proc/self/statm``) is sampled every ``--every`` frames; after a warm-up of ``--warmup``
  frames it must stay within 5 % of its value at the end of the warm-up.
* ``crowd``: one synthetic 480x360 frame with 100 public detections on a grid, jittered each
  frame, tracked for ``--crowd-frames`` frames: the same check.

Falls back to a synthetic scene when the data is absent. Prints a table and writes it, with
every sample, to ``soak.txt`` in ``--out`` (default ``out/soak``).

Usage (from the repository root)::

    python -m experiments.soak [--data ../shared/data] [--frames 10000] [--out out/soak]
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from experiments._common import data_root, experiment_parser, tee_stdout

TOLERANCE = 0.05  # RSS growth allowed after the warm-up


def rss_mib() -> float:
    """Resident set size of this process in MiB (Linux ``/proc/self/statm``)."""
    with open("/proc/self/statm") as fh:
        pages = int(fh.read().split()[1])
    return pages * os.sysconf("SC_PAGE_SIZE") / 2**20


@dataclass(frozen=True)
class Soak:
    """RSS samples of one run."""

    name: str
    frames: list[int]
    rss: list[float]
    warmup: int
    seconds: float
    objects: int  # tracks reported on the last frame

    @property
    def base(self) -> float:
        """RSS at the end of the warm-up (the first sample at or after it)."""
        return next(r for f, r in zip(self.frames, self.rss, strict=True) if f >= self.warmup)

    @property
    def growth(self) -> float:
        """Largest relative RSS increase over :attr:`base` after the warm-up."""
        after = [r for f, r in zip(self.frames, self.rss, strict=True) if f >= self.warmup]
        return max(after) / self.base - 1.0

    @property
    def flat(self) -> bool:
        """Growth within :data:`TOLERANCE`."""
        return self.growth <= TOLERANCE

    def row(self) -> str:
        """One line of the table."""
        return (
            f"{self.name:6s} {self.frames[-1]:6d} frames in {self.seconds:7.1f} s, "
            f"{self.objects:3d} tracks on the last  RSS "
            f"{self.rss[0]:6.1f} -> {self.base:6.1f} (after {self.warmup}) -> "
            f"{self.rss[-1]:6.1f} MiB, max growth {100 * self.growth:+.2f} %  "
            f"{'flat' if self.flat else 'GROWING'}"
        )


def soak(
    name: str,
    frames: Iterator[tuple[NDArray[np.uint8], Any]],
    n_frames: int,
    every: int,
    warmup: int,
    tracker: Any = None,
) -> Soak:
    """Feed `n_frames` frames (and detections) to one tracker, sampling RSS every `every`."""
    from pftrack.tracking import MultiObjectTracker

    tracker = tracker if tracker is not None else MultiObjectTracker(rng=0)
    seen, rss = [0], [rss_mib()]
    reported: list[Any] = []
    t0 = time.perf_counter()
    for k in range(1, n_frames + 1):
        frame, dets = next(frames)
        reported = tracker.update(frame, dets)
        if k % every == 0 or k == n_frames:
            seen.append(k)
            rss.append(rss_mib())
    return Soak(name, seen, rss, warmup, time.perf_counter() - t0, len(reported))


def looped_video(source: Path | Callable[[], Any]) -> Iterator[tuple[NDArray[np.uint8], None]]:
    """The frames of `source` (a video or a callable giving frames) again and again."""
    from pftrack.io.video import FrameSource

    while True:
        frames = FrameSource(source) if isinstance(source, Path) else source()
        for frame in frames:
            yield np.asarray(frame), None


def crowd(n: int = 100, seed: int = 0) -> Iterator[tuple[NDArray[np.uint8], NDArray[np.float64]]]:
    """One textured 480x360 frame with `n` coloured boxes on a grid; detections jitter."""
    rng = np.random.default_rng(seed)
    frame = rng.integers(0, 255, (360, 480, 3), dtype=np.uint8)
    cols = int(np.ceil(np.sqrt(n)))
    boxes = np.array([[8 + 46 * (k % cols), 6 + 34 * (k // cols), 20, 28] for k in range(n)], float)
    for k, (x, y, w, h) in enumerate(boxes.astype(int)):
        frame[y : y + h, x : x + w] = rng.integers(0, 255, 3, dtype=np.uint8) if k else 255
    while True:
        yield frame, boxes + rng.normal(0, 0.5, boxes.shape)


def main(argv: list[str] | None = None) -> int:
    """Run both soaks; exit 1 if either grows by more than 5 %."""
    parser = experiment_parser("soak", __doc__)
    parser.add_argument("--frames", type=int, default=10_000, help="frames of the video soak")
    parser.add_argument("--warmup", type=int, default=1000, help="frames before the baseline")
    parser.add_argument("--every", type=int, default=250, help="frames between RSS samples")
    parser.add_argument("--crowd-frames", type=int, default=1000, help="frames of the crowd soak")
    args = parser.parse_args(argv)
    video = data_root(args.data) / "pets09-s2l1" / "video.avi"
    args.out.mkdir(parents=True, exist_ok=True)
    with tee_stdout(args.out / "soak.txt"):
        if video.is_file():
            source: Path | Callable[[], Any] = video
            name = "pets"
        else:
            from pftrack.synthetic import make_scene

            scene = make_scene(n_frames=200, rng=0)
            source, name = (lambda: scene.frames), "synth"
        runs = [
            soak(name, looped_video(source), args.frames, args.every, args.warmup),
            soak("crowd", crowd(), args.crowd_frames, max(args.crowd_frames // 20, 1),
                 args.crowd_frames // 5),
        ]  # fmt: skip
        print(f"RSS soak (tolerance {100 * TOLERANCE:.0f} % after the warm-up)")
        for r in runs:
            print(r.row())
        for r in runs:
            print(
                f"{r.name} samples (frame: MiB): "
                + ", ".join(f"{f}: {v:.1f}" for f, v in zip(r.frames, r.rss, strict=True))
            )
    return 0 if all(r.flat for r in runs) else 1


if __name__ == "__main__":
    raise SystemExit(main())
