"""``pftrack demo``: the built-in job on a synthetic scene (no data, no download)."""

from __future__ import annotations

import argparse
from typing import Any

from pftrack._limits import MAX_PARTICLES
from pftrack.cli._options import add_command, bounded_int, non_negative_int


def add_parser(sub: Any) -> None:
    """Register ``demo`` on `sub` (from ``add_subparsers``)."""
    p = add_command(
        sub,
        "demo",
        help="the built-in job: a synthetic scene tracked, rendered, scored and recovered",
        description="Generate a synthetic scene (coloured walkers crossing on a textured "
        "background, a lamp post in front), track it with one colour particle filter per "
        "walker, print MOTA/IDF1 against the known truth, write tracks, an annotated video and "
        "a trajectory plot, then cut gaps into the truth and print each recovery method's "
        "error. Needs no data and no download.",
    )
    p.add_argument(
        "--out-dir", default="pftrack-demo", metavar="DIR",
        help="folder for the outputs (created, with any missing parent folders, as every "
        "output folder is: pftrack batch --out; a file output such as track --out needs an "
        "existing folder); the folders it created are removed again if it stops before "
        "writing",
    )  # fmt: skip
    p.add_argument("--seed", type=non_negative_int, default=0,
                   help="scene and tracker seed, an integer >= 0")  # fmt: skip
    p.add_argument("--frames", type=bounded_int(1, 1000), default=150,
                   help="scene length (1 to 1000: the scene is held in memory)")  # fmt: skip
    p.add_argument("--particles", type=bounded_int(1, MAX_PARTICLES), default=100,
                   help=f"particles per object (1 to {MAX_PARTICLES})")  # fmt: skip
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``pftrack demo``; return the exit status."""
    from pftrack.cli._options import opencv_single_threaded
    from pftrack.demo import run_demo

    opencv_single_threaded()

    return run_demo(args.out_dir, seed=args.seed, n_frames=args.frames, particles=args.particles)
