"""The person size the offline pass completes boxes to: every fit, and the rows under other sizes.

``Tracker.finalize()`` completes partly seen people's boxes (``LifecycleConfig.amodal_share``,
``pftrack.tracking.offline.complete_boxes``) to the built-in detector's person-size model's
*last* fit. This runs ``experiments.detector_robustness``'s cases (the same frames, every
default, ``--hold-frames`` as given), records every fit the size model makes (``--fits``:
isolated boxes seen, the candidate lines, kept or refused by ``max_cut_share``) and then calls
the run's ``finalize()`` again with the completion given other lines (the offline pass is
repeatable: the last size gives the run's own rows, checked). Sizes scored (MOTA / IDF1 /
HOTA):

``last``      the last fit kept (the default, main's rows)
``median``    the element-wise median of every fit kept over the video
``full``      that median over the fits made from a full sample buffer (``max_samples``
              boxes), else the last fit: fits from too few boxes left out
``samples``   one fit (``pftrack._core.size_fit``) over every isolated box the model was given
``rows``      one fit over the run's rows before the completion, those whose columns overlap
              no other row of their frame (the run's confirmed boxes, at the offline pass)
``none``      no completion (``amodal_share=None``)

and, for the last fit, the worst and best change when one of its two intercepts (height or
width) moves by one pixel (``1px-``, ``1px+``): how much one pixel of the size moves a row.

With ``--ill-posed``, three completions that know when the head row cannot give a height (one
pixel of the head row or of the height line's intercept moves the expected height ``h_e`` by
``max(1, |s|) / |1 - s|`` px for the height slope ``s``; a box is *ill-posed* when that is more
than ``1 - amodal_share`` of its own height, the band within which a box counts as whole),
each scored with the last fit and with its own one-pixel worst change (``...1px-``):

``leave``     ill-posed boxes are left as they are (the rest completed as by default)
``track``     ill-posed boxes are completed to their track's median height instead of ``h_e``
              (the offline pass sees the whole track: evidence that does not pass through the
              head row)
``margin``    every box is completed only when every line within one pixel of the intercept
              would complete it: shorter than ``amodal_share (h_e - sensitivity)``, not only
              than ``amodal_share h_e`` (the decision made robust, the height still ``h_e``)

Usage (from the repository root)::

    python -m experiments.person_size [--data ../shared/data]
        [--sequences pets,tud,walkers,present,groups,overhead] [--variants ident,grey,ramp]
        [--hold-frames 0] [--fits] [--ill-posed] [--out out/person_size]
"""

from __future__ import annotations

import sys
import unittest.mock
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from itertools import product
from typing import Any

import numpy as np

from experiments._common import data_root, experiment_parser, tee_stdout
from experiments.detector_robustness import REAL, SYNTHETIC, real_case, synthetic_case
from pftrack import _core
from pftrack._typing import F64
from pftrack.detection.size_model import PersonSizeModel
from pftrack.eval import evaluate_sequence
from pftrack.io.mot import as_written
from pftrack.tracking import LifecycleConfig, api, offline

SIZES = ("last", "median", "full", "samples", "rows", "none")


@dataclass
class Fit:
    """One fit of the size model: boxes seen so far, those held, the candidate lines (kept
    or refused), and the held boxes' foot rows (lowest, highest) and median height, width."""

    seen: int
    held: int
    lines: F64
    kept: bool
    foot: tuple[float, float]
    median_hw: tuple[float, float]


@dataclass
class Recorder:
    """What one run's size model and offline pass did (filled by the patches of `record`)."""

    fits: list[Fit] = field(default_factory=list)
    samples: list[F64] = field(default_factory=list)  # every isolated box: foot y, h, w
    last_n: int = 0  # boxes seen when `samples` was last extended
    tracker: Any = None
    rows: F64 | None = None  # the rows given to the completion
    lines: F64 | None = None  # the lines it used

    def take_samples(self, model: PersonSizeModel) -> None:
        """Add the boxes the model took in since the last call (read from its ring buffer)."""
        size = model.config.max_samples
        new = np.arange(max(self.last_n, model._n - size), model._n)  # noqa: SLF001
        self.samples.append(model._samples[new % size].copy())  # noqa: SLF001
        self.last_n = model._n  # noqa: SLF001


