"""``auto``'s replacement rule at other thresholds, on the sequences and their perturbed copies.

``auto`` replaces a straight line only where a method wins a paired test on the validation
gaps: a mean paired error lower by more than ``PAIRED_Z`` standard errors and by
``LINEAR_MARGIN`` of linear's (:mod:`pftrack.recovery.calibrate`, 2 and 1 %). A stricter rule
keeps more straight lines: fewer sequences where ``auto`` ends up worse than ``linear`` (the
held-out goal of issue 12), at some cost where another method really is better. This script
measures that trade on every source of ``experiments.auto_seeds`` (the five development
sequences and the three synthetic scenes), as they are and perturbed as
``experiments.perturbed_gaps`` perturbs them (``pan`` and ``halffps`` once, they draw nothing;
``shake`` and ``jitter`` with each of ``--seeds``), each scored with ``auto`` and ``linear`` by
the protocol of ``pftrack experiment gaps`` (calibration seed 0).

For each (Z, margin) it prints ``auto``'s MMAE on each unperturbed sequence, the gap-weighted
MMAE of the unperturbed and of the perturbed sequences, and the sequences where ``auto`` is
worse than ``linear``; written to ``rule_thresholds.txt`` in ``--out``.

Usage (from the repository root)::

    python -m experiments.rule_thresholds [--data ../shared/data] [--z 2 2.5 3]
        [--margin 0.01 0.03 0.05] [--seeds 0 1 2] [--out out/rule_thresholds]
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

from experiments._common import data_root, experiment_parser, tee_stdout
from experiments.auto_seeds import sources
from experiments.perturbed_gaps import perturbed
from pftrack._typing import F64
from pftrack.recovery import calibrate
from pftrack.recovery.experiment import run_sequence, trajectories

#: The perturbations of ``experiments.perturbed_gaps`` scored here: the four its figures in
#: docs/results.md were measured on (``thirdfps`` and ``zoom`` came later).
PERTURBED = ("pan", "shake", "halffps", "jitter")
#: Perturbations that draw nothing: the same sequence with every seed, scored once.
UNSEEDED = ("pan", "halffps")

#: A source as ``experiments.auto_seeds.sources`` gives it: name, rows, width, height, fps.
Source = tuple[str, F64, float, float, float]


@dataclass(frozen=True)
class Scored:
    """One sequence's gaps, and the MMAE of ``auto`` and ``linear`` on them."""

    name: str
    perturbation: str  # "none" for the sequence as it is
    n_gaps: int
    auto: float
    linear: float


@contextlib.contextmanager
def rule(z: float, margin: float) -> Iterator[None]:
    """``calibrate.PAIRED_Z`` and ``calibrate.LINEAR_MARGIN`` set for the block, then restored."""
    before = calibrate.PAIRED_Z, calibrate.LINEAR_MARGIN
    calibrate.PAIRED_Z, calibrate.LINEAR_MARGIN = z, margin
    try:
        yield
    finally:
        calibrate.PAIRED_Z, calibrate.LINEAR_MARGIN = before


def variants(seeds: Sequence[int]) -> list[tuple[str, int]]:
    """``(perturbation, seed)`` of every distinct sequence made from one source."""
    out = [("none", seeds[0])]
    for how in PERTURBED:
        out += [(how, s) for s in (seeds[:1] if how in UNSEEDED else seeds)]
    return out


def score(srcs: Sequence[Source], z: float, margin: float, seeds: Sequence[int]) -> list[Scored]:
    """Every source and distinct perturbed copy, scored with ``auto`` under the rule (z, margin)."""
    out = []
    with rule(z, margin):
        for how, seed in variants(seeds):
            for name, rows, w, h, fps in srcs:
                if how != "none":
                    rows = perturbed(name, rows, w, h, fps, how, seed)
                label = (
                    name
                    if how == "none"
                    else f"{name}-{how}" + ("" if how in UNSEEDED else f"-s{seed}")
                )
                r = run_sequence(label, trajectories(rows), w, h, ("auto", "linear"))
                out.append(Scored(label, how, r.n_gaps, r.mmae("auto"), r.mmae("linear")))
    return out


def _pooled(rows: Sequence[Scored], attr: str) -> float:
    n = sum(r.n_gaps for r in rows)
    return sum(r.n_gaps * getattr(r, attr) for r in rows) / n if n else float("nan")


def format_table(results: dict[tuple[float, float], list[Scored]]) -> str:
    """One line per rule; then, per rule, the sequences where ``auto`` is worse than linear."""
    first = next(iter(results.values()))
    originals = [r.name for r in first if r.perturbation == "none"]
    head = f"{'Z':>4}{'margin':>7}" + "".join(f"{n[:11]:>12}" for n in originals)
    lines = [head + f"{'pool':>8}{'perturbed':>10}{'worse':>6}"]
    notes = []
    for (z, margin), rows in results.items():
        by = {r.name: r for r in rows}
        plain = [r for r in rows if r.perturbation == "none"]
        pert = [r for r in rows if r.perturbation != "none"]
        worse = [r for r in rows if r.auto > r.linear]
        lines.append(
            f"{z:>4g}{margin:>7g}" + "".join(f"{by[n].auto:>12.3f}" for n in originals)
            + f"{_pooled(plain, 'auto'):>8.3f}{_pooled(pert, 'auto'):>10.3f}{len(worse):>6}"
        )  # fmt: skip
        notes.append(
            f"Z={z:g} margin={margin:g}: worse than linear on "
            + (", ".join(f"{r.name} ({r.auto:.3f} > {r.linear:.3f})" for r in worse) or "none")
        )
    lines.append(
        f"{'linear':>11}" + "".join(f"{r.linear:>12.3f}" for r in first if r.name in originals)
        + f"{_pooled([r for r in first if r.perturbation == 'none'], 'linear'):>8.3f}"
        + f"{_pooled([r for r in first if r.perturbation != 'none'], 'linear'):>10.3f}"
    )  # fmt: skip
    n_seq = len(first)
    lines.append(
        f"(auto's MMAE in px; pool: the {len(originals)} sequences as they are, gap-weighted; "
        f"perturbed: their {n_seq - len(originals)} distinct perturbed copies; worse: of all "
        f"{n_seq}, those where auto is worse than linear)"
    )
    return "\n".join(lines + notes)


def main(argv: Sequence[str] | None = None) -> int:
    ap = experiment_parser("rule_thresholds", __doc__)
    ap.add_argument(
        "--z", type=float, nargs="+", default=[2.0, 2.5, 3.0],
        help="standard errors of the paired test (default: 2 2.5 3)",
    )  # fmt: skip
    ap.add_argument(
        "--margin", type=float, nargs="+", default=[0.01, 0.03, 0.05],
        help="least share of linear's error to win by (default: 0.01 0.03 0.05)",
    )  # fmt: skip
    ap.add_argument(
        "--seeds", type=int, nargs="+", default=[0, 1, 2],
        help="seeds of shake and jitter (default: 0 1 2)",
    )  # fmt: skip
    args = ap.parse_args(argv)
    if any(z < 0 for z in args.z) or any(not 0 <= m < 1 for m in args.margin):
        ap.error("--z must be >= 0 and --margin in [0, 1)")
    if any(s < 0 for s in args.seeds):
        ap.error("--seeds must be >= 0")
    srcs = sources(data_root(args.data))
    results = {(z, m): score(srcs, z, m, args.seeds) for z in args.z for m in args.margin}
    with tee_stdout(args.out / "rule_thresholds.txt"):
        print(format_table(results))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
