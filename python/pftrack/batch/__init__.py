"""Many sequences at once on Dask distributed (``pftrack batch``, several-file recover/smooth).

``pftrack batch`` tracks many sequences, ``pftrack recover`` and ``pftrack smooth`` with several
files or a folder fill or smooth many tracks files, one Dask task each:

- :func:`track_many`, :func:`recover_many`, :func:`smooth_many` (:mod:`.api`): the entry points,
  returning a :class:`BatchSummary`;
- :func:`find_sequences`, :func:`find_track_files`, :class:`SequenceInput` (:mod:`.inputs`):
  what a batch runs on;
- :class:`TrackOptions`, :class:`RecoverOptions`, :class:`SmoothOptions` and the task
  functions (:mod:`.tasks`): the work of one task, free of Dask;
- :func:`dask_client`, :func:`run_jobs`, :func:`fingerprint` (:mod:`.engine`): the Dask layer,
  outputs and resume.

Dask itself is imported only when a cluster is used.
"""

from __future__ import annotations

from pftrack._lazy import lazy_exports
from pftrack.batch.api import recover_many, smooth_many, track_many
from pftrack.batch.engine import BatchSummary, Job, dask_client, fingerprint, run_jobs
from pftrack.batch.inputs import SequenceInput, find_sequences, find_track_files
from pftrack.batch.tasks import (
    RecoverOptions,
    SmoothOptions,
    TaskResult,
    TrackOptions,
    recover_file,
    sequence_metrics,
    smooth_file,
    track_sequence,
)

__all__ = [
    "BatchSummary",
    "Job",
    "RecoverOptions",
    "SequenceInput",
    "SmoothOptions",
    "TaskResult",
    "TrackOptions",
    "dask_client",
    "find_sequences",
    "fingerprint",
    "find_track_files",
    "recover_file",
    "recover_many",
    "run_jobs",
    "sequence_metrics",
    "smooth_file",
    "smooth_many",
    "track_many",
    "track_sequence",
]

# a public submodule loads on first use after a bare ``import pftrack`` (``pftrack.batch.x``)
_, __getattr__, __dir__ = lazy_exports(__name__, {}, globals())
