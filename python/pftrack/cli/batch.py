"""``pftrack batch``: track many sequences on Dask; the batch side of ``recover``/``smooth``.

Dask is imported only when a batch runs, never for ``--help``.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

from pftrack._threads import usable_cpus
from pftrack.cli._options import (
    DET_BASE_HELP,
    DET_BASES,
    DET_SCALE_RANGE,
    IOU_HELP,
    add_command,
    add_tracker_options,
    bounded_int,
    det_scale,
    iou_threshold,
    non_negative_int,
)
from pftrack.cli._signals import Terminated, exit_status, line_end

if TYPE_CHECKING:
    from pftrack.batch import BatchSummary

#: Exit status when a batch ran but some of its tasks failed (2: bad usage, nothing ran).
EXIT_SOME_FAILED = 1
#: ``--max-gap``'s upper bound (``recover``, ``smooth``, one file or a batch):
#: :data:`pftrack.recovery.fill.MAX_GAP_LIMIT` and :class:`pftrack.recovery.LinkConfig`'s,
#: stated here so that ``--help`` does not import the recovery code (a test checks they agree).
MAX_GAP = 100_000
#: Seconds a batch waits for a worker on a scheduler that has none:
#: :data:`pftrack.batch.engine.NO_WORKERS_WAIT`, stated here so that ``--help`` does not import
#: the engine (a test checks they agree).
NO_WORKERS_WAIT = 60


def max_gap(text: str) -> int:
    """Argument type of ``--max-gap`` (``recover``, ``smooth``; one file or a batch)."""
    return int(bounded_int(1, MAX_GAP)(text))


max_gap.__name__ = "int"  # argparse names the type in its messages


def add_batch_options(p: argparse.ArgumentParser) -> None:
    """Where a batch runs, and resuming: shared by ``batch``, ``recover`` and ``smooth``."""
    g = p.add_argument_group("batch (several inputs)")
    g.add_argument(
        "--scheduler", metavar="ADDRESS", default=None,
        help="a running Dask scheduler, tcp://HOST:PORT, checked first (protocol, host, port "
        "1-65535; not with --workers), connected to before --out is written (not at all when "
        "every output is complete: nothing runs, as no local cluster starts); waits up to "
        "Dask's connect timeout to reach it (30 s; $DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT), "
        "as long for a tcp:// port that says nothing or does not finish Dask's handshake "
        "(no Dask scheduler, or a frozen one; a web server, such "
        "as the dashboard's port, or a Dask worker's port is named as one at once), "
        "and while it has no worker (at the start, or after losing them all) or stops answering "
        "mid-run, says so at once "
        f"and waits up to {NO_WORKERS_WAIT} s for one "
        "($DASK_DISTRIBUTED__SCHEDULER__NO_WORKERS_TIMEOUT), "
        "then fails: at the start with exit status 2, nothing written; mid-run the tasks left "
        "fail (default: $DASK_SCHEDULER_ADDRESS, else none: a local cluster is started for "
        "the run and closed at the end)",
    )  # fmt: skip
    g.add_argument(
        "--workers", type=non_negative_int, default=None, metavar="N",
        help="worker processes of the local cluster, one thread each (default: one per core "
        f"this process may use, {usable_cpus()} here); 0 runs in this process without Dask; "
        "not with --scheduler (and given, a local run even where $DASK_SCHEDULER_ADDRESS is "
        "set)",
    )  # fmt: skip
    g.add_argument("--force", action="store_true",
                   help="redo inputs whose outputs are complete, instead of skipping "
                   "them, and replace files of the outputs' names in DIR that no earlier "
                   "batch wrote (refused without it); given one file, replace an --out that "
                   "holds no MOTChallenge rows (refused without it)")  # fmt: skip


#: The options of :func:`add_batch_options`, which a command given one file does not use
#: (``--force`` it does: an ``--out`` that pftrack would not replace, docs/io.md).
BATCH_ONLY = ("scheduler", "workers")


def refuse_batch_options(args: argparse.Namespace) -> None:
    """Refuse the batch options on a command given one file (they would do nothing).

    A one-file command's first check, so a missing input is said first: ``pftrack recover
    results/ --out filled/ --workers 0`` with no ``results/`` (a batch that never ran) said
    ``--workers applies to a batch ...: drop it``, then ``--out filled/ names a folder``, two
    mends for a folder that is not there.

    Raises
    ------
    FileNotFoundError
        The one input (``args.tracks``) does not exist (a broken link is named when read).
    ValueError
        ``--scheduler`` or ``--workers`` was given (``$DASK_SCHEDULER_ADDRESS``
        is not: it is read only by a batch).
    """
    for path in getattr(args, "tracks", None) or []:
        if not os.path.lexists(path):
            from pftrack.io.atomic import refuse_dash

            refuse_dash(Path(path), "tracks file")  # "-": stdin is not read, said so
            raise FileNotFoundError(f"tracks file not found: {path}")
    given = [
        f"--{n}"
        for n in BATCH_ONLY
        if getattr(args, n) is not None and getattr(args, n) is not False
    ]
    if given:
        raise ValueError(
            f"{', '.join(given)} {'applies' if len(given) == 1 else 'apply'} to a batch "
            "(several files or a folder); one file runs in this process: drop it"
        )


def is_batch(paths: list[str]) -> bool:
    """Several inputs, or a folder: the command runs as a batch (``--out`` is a folder)."""
    return len(paths) > 1 or any(Path(p).is_dir() for p in paths)


def _names_a_file(out: str) -> bool:
    """Whether a batch's `out` is named like a tracks file (``f.txt``) and is no folder."""
    return Path(out).suffix.lower() == ".txt" and not Path(out).is_dir()


