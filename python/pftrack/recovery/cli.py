"""Handlers of ``pftrack recover`` and ``pftrack experiment gaps`` (pftrack.cli only wires them)."""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path
from typing import Any

import numpy as np

from pftrack.recovery.methods import METHODS


def add_recover_parser(sub: Any) -> None:
    """Add the ``recover`` sub-command."""
    p = sub.add_parser(
        "recover",
        help="fill the gaps of any tracker's MOTChallenge output (optionally link fragments)",
        description=(
            "Fill holes of at most --max-gap frames inside each track. Filled rows have the "
            "interpolated flag (column 8, 1-based) set to 1. Rows flagged by an earlier run "
            "count as observed, so running it twice changes nothing more."
        ),
    )
    p.add_argument("tracks", help="MOTChallenge tracks file (frame,id,left,top,w,h,conf,x,y,z)")
    p.add_argument("--out", required=True, help="output file (written atomically)")
    p.add_argument("--method", default="gdt-mix", choices=METHODS, help="recovery method")
    p.add_argument("--max-gap", type=int, default=30, help="longest hole filled, in frames")
    p.add_argument("--link", action="store_true", help="join fragments of one object first")
    p.add_argument(
        "--max-distance",
        type=float,
        default=50.0,
        help="linking gate on the motion-prediction distance (pixels)",
    )
    p.add_argument("--video", help="video or image folder for the colour term of --link")
    p.add_argument(
        "--in-place",
        action="store_true",
        help="allow --out to be the input file (it is replaced atomically)",
    )
    p.set_defaults(func=run_recover)


def add_experiment_parser(sub: Any) -> None:
    """Add the ``experiment`` sub-command (``experiment gaps``)."""
    p = sub.add_parser("experiment", help="reproduce the papers' experiments")
    esub = p.add_subparsers(dest="experiment", metavar="EXPERIMENT")
    esub.required = True
    g = esub.add_parser(
        "gaps",
        help="trajectory recovery under a mask (Oh & Jung 2015, Tables 1 and 2)",
        description=(
            "Ground-truth points inside a square mask are lost; each maximal run of lost points "
            "is one gap recovered from the observed segments around it; trajectories starting or "
            "ending inside the mask are left out. Prints MMAE per axis, MMAE total (mean "
            "Euclidean), pooled MAE and wall time per method, for one mask and as the median "
            "over every mask position on a grid that meets the selection."
        ),
    )
    g.add_argument("--gt", required=True, help="ground truth (MOTChallenge)")
    g.add_argument("--mask", help="x,y,w,h of the representative mask (default: chosen by rule)")
    g.add_argument(
        "--point",
        default="centre",
        choices=("centre", "foot"),
        help="box point used as the trajectory",
    )
    g.add_argument("--size", type=float, default=100.0, help="mask side for the sweep (px)")
    g.add_argument("--grid", type=float, default=4.0, help="mask position step of the sweep (px)")
    g.add_argument("--image-size", help="WxH of the ground-truth coordinates (default: GT extent)")
    g.add_argument("--trajectories", type=int, help="keep positions with exactly this many")
    g.add_argument("--gaps", type=int, help="keep positions with exactly this many gaps")
    g.add_argument(
        "--min-gaps",
        type=int,
        default=3,
        help="without --trajectories/--gaps: keep positions with at least this many",
    )
    g.add_argument("--methods", default=",".join(METHODS), help="comma-separated methods")
    g.add_argument("--repeat", type=int, default=5, help="timing: best of this many runs")
    g.add_argument(
        "--max-positions",
        type=int,
        default=0,
        help="evaluate at most this many sweep positions, evenly spread (0 = all)",
    )
    g.add_argument("--figure", help="PNG of ground truth against recovered paths (OpenCV)")
    g.set_defaults(func=run_experiment_gaps)


def run_recover(args: argparse.Namespace) -> int:
    """``pftrack recover``."""
    from pftrack.io.mot import data_line_numbers, read_mot, write_mot
    from pftrack.recovery.linking import LinkConfig, check_unique, fill_gaps, link_tracklets

    src = Path(args.tracks)
    rows = read_mot(src, what="tracks file")
    check_unique(rows, data_line_numbers(src))
    out = Path(args.out)
    if out.exists() and os.path.samefile(out, src) and not args.in_place:
        raise ValueError(
            f"--out {out} is the input file; pass --in-place to replace it (atomically)"
        )
    if args.max_gap < 1:
        raise ValueError(f"--max-gap is {args.max_gap}, expected >= 1")
    n_links = 0
    if args.link:
        frames = None
        if args.video:
            from pftrack.io.video import read_frames

            frames = read_frames(args.video)
        cfg = LinkConfig(max_gap=args.max_gap, max_distance=args.max_distance)
        rows, mapping = link_tracklets(rows, cfg, frames)
        n_links = len(mapping)
    t0 = time.perf_counter()
    filled, rep = fill_gaps(rows, args.method, args.max_gap)
    dt = time.perf_counter() - t0
    write_mot(out, filled)
    print(
        f"{src}: {len(rows)} rows, {n_links} fragments linked, {rep.n_gaps} gaps filled with "
        f"{rep.n_filled_rows} rows ({args.method}, {1e3 * dt:.1f} ms) -> {out} "
        f"(interpolated flag: column 8)"
    )
    return 0


