"""``pftrack track``: track a video or image folder, MOTChallenge rows out."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from pftrack.cli._options import add_command, add_tracker_options, bounded_float, tracker_config


def add_parser(sub: Any) -> None:
    """Register ``track`` on `sub` (from ``add_subparsers``)."""
    p = add_command(
        sub,
        "track",
        help="track a video or image folder; MOTChallenge output",
        description="Track every object in SOURCE (a video file, or a folder of images such as "
        "a MOTChallenge img1/). Without --detections, objects come from background "
        "subtraction; with a MOTChallenge det.txt the tracker is a drop-in backend for any "
        "detector. Output: MOTChallenge rows frame,id,left,top,width,height,score,-1,-1,-1 "
        "(1-based frames, pixels of SOURCE), written atomically.",
    )
    p.add_argument("source", help="video file or image folder")
    p.add_argument("--out", required=True, help="tracks in MOTChallenge format (e.g. tracks.txt)")
    p.add_argument("--detections", help="MOTChallenge detection file (frame,-1,l,t,w,h,score,...)")
    p.add_argument(
        "--det-scale", type=bounded_float(1e-3, 1e3), default=1.0, metavar="S",
        help="multiply detection boxes by S to reach the video's pixels (0.625 for PETS09 "
        "det.txt on its 480x360 video)",
    )  # fmt: skip
    p.add_argument("--render", help="write an annotated video (.mp4 or .avi)")
    p.add_argument("--plot", help="write a trajectory plot (.png)")
    add_tracker_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``pftrack track``; return the exit status."""
    from pftrack.io.atomic import check_output, staged_outputs
    from pftrack.io.mot import write_mot
    from pftrack.io.video import FrameSource
    from pftrack.recovery import LinkConfig
    from pftrack.render import plot_trajectories, write_annotated_video
    from pftrack.tracking import BoxSmoother, load_detections, track_frames

    inputs = (args.source,) + ((args.detections,) if args.detections else ())
    check_output(args.out, what="--out", inputs=inputs)
    if args.render:
        check_output(args.render, what="--render", suffixes=(".mp4", ".avi"), inputs=inputs)
    if args.plot:
        check_output(args.plot, what="--plot", suffixes=(".png", ".jpg", ".jpeg"), inputs=inputs)
    source = FrameSource(args.source)
    dets = load_detections(args.detections, args.det_scale) if args.detections else None
    result = track_frames(
        source,
        detections=dets,
        config=tracker_config(args),
        rng=args.seed,
        fill=args.fill,
        smoother=None if args.no_smooth else BoxSmoother(),
        link=None if args.no_link else LinkConfig(),
    )
    n_ids = len(set(result.rows[:, 1].astype(int))) if len(result.rows) else 0
    with staged_outputs() as stage:  # all outputs replaced at the end, or none
        write_mot(stage(args.out), result.rows)
        if args.render:
            write_annotated_video(stage(args.render), FrameSource(args.source), result.rows,
                                  source.fps)  # fmt: skip
        if args.plot:
            first = next(iter(FrameSource(args.source)))
            plot_trajectories(stage(args.plot), result.rows, background=first,
                              title=Path(args.source).name)  # fmt: skip
    print(
        f"{result.n_frames} frames, {n_ids} tracks, {len(result.rows)} boxes in "
        f"{result.seconds:.2f} s ({result.fps:.0f} frames/s), seed {args.seed} -> {args.out}"
    )
    if args.render:
        print(f"annotated video -> {args.render}")
    if args.plot:
        print(f"trajectory plot -> {args.plot}")
    return 0
