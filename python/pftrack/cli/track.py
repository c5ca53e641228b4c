"""``pftrack track``: track a video, image folder, sequence, camera or stream; MOT rows out."""

from __future__ import annotations

import argparse
import contextlib
import os
import signal
import sys
import warnings
from pathlib import Path
from typing import IO, Any

from pftrack._warn import warn
from pftrack.cli._options import (
    DET_BASE_HELP,
    DET_BASES,
    DET_SCALE_RANGE,
    FPS_RANGE,
    TRACKS_YOURS,
    YOURS,
    add_command,
    add_force,
    add_tracker_options,
    bounded_float,
    counted,
    det_scale,
    report_stream,
    tracker_config,
)

#: ``--plot``'s formats; the first is a device's (``--plot /dev/stdout``).
PLOT_SUFFIXES = (".png", ".jpg", ".jpeg")


def add_parser(sub: Any) -> None:
    """Register ``track`` on `sub` (from ``add_subparsers``)."""
    p = add_command(
        sub,
        "track",
        help="track a video, image folder, camera or stream; MOTChallenge output",
        description="Track every object in SOURCE: a video file, a folder of images (natural "
        "order: 2.jpg before 10.jpg, frame k the k-th image; names that skip numbers are "
        "refused with detections, and in a MOTChallenge sequence's image folder, where "
        "image 1 is frame 1), a "
        "MOTChallenge sequence folder (seqinfo.ini gives the frame rate and image folder, "
        "det/det.txt or det.txt the detections of --detections auto; without its image "
        "folder, the one video file beside seqinfo.ini is read, as pftrack batch does), a "
        "camera index (0) or a stream URL (rtsp://, http://, ...). Without --detections, "
        "objects come from background subtraction; with a MOTChallenge det.txt the tracker is "
        "a drop-in backend for any detector. Output: MOTChallenge rows "
        "frame,id,left,top,width,height,score,flag,-1,-1 (1-based frames, pixels of SOURCE; "
        "flag 1 on a box the offline pass filled in a hole, else -1), "
        "written atomically. The boxes are the filters' estimates, not clipped to the frame: "
        "near its edge one may reach past it by a few pixels, as ground-truth boxes do (clip "
        "them before cropping).\n\n"
        "Live sources (camera, stream URL, named pipe): the rows the tracker settles (online "
        "boxes, flushed every frame) go to a hidden file beside --out (.NAME.<hex>.part), and "
        "--out is left as it was until the run ends; Ctrl-C stops after the current frame, "
        "and --out is then replaced by the finished tracks (linked and smoothed, unless "
        "--no-link / --no-smooth) with exit status 0; a second Ctrl-C aborts (exit 130): "
        "--out stays as it was, and the online rows so far are kept beside it in a new "
        "STEM.partial.SUFFIX (tracks.partial.txt for tracks.txt; tracks.partial-2.txt if that "
        "exists, ...), as the last message says; SIGTERM or an error likewise. A device or "
        "pipe --out (/dev/stdout) gets the online rows themselves, and no finished tracks. On "
        "a file source, Ctrl-C aborts and leaves --out as it was (exit 130).",
    )
    p.add_argument(
        "source",
        help="video file, image folder, MOTChallenge sequence folder, camera index or URL",
    )
    p.add_argument("--out", required=True, help="tracks in MOTChallenge format (e.g. tracks.txt)")
    add_force(p)
    p.add_argument(
        "--detections", metavar="FILE",
        help="MOTChallenge detection file (frame,-1,l,t,w,h,score,...), or 'auto' for the "
        "sequence's det/det.txt (default: the built-in detector)",
    )  # fmt: skip
    p.add_argument(
        "--det-scale", type=det_scale, default="auto", metavar="S",
        help="multiply detection boxes by S to reach the video's pixels "
        f"({DET_SCALE_RANGE[0]:g} to {DET_SCALE_RANGE[1]:g}; 0.625 for PETS09 det.txt on its "
        "480x360 video); auto: for the sequence's own detections, the frame width over "
        "seqinfo.ini's imWidth, else 1; a number only with --detections",
    )  # fmt: skip
    p.add_argument(
        "--det-base", type=int, choices=DET_BASES, default=None, metavar="{0,1}",
        help=f"{DET_BASE_HELP}; only with --detections",
    )  # fmt: skip
    p.add_argument(
        "--fps", type=bounded_float(*FPS_RANGE), metavar="FPS",
        help=f"frame rate of SOURCE, for --render, {FPS_RANGE[0]:g} to {FPS_RANGE[1]:g} "
        "(default: seqinfo.ini's frameRate, in the same range, else the container's header, "
        "else the frames' time stamps (a header rate of 1000 or more is a time base), else 25)",
    )  # fmt: skip
    p.add_argument(
        "--render", metavar="VIDEO",
        help="write an annotated video while tracking: .mp4 (H.264, plays in browsers) or "
        ".avi (MJPG; a device or pipe without extension, e.g. /dev/stdout: .mp4); boxes, ids "
        "and trails as tracked online. Its size is the source's, made even (H.264's 4:2:0 "
        "needs it): an odd width or height gets one copied column or row at the right or "
        "bottom, so a 321x241 source gives a 322x242 video (default: none)",
    )  # fmt: skip
    p.add_argument("--plot", metavar="PNG",
                   help="write a trajectory plot on the first frame that is not dark: .png, "
                   ".jpg (a device or pipe without extension: .png) (default: none)")  # fmt: skip
    add_tracker_options(p)
    p.set_defaults(func=run)


