"""The Dask worker plugin of a batch (imports Dask: load it only when a cluster is used)."""

from __future__ import annotations

import atexit
import contextlib
import logging
import multiprocessing
import os
import signal
import sys
import threading
from collections.abc import Coroutine
from typing import Any

import cloudpickle  # type: ignore[import-untyped]  # distributed's; no type information
from distributed.diagnostics.plugin import WorkerPlugin

__all__ = ["SETUP_FAILED_TOPIC", "SingleThreaded"]

#: The Dask event topic on which a worker whose plugin setup fails (no pftrack to import) says
#: so, ``[worker address, "ModuleNotFoundError: ..."]``: a batch running listens to it. Such a
#: worker that joins mid-run dies on the first task it is given (Dask cannot unpickle it), too
#: soon for the batch's count of the workers to see it.
SETUP_FAILED_TOPIC = "pftrack-worker-setup-failed"

# The plugin goes to the workers by value, not by name: a worker that cannot import pftrack
# then fails in `setup` (logged, the worker runs on, and the batch names the problem:
# engine.check_pftrack) instead of failing to unpickle it, which leaves a worker that joins
# later stuck "closing" (Dask 2026.8), the batch waiting on it with no word of pftrack.
cloudpickle.register_pickle_by_value(sys.modules[__name__])


class SingleThreaded(WorkerPlugin):
    """Make each worker process single-threaded: one sequence per core, no oversubscription.

    Tracking in a worker uses no read-ahead or detector thread, and the C++ kernels one thread
    (:mod:`pftrack._threads`).

    No progress bar either: the worker's tasks draw none (:func:`pftrack._progress.set_quiet`).
    A local cluster's workers share the terminal, where the bars of the code a task calls
    (``auto: calibrating``, ``smoothing``) were drawn over the batch's own; a remote worker's
    go to its log.

    OpenCV gets ``cv2.setNumThreads(1)`` when the plugin is set up. BLAS and OpenMP read their
    thread counts when they load, so those come from the environment the worker starts with:
    Dask's nanny sets ``OMP_NUM_THREADS``, ``OPENBLAS_NUM_THREADS`` and ``MKL_NUM_THREADS`` to 1
    by default (``distributed.nanny.pre-spawn-environ``); the plugin sets them too, for the
    child processes a worker may start.

    Parameters
    ----------
    ignore_interrupt : bool
        For the local cluster of a run, whose workers share the terminal's process group, so
        that Ctrl-C reaches only the client, which cancels the tasks and closes the cluster
        (instead of every worker printing a traceback): ignore SIGINT in the worker (its
        process also starts with SIGINT blocked: :func:`pftrack.batch.dask_client`), and
        silence the worker's Dask logs once it closes (a heartbeat cut short by the close of
        its connections, a task cancelled in the middle: Dask logs either as an error).
    """

    idempotent = True
    name = "pftrack-single-threaded"

    def __init__(self, ignore_interrupt: bool = False) -> None:
        self.ignore_interrupt = ignore_interrupt

    def setup(self, worker: Any) -> Coroutine[Any, Any, None] | None:
        """Limit OpenCV to one thread in this worker process, and load the tasks' modules.

        Importing the tracker, the video reader and recovery costs about a quarter of a second
        of CPU: done here, while the cluster starts, rather than in the first task. Not the
        evaluation (:mod:`pftrack.eval`, SciPy's optimize: 0.33 s of CPU more in each worker,
        measured at stop 64), which only a sequence with ground truth needs: its task imports
        it.
        A failure is also sent to the scheduler as an event on :data:`SETUP_FAILED_TOPIC`
        (awaited: the worker's batched stream would send it too late), then raised (Dask logs
        it on the worker).
        """
        try:
            self._setup()
        except Exception as exc:  # noqa: BLE001 - raised again, once said
            return _said(worker, exc)
        return None

    def _setup(self) -> None:
        import cv2

        from pftrack._progress import set_quiet

        set_quiet(True)  # the batch's bar, on the client, is the only one
        cv2.setNumThreads(1)
        from pftrack._threads import WORKER_THREADS_VARIABLE, one_blas_thread

        one_blas_thread()

        os.environ[WORKER_THREADS_VARIABLE] = "0"  # no read-ahead, detector or kernel thread either
        import pftrack.io.video
        import pftrack.recovery
        import pftrack.tracking.run  # noqa: F401

        if self.ignore_interrupt and threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGINT, signal.SIG_IGN)

    def teardown(self, worker: Any) -> None:
        """The worker closes: from now on, its Dask logs are silent (local cluster only).

        And its process, once the worker has closed, ends without Python's own teardown
        (:func:`_exit_at_once`), in a process of its own only: not a worker inside this one.
        """
        if self.ignore_interrupt:
            logging.getLogger("distributed").setLevel(logging.CRITICAL + 1)
            if multiprocessing.parent_process() is not None:  # a nanny's worker process
                atexit.register(_exit_at_once)  # the last registered: the first to run


def _exit_at_once() -> None:
    """End a local cluster's worker process whose worker has closed: ``os._exit(0)``.

    Registered with :mod:`atexit` by :meth:`SingleThreaded.teardown`, after every other exit
    handler of the process, so it runs first. Its worker closed cleanly (its teardown ran):
    its tasks are over, its local directory removed (Dask's ``Server.close``), and a worker
    writes no file. What is left is the interpreter's teardown (the other exit handlers, every
    module and object freed one by one), which ``pftrack batch`` waited for: the close of a
    two-worker local cluster took 0.47-0.80 s with it and 0.04 s without, and each worker
    0.12-0.15 CPU-seconds more (3 runs alternated against main's install at load 10, stop 68,
    docs/batch.md). A ``forkserver``'s workers end so already (``os._exit`` after their
    target). Its logs and streams are flushed first.
    """
    logging.shutdown()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):  # a stream closed or gone: nothing to flush
            stream.flush()
    os._exit(0)


async def _said(worker: Any, exc: Exception) -> None:
    """Send `exc` (one line) on :data:`SETUP_FAILED_TOPIC` with `worker`'s address; raise it."""
    said = " ".join(f"{type(exc).__name__}: {exc}".split())
    try:
        await worker.scheduler.log_event(topic=SETUP_FAILED_TOPIC, msg=[str(worker.address), said])
    except Exception:  # noqa: BLE001, S110 - the setup's own error is the one raised
        pass
    raise exc
