"""Bagging ``auto``'s choice: the seed sweep of :mod:`experiments.auto_seeds` per variant.

For each variant (``bags=K``: the choice made on K bootstrap resamples of the validation gaps
and the methods' weights averaged, :data:`pftrack.recovery.calibrate.BAGS`; ``bags=0``: one
choice, the rule before bagging), ``auto`` is scored on the five development sequences (3
automatic masks each, as ``pftrack experiment gaps``) and the synthetic scenes
``make_scene(n_frames=300, n_walkers=12, rng=0..2)`` with calibration seeds ``0..N-1``; the
fixed methods once. Per-gap errors are cached in ``--out`` (``cache.json``), so a variant
already run is not run again. Prints, per variant, the table of :mod:`experiments.auto_seeds`,
then the adoption rule against the first variant: pooled MMAE of the real sequences (mean
over seeds) falls, no sequence's seed-mean rises by more than 1 %, nothing worse than
``linear`` with any seed.

Usage (from the repository root)::

    python -m experiments.auto_bagging [--data ../shared/data] [--seeds 6] [--bags 0 16]
        [--out out/auto_bagging]
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from typing import Any

import numpy as np

import pftrack.recovery.calibrate as cal_mod
from experiments._common import data_root, experiment_parser, tee_stdout
from experiments.auto_seeds import FIXED, SEQUENCES, SeedRow, format_rows, scenes
from pftrack._typing import F64
from pftrack.recovery.experiment import auto_masks, run_mask


def gap_errors(
    trajs: dict[int, F64],
    masks: Sequence[Sequence[float]],
    methods: Sequence[str],
    seed: int = 0,
) -> dict[str, list[float]]:
    """Per-gap mean Euclidean error of each method over the masks, in mask order."""
    errors: dict[str, list[float]] = {m: [] for m in methods}
    for mk in masks:
        run = run_mask(trajs, mk, methods, seed=seed)
        for m in methods:
            for g, p in zip(run.gaps, run.paths.get(m, []), strict=True):
                errors[m].append(float(np.mean(g.errors(p))))
    return errors


def _forcing(calibrate: Any, bags: int) -> Any:
    """`calibrate` with `bags` whatever its caller passes."""

    def run(*args: Any, **kwargs: Any) -> Any:
        kwargs["bags"] = bags
        return calibrate(*args, **kwargs)

    return run


def main(argv: Sequence[str] | None = None) -> int:
    ap = experiment_parser("auto_bagging", __doc__)
    ap.add_argument("--seeds", type=int, default=6, help="calibration seeds 0..N-1 (default 6)")
    ap.add_argument(
        "--bags", type=int, nargs="+", default=[0, cal_mod.BAGS], help="variants (bags)"
    )
    args = ap.parse_args(argv)
    seeds = list(range(args.seeds))
    args.out.mkdir(parents=True, exist_ok=True)
    cache_file = args.out / "cache.json"
    cache: dict[str, Any] = json.loads(cache_file.read_text()) if cache_file.is_file() else {}
    original = cal_mod.calibrate
    real = [n for n, _ in SEQUENCES]
    tables = {}
    for name, trajs, w, h in scenes(data_root(args.data)):
        entry = cache.setdefault(name, {})
        if "masks" not in entry:
            entry["masks"] = [list(m) for m in auto_masks(trajs, w, h, 3)]
            entry["fixed"] = gap_errors(trajs, entry["masks"], FIXED)
        for bags in args.bags:
            for s in seeds:
                key = f"bags={bags} seed={s}"
                if key in entry:
                    continue
                cal_mod.calibrate = _forcing(original, bags)  # type: ignore[assignment]
                try:
                    entry[key] = gap_errors(trajs, entry["masks"], ("auto",), s)["auto"]
                finally:
                    cal_mod.calibrate = original  # type: ignore[assignment]
                cache_file.write_text(json.dumps(cache))
                print(f"{name} {key}: {np.mean(entry[key]):.3f}", flush=True)
    with tee_stdout(args.out / "bagging.txt"):
        for bags in args.bags:
            rows = []
            for name, entry in cache.items():
                fixed = {m: float(np.mean(v)) for m, v in entry["fixed"].items()}
                auto = tuple(float(np.mean(entry[f"bags={bags} seed={s}"])) for s in seeds)
                rows.append(SeedRow(name, len(entry["fixed"]["linear"]), fixed, auto))
            tables[bags] = rows
            print(f"\nbags={bags}")
            print(format_rows(rows, seeds, real))
        ref = tables[args.bags[0]]
        for bags in args.bags[1:]:
            print(f"\nbags={bags} against bags={args.bags[0]} (seed means)")
            print(rule(ref, tables[bags], real))
    return 0


def rule(before: Sequence[SeedRow], after: Sequence[SeedRow], real: Sequence[str]) -> str:
    """Seed-mean per sequence before -> after, pooled, and whether the adoption rule passes."""
    lines = []
    ok = True
    for b, a in zip(before, after, strict=True):
        mb, ma = float(np.mean(b.auto)), float(np.mean(a.auto))
        worse = [s for s, v in enumerate(a.auto) if v > a.fixed["linear"]]
        rise = ma > 1.01 * mb
        ok = ok and not rise and not worse
        flag = (" RISES >1%" if rise else "") + (
            f" worse than linear: seeds {worse}" if worse else ""
        )
        lines.append(f"{b.name:<14}{mb:>8.3f} -> {ma:>8.3f} ({100 * (ma / mb - 1):+.1f} %){flag}")

    def pooled(rows: Sequence[SeedRow]) -> float:
        pool = [r for r in rows if r.name in real]
        n = sum(r.n_gaps for r in pool)
        return float(
            np.mean([sum(r.n_gaps * r.auto[k] for r in pool) / n for k in range(len(pool[0].auto))])
        )

    pb, pa = pooled(before), pooled(after)
    ok = ok and pa < pb
    lines.append(
        f"{'pooled (real)':<14}{pb:>8.3f} -> {pa:>8.3f}   rule {'PASSES' if ok else 'FAILS'}"
    )
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main())