def _as_batch(command: str, paths: list[str], out: str, where: dict[str, Any]) -> None:
    """Say why `command` runs as a batch before its batch-only errors (folder out, Dask).

    A folder given where one tracks file was meant (``pftrack recover SEQ --out f.txt``) ran
    a batch: with ``--out f.txt`` it made a folder named like a file, and without Dask the
    user read about Dask, not about the folder.
    """
    if len(paths) == 1 and Path(paths[0]).is_dir():
        why = f"{paths[0]} is a folder: pftrack {command} runs the tracks files in it"
    else:
        why = f"{len(paths)} inputs: pftrack {command} runs them"
    if _names_a_file(out):
        raise ValueError(
            f"{why} as a batch, whose --out is a folder for one output per file, not {out}; "
            f"give one tracks file for --out {out}"
        )
    if where.get("n_workers") != 0:
        from pftrack.batch.engine import _require_dask

        try:
            _require_dask()
        except ImportError as exc:
            raise ValueError(
                f"{why} as a batch, on Dask by default, which cannot be imported "
                f"({exc.name}): pip install 'pftrack[dask]', or --workers 0 to run them one "
                "after another in this process"
            ) from exc


def add_parser(sub: Any) -> None:
    """Register ``batch`` on `sub` (from ``add_subparsers``)."""
    p = add_command(
        sub,
        "batch",
        help="track many videos or sequences at once on Dask (local or a cluster)",
        description="Track every sequence of INPUT... (videos, image folders, MOTChallenge "
        "sequence folders SEQ/img1 + seqinfo.ini + det/det.txt + gt/gt.txt, or folders of "
        "them), one Dask task per sequence. Writes DIR/NAME.txt exactly as pftrack track "
        "does (NAME: the video's stem or the sequence folder's name), NAME.json beside it, "
        "and DIR/summary.json; prints frames, tracks, frames/s and, where gt/gt.txt exists, "
        "HOTA, MOTA and IDF1 per sequence (pftrack eval's figures), and the warnings each "
        "sequence raised. Workers read the inputs by these paths; this process "
        "writes every output. A re-run skips sequences whose outputs are complete.\n\n"
        "exit status: 0 all done, 1 some sequences failed (the others' outputs are written), "
        "2 bad usage (nothing ran), 130 interrupted (Ctrl-C), 143 terminated (SIGTERM).",
    )
    p.add_argument("inputs", nargs="+", metavar="INPUT", help="video, image or sequence folder")
    p.add_argument("--out", required=True, metavar="DIR",
                   help="output folder (created, with any missing parent folders)")  # fmt: skip
    p.add_argument(
        "--detections", choices=("auto",), default=None,
        help="auto: each sequence's det/det.txt (or det.txt) instead of the built-in detector",
    )  # fmt: skip
    p.add_argument(
        "--det-scale", type=det_scale, default="auto", metavar="S",
        help=f"multiply detection boxes by S ({DET_SCALE_RANGE[0]:g} to {DET_SCALE_RANGE[1]:g}); "
        "auto: the frame width over seqinfo.ini's imWidth where there is one (0.625 for "
        "PETS09-S2L1's video), else 1; a number only with --detections auto",
    )  # fmt: skip
    p.add_argument(
        "--det-base", type=int, choices=DET_BASES, default=None, metavar="{0,1}",
        help=f"{DET_BASE_HELP}; only with --detections auto",
    )  # fmt: skip
    p.add_argument("--render", action="store_true",
                   help="also write DIR/NAME.mp4: the final tracks of DIR/NAME.txt (linked, "
                   "filled and smoothed) drawn on the frames, boxes, ids and trails, as "
                   "pftrack render INPUT DIR/NAME.txt draws them; not the boxes as tracked "
                   "online that track --render draws. An odd width or height is made even by "
                   "one copied column or row; a later batch that scans DIR passes the video "
                   "over (its NAME.json lists it), so DIR may be the input folder")  # fmt: skip
    p.add_argument("--iou", type=iou_threshold, default=0.5,
                   help=f"{IOU_HELP}, for the metrics")  # fmt: skip
    add_tracker_options(p)
    add_batch_options(p)
    p.set_defaults(func=run)


