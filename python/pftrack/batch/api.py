"""The batch entry points: :func:`track_many`, :func:`recover_many`, :func:`smooth_many`."""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING

from pftrack._typing import PathLike
from pftrack.batch.engine import BatchSummary, Job, run_jobs
from pftrack.batch.inputs import Inputs, find_sequences, find_track_files
from pftrack.batch.tasks import (
    RecoverOptions,
    SmoothOptions,
    TrackOptions,
    recover_file,
    sequence_length,
    smooth_file,
    track_sequence,
)
from pftrack.io.video import source_files

if TYPE_CHECKING:
    from distributed import Client

__all__ = ["recover_many", "smooth_many", "track_many"]


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
        Workers of the local cluster (default: one per core); 0 runs in this process, one
        sequence after the other, without Dask.
    force : bool
        Redo sequences whose outputs are already complete.
    show_progress : bool, optional
        Progress bar on stderr (default: when stderr is a terminal): the frames tracked over
        all the sequences, with the time left where every sequence's length is known (a
        video's header, an image folder; else the count and rate), and the sequences done.
        The tasks report their frames as they go, from Dask workers too (as Dask events,
        twice a second at most).

    Returns
    -------
    BatchSummary
        Frames, tracks, frames/s and metrics (where ``gt/gt.txt`` exists) per sequence; failed
        sequences with their error.
    """
    opts = options if options is not None else TrackOptions()
    seqs = find_sequences(inputs)
    jobs = [
        Job(
            s.name,
            track_sequence,
            (s, opts),
            s.files,
            functools.partial(sequence_length, s),
            guards=tuple(source_files(s.frames)),  # every image read, seqinfo.ini
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

    As :func:`track_many`; each ``out_dir/NAME.txt`` equals ``pftrack recover FILE`` with the
    same settings.
    """
    opts = options if options is not None else RecoverOptions()
    jobs = [Job(p.stem, recover_file, (p, opts), (p,)) for p in find_track_files(inputs)]
    return run_jobs(
        jobs,
        out_dir,  # as given: run_jobs refuses an empty one (Path("") is ".")
        kind="recover",
        settings=opts.settings(),
        client=client,
        scheduler=scheduler,
        n_workers=n_workers,
        force=force,
        show_progress=show_progress,
    )


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

    As :func:`track_many`; each ``out_dir/NAME.txt`` equals ``pftrack smooth FILE`` with the
    same settings.
    """
    opts = options if options is not None else SmoothOptions()
    jobs = [Job(p.stem, smooth_file, (p, opts), (p,)) for p in find_track_files(inputs)]
    return run_jobs(
        jobs,
        out_dir,  # as given: run_jobs refuses an empty one (Path("") is ".")
        kind="smooth",
        settings=opts.settings(),
        client=client,
        scheduler=scheduler,
        n_workers=n_workers,
        force=force,
        show_progress=show_progress,
    )
