"""``pftrack experiment gaps``: the recovery paper's masking experiment on ground truth."""

from __future__ import annotations

import argparse
import os
from collections.abc import Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

from pftrack._warn import warn
from pftrack.cli._options import (
    YOURS,
    WidthHeight,
    add_command,
    add_force,
    bounded_float,
    bounded_int,
    counted,
    non_negative_int,
    positive_int,
    report_stream,
)
from pftrack.cli._signals import hold_interrupts
from pftrack.recovery.names import METHODS

MAX_SIDE = 100_000.0  # px: image sizes, mask sides and positions beyond this are refused
#: ``--figure``'s formats; the first is a device's (``--figure /dev/stdout``).
FIGURE_SUFFIXES = (".png", ".jpg")
#: Most timing runs ``--repeat`` takes: each run recovers every gap again, and a typo of
#: 100000000 ran without a word until killed (a user trial).
MAX_REPEAT = 1000
#: Options of the one-sequence sweep (one --gt, no --auto-masks): refused in the other mode.
SINGLE_ONLY = ("mask", "size", "grid", "trajectories", "gaps", "min_gaps", "repeat",
               "max_positions", "figure")  # fmt: skip
#: Options of the multi-sequence protocol (several --gt, or --auto-masks): refused with one.
MULTI_ONLY = ("n_masks",)
#: Defaults of the options above that have one (their parser default is None: given or not).
DEFAULTS: dict[str, Any] = {
    "size": 100.0, "grid": 4.0, "min_gaps": 3, "repeat": 5, "max_positions": 0, "n_masks": 3,
}  # fmt: skip


def add_parser(sub: Any) -> None:
    """Register ``experiment`` (with its one experiment, ``gaps``) on `sub`."""
    p = add_command(sub, "experiment", help="reproduce the papers' experiments")
    esub = p.add_subparsers(dest="experiment", metavar="EXPERIMENT")
    esub.required = True
    g = add_command(
        esub,
        "gaps",
        help="trajectory recovery under a mask (Oh & Jung 2015, Tables 1 and 2)",
        description="Ground-truth points inside a square mask are lost; each maximal run of "
        "lost points is one gap recovered from the observed segments around it; trajectories "
        "starting or ending inside the mask are left out. Two modes:\n\n"
        "one sequence (one --gt): prints MMAE per axis, MMAE total (mean Euclidean), pooled MAE "
        "and wall time per method, for one mask and as the median over every mask position on "
        "a grid that meets the selection.\n\n"
        "multi-sequence (several --gt files, or --auto-masks): per sequence, --n-masks "
        "non-overlapping square masks of side round(100 W/768) px placed greedily on a "
        "round(4 W/768) px grid where they cut the most gaps; prints per-sequence and pooled "
        "MMAE of every method (image size W x H from seqinfo.ini beside the ground truth or one "
        "folder up, else --image-size).\n\n"
        "Options whose help starts with 'one sequence:' or 'multi-sequence:' belong to that "
        "mode and are refused in the other; the others serve both.",
    )
    g.add_argument("--gt", required=True, nargs="+",
                   help="ground truth file(s) (MOTChallenge); one: the one-sequence sweep, "
                   "several (each file once): the multi-sequence protocol")  # fmt: skip
    g.add_argument("--auto-masks", action="store_true",
                   help="the multi-sequence protocol, even for one --gt")  # fmt: skip
    g.add_argument("--n-masks", type=positive_int, default=None, metavar="N",
                   help=f"multi-sequence: masks per sequence (default: "
                   f"{DEFAULTS['n_masks']})")  # fmt: skip
    g.add_argument("--json", metavar="OUT",
                   help="write the results as JSON (default: none); multi-sequence: protocol, "
                   "methods, per sequence its name, image size, masks, gaps, MMAE and per-gap "
                   "errors, and the pooled MMAE; one sequence: protocol, ground truth, image "
                   "size, point, methods, the representative mask with its trajectories, gaps, "
                   "lost points, scores (the table's rows) and per-gap errors, and the sweep "
                   "with its medians")  # fmt: skip
    g.add_argument("--mask", help="one sequence: x,y,w,h of the representative mask (default: "
                   "chosen by rule)")  # fmt: skip
    g.add_argument("--point", default="centre", choices=("centre", "foot"),
                   help="box point used as the trajectory")  # fmt: skip
    g.add_argument("--size", type=bounded_float(1.0, MAX_SIDE), default=None, metavar="PX",
                   help=f"one sequence: mask side for the sweep (px, 1 to {MAX_SIDE:g}; "
                   f"default: {DEFAULTS['size']:g})")  # fmt: skip
    g.add_argument("--grid", type=bounded_float(0.1, MAX_SIDE), default=None, metavar="PX",
                   help=f"one sequence: mask position step of the sweep (px, 0.1 to "
                   f"{MAX_SIDE:g}; default: {DEFAULTS['grid']:g})")  # fmt: skip
    g.add_argument("--image-size", action=WidthHeight,
                   help="image size of the ground-truth coordinates, W H or WxH, as pftrack "
                   "eval takes it (px, each in (0, 100000]) (default: imWidth x imHeight of "
                   "the seqinfo.ini beside the ground truth or one folder up, else the ground "
                   "truth's extent; multi-sequence: used only for sequences without "
                   "seqinfo.ini, which need it)")  # fmt: skip
    g.add_argument("--trajectories", type=non_negative_int, metavar="N",
                   help="one sequence: keep positions with exactly this many (default: any "
                   "number)")  # fmt: skip
    g.add_argument("--gaps", type=non_negative_int, metavar="N",
                   help="one sequence: keep positions with exactly this many gaps (default: "
                   "any)")  # fmt: skip
    g.add_argument(
        "--min-gaps", type=non_negative_int, default=None, metavar="N",
        help="one sequence, without --trajectories/--gaps: keep positions with at least this "
        f"many gaps (default: {DEFAULTS['min_gaps']})",
    )  # fmt: skip
    g.add_argument("--methods", default=",".join(METHODS), help="comma-separated methods")
    g.add_argument("--repeat", type=bounded_int(1, MAX_REPEAT), default=None, metavar="N",
                   help=f"one sequence: timing, best of this many runs, 1 to {MAX_REPEAT} "
                   f"(default: {DEFAULTS['repeat']})")  # fmt: skip
    g.add_argument(
        "--max-positions", type=non_negative_int, default=None, metavar="N",
        help="one sequence: evaluate at most this many sweep positions, evenly spread "
        f"(default: {DEFAULTS['max_positions']}, all)",
    )  # fmt: skip
    g.add_argument("--figure", metavar="PNG",
                   help="one sequence: PNG of ground truth against recovered paths under the "
                   "representative mask (default: none)")  # fmt: skip
    add_force(g)
    g.set_defaults(func=run_gaps)


