"""Linking + filling on PETS09-S2L1 ground truth cut into fragments (a synthetic tracker output).

Every ground-truth track is cut into fragments of 40-119 frames separated by holes of 3-19
frames; each fragment after the first gets a new id. ``link_tracklets`` should join fragments
of one person (and no others), ``fill_gaps`` should put the removed boxes back. Prints the
links made (and how many are right) and the centre error of the filled boxes; the same lines
go to ``linking.txt`` in ``--out`` (default ``out/recovery_linking_pets``).

Usage (from the repository root)::

    python -m experiments.recovery_linking_pets [--data ../shared/data] [--seed 0]
        [--method gdt-bi] [--out out/recovery_linking_pets]
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from experiments._common import data_root, experiment_parser, tee_stdout
from pftrack.io.mot import read_mot
from pftrack.recovery import FLAG_COLUMN, LinkConfig, fill_gaps, link_tracklets


def main(argv: Sequence[str] | None = None) -> int:
    ap = experiment_parser("recovery_linking_pets", __doc__)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--method", default="gdt-bi")
    args = ap.parse_args(argv)
    with tee_stdout(args.out / "linking.txt"):
        link_and_fill(data_root(args.data) / "pets09-s2l1" / "gt.txt", args.seed, args.method)
    return 0


def link_and_fill(path: Path, seed: int, method: str) -> None:
    """Cut the ground truth of `path` into fragments, link and fill them, print the scores."""
    gt = read_mot(path)
    rng = np.random.default_rng(seed)
    rows, cut_rows = [], []
    owner: dict[int, int] = {}
    next_id = 1000
    for tid in np.unique(gt[:, 1]).astype(int):
        r = gt[gt[:, 1] == tid]
        r = r[np.argsort(r[:, 0])]
        pos, cur = 0, tid
        while pos < len(r):
            n = int(rng.integers(40, 120))
            seg = r[pos : pos + n].copy()
            seg[:, 1] = cur
            owner[cur] = tid
            rows.append(seg)
            pos += n
            gap = int(rng.integers(3, 20))
            cut_rows.append(r[pos : pos + gap])
            pos += gap
            next_id += 1
            cur = next_id
    frag = np.vstack(rows)
    n_frag = len(np.unique(frag[:, 1]))
    true_joins = n_frag - len(np.unique(gt[:, 1]))
    t0 = time.perf_counter()
    linked, mapping = link_tracklets(frag, LinkConfig(max_gap=20, max_distance=50))
    t1 = time.perf_counter()
    correct = sum(owner[o] == owner[n] for o, n in mapping.items())
    print(
        f"fragments {n_frag}, true joins {true_joins}, links made {len(mapping)}, "
        f"correct {correct} ({1e3 * (t1 - t0):.1f} ms)"
    )
    t0 = time.perf_counter()
    filled, rep = fill_gaps(linked, method, max_gap=20)
    t1 = time.perf_counter()
    cut = np.vstack([c for c in cut_rows if len(c)])
    errs = []
    for row in filled[filled[:, FLAG_COLUMN] == 1]:
        m = cut[(cut[:, 0] == row[0]) & (cut[:, 1] == owner[int(row[1])])]
        if len(m):
            c = np.array([row[2] + row[4] / 2, row[3] + row[5] / 2])
            ct = np.array([m[0, 2] + m[0, 4] / 2, m[0, 3] + m[0, 5] / 2])
            errs.append(float(np.hypot(*(c - ct))))
    print(
        f"{rep.n_gaps} gaps, {rep.n_filled_rows} rows filled ({method}, "
        f"{1e3 * (t1 - t0):.1f} ms incl. noise estimation); {len(errs)} match a removed box: "
        f"mean centre error {np.mean(errs):.2f} px, median {np.median(errs):.2f} px"
    )


if __name__ == "__main__":
    raise SystemExit(main())
