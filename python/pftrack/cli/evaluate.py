"""``pftrack eval``: score a MOTChallenge result file against ground truth."""

from __future__ import annotations

import argparse
from typing import Any

from pftrack.cli._options import add_command


def add_parser(sub: Any) -> None:
    """Register ``eval`` on `sub` (from ``add_subparsers``)."""
    p = add_command(
        sub,
        "eval",
        help="score a tracking result against ground truth (MOTA, IDF1, ...)",
        description="Score a MOTChallenge result file against a ground-truth file: CLEAR-MOT "
        "(MOTA, MOTP as mean IoU of matches, FP, FN, IDSW, Frag, MT/PT/ML), IDF1/IDP/IDR, and "
        "Smith et al.'s success rate and centroid distance. Ground-truth rows with conf 0 are "
        "not scored.",
    )
    p.add_argument("--gt", required=True, help="ground truth, MOTChallenge text file")
    p.add_argument("--res", required=True, help="result, MOTChallenge text file")
    p.add_argument(
        "--scale", type=float, default=1.0,
        help="multiply ground-truth boxes by this (0.625 for PETS09 gt on the 480x360 video)",
    )  # fmt: skip
    p.add_argument("--iou", type=float, default=0.5, help="IoU threshold of a match")
    p.add_argument("--image-size", type=int, nargs=2, metavar=("W", "H"), default=None,
                   help="image size for the centroid-distance ratio")  # fmt: skip
    p.add_argument("--json", default=None, help="also write all metrics to this JSON file")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``pftrack eval``: print the table, optionally write JSON; return the exit status."""
    from pftrack.eval import evaluate_mot
    from pftrack.io.atomic import atomic_write, check_output
    from pftrack.io.mot import read_mot

    if args.json:
        check_output(args.json, what="--json", suffixes=(".json",), inputs=(args.gt, args.res))
    gt = read_mot(args.gt, what="ground truth")
    res = read_mot(args.res, what="result file")
    size = tuple(args.image_size) if args.image_size else None
    m = evaluate_mot(gt, res, iou_threshold=args.iou, scale=args.scale, image_size=size)
    print(m.table())
    if args.json:
        with atomic_write(args.json) as fh:
            fh.write(m.to_json() + "\n")
    return 0