def keep_plot_background(kept: list[Any], frame: Any) -> None:
    """Keep in `kept` the background of ``--plot``: the first frame that is not dark.

    A video that fades in from black, or starts with the lens cap on, gave a plot on a black
    picture (frame 1). A frame is dark as the built-in detector counts it
    (:func:`pftrack.detection.light.is_dark`); the first frame is kept until a frame that is
    not dark comes, so a video dark throughout is drawn on its first frame, as before. Each
    frame is looked at only while the one kept is dark; `kept` holds the frame and whether it
    is dark (``kept[0]``, ``kept[1]``: the kept frame's darkness measured once, not per frame).
    """
    from pftrack.detection.light import is_dark

    if not kept:
        kept.extend((frame.copy(), is_dark(frame)))
    elif kept[1] and not is_dark(frame):
        kept[:] = [frame.copy(), False]


class _StopOnCtrlC:
    """While active, the first Ctrl-C stops `source` after the current frame; a second aborts."""

    def __init__(self, source: Any) -> None:
        self.source = source
        self._previous: Any = None

    def _handler(self, signum: int, frame: Any) -> None:
        if self.source.stopped:
            from pftrack._interrupt import put_off_in_imports

            if put_off_in_imports(frame, signum):  # at the next line outside importlib
                return
            # the abort, once: a third Ctrl-C raised in its cleanup could skip the wait for the
            # source's reader threads, and the process aborted at exit with a thread inside a
            # C++ read ("FATAL: exception not rethrown"); __exit__ restores the handler
            signal.signal(signal.SIGINT, signal.SIG_IGN)
            if callable(self._previous):  # the abort is a Ctrl-C as the handler before takes
                # it: the pftrack process's notes it (pftrack._interrupt), so the outputs are
                # not put in place if code in C drops the KeyboardInterrupt
                self._previous(signum, frame)
            raise KeyboardInterrupt
        self.source.stop()
        from pftrack.cli._signals import line_end

        print(f"{line_end()}stopping after this frame (Ctrl-C again to abort)", file=sys.stderr)

    def __enter__(self) -> _StopOnCtrlC:
        self._previous = signal.signal(signal.SIGINT, self._handler)
        return self

    def __exit__(self, *exc: object) -> None:
        signal.signal(signal.SIGINT, self._previous)