def _parse_mask(text: str) -> tuple[float, float, float, float]:
    parts = text.replace(" ", "").split(",")
    try:
        vals = [float(v) for v in parts]
    except ValueError:
        raise ValueError(f"--mask is {text!r}, expected x,y,w,h numbers") from None
    if len(vals) != 4 or not all(abs(v) <= MAX_SIDE for v in vals) or min(vals[2:]) <= 0:
        raise ValueError(
            f"--mask is {text!r}, expected x,y,w,h with w, h > 0 and each within ±{MAX_SIDE:g}"
        )
    return vals[0], vals[1], vals[2], vals[3]


def _parse_size(values: Sequence[str]) -> tuple[float, float]:
    """``--image-size``: ``W H`` (two words, as ``pftrack eval`` takes it) or ``WxH`` (one)."""
    text = " ".join(values)
    parts = values[0].lower().split("x") if len(values) == 1 else list(values)
    try:
        w_s, h_s = parts
        w, h = float(w_s), float(h_s)
    except ValueError:
        raise ValueError(f"--image-size is {text!r}, expected W H or WxH") from None
    if not (0 < w <= MAX_SIDE and 0 < h <= MAX_SIDE):
        raise ValueError(f"--image-size is {text!r}, expected W and H in (0, {MAX_SIDE:g}] px")
    return w, h


def _seqinfo_file(gt_path: str) -> Path | None:
    """The ``seqinfo.ini`` beside the ground truth or one folder up (None: there is none)."""
    gt = Path(os.path.realpath(gt_path))  # realpath: a link loop is refused when read
    for folder in (gt.parent, gt.parent.parent):
        if (folder / "seqinfo.ini").is_file():
            return folder / "seqinfo.ini"
    return None


