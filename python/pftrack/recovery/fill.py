"""Gap filling of any tracker's MOTChallenge output.

Every hole of at most ``max_gap`` frames inside an id's track is filled by a recovery method
(:mod:`pftrack.recovery.registry`); filled rows carry the **interpolated flag in column 8**
(1-based; index :data:`~pftrack.recovery.linking.FLAG_COLUMN`): ``1`` on every row pftrack filled,
observed rows untouched. Rows already flagged count as observed when a file is processed again,
so running the fill twice changes nothing more.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pftrack._typing import F64
from pftrack.recovery.calibrate import Calibration, recover_auto
from pftrack.recovery.linking import FLAG_COLUMN, box_centres, check_unique, split_tracks
from pftrack.recovery.mixture import MotionFit, fit_motion
from pftrack.recovery.noise import NoiseEstimate, estimate_noise
from pftrack.recovery.registry import DEFAULT_METHOD, METHODS, recover_gaps

__all__ = ["FillReport", "fill_gaps"]


@dataclass(frozen=True)
class FillReport:
    """What :func:`fill_gaps` did.

    ``calibration``: with ``"auto"``, the method chosen per gap-length bucket and the
    validation MMAE of every candidate (:class:`~pftrack.recovery.calibrate.Calibration`).
    """

    n_gaps: int
    n_filled_rows: int
    noise: NoiseEstimate | None
    calibration: Calibration | None = None


def fill_gaps(
    tracks: F64,
    method: str = DEFAULT_METHOD,
    max_gap: int = 30,
    noise: NoiseEstimate | None = None,
    *,
    seed: int = 0,
) -> tuple[F64, FillReport]:
    """Fill every hole of at most `max_gap` missing frames inside each id's track.

    Parameters
    ----------
    tracks : (M, 10) ndarray
        MOTChallenge rows; each (frame, id) at most once.
    method : str
        One of :data:`~pftrack.recovery.registry.METHODS`; default ``"auto"`` (calibrated on
        the file's own observed tracks, :mod:`pftrack.recovery.calibrate`).
    max_gap : int
        Longest hole filled, in frames (>= 1).
    noise : NoiseEstimate, optional
        For ``"gdt-bi"`` and ``"gdt-mix"``: noise levels to use; default: estimated from every
        track of the file (:func:`~pftrack.recovery.noise.estimate_noise`). ``"gdt-mix"`` fits
        one motion model to the whole file.
    seed : int
        For ``"auto"``: seed of the generator placing the artificial calibration gaps.

    Returns
    -------
    rows : (M + n, 10) ndarray
        The rows plus the filled ones, sorted by (frame, id). Filled rows get positions from
        `method`, sizes by linear interpolation, ``conf`` = the smaller of the two neighbours'
        and the interpolated flag (column 8, :data:`FLAG_COLUMN`) set to 1.
    report : FillReport
        How many holes and rows were filled; with ``"auto"``, what was chosen
        (``report.calibration``).

    Raises
    ------
    ValueError
        Unknown method, `max_gap` < 1, rows not ``(M, 10)`` or a duplicate (frame, id).
    """
    if method not in METHODS:
        raise ValueError(f"fill_gaps: method is {method!r}, expected one of {METHODS}")
    if max_gap < 1:
        raise ValueError(f"fill_gaps: max_gap is {max_gap}, expected >= 1")
    rows = np.asarray(tracks, dtype=np.float64)
    if rows.ndim != 2 or rows.shape[1] != 10:
        raise ValueError(f"fill_gaps: tracks must have shape (M, 10), got {rows.shape}")
    check_unique(rows)
    per_id = split_tracks(rows)
    segs: list[tuple[F64, F64]] = []
    meta: list[tuple[int, F64, F64]] = []
    for tid, r in per_id.items():
        c = box_centres(r)
        seg = np.column_stack([c, r[:, 4], r[:, 5]])
        holes = np.flatnonzero(np.diff(r[:, 0]) > 1)
        for h in holes:
            missing = int(r[h + 1, 0] - r[h, 0] - 1)
            if missing > max_gap:
                continue
            segs.append((seg[: h + 1], seg[h + 1 :]))
            meta.append((tid, r[h], r[h + 1]))
    motion: MotionFit | None = None
    calibration: Calibration | None = None
    if method in ("gdt-bi", "gdt-mix") and segs:
        whole = [box_centres(r) for r in per_id.values()]
        if noise is None:
            noise = estimate_noise(whole)
        if method == "gdt-mix":  # one model for the file, not one per pair of segments
            motion = fit_motion(whole, noise)
    new_rows: list[F64] = []
    if segs:
        if method == "auto":
            whole = [box_centres(r) for r in per_id.values()]
            paths, calibration = recover_auto(segs, whole, noise, motion, seed=seed)
        else:
            paths = recover_gaps(segs, method, noise=noise, motion=motion)
        for (tid, ra, rb), xy in zip(meta, paths, strict=True):
            fr = np.arange(ra[0] + 1, rb[0])
            s = (fr - ra[0]) / (rb[0] - ra[0])
            w = (1 - s) * ra[4] + s * rb[4]
            h = (1 - s) * ra[5] + s * rb[5]
            out = np.empty((len(fr), 10))
            out[:, 0] = fr
            out[:, 1] = tid
            out[:, 2] = xy[:, 0] - 0.5 * w
            out[:, 3] = xy[:, 1] - 0.5 * h
            out[:, 4] = w
            out[:, 5] = h
            out[:, 6] = min(ra[6], rb[6])
            out[:, FLAG_COLUMN] = 1.0
            out[:, 8] = -1.0
            out[:, 9] = -1.0
            new_rows.append(out)
    filled = np.vstack([rows, *new_rows]) if new_rows else rows.copy()
    order = np.lexsort((filled[:, 1], filled[:, 0]))
    n_new = sum(len(r) for r in new_rows)
    return filled[order], FillReport(len(segs), n_new, noise, calibration)