#: The modules of the ``pftrack[dask]`` extra.
_DASK = ("dask", "distributed")


@contextlib.contextmanager
def _environment_scheduler() -> Iterator[None]:
    """Dask's ``scheduler-address`` setting is ``$DASK_SCHEDULER_ADDRESS`` as it is now.

    The batch reads the setting itself, so that an address given by no option is said to come
    from it where it cannot be reached (a user trial: "cannot connect to the Dask scheduler at
    tcp://127.0.0.1:8797", an address on no command line). Dask reads the variable once, as it
    is imported: a caller of :func:`pftrack.cli.main` that set it later is read here. Harmless
    with ``--scheduler`` or ``--workers``, which the batch takes before the setting.
    """
    address = os.environ.get("DASK_SCHEDULER_ADDRESS")
    if not address:
        yield
        return
    try:
        import dask
    except ImportError:  # the batch says how to install it, if it needs it
        yield
        return
    with dask.config.set({"scheduler-address": address}):
        yield


def _run(command: str, call: Callable[[], BatchSummary], explain: bool = False) -> int:
    """Run the batch; print its table, or what stopped it; return the exit status."""
    from pftrack._text import SaidBefore, opening
    from pftrack.batch.engine import named_as_options, warnings_as_they_come
    from pftrack.cli import said_above_bar

    said: set[str] = set()  # the tasks whose warnings were printed as they arrived
    before = SaidBefore()

    def say(name: str, warning: str) -> None:
        # a warning already said for another task, in the same words but for the names, in
        # one short line (was: 40 sequences, 40 lines of the same warning)
        first = before.first(name, warning)
        if first is not None:
            warning = f"the same as {first}'s ({opening(warning)})"
        said.add(name)
        said_above_bar(f"{name}: warning: {warning}")

    try:
        # --out, --render; from Python: out_dir, options.render
        with named_as_options(), _environment_scheduler(), warnings_as_they_come(say):
            summary = call()
    except KeyboardInterrupt as exc:  # Ctrl-C, or SIGTERM (pftrack.cli._signals)
        how = "terminated (SIGTERM)" if isinstance(exc, Terminated) else "interrupted"
        from pftrack.batch.engine import interrupted_left, interrupted_summary

        # none said: it stopped before the batch's run (scanning the inputs, ...)
        left = interrupted_left(exc) or "nothing was written: it stopped before the run began"
        stopped = interrupted_summary(exc)
        end = line_end()  # after the progress bar's line
        if stopped is not None:  # the table a batch that ends prints (was: summary.json alone)
            sys.stderr.write(end)
            end = ""
            _print_table(stopped, said, unwritten=False)  # the last line says why, if not
        print(f"{end}pftrack {command}: {how}; {left}", file=sys.stderr)
        return exit_status(exc)
    except ImportError as exc:  # Dask is an extra: pftrack[dask]
        hint = "; or --workers 0: in this process, without Dask" if exc.name in _DASK else ""
        print(f"pftrack {command}: error: {exc}{hint}", file=sys.stderr)
        return 2
    for e in summary.entries if explain else ():
        if e.get("explain"):
            print(f"{e['name']}:\n{e['explain']}")
    _print_table(summary, said)
    if summary.unwritten is None:  # else said with the problems
        print(f"summary -> {summary.out_dir / 'summary.json'}")
    return EXIT_SOME_FAILED if summary.failed or summary.unwritten else 0


