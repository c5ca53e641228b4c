"""The paper's experiment: points of ground-truth trajectories inside a mask are lost; recover.

Protocol (Oh & Jung 2015, sec. 4): a ``w x h`` mask region (100 x 100 px); every ground-truth
point inside it is treated as lost; each maximal run of lost points of a trajectory is one gap,
recovered from the observed segments before and after it (from the previous gap, or the
trajectory's start, to the next gap, or its end); trajectories that start or end inside the mask
are left out. Errors per gap: mean absolute error per axis and mean Euclidean distance; MMAE is
their mean over gaps, MAE the mean over all recovered points.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import cast

import numpy as np
from numpy.typing import NDArray

from pftrack._check import mot_rows, option
from pftrack._progress import progress
from pftrack._typing import F64, RecoveryMethod
from pftrack.recovery.linking import check_unique
from pftrack.recovery.mixture import MotionFit, _fit_motion
from pftrack.recovery.names import NEIGHBOUR_METHODS
from pftrack.recovery.noise import NoiseEstimate, _estimate_noise
from pftrack.recovery.registry import METHODS, recover_gaps

__all__ = [
    "Gap",
    "MaskRun",
    "MedianScores",
    "Excess",
    "MethodScore",
    "SequenceResult",
    "Sweep",
    "auto_masks",
    "count_gaps_grid",
    "draw_figure",
    "find_gaps",
    "format_excess",
    "format_median",
    "format_sequences",
    "format_table",
    "median_over",
    "observed_runs",
    "paired_excess",
    "run_mask",
    "run_sequence",
    "score",
    "sweep",
    "trajectories",
]

MAX_SWEEP_POSITIONS = 1_000_000  # mask positions of one sweep (each costs a pass over the points)


@dataclass(frozen=True)
class Gap:
    """One gap: the segments around it and the true lost points ``(frame, x, y)``."""

    track_id: int
    segment_a: F64
    segment_b: F64
    truth: F64

    def at_truth(self, path: F64) -> F64:
        """The rows of `path` at the frames of the true lost points, ``(len(truth), 2)``.

        `path` holds ``(x, y)`` for every frame strictly between the two segments (what the
        recovery methods return); where the trajectory itself skips frames (ground truth with
        holes, a tracker's output), only the frames it has are scored.
        """
        at = (self.truth[:, 0] - self.segment_a[-1, 0] - 1).astype(np.int64)
        out: F64 = path[at, :2]
        return out

    def errors(self, path: F64) -> F64:
        """Euclidean error of `path` at each true lost point, ``(len(truth),)``."""
        d = self.at_truth(path) - self.truth[:, 1:3]
        out: F64 = np.hypot(d[:, 0], d[:, 1])
        return out


def trajectories(gt: F64, point: str = "centre") -> dict[int, F64]:
    """Split ground truth into trajectories: per id, rows ``(frame, x, y)`` sorted by frame.

    ``point`` is the box centre or its bottom centre (``"foot"``). A trajectory may skip
    frames (ground truth with holes, a tracker's output): only the frames it has are scored.

    Raises
    ------
    ValueError
        An unknown `point`, or a (frame, id) pair given twice (read a file with
        :func:`~pftrack.recovery.linking.read_tracks` for the lines).
    """
    option(point, "trajectories: point", ("centre", "center", "foot"))
    if point not in ("centre", "center", "foot"):
        raise ValueError(f"trajectories: point is {point!r}, expected 'centre' or 'foot'")
    gt = mot_rows(gt, "trajectories")
    check_unique(gt, who="trajectories")
    out: dict[int, F64] = {}
    for tid in np.unique(gt[:, 1]).astype(int):
        r = gt[gt[:, 1] == tid]
        r = r[np.argsort(r[:, 0])]
        x = r[:, 2] + 0.5 * r[:, 4]
        y = r[:, 3] + (r[:, 5] if point == "foot" else 0.5 * r[:, 5])
        out[int(tid)] = np.column_stack([r[:, 0], x, y])
    return out


def find_gaps(trajs: dict[int, F64], mask: Sequence[float]) -> tuple[list[Gap], int]:
    """Find the gaps made by `mask` ``(x, y, w, h)``.

    Returns the gaps and the number of trajectories that have at least one.
    """
    mx, my, mw, mh = (float(v) for v in mask)
    gaps: list[Gap] = []
    n_traj = 0
    for tid, tr in trajs.items():
        inside = (tr[:, 1] >= mx) & (tr[:, 1] < mx + mw) & (tr[:, 2] >= my) & (tr[:, 2] < my + mh)
        if not inside.any() or inside[0] or inside[-1]:
            continue
        n_traj += 1
        edges = np.diff(inside.astype(np.int8))
        starts = np.flatnonzero(edges == 1) + 1
        ends = np.flatnonzero(edges == -1) + 1  # exclusive
        bounds = [0] + [int(v) for pair in zip(starts, ends, strict=True) for v in pair] + [len(tr)]
        for g, (s, e) in enumerate(zip(starts, ends, strict=True)):
            a = tr[bounds[2 * g] : s]
            b = tr[e : bounds[2 * g + 3]]
            gaps.append(Gap(tid, a, b, tr[s:e]))
    return gaps, n_traj


def count_gaps_grid(
    trajs: dict[int, F64], size: float, width: float, height: float, step: float
) -> tuple[F64, F64, NDArray[np.int64], NDArray[np.int64]]:
    """Count trajectories and gaps for every mask position on a grid (vectorised)."""
    xs = np.arange(0.0, width - size + 1e-9, step)
    ys = np.arange(0.0, height - size + 1e-9, step)
    n_traj = np.zeros((len(ys), len(xs)), dtype=np.int64)
    n_gaps = np.zeros((len(ys), len(xs)), dtype=np.int64)
    for tr in trajs.values():
        inx = (tr[None, :, 1] >= xs[:, None]) & (tr[None, :, 1] < xs[:, None] + size)  # (X, P)
        iny = (tr[None, :, 2] >= ys[:, None]) & (tr[None, :, 2] < ys[:, None] + size)  # (Y, P)
        inside = iny[:, None, :] & inx[None, :, :]  # (Y, X, P)
        ok = inside.any(axis=2) & ~inside[:, :, 0] & ~inside[:, :, -1]
        runs = np.sum(np.diff(inside.astype(np.int8), axis=2) == 1, axis=2)
        n_traj += ok
        n_gaps += np.where(ok, runs, 0)
    return xs, ys, n_traj, n_gaps


@dataclass(frozen=True)
class MethodScore:
    """Scores of one method over the gaps of one mask."""

    mmae_x: float
    mmae_y: float
    mmae_total: float
    mae_x: float
    mae_y: float
    mae_total: float
    time_ms: float


def observed_runs(trajs: dict[int, F64], mask: Sequence[float]) -> list[F64]:
    """Every run of consecutive observed (outside the mask) points of every trajectory."""
    mx, my, mw, mh = (float(v) for v in mask)
    runs: list[F64] = []
    for tr in trajs.values():
        inside = (tr[:, 1] >= mx) & (tr[:, 1] < mx + mw) & (tr[:, 2] >= my) & (tr[:, 2] < my + mh)
        cut = np.flatnonzero(np.diff(inside.astype(np.int8)) != 0) + 1
        for part, flag in zip(np.split(tr, cut), np.split(inside, cut), strict=True):
            if not flag[0]:
                runs.append(part)
    return runs


def score(
    gaps: Sequence[Gap],
    method: RecoveryMethod,
    repeat: int = 1,
    noise: NoiseEstimate | None = None,
    motion: MotionFit | None = None,
    observed: Sequence[F64] | None = None,
    *,
    seed: int = 0,
    combine: bool = True,
) -> tuple[MethodScore, list[F64]]:
    """Recover all gaps with `method` (best wall time of `repeat` runs) and score them.

    `observed`, `seed`, `combine`: for ``"auto"``, the observed runs it calibrates on (all
    points outside the mask), its calibration seed and whether it may blend two methods;
    `observed` also for ``"linear-nb"`` and ``"rts-nb"`` (the tracks that correct them).
    """
    pairs = [(g.segment_a, g.segment_b) for g in gaps]
    best = np.inf
    paths: list[F64] = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        paths = recover_gaps(
            pairs, method, noise=noise, motion=motion, observed=observed, seed=seed,
            combine=combine,
        )  # fmt: skip
        best = min(best, time.perf_counter() - t0)
    ex, ey, ee = [], [], []
    for g, p in zip(gaps, paths, strict=True):  # scored where the truth has a point
        d = g.at_truth(p) - g.truth[:, 1:3]
        ex.append(np.abs(d[:, 0]))
        ey.append(np.abs(d[:, 1]))
        ee.append(np.hypot(d[:, 0], d[:, 1]))
    cat = np.concatenate
    return (
        MethodScore(
            float(np.mean([v.mean() for v in ex])),
            float(np.mean([v.mean() for v in ey])),
            float(np.mean([v.mean() for v in ee])),
            float(cat(ex).mean()),
            float(cat(ey).mean()),
            float(cat(ee).mean()),
            1e3 * best,
        ),
        paths,
    )


@dataclass
class MaskRun:
    """Everything measured on one mask position."""

    mask: tuple[float, float, float, float]
    gaps: list[Gap]
    n_traj: int
    scores: dict[str, MethodScore]
    paths: dict[str, list[F64]]
    noise: NoiseEstimate | None
    noise_ms: float
    motion: MotionFit | None = None
    motion_ms: float = 0.0


def run_mask(
    trajs: dict[int, F64],
    mask: Sequence[float],
    methods: Sequence[str] = METHODS,
    repeat: int = 1,
    *,
    seed: int = 0,
    combine: bool = True,
) -> MaskRun:
    """Run all methods on one mask.

    The noise levels of ``"gdt-bi"`` and the model of ``"gdt-mix"`` are estimated once from
    every observed point of the sequence (all points outside the mask), timed separately;
    ``"auto"`` calibrates on the same observed points (its time includes the calibration),
    with calibration seed `seed` and blends allowed by `combine`.
    """
    gaps, n_traj = find_gaps(trajs, mask)
    scores: dict[str, MethodScore] = {}
    paths: dict[str, list[F64]] = {}
    noise = motion = None
    noise_ms = motion_ms = 0.0
    runs: list[F64] | None = None
    if gaps:
        if set(methods) & {"auto", "gdt-bi", "gdt-mix", *NEIGHBOUR_METHODS}:
            runs = observed_runs(trajs, mask)  # what those methods see of the sequence
        if runs is not None and ("gdt-bi" in methods or "gdt-mix" in methods):
            t0 = time.perf_counter()
            noise = _estimate_noise(runs)
            noise_ms = 1e3 * (time.perf_counter() - t0)
            if "gdt-mix" in methods:
                t0 = time.perf_counter()
                motion = _fit_motion(runs, noise)
                motion_ms = 1e3 * (time.perf_counter() - t0)
        for m in methods:
            name = cast("RecoveryMethod", m)  # recover_gaps refuses a name that is not one
            if m == "auto":  # calibrates itself, from the observed points only
                scores[m], paths[m] = score(
                    gaps, name, repeat, observed=runs, seed=seed, combine=combine
                )
            elif m in NEIGHBOUR_METHODS:  # corrected by the other tracks outside the mask
                scores[m], paths[m] = score(gaps, name, repeat, observed=runs)
            else:
                scores[m], paths[m] = score(gaps, name, repeat, noise, motion)
    mk = tuple(float(v) for v in mask)
    return MaskRun(
        (mk[0], mk[1], mk[2], mk[3]),
        gaps,
        n_traj,
        scores,
        paths,
        noise,
        noise_ms,
        motion,
        motion_ms,
    )


def format_table(scores: dict[str, MethodScore], title: str = "") -> str:
    """Table 1 + 2 of the paper, one column per method."""
    methods = list(scores)
    width = max(10, *(len(m) + 2 for m in methods))
    head = f"{'':<14}" + "".join(f"{m:>{width}}" for m in methods)
    rows = [title, head] if title else [head]
    for label, attr in [
        ("MMAE x", "mmae_x"),
        ("MMAE y", "mmae_y"),
        ("MMAE total", "mmae_total"),
        ("MAE x", "mae_x"),
        ("MAE y", "mae_y"),
        ("MAE total", "mae_total"),
        ("time (ms)", "time_ms"),
    ]:
        rows.append(
            f"{label:<14}" + "".join(f"{getattr(scores[m], attr):>{width}.3f}" for m in methods)
        )
    return "\n".join(rows)


def _draw_panel(
    trajs: dict[int, F64],
    gaps: Sequence[Gap],
    paths: dict[str, list[F64]],
    mask: Sequence[float],
    methods: Sequence[str],
    origin: tuple[float, float],
    scale: float,
    size: tuple[int, int],
) -> NDArray[np.uint8]:
    import cv2

    img = np.zeros((size[1], size[0], 3), np.uint8)
    ox, oy = origin

    def pts(xy: F64) -> NDArray[np.int32]:
        scaled = np.column_stack([(xy[:, 0] - ox) * scale, (xy[:, 1] - oy) * scale]) * 16
        out: NDArray[np.int32] = np.round(scaled).astype(np.int32)
        return out

    for tr in trajs.values():
        cv2.polylines(img, [pts(tr[:, 1:3])], False, (90, 90, 90), 1, cv2.LINE_AA, 4)
    mx, my, mw, mh = mask
    corners = pts(np.array([[mx, my], [mx + mw, my + mh]]))
    cv2.rectangle(img, tuple(corners[0]), tuple(corners[1]), (0, 200, 200), 1, cv2.LINE_AA, 4)
    for k, m in enumerate(methods):
        for g, p in zip(gaps, paths.get(m, []), strict=False):
            full = np.vstack([g.segment_a[-1:, 1:3], p, g.segment_b[:1, 1:3]])
            cv2.polylines(img, [pts(full)], False, _COLOURS[k % len(_COLOURS)], 1, cv2.LINE_AA, 4)
    radius = max(1, int(round(0.6 * scale)))
    for g in gaps:
        for x, y in pts(g.truth[:, 1:3]):
            cv2.circle(img, (int(x), int(y)), radius * 16, (255, 255, 255), -1, cv2.LINE_AA, 4)
    return img


_COLOURS = [(60, 60, 255), (0, 220, 0), (255, 160, 0), (255, 0, 255), (0, 255, 255)]


#: Widest scene panel of :func:`draw_figure`, in heights (a 4:1 image fills it).
FIGURE_ASPECT = 4.0


def draw_figure(
    trajs: dict[int, F64],
    gaps: Sequence[Gap],
    paths: dict[str, list[F64]],
    mask: Sequence[float],
    size: tuple[int, int],
    methods: Sequence[str] = ("gdt", "gdt-mix", "bspline"),
    height: int = 360,
) -> NDArray[np.uint8]:
    """Draw ground truth against recovered paths with OpenCV.

    Left: the whole scene (`height` px high, at most :data:`FIGURE_ASPECT` times as wide);
    right: the mask region enlarged. Grey: ground-truth trajectories; white dots: the lost
    (ground-truth) points; coloured: recovered paths; yellow: the mask.
    """
    import cv2

    from pftrack.io.opencv_io import text_for_opencv

    w, h = size
    # at most FIGURE_ASPECT heights wide, at least 1 px: an image of 100000x1 px asked for a
    # panel 36 million px wide (out of memory), one of 1x100000 px for one 0 px wide (cv2.error)
    s_full = min(height / float(h), FIGURE_ASPECT * height / float(w))
    left = _draw_panel(
        trajs, gaps, paths, mask, methods, (0.0, 0.0), s_full,
        (max(1, int(round(w * s_full))), height),
    )  # fmt: skip
    mx, my, mw, mh = mask
    pad = 0.15 * max(mw, mh)
    side = max(mw, mh) + 2 * pad
    s_zoom = height / side
    right = _draw_panel(
        trajs, gaps, paths, mask, methods, (mx - pad, my - pad), s_zoom, (height, height)
    )
    img = np.hstack([left, np.full((height, 4, 3), 255, np.uint8), right])
    for k, m in enumerate(methods):
        cv2.putText(
            img,
            text_for_opencv(m),
            (8, 18 + 18 * k),
            cv2.FONT_HERSHEY_SIMPLEX,
            0.5,
            _COLOURS[k % len(_COLOURS)],
            1,
            cv2.LINE_AA,
        )
    cv2.putText(
        img,
        text_for_opencv("ground truth (dots: lost points)"),
        (8, 18 + 18 * len(methods)),
        cv2.FONT_HERSHEY_SIMPLEX,
        0.5,
        (255, 255, 255),
        1,
        cv2.LINE_AA,
    )
    return img


@dataclass(frozen=True)
class Sweep:
    """Mask positions of a grid that meet a selection."""

    positions: F64  # (K, 4) x, y, w, h
    selection: str

    def __len__(self) -> int:
        return len(self.positions)

    def representative(self) -> tuple[float, float, float, float]:
        """Return the kept position nearest the centroid of all kept positions.

        A rule that does not look at any result.
        """
        c = self.positions[:, :2].mean(axis=0)
        i = int(np.argmin(np.hypot(*(self.positions[:, :2] - c).T)))
        x, y, w, h = (float(v) for v in self.positions[i])
        return x, y, w, h


def sweep(
    trajs: dict[int, F64],
    size: float,
    width: float,
    height: float,
    step: float,
    n_trajectories: int | None = None,
    n_gaps: int | None = None,
    min_gaps: int = 1,
) -> Sweep:
    """Select mask positions (``size`` squares on a ``step`` grid).

    Kept: exactly `n_trajectories` trajectories and `n_gaps` gaps when given, else at least
    `min_gaps` gaps.
    """
    if not (size > 0 and step > 0 and np.isfinite(size) and np.isfinite(step)):
        raise ValueError(f"sweep: size {size} and step {step} must be finite and > 0")
    if not (np.isfinite(width) and np.isfinite(height)):
        raise ValueError(f"sweep: the image size {width} x {height} must be finite")
    nx = max(0.0, np.floor((width - size) / step) + 1)
    ny = max(0.0, np.floor((height - size) / step) + 1)
    if nx * ny > MAX_SWEEP_POSITIONS:
        raise ValueError(
            f"sweep: a {step:g} px grid over {width:g} x {height:g} gives {nx * ny:.3g} mask "
            f"positions, more than the limit of {MAX_SWEEP_POSITIONS}; use a coarser grid"
        )
    xs, ys, nt, ng = count_gaps_grid(trajs, size, width, height, step)
    keep = np.ones_like(nt, dtype=bool)
    parts = []
    if n_trajectories is not None:
        keep &= nt == n_trajectories
        parts.append(f"{n_trajectories} trajectories")
    if n_gaps is not None:
        keep &= ng == n_gaps
        parts.append(f"{n_gaps} gaps")
    if n_trajectories is None and n_gaps is None:
        keep &= ng >= min_gaps
        parts.append(f">= {min_gaps} gaps")
    iy, ix = np.nonzero(keep)
    pos = np.column_stack([xs[ix], ys[iy], np.full(len(ix), size), np.full(len(ix), size)])
    return Sweep(pos.astype(np.float64), ", ".join(parts))


@dataclass(frozen=True)
class MedianScores:
    """Medians over mask positions, per method, and how often each method was best."""

    n_positions: int
    median: dict[str, MethodScore]
    wins: dict[str, int]


def median_over(
    trajs: dict[int, F64], sw: Sweep, methods: Sequence[str] = METHODS, max_positions: int = 0
) -> MedianScores:
    """Run every method at every kept position and take the median of each score.

    With `max_positions`, only that many evenly spread positions are evaluated.
    """
    pos = sw.positions
    if max_positions and len(pos) > max_positions:
        pos = pos[np.linspace(0, len(pos) - 1, max_positions).round().astype(int)]
    per: dict[str, list[MethodScore]] = {m: [] for m in methods}
    wins = {m: 0 for m in methods}
    for p in progress(pos, desc="mask positions", unit="mask"):
        r = run_mask(trajs, p, methods)
        if not r.gaps:
            continue
        for m in methods:
            per[m].append(r.scores[m])
        wins[min(methods, key=lambda m: r.scores[m].mmae_total)] += 1
    fields = list(MethodScore.__dataclass_fields__)
    med = {
        m: MethodScore(*(float(np.median([getattr(s, f) for s in v])) for f in fields))
        for m, v in per.items()
        if v
    }
    return MedianScores(len(per[methods[0]]), med, wins)


def format_median(ms: MedianScores) -> str:
    """Table of the medians, plus the number of positions where each method was best."""
    text = format_table(ms.median, f"median over {ms.n_positions} mask positions")
    methods = list(ms.median)
    width = max(10, *(len(m) + 2 for m in methods))
    return text + "\n" + f"{'best at':<14}" + "".join(f"{ms.wins[m]:>{width}d}" for m in methods)


def auto_mask_side(width: float) -> float:
    """The side of :func:`auto_masks`' squares on an image `width` px wide: ``round(100 W/768)``.

    The image must hold it: at least that high (and wide, from 1 px up).
    """
    return float(round(100.0 * width / 768.0))


def auto_masks(
    trajs: dict[int, F64], width: float, height: float, n: int = 3
) -> list[tuple[float, float, float, float]]:
    """Masks of the multi-sequence protocol, placed greedily where they cut the most gaps.

    Squares of side ``round(100 W / 768)`` px on a ``round(4 W / 768)`` px grid, fully inside
    the ``width x height`` image; each next mask is the position (not overlapping the masks
    already placed) with the most gaps, ties broken by more trajectories, then by the mask
    centre nearer the image centre, then by grid order. Positions without a gap are not used,
    so fewer than `n` masks may be returned.

    Raises
    ------
    ValueError
        A non-positive image size, an image smaller than the mask, or `n` < 1.
    """
    if width <= 0 or height <= 0:
        raise ValueError(f"auto_masks: image size is {width:g}x{height:g}, expected > 0")
    if n < 1:
        raise ValueError(f"auto_masks: n is {n}, expected >= 1")
    size = auto_mask_side(width)
    step = float(max(1, round(4.0 * width / 768.0)))
    if size > width or size > height:
        raise ValueError(
            f"auto_masks: mask side {size:g} px exceeds the image {width:g}x{height:g}"
        )
    xs, ys, nt, ng = count_gaps_grid(trajs, size, width, height, step)
    gx, gy = np.meshgrid(xs, ys)
    dist = np.hypot(gx + size / 2 - width / 2, gy + size / 2 - height / 2)
    # lexsort: last key first -> most gaps, most trajectories, nearest centre, grid order
    order = np.lexsort((np.arange(dist.size), dist.ravel(), -nt.ravel(), -ng.ravel()))
    masks: list[tuple[float, float, float, float]] = []
    for i in order:
        if ng.flat[i] <= 0 or len(masks) >= n:
            break
        x, y = float(gx.flat[i]), float(gy.flat[i])
        if all(abs(x - m[0]) >= size or abs(y - m[1]) >= size for m in masks):
            masks.append((x, y, size, size))
    return masks


@dataclass(frozen=True)
class SequenceResult:
    """Multi-sequence protocol, one sequence: its masks and the errors of every gap per method.

    ``errors[m]`` holds the mean Euclidean error (px) of each gap, in mask order; the
    sequence's MMAE is their mean.
    """

    name: str
    image_size: tuple[float, float]
    masks: tuple[tuple[float, float, float, float], ...]
    n_gaps: int
    errors: dict[str, tuple[float, ...]]

    def mmae(self, method: str) -> float:
        """MMAE of `method` over every gap of the sequence (NaN without gaps)."""
        e = self.errors[method]
        return float(np.mean(e)) if e else float("nan")


def run_sequence(
    name: str,
    trajs: dict[int, F64],
    width: float,
    height: float,
    methods: Sequence[str] = METHODS,
    n_masks: int = 3,
    *,
    seed: int = 0,
    combine: bool = True,
) -> SequenceResult:
    """Run every method on the gaps of the automatic masks (:func:`auto_masks`) of a sequence.

    Each mask is its own experiment: the points inside it are lost, everything outside it is
    observed (noise levels, motion model and ``"auto"``'s calibration use only those; `seed`
    and `combine` are ``"auto"``'s, as in :func:`run_mask`).
    """
    masks = auto_masks(trajs, width, height, n_masks)
    errors: dict[str, list[float]] = {m: [] for m in methods}
    n_gaps = 0
    for mk in masks:
        run = run_mask(trajs, mk, methods, seed=seed, combine=combine)
        n_gaps += len(run.gaps)
        for m in methods:
            for g, p in zip(run.gaps, run.paths.get(m, []), strict=True):
                errors[m].append(float(np.mean(g.errors(p))))
    return SequenceResult(
        name,
        (float(width), float(height)),
        tuple(masks),
        n_gaps,
        {m: tuple(v) for m, v in errors.items()},
    )


#: What :func:`format_sequences` shows in place of the MMAEs of a sequence without a gap.
NO_GAPS = "no gaps: no mask cuts a trajectory (no MMAE; nothing pooled)"


def format_sequences(results: Sequence[SequenceResult], methods: Sequence[str]) -> str:
    """Per-sequence and pooled MMAE (px), one column per method; ``*`` marks each row's best.

    A sequence without a gap under its masks (so no error to average) shows :data:`NO_GAPS`
    instead of a row of NaN; the pooled row averages the gaps of the others.
    """
    width = max(10, *(len(m) + 3 for m in methods))
    name_w = max(12, *(len(r.name) + 2 for r in results)) if results else 12
    head = f"{'sequence':<{name_w}}{'gaps':>6}" + "".join(f"{m:>{width}}" for m in methods)
    lines = [head]
    pooled = {m: [e for r in results for e in r.errors[m]] for m in methods}
    rows = [(r.name, r.n_gaps, {m: r.mmae(m) for m in methods}) for r in results]
    n_all = sum(r.n_gaps for r in results)
    rows.append(
        ("pooled", n_all, {m: float(np.mean(v)) if v else float("nan") for m, v in pooled.items()})
    )
    for k, (label, n, vals) in enumerate(rows):
        if not n:  # the last row is the pooled one: then no sequence has a gap
            said = NO_GAPS if k < len(results) else "no gaps in any sequence: no MMAE"
            lines.append(f"{label:<{name_w}}{n:>6}  {said}")
            continue
        finite = [v for v in vals.values() if np.isfinite(v)]
        best = min(finite) if finite else float("nan")
        cells = "".join(
            f"{vals[m]:>{width - 1}.3f}{'*' if vals[m] == best else ' '}" for m in methods
        )
        lines.append(f"{label:<{name_w}}{n:>6}{cells}")
    return "\n".join(lines)


@dataclass(frozen=True)
class Excess:
    """One method's paired excess error over the best other method of a sequence (or the pool).

    Attributes
    ----------
    name : str
        The sequence, or ``"pooled"``.
    method : str
        The method compared (``"auto"`` by default: the first of the methods run).
    best : str
        The other method with the lowest MMAE on these gaps (the first of equals).
    n_gaps : int
        Gaps compared.
    diff : float
        Mean over the gaps of ``method``'s error less ``best``'s (px; negative: `method` is
        better).
    se : float
        Standard error of `diff` (the gaps' differences' standard deviation over
        ``sqrt(n_gaps)``; NaN with one gap). A `diff` within about two of these is what
        another draw of the gaps could undo.
    share : float
        `diff` over ``best``'s MMAE (0.054: 5.4 % worse).
    """

    name: str
    method: str
    best: str
    n_gaps: int
    diff: float
    se: float
    share: float


def paired_excess(results: Sequence[SequenceResult], method: str) -> list[Excess]:
    """`method` against the best of the other methods, per sequence with gaps and pooled.

    The comparison is paired: both methods filled the same gaps, so the error of each gap is
    compared with its own, and the spread of those differences gives the standard error (far
    smaller than the spread of the errors themselves, which the gaps' difficulty dominates).

    Raises
    ------
    ValueError
        `method` not among the results' methods, or no other method to compare it with.
    """
    methods = list(results[0].errors) if results else []
    if method not in methods:
        raise ValueError(f"paired_excess: {method!r} is not among the methods {methods}")
    others = [m for m in methods if m != method]
    if not others:
        raise ValueError(f"paired_excess: {method!r} is the only method: nothing to compare")
    rows = [(r.name, {m: np.asarray(r.errors[m], np.float64) for m in methods}) for r in results]
    rows.append(
        ("pooled", {m: np.asarray([e for r in results for e in r.errors[m]]) for m in methods})
    )
    out = []
    for name, errors in rows:
        n = len(errors[method])
        if not n:
            continue
        best = min(others, key=lambda m: float(errors[m].mean()))
        d = errors[method] - errors[best]
        se = float(d.std(ddof=1) / np.sqrt(n)) if n > 1 else float("nan")
        out.append(
            Excess(
                name, method, best, n, float(d.mean()), se, float(d.mean() / errors[best].mean())
            )
        )
    return out


def format_excess(excess: Sequence[Excess]) -> str:
    """:func:`paired_excess` as a table, one row per sequence and the pooled row."""
    if not excess:
        return ""
    method = excess[0].method
    name_w = max(12, *(len(e.name) + 2 for e in excess))
    best_w = max(8, *(len(e.best) + 2 for e in excess))
    head = f"{'sequence':<{name_w}}{'gaps':>6}  {'best other':<{best_w}}"
    lines = [
        f"{method} against the best other method of each row: the mean over the gaps of the "
        "difference in error (px), ± its standard error; negative: better",
        f"{head}{'excess (px)':>18}{'share':>10}",
    ]
    for e in excess:
        lines.append(
            f"{e.name:<{name_w}}{e.n_gaps:>6}  {e.best:<{best_w}}"
            f"{f'{e.diff:+.3f} ± {_se(e.se)}':>18}{f'{100 * e.share:+.1f} %':>10}"
        )
    return "\n".join(lines)


def _se(se: float) -> str:
    return f"{se:.3f}" if np.isfinite(se) else "-"  # one gap: no spread to measure
