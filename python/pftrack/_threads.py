"""How many threads this process gives to work that can be split (C++ kernels, read-ahead).

A Dask worker of ``pftrack batch`` runs one task per core already: its plugin sets
:data:`WORKER_THREADS_VARIABLE` to ``"0"``, and everything here then stays on one thread.
"""

from __future__ import annotations

import os

__all__ = ["MAX_KERNEL_THREADS", "WORKER_THREADS_VARIABLE", "kernel_threads", "tracking_threads"]

#: Set to "0" by the worker plugin (:mod:`pftrack.batch._plugin`) in every Dask worker.
WORKER_THREADS_VARIABLE = "PFTRACK_TRACKING_THREADS"

#: Most threads a C++ kernel splits its work over: past a few, starting them costs more than
#: the pieces (a file's gaps, a grid's models) save.
MAX_KERNEL_THREADS = 4


def tracking_threads() -> bool:
    """Whether tracking here decodes and detects on threads ahead of the tracker.

    Yes in an ordinary process (``pftrack track``, ``pftrack batch --workers 0``); no in a
    Dask worker of a batch, which already has one task per core: the threads would only cost
    CPU there (the rows are the same either way).
    """
    return os.environ.get(WORKER_THREADS_VARIABLE, "1") != "0"


def kernel_threads() -> int:
    """Threads for a C++ kernel of independent pieces (the results do not depend on it).

    1 in a Dask worker of a batch (:func:`tracking_threads` is False); else the CPUs this
    process may run on, at most :data:`MAX_KERNEL_THREADS`.
    """
    if not tracking_threads():
        return 1
    try:
        cpus = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        cpus = os.cpu_count() or 1
    return max(1, min(cpus, MAX_KERNEL_THREADS))
