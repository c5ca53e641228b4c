"""``auto`` against ``linear`` on small and unusual files, where calibration has little to go on.

Issue 12 asks ``auto`` to be never worse than a straight line on files it has never seen, and
users' files are often small. Each case below is made from the real ground truths (the five
sequences of ``experiments.auto_seeds``: PETS09-S2L1, TUD-Campus, ADL-Rundle-6, ETH-Sunnyday,
KITTI-17), once per ``--seeds`` seed (the seed draws the ids, the pieces and the holes; the
cases that draw nothing, ``all``, ``third``, ``dup60``, ``x0.1`` and ``x10``, run once; the
calibration seed is the CLI's, 0, unless ``--calibration-seed``), and scored with the project's
protocol: gaps made by deleting ground-truth rows, every method recovering the same gaps from
the observed rows only, the mean error per gap (px) compared in pairs.

Cases (``masks``: the 3 automatic masks of ``pftrack experiment gaps`` delete the rows;
``holes``: random stretches of 1-40 rows of each track are deleted, at least 3 rows kept
between them and at both ends):

- ``all``: every id, as ``pftrack experiment gaps`` runs them (the reference);
- ``ids1``, ``ids2``, ``ids3``, ``ids5``: 1, 2, 3 or 5 random ids of a sequence (masks);
- ``short``: every track cut into pieces of 10-30 frames, 5-20 frames dropped between
  pieces, each piece its own id (masks);
- ``long``: 3 random ids with at least 60 rows, each kept only for its first and last 8-20
  rows (one gap of the middle, longer than any observed run: no validation gap of its length
  can be cut) and with one hole of 1-3 rows in each end piece of 12 rows or more;
- ``third``: every 3rd frame kept (1, 4, 7, ... renumbered 1, 2, 3, ...), all ids (masks);
  ``third-ids3``: the same, 3 random ids;
- ``dup60``: every frame written twice (frame f as 2f-1 and 2f: a 60 fps file of a 30 fps
  video), all ids (masks); ``dup60-ids3``: 3 random ids;
- ``x0.1``, ``x10``: boxes and image scaled by 0.1 and by 10, all ids (masks); ``x0.1-ids3``,
  ``x10-ids3``: 3 random ids;
- ``holes5``: 5 random ids with at least 20 rows (holes); ``holes5-x0.001``: the same ids and
  holes with boxes and image scaled by 0.001 (coordinates normalised to the image, as some
  detectors write them; masks of whole pixels cannot be laid there);
- ``standing``: only the tracks whose centre stays within 0.5 median box heights of its
  median over the track (people standing; the sequences that have two or more), holes;
- ``fast``: the 3 ids with the highest median speed per frame (holes);
- ``car``: one synthetic car (a 150 x 70 px box, 8-20 px a frame along a gentle arc, corners
  jittered by 1 px, 80-200 frames, 1280 x 720 image), holes.

Prints per case: files with gaps, gaps, ``auto``'s and ``linear``'s MMAE (px, and as a ratio),
``auto - linear`` per gap (mean ± standard error), the best of the other methods, and the files
where ``auto`` is worse than ``linear`` (``!``: by more than 2 standard errors of that file's
paired difference); ``!`` marks a case where ``auto`` is worse than
``linear`` by more than 2 standard errors. Per case, the gaps without a validation gap of
their length (their bucket took the file's choice) are scored apart, and so are the gaps with
fewer than 3 observed rows on a side (validation gaps keep at least 3). Written to
``small_files.txt`` in ``--out``.

Usage (from the repository root)::

    python -m experiments.small_files [--data ../shared/data] [--seeds 0 1 2 3 4]
        [--cases ids1 ...] [--calibration-seed 0] [--out out/small_files]
"""

from __future__ import annotations

import functools
import zlib
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from experiments._common import data_root, experiment_parser, tee_stdout
from experiments.auto_seeds import SEQUENCES
from pftrack._typing import F64
from pftrack.io.mot import read_mot
from pftrack.io.video import read_seqinfo
from pftrack.recovery.calibrate import CONTEXT, MIN_VALIDATION_GAPS, recover_auto
from pftrack.recovery.experiment import Gap, auto_masks, find_gaps, observed_runs, trajectories
from pftrack.recovery.mixture import fit_motion
from pftrack.recovery.noise import estimate_noise
from pftrack.recovery.registry import recover_gaps