def _seqinfo(gt_path: str) -> tuple[str, float, float] | None:
    """Name and image size from ``seqinfo.ini`` beside the ground truth or one folder up.

    Read by :func:`pftrack.io.video.read_seqinfo` (its errors name the file, the key and its
    value: ``imWidth is '0', expected a number > 0``; at most ``MAX_IMAGE_SIDE`` px, the bound
    of ``--image-size``); ``imWidth`` and ``imHeight`` must be given. Only ``name``,
    ``imWidth`` and ``imHeight`` are read: the experiment has no use for the frame rate or
    the length, whose values are not checked.
    """
    from pftrack.io.video import read_seqinfo

    ini = _seqinfo_file(gt_path)
    if ini is None:
        return None
    # the experiment uses no other key: frameRate=0 or a bad seqLength does not stop it
    info = read_seqinfo(ini, keys=("name", "imWidth", "imHeight"))
    for key, value in (("imWidth", info.width), ("imHeight", info.height)):
        if value is None:
            raise ValueError(
                f"{ini}: no {key} in [Sequence]; the image size of the ground truth needs "
                "imWidth and imHeight"
            )
    assert info.width is not None and info.height is not None  # checked above
    return info.name, float(info.width), float(info.height)


def _methods(text: str) -> list[str]:
    methods = [m.strip() for m in text.split(",") if m.strip()]
    for m in methods:
        if m not in METHODS:
            raise ValueError(f"--methods: unknown method {m!r}, expected some of {METHODS}")
    if not methods:
        raise ValueError("--methods is empty")
    twice = sorted({m for m in methods if methods.count(m) > 1})
    if twice:  # was taken: each position counted once per copy ("median over 4 positions")
        raise ValueError(f"--methods names {', '.join(twice)} more than once; name each once")
    return methods


def _option(name: str) -> str:
    return "--" + name.replace("_", "-")


def _check_mode(args: argparse.Namespace) -> bool:
    """Refuse the options of the other mode; fill in the defaults; True for multi-sequence.

    Raises
    ------
    ValueError
        An option of the one-sequence sweep with several ``--gt`` or ``--auto-masks``, one of
        the multi-sequence protocol with one ``--gt``, or ``--min-gaps`` with
        ``--trajectories``/``--gaps`` (it selects only without them).
    """
    multi = len(args.gt) > 1 or args.auto_masks
    if multi:
        for name in SINGLE_ONLY:
            if getattr(args, name) is not None:
                why = "several --gt files" if len(args.gt) > 1 else "--auto-masks"
                raise ValueError(
                    f"{_option(name)} belongs to the one-sequence mask sweep; with {why} "
                    "(automatic masks per sequence) nothing uses it: drop it"
                )
    else:
        for name in MULTI_ONLY:
            if getattr(args, name) is not None:
                raise ValueError(
                    f"{_option(name)} belongs to the multi-sequence protocol; with one --gt "
                    "nothing uses it: add --auto-masks or drop it"
                )
        if args.min_gaps is not None and (args.trajectories is not None or args.gaps is not None):
            raise ValueError(
                "--min-gaps selects positions only without --trajectories/--gaps; drop one"
            )
    for name, value in DEFAULTS.items():
        if getattr(args, name) is None:
            setattr(args, name, value)
    return bool(multi)


def _check_distinct_gt(paths: list[str]) -> None:
    """Refuse one ground-truth file given twice (``A/gt.txt A/./gt.txt``, a link to it).

    It would be one sequence counted twice: two rows, and its gaps twice in the pooled MMAE.
    """
    seen: dict[object, str] = {}
    for path in paths:
        p = Path(path)
        try:
            st = p.stat()
            key: object = (st.st_dev, st.st_ino)
        except OSError:  # missing: refused when read; compared by name meanwhile
            key = os.path.realpath(p)
        if key in seen:
            raise ValueError(
                f"--gt {seen[key]} and {path} are the same file; give each sequence once"
            )
        seen[key] = path