def record(rec: Recorder) -> list[Any]:
    """Patches recording every size fit, the tracker that finalizes and the completion's input."""
    fit, finalize, complete = PersonSizeModel._fit, api.Tracker.finalize, api.complete_boxes  # noqa: SLF001

    def fit_and_record(model: PersonSizeModel) -> None:
        rec.take_samples(model)
        before = model._coef  # noqa: SLF001
        fit(model)
        held = model._samples[: model.n_samples]  # noqa: SLF001
        rec.fits.append(
            Fit(
                model._n,  # noqa: SLF001
                len(held),
                _core.size_fit(held),
                model._coef is not before,  # noqa: SLF001
                (float(held[:, 0].min()), float(held[:, 0].max())),
                (float(np.median(held[:, 1])), float(np.median(held[:, 2]))),
            )
        )

    def finalize_and_record(tracker: Any) -> F64:
        rec.tracker = tracker
        model = getattr(tracker._tracker.detector, "size_model", None)  # noqa: SLF001
        if isinstance(model, PersonSizeModel):
            rec.take_samples(model)
        out: F64 = finalize(tracker)
        return out

    def complete_and_record(rows: F64, lines: F64, *args: Any, **kw: Any) -> F64:
        rec.rows, rec.lines = np.array(rows, np.float64), np.array(lines, np.float64)
        out: F64 = complete(rows, lines, *args, **kw)
        return out

    return [
        unittest.mock.patch.object(PersonSizeModel, "_fit", fit_and_record),
        unittest.mock.patch.object(api.Tracker, "finalize", finalize_and_record),
        unittest.mock.patch.object(api, "complete_boxes", complete_and_record),
    ]


def isolated_rows(rows: F64) -> F64:
    """``foot y, h, w`` of the rows whose columns overlap no other row of their frame."""
    keep = np.zeros(len(rows), dtype=bool)
    for f in np.unique(rows[:, 0]):
        i = np.flatnonzero(rows[:, 0] == f)
        left, right = rows[i, 2], rows[i, 2] + rows[i, 4]
        overlap = (left[:, None] < right[None, :]) & (left[None, :] < right[:, None])
        np.fill_diagonal(overlap, False)
        keep[i[~overlap.any(axis=1)]] = True
    r = rows[keep]
    return np.column_stack([r[:, 3] + r[:, 5], r[:, 5], r[:, 4]])


def one_fit(samples: F64, most: int = 3000) -> F64:
    """`pftrack._core.size_fit` over `samples`, evenly thinned to `most` (Theil-Sen is n^2)."""
    if len(samples) > most:
        samples = samples[np.linspace(0, len(samples) - 1, most).astype(int)]
    lines: F64 = _core.size_fit(samples)
    return lines


def sizes(rec: Recorder) -> dict[str, F64 | None]:
    """The lines of every size of the module's docstring (None: no completion)."""
    assert rec.lines is not None and rec.rows is not None
    kept = [f for f in rec.fits if f.kept]
    full = [f.lines for f in kept if f.held == PersonSizeModel().config.max_samples]
    return {
        "last": rec.lines,
        "median": np.median([f.lines for f in kept], axis=0),
        "full": np.median(full, axis=0) if full else rec.lines,
        "samples": one_fit(np.vstack(rec.samples)),
        "rows": one_fit(isolated_rows(rec.rows)),
        "none": None,
    }