#: Methods scored besides ``auto`` (``linear`` first: the reference).
OTHERS = ("linear", "rts", "gdt-bi", "gdt-mix", "gdt-fixed")
CASES = (
    "all", "ids1", "ids2", "ids3", "ids5", "short", "long", "third", "third-ids3", "dup60",
    "dup60-ids3", "x0.1", "x0.1-ids3", "x10", "x10-ids3", "holes5", "holes5-x0.001", "standing",
    "fast", "car",
)  # fmt: skip
#: Cases that draw nothing (the same files with every seed): run once.
FIXED_CASES = ("all", "third", "dup60", "x0.1", "x10")
#: Longest random hole (rows) of the ``holes`` protocol.
MAX_HOLE = 40


@dataclass
class CaseResult:
    """Per-gap errors of one case over its files and seeds."""

    errors: dict[str, list[float]] = field(default_factory=dict)
    unvalidated: list[bool] = field(default_factory=list)  # no validation gap of its length
    context: list[int] = field(default_factory=list)  # observed rows on its shorter side
    #: per file: name, auto's and linear's MMAE, gaps, the paired difference's standard error
    files: list[tuple[str, float, float, int, float]] = field(default_factory=list)

    def add(
        self, name: str, errs: dict[str, list[float]], unval: list[bool], context: list[int]
    ) -> None:
        """Add one file's gaps."""
        if not errs["auto"]:
            return
        for m, v in errs.items():
            self.errors.setdefault(m, []).extend(v)
        self.unvalidated.extend(unval)
        self.context.extend(context)
        d = np.subtract(errs["auto"], errs["linear"])
        se = float(d.std(ddof=1) / np.sqrt(len(d))) if len(d) > 1 else float("nan")
        self.files.append(
            (name, float(np.mean(errs["auto"])), float(np.mean(errs["linear"])), len(d), se)
        )


@dataclass(frozen=True)
class File:
    """One small file: its tracks, image size and how its gaps are made."""

    name: str
    trajs: dict[int, F64]
    width: float
    height: float
    protocol: str  # "masks" or "holes"
    lost: dict[int, np.ndarray] | None = None  # holes: per id, the rows deleted


def _holes(trajs: dict[int, F64], rng: np.random.Generator) -> dict[int, np.ndarray]:
    """Random stretches of 1-MAX_HOLE rows of each track, log-uniform lengths."""
    out = {}
    for tid, tr in trajs.items():
        lost = np.zeros(len(tr), bool)
        at = 3 + int(rng.integers(0, 6))
        while True:
            n = int(np.exp(rng.uniform(0.0, np.log(MAX_HOLE + 1))))
            if at + n + 3 > len(tr):
                break
            lost[at : at + n] = True
            at += n + 3 + int(rng.integers(0, 10))
        out[tid] = lost
    return out


def _gaps_of(trajs: dict[int, F64], lost: dict[int, np.ndarray]) -> tuple[list[Gap], list[F64]]:
    """The gaps the deleted rows make (as :func:`find_gaps`) and the observed runs."""
    gaps: list[Gap] = []
    runs: list[F64] = []
    for tid, tr in trajs.items():
        inside = lost[tid]
        cut = np.flatnonzero(np.diff(inside.astype(np.int8)) != 0) + 1
        for part, flag in zip(np.split(tr, cut), np.split(inside, cut), strict=True):
            if not flag[0]:
                runs.append(part)
        if not inside.any() or inside[0] or inside[-1]:
            continue
        edges = np.diff(inside.astype(np.int8))
        starts = np.flatnonzero(edges == 1) + 1
        ends = np.flatnonzero(edges == -1) + 1
        bounds = [0] + [int(v) for pair in zip(starts, ends, strict=True) for v in pair] + [len(tr)]
        for g, (s, e) in enumerate(zip(starts, ends, strict=True)):
            gaps.append(Gap(tid, tr[bounds[2 * g] : s], tr[e : bounds[2 * g + 3]], tr[s:e]))
    return gaps, runs


