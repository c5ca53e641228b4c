"""Gap filling of other trackers' output: ByteTrack's and StrongSORT's against pftrack's.

Each peer of :mod:`experiments.compare_trackers` that is installed (SORT of ``sort-track``,
supervision's ``sv.ByteTrack``, norfair, motpy) runs on a sequence's public detections, exactly
as there (:func:`~experiments.compare_trackers.online_rows`; peers read no pixels, so the frames
are black ones of the video's size). Its raw output is then post-processed as below, and each
result is scored by :func:`pftrack.eval.evaluate_sequence` (MOTA, IDF1 at IoU 0.5 and HOTA, as
TrackEval computes them):

``raw``
    (a) the peer's rows as it reported them.
``linear``
    (b) ByteTrack's ``tools/interpolation.py`` (``dti``): inside each id of more than ``n_min``
    rows, every hole whose ends are fewer than ``n_dti`` frames apart is filled by a straight
    line between the two boxes (:func:`bytetrack_interpolation`).
``gsi``
    (c) StrongSORT's Gaussian-smoothed interpolation (Du et al. 2023, ``GSI.py``): the same
    linear fill (holes whose ends are fewer than ``interval`` frames apart), then each id's
    left, top, width and height, observed and filled rows alike, replaced by the posterior mean
    of a Gaussian process over the frame number (RBF kernel of fixed length
    ``clip(tau log(tau^3 / n), 1/tau, tau^2)`` for an id of ``n`` rows, noise 1e-10, zero prior
    mean), as scikit-learn's ``GaussianProcessRegressor`` computes it (:func:`strongsort_gsi`).
    pftrack's ``gsi`` recovery method is not this: it fills the hole's frames only, keeps the
    observed rows and interpolates sizes linearly; it is scored too, as ``recover-gsi``.
``recover``
    (d) ``pftrack recover`` (:func:`pftrack.recovery.fill_gaps`, method ``auto``): holes inside
    each id filled, observed rows unchanged, no linking.
``smooth``
    (e) ``pftrack smooth`` (:func:`pftrack.tracking.smooth_tracks` with the command's linking
    gate): fragments linked, holes filled, every track smoothed.
``smooth-no-link``
    ``pftrack smooth --no-link``: holes filled and every track smoothed, no linking; like GSI,
    it changes the observed boxes and joins nothing, so it is the pass to set beside ``gsi``.

All fill holes of at most ``--max-gap`` missing frames: the common setting of ByteTrack's
``n_dti`` and StrongSORT's ``interval``, 20, is a bound on the frame difference of a hole's ends
(``< 20``), so 18 missing frames; pftrack's ``--max-gap`` (its linking gate too) counts missing
frames and is given 18. ByteTrack's ``n_min`` is 5, as its ``interpolation.py`` runs it.
``--seed`` is the calibration seed of pftrack's ``auto``; nothing else draws.

The ``pooled`` rows score a peer's sequences together (TrackEval's combination,
:meth:`pftrack.eval.SequenceScores.combine`). Rows are scored in memory, unrounded.

Usage (from the repository root)::

    python -m experiments.peer_gap_filling [--data ../shared/data] [--out out/peer_gap_filling]
        [--seq pets09-s2l1 ...] [--tracker sort bytetrack norfair motpy] [--max-gap 18]
        [--seed 0]
"""

from __future__ import annotations

import contextlib
import io
import sys
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.linalg

from experiments import compare_trackers
from experiments._common import data_folder, experiment_parser, write_text
from experiments.public_detections import BlackFrames
from pftrack._typing import F64
from pftrack.eval import SequenceScores, evaluate_sequence
from pftrack.io.mot import read_mot
from pftrack.io.video import read_seqinfo
from pftrack.recovery import fill_gaps
from pftrack.recovery.linking import link_config_for
from pftrack.tracking import smooth_tracks

PEERS = ("sort", "bytetrack", "norfair", "motpy")
VARIANTS = ("raw", "linear", "gsi", "recover", "recover-gsi", "smooth", "smooth-no-link")
POOLED = "pooled"


# ---- the peers' post-processing, from their published code -----------------------------------


def _by_id(rows: F64) -> list[F64]:
    """The rows of each id, sorted by frame, ids in increasing order."""
    rows = rows[np.lexsort((rows[:, 0], rows[:, 1]))]
    cuts = np.flatnonzero(np.diff(rows[:, 1])) + 1
    return [t for t in np.split(rows, cuts) if len(t)]


