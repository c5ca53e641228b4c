"""``pftrack smooth``: the offline pass (link, fill, smooth) for any tracker's output."""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import Any

from pftrack._warn import warn
from pftrack.cli import batch
from pftrack.cli._options import (
    TRACKS_YOURS,
    add_command,
    add_max_distance,
    counted,
    report_stream,
)


def add_parser(sub: Any) -> None:
    """Register ``smooth`` on `sub` (from ``add_subparsers``)."""
    p = add_command(
        sub,
        "smooth",
        help="link, fill and smooth any tracker's MOTChallenge output (offline)",
        description="The offline pass pftrack track applies to its own tracks, for any "
        "tracker's output: join fragments of one object by motion and size across gaps of up "
        "to --max-gap frames (gate: 50 px, times the diagonal of the boxes' extent over 800 "
        "when it is larger than 640x480), add the frames missing inside each track (recovered "
        "by the method of pftrack recover, auto; flagged 1 in column 8, with -1 in columns "
        "9-10; also with --no-link), "
        "and replace every box by a Rauch-Tung-Striebel smoother's estimate over the whole "
        "track. Smoothing is not idempotent: run it once, on raw output.",
    )
    p.add_argument("tracks", nargs="+", help="MOTChallenge tracks file (frame,id,left,top,w,h,"
                   "conf,...); several, or folders of *.txt: a batch on Dask, --out is then a "
                   "folder (see pftrack batch)")  # fmt: skip
    p.add_argument("--out", required=True, help="output file (written atomically; never the input)")
    p.add_argument("--max-gap", type=batch.max_gap, default=30, metavar="FRAMES",
                   help=f"longest gap joined and filled, in frames (1 to {batch.MAX_GAP}; longer "
                   "holes stay holes: bounded work; their number and the longest are "
                   "printed)")  # fmt: skip
    p.add_argument("--no-link", action="store_true",
                   help="join no fragments: fill the holes inside each id and smooth each id "
                   "as it is")  # fmt: skip
    add_max_distance(p)
    batch.add_batch_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``pftrack smooth``; return the exit status."""
    if args.no_link and args.max_distance is not None:
        raise ValueError("--max-distance is the linking gate: drop it or --no-link")
    if batch.is_batch(args.tracks):
        return batch.run_smooth(args)
    batch.refuse_batch_options(args)
    args.tracks = args.tracks[0]
    from pftrack._stats import unique_values
    from pftrack.cli._signals import hold_interrupts
    from pftrack.cli.recover import flag_note
    from pftrack.io.atomic import check_output, check_replaceable
    from pftrack.io.mot import is_mot_text, say_far_boxes, write_mot
    from pftrack.recovery.fill import jump_note, long_holes, short_holes, unfilled_note
    from pftrack.recovery.linking import link_config_for, read_tracks
    from pftrack.tracking import smooth_tracks
    from pftrack.tracking.offline import smoothed_copies

    src, out = Path(args.tracks), Path(args.out)
    if out.exists() and src.exists() and os.path.samefile(out, src):
        raise ValueError(f"--out {out} is the input file; write the result elsewhere")
    check_output(args.out, what="--out", tracks=True)
    check_replaceable(args.out, "--out", is_mot_text, force=args.force, yours=TRACKS_YOURS)
    rows = read_tracks(src)
    say_far_boxes(rows, src)
    link = None if args.no_link else link_config_for(rows, args.max_gap, args.max_distance)
    result = smooth_tracks(rows, link=link, max_gap=args.max_gap)
    # the work is done: --out is written whatever comes (as in recover; after a Ctrl-C
    # that code in C dropped, the writer still refuses: pftrack._interrupt)
    hold_interrupts()
    write_mot(args.out, result, exact=smoothed_copies(result))  # given values: all digits
    ids_in = len(unique_values(rows[:, 1])) if len(rows) else 0
    ids_out = len(unique_values(result[:, 1])) if len(result) else 0
    to = report_stream(args.out)  # rows on stdout (--out /dev/stdout): the report not
    print(
        f"{src}: {counted(ids_in, 'id')}, {counted(len(rows), 'row')} -> "
        f"{counted(ids_out, 'id')}, {counted(len(result), 'row')} ({flag_note(rows)}) -> {out}",
        file=to,
    )
    n_long, longest = long_holes(result, args.max_gap)  # every shorter hole was filled
    if n_long:  # bounded work, said: was silent
        print(f"{src}: {unfilled_note(n_long, longest, args.max_gap)}", file=to)
    n_jumps = short_holes(result, args.max_gap)  # every other shorter hole was filled
    if n_jumps:  # was filled without a word: a path drawn between two objects (issue 12)
        warn(f"{src}: {jump_note(n_jumps, 0.0)}")
    return 0
