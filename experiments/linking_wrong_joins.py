"""Wrong joins of ``pftrack smooth``'s linker on the five ground truths cut into fragments.

Each ground truth (rows of conf 0 left out) is cut into fragments of 10-59 frames with holes of
1-14 frames, each fragment a new id (a tracker that loses people often); with ``--swap`` a share
of the fragments also exchange their tails with another fragment that overlaps them in time (a
ByteTrack-like identity switch). The fragments are linked as ``pftrack smooth`` links them
(:func:`~pftrack.recovery.linking.link_config_for` with ``--max-gap 30``, no video) and
smoothed (:func:`~pftrack.tracking.smooth_tracks`). A wrong join is an output id holding two
ground-truth identities where no input id did (the identity rides in column 8). Prints, per
sequence, fragments, joins made, wrong joins and IDF1 / HOTA of the fragments and of the
output; written to ``joins.txt`` in ``--out``.

Usage (from the repository root)::

    python -m experiments.linking_wrong_joins [--data ../shared/data] [--seed 0]
        [--swap 0 0.1] [--out out/linking_wrong_joins]
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from experiments._common import data_root, experiment_parser, tee_stdout
from pftrack._typing import F64
from pftrack.eval import evaluate_sequence
from pftrack.io.mot import read_mot
from pftrack.recovery.linking import link_config_for, link_tracklets
from pftrack.tracking import smooth_tracks

SEQUENCES = {
    "PETS09-S2L1": "pets09-s2l1",
    "TUD-Campus": "tud-campus",
    "ADL-Rundle-6": "mot15-gt/ADL-Rundle-6",
    "ETH-Sunnyday": "mot15-gt/ETH-Sunnyday",
    "KITTI-17": "mot15-gt/KITTI-17",
}


def fragment(gt: F64, rng: np.random.Generator, swap: float = 0.0) -> F64:
    """`gt` cut into fragments (new ids), the true id in column 8, sorted by (frame, id)."""
    rows = []
    nid = 100_000
    for tid in np.unique(gt[:, 1]).astype(int):
        r = gt[gt[:, 1] == tid]
        r = r[np.argsort(r[:, 0])]
        pos = 0
        while pos < len(r):
            seg = r[pos : pos + int(rng.integers(10, 60))].copy()
            nid += 1
            seg[:, 1], seg[:, 7] = nid, tid
            rows.append(seg)
            pos += len(seg) + int(rng.integers(1, 15))
    frag = np.vstack(rows)
    ids = np.unique(frag[:, 1])
    for _ in range(int(swap * len(ids))):
        a, b = rng.choice(ids, 2, replace=False)
        fa, fb = frag[frag[:, 1] == a, 0], frag[frag[:, 1] == b, 0]
        lo, hi = max(fa.min(), fb.min()), min(fa.max(), fb.max())
        if hi - lo < 4:
            continue
        t = rng.integers(lo + 1, hi)
        ma = (frag[:, 1] == a) & (frag[:, 0] >= t)
        mb = (frag[:, 1] == b) & (frag[:, 0] >= t)
        frag[ma, 1], frag[mb, 1] = b, a
    out: F64 = frag[np.lexsort((frag[:, 1], frag[:, 0]))]
    return out


def mixed(rows: F64) -> int:
    """Ids whose rows hold more than one true identity (column 8; filled rows, -1, skipped)."""
    return sum(
        len(np.unique(rows[(rows[:, 1] == i) & (rows[:, 7] > 0), 7])) > 1
        for i in np.unique(rows[:, 1])
    )


def main(argv: Sequence[str] | None = None) -> int:
    ap = experiment_parser("linking_wrong_joins", __doc__)
    ap.add_argument("--seed", type=int, default=0, help="seed of the cuts and swaps")
    ap.add_argument("--swap", type=float, nargs="+", default=[0.0, 0.1],
                    help="shares of fragments whose tails are swapped (default 0 0.1)")  # fmt: skip
    args = ap.parse_args(argv)
    root = data_root(args.data)
    with tee_stdout(args.out / "joins.txt"):
        for swap in args.swap:
            for name, sub in SEQUENCES.items():
                if not (root / sub / "gt.txt").is_file():
                    continue
                gt = read_mot(root / sub / "gt.txt")
                gt = gt[gt[:, 6] != 0]
                frag = fragment(gt, np.random.default_rng(args.seed), swap)
                cfg = link_config_for(frag, 30, None)
                linked, mapping = link_tracklets(frag, cfg)
                out = smooth_tracks(frag, link=cfg, max_gap=30)
                s0, s1 = evaluate_sequence(gt, frag), evaluate_sequence(gt, out)
                print(
                    f"swap {swap:g} {name:<13} fragments {len(np.unique(frag[:, 1])):4d} "
                    f"joins {len(mapping):4d} wrong {mixed(linked) - mixed(frag):3d}  "
                    f"IDF1 {100 * s0.mot.idf1:5.1f} -> {100 * s1.mot.idf1:5.1f}  "
                    f"HOTA {100 * s0.hota.hota:5.1f} -> {100 * s1.hota.hota:5.1f}",
                    flush=True,
                )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
