"""How many threads this process gives to work that can be split (C++ kernels, read-ahead).

A Dask worker of ``pftrack batch`` runs one task per core already: its plugin sets
:data:`WORKER_THREADS_VARIABLE` to ``"0"``, and everything here then stays on one thread.
"""

from __future__ import annotations

import glob
import os
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager

__all__ = [
    "BLAS_THREAD_VARIABLES",
    "blas_on_one_thread",
    "MAX_KERNEL_THREADS",
    "WORKER_THREADS_VARIABLE",
    "join_through_interrupts",
    "kernel_threads",
    "one_blas_thread",
    "openblas_threads",
    "tracking_threads",
    "usable_cpus",
    "wait_through_interrupts",
]

#: Set to "0" by the worker plugin (:mod:`pftrack.batch._plugin`) in every Dask worker.
WORKER_THREADS_VARIABLE = "PFTRACK_TRACKING_THREADS"

#: Thread counts BLAS and OpenMP libraries read when they load (NumPy's OpenBLAS, MKL).
BLAS_THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")

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


def usable_cpus() -> int:
    """The CPUs this process may run on: its affinity (``taskset``, a container's cpuset).

    ``os.cpu_count()`` where the affinity cannot be read (not on Linux): it counts the
    machine's CPUs, more than a process limited to some of them may use.
    """
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def kernel_threads() -> int:
    """Threads for a C++ kernel of independent pieces (the results do not depend on it).

    1 in a Dask worker of a batch (:func:`tracking_threads` is False); else the CPUs this
    process may run on, at most :data:`MAX_KERNEL_THREADS`.
    """
    if not tracking_threads():
        return 1
    return min(usable_cpus(), MAX_KERNEL_THREADS)


def one_blas_thread() -> None:
    """Set :data:`BLAS_THREAD_VARIABLES` to 1 in this process, unless they are set already.

    For a process that is pftrack's own (the ``pftrack`` command, a batch worker): BLAS then
    starts no thread pool. pftrack's BLAS calls are small (a Kalman step, a trajectory's
    smoothing), and an idle pool's threads spin on the cores the tracker's own threads need:
    ``pftrack recover`` of a 500-track file took 0.78-0.84 s of user CPU with one thread
    against 0.87-0.99 s with the default two, ``pftrack experiment gaps`` on five sequences
    6.4-7.5 s against 8.1-8.2 s (3 December, 2 cores). It also keeps the ``gsi`` baseline's
    values (a Cholesky solve, whose sums a pool splits) from depending on the number of cores.
    BLAS reads the variables when NumPy loads: call this before anything imports it.
    """
    for name in BLAS_THREAD_VARIABLES:
        os.environ.setdefault(name, "1")


#: The (get, set) symbol pairs of the OpenBLAS NumPy's wheels carry (64-bit integers, and the
#: 32-bit one).
_OPENBLAS_SYMBOLS = (
    ("scipy_openblas_get_num_threads64_", "scipy_openblas_set_num_threads64_"),
    ("scipy_openblas_get_num_threads", "scipy_openblas_set_num_threads"),
)
#: OpenBLAS's (get, set) of its thread count in this process: None until first asked, then
#: the pair, or False where NumPy's BLAS is not an OpenBLAS found by :func:`openblas_threads`.
_OPENBLAS: tuple[Callable[[], int], Callable[[int], object]] | bool | None = None
#: Held while the count is lowered (one setting a process: two threads lowering it at once
#: would restore each other's count, and run at the pool's).
_BLAS_LOCK = threading.Lock()