def _print_table(summary: BatchSummary, said: set[str], unwritten: bool = True) -> None:
    """`summary`'s table on stdout, its problems on stderr (stdout's table stays parseable).

    The warnings first: those of the tasks in `said` were printed as they arrived, the others'
    (a skipped task's, from its earlier run) are printed here, before the table, alike ones
    once (:func:`~pftrack.batch.engine.said_once`); the errors after it. `unwritten`: with
    the line that says why ``summary.json`` is not written, if it is not.
    """
    from pftrack.batch.engine import said_once

    noun = "sequence" if summary.kind == "track" else "file"
    earlier = said_once(
        [
            (e["name"], w)
            for e in summary.entries
            if e["name"] not in said
            for w in e.get("warnings", ())
        ],
        noun,
        "warning",
    )
    if earlier:
        print("\n".join(earlier), file=sys.stderr)
        sys.stderr.flush()
    print(summary.table(problems=False))
    problems = summary.problems(unwritten=unwritten, warned=False)
    if problems:
        sys.stdout.flush()
        print("\n".join(problems), file=sys.stderr)


def _where(args: argparse.Namespace) -> dict[str, Any]:
    """Where the batch runs, checked before anything runs (the keywords of ``track_many``).

    ``--scheduler`` (checked: an empty or malformed address is refused) or ``--workers``, not
    both; with neither, ``$DASK_SCHEDULER_ADDRESS`` if set, else a local cluster. An explicit
    ``--workers`` runs locally even where ``$DASK_SCHEDULER_ADDRESS`` is set.
    """
    from pftrack.batch.engine import check_scheduler_address

    where: dict[str, Any] = {"scheduler": None, "n_workers": args.workers, "force": args.force}
    if args.scheduler is not None:
        if args.workers is not None:
            raise ValueError(
                "--scheduler and --workers contradict each other: --workers sizes the local "
                "cluster (0: this process), which --scheduler replaces; give one"
            )
        where["scheduler"] = check_scheduler_address(args.scheduler, "--scheduler")
    elif args.workers is None and os.environ.get("DASK_SCHEDULER_ADDRESS"):
        # checked here, read by the batch as Dask's setting: errors then say where it came from
        check_scheduler_address(os.environ["DASK_SCHEDULER_ADDRESS"], "$DASK_SCHEDULER_ADDRESS")
    return where


def run(args: argparse.Namespace) -> int:
    """Run ``pftrack batch``; return the exit status."""
    from pftrack.batch import TrackOptions, track_many
    from pftrack.cli._options import opencv_single_threaded, tracker_config

    if _names_a_file(args.out):  # was: made a folder named like a file (as recover's did)
        raise ValueError(
            f"--out is a folder for one output per sequence, not {args.out}; "
            f"give a folder, such as {Path(args.out).with_suffix('')}"
        )
    opencv_single_threaded()

    options = TrackOptions(
        config=tracker_config(args),
        seed=args.seed,
        detections=args.detections,
        det_scale=args.det_scale,
        det_base=args.det_base,
        fill=args.fill,
        smooth=not args.no_smooth,
        link=not args.no_link,
        render=".mp4" if args.render else None,
        iou=args.iou,
    )
    where = _where(args)
    return _run("batch", lambda: track_many(args.inputs, args.out, options=options, **where))


def run_recover(args: argparse.Namespace) -> int:
    """``pftrack recover`` with several files or a folder: one task per file."""
    from pftrack.batch import RecoverOptions, recover_many

    for flag, given in (("--video", args.video), ("--in-place", args.in_place)):
        if given:
            raise ValueError(f"{flag} takes one tracks file, not several or a folder")
    options = RecoverOptions(
        method=args.method,
        max_gap=args.max_gap,
        seed=args.seed,
        link=args.link,
        max_distance=args.max_distance,
    )
    where = _where(args)
    _as_batch("recover", args.tracks, args.out, where)
    return _run(
        "recover",
        lambda: recover_many(args.tracks, args.out, options=options, **where),
        explain=args.explain,
    )


def run_smooth(args: argparse.Namespace) -> int:
    """``pftrack smooth`` with several files or a folder: one task per file."""
    from pftrack.batch import SmoothOptions, smooth_many

    options = SmoothOptions(
        max_gap=args.max_gap, link=not args.no_link, max_distance=args.max_distance
    )
    where = _where(args)
    _as_batch("smooth", args.tracks, args.out, where)
    return _run("smooth", lambda: smooth_many(args.tracks, args.out, options=options, **where))