def run_gaps(args: argparse.Namespace) -> int:
    """Run ``pftrack experiment gaps``; return the exit status."""
    from pftrack.io.atomic import check_distinct, check_output, check_replaceable
    from pftrack.io.marks import is_marked_image, is_marked_json

    multi = _check_mode(args)  # before any other check: the options a mode does not use
    _check_distinct_gt(args.gt)
    inputs = tuple(args.gt)
    if args.mask:
        _parse_mask(args.mask)  # bad options are refused before any work
    if args.image_size:
        _parse_size(args.image_size)
    if args.json is not None:  # "" too: refused as empty (was: nothing written, silently)
        check_output(args.json, what="--json", suffixes=(".json",), inputs=inputs)
    if args.figure is not None:
        check_output(args.figure, what="--figure", suffixes=FIGURE_SUFFIXES, inputs=inputs)
    # was: --json /dev/stdout --figure /dev/stdout wrote a PNG and the JSON into one stream
    check_distinct({"--json": args.json, "--figure": args.figure})
    if args.json:
        check_replaceable(args.json, "--json", is_marked_json, force=args.force, yours=YOURS)
    if args.figure:
        check_replaceable(args.figure, "--figure", is_marked_image, force=args.force, yours=YOURS)
    if multi:
        return _run_sequences(args)
    import numpy as np

    from pftrack.recovery import experiment as E
    from pftrack.recovery.linking import read_tracks

    args.gt = args.gt[0]
    gt = read_tracks(args.gt, what="ground truth")  # a repeated (frame, id): FILE:LINE
    if len(gt) == 0:
        raise ValueError(f"ground truth {args.gt} is empty")
    methods = _methods(args.methods)
    info = None if args.image_size else _seqinfo(args.gt)  # as eval and multi-sequence read it
    if args.image_size:
        width, height = _parse_size(args.image_size)
    elif info is not None:  # was: the ground truth's extent, seqinfo.ini passed over
        _, width, height = info
    else:
        width = float(np.ceil(np.max(gt[:, 2] + gt[:, 4])))
        height = float(np.ceil(np.max(gt[:, 3] + gt[:, 5])))
    trajs = E.trajectories(gt, args.point)
    sweep = E.sweep(
        trajs, args.size, width, height, args.grid, args.trajectories, args.gaps, args.min_gaps
    )
    said = [  # printed once the figure is written: a closed stdout cannot lose it
        f"{args.gt}: {counted(len(trajs), 'trajectory', 'trajectories')}, "
        f"{args.point} point, {width:.0f}x{height:.0f}",
        f"sweep: {args.size:g}x{args.size:g} masks on a {args.grid:g} px grid, "
        f"{len(sweep)} positions kept ({sweep.selection})",
    ]
    if args.mask:
        mask = _parse_mask(args.mask)
        x, y, w, h = mask
        if x < 0 or y < 0 or x + w > width or y + h > height:  # was: "no gap under this mask"
            raise ValueError(
                f"--mask {args.mask} is not inside the {width:g}x{height:g} image (x, y >= 0, "
                "x + w <= width, y + h <= height)"
            )
    elif len(sweep):
        mask = sweep.representative()
    elif args.size > width or args.size > height:  # was: "no mask position meets the selection"
        raise ValueError(
            f"--size {args.size:g}: no {args.size:g} px mask fits in the {width:g}x{height:g} "
            "image; give a smaller --size, or --mask"
        )
    else:
        raise ValueError(
            f"no mask position meets the selection ({sweep.selection}); relax it (--min-gaps, "
            "--trajectories, --gaps, --size), or pass --mask"
        )
    run = E.run_mask(trajs, mask, methods, args.repeat)
    said += [
        "",
        f"representative mask x,y,w,h = {','.join(f'{v:g}' for v in mask)}: "
        f"{counted(run.n_traj, 'trajectory', 'trajectories')}, "
        f"{counted(len(run.gaps), 'gap')}, "
        f"{sum(len(g.truth) for g in run.gaps)} lost points",
    ]
    doc: dict[str, Any] = {
        "protocol": f"one sequence: {args.size:g} px square masks on a {args.grid:g} px grid, "
        f"positions kept: {sweep.selection}; representative mask: "
        f"{'--mask' if args.mask else 'the kept position nearest their centroid'}; "
        f"{args.point} point",
        "gt": str(args.gt),
        "image_size": [width, height],
        "point": args.point,
        "methods": methods,
        "mask": _mask_doc(run, methods),
        "sweep": {
            "size": args.size,
            "grid": args.grid,
            "selection": sweep.selection,
            "n_positions": len(sweep),
            "median": None,
        },
    }
    if not run.gaps:
        said.append("no gap under this mask")
        figure = None
        if args.figure:  # the ground truth and the mask: where it missed (was: not written)
            figure = E.draw_figure(trajs, run.gaps, run.paths, mask, (int(width), int(height)), [])
        return _finish(args, said, doc, figure)
    said.append(E.format_table(run.scores))
    if run.noise is not None:
        said.append(
            f"gdt-bi noise (estimated from the observed points, {run.noise_ms:.1f} ms): "
            f"q = {run.noise.q[0]:.4g}, {run.noise.q[1]:.4g} px^2/frame^3, "
            f"r = {run.noise.r[0]:.4g}, {run.noise.r[1]:.4g} px^2"
        )
    if run.motion is not None:
        said.append(
            f"gdt-mix model (fitted to the observed points, {run.motion_ms:.1f} ms): "
            f"{run.motion.describe()}"
        )
    if len(sweep):
        import sys

        from pftrack._progress import enabled, quiet

        n = len(sweep) if not args.max_positions else min(len(sweep), args.max_positions)
        if not (quiet() or enabled()):  # no bar to show it: say what is coming (looked hung)
            print(
                f"pftrack experiment gaps: every method at {n} mask positions of {len(sweep)} "
                "(--max-positions N runs N of them)",
                file=sys.stderr,
                flush=True,
            )
        median = E.median_over(trajs, sweep, methods, args.max_positions)
        said += ["", E.format_median(median)]
        doc["sweep"]["median"] = {
            "n_positions": median.n_positions,
            "scores": {m: asdict(v) for m, v in median.median.items()},
            "best_at": median.wins,
        }
    figure = None
    if args.figure:
        figure = E.draw_figure(
            trajs, run.gaps, run.paths, mask, (int(width), int(height)),
            [m for m in ("gdt", "gdt-mix", "bspline") if m in methods],
        )  # fmt: skip
    return _finish(args, said, doc, figure)


