"""The batch entry points: :func:`track_many`, :func:`recover_many`, :func:`smooth_many`."""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, TypeVar

from pftrack._check import shown
from pftrack._typing import PathLike
from pftrack.batch.engine import BatchSummary, Job, run_jobs
from pftrack.batch.inputs import Inputs, SequenceInput, find_sequences, find_track_files
from pftrack.batch.tasks import (
    RecoverOptions,
    SmoothOptions,
    TaskResult,
    TrackOptions,
    missing_detections,
    recover_file,
    sequence_length,
    smooth_file,
    track_sequence,
)
from pftrack.io.video import source_files

if TYPE_CHECKING:
    from pathlib import Path

    from distributed import Client

__all__ = ["recover_many", "smooth_many", "track_many"]

_Options = TypeVar("_Options", TrackOptions, RecoverOptions, SmoothOptions)

#: Which entry point takes which options class (named when another one is given).
_TAKEN_BY = {
    TrackOptions: "track_many",
    RecoverOptions: "recover_many",
    SmoothOptions: "smooth_many",
}


def _options(options: object, kind: type[_Options], func: str) -> _Options:
    """`options`, or ``kind()`` for None; anything else is refused before any task runs.

    Raises
    ------
    TypeError
        `options` is not a `kind` (was: ``recover_many(..., options=TrackOptions())`` failed
        every file with an AttributeError, ``smooth_many(..., options=RecoverOptions(...))``
        ran with the wrong class's settings, ``options="seed=1"`` raised an AttributeError).
    """
    if options is None:
        return kind()
    if isinstance(options, kind):
        return options
    other = _TAKEN_BY.get(type(options))
    hint = f"{type(options).__name__} ({type(options).__name__} is {other}'s)" if other else None
    raise TypeError(
        f"{func}: options must be a {kind.__name__} or None, got {hint or shown(options)}"
    )


def track_many(
    inputs: Inputs,
    out_dir: PathLike,
    client: Client | None = None,
    *,
    options: TrackOptions | None = None,
    scheduler: str | None = None,
    n_workers: int | None = None,
    force: bool = False,
    show_progress: bool | None = None,
) -> BatchSummary:
    """Track every sequence of `inputs`, one Dask task each; write ``out_dir/NAME.txt``.

    Parameters
    ----------
    inputs : path or sequence of paths
        Videos, image folders, MOTChallenge sequence folders, or folders of them (see
        :func:`~pftrack.batch.find_sequences`). Workers read them by these paths.
    out_dir : path
        Output folder (created if missing): ``NAME.txt`` (byte-identical to ``pftrack track``
        with the same settings), ``NAME.mp4`` with ``options.render``, the sidecar
        ``NAME.json`` and ``summary.json``. Written by this process, not by the workers.
    client : distributed.Client, optional
        Run on this client's cluster (left open). Default: `scheduler`, else a new
        ``LocalCluster`` with `n_workers` single-threaded worker processes, closed at the end.
    options : TrackOptions, optional
        Tracker and output settings (default ``TrackOptions()``).
    scheduler : str, optional
        Address of a running Dask scheduler (also read from ``DASK_SCHEDULER_ADDRESS``).
    n_workers : int, optional
        Workers of the local cluster (default: one per core this process may use); 0 runs in
        this process, one sequence after the other, without Dask.
    force : bool
        Redo sequences whose outputs are already complete.
    show_progress : bool, optional
        Progress bar on stderr (default: when stderr is a terminal): the frames tracked over
        all the sequences, with the time left where every sequence's length is known (a
        video's header, an image folder; else the count and rate; one that cannot be opened
        counts 0 frames, named in the label: ``1 unreadable``), and the sequences done.
        The tasks report their frames as they go, from Dask workers too (as Dask events,
        twice a second at most).

    Returns
    -------
    BatchSummary
        Frames, tracks, frames/s and metrics (where ``gt/gt.txt`` exists) per sequence; failed
        sequences with their error.

    Raises
    ------
    TypeError
        `options` is not a :class:`TrackOptions` (nor None), before anything else; `client`
        is not a ``distributed.Client``.
    ValueError
        Bad inputs, or an `out_dir` that is a file or would overwrite an input (named
        ``out_dir``), before any task runs; an `out_dir` that another batch is writing into;
        see :func:`~pftrack.batch.run_jobs` for the rest.
    PermissionError
        An `out_dir` that cannot be written (or made), before the cluster starts.

    Warns
    -----
    UserWarning
        A folder of `inputs` has sequences deeper than the one level looked into: they are
        not tracked (see :func:`~pftrack.batch.find_sequences`).
    """
    opts = _options(options, TrackOptions, "track_many")
    seqs = find_sequences(inputs)
    jobs = [
        Job(
            s.name,
            track_sequence,
            (s, opts),
            s.files,
            functools.partial(sequence_length, s),
            guards=_guards(s),
            # certain to fail: reported failed without a task (was: sent to the cluster)
            refused=missing_detections(s, opts),
        )
        for s in seqs
    ]
    return run_jobs(
        jobs,
        out_dir,  # as given: run_jobs refuses an empty one (Path("") is ".")
        kind="track",
        settings=opts.settings(),
        suffixes=(opts.render,) if opts.render else (),
        client=client,
        scheduler=scheduler,
        n_workers=n_workers,
        force=force,
        show_progress=show_progress,
    )