def _track(live: bool, first: list[Any], source: Any, **kwargs: Any) -> Any:
    """``track_frames(source, **kwargs)``, with Ctrl-C before a live source's first frame.

    That is an interrupt (exit 130), not the bad input "stopped before its first frame" (exit
    2). `first` is the list the run's ``on_frame`` puts the first frame in.
    """
    from pftrack.tracking import track_frames

    try:
        return track_frames(source, **kwargs)
    except ValueError:
        if live and source.stopped and not first:
            raise KeyboardInterrupt from None
        raise


def _abort_note(out: str, side: Any, streamed: int | None, committed: bool) -> str | None:
    """What a live run that failed or was aborted left, for ``main``'s last line; None: nothing.

    Parameters
    ----------
    out : str
        ``--out``.
    side : SideFile or None
        The side file of a run into a file (:func:`pftrack.io.atomic.side_file`), its block
        left already: :attr:`~pftrack.io.atomic.SideFile.kept` says where its rows are.
    streamed : int or None
        Rows written through into ``--out`` (a device, pipe or descriptor); None if not one.
    committed : bool
        Whether every output had been renamed into place.
    """
    if committed:
        return "every output was written"
    if streamed:
        return (
            f"the {streamed} online rows tracked so far were written to {out}; no other "
            "output was changed"
        )
    if side is not None and side.kept is not None:
        return (
            f"no output was changed; the {side.lines} online rows tracked so far are kept in "
            f"{side.kept}"
        )
    return None


def _resolve_detections(args: argparse.Namespace, source: Any) -> str | os.PathLike[str] | None:
    """The detection file's path; with ``--det-base``, a :class:`~pftrack.io.mot.MotFile`.

    The numbering travels with the path: ``load_detections`` reads it so, and the note of a
    file that looks numbered from 0 is not said of a numbering the user stated.
    """
    if args.detections != "auto":
        path = str(args.detections) if args.detections else None
    else:
        found = source.sequence.detections if source.sequence is not None else None
        if found is None:
            raise ValueError(
                f"--detections auto: {args.source} is not a MOTChallenge sequence with "
                "det/det.txt (a folder with seqinfo.ini or img1/, or its img1/); give the "
                "detection file"
            )
        path = str(found)
    if path is None or args.det_base is None:
        return path
    from pftrack.io.mot import MotFile

    return MotFile(path, args.det_base)


def _det_scale(
    args: argparse.Namespace, source: Any, det_path: str | os.PathLike[str], said: list[str]
) -> float:
    """``--det-scale``, or the sequence's own: its detections are in seqinfo.ini's pixels.

    A scale taken from seqinfo.ini is said in `said` (printed once the outputs are written).
    """
    if args.det_scale is not None:
        return float(args.det_scale)
    seq = source.sequence
    own = seq.detections if seq is not None else None
    if own is None or seq.width is None or not own.samefile(det_path):
        return 1.0
    from pftrack.io.video import info_scale
    from pftrack.tracking.run import SeqinfoScale

    scale = info_scale(
        (source.width, source.height), (seq.width, seq.height), seq.folder / "seqinfo.ini"
    )
    if scale == 1.0:
        return 1.0
    said.append(
        f"detections scaled by {scale:g}: frames are {source.width} px wide, "
        f"{seq.folder / 'seqinfo.ini'} says imWidth={seq.width} (--det-scale overrides)"
    )
    return SeqinfoScale(scale)  # not stated: its boxes may be refused at the frames' edges


