"""Test inputs shared by the tests of tests/eval (no TrackEval needed to import them)."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def write_rows(path: Path, rows: np.ndarray) -> Path:
    """MOT rows with every digit (so TrackEval and pftrack read the same numbers)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("".join(",".join(repr(float(v)) for v in r) + "\n" for r in rows))
    return path


def perturbed(gt: np.ndarray, seed: int) -> np.ndarray:
    """Ground truth as a tracker's output: jitter, misses, id switches, new ids, clutter."""
    rng = np.random.default_rng(seed)
    keep = rng.random(len(gt)) > 0.15
    r = gt[keep].copy()
    r[:, 2:6] += rng.normal(0, 0.08, (len(r), 4)) * r[:, [4, 5, 4, 5]]
    r[:, 4:6] = np.abs(r[:, 4:6])
    ids = r[:, 1].copy()
    for a, b in rng.choice(np.unique(ids), (3, 2)):  # swap ids over a stretch
        lo = rng.integers(r[:, 0].min(), r[:, 0].max())
        s = (r[:, 0] > lo) & (r[:, 0] < lo + 30)
        ia, ib = s & (ids == a), s & (ids == b)
        r[ia, 1], r[ib, 1] = b, a
    late = r[:, 0] > np.median(r[:, 0])
    r[late & (r[:, 1] % 3 == 0), 1] += 1000  # fragments under new ids
    clutter = r[rng.choice(len(r), len(r) // 10)].copy()
    clutter[:, 1] = 5000 + np.arange(len(clutter))
    clutter[:, 2:4] += rng.uniform(-60, 60, (len(clutter), 2))
    r = np.vstack([r, clutter])
    _, first = np.unique(r[:, :2], axis=0, return_index=True)
    r = r[np.sort(first)]
    r[:, 6:] = [1.0, -1.0, -1.0, -1.0]
    return r