Scored = tuple[dict[str, list[float]], list[bool], list[int]]


def _score(gaps: list[Gap], runs: list[F64], cal_seed: int) -> Scored:
    """Every method's mean error per gap, which gaps had no validation gap of their length, and
    each gap's observed rows on its shorter side."""
    pairs = [(g.segment_a, g.segment_b) for g in gaps]
    noise = estimate_noise(runs)
    motion = fit_motion(runs, noise)
    out: dict[str, list[float]] = {}
    paths, cal = recover_auto(pairs, runs, seed=cal_seed)
    out["auto"] = [float(np.mean(g.errors(p))) for g, p in zip(gaps, paths, strict=True)]
    for m in OTHERS:
        paths = recover_gaps(pairs, m, noise=noise, motion=motion)  # type: ignore[arg-type]
        out[m] = [float(np.mean(g.errors(p))) for g, p in zip(gaps, paths, strict=True)]
    lengths = [int(g.segment_b[0, 0] - g.segment_a[-1, 0]) - 1 for g in gaps]
    nval = {c.lengths: c.n_validation for c in cal.buckets}
    unval = [
        next(n for (lo, hi), n in nval.items() if lo <= L <= hi) < MIN_VALIDATION_GAPS
        for L in lengths
    ]
    return out, unval, [min(len(g.segment_a), len(g.segment_b)) for g in gaps]


def run_file(f: File, cal_seed: int) -> Scored:
    """The errors per gap of every method on one file (no gaps: empty lists)."""
    empty: dict[str, list[float]] = {m: [] for m in ("auto", *OTHERS)}
    if f.protocol == "holes":
        assert f.lost is not None
        gaps, runs = _gaps_of(f.trajs, f.lost)
        return _score(gaps, runs, cal_seed) if gaps else (empty, [], [])
    errs: dict[str, list[float]] = {m: [] for m in ("auto", *OTHERS)}
    unval: list[bool] = []
    ctx: list[int] = []
    for mk in auto_masks(f.trajs, f.width, f.height, 3):
        gaps, _ = find_gaps(f.trajs, mk)
        if not gaps:
            continue
        e, u, c = _score(gaps, observed_runs(f.trajs, mk), cal_seed)
        for m, v in e.items():
            errs[m].extend(v)
        unval.extend(u)
        ctx.extend(c)
    return errs, unval, ctx


def _subset(
    trajs: dict[int, F64], k: int, rng: np.random.Generator, min_rows: int = 10
) -> dict[int, F64]:
    ids = sorted(i for i, t in trajs.items() if len(t) >= min_rows)
    pick = rng.choice(len(ids), size=min(k, len(ids)), replace=False)
    return {ids[i]: trajs[ids[i]] for i in sorted(pick)}


def _pieces(trajs: dict[int, F64], rng: np.random.Generator) -> dict[int, F64]:
    out: dict[int, F64] = {}
    for t in trajs.values():
        at = 0
        while at < len(t):
            n = int(rng.integers(10, 31))
            if at + n <= len(t):
                out[len(out) + 1] = t[at : at + n]
            at += n + int(rng.integers(5, 21))
    return out