@contextmanager
def blas_on_one_thread() -> Iterator[None]:
    """Run the block's BLAS calls on one thread: :func:`one_blas_thread` once NumPy is loaded.

    With NumPy's BLAS the OpenBLAS of NumPy's wheels at more than one thread, its count is set
    to 1 for the block and set back after it, under a lock; the block's products are then one
    thread's, the bits of a process started with ``OPENBLAS_NUM_THREADS=1``. The count is the
    process's: a BLAS call of another thread inside the block runs on one thread too. Any other
    BLAS (MKL, Accelerate, a system OpenBLAS), or a count of 1 already: the block as it is.
    For short blocks (a product of a frame), not for long work.
    """
    blas = openblas_threads()
    if not isinstance(blas, tuple):
        yield
        return
    get, put = blas
    with _BLAS_LOCK:
        before = get()
        if before <= 1:
            yield
            return
        put(1)
        try:
            yield
        finally:
            put(before)


def openblas_threads() -> tuple[Callable[[], int], Callable[[int], object]] | bool:
    """OpenBLAS's get and set of its thread count in NumPy's BLAS (False: none found).

    The library is the one NumPy's wheels carry beside it (``numpy.libs``, ``numpy/.dylibs``),
    opened by ``ctypes`` only if it is loaded already (the copy NumPy calls; OpenCV's wheels
    carry another, whose count is not NumPy's); the pair is its ``get_num_threads`` and
    ``set_num_threads``, looked up once a process.
    """
    global _OPENBLAS
    if _OPENBLAS is None:
        _OPENBLAS = _find_openblas() or False
    return _OPENBLAS


def _find_openblas() -> tuple[Callable[[], int], Callable[[int], object]] | None:
    """:func:`openblas_threads`' pair, looked up; None for a NumPy on another BLAS."""
    import ctypes  # here: the command imports this module at its start, for one_blas_thread

    import numpy as np  # (before NumPy loads)

    noload = getattr(os, "RTLD_NOLOAD", 0) | ctypes.RTLD_LOCAL  # open only if loaded already

    root = os.path.dirname(os.path.dirname(os.path.abspath(np.__file__)))
    paths = [
        path
        for pattern in ("numpy.libs/*openblas*", "numpy/.dylibs/*openblas*")
        for path in sorted(glob.glob(os.path.join(root, pattern)))
    ]
    for path in paths:
        try:
            lib = ctypes.CDLL(path, mode=noload)
        except OSError:
            continue
        for get_name, set_name in _OPENBLAS_SYMBOLS:
            get, put = getattr(lib, get_name, None), getattr(lib, set_name, None)
            if get is not None and put is not None:
                get.restype, get.argtypes = ctypes.c_int, []
                put.restype, put.argtypes = None, [ctypes.c_int]
                return get, put
    return None


def join_through_interrupts(thread: threading.Thread, finished: threading.Event) -> None:
    """Wait for `thread`, which sets `finished` as its last act, through Ctrl-C; raise it after.

    A ``KeyboardInterrupt`` raised inside the wait (a second Ctrl-C while the first one's
    cleanup stops the threads; SIGTERM, which ``pftrack`` raises as one) left `thread`
    running. A daemon thread still inside C++ as the process exits (OpenCV's decoder, a
    pftrack kernel) is ended by a forced unwind when it takes the GIL back, and the process
    aborted: ``pftrack track`` of PETS09-S2L1 Ctrl-C'd twice 3-60 ms apart died of SIGABRT
    ("terminate called without an active exception") in 4 runs of 46.

    The wait is on `finished`, not on ``thread.join()``: a join cut short by an interrupt
    marks a thread that still runs as stopped (CPython 3.11 releases its state lock in the
    handler), so a second join returns at once. The wait lasts as long as `thread` takes to
    see its stop (a frame's decoding, at the caller's site).
    """
    try:
        wait_through_interrupts(finished)
    finally:
        thread.join()  # past its work: a moment


def wait_through_interrupts(finished: threading.Event) -> None:
    """``finished.wait()``, waited out through Ctrl-C; the first interrupt raised after it.

    For work on another thread that must not be left running when the process exits
    (:func:`join_through_interrupts`); `finished` is set as that work's last act.
    """
    caught: KeyboardInterrupt | None = None
    while True:
        try:
            finished.wait()
        except KeyboardInterrupt as exc:  # the work still runs: wait again
            caught = caught or exc
            continue
        break
    if caught is not None:
        raise caught