def rows_with(rec: Recorder, lines: F64 | None) -> F64:
    """The run's ``finalize()`` again, its completion given `lines` (None: no completion)."""
    complete = api.complete_boxes

    def given(rows: F64, _lines: F64, *args: Any, **kw: Any) -> F64:
        return rows if lines is None else complete(rows, lines, *args, **kw)

    with unittest.mock.patch.object(api, "complete_boxes", given):
        out: F64 = rec.tracker.finalize()
    return out


#: The completions of ill-posed boxes ``--ill-posed`` scores (see the module's docstring).
ILL_POSED = ("leave", "track", "margin")


def head_row_sensitivity(lines: F64) -> float:
    """Pixels of ``h_e`` one pixel of the head row (or of the intercept) moves."""
    s = float(lines[0, 0])
    return np.inf if s == 1.0 else max(1.0, abs(s)) / abs(1.0 - s)


def rows_ill_posed(rec: Recorder, how: str, lines: F64) -> F64:
    """The run's ``finalize()`` again, the completion given `lines` and ill-posed boxes done `how`.

    The library's ``complete_boxes`` runs unchanged; only the expected height it reads for an
    ill-posed box is replaced (``head_height``): not positive (``leave``: such a box is left
    alone; ``margin``: a box one pixel would complete or not) or the box's track's median
    height (``track``).
    """
    complete, head = api.complete_boxes, offline.head_height
    share = LifecycleConfig().amodal_share
    assert share is not None
    given: list[F64] = []

    def complete_given(rows: F64, _lines: F64, *args: Any, **kw: Any) -> F64:
        given[:] = [np.asarray(rows, np.float64)]
        return complete(rows, lines, *args, **kw)

    def head_given(coef: F64, top: F64) -> F64:
        rows = given[0]
        h_e = head(coef, top)
        ill = head_row_sensitivity(coef) > (1.0 - share) * rows[:, 5]
        if how == "leave":
            return np.where(ill, -1.0, h_e)
        if how == "margin":  # left alone where one pixel would flip the decision
            h = rows[:, 5]
            flips = (h >= share * (h_e - head_row_sensitivity(coef))) & (h < share * h_e)
            return np.where(flips, -1.0, h_e)
        ids, inv = np.unique(rows[:, 1], return_inverse=True)
        median = np.array([np.median(rows[inv == k, 5]) for k in range(len(ids))])
        return np.where(ill, median[inv], h_e)

    with (
        unittest.mock.patch.object(api, "complete_boxes", complete_given),
        unittest.mock.patch.object(offline, "head_height", head_given),
    ):
        out: F64 = rec.tracker.finalize()
    return out


def scores(gt: F64, rows: F64) -> F64:
    """MOTA, IDF1, HOTA in %."""
    s = evaluate_sequence(gt, as_written(rows))
    return 100 * np.array([s.mot.mota, s.mot.idf1, s.hota.hota])


def line_text(lines: F64 | None) -> str:
    """``h = a y + b, w = c y + d`` (foot row y)."""
    if lines is None:
        return "none"
    (hs, hi), (ws, wi) = lines
    return f"h {hs:.3f} y {hi:+.1f}, w {ws:.3f} y {wi:+.1f}"


def one_pixel(rec: Recorder, gt: F64, score: Callable[[F64 | None], F64]) -> tuple[F64, F64]:
    """Worst and best change of the scores when one intercept of the last fit moves 1 px."""
    assert rec.lines is not None
    base = score(rec.lines)
    changes = []
    for row, step in product((0, 1), (-1.0, 1.0)):
        moved = rec.lines.copy()
        moved[row, 1] += step
        changes.append(score(moved) - base)
    return np.min(changes, axis=0), np.max(changes, axis=0)


def fmt(v: F64) -> str:
    return " / ".join(f"{x:.1f}" for x in v)