def _parse_mask(text: str) -> tuple[float, float, float, float]:
    parts = text.replace(" ", "").split(",")
    try:
        vals = [float(v) for v in parts]
    except ValueError:
        raise ValueError(f"--mask is {text!r}, expected x,y,w,h numbers") from None
    if len(vals) != 4 or vals[2] <= 0 or vals[3] <= 0:
        raise ValueError(f"--mask is {text!r}, expected x,y,w,h with w, h > 0")
    return vals[0], vals[1], vals[2], vals[3]


def run_experiment_gaps(args: argparse.Namespace) -> int:
    """``pftrack experiment gaps``."""
    from pftrack.io.mot import read_mot
    from pftrack.recovery import experiment as E

    gt = read_mot(args.gt, what="ground truth")
    if len(gt) == 0:
        raise ValueError(f"ground truth {args.gt} is empty")
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    for m in methods:
        if m not in METHODS:
            raise ValueError(f"--methods: unknown method {m!r}, expected some of {METHODS}")
    if args.image_size:
        try:
            w_s, h_s = args.image_size.lower().split("x")
            width, height = float(w_s), float(h_s)
        except ValueError:
            raise ValueError(f"--image-size is {args.image_size!r}, expected WxH") from None
    else:
        width = float(np.ceil(np.max(gt[:, 2] + gt[:, 4])))
        height = float(np.ceil(np.max(gt[:, 3] + gt[:, 5])))
    trajs = E.trajectories(gt, args.point)
    sweep = E.sweep(
        trajs, args.size, width, height, args.grid, args.trajectories, args.gaps, args.min_gaps
    )
    print(f"{args.gt}: {len(trajs)} trajectories, {args.point} point, {width:.0f}x{height:.0f}")
    print(
        f"sweep: {args.size:g}x{args.size:g} masks on a {args.grid:g} px grid, "
        f"{len(sweep)} positions kept ({sweep.selection})"
    )
    if args.mask:
        mask = _parse_mask(args.mask)
    elif len(sweep):
        mask = sweep.representative()
    else:
        raise ValueError("no mask position meets the selection; pass --mask")
    run = E.run_mask(trajs, mask, methods, args.repeat)
    print()
    print(
        f"representative mask x,y,w,h = {','.join(f'{v:g}' for v in mask)}: "
        f"{run.n_traj} trajectories, {len(run.gaps)} gaps, "
        f"{sum(len(g.truth) for g in run.gaps)} lost points"
    )
    if not run.gaps:
        print("no gap under this mask")
        return 0
    print(E.format_table(run.scores))
    if run.noise is not None:
        print(
            f"gdt-bi noise (estimated from the observed points, {run.noise_ms:.1f} ms): "
            f"q = {run.noise.q[0]:.4g}, {run.noise.q[1]:.4g} px^2/frame^3, "
            f"r = {run.noise.r[0]:.4g}, {run.noise.r[1]:.4g} px^2"
        )
    if run.motion is not None:
        print(
            f"gdt-mix model (fitted to the observed points, {run.motion_ms:.1f} ms): "
            f"{run.motion.describe()}"
        )
    if len(sweep):
        med = E.median_over(trajs, sweep, methods, args.max_positions)
        print()
        print(E.format_median(med))
    if args.figure:
        import cv2

        from pftrack.io.atomic import atomic_path

        img = E.draw_figure(
            trajs,
            run.gaps,
            run.paths,
            mask,
            (int(width), int(height)),
            [m for m in ("gdt", "gdt-mix", "bspline") if m in methods],
        )
        with atomic_path(args.figure) as tmp:
            if not cv2.imwrite(str(tmp), img, [cv2.IMWRITE_PNG_COMPRESSION, 9]):
                raise ValueError(f"cannot write figure {args.figure}")
        print(f"figure: {args.figure}")
    return 0