def _guards(seq: SequenceInput) -> tuple[Path, ...]:
    """What no output may replace: every image `seq` reads, its ``seqinfo.ini``.

    Only the frames' path for a folder that cannot be looked into (its task fails, named so;
    was: the whole batch stopped, ``Permission denied: .../img1/seqinfo.ini``).
    """
    try:
        return tuple(source_files(seq.frames))
    except PermissionError:
        return (seq.frames,)


def recover_many(
    inputs: Inputs,
    out_dir: PathLike,
    client: Client | None = None,
    *,
    options: RecoverOptions | None = None,
    scheduler: str | None = None,
    n_workers: int | None = None,
    force: bool = False,
    show_progress: bool | None = None,
) -> BatchSummary:
    """Fill the gaps of every tracks file of `inputs` (files or folders of ``*.txt``).

    As :func:`track_many`, for tracks files instead of sequences.

    Parameters
    ----------
    inputs : path or sequence of paths
        MOTChallenge tracks files, or folders of ``*.txt`` (see
        :func:`~pftrack.batch.find_track_files`).
    out_dir : path
        Output folder (created if missing): ``NAME.txt`` for each ``NAME.txt`` of `inputs`,
        equal to ``pftrack recover FILE`` with the same settings, its sidecar ``NAME.json`` and
        ``summary.json``.
    client : distributed.Client, optional
        Run on this client's cluster (left open). Default: `scheduler`, else a new
        ``LocalCluster`` with `n_workers` workers, closed at the end.
    options : RecoverOptions, optional
        The command's settings (default ``RecoverOptions()``).
    scheduler : str, optional
        Address of a running Dask scheduler (also read from ``DASK_SCHEDULER_ADDRESS``).
    n_workers : int, optional
        Workers of the local cluster (default: one per core this process may use); 0 runs in
        this process, one file after the other, without Dask.
    force : bool
        Redo files whose outputs are already complete.
    show_progress : bool, optional
        Progress bar over the files on stderr (default: when stderr is a terminal).

    Returns
    -------
    BatchSummary
        Per file: rows in and out, fragments linked, gaps and rows filled, holes left
        unfilled (longer than ``max_gap``), what ``auto`` chose; failed files with their error.

    Raises
    ------
    TypeError
        `options` is not a :class:`RecoverOptions` (nor None), before anything else.
    """
    opts = _options(options, RecoverOptions, "recover_many")
    return _each_file(
        "recover", recover_file, opts, inputs, out_dir,
        client, scheduler, n_workers, force, show_progress,
    )  # fmt: skip


def smooth_many(
    inputs: Inputs,
    out_dir: PathLike,
    client: Client | None = None,
    *,
    options: SmoothOptions | None = None,
    scheduler: str | None = None,
    n_workers: int | None = None,
    force: bool = False,
    show_progress: bool | None = None,
) -> BatchSummary:
    """Link, fill and smooth every tracks file of `inputs` (files or folders of ``*.txt``).

    As :func:`track_many`, for tracks files instead of sequences.

    Parameters
    ----------
    inputs : path or sequence of paths
        MOTChallenge tracks files, or folders of ``*.txt`` (see
        :func:`~pftrack.batch.find_track_files`).
    out_dir : path
        Output folder (created if missing): ``NAME.txt`` for each ``NAME.txt`` of `inputs`,
        equal to ``pftrack smooth FILE`` with the same settings, its sidecar ``NAME.json`` and
        ``summary.json``.
    client : distributed.Client, optional
        Run on this client's cluster (left open). Default: `scheduler`, else a new
        ``LocalCluster`` with `n_workers` workers, closed at the end.
    options : SmoothOptions, optional
        The command's settings (default ``SmoothOptions()``).
    scheduler : str, optional
        Address of a running Dask scheduler (also read from ``DASK_SCHEDULER_ADDRESS``).
    n_workers : int, optional
        Workers of the local cluster (default: one per core this process may use); 0 runs in
        this process, one file after the other, without Dask.
    force : bool
        Redo files whose outputs are already complete.
    show_progress : bool, optional
        Progress bar over the files on stderr (default: when stderr is a terminal).

    Returns
    -------
    BatchSummary
        Per file: ids and rows in and out, holes left unfilled (longer than ``max_gap``);
        failed files with their error.

    Raises
    ------
    TypeError
        `options` is not a :class:`SmoothOptions` (nor None), before anything else.
    """
    opts = _options(options, SmoothOptions, "smooth_many")
    return _each_file(
        "smooth", smooth_file, opts, inputs, out_dir,
        client, scheduler, n_workers, force, show_progress,
    )  # fmt: skip


def _each_file(
    kind: str,
    task: Callable[[Path, Any], TaskResult],
    opts: RecoverOptions | SmoothOptions,
    inputs: Inputs,
    out_dir: PathLike,
    client: Client | None,
    scheduler: str | None,
    n_workers: int | None,
    force: bool,
    show_progress: bool | None,
) -> BatchSummary:
    """Run `task` with `opts` on every tracks file of `inputs`, one job each.

    The body of :func:`recover_many` (`kind` ``"recover"``) and :func:`smooth_many`
    (``"smooth"``), once their options are checked.
    """
    jobs = [Job(p.stem, task, (p, opts), (p,)) for p in find_track_files(inputs)]
    return run_jobs(
        jobs,
        out_dir,  # as given: run_jobs refuses an empty one (Path("") is ".")
        kind=kind,
        settings=opts.settings(),
        client=client,
        scheduler=scheduler,
        n_workers=n_workers,
        force=force,
        show_progress=show_progress,
    )
