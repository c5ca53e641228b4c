"""``pftrack recover``: fill the gaps inside every track of any tracker's output."""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path
from typing import Any

from pftrack._warn import warn
from pftrack.cli import batch
from pftrack.cli._options import (
    TRACKS_YOURS,
    add_command,
    add_max_distance,
    counted,
    non_negative_int,
    report_stream,
)
from pftrack.recovery.names import DEFAULT_METHOD, METHODS


def add_parser(sub: Any) -> None:
    """Register ``recover`` on `sub` (from ``add_subparsers``)."""
    p = add_command(
        sub,
        "recover",
        help="fill the gaps of any tracker's MOTChallenge output (optionally link fragments)",
        description="Fill holes of at most --max-gap frames inside each track. Filled rows "
        "have the interpolated flag (column 8, 1-based) set to 1 and columns 9-10 set to -1; "
        "observed rows keep their values (written in their shortest form: 88.00 as 88). Rows "
        "flagged by an earlier run count as observed, so running it twice changes nothing "
        "more.",
    )
    p.add_argument("tracks", nargs="+", help="MOTChallenge tracks file (frame,id,left,top,w,h,"
                   "conf,x,y,z); several, or folders of *.txt: a batch on Dask, --out is then a "
                   "folder (see pftrack batch)")  # fmt: skip
    p.add_argument("--out", required=True, help="output file (written atomically)")
    p.add_argument("--method", default=DEFAULT_METHOD, choices=METHODS, help="recovery method")
    p.add_argument("--max-gap", type=batch.max_gap, default=30, metavar="FRAMES",
                   help=f"longest hole filled, in frames (1 to {batch.MAX_GAP}; longer holes "
                   "stay holes: bounded work; their number and the longest are "
                   "printed)")  # fmt: skip
    p.add_argument("--explain", action="store_true",
                   help="with auto: print the method chosen per gap length (or the methods it "
                   "blends, with their weights: two, or more when bagging averages the "
                   "resamples' choices) and its validation MMAE, for box centres and "
                   "sizes")  # fmt: skip
    p.add_argument("--seed", type=non_negative_int, default=None,
                   help="auto: seed of the artificial calibration gaps, an integer >= 0 "
                   "(default: 0; refused with another --method)")  # fmt: skip
    p.add_argument("--link", action="store_true", help="join fragments of one object first")
    add_max_distance(p)
    p.add_argument("--video", help="video or image folder of the tracks: the colour term "
                   "of --link (only the frames of fragment ends are read) and, "
                   "with or without --link, the holes' two sides (a hole whose sides each look "
                   "more like another object than like each other is left unfilled, and said): "
                   "both in one pass over the video; refused when it "
                   "has fewer frames than the tracks, or boxes start more than a tenth of "
                   "its width or height past its right or bottom edge (default: none, motion "
                   "and size only)")  # fmt: skip
    p.add_argument("--in-place", action="store_true",
                   help="allow --out to be the input file (it is replaced atomically)")  # fmt: skip
    batch.add_batch_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``pftrack recover``; return the exit status."""
    if args.seed is not None and args.method != "auto":
        raise ValueError(
            f"--seed is used only by --method auto (its calibration gaps), not {args.method}; "
            "drop it"
        )
    args.seed = args.seed or 0
    if args.max_distance is not None and not args.link:  # one file and a batch alike
        raise ValueError(
            "--max-distance is used only by --link (its linking gate); add --link or drop it"
        )
    if batch.is_batch(args.tracks):
        return batch.run_recover(args)
    batch.refuse_batch_options(args)
    args.tracks = args.tracks[0]
    from pftrack.cli._signals import hold_interrupts
    from pftrack.io.atomic import check_output, check_replaceable
    from pftrack.io.mot import is_mot_text, say_far_boxes, write_mot
    from pftrack.recovery import fill_gaps, link_tracklets
    from pftrack.recovery.fill import (
        copied_values,
        jump_note,
        side_frames,
        swap_note,
        unfilled_note,
    )
    from pftrack.recovery.linking import BoxColours, link_config_for, link_frames, read_tracks

    src = Path(args.tracks)
    out = Path(args.out)
    if out.exists() and src.exists() and os.path.samefile(out, src) and not args.in_place:
        raise ValueError(
            f"--out {out} is the input file; pass --in-place to replace it (atomically)"
        )
    inputs: tuple[Path, ...] = ()
    if args.video:  # the video, or every image of a folder and a sequence's seqinfo.ini
        from pftrack.io.video import source_files  # OpenCV: only with a video

        inputs = tuple(source_files(args.video))
    check_output(args.out, what="--out", inputs=inputs, tracks=True)
    if not args.in_place:  # --in-place: --out is the input, its rows read
        check_replaceable(args.out, "--out", is_mot_text, force=args.force, yours=TRACKS_YOURS)
    if args.video:  # an image --out beside its frames: one more frame of the next run
        from pftrack.io.video import check_outside_frames

        check_outside_frames({"--out": args.out}, args.video)
    rows = read_tracks(src)
    say_far_boxes(rows, src)
    n_links = 0
    frames = None
    if args.video:
        from pftrack.io.video import FrameSequence

        frames = FrameSequence(args.video)  # read when the colour term asks, in one pass
        check_video(args.video, frames, rows, src)
    try:
        colours: Any = frames
        if args.link:
            cfg = link_config_for(rows, args.max_gap, args.max_distance)
            if frames is not None:  # the linker's and the holes' frames in one decode
                wanted = link_frames(rows, cfg) | side_frames(rows, args.max_gap)
                colours = BoxColours(frames, rows, wanted)
            rows, mapping = link_tracklets(rows, cfg, colours)
            n_links = len(mapping)
        t0 = time.perf_counter()
        # with the video, the holes' sides too: two neighbours under one id
        filled, rep = fill_gaps(rows, args.method, args.max_gap, seed=args.seed, frames=colours)
        dt = time.perf_counter() - t0
    finally:
        if frames is not None:
            frames.close()
    # the work is done: --out is written whatever comes (held before the write, as the
    # commands with several outputs hold before their renames: held after it, a Ctrl-C
    # between the rename and the hold said "no output was changed" of a replaced --out; after
    # a Ctrl-C that code in C dropped, the writer still refuses: pftrack._interrupt)
    hold_interrupts()
    write_mot(args.out, filled, exact=copied_values(rows, filled))  # given values: all digits
    to = report_stream(args.out)  # rows on stdout (--out /dev/stdout): the report on stderr
    print(
        f"{src}: {counted(len(rows), 'row')}, {counted(n_links, 'fragment')} linked, "
        f"{counted(rep.n_gaps, 'gap')} filled with {counted(rep.n_filled_rows, 'row')} "
        f"({args.method}, {1e3 * dt:.1f} ms) -> {out} ({flag_note(rows)})",
        file=to,
    )
    if rep.n_long_holes:  # bounded work, said: was silent ("0 gaps filled")
        print(f"{src}: {unfilled_note(rep.n_long_holes, rep.longest_hole, args.max_gap)}", file=to)
    if rep.n_jumps:  # was filled without a word: a path drawn between two objects (issue 12)
        warn(f"{src}: {jump_note(rep.n_jumps, rep.largest_jump)}")
    if rep.n_swaps:  # with --video: two neighbours under one id (issue 12, stop 72)
        warn(f"{src}: {swap_note(rep.n_swaps, rep.largest_swap)}")
    if args.explain:
        print(rep.describe(), file=to)
    return 0


#: How far past the video's right or bottom edge a box may start, as a share of the frame's
#: width or height, before ``recover --video`` refuses the video as not the tracks' own.
EDGE_SLACK = 0.1


def check_video(video: str, frames: Any, rows: Any, src: Path) -> None:
    """Refuse a ``--video`` that cannot be the video of the tracks `rows` (of file `src`).

    Raises
    ------
    ValueError
        The video has fewer frames (by its header, or an image folder's count) than the
        tracks' last frame, or a box starts more than :data:`EDGE_SLACK` of the frame past its
        right or bottom edge (tracks of another video, or in another pixel scale).
    """
    if len(rows) == 0:
        return
    source = frames.source
    last = int(rows[:, 0].max())
    header = source.frames_to(last)  # 0: not known (Matroska's count is FFmpeg's estimate)
    if 0 < header < last:
        raise ValueError(
            f"--video {video} has {counted(header, 'frame')} but {src} has rows up to frame "
            f"{last}: not the video of these tracks"
        )
    for axis, size, edge in ((2, source.width, "right"), (3, source.height, "bottom")):
        k = int(rows[:, axis].argmax())
        start = float(rows[k, axis])
        if start > size * (1 + EDGE_SLACK):
            what = "left" if axis == 2 else "top"
            raise ValueError(
                f"--video {video} is {source.width}x{source.height} px but {src} has a box with "
                f"{what} {start:g} (frame {int(rows[k, 0])}, id {int(rows[k, 1])}), past its "
                f"{edge} edge: not the video of these tracks, or boxes in another pixel scale"
            )


def flag_note(rows: Any) -> str:
    """How filled rows are marked, and how many input rows were marked so already."""
    from pftrack.recovery.linking import filled_mask

    note = "interpolated flag: column 8 = 1, columns 9-10 = -1"
    n = int(filled_mask(rows).sum())
    return note + (f"; {counted(n, 'input row')} had it already, kept as observed" if n else "")