def main(argv: Sequence[str] | None = None) -> int:
    p = experiment_parser("person_size", __doc__)
    p.add_argument("--sequences", default="pets,tud," + ",".join(SYNTHETIC))
    p.add_argument("--variants", default="ident,grey,ramp", help="ident, grey or ramp")
    p.add_argument("--hold-frames", type=int, default=0, help="TrackerConfig.hold_frames")
    p.add_argument("--fits", action="store_true", help="print every fit of the size model")
    p.add_argument(
        "--ill-posed", action="store_true", help="score completions of ill-posed boxes too"
    )
    args = p.parse_args(argv)
    from pftrack.tracking import TrackerConfig, track_frames

    names = [s for s in args.sequences.split(",") if s]
    variants = [v for v in args.variants.split(",") if v]
    bad = sorted(set(names) - set(REAL) - set(SYNTHETIC))
    bad += sorted(set(variants) - {"ident", "grey", "ramp"})
    if bad:
        p.error(f"unknown sequence(s) or variant(s): {', '.join(bad)}")
    if not names or not variants:  # (was: the header alone, status 0)
        p.error(f"--{'sequences' if not names else 'variants'} names none")
    if args.hold_frames < 0:
        p.error(f"--hold-frames is {args.hold_frames}, expected 0 (off) or more")
    data = data_root(args.data)
    ran = 0
    with tee_stdout(args.out / "person_size.txt"):
        print(f"hold_frames={args.hold_frames} seed=0 (MOTA / IDF1 / HOTA in %)")
        for name, variant in product(names, variants):
            case = (
                real_case(name, variant, data, args.out)
                if name in REAL
                else synthetic_case(name, variant)
            )
            if case is None:
                print(f"{name} {variant}: skipped (no data)")
                continue
            source, gt = case
            ran += 1
            rec = Recorder()
            patches = record(rec)
            for patch in patches:
                patch.start()
            try:
                run = track_frames(
                    source,
                    config=TrackerConfig(hold_frames=args.hold_frames),
                    rng=0,
                    show_progress=False,
                )
            finally:
                for patch in patches:
                    patch.stop()
            if rec.lines is None:
                print(f"{name} {variant}: the size model was never fitted")
                continue
            if not np.array_equal(rows_with(rec, rec.lines), run.rows):
                raise RuntimeError("finalize() again with the last fit did not give the rows")
            print(f"{name} {variant}: {len(rec.fits)} fits, {rec.last_n} isolated boxes")
            if args.fits:
                for k, f in enumerate(rec.fits, 1):
                    print(
                        f"  fit {k:3d}: seen {f.seen:5d} held {f.held:3d} feet "
                        f"{f.foot[0]:.0f}-{f.foot[1]:.0f} median h {f.median_hw[0]:.0f} "
                        f"w {f.median_hw[1]:.0f}: {line_text(f.lines)} "
                        f"{'kept' if f.kept else 'refused'}"
                    )

            def score(lines: F64 | None, rec: Recorder = rec, gt: F64 = gt) -> F64:
                return scores(gt, rows_with(rec, lines))

            for size, lines in sizes(rec).items():
                print(f"  {size:8s} {fmt(score(lines)):20s} {line_text(lines)}")
            worst, best = one_pixel(rec, gt, score)
            print(f"  1px-     {fmt(worst)}\n  1px+     {fmt(best)}", flush=True)
            for how in ILL_POSED if args.ill_posed else ():

                def score_ill(
                    lines: F64 | None, how: str = how, rec: Recorder = rec, gt: F64 = gt
                ) -> F64:
                    assert lines is not None
                    return scores(gt, rows_ill_posed(rec, how, lines))

                worst = one_pixel(rec, gt, score_ill)[0]
                assert rec.lines is not None
                print(f"  {how:8s} {fmt(score_ill(rec.lines)):20s} 1px- {fmt(worst)}", flush=True)
    if not ran:  # every one asked was a real sequence missing under --data (was: status 0)
        print(f"no pets09-s2l1 or tud-campus video under {data}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