def _check_outputs(args: argparse.Namespace, live: bool) -> None:
    """Before any work: the detection file can be read, every output written, none twice."""
    from pftrack.cli._options import check_input_file
    from pftrack.io.atomic import check_distinct, check_output, check_replaceable
    from pftrack.io.marks import is_marked_image
    from pftrack.io.mot import is_mot_text
    from pftrack.io.video import check_outside_frames, find_sequence, source_files
    from pftrack.io.video_writer import VIDEO_SUFFIXES, is_render

    given = [d for d in (args.detections,) if d and d != "auto"]
    for det in given:
        check_input_file(det, what="--detections")
    # the video, or every image of a folder and a sequence's seqinfo.ini (or its one video)
    inputs = tuple(source_files(args.source) if not live else []) + tuple(given)
    if not live and args.detections == "auto":  # the sequence's det.txt is an input too
        with contextlib.suppress(ValueError):  # a bad seqinfo.ini is refused when read
            seq = find_sequence(args.source)
            found = seq.detections if seq is not None else None
            inputs += (found,) if found is not None else ()
    check_output(args.out, what="--out", inputs=inputs, tracks=True)
    if args.render is not None:  # "" too: refused as empty (was: no video, without a word)
        check_output(args.render, what="--render", suffixes=VIDEO_SUFFIXES, inputs=inputs)
    if args.plot is not None:
        check_output(args.plot, what="--plot", suffixes=PLOT_SUFFIXES, inputs=inputs)
    outputs = {"--out": args.out, "--render": args.render, "--plot": args.plot}
    check_distinct(outputs)
    force = args.force
    check_replaceable(args.out, "--out", is_mot_text, force=force, yours=TRACKS_YOURS)
    if args.render:
        check_replaceable(args.render, "--render", is_render, force=force)
    if args.plot:
        check_replaceable(args.plot, "--plot", is_marked_image, force=force, yours=YOURS)
    if not live:
        check_outside_frames(outputs, args.source)