def _finish(args: argparse.Namespace, said: list[str], doc: dict[str, Any], figure: Any) -> int:
    """Write the one-sequence sweep's --figure and --json, then print what it has to say.

    The two files are replaced together at the end, or neither (was: the figure replaced, then
    exit 2 for a JSON that could not be written). The report comes after them: a closed stdout
    cannot lose them; and never into a file written to stdout.
    """
    import json

    import cv2

    from pftrack.io.atomic import output_format, staged_outputs
    from pftrack.io.marks import json_marked
    from pftrack.io.opencv_io import write_image

    with staged_outputs() as stage:
        if args.figure:
            ext = output_format(args.figure, FIGURE_SUFFIXES)  # a device (/dev/stdout): .png
            params = [cv2.IMWRITE_PNG_COMPRESSION, 9]
            write_image(stage(args.figure, ext), figure, params, ext=ext, mark=True)
        if args.json:
            with open(stage(args.json), "w", encoding="utf-8") as f:
                json.dump(json_marked(doc, "experiment gaps"), f, indent=1)
        if args.figure or args.json:  # (none: nothing was written, as a report error says)
            hold_interrupts()  # the work is done: the outputs are put in place whatever comes
    said += [f"{what}: {path}" for what, path in (("figure", args.figure), ("json", args.json))
             if path]  # fmt: skip
    print("\n".join(said), file=report_stream(args.json, args.figure))
    return 0


def _mask_doc(run: Any, methods: list[str]) -> dict[str, Any]:
    """One mask's part of the one-sequence JSON: what it cuts, and every method's scores."""
    import numpy as np

    return {
        "box": list(run.mask),  # x, y, w, h
        "n_trajectories": run.n_traj,
        "n_gaps": len(run.gaps),
        "n_lost_points": sum(len(g.truth) for g in run.gaps),
        "scores": {m: asdict(run.scores[m]) if m in run.scores else None for m in methods},
        "gap_errors": {  # mean Euclidean error of each gap (px), as the multi-sequence JSON's
            m: [
                float(np.mean(g.errors(p)))
                for g, p in zip(run.gaps, run.paths.get(m, []), strict=True)
            ]
            for m in methods
        },
    }


def _write_json(path: str, doc: dict[str, Any]) -> None:
    import json

    from pftrack.io.atomic import atomic_write
    from pftrack.io.marks import json_marked

    with atomic_write(path) as f:
        json.dump(json_marked(doc, "experiment gaps"), f, indent=1)