def _frames(trajs: dict[int, F64], how: str) -> dict[int, F64]:
    out = {}
    for tid, t in trajs.items():
        if how == "third":
            t = t[t[:, 0] % 3 == 1].copy()
            t[:, 0] = (t[:, 0] + 2) // 3
        else:  # dup60
            t = np.repeat(t, 2, axis=0)
            t[:, 0] = 2 * t[:, 0] - np.tile([1, 0], len(t) // 2)
        if len(t) >= 2:
            out[tid] = t
    return out


def _scaled(trajs: dict[int, F64], s: float) -> dict[int, F64]:
    return {tid: np.column_stack([t[:, 0], s * t[:, 1:]]) for tid, t in trajs.items()}


def _standing(rows: F64) -> dict[int, F64]:
    trajs = trajectories(rows)
    out = {}
    for tid, t in trajs.items():
        h = float(np.median(rows[rows[:, 1] == tid, 5]))
        if (
            len(t) >= 20
            and np.max(np.hypot(*(t[:, 1:3] - np.median(t[:, 1:3], axis=0)).T)) < 0.5 * h
        ):
            out[tid] = t
    return out


def _fast(trajs: dict[int, F64]) -> dict[int, F64]:
    speed = {
        tid: float(np.median(np.hypot(*np.diff(t[:, 1:3], axis=0).T)))
        for tid, t in trajs.items()
        if len(t) >= 20
    }
    top = sorted(speed, key=lambda k: -speed[k])[:3]
    return {k: trajs[k] for k in sorted(top)}


def _car(rng: np.random.Generator) -> dict[int, F64]:
    n = int(rng.integers(80, 201))
    speed = rng.uniform(8.0, 20.0)
    turn = rng.uniform(-0.004, 0.004)  # radians per frame
    head = rng.uniform(-0.3, 0.3) + (np.pi if rng.random() < 0.5 else 0.0)
    ang = head + turn * np.arange(n)
    xy = np.cumsum(np.column_stack([np.cos(ang), np.sin(ang)]) * speed, axis=0)
    xy += np.array([640.0, 360.0]) - xy[n // 2]
    xy += rng.normal(0.0, 1.0, xy.shape)  # the box's corner jitter, as its centre's
    return {1: np.column_stack([np.arange(1.0, n + 1), xy])}


@functools.cache
def real_sequences(root: Path) -> tuple[tuple[str, F64, float, float], ...]:
    """The five real sequences under `root` (those present): name, rows, width, height.

    (``auto_seeds.sources`` without its synthetic scenes, which take long to draw.)
    """
    out = []
    for name, sub in SEQUENCES:
        folder = root / sub
        if (folder / "gt.txt").is_file():
            info = read_seqinfo(folder)
            if info.width is None or info.height is None:
                raise ValueError(f"{folder}/seqinfo.ini: no imWidth/imHeight")
            out.append((name, read_mot(folder / "gt.txt"), float(info.width), float(info.height)))
    return tuple(out)


def files(case: str, root: Path, seed: int) -> Iterator[File]:
    """The files of `case` with seed `seed`: one per real sequence (``car``: one)."""
    if case == "car":
        rng = np.random.default_rng([seed, zlib.crc32(b"car")])
        trajs = _car(rng)
        yield File("car", trajs, 1280.0, 720.0, "holes", _holes(trajs, rng))
        return
    for name, rows, w, h in real_sequences(root):
        rng = np.random.default_rng([seed, zlib.crc32(f"{name}/{case}".encode())])
        trajs = trajectories(rows)
        base, _, sub = case.partition("-")
        if base == "holes5":  # the same ids and holes with and without "-x0.001"
            rng = np.random.default_rng([seed, zlib.crc32(f"{name}/holes5".encode())])
            picked = _subset(trajs, 5, rng, min_rows=20)
            lost = _holes(picked, rng)
            s = 1e-3 if sub else 1.0
            yield File(name, _scaled(picked, s), s * w, s * h, "holes", lost)
            continue
        if sub:  # "-ids3": three random ids first
            trajs = _subset(trajs, 3, rng)
        if base == "all":
            yield File(name, trajs, w, h, "masks")
        elif base.startswith("ids"):
            yield File(name, _subset(trajs, int(base[3:]), rng), w, h, "masks")
        elif base == "short":
            yield File(name, _pieces(trajs, rng), w, h, "masks")
        elif base in ("third", "dup60"):
            yield File(name, _frames(trajs, base), w, h, "masks")
        elif base in ("x0.1", "x10"):
            s = float(base[1:])
            yield File(name, _scaled(trajs, s), s * w, s * h, "masks")
        elif base == "long":
            picked = _subset(trajs, 3, rng, min_rows=60)
            cut, lost = {}, {}
            for tid, t in picked.items():
                a, b = (int(v) for v in rng.integers(8, 21, size=2))
                keep = np.r_[0:a, len(t) - b : len(t)]
                gone = np.zeros(len(keep), bool)
                for lo, n in ((0, a), (a, b)):
                    if n >= 12:
                        at = lo + int(rng.integers(4, n - 6))
                        gone[at : at + int(rng.integers(1, 4))] = True
                # the middle as one gap: lost rows of the frames between the two pieces
                mid = t[a : len(t) - b]
                cut[tid] = np.vstack([t[:a], mid, t[len(t) - b :]])
                lost[tid] = np.r_[gone[:a], np.ones(len(mid), bool), gone[a:]]
            if cut:
                yield File(name, cut, w, h, "holes", lost)
        elif base == "standing":
            trajs = _standing(rows)
            if len(trajs) >= 2:
                yield File(name, trajs, w, h, "holes", _holes(trajs, rng))
        elif base == "fast":
            trajs = _fast(trajs)
            yield File(name, trajs, w, h, "holes", _holes(trajs, rng))
        else:
            raise ValueError(f"unknown case {case!r}")


def run_case(case: str, root: Path, seeds: Sequence[int], cal_seed: int) -> CaseResult:
    """Every file of `case` with every seed (the cases that draw nothing: once)."""
    res = CaseResult()
    for s in seeds if case not in FIXED_CASES else seeds[:1]:
        for f in files(case, root, s):
            res.add(f"{f.name}/{s}", *run_file(f, cal_seed))
    return res


def _diff(a: np.ndarray, b: np.ndarray) -> str:
    d = a - b
    se = d.std(ddof=1) / np.sqrt(len(d)) if len(d) > 1 else float("nan")
    mark = "!" if len(d) > 1 and d.mean() > 2 * se else " "
    return f"{d.mean():+8.3g} ± {se:6.3g}{mark}"


def format_case(case: str, r: CaseResult) -> str:
    """One line for the case, one for its unvalidated gaps, then the files worse than linear."""
    if not r.files:
        return f"{case:<12} no gaps"
    e = {m: np.asarray(v) for m, v in r.errors.items()}
    lines = []
    ctx = np.asarray(r.context)
    for label, sel in (
        ("", np.ones(len(e["auto"]), bool)),
        ("  no val.", np.asarray(r.unvalidated)),
        ("  ctx<3", ctx < CONTEXT),
    ):
        if not sel.any():
            continue
        a, lin = e["auto"][sel], e["linear"][sel]
        others = {m: float(v[sel].mean()) for m, v in e.items() if m not in ("auto",)}
        bm = min(others, key=lambda m: others[m])
        lines.append(
            f"{(case + label):<14}{len(r.files) if not label else '':>5}{sel.sum():>6}"
            f"{a.mean():>9.4g}{lin.mean():>9.4g}{a.mean() / lin.mean():>7.3f} {_diff(a, lin)}"
            f"  {bm:<9}{others[bm]:>8.4g}"
        )
    worse = [
        f"{n} {au:.3g}/{li:.3g} ({k}){'!' if au - li > 2 * se else ''}"
        for n, au, li, k, se in r.files
        if au > li * 1.001
    ]
    if worse:
        lines.append(f"    worse than linear ({len(worse)} of {len(r.files)}): " + ", ".join(worse))
    return "\n".join(lines)


HEAD = (
    f"{'case':<14}{'files':>5}{'gaps':>6}{'auto':>9}{'linear':>9}{'ratio':>7}"
    f" {'auto-linear per gap':>18}  {'best other':<9}{'MMAE':>8}"
)


def main(argv: Sequence[str] | None = None) -> int:
    ap = experiment_parser("small_files", __doc__)
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3, 4], help="case seeds")
    ap.add_argument("--cases", nargs="+", default=list(CASES), choices=CASES, metavar="CASE",
                    help=f"cases to run, of {', '.join(CASES)}")  # fmt: skip
    ap.add_argument("--calibration-seed", type=int, default=0, help="auto's calibration seed")
    args = ap.parse_args(argv)
    if min(args.seeds) < 0 or args.calibration_seed < 0:
        ap.error("seeds must be >= 0")
    root = data_root(args.data)
    with tee_stdout(args.out / "small_files.txt"):
        print(HEAD, flush=True)
        for case in args.cases:
            print(
                format_case(case, run_case(case, root, args.seeds, args.calibration_seed)),
                flush=True,
            )
        print("('!' = auto worse than linear by more than 2 standard errors of the paired "
              "difference; 'no val.' = gaps whose length had fewer than "
              f"{MIN_VALIDATION_GAPS} validation gaps)")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
