"""A seeded synthetic tracks file for timing ``pftrack recover`` on a whole MOT file.

``python -m bench.recovery_file tracks.txt [--tracks 500] [--seed 0]`` writes MOTChallenge rows
of `--tracks` walkers (smooth curved paths with speed changes and short stops, box jitter,
1920x1080) with random holes of 1-40 frames cut into each track: the input of the
whole-process timing in docs/results.md (``time pftrack recover tracks.txt --out out.txt``).
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence

import numpy as np

from pftrack._typing import F64
from pftrack.io.mot import write_mot

__all__ = ["synthetic_tracks"]


def synthetic_tracks(n_tracks: int = 500, seed: int = 0, n_frames: int = 2000) -> F64:
    """MOTChallenge rows ``(M, 10)`` of `n_tracks` walkers with holes, sorted by frame and id.

    Each track lives 80-240 frames; its velocity is an Ornstein-Uhlenbeck process (a few px per
    frame), some tracks stop for 10-40 frames; box centres get 0.5 px jitter; each track loses
    0-4 holes of 1-40 frames (never its first or last 5 frames).
    """
    if n_tracks < 1:
        raise ValueError(f"synthetic_tracks: n_tracks is {n_tracks}, expected >= 1")
    rng = np.random.default_rng(seed)
    out = []
    for tid in range(1, n_tracks + 1):
        n = int(rng.integers(80, 241))
        start = int(rng.integers(1, max(2, n_frames - n)))
        v = rng.normal(0, 2.0, 2)
        p = rng.uniform([200, 200], [1700, 900])
        pts = np.empty((n, 2))
        stop = (-1, -1)
        if rng.random() < 0.3:
            t1 = int(rng.integers(10, max(11, n - 50)))
            stop = (t1, t1 + int(rng.integers(10, 41)))
        for k in range(n):
            v += -0.05 * v + rng.normal(0, 0.25, 2)
            if not stop[0] <= k < stop[1]:
                p = p + v
            pts[k] = p
        pts += rng.normal(0, 0.5, pts.shape)
        keep = np.ones(n, dtype=bool)
        for _ in range(int(rng.integers(0, 5))):
            length = int(rng.integers(1, 41))
            if n - length - 10 > 5:
                s = int(rng.integers(5, n - length - 5))
                keep[s : s + length] = False
        w, h = rng.uniform(30, 80), rng.uniform(80, 200)
        rows = np.empty((n, 10))
        rows[:, 0] = start + np.arange(n)
        rows[:, 1] = tid
        rows[:, 4] = w * (1 + 0.002 * np.arange(n))
        rows[:, 5] = h * (1 + 0.002 * np.arange(n))
        rows[:, 2] = pts[:, 0] - 0.5 * rows[:, 4]
        rows[:, 3] = pts[:, 1] - 0.5 * rows[:, 5]
        rows[:, 6] = 1.0
        rows[:, 7:] = -1.0
        out.append(rows[keep])
    a = np.vstack(out)
    result: F64 = a[np.lexsort((a[:, 1], a[:, 0]))]
    return result


def main(argv: Sequence[str] | None = None) -> None:
    """Write the file; bad arguments or an unwritable `out` are one line and exit status 2."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out", help="tracks file to write")
    p.add_argument("--tracks", type=int, default=500, help="number of tracks")
    p.add_argument("--seed", type=int, default=0, help="seed")
    args = p.parse_args(argv)
    try:
        rows = synthetic_tracks(args.tracks, args.seed)
        write_mot(args.out, rows)
    except (ValueError, OSError) as err:  # a traceback before
        p.error(str(err))
    print(f"{args.out}: {len(rows)} rows, {args.tracks} tracks")


if __name__ == "__main__":
    main()
