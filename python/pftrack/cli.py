"""The ``pftrack`` command line: parses arguments and wires the library together.

Sub-commands: ``demo`` (the built-in job), ``track``, ``eval``, ``recover``, ``experiment``.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

EPILOG = """\
examples:
  pftrack demo                                   # synthetic scene: track, render, score, recover
  pftrack track video.avi --out tracks.txt --render annotated.mp4 --plot paths.png
  pftrack track seq/img1 --detections det.txt --out tracks.txt      # drop-in for any detector
  pftrack eval --gt gt.txt --res tracks.txt --scale 0.625
  pftrack recover tracks.txt --out filled.txt --method gdt --link
"""


def _positive_int(text: str) -> int:
    v = int(text)
    if v < 1:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, got {v}")
    return v


def _positive_float(text: str) -> float:
    v = float(text)
    if not v > 0:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {v}")
    return v


def _add_tracker_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--particles", type=_positive_int, default=100, metavar="N",
                   help="particles per object (default 100)")
    p.add_argument("--seed", type=int, default=0, help="random seed: same seed, same tracks (default 0)")
    p.add_argument("--detector", choices=("paper", "mog2", "knn"), default="paper",
                   help="built-in detector: the paper's adaptive background (C++), or OpenCV's "
                        "MOG2/KNN (default paper)")
    p.add_argument("--sampler", choices=("sis", "mh", "rjmcmc"), default="sis",
                   help="sis: one sequential-importance-sampling filter per object (the paper's "
                        "method, default); mh: Metropolis-Hastings per object; rjmcmc: one joint "
                        "RJ-MCMC chain over all objects (Smith et al. 2005)")
    p.add_argument("--dynamics", choices=("ar2", "ar2-mean"), default="ar2",
                   help="AR(2) model per particle (eq. 7) or from the particle-set means (eq. 8)")
    p.add_argument("--max-coast", type=int, default=10, metavar="FRAMES",
                   help="frames a track survives on its particle filter alone (default 10)")
    p.add_argument("--fill", choices=("linear", "pf"), default="linear",
                   help="with --no-smooth, boxes of a gap the filter bridged: interpolated, or "
                        "the filter's own")
    p.add_argument("--no-smooth", action="store_true",
                   help="write each frame's box as the tracker reported it online, instead of "
                        "smoothing every track over the whole run (RTS smoother; bridged gaps "
                        "are the smoother's interpolation)")
    p.add_argument("--no-link", action="store_true",
                   help="keep fragments of one object under separate ids, instead of joining "
                        "them by motion and size across gaps of up to 30 frames")


def _tracker_config(args: argparse.Namespace):  # type: ignore[no-untyped-def]
    from dataclasses import replace

    from pftrack.tracker import TrackerConfig

    base = TrackerConfig()
    model = replace(base.filter.model, use_means=args.dynamics == "ar2-mean")
    filt = replace(base.filter, n_particles=args.particles, model=model)
    return replace(base, filter=filt, detector=args.detector, sampler=args.sampler,
                   max_coast=args.max_coast)  # fmt: skip


def _cmd_track(args: argparse.Namespace) -> int:
    from pftrack.io.mot import write_mot
    from pftrack.io.video import FrameSource
    from pftrack.render import plot_trajectories, write_annotated_video
    from pftrack.recovery.linking import LinkConfig
    from pftrack.run import load_detections, track_frames
    from pftrack.smoothing import BoxSmoother

    for out in (args.out, args.render, args.plot):
        if out is not None and Path(out).resolve() == Path(args.source).resolve():
            raise ValueError(f"output {out} would overwrite the input video")
    source = FrameSource(args.source)
    dets = load_detections(args.detections, args.det_scale) if args.detections else None
    run = track_frames(source, detections=dets, config=_tracker_config(args), rng=args.seed,
                       fill=args.fill, smoother=None if args.no_smooth else BoxSmoother(),
                       link=None if args.no_link else LinkConfig())  # fmt: skip
    write_mot(args.out, run.rows)
    n_ids = len(set(run.rows[:, 1].astype(int))) if len(run.rows) else 0
    print(f"{run.n_frames} frames, {n_ids} tracks, {len(run.rows)} boxes in {run.seconds:.2f} s "
          f"({run.fps:.0f} frames/s), seed {args.seed} -> {args.out}")  # fmt: skip
    if args.render:
        write_annotated_video(args.render, FrameSource(args.source), run.rows, source.fps)
        print(f"annotated video -> {args.render}")
    if args.plot:
        first = next(iter(FrameSource(args.source)))
        plot_trajectories(args.plot, run.rows, background=first, title=Path(args.source).name)
        print(f"trajectory plot -> {args.plot}")
    return 0


def _cmd_demo(args: argparse.Namespace) -> int:
    from pftrack.demo import run_demo

    return run_demo(Path(args.out_dir), seed=args.seed, n_frames=args.frames, particles=args.particles)


def _cmd_smooth(args: argparse.Namespace) -> int:
    import os

    import numpy as np

    from pftrack.io.mot import data_line_numbers, read_mot, write_mot
    from pftrack.recovery.linking import LinkConfig, check_unique
    from pftrack.smoothing import smooth_tracks

    src, out = Path(args.tracks), Path(args.out)
    if out.exists() and os.path.samefile(out, src):
        raise ValueError(f"--out {out} is the input file; write the result elsewhere")
    rows = read_mot(src, what="tracks file")
    check_unique(rows, data_line_numbers(src))
    link = None if args.no_link else LinkConfig(max_gap=args.max_gap)
    result = smooth_tracks(rows, link=link)
    write_mot(out, result)
    print(f"{src}: {len(np.unique(rows[:, 1])) if len(rows) else 0} ids, {len(rows)} rows -> "
          f"{len(np.unique(result[:, 1])) if len(result) else 0} ids, {len(result)} rows "
          f"(filled rows flagged in column 8) -> {out}")  # fmt: skip
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every sub-command."""
    parser = argparse.ArgumentParser(
        prog="pftrack",
        description=(
            "Track many people or objects in video with one colour particle filter each, "
            "and recover the parts of their paths that tracking lost."
        ),
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True

    demo = sub.add_parser(
        "demo", help="the built-in job: a synthetic scene tracked, rendered, scored and recovered",
        description="Generate a synthetic scene (coloured walkers crossing on a textured "
                    "background, a lamp post in front), track it with one colour particle filter "
                    "per walker, print MOTA/IDF1 against the known truth, write tracks, an "
                    "annotated video and a trajectory plot, then cut gaps into the truth and "
                    "print each recovery method's error. Needs no data and no download.",
    )  # fmt: skip
    demo.add_argument("--out-dir", default="pftrack-demo", help="folder for the outputs (default pftrack-demo)")
    demo.add_argument("--seed", type=int, default=0, help="scene and tracker seed (default 0)")
    demo.add_argument("--frames", type=_positive_int, default=150, help="scene length (default 150)")
    demo.add_argument("--particles", type=_positive_int, default=100, help="particles per object")
    demo.set_defaults(func=_cmd_demo)

    track = sub.add_parser(
        "track", help="track a video or image folder; MOTChallenge output",
        description="Track every object in SOURCE (a video file, or a folder of images such as "
                    "a MOTChallenge img1/). Without --detections, objects come from background "
                    "subtraction; with a MOTChallenge det.txt the tracker is a drop-in backend "
                    "for any detector. Output: MOTChallenge rows frame,id,left,top,width,height,"
                    "score,-1,-1,-1 (1-based frames, pixels of SOURCE), written atomically.",
    )  # fmt: skip
    track.add_argument("source", help="video file or image folder")
    track.add_argument("--out", required=True, help="tracks in MOTChallenge format (e.g. tracks.txt)")
    track.add_argument("--detections", help="MOTChallenge detection file (frame,-1,l,t,w,h,score,...)")
    track.add_argument("--det-scale", type=_positive_float, default=1.0, metavar="S",
                       help="multiply detection boxes by S to reach the video's pixels "
                            "(0.625 for PETS09 det.txt on its 480x360 video)")
    track.add_argument("--render", help="write an annotated video (.mp4 or .avi)")
    track.add_argument("--plot", help="write a trajectory plot (.png)")
    _add_tracker_options(track)
    track.set_defaults(func=_cmd_track)

    smooth = sub.add_parser(
        "smooth", help="link, fill and smooth any tracker's MOTChallenge output (offline)",
        description="The offline pass pftrack track applies to its own tracks, for any "
                    "tracker's output: join fragments of one object by motion and size across "
                    "gaps of up to --max-gap frames, add the frames missing inside each track "
                    "(flagged 1 in column 8), and replace every box by a Rauch-Tung-Striebel "
                    "smoother's estimate over the whole track. Measured on PETS09-S2L1 public "
                    "detections: SORT 62.3/35.2 -> 71.7/60.1 MOTA/IDF1, ByteTrack 59.1/43.0 -> "
                    "75.2/52.3 (README). Smoothing is not idempotent: run it once, on raw output.",
    )  # fmt: skip
    smooth.add_argument("tracks", help="MOTChallenge tracks file (frame,id,left,top,w,h,conf,...)")
    smooth.add_argument("--out", required=True, help="output file (written atomically; never the input)")
    smooth.add_argument("--max-gap", type=_positive_int, default=30, metavar="FRAMES",
                        help="longest gap joined and filled (default 30)")
    smooth.add_argument("--no-link", action="store_true", help="smooth each id as it is")
    smooth.set_defaults(func=_cmd_smooth)

    from pftrack.eval.cli import add_eval_parser

    add_eval_parser(sub)

    from pftrack.recovery.cli import add_experiment_parser, add_recover_parser

    add_recover_parser(sub)
    add_experiment_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``pftrack`` script; returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except (FileNotFoundError, ValueError, TypeError) as exc:
        print(f"pftrack {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