def run(args: argparse.Namespace) -> int:
    """Run ``pftrack track``; return the exit status.

    Warnings go to stderr as they are raised (above the progress bar); the summary goes to
    stdout once every output is written: a closed stdout (``| head``) then costs the summary,
    never the files.
    """
    from pftrack._stats import unique_values
    from pftrack.cli._options import opencv_single_threaded
    from pftrack.cli._signals import hold_interrupts, set_outcome
    from pftrack.io.atomic import (
        SideFile,
        atomic_write,
        output_format,
        side_file,
        staged_outputs,
        writes_through,
    )
    from pftrack.io.mot import format_mot_row, write_mot
    from pftrack.io.video import FrameSource, check_source, gap_note, is_live_source
    from pftrack.io.video_writer import VIDEO_SUFFIXES, check_frame_size
    from pftrack.recovery import LinkConfig
    from pftrack.render import TrackRenderer, paths_title, plot_trajectories
    from pftrack.tracking import BoxSmoother, load_detections
    from pftrack.tracking.run import say_zero_based

    opencv_single_threaded()

    check_source(args.source)  # "" would track the current folder
    live = is_live_source(args.source)
    config = tracker_config(args)  # contradictory options refused before any work
    if args.fps is not None and not args.render:  # was ignored, as no other option is
        raise ValueError(
            f"--fps {args.fps:g} is the frame rate of --render's video; without --render "
            "nothing uses it (tracking counts frames): drop it, or give --render VIDEO"
        )
    _check_outputs(args, live)
    source = FrameSource(args.source, fps=args.fps)
    renderer: TrackRenderer | None = None
    said: list[str] = []  # stdout, after the outputs are written
    # a live run into a device, pipe or descriptor (/dev/stdout) streams its rows there and
    # only there: the finished tracks cannot replace what was written already. Into a file,
    # its rows go to a hidden side file beside --out, which the finished tracks replace at
    # the end; --out is not touched before then (an abort keeps the rows: see _abort_note)
    streamed = live and writes_through(args.out)
    online: IO[str] | None = None  # where the streamed rows go
    n_online = [0]  # rows streamed so far
    online_ids: set[float] = set()  # their ids
    side: SideFile | None = None
    committed = False  # every staged output renamed into place
    try:
        if args.render:  # a size its encoder cannot take: said before any work
            fmt = output_format(args.render, VIDEO_SUFFIXES)
            check_frame_size(f"--render {args.render}", fmt, source.width, source.height)
        with contextlib.ExitStack() as keep:
            if live and not streamed:
                side = keep.enter_context(side_file(args.out))
            with staged_outputs() as stage:  # every output replaced at the end, or none
                det_path = _resolve_detections(args, source)
                dets = (
                    load_detections(det_path, _det_scale(args, source, det_path, said))
                    if det_path
                    else None
                )
                if args.render:  # a device (/dev/null, /dev/stdout) takes the default, .mp4
                    video = stage(args.render, output_format(args.render, VIDEO_SUFFIXES))
                    renderer = TrackRenderer(video, source.fps)
                first: list[Any] = []
                background: list[Any] = []  # --plot's: the first frame that is not dark

                def on_frame(n: int, frame: Any, tracks: Any, rows: Any) -> None:
                    if n == 1:
                        first.append(frame)
                    if args.plot:
                        keep_plot_background(background, frame)
                    if renderer is not None:
                        renderer.add(frame, tracks)
                    if side is not None:
                        side.write_lines(format_mot_row(r) for r in rows)
                    elif online is not None:
                        for r in rows:
                            online.write(format_mot_row(r) + "\n")
                        online.flush()
                        n_online[0] += len(rows)
                        online_ids.update(r[1] for r in rows)

                with contextlib.ExitStack() as stack:
                    if streamed:
                        online = stack.enter_context(atomic_write(args.out))  # written through
                    if live:  # into a pipe too: the run's --render and --plot are kept
                        stack.enter_context(_StopOnCtrlC(source))
                    # each warning on stderr as it is raised (the command's showwarning), not
                    # after the run: a variable frame rate is said at frame 50 of an hour's video
                    stack.enter_context(warnings.catch_warnings())
                    warnings.simplefilter("always")
                    gap = gap_note(source) if dets is None else None  # with them: refused
                    if gap is not None:
                        # was said nowhere: the rows past the gap are numbered by position,
                        # and a ground truth numbered by the names scored them shifted
                        warn(gap)
                    if det_path is not None and dets is not None:
                        say_zero_based(dets, source.counted_frames, det_path)
                    result = _track(
                        live,
                        first,
                        source,
                        detections=dets,
                        config=config,
                        rng=args.seed,
                        fill=args.fill,
                        bootstrap=args.bootstrap,
                        smoother=None if args.no_smooth else BoxSmoother(),
                        link=None if args.no_link else LinkConfig(),
                        on_frame=on_frame,
                    )
                if not streamed:
                    write_mot(stage(args.out), result.rows)
                n_ids = len(unique_values(result.rows[:, 1])) if len(result.rows) else 0
                n_rows = len(result.rows)
                if streamed:  # what went there: the finished tracks are not written
                    n_ids, n_rows = len(online_ids), n_online[0]
                stopped = " (stopped by Ctrl-C)" if source.stopped else ""
                how = " (online rows, as they settled)" if streamed else ""
                said.append(
                    f"{counted(result.n_frames, 'frame')}{stopped}, {counted(n_ids, 'track')}, "
                    f"{counted(n_rows, 'box', 'boxes')} in {result.seconds:.2f} s "
                    f"({result.fps:.0f} frames/s), seed "
                    f"{args.seed} -> {args.out}{how}"
                )
                if renderer is not None:
                    renderer.close()
                    origin = "--fps" if source.fps_origin == "given" else source.fps_origin
                    said.append(
                        f"annotated video ({renderer.writer.codec}, {source.fps:g} fps from "
                        f"{origin}) -> {args.render}"
                    )
                if args.plot:
                    name = (
                        source.sequence.name
                        if source.sequence is not None
                        else Path(args.source).name
                    )
                    plot = stage(args.plot, output_format(args.plot, PLOT_SUFFIXES))  # device: png
                    title = paths_title(name, result.rows)
                    plot_trajectories(plot, result.rows, background=background[0], title=title)
                    said.append(f"trajectory plot -> {args.plot}")
                hold_interrupts()  # the work is done: the outputs are put in place whatever comes
            committed = True
    except BaseException as exc:
        if renderer is not None:
            renderer.abort()  # no half-written video (a finished one stays)
        if live:
            rows = n_online[0] if streamed else None
            set_outcome(exc, _abort_note(args.out, side, rows, committed))
        raise
    finally:
        source.close()
    to = report_stream(args.out, args.render, args.plot)  # none of them on stdout's rows
    for line in said:
        print(line, file=to)
    return 0