def bytetrack_interpolation(rows: F64, n_dti: int = 20, n_min: int = 5) -> F64:
    """ByteTrack's disconnected-track interpolation (``tools/interpolation.py``, ``dti``).

    Parameters
    ----------
    rows : (M, 10) ndarray of float
        MOTChallenge rows, one per (frame, id).
    n_dti : int
        A hole is filled when its ends are more than 1 and fewer than `n_dti` frames apart
        (at most ``n_dti - 2`` missing frames).
    n_min : int
        Only ids of more than `n_min` rows are filled.

    Returns
    -------
    (M + K, 10) ndarray of float
        The rows, then each filled row (``frame, id, box, 1, -1, -1, -1``), sorted by frame
        then id. A filled box is the straight line between the hole's two boxes.

    References
    ----------
    .. [1] Zhang, Y. et al. (2022). ByteTrack: multi-object tracking by associating every
       detection box. ECCV; ``tools/interpolation.py`` of its repository.
    """
    out = [rows]
    for t in _by_id(rows):
        if len(t) <= n_min:
            continue
        f = t[:, 0]
        for i in np.flatnonzero((np.diff(f) > 1) & (np.diff(f) < n_dti)):
            left, right = f[i], f[i + 1]
            mid = np.arange(left + 1, right)
            frac = ((mid - left) / (right - left))[:, None]
            boxes = frac * (t[i + 1, 2:6] - t[i, 2:6]) + t[i, 2:6]
            filled = np.zeros((len(mid), 10))
            filled[:, 0], filled[:, 1], filled[:, 2:6] = mid, t[0, 1], boxes
            filled[:, 6:] = (1.0, -1.0, -1.0, -1.0)
            out.append(filled)
    res = np.concatenate(out)
    return res[np.lexsort((res[:, 1], res[:, 0]))]


def strongsort_linear(rows: F64, interval: int = 20) -> F64:
    """StrongSORT's ``LinearInterpolation``: every column of the rows on either side of a hole
    whose ends are more than 1 and fewer than `interval` frames apart, interpolated linearly.

    Returns the rows and the filled ones, sorted by id then frame.
    """
    out = [rows]
    for t in _by_id(rows):
        f = t[:, 0]
        for i in np.flatnonzero((np.diff(f) > 1) & (np.diff(f) < interval)):
            k = np.arange(1, f[i + 1] - f[i])[:, None]
            out.append(t[i] + (t[i + 1] - t[i]) / (f[i + 1] - f[i]) * k)
    res = np.concatenate(out)
    return res[np.lexsort((res[:, 0], res[:, 1]))]


def gp_posterior_mean(t: F64, y: F64, length: float, noise: float = 1e-10) -> F64:
    """Posterior mean at `t` of a zero-mean GP with an RBF kernel fitted to ``(t, y)``.

    scikit-learn's ``GaussianProcessRegressor(RBF(length, "fixed"))`` (``alpha`` = `noise`,
    no normalisation): ``K (K + noise I)^-1 y`` by a Cholesky factor. Where the factor fails
    (a matrix not positive definite in floating point, where scikit-learn would raise), the
    noise is multiplied by 10 until it succeeds.
    """
    K = np.exp(-0.5 * ((t[:, None] - t[None, :]) / length) ** 2)
    while True:
        try:
            c = scipy.linalg.cho_factor(K + noise * np.eye(len(t)), lower=True)
            break
        except np.linalg.LinAlgError:
            noise *= 10.0
    return np.asarray(K @ scipy.linalg.cho_solve(c, y), dtype=np.float64)


def strongsort_gsi(rows: F64, interval: int = 20, tau: float = 10.0) -> F64:
    """StrongSORT's Gaussian-smoothed interpolation (``GSI.py``, ``GSInterpolation``).

    Parameters
    ----------
    rows : (M, 10) ndarray of float
        MOTChallenge rows, one per (frame, id).
    interval : int
        Holes whose ends are fewer than `interval` frames apart are filled
        (:func:`strongsort_linear`).
    tau : float
        The smoothing constant: an id of ``n`` rows (after the fill) is regressed with the RBF
        length ``clip(tau log(tau^3 / n), 1/tau, tau^2)`` frames.

    Returns
    -------
    (M + K, 10) ndarray of float
        Every row of every id, its box replaced by the GP's posterior mean at its frame
        (:func:`gp_posterior_mean`), columns 7-10 ``1, -1, -1, -1``; sorted by id then frame.

    References
    ----------
    .. [1] Du, Y. et al. (2023). StrongSORT: make DeepSORT great again. IEEE Trans.
       Multimedia 25; ``GSI.py`` of its repository.
    """
    out = []
    for t in _by_id(strongsort_linear(rows, interval)):
        length = float(np.clip(tau * np.log(tau**3 / len(t)), 1.0 / tau, tau**2))
        res = np.zeros((len(t), 10))
        res[:, :2] = t[:, :2]
        res[:, 2:6] = gp_posterior_mean(t[:, 0], t[:, 2:6], length)
        res[:, 6:] = (1.0, -1.0, -1.0, -1.0)
        out.append(res)
    return np.concatenate(out) if out else np.zeros((0, 10))


