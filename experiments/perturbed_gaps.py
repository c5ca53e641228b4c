"""``auto`` against the fixed methods on perturbed copies of every sequence (unseen conditions).

The held-out goal of issue 12 asks for a default that is never worse than a straight line on
sequences nobody chose it on: other cameras, frame rates and annotators. This script makes
such conditions out of the data at hand. Each development sequence (the five real ones with
ground truth and the three synthetic scenes of ``experiments.auto_seeds``) is perturbed eight
ways, in memory, and scored with the multi-sequence protocol of ``pftrack experiment gaps``
(3 automatic masks per sequence, ``auto`` with calibration seed 0):

- ``pan``: a smooth camera pan, every box moved by ``0.08 W sin(2 pi t / 8 s + 1)``
  horizontally and ``0.03 H sin(2 pi t / 5 s)`` vertically (t from the frame rate);
- ``shake``: a hand-held camera, every box moved by a random walk of ``0.004 W`` per frame
  and axis, smoothed over 3 frames;
- ``halffps``: every other frame (1, 3, 5, ...), renumbered 1, 2, 3, ...: half the frame
  rate, motion per frame doubled;
- ``jitter``: a noisier annotator, each box's corner moved by ``N(0, (0.02 h)^2)`` per axis
  (h its height);
- ``thirdfps``: every third frame (1, 4, 7, ...), renumbered 1, 2, 3, ...: a 30 fps file seen
  at 10 fps, as KITTI-17 is;
- ``zoom``: a smooth zoom of the camera, every box scaled about the image centre by
  ``1 + 0.15 sin(2 pi t / 10 s)`` (its corner moved toward or away from the centre, its width
  and height scaled alike);
- ``fps14``: a 30 fps file seen at 14 fps, as ADL-Rundle-6 would be: new frame ``k`` (1, 2,
  ...) is old frame ``1 + round((k - 1) 30 / 14)``, so the steps between kept frames are 2 or
  3 old frames, unevenly (ratio 30/14 whatever the source's rate);
- ``walk``: a camera walking forward, as ETH-Sunnyday's: every box scaled about the image
  centre by ``1 + 0.5 (f - f0) / (f1 - f0)``, a drift from 1 at the file's first frame to 1.5
  at its last (not periodic, unlike ``zoom``).

The recovered paths are scored against the perturbed ground truth (what the perturbed file
holds), so ``jitter``'s errors include the jitter itself. ``shake`` and ``jitter`` draw from
``--seed``; the other six are the same with every seed (``--only shake,jitter`` runs the
ones a new seed changes). Prints, per perturbation and sequence, ``auto``, ``linear`` and the
best fixed method, ``auto``'s excess over that best, ``<`` where ``auto`` is worse than
``linear``, and the gap-weighted pool of each perturbation; then the copies where ``auto`` is
worse than ``linear`` and those where it is more than 2 % above the best fixed method; written
to ``perturbed_seedN.txt`` in ``--out``.

Usage (from the repository root)::

    python -m experiments.perturbed_gaps [--data ../shared/data] [--seed 0]
        [--only pan,shake,...] [--out out/perturbed_gaps]
"""

from __future__ import annotations

import zlib
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from experiments._common import data_root, experiment_parser, tee_stdout
from experiments.auto_seeds import FIXED, sources
from pftrack._typing import F64
from pftrack.recovery.experiment import SequenceResult, run_sequence, trajectories

#: One perturbation: (rows, width, height, fps, rng) -> perturbed rows.
Perturb = Callable[[F64, float, float, float, np.random.Generator], F64]


def _pan(rows: F64, width: float, height: float, fps: float, rng: np.random.Generator) -> F64:
    t = rows[:, 0] / fps
    out = rows.copy()
    out[:, 2] += 0.08 * width * np.sin(2 * np.pi * t / 8.0 + 1.0)
    out[:, 3] += 0.03 * height * np.sin(2 * np.pi * t / 5.0)
    return out


def _shake(rows: F64, width: float, height: float, fps: float, rng: np.random.Generator) -> F64:
    n = int(rows[:, 0].max()) + 2
    walk = np.cumsum(rng.normal(0.0, 0.004 * width, (n, 2)), axis=0)
    kernel = np.ones(3) / 3.0
    walk = np.column_stack([np.convolve(walk[:, k], kernel, "same") for k in range(2)])
    f = rows[:, 0].astype(int)
    out = rows.copy()
    out[:, 2:4] += walk[f]
    return out


def _seen_at(rows: F64, ratio: float) -> F64:
    """`rows` at 1/`ratio` of their frame rate: new frame k is old frame 1 + round((k - 1) ratio).

    A whole `ratio` keeps every ratio-th frame from the first; 30/14 steps 2 or 3 frames.
    """
    last = int(rows[:, 0].max())
    old = 1 + np.rint(np.arange(last) * ratio).astype(int)  # old frame of new frame k
    old = old[old <= last]
    new = np.full(last + 1, 0)
    new[old] = np.arange(1, len(old) + 1)
    out = rows[new[rows[:, 0].astype(int)] > 0].copy()
    out[:, 0] = new[out[:, 0].astype(int)]
    return out


def _scaled(rows: F64, s: F64, width: float, height: float) -> F64:
    """Each box scaled about the image centre by its row's `s` (corner and size alike)."""
    centre = np.array([width / 2.0, height / 2.0])
    out = rows.copy()
    out[:, 2:4] = centre + s[:, None] * (rows[:, 2:4] - centre)
    out[:, 4:6] *= s[:, None]
    return out


def _half_fps(rows: F64, width: float, height: float, fps: float, rng: np.random.Generator) -> F64:
    return _seen_at(rows, 2.0)


