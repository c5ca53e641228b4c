"""``pftrack render``: any MOTChallenge tracks file drawn on its video, and its trajectory plot.

``pftrack track --render`` draws the tracker's online boxes while it tracks; the file it writes
is the offline pass's (linked ids, filled and smoothed boxes). This command draws a file as it
is: ``pftrack track``'s, ``smooth``'s or ``recover``'s output, another tracker's, or the
ground truth.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path
from typing import Any

from pftrack.cli._options import (
    FPS_RANGE,
    YOURS,
    add_command,
    add_force,
    bounded_float,
    check_input_file,
    counted,
    report_stream,
)
from pftrack.cli.track import PLOT_SUFFIXES, keep_plot_background

#: A file most of whose boxes do not lie wholly inside the frame is in another frame's pixels:
#: warned (people at the edges cross it; most boxes do not).
OUTSIDE_SHARE = 0.5


def add_parser(sub: Any) -> None:
    """Register ``render`` on `sub` (from ``add_subparsers``)."""
    p = add_command(
        sub,
        "render",
        help="draw a MOTChallenge tracks file on its video (any tracker's output, or truth)",
        description="Draw the boxes, ids and trails of a MOTChallenge tracks file on the frames "
        "of its video, image folder or sequence folder, and write an annotated video and, "
        "with --plot, a trajectory plot on the first frame that is not dark. Row frame k is "
        "drawn on the video's k-th frame. pftrack track --render shows the boxes as tracked "
        "online; this shows a file as it is: pftrack track's final tracks, the output of "
        "pftrack smooth or recover (filled rows dashed), another tracker's, or the ground truth.",
    )
    p.add_argument("source", help="video file, image folder, or MOTChallenge sequence folder")
    p.add_argument("tracks", help="MOTChallenge tracks file (frame,id,left,top,w,h,...)")
    p.add_argument(
        "--out", required=True, metavar="VIDEO",
        help=".mp4 (H.264, plays in browsers) or .avi (MJPG); a device or pipe without "
        "extension (/dev/stdout): .mp4. Written atomically. An odd width or height gets one "
        "copied column or row (4:2:0), as pftrack track --render",
    )  # fmt: skip
    add_force(p)
    p.add_argument(
        "--scale", type=bounded_float(1e-3, 1e3), default=1.0, metavar="S",
        help="multiply the file's boxes by S to reach the video's pixels (0.001 to 1000; "
        "0.625 for PETS09 ground truth, 768x576, on its 480x360 video)",
    )  # fmt: skip
    p.add_argument(
        "--fps", type=bounded_float(*FPS_RANGE), metavar="FPS",
        help=f"frame rate of the video written, {FPS_RANGE[0]:g} to {FPS_RANGE[1]:g} (default: "
        "seqinfo.ini's frameRate, else the container's header, else the frames' time stamps "
        "(a header rate of 1000 or more is a time base), else 25)",
    )  # fmt: skip
    p.add_argument(
        "--trail",
        type=int,
        default=40,
        metavar="FRAMES",
        help="foot points of the last FRAMES frames drawn behind each track (0 to 100000; 0: none)",
    )
    p.add_argument("--plot", metavar="PNG",
                   help="also write a trajectory plot on the first frame that is not dark: "
                   ".png, .jpg (default: none)")  # fmt: skip
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``pftrack render``; return the exit status."""
    import numpy as np

    from pftrack._text import on_one_line as _shown  # a name's bytes not UTF-8 as \xe9, as errors
    from pftrack.cli._options import opencv_single_threaded
    from pftrack.cli._signals import hold_interrupts
    from pftrack.io.atomic import (
        check_distinct,
        check_output,
        check_replaceable,
        output_format,
        staged_outputs,
    )
    from pftrack.io.marks import is_marked_image
    from pftrack.io.mot import zero_based_note
    from pftrack.io.video import (
        FrameSource,
        check_outside_frames,
        check_source,
        is_live_source,
        source_files,
    )
    from pftrack.io.video_writer import VIDEO_SUFFIXES, check_frame_size, is_render
    from pftrack.recovery.linking import read_tracks
    from pftrack.render import paths_title, plot_trajectories, write_annotated_video

    if not 0 <= args.trail <= 100_000:
        raise ValueError(f"--trail is {args.trail}, expected 0 to 100000 frames")
    opencv_single_threaded()
    check_source(args.source)
    if is_live_source(args.source):
        raise ValueError(f"{args.source} is a live source: render reads a video file or folder")
    check_input_file(args.tracks, what="tracks file")
    inputs = (*source_files(args.source), args.tracks)
    check_output(args.out, what="--out", suffixes=VIDEO_SUFFIXES, inputs=inputs)
    if args.plot is not None:  # "" too: refused as empty (was: no plot, without a word)
        check_output(args.plot, what="--plot", suffixes=PLOT_SUFFIXES, inputs=inputs)
    check_distinct({"--out": args.out, "--plot": args.plot})
    check_replaceable(args.out, "--out", is_render, force=args.force)
    if args.plot:
        check_replaceable(args.plot, "--plot", is_marked_image, force=args.force, yours=YOURS)
    check_outside_frames({"--out": args.out, "--plot": args.plot}, args.source)
    rows = read_tracks(args.tracks, tracks_only=False)  # id -1 rows drawn, as any other
    rows[:, 2:6] *= args.scale
    source = FrameSource(args.source, fps=args.fps)
    fmt = output_format(args.out, VIDEO_SUFFIXES)  # a size its encoder cannot take: said now
    check_frame_size(f"--out {args.out}", fmt, source.width, source.height)
    # 0: not known (Matroska's count is FFmpeg's estimate); a header short of the rows: counted
    known = source.frames_to(int(rows[:, 0].min())) if len(rows) else source.counted_frames
    if known and len(rows) and rows[:, 0].min() > known:  # was: an empty video, exit 0
        raise ValueError(
            f"every row of {args.tracks} lies past the last frame of {source.name}, which has "
            f"{known} (the rows' frames are {int(rows[:, 0].min())}-"
            f"{int(rows[:, 0].max())}): the tracks of another video?"
        )
    n_frames = len(source)
    out = report_stream(args.out, args.plot)
    drawn = [0]
    kept: list[Any] = []  # the plot's background, the first frame not dark (read once)

    def read_counting() -> Any:
        for frame in source:
            if args.plot:
                keep_plot_background(kept, frame)
            drawn[0] += 1
            yield frame

    # what it has to say is printed once the outputs are written (a closed stdout or stderr
    # then costs the messages, never the files), as pftrack track does
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with staged_outputs() as stage:  # both outputs replaced at the end, or neither
            video = stage(args.out, output_format(args.out, VIDEO_SUFFIXES))
            write_annotated_video(video, _progress(read_counting(), n_frames), rows, source.fps,
                                  trail=args.trail)  # fmt: skip
            if args.plot:
                plot = stage(args.plot, output_format(args.plot, PLOT_SUFFIXES))
                # the sequence's or the file's name, as pftrack track's plot (was the whole path)
                name = source.sequence.name if source.sequence else Path(args.source).name
                # the rows the video shows (was: those past its end too, said not drawn)
                seen = rows[rows[:, 0] <= drawn[0]]
                plot_trajectories(plot, seen, background=kept[0], title=paths_title(name, seen))
            hold_interrupts()  # the work is done: the outputs are put in place whatever comes
    late = rows[rows[:, 0] > drawn[0]]
    notes = [str(w.message) for w in caught] + _outside(rows, source.width, source.height)
    if len(late):
        first, last = int(late[:, 0].min()), int(late[:, 0].max())
        frames = f"frame {first}" if first == last else f"frames {first}-{last}"
        # names that skip numbers: another tool may have numbered the rows by them
        gap = f" ({source.gap}: row frame k is drawn on the k-th image)" if source.gap else ""
        notes.append(
            f"{len(late)} row{'s' * (len(late) != 1)} of {frames} "
            f"{'are' if len(late) != 1 else 'is'} past the video's last frame {drawn[0]}: not "
            f"drawn{gap}"
        )
    elif len(rows):  # was said nowhere: rows numbered from 0 drawn a frame early
        base = zero_based_note(
            rows[:, 0].astype(np.int64), drawn[0], args.tracks, what="rows", mended="tracks1.txt"
        )
        notes += [base] if base is not None else []
    for note in notes:
        print(f"pftrack render: warning: {_shown(note)}", file=sys.stderr)
    shown = rows[rows[:, 0] <= drawn[0]]
    ids = len(np.unique(shown[:, 1])) if len(shown) else 0
    print(
        f"{counted(drawn[0], 'frame')}, {counted(ids, 'track')}, "
        f"{counted(len(shown), 'box', 'boxes')} drawn, {source.fps:g} fps "
        f"({source.fps_origin if source.fps_origin != 'given' else '--fps'}) -> {args.out}"
        + (f"; trajectory plot -> {args.plot}" if args.plot else ""),
        file=out,
    )
    return 0


def _progress(frames: Any, total: int) -> Any:
    from pftrack._progress import progress

    return progress(frames, total=total or None, desc="rendering", unit="frame")


def _outside(rows: Any, width: int, height: int) -> list[str]:
    """A warning when most boxes are not wholly in the frame: another frame's pixels (--scale)."""
    import numpy as np

    if not len(rows):
        return []
    x0, y0 = rows[:, 2], rows[:, 3]
    x1, y1 = x0 + rows[:, 4], y0 + rows[:, 5]
    # a pixel of slack: a box's right edge at the last column's far side is inside
    out = (x0 < -1) | (y0 < -1) | (x1 > width + 1) | (y1 > height + 1)
    right, bottom = float(np.max(x1)), float(np.max(y1))
    if out.mean() <= OUTSIDE_SHARE:
        return []
    return [
        f"{int(out.sum())} of {len(rows)} boxes reach outside the {width}x{height} frame "
        f"(up to {right:.0f}x{bottom:.0f}): are they in another frame's pixels? (--scale S)"
    ]