def variants(rows: F64, max_gap: int = 18, seed: int = 0) -> dict[str, F64]:
    """A peer's `rows` after each post-processing of :data:`VARIANTS` (see the module's text).

    `max_gap` is the most missing frames any of them fills: ByteTrack's ``n_dti`` and
    StrongSORT's ``interval`` are ``max_gap + 2``; `seed` is pftrack's calibration seed.
    """
    if len(rows) == 0:
        return dict.fromkeys(VARIANTS, rows)
    link = link_config_for(rows, max_gap)
    return {
        "raw": rows,
        "linear": bytetrack_interpolation(rows, n_dti=max_gap + 2),
        "gsi": strongsort_gsi(rows, interval=max_gap + 2),
        "recover": fill_gaps(rows, "auto", max_gap, seed=seed)[0],
        "recover-gsi": fill_gaps(rows, "gsi", max_gap)[0],
        "smooth": smooth_tracks(rows, link=link, max_gap=max_gap, seed=seed),
        "smooth-no-link": smooth_tracks(rows, link=None, max_gap=max_gap, seed=seed),
    }


# ---- running -----------------------------------------------------------------------------------


@dataclass(frozen=True)
class PeerInput:
    """What a peer needs of one sequence: its detections per frame, and what scores it."""

    seq: compare_trackers.Sequence
    frames: BlackFrames  # the video's length and size; peers read no pixels
    dets: list[compare_trackers.Boxes]
    gt: F64
    size: tuple[int, int]


def peer_input(root: Path, name: str) -> PeerInput:
    """The sequence `name` of :data:`experiments.compare_trackers.SEQUENCES` under `root`,
    without decoding its video: the length and size come from its ``seqinfo.ini`` (PETS09's
    768x576 scaled by 0.625, as its detections and truth are)."""
    seq = compare_trackers.SEQUENCES[name]
    folder = root / (seq.folder or name)
    info = read_seqinfo(folder, keys=("seqLength", "imWidth", "imHeight"))
    if info.length is None or info.width is None or info.height is None:
        raise ValueError(f"{folder}/seqinfo.ini: no seqLength/imWidth/imHeight")
    size = (round(info.width * seq.scale), round(info.height * seq.scale))
    frames = BlackFrames(info.length, *size)
    dets = compare_trackers.public_detections(folder, seq, info.length)
    gt = read_mot(folder / "gt.txt", what="ground truth")
    return PeerInput(seq, frames, dets, gt, size)


def peer_rows(tracker: str, inp: PeerInput) -> F64:
    """The rows `tracker` (a key of ``compare_trackers.TRACKERS``) reports on `inp`.

    Raises ImportError when the peer is not installed.
    """
    step = compare_trackers.TRACKERS[tracker](inp.seq)
    with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
        warnings.simplefilter("ignore")
        return compare_trackers.online_rows(step, inp.frames, inp.dets)[0]


@dataclass(frozen=True)
class Row:
    """One scored result: a peer's rows on a sequence (or pooled) after one variant."""

    tracker: str
    sequence: str
    variant: str
    scores: SequenceScores
    n_rows: int


HEAD = "| tracker | sequence | variant | MOTA | IDF1 | HOTA | IDSW | FP | FN | rows |"


def markdown_line(r: Row) -> str:
    """One table line of `r` (percentages with one decimal)."""
    m, h = r.scores.mot, r.scores.hota
    return (
        f"| {r.tracker} | {r.sequence} | {r.variant} | {100 * m.mota:.1f} | "
        f"{100 * m.idf1:.1f} | {100 * h.hota:.1f} | {m.num_switches} | "
        f"{m.false_positives} | {m.misses} | {'' if r.n_rows < 0 else r.n_rows} |"
    )