def _jitter(rows: F64, width: float, height: float, fps: float, rng: np.random.Generator) -> F64:
    out = rows.copy()
    out[:, 2:4] += rng.normal(0.0, 1.0, (len(out), 2)) * 0.02 * out[:, 5:6]
    return out


def _third_fps(rows: F64, width: float, height: float, fps: float, rng: np.random.Generator) -> F64:
    return _seen_at(rows, 3.0)


def _zoom(rows: F64, width: float, height: float, fps: float, rng: np.random.Generator) -> F64:
    return _scaled(rows, 1.0 + 0.15 * np.sin(2 * np.pi * rows[:, 0] / fps / 10.0), width, height)


def _fps14(rows: F64, width: float, height: float, fps: float, rng: np.random.Generator) -> F64:
    return _seen_at(rows, 30.0 / 14.0)


def _walk(rows: F64, width: float, height: float, fps: float, rng: np.random.Generator) -> F64:
    f0, f1 = rows[:, 0].min(), rows[:, 0].max()
    return _scaled(rows, 1.0 + 0.5 * (rows[:, 0] - f0) / max(f1 - f0, 1.0), width, height)


PERTURBATIONS: dict[str, Perturb] = {
    "pan": _pan,
    "shake": _shake,
    "halffps": _half_fps,
    "jitter": _jitter,
    "thirdfps": _third_fps,
    "zoom": _zoom,
    "fps14": _fps14,
    "walk": _walk,
}

#: How far above the best fixed method a copy is listed as a miss (2 %).
BEST_MARGIN = 0.02


def perturbed(
    name: str, rows: F64, width: float, height: float, fps: float, how: str, seed: int
) -> F64:
    """`rows` perturbed by `how`, drawing from `seed` and the sequence's name."""
    rng = np.random.default_rng([seed, zlib.crc32(f"{name}/{how}".encode())])
    return PERTURBATIONS[how](rows, width, height, fps, rng)


def score(
    root: Path,
    seed: int,
    methods: Sequence[str] = ("auto", *FIXED),
    only: Sequence[str] = tuple(PERTURBATIONS),
) -> dict[str, list[SequenceResult]]:
    """The perturbations `only` of every source, scored by the multi-sequence protocol."""
    srcs = sources(root)
    return {
        how: [
            run_sequence(
                f"{name}-{how}",
                trajectories(perturbed(name, rows, w, h, fps, how, seed)),
                w,
                h,
                methods,
            )
            for name, rows, w, h, fps in srcs
        ]
        for how in only
    }


def format_table(results: dict[str, list[SequenceResult]]) -> str:
    """One line per perturbed sequence, one pooled line per perturbation, then the misses."""
    lines = [
        f"{'sequence':<22}{'gaps':>5}{'auto':>8}{'linear':>8}  {'best fixed':<17}{'auto/best':>9}"
    ]
    worse: list[str] = []
    above: list[str] = []
    for how, rows in results.items():
        for r in rows:
            fixed = {m: r.mmae(m) for m in r.errors if m != "auto"}
            bm = min(fixed, key=lambda k: fixed[k])
            a, lin = r.mmae("auto"), fixed["linear"]
            mark = "<" if a > lin else " "
            if a > lin:
                worse.append(r.name)
            if a > (1 + BEST_MARGIN) * fixed[bm]:
                above.append(r.name)
            lines.append(
                f"{r.name:<22}{r.n_gaps:>5}{a:>8.3f}{lin:>8.3f}{mark} {bm:<9}{fixed[bm]:>7.3f}"
                f"{100 * (a / fixed[bm] - 1):>+8.1f}%"
            )
        n = sum(r.n_gaps for r in rows)
        pooled = {
            m: sum(r.n_gaps * r.mmae(m) for r in rows) / n for m in rows[0].errors
        }  # gap-weighted: the mean over every gap of the perturbation
        fixed = {m: v for m, v in pooled.items() if m != "auto"}
        bm = min(fixed, key=lambda k: fixed[k])
        lines.append(
            f"{'pooled ' + how:<22}{n:>5}{pooled['auto']:>8.3f}{fixed['linear']:>8.3f}  "
            f"{bm:<9}{fixed[bm]:>7.3f}{100 * (pooled['auto'] / fixed[bm] - 1):>+8.1f}%"
        )
    lines.append("('<' = auto worse than linear; auto/best = auto's excess over the best fixed)")
    margin = f"{100 * BEST_MARGIN:g} %"
    lines.append(f"more than {margin} above the best fixed: {', '.join(above) or 'none'}")
    lines.append(f"worse than linear: {', '.join(worse) if worse else 'none'}")
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    ap = experiment_parser("perturbed_gaps", __doc__)
    ap.add_argument("--seed", type=int, default=0, help="seed of shake and jitter")
    ap.add_argument(
        "--only",
        default=",".join(PERTURBATIONS),
        help="comma-separated perturbations to run, of " + ", ".join(PERTURBATIONS),
    )
    args = ap.parse_args(argv)
    if args.seed < 0:
        ap.error(f"--seed is {args.seed}, expected >= 0")
    only = [h.strip() for h in args.only.split(",") if h.strip()]
    unknown = [h for h in only if h not in PERTURBATIONS]
    if unknown or not only:
        ap.error(
            f"--only is {args.only!r}, expected a comma-separated list of "
            + ", ".join(PERTURBATIONS)
        )
    results = score(data_root(args.data), args.seed, only=tuple(dict.fromkeys(only)))
    with tee_stdout(args.out / f"perturbed_seed{args.seed}.txt"):
        print(format_table(results))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