def _run_sequences(args: argparse.Namespace) -> int:
    """The multi-sequence protocol with automatic masks (``--gt A B ...`` or ``--auto-masks``)."""
    from pftrack._progress import progress
    from pftrack.recovery import experiment as E
    from pftrack.recovery.linking import read_tracks

    methods = _methods(args.methods)
    jobs = []
    for path in args.gt:
        gt = read_tracks(path, what="ground truth")  # a repeated (frame, id): FILE:LINE
        if len(gt) == 0:
            raise ValueError(f"ground truth {path} is empty")
        info = _seqinfo(path)
        if info is not None:
            name, width, height = info
            where = f"{_seqinfo_file(path)}: imWidth x imHeight"
        elif args.image_size:
            width, height = _parse_size(args.image_size)
            p = Path(
                os.path.realpath(path)
            )  # SEQ/gt/gt.txt or SEQ/gt.txt: the sequence; else the file
            name = p.parent.name if p.stem == "gt" else p.stem
            where = f"{path}: --image-size"  # the sequence named: the size is for it
        else:
            raise ValueError(
                f"{path}: no seqinfo.ini beside it or one folder up; pass --image-size"
            )
        side = E.auto_mask_side(width)
        if side > width or side > height:  # was: "auto_masks: mask side ... exceeds the image"
            raise ValueError(
                f"{where} {width:g}x{height:g} cannot hold the masks: their side is "
                f"round(100 W/768) = {side:g} px"
            )
        jobs.append((name, E.trajectories(gt, args.point), width, height))
    results = [
        E.run_sequence(name, trajs, width, height, methods, args.n_masks)
        for name, trajs, width, height in progress(jobs, total=len(jobs), desc="sequences")
    ]
    excess = E.paired_excess(results, methods[0]) if len(methods) > 1 else []
    if args.json:
        doc: dict[str, Any] = {
            "protocol": "auto masks: side round(100W/768), grid round(4W/768), greedy, "
            f"{args.n_masks} per sequence, {args.point} point",
            "methods": methods,
            "sequences": [
                {
                    "name": r.name,
                    "image_size": list(r.image_size),
                    "masks": [list(m) for m in r.masks],
                    "n_gaps": r.n_gaps,
                    "mmae": {m: r.mmae(m) if r.n_gaps else None for m in methods},
                    "gap_errors": {m: list(r.errors[m]) for m in methods},
                }
                for r in results
            ],
        }
        pooled = {m: [e for r in results for e in r.errors[m]] for m in methods}
        doc["pooled"] = {
            "n_gaps": sum(r.n_gaps for r in results),
            "mmae": {m: (sum(v) / len(v) if v else None) for m, v in pooled.items()},
        }
        doc["excess"] = [  # methods[0] against the best other method; no NaN in JSON
            {k: (None if isinstance(v, float) and v != v else v) for k, v in asdict(e).items()}
            for e in excess
        ]
        hold_interrupts()  # the work is done: --json is written whatever comes (as recover)
        _write_json(args.json, doc)
    to = report_stream(args.json)  # not into a JSON file written to stdout
    for r in results:  # printed once the JSON is written: a closed stdout cannot lose it
        masks = "; ".join(",".join(f"{v:g}" for v in m) for m in r.masks) or "none"
        print(
            f"{r.name} ({r.image_size[0]:g}x{r.image_size[1]:g}): {r.n_gaps} gaps, masks {masks}",
            file=to,
        )
        if r.n_gaps and len(r.masks) < args.n_masks:  # was: fewer, without a word
            warn(
                f"{r.name}: {len(r.masks)} of the {args.n_masks} masks asked for were placed "
                "(no more fit without overlapping, or none more cuts a gap)",
                stacklevel=2,
            )
        if not r.n_gaps:  # was: a row of nan, and nothing said
            warn(
                f"{r.name}: no gap under any mask (no mask position cuts a trajectory that is "
                "observed on both sides of it): no MMAE, and nothing of it in the pooled "
                "figures",
                stacklevel=2,
            )
    print(file=to)
    print("MMAE (px, mean over gaps of the mean Euclidean error); * = best of the row", file=to)
    print(E.format_sequences(results, methods), file=to)
    if len(methods) > 1 and any(r.n_gaps for r in results):
        print(file=to)
        print(E.format_excess(excess), file=to)
    if args.json:
        print(f"json: {args.json}", file=to)
    return 0