def markdown(rows: list[Row]) -> str:
    """The long table: one line per (tracker, sequence, variant)."""
    return "\n".join([HEAD, "|" + "---|" * (HEAD.count("|") - 1), *map(markdown_line, rows)])


def summary(rows: list[Row]) -> str:
    """MOTA / IDF1 / HOTA of each variant side by side, one line per tracker and sequence."""
    head = "| tracker | sequence | " + " | ".join(VARIANTS) + " |"
    lines = [head, "|" + "---|" * (len(VARIANTS) + 2)]
    cells: dict[tuple[str, str], dict[str, str]] = {}
    for r in rows:
        m, h = r.scores.mot, r.scores.hota
        cells.setdefault((r.tracker, r.sequence), {})[r.variant] = (
            f"{100 * m.mota:.1f} / {100 * m.idf1:.1f} / {100 * h.hota:.1f}"
        )
    for (tracker, name), c in cells.items():
        lines.append(f"| {tracker} | {name} | " + " | ".join(c.get(v, "") for v in VARIANTS) + " |")
    return "\n".join(lines)


def run(
    root: Path,
    names: list[str],
    trackers: list[str],
    *,
    max_gap: int = 18,
    seed: int = 0,
    echo: Callable[[str], None] = print,
) -> tuple[list[Row], list[str]]:
    """Score every tracker of `trackers` on every sequence of `names` after each variant;
    return the rows (each tracker's pooled rows after its sequences) and notes on skipped
    peers."""
    rows: list[Row] = []
    notes: list[str] = []
    per: dict[tuple[str, str], list[SequenceScores]] = {}
    inputs = {name: peer_input(root, name) for name in names}
    for tracker in trackers:
        for name, inp in inputs.items():
            try:
                raw = peer_rows(tracker, inp)
            except ImportError as exc:
                notes.append(f"{tracker}: skipped ({exc})")
                break
            for variant, res in variants(raw, max_gap, seed).items():
                s = evaluate_sequence(inp.gt, res, scale=inp.seq.scale, image_size=inp.size)
                per.setdefault((tracker, variant), []).append(s)
                rows.append(Row(tracker, name, variant, s, len(res)))
                echo(markdown_line(rows[-1]))
        else:
            for variant in VARIANTS:
                pooled = SequenceScores.combine(per[(tracker, variant)])
                rows.append(Row(tracker, POOLED, variant, pooled, -1))
                echo(markdown_line(rows[-1]))
    return rows, notes


def main(argv: list[str] | None = None) -> int:
    ap = experiment_parser("peer_gap_filling", __doc__)
    ap.add_argument("--seq", nargs="+", default=list(compare_trackers.SEQUENCES),
                    metavar="SEQ", help="sequences, of experiments.compare_trackers.SEQUENCES "
                    "(default: all five)")  # fmt: skip
    ap.add_argument("--tracker", nargs="+", default=list(PEERS), choices=PEERS,
                    help="peers (default: every one; one not installed is skipped)")  # fmt: skip
    ap.add_argument("--max-gap", type=int, default=18,
                    help="most missing frames filled by every variant: ByteTrack's n_dti and "
                    "StrongSORT's interval are this + 2 (default: 18, their 20)")  # fmt: skip
    ap.add_argument("--seed", type=int, default=0,
                    help="seed of pftrack's auto calibration (default: 0)")  # fmt: skip
    args = ap.parse_args(argv)
    root = data_folder(args.data)
    if root is None:
        return 2
    unknown = [s for s in args.seq if s not in compare_trackers.SEQUENCES]
    if unknown:
        print(f"unknown sequence {unknown[0]!r}: expected one of "
              f"{', '.join(compare_trackers.SEQUENCES)}", file=sys.stderr)  # fmt: skip
        return 2
    if args.max_gap < 1:
        print(f"--max-gap is {args.max_gap}, expected at least 1", file=sys.stderr)
        return 2
    print(HEAD, flush=True)
    rows, notes = run(
        root, args.seq, args.tracker, max_gap=args.max_gap, seed=args.seed,
        echo=lambda s: print(s, flush=True),
    )  # fmt: skip
    text = markdown(rows) + "\n\nMOTA / IDF1 / HOTA:\n\n" + summary(rows) + "\n"
    text += "".join(f"\n- {n}" for n in notes)
    print()
    print(text)
    write_text(args.out / "peer_gap_filling.md", text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
