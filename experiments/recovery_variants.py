"""Principled variants of ``gdt-bi`` on the paper's mask protocol (an exploration, not a test).

Reproduces the table "Variants tried" of docs/recovery.md: the median over mask positions of
the MMAE total (box centre) of the shipped ``gdt-bi`` and of variants whose parameters are all
estimated from observed points, never chosen on the lost ones:

* ``per-gap noise``: ``q, r`` estimated by maximum likelihood from the two segments of each gap
  instead of from every observed point of the sequence;
* ``history H``: the end-state filters use only the last/first ``H`` points;
* ``iou tau=K``: velocity as an Ornstein-Uhlenbeck process of time constant ``K`` frames
  (``dv = -v/K dt + sqrt(q) dW``; ``K -> inf`` is the white-noise-acceleration model of
  ``gdt-bi``), ``q, r`` re-estimated by maximum likelihood for each ``K``, fixed-interval
  (RTS) smoother over both segments and the gap;
* ``bma over tau``: per gap and axis, Bayesian model average of the ``iou`` smoothers
  (``K`` in {inf, 40, 20, 10, 5}) weighted by the Kalman likelihood of the gap's window.

``--more`` (second round, docs/recovery.md "Second round") adds, on PETS, TUD-Campus and the
synthetic scenes 0/1/2:

* ``ca``: constant acceleration (white jerk), ``q, r`` by maximum likelihood;
* ``singer``: acceleration as an Ornstein-Uhlenbeck process (Singer 1970), ``q, r`` and its
  time constant by maximum likelihood;
* ``singer+ou``: the same plus a mean-reverting velocity (both time constants by ML);
* ``stop mixture``: ``gdt-bi`` mixed over "the object stands still inside the gap" hypotheses
  (:func:`stop_mixture`), stop rate estimated from the observed runs
  (:func:`pftrack.recovery.mixture.stand_rate`);
* the per-mask oracle of ``gdt-bi`` over the ratio ``q / r`` (a bound, uses the lost points).

For the ``iou`` variants ``q, r`` are fitted once per sequence on the points observed around
the representative mask (the fit is cheap in C++ for ``gdt-bi`` but slow in this NumPy
exploration), so they see nothing inside that mask.

The printed tables are also written to ``--out`` (default ``out/recovery_variants``):
``variants.txt``, ``by_length.txt`` (``--by-length``: ``gdt-bi`` and ``linear`` error per
gap-length bin on PETS) or ``more_centre.txt`` / ``more_foot.txt`` (``--more``, which also writes
the synthetic scenes' ground truth there).

Usage (from the repository root; about 3 minutes on one core)::

    python -m experiments.recovery_variants [--data ../shared/data] [--max-positions 60]
        [--by-length | --more [--point centre|foot]] [--out out/recovery_variants]
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy.linalg import expm
from scipy.optimize import minimize

from experiments._common import data_root, experiment_parser, tee_stdout
from pftrack._typing import F64
from pftrack.io.mot import read_mot
from pftrack.recovery import (
    NoiseEstimate,
    estimate_noise,
    fit_motion,
    gdt_bi_problem,
    recover_gaps,
)
from pftrack.recovery import experiment as E
from pftrack.recovery.mixture import stand_rate

_BIG = 1e4  # prior variance of the unknown initial position and velocity


def iou_model(q: float, tau: float) -> tuple[F64, F64]:
    """One-frame transition and noise of ``(p, v)`` with ``dv = -v/tau dt + sqrt(q) dW``.

    Van Loan's matrix exponential, so ``tau = inf`` gives the white-noise-acceleration model.
    """
    Fc = np.array([[0.0, 1.0], [0.0, 0.0 if np.isinf(tau) else -1.0 / tau]])
    M = np.zeros((4, 4))
    M[:2, :2] = -Fc
    M[1, 3] = q
    M[2:, 2:] = Fc.T
    V = expm(M)
    F = V[2:, 2:].T
    Q = F @ V[:2, 2:]
    return F, 0.5 * (Q + Q.T)


def _padded(runs: Sequence[F64], axis: int) -> tuple[F64, NDArray[np.bool_]]:
    """One axis of every run of at least 6 points, as rows padded to the longest, and the mask
    of real entries (what :func:`_loglik` takes)."""
    runs = [r for r in runs if len(r) >= 6]
    L = max(len(r) for r in runs)
    Z = np.zeros((len(runs), L))
    mask = np.zeros((len(runs), L), dtype=bool)
    for i, r in enumerate(runs):
        Z[i, : len(r)] = r[:, 1 + axis]
        mask[i, : len(r)] = True
    return Z, mask


def fit_iou(runs: Sequence[F64], axis: int, tau: float) -> tuple[float, float]:
    """Maximum-likelihood ``(q, r)`` of one axis for a given ``tau`` (Nelder-Mead on logs)."""
    Z, mask = _padded(runs, axis)

    def nll(th: F64) -> float:
        F, Q = iou_model(float(np.exp(th[0])), tau)
        return -_loglik(F, Q, float(np.exp(th[1])), Z, mask)

    res = minimize(nll, np.log([0.1, 0.1]), method="Nelder-Mead", options={"xatol": 1e-3})
    return float(np.exp(res.x[0])), float(np.exp(res.x[1]))


def smooth_gap(
    F: F64, Q: F64, r: float, a: F64, b: F64, axis: int, history: int = 60
) -> tuple[F64, float]:
    """RTS-smoothed positions inside the gap and the window's Kalman log-likelihood, for any
    state dimension (position first; diffuse start)."""
    a, b = a[-history:], b[:history]
    d = F.shape[0]
    f0 = int(a[0, 0])
    n = int(b[-1, 0]) - f0 + 1
    z = np.full(n, np.nan)
    z[(a[:, 0] - f0).astype(int)] = a[:, 1 + axis]
    z[(b[:, 0] - f0).astype(int)] = b[:, 1 + axis]
    m = np.zeros(d)
    m[0] = z[0]
    P = np.eye(d) * _BIG
    ms, Ps = np.zeros((n, d)), np.zeros((n, d, d))
    mp, Pp = np.zeros((n, d)), np.zeros((n, d, d))
    ll, seen = 0.0, 0
    for t in range(n):
        if t > 0:
            m, P = F @ m, F @ P @ F.T + Q
        mp[t], Pp[t] = m, P
        if not np.isnan(z[t]):
            S = P[0, 0] + r
            v = z[t] - m[0]
            if seen >= 2:
                ll -= 0.5 * (np.log(2.0 * np.pi * S) + v * v / S)
            seen += 1
            K = P[:, 0] / S
            m, P = m + K * v, P - np.outer(K, P[0])
        ms[t], Ps[t] = m, P
    for t in range(n - 2, -1, -1):
        C = Ps[t] @ F.T @ np.linalg.inv(Pp[t + 1])
        ms[t] = ms[t] + C @ (ms[t + 1] - mp[t + 1])
    fa, fb = int(a[-1, 0]) - f0, int(b[0, 0]) - f0
    return ms[fa + 1 : fb, 0], ll


Variant = Callable[[list[E.Gap], list[F64]], list[F64]]
"""A recovery variant: (gaps of one mask, observed runs of that mask) -> one path per gap."""

Selection = tuple[int | None, int | None, int]
"""Mask positions kept by :func:`pftrack.recovery.experiment.sweep`: n_trajectories, n_gaps,
min_gaps."""
PETS_MASKS: Selection = (15, 23, 1)  # the paper's: 15 trajectories, 23 gaps
OTHER_MASKS: Selection = (None, None, 3)  # at least 3 gaps


def shipped(history: int | None = None, per_gap: bool = False) -> Variant:
    def run(gaps: list[E.Gap], runs: list[F64]) -> list[F64]:
        pairs = [(g.segment_a, g.segment_b) for g in gaps]
        if per_gap:
            return [recover_gaps([p], "gdt-bi", history=history)[0] for p in pairs]
        return recover_gaps(pairs, "gdt-bi", noise=estimate_noise(runs), history=history)

    return run


def iou(models: list[list[tuple[F64, F64, float]]]) -> Variant:
    """One model per axis -> RTS smoother; several -> per-gap likelihood-weighted average."""

    def run(gaps: list[E.Gap], runs: list[F64]) -> list[F64]:
        out = []
        for g in gaps:
            cols = []
            for axis in range(2):
                paths, lls = [], []
                for F, Q, r in models[axis]:
                    p, ll = smooth_gap(F, Q, r, g.segment_a, g.segment_b, axis)
                    paths.append(p)
                    lls.append(ll)
                w = np.exp(np.array(lls) - max(lls))
                cols.append(np.sum(w[:, None] * np.array(paths), axis=0) / w.sum())
            out.append(np.column_stack(cols))
        return out

    return run


def state_model(q: float, tau_a: float, tau_v: float = np.inf) -> tuple[F64, F64]:
    """One-frame ``(F, Q)`` of ``(p, v, a)`` (Van Loan), continuous model below.

    ``da = -a/tau_a dt + sqrt(q) dW`` and ``dv = (a - v/tau_v) dt``; ``tau_a = inf`` is
    constant acceleration (white jerk), finite ``tau_a`` the Singer model.
    """
    Fc = np.array(
        [
            [0.0, 1.0, 0.0],
            [0.0, 0.0 if np.isinf(tau_v) else -1.0 / tau_v, 1.0],
            [0.0, 0.0, 0.0 if np.isinf(tau_a) else -1.0 / tau_a],
        ]
    )
    d = 3
    M = np.zeros((2 * d, 2 * d))
    M[:d, :d] = -Fc
    M[d - 1, 2 * d - 1] = q
    M[d:, d:] = Fc.T
    V = expm(M)
    F = V[d:, d:].T
    Q = F @ V[:d, d:]
    return F, 0.5 * (Q + Q.T)


def _loglik(F: F64, Q: F64, r: float, Z: F64, mask: NDArray[np.bool_]) -> float:
    """Kalman prediction-error log-likelihood of many runs (rows of Z) for any state dimension
    ``d`` (first ``d`` points given; -inf when it is not finite)."""
    n_runs, d = Z.shape[0], F.shape[0]
    m = np.zeros((n_runs, d))
    m[:, 0] = Z[:, 0]
    P = np.broadcast_to(np.eye(d) * _BIG, (n_runs, d, d)).copy()
    ll = 0.0
    for t in range(Z.shape[1]):
        if t > 0:
            m = m @ F.T
            P = F @ P @ F.T + Q
        S = P[:, 0, 0] + r
        v = Z[:, t] - m[:, 0]
        K = P[:, :, 0] / S[:, None]
        ok = mask[:, t]
        m = np.where(ok[:, None], m + K * v[:, None], m)
        P = np.where(ok[:, None, None], P - K[:, :, None] * P[:, 0, None, :], P)
        if t >= d:
            ll -= 0.5 * float(np.sum((np.log(S) + v * v / S)[ok]))
    return ll if np.isfinite(ll) else -np.inf


def fit_state_model(runs: Sequence[F64], axis: int, kind: str) -> tuple[F64, F64, float]:
    """Maximum-likelihood ``(F, Q, r)`` of one axis; ``kind`` in {ca, singer, singer+ou}."""
    Z, mask = _padded(runs, axis)

    def unpack(th: F64) -> tuple[float, float, float, float]:
        e = np.exp(th)
        tau_a = float(e[2]) if kind != "ca" else np.inf
        tau_v = float(e[3]) if kind == "singer+ou" else np.inf
        return float(e[0]), float(e[1]), tau_a, tau_v

    def nll(th: F64) -> float:
        q, r, tau_a, tau_v = unpack(th)
        F, Q = state_model(q, tau_a, tau_v)
        ll = _loglik(F, Q, r, Z, mask)
        return -ll if np.isfinite(ll) else 1e12

    x0 = np.log([0.1, 0.1, 3.0, 50.0][: {"ca": 2, "singer": 3, "singer+ou": 4}[kind]])
    with np.errstate(all="ignore"):
        res = minimize(nll, x0, method="Nelder-Mead", options={"xatol": 1e-3, "fatol": 1e-3})
    q, r, tau_a, tau_v = unpack(res.x)
    F, Q = state_model(q, tau_a, tau_v)
    return F, Q, r


def nd_variant(models: list[tuple[F64, F64, float]]) -> Variant:
    def run(gaps: list[E.Gap], runs: list[F64]) -> list[F64]:
        return [
            np.column_stack(
                [smooth_gap(*models[ax], g.segment_a, g.segment_b, ax)[0] for ax in range(2)]
            )
            for g in gaps
        ]

    return run


def stop_mixture(a: F64, b: F64, noise: NoiseEstimate, rate: float, v2: F64, grid: int = 12) -> F64:
    """``gdt-bi`` mixed over hypotheses "walks, stands still from step t1 to t2, walks on".

    Each hypothesis is a linear-Gaussian path with per-step ``A_t, Q_t`` (standing: velocity
    reset to 0, position random walk ``q/3``; restart: fresh velocity of variance ``v2``, the
    mean squared observed velocity); it is conditioned on the same start (forward filter over
    A) and goal (backward filter over B) as ``gdt-bi``. ``t1 < t2`` on a grid of ``grid`` steps;
    prior ``P(no stop) = exp(-rate T)``, the rest spread evenly; posterior weights from the
    evidence of the goal. ``rate = 0`` is ``gdt-bi`` exactly.
    """
    problem = gdt_bi_problem(a, b, noise)
    Pi, m0, P0, y, T = problem.Pi_T, problem.m0, problem.Pi_0, problem.y_T, problem.T
    if rate <= 0.0:
        return recover_gaps([(a, b)], "gdt-bi", noise=noise)[0]
    ks = np.unique(np.round(np.linspace(0, T - 1, min(grid, T))).astype(int))
    hyps = [(t1, t2) for t1 in ks for t2 in ks if t2 > t1]
    nh = len(hyps) + 1
    p_stop = -np.expm1(-rate * T)
    logw = np.full(nh, np.log(p_stop / max(nh - 1, 1)))
    logw[0] = -rate * T
    walk = np.array([[1.0, 1.0], [0.0, 1.0]])
    stand = np.array([[1.0, 0.0], [0.0, 0.0]])
    paths = np.zeros((nh, T + 1, 2))
    for ax in range(2):
        q = noise.q[ax]
        A = np.broadcast_to(walk, (nh, T + 1, 2, 2)).copy()
        Q = np.broadcast_to(q * np.array([[1 / 3, 1 / 2], [1 / 2, 1.0]]), (nh, T + 1, 2, 2)).copy()
        for h, (t1, t2) in enumerate(hyps, start=1):
            A[h, t1 + 1 : t2 + 2] = stand
            Q[h, t1 + 1 : t2 + 1] = np.diag([q / 3.0, 0.0])
            if t2 + 1 <= T:
                Q[h, t2 + 1] = np.diag([q / 3.0, v2[ax]])
        idx = [ax, ax + 2]
        mu = np.zeros((nh, T + 1, 2))
        Sig = np.zeros((nh, T + 1, 2, 2))
        mu[:, 0] = m0[idx]
        Sig[:, 0] = P0[np.ix_(idx, idx)]
        for k in range(1, T + 1):
            mu[:, k] = np.einsum("hij,hj->hi", A[:, k], mu[:, k - 1])
            Sig[:, k] = A[:, k] @ Sig[:, k - 1] @ A[:, k].transpose(0, 2, 1) + Q[:, k]
        Phi = np.zeros((nh, T + 1, 2, 2))  # Phi(T, t)
        Phi[:, T] = np.eye(2)
        for k in range(T, 0, -1):
            Phi[:, k - 1] = Phi[:, k] @ A[:, k]
        Sy = Sig[:, T] + Pi[np.ix_(idx, idx)]
        Syi = np.linalg.inv(Sy)
        innov = y[idx] - mu[:, T]
        gain = np.einsum("htij,htkj,hkl->htil", Sig, Phi, Syi)  # cov(x_t, x_T) Sy^-1
        paths[:, :, ax] = mu[:, :, 0] + np.einsum("htj,hj->ht", gain[:, :, 0, :], innov)
        logw -= 0.5 * (np.log(np.linalg.det(Sy)) + np.einsum("hi,hij,hj->h", innov, Syi, innov))
    w = np.exp(logw - logw.max())
    return np.asarray(np.einsum("h,htc->tc", w / w.sum(), paths)[1:T])


def gdt_mix() -> Variant:
    """The shipped ``gdt-mix``: model fitted per mask to every observed point."""

    def run(gaps: list[E.Gap], runs: list[F64]) -> list[F64]:
        pairs = [(g.segment_a, g.segment_b) for g in gaps]
        noise = estimate_noise(runs)
        return recover_gaps(pairs, "gdt-mix", noise=noise, motion=fit_motion(runs, noise))

    return run


def stop_variant() -> Variant:
    def run(gaps: list[E.Gap], runs: list[F64]) -> list[F64]:
        noise = estimate_noise(runs)
        rate = stand_rate(runs, noise)
        v2 = np.mean(np.vstack([np.diff(r[:, 1:3], axis=0) for r in runs if len(r) > 1]) ** 2, 0)
        return [stop_mixture(g.segment_a, g.segment_b, noise, rate, v2) for g in gaps]

    return run


def oracle_ratio(masks: list[tuple[list[E.Gap], list[F64]]]) -> float:
    """Median over masks of the best ``gdt-bi`` MMAE over ``q/r`` scaled by 1/100 .. 100."""
    per = []
    for gaps, runs in masks:
        n = estimate_noise(runs)
        pairs = [(g.segment_a, g.segment_b) for g in gaps]
        best = np.inf
        for f in 10.0 ** np.arange(-2.0, 2.01, 0.5):
            paths = recover_gaps(
                pairs, "gdt-bi", noise=NoiseEstimate(q=(n.q[0] * f, n.q[1] * f), r=n.r)
            )
            best = min(
                best,
                float(np.mean([g.errors(p).mean() for p, g in zip(paths, gaps, strict=True)])),
            )
        per.append(best)
    return float(np.median(per))


def more(data: Path, max_positions: int, point: str, out: Path) -> None:
    """Second round: higher-order ML models, the stop mixture and the q/r oracle.

    The ground truth of the synthetic scenes is written to `out` (``syn0.txt`` ...) and read back.
    """
    from pftrack.synthetic import make_scene

    setups: list[tuple[str, Path, tuple[int, int], Selection]] = [
        ("PETS", data / "pets09-s2l1" / "gt.txt", (768, 576), PETS_MASKS),
        ("TUD-Campus", data / "tud-campus" / "gt.txt", (640, 480), OTHER_MASKS),
    ]
    out.mkdir(parents=True, exist_ok=True)
    for seed in (0, 1, 2):
        path = make_scene(n_frames=300, n_walkers=12, rng=seed).write_truth(out / f"syn{seed}.txt")
        setups.append((f"synthetic {seed}", path, (480, 360), OTHER_MASKS))
    for name, gt, (w, h), sel in setups:
        trajs = E.trajectories(read_mot(gt), point)
        sw = E.sweep(trajs, 100, w, h, 4, *sel)
        pos = sw.positions
        cap = 0 if name == "PETS" else max_positions
        if cap and len(pos) > cap:
            pos = pos[np.linspace(0, len(pos) - 1, cap).round().astype(int)]
        masks = [(E.find_gaps(trajs, p)[0], E.observed_runs(trajs, p)) for p in pos]
        fit_runs = E.observed_runs(trajs, sw.representative())
        variants: dict[str, Variant] = {"gdt-bi (shipped)": shipped()}
        for kind in ("ca", "singer", "singer+ou"):
            variants[kind] = nd_variant([fit_state_model(fit_runs, ax, kind) for ax in range(2)])
        variants["stop mixture"] = stop_variant()
        variants["gdt-mix (shipped)"] = gdt_mix()
        print(f"{name} ({point}): median MMAE total over {len(masks)} positions", flush=True)
        for label, v in variants.items():
            print(f"  {label:<20}{median_mmae(masks, v):8.3f}", flush=True)
        print(f"  {'oracle q/r per mask':<20}{oracle_ratio(masks):8.3f}", flush=True)


def median_mmae(masks: list[tuple[list[E.Gap], list[F64]]], variant: Variant) -> float:
    per = []
    for gaps, runs in masks:
        paths = variant(gaps, runs)
        per.append(np.mean([g.errors(p).mean() for p, g in zip(paths, gaps, strict=True)]))
    return float(np.median(per))


def by_length(data: Path) -> None:
    """Mean error of ``gdt-bi`` and ``linear`` per gap-length bin, all PETS 15/23 masks."""
    trajs = E.trajectories(read_mot(data / "pets09-s2l1" / "gt.txt"))
    rows = []
    for p in E.sweep(trajs, 100, 768, 576, 4, 15, 23).positions:
        gaps = E.find_gaps(trajs, p)[0]
        pairs = [(g.segment_a, g.segment_b) for g in gaps]
        bi = recover_gaps(pairs, "gdt-bi", noise=estimate_noise(E.observed_runs(trajs, p)))
        lin = recover_gaps(pairs, "linear")
        for g, pb, pl in zip(gaps, bi, lin, strict=True):
            rows.append((len(g.truth), g.errors(pb).mean(), g.errors(pl).mean()))
    a = np.array(rows)
    print(f"{len(a)} gaps; lost frames | gaps | gdt-bi mean | linear mean (px)")
    for lo, hi in [(1, 10), (10, 20), (20, 30), (30, 1000)]:
        s = (a[:, 0] >= lo) & (a[:, 0] < hi)
        print(f"{lo:>4}-{hi - 1:<4}{int(s.sum()):>6}{a[s, 1].mean():>10.3f}{a[s, 2].mean():>10.3f}")


def main(argv: Sequence[str] | None = None) -> int:
    ap = experiment_parser("recovery_variants", __doc__)
    ap.add_argument("--max-positions", type=int, default=60, help="for TUD-Campus")
    ap.add_argument("--by-length", action="store_true", help="PETS: gdt-bi error by gap length")
    ap.add_argument("--more", action="store_true", help="second round (docs: Second round)")
    ap.add_argument("--point", choices=("centre", "foot"), default="centre", help="with --more")
    args = ap.parse_args(argv)
    data = data_root(args.data)
    if args.more:
        with tee_stdout(args.out / f"more_{args.point}.txt"):
            more(data, args.max_positions, args.point, args.out)
    elif args.by_length:
        with tee_stdout(args.out / "by_length.txt"):
            by_length(data)
    else:
        with tee_stdout(args.out / "variants.txt"):
            first_round(data, args.max_positions)
    return 0


def first_round(data: Path, max_positions: int) -> None:
    """The table "Variants tried": shipped ``gdt-bi``, per-gap noise, history, ``iou``, BMA."""
    setups: list[tuple[str, tuple[int, int], Selection]] = [
        ("pets09-s2l1", (768, 576), PETS_MASKS),
        ("tud-campus", (640, 480), OTHER_MASKS),
    ]
    taus = [np.inf, 40.0, 20.0, 10.0, 5.0]
    for name, (w, h), sel in setups:
        trajs = E.trajectories(read_mot(data / name / "gt.txt"))
        sw = E.sweep(trajs, 100, w, h, 4, *sel)
        pos = sw.positions
        if len(pos) > max_positions:
            pos = pos[np.linspace(0, len(pos) - 1, max_positions).round().astype(int)]
        masks = [(E.find_gaps(trajs, p)[0], E.observed_runs(trajs, p)) for p in pos]
        fit_runs = E.observed_runs(trajs, sw.representative())
        per_tau: dict[float, list[tuple[F64, F64, float]]] = {}
        for tau in taus:
            per_tau[tau] = []
            for axis in range(2):
                q, r = fit_iou(fit_runs, axis, tau)
                F, Q = iou_model(q, tau)
                per_tau[tau].append((F, Q, r))
        variants: dict[str, Variant] = {
            "gdt-bi (shipped)": shipped(),
            "per-gap noise": shipped(per_gap=True),
            "history 10": shipped(history=10),
        }
        for tau in taus:
            variants[f"iou tau={tau:g}"] = iou([[per_tau[tau][0]], [per_tau[tau][1]]])
        variants["bma over tau"] = iou([[per_tau[t][a] for t in taus] for a in range(2)])
        print(f"{name}: median MMAE total over {len(masks)} positions ({sw.selection})")
        for label, v in variants.items():
            print(f"  {label:<20}{median_mmae(masks, v):8.3f}", flush=True)


if __name__ == "__main__":
    raise SystemExit(main())
