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


def edge_case(rng: np.random.Generator, benchmark: str) -> tuple[np.ndarray, np.ndarray]:
    """Random ground truth and result with the edge cases a scorer can get wrong.

    Ground truth: walkers whose ids come back after a gap, holes, boxes of zero width or
    height, flags 0 and not integers (0.3 is 0 to TrackEval), for MOT17/MOT20 other classes
    and distractors, rows out of frame order, and copies of objects under other ids on exactly
    the same boxes (ties); sometimes no object. Result: the truth jittered (or not: integer
    boxes, exact ties), missed, under new ids, with any conf; clutter reusing ids and reaching
    frames past the last of the truth, copies under other ids written before or after the
    originals, ids swapped over a stretch; sometimes no row.
    """
    n_frames = int(rng.integers(1, 40)) if rng.random() < 0.2 else int(rng.integers(15, 40))
    n_obj = int(rng.integers(1, 12)) if rng.random() > 0.05 else 0
    integer = rng.random() < 0.5
    gt = []
    for oid in range(1, n_obj + 1):
        start = int(rng.integers(1, n_frames + 1))
        end = int(rng.integers(start, n_frames + 1))
        spans = [(start, end)]
        if rng.random() < 0.3 and end + 3 <= n_frames:  # the id again after a gap
            again = int(rng.integers(end + 2, n_frames + 1))
            spans.append((again, int(rng.integers(again, n_frames + 1))))
        x, y = rng.uniform(0, 80, 2)
        v = rng.normal(0, 2, 2)
        w, h = rng.uniform(5, 30), rng.uniform(10, 50)
        cls = 1 if benchmark == "MOT15" or rng.random() < 0.7 else int(rng.integers(2, 14))
        for a, b in spans:
            for f in range(a, b + 1):
                if rng.random() < 0.1:
                    continue
                box = [x + v[0] * f, y + v[1] * f, w, h]
                box = [float(round(c)) for c in box] if integer else box
                box[2] = 0.0 if rng.random() < 0.04 else box[2]
                box[3] = 0.0 if rng.random() < 0.04 else box[3]
                r = rng.random()
                flag = 0.0 if r < 0.08 else float(rng.choice([0.3, 2.0, -1.0])) if r < 0.12 else 1.0
                extra = [-1.0, -1.0, -1.0] if benchmark == "MOT15" else [cls, rng.random(), -1.0]
                gt.append([f, oid, *box, flag, *extra])
    g = np.array(gt, dtype=float).reshape(-1, 10)
    if len(g) and rng.random() < 0.4:  # other objects on exactly the same boxes
        dup = g[rng.random(len(g)) < 0.3].copy()
        dup[:, 1] += 50
        g = np.vstack([dup, g] if rng.random() < 0.5 else [g, dup])
        g = g[np.argsort(g[:, 0], kind="stable")]
    res = []
    next_id = 100 if rng.random() < 0.7 else 1  # or the ids of the truth, for other objects
    ids: dict[int, int] = {}
    p_miss = rng.choice([0.0, 0.1, 0.2, 0.5])
    for row in g:
        if int(row[1]) not in ids or rng.random() < 0.08:
            ids[int(row[1])] = next_id
            next_id += 1
        if rng.random() < p_miss:
            continue
        box = row[2:6] + rng.normal(0, rng.choice([0.0, 0.05, 0.2]), 4) * row[[4, 5, 4, 5]]
        box[2:] = np.abs(box[2:])
        box = np.round(box) if integer else box
        conf = float(rng.choice([1.0, 0.0, 0.5, -3.0, 17.0]))  # not looked at
        cls = -1.0 if benchmark == "MOT15" or rng.random() < 0.5 else 1.0
        res.append([row[0], ids[int(row[1])], *box, conf, cls, -1.0, -1.0])
    last = n_frames + int(rng.integers(0, 3))
    for _ in range(int(rng.integers(0, 3 * n_frames))):  # clutter
        box = np.r_[rng.uniform(0, 100, 2), rng.uniform(5, 30), rng.uniform(10, 50)]
        box = np.round(box) if integer else box
        box[2] = 0.0 if rng.random() < 0.05 else box[2]
        hid = int(rng.integers(1, max(next_id, 100) + 3))
        res.append([int(rng.integers(1, last + 1)), hid, *box, 1.0, -1.0, -1.0, -1.0])
    r = np.array(res, dtype=float).reshape(-1, 10)
    if len(r) and rng.random() < 0.4:  # copies under other ids: ties
        copies = r[rng.random(len(r)) < 0.3].copy()
        copies[:, 1] += 5000
        r = np.vstack([copies, r] if rng.random() < 0.5 else [r, copies])
    if len(r) and rng.random() < 0.5 and len(np.unique(r[:, 1])) >= 2:  # swapped ids
        a, b = rng.choice(np.unique(r[:, 1]), 2, replace=False)
        lo = rng.integers(1, last + 1)
        s = (r[:, 0] >= lo) & (r[:, 0] < lo + 5)
        ia, ib = s & (r[:, 1] == a), s & (r[:, 1] == b)
        r[ia, 1], r[ib, 1] = b, a
    if len(r):
        _, first = np.unique(r[:, :2], axis=0, return_index=True)  # ids unique in a frame
        r = r[np.sort(first)]
        r = r[np.argsort(r[:, 0], kind="stable")] if rng.random() < 0.5 else r
    if rng.random() < 0.04:
        r = np.zeros((0, 10))
    if len(g) and rng.random() < 0.3:
        g = g[rng.permutation(len(g))]
    return (g if benchmark == "MOT15" else g[:, :9]), r
