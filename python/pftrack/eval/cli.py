"""``pftrack eval``: score a MOT result file against a ground-truth file."""

from __future__ import annotations

import argparse

from pftrack.eval.metrics import evaluate_mot
from pftrack.io.atomic import atomic_write
from pftrack.io.mot import read_mot


def add_eval_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:  # type: ignore[type-arg]
    """Register the ``eval`` sub-command on `sub` (from ``add_subparsers``)."""
    p: argparse.ArgumentParser = sub.add_parser(
        "eval",
        help="score a tracking result against ground truth (MOTA, IDF1, ...)",
        description=(
            "Score a MOTChallenge result file against a ground-truth file: CLEAR-MOT (MOTA, "
            "MOTP as mean IoU of matches, FP, FN, IDSW, Frag, MT/PT/ML), IDF1/IDP/IDR, and "
            "Smith et al.'s success rate and centroid distance. Ground-truth rows with conf 0 "
            "are not scored."
        ),
    )
    p.add_argument("--gt", required=True, help="ground truth, MOTChallenge text file")
    p.add_argument("--res", required=True, help="result, MOTChallenge text file")
    p.add_argument(
        "--scale", type=float, default=1.0,
        help="multiply ground-truth boxes by this (0.625 for PETS09 gt on the 480x360 video)",
    )
    p.add_argument("--iou", type=float, default=0.5, help="IoU threshold of a match (0.5)")
    p.add_argument(
        "--image-size", type=int, nargs=2, metavar=("W", "H"), default=None,
        help="image size for the centroid-distance ratio",
    )
    p.add_argument("--json", default=None, help="also write all metrics to this JSON file")
    p.set_defaults(func=run_eval)
    return p


def run_eval(args: argparse.Namespace) -> int:
    """Run ``pftrack eval``: print the table, optionally write JSON; return 0."""
    gt = read_mot(args.gt, what="ground truth")
    res = read_mot(args.res, what="result file")
    size = tuple(args.image_size) if args.image_size else None
    m = evaluate_mot(gt, res, iou_threshold=args.iou, scale=args.scale, image_size=size)
    print(m.table())
    if args.json:
        with atomic_write(args.json) as fh:
            fh.write(m.to_json() + "\n")
    return 0
