"""Run many tasks on Dask distributed; write their outputs on the client; resume; summarise.

One task per sequence (or tracks file). The client submits every task that is not already
complete, writes each result as it arrives (``DIR/NAME.txt``, extra files, then the sidecar
``DIR/NAME.json``, each atomically), and writes ``DIR/summary.json`` at the end.

*Complete* means: the sidecar exists, names the same inputs and settings, records the same
fingerprint of each input (:func:`fingerprint`: size and modification time; for an image folder,
those of every image by name), and every output it lists is still the file it wrote (the same
size and SHA-256: :func:`output_print`). The sidecar is first replaced
by one that says ``writing``, then written last, and every file atomically, so a run stopped at
any point leaves each output either complete or not; a re-run skips the complete ones.

Where the tasks run (a scheduler to connect to, or a local cluster to start) is settled before
``DIR`` is created or any file written: a scheduler that cannot be reached changes nothing.
"""

from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import hashlib
import json
import logging
import math
import numbers
import os
import signal
import socket
import stat
import threading
import time
import traceback
import warnings
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

from pftrack._check import brief, flag, path_arg, shown
from pftrack._interrupt import raise_if_interrupted, written_anyway
from pftrack._progress import Bar, enabled, progress, quiet, set_quiet
from pftrack._text import counted, listed, listed_compactly, said_alike
from pftrack._threads import usable_cpus
from pftrack._warn import warn
from pftrack.batch.inputs import cannot_read
from pftrack.batch.tasks import TaskCancelled, TaskResult, one_line, reporting_frames
from pftrack.io.atomic import (
    atomic_write,
    check_output,
    check_output_folder,
    interrupts_deferred,
    link_loop,
    replaceable,
    staged_outputs,
)
from pftrack.io.mot import write_mot
from pftrack.io.video import IMAGE_SUFFIXES

if TYPE_CHECKING:
    from distributed import Client, LocalCluster

__all__ = [
    "BatchSummary",
    "Job",
    "check_pftrack",
    "check_scheduler_address",
    "dask_client",
    "fingerprint",
    "output_print",
    "run_jobs",
]

SUMMARY_NAME = "summary.json"

#: Dask starts workers with MALLOC_TRIM_THRESHOLD_=65536, which turns off glibc's adaptive mmap
#: threshold: every frame-sized array is then mmap'ed and unmapped again (11x the page faults,
#: ~1.5x the CPU time per sequence, measured on a 480x360 video). Unset for the local cluster.
NO_MALLOC_TRIM = "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_"
#: The workers' statistical profiler samples every thread 100 times a second, for a dashboard
#: the local cluster does not have: ~10 % of a worker's CPU time (noisy). Off for the local cluster.
NO_PROFILER = "distributed.worker.profile.enabled"
#: Dask's periodic loops, slowed for the local cluster (its scheduler, nannies and client run
#: in this process): the event loops' tick (every 20 ms, only to warn of a blocked loop), the
#: memory monitors (every 100 ms, each worker's and each nanny's: the memory limits are then
#: looked at once a second) and the system monitor (every 500 ms, a dashboard's figures). A
#: worker's event loop woke 50 times a second to take the GIL from its task. Measured on a
#: warm two-worker cluster, 10 s with nothing to run, 2 runs each at load 13-15: this process
#: 34-36 ms of CPU a second and each worker 19-22 ms with Dask's defaults, 9-10 and 4 ms with
#: these (docs/batch.md, stop 64).
SLOWER_LOOPS = {
    "distributed.admin.tick.interval": "1s",
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.admin.system-monitor.interval": "5s",
}


@dataclass(frozen=True)
class Job:
    """One task of a batch.

    Attributes
    ----------
    name : str
        Output name: ``DIR/NAME.txt`` and the sidecar ``DIR/NAME.json``.
    func : callable
        A module-level function (Dask pickles it by name) returning a :class:`TaskResult`.
    args : tuple
        Its arguments (picklable).
    reads : tuple of Path
        Files and folders the task reads (outputs may not be one of them).
    count : callable, optional
        For the progress bar: returns how many frames the task will report (through
        :func:`~pftrack.batch.tasks.reporting_frames`), None if unknown; 0 for an input that
        cannot be read (the task will fail without a frame: the bar says so and keeps the
        others' total). Called on the client before the tasks run, and only when a bar is
        drawn.
    guards : tuple of Path
        The files inside `reads` the task reads too, which outputs may not be either (the
        images of a folder); not fingerprinted.
    refused : str, optional
        Why the task is certain to fail, known on the client (``--detections auto`` for a
        sequence without ``det/det.txt``): it is not sent to the cluster, nor run, but
        reported failed with this error (its entry says ``"refused": true``), while the
        others run. Was: sent as a task, which failed on its worker.
    """

    name: str
    func: Callable[..., TaskResult]
    args: tuple[Any, ...]
    reads: tuple[Path, ...]
    count: Callable[[], int | None] | None = None
    guards: tuple[Path, ...] = ()
    refused: str | None = None


@dataclass
class BatchSummary:
    """What a batch did: one entry per task, in input order.

    Attributes
    ----------
    kind : str
        ``"track"``, ``"recover"`` or ``"smooth"``.
    out_dir : Path
        The output folder.
    entries : list of dict
        Per task: ``name``, ``status`` (``"done"``, ``"skipped"``: complete from an earlier run,
        ``"failed"``, ``"cancelled"``), ``error`` (one line, failed only), ``note`` (why a task
        complete from an earlier run was redone: ``"redone: PATH changed since the last run"``,
        ``"redone: its output PATH changed since the last run wrote it (...)"``),
        and the task's figures (``frames``, ``tracks``, ``fps``, ``metrics`` ... for tracking).
    seconds : float
        Wall time of the batch (cluster start included).
    workers : int
        Workers that ran its tasks, those that joined mid-run included; 0 in this process,
        and with a `scheduler` where no task came back from any worker (all lost, or an
        interrupt first: was the count at the start, which the table then gave as the workers
        the batch ran on).
    scheduler : str or None
        Address of the Dask scheduler, as given (``--scheduler``, ``DASK_SCHEDULER_ADDRESS``),
        else as Dask reports it (None: in this process).
    settings : dict
        The settings every task ran with.
    unwritten : str or None
        Why ``out_dir/summary.json`` could not be written at the end (a full disk, a folder
        made read-only meanwhile, the folder removed: then the outputs lost with it are named),
        else None: the tasks' outputs written stay, and this is the run's only record
        (``pftrack`` prints its table and exits with status 1).
    """

    kind: str
    out_dir: Path
    entries: list[dict[str, Any]] = field(default_factory=list)
    seconds: float = 0.0
    workers: int = 0
    scheduler: str | None = None
    settings: dict[str, Any] = field(default_factory=dict)
    unwritten: str | None = None

    @property
    def failed(self) -> list[dict[str, Any]]:
        """Entries of the tasks that failed."""
        return [e for e in self.entries if e["status"] == "failed"]

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready dict (NaN and infinities become None)."""
        counts = {s: sum(e["status"] == s for e in self.entries) for s in _STATUSES}
        out: dict[str, Any] = _clean(
            {
                "kind": self.kind,
                "out_dir": str(self.out_dir),
                "seconds": self.seconds,
                "workers": self.workers,
                "scheduler": self.scheduler,
                "counts": counts,
                "settings": self.settings,
                "sequences" if self.kind == "track" else "files": self.entries,
            }
        )
        return out

    def to_json(self) -> str:
        """JSON text of :meth:`as_dict`."""
        return json.dumps(self.as_dict(), indent=2)

    def __str__(self) -> str:
        """:meth:`table`, what ``print(summary)`` shows (``repr``: every field)."""
        return self.table()

    def table(self, problems: bool = True) -> str:
        """A text table: one line per task, then the totals, the notes and the problems.

        Parameters
        ----------
        problems : bool
            End with :meth:`problems`' lines (each task's warnings and errors); ``pftrack``
            prints the table without them on stdout, and them on stderr.
        """
        cols = _COLUMNS[self.kind]
        head = ["name", "status"] + [c for c, _, _ in cols]
        lines = [head]
        for e in self.entries:
            line = [e["name"], e["status"]]
            for _, key, fmt in cols:
                value = _lookup(e, key)
                line.append("-" if value is None else fmt(value))
            lines.append(line)
        widths = [max(len(r[i]) for r in lines) for i in range(len(head))]
        text = [
            "  ".join(
                c.ljust(w) if i < 2 else c.rjust(w)
                for i, (c, w) in enumerate(zip(r, widths, strict=True))
            )
            for r in lines
        ]
        counts = ", ".join(
            f"{n} {s}" for s in _STATUSES if (n := sum(e["status"] == s for e in self.entries))
        )
        where = counted(self.workers, "worker") if self.workers else "in this process"
        if not self.workers and all(
            e["status"] == "skipped" or e.get("refused") for e in self.entries
        ):  # no cluster is started or asked for skipped inputs, nor for those refused
            where = "nothing to run"
        elif not self.workers and self.scheduler:  # the workers lost before any task came back
            where = f"no worker at {self.scheduler} finished a task"
        if self.scheduler and self.workers:
            where += f" at {self.scheduler}"
        noun = "sequence" if self.kind == "track" else "file"
        text.append(f"{counted(len(self.entries), noun)}: {counts}; {self.seconds:.1f} s, {where}")
        for e in self.entries:
            if e.get("note"):
                text.append(f"{e['name']}: {e['note']}")
            if e.get("long_holes"):  # recover, smooth: holes longer than --max-gap
                from pftrack.recovery.fill import unfilled_note

                note = unfilled_note(e["long_holes"], e["longest_hole"], self.settings["max_gap"])
                text.append(f"{e['name']}: {note}")
            if e.get("jump_holes"):  # recover, smooth: two objects under one id, as one file
                from pftrack.recovery.fill import jump_note

                note = jump_note(e["jump_holes"], e.get("largest_jump", 0.0))
                text.append(f"{e['name']}: {note}")
        if problems:
            text.extend(self.problems())
        return "\n".join(text)

    def problems(self, unwritten: bool = True, warned: bool = True) -> list[str]:
        """The tasks' warnings (``NAME: warning: ...``), then errors (``NAME: error: ...``).

        `warned` False: the errors alone (the warnings said as they arrived,
        :func:`warnings_as_they_come`, and a skipped task's before the table).

        An error that several tasks failed with is said once, with their count and names (runs
        of numbered names as ``first..last``, four items, then ``...``): ``29 sequences
        (cam01..cam29): error: ...``; so are errors that differ only where each names its own
        task, said with ``NAME`` there (``12 sequences (cam01..cam12): error: --detections auto:
        sequence NAME has no det/det.txt (nor det.txt)``). Warnings likewise (``40 sequences
        (cam01..cam40): warning: ...``; was: one line each). Each entry keeps its own.

        Last, ``error: DIR/summary.json not written (...)`` if it could not be (and
        `unwritten`: an interrupted batch's last line says it instead).
        """
        noun = "sequence" if self.kind == "track" else "file"
        raised = [(e["name"], w) for e in self.entries if warned for w in e.get("warnings", ())]
        # one error said once, where several tasks failed with it (was: once per task, 29
        # identical lines for 29 sequences on a cluster that had lost its workers, a trial),
        # or with the same words but their own names (was: one line each); warnings too
        text = said_once(raised, noun, "warning")
        text += said_once([(e["name"], e["error"]) for e in self.failed], noun, "error")
        text += said_once(
            [(e["name"], kept_note(e["kept"], self.out_dir)) for e in self.failed if e.get("kept")],
            noun,
            "warning",
        )
        if self.unwritten and unwritten:
            text.append(f"error: {self.unwritten}")
        return text


def kept_note(kept: Sequence[str], out_dir: Path) -> str:
    """What a failed task's outputs of an earlier run, left as they were in `out_dir`, are.

    A re-run whose task fails writes none of its outputs, and those an earlier run wrote stay
    (outputs are replaced whole or not at all); but beside the others' new outputs they look
    like this run's, and ``pftrack recover`` or ``pftrack eval`` of the folder reads them as
    such (a user trial: a sequence whose images changed, re-run and failed, kept its tracks of
    the old images, said only by the table's ``failed``).
    """
    files = " and ".join([", ".join(kept[:-1]), kept[-1]] if len(kept) > 1 else kept)
    are, they, were = ("are", "they", "were") if len(kept) > 1 else ("is", "it", "was")
    return (
        f"{files} in {out_dir} {are} an earlier run's, left as {they} {were}: not this run's "
        "(it failed), nor, if its inputs or settings changed since, theirs; move "
        f"{'them' if len(kept) > 1 else 'it'} away before reading the folder's results "
        "(pftrack recover, eval)"
    )


def _stat_of(path: Path) -> tuple[int, int, int, int] | None:
    """``(st_dev, st_ino, st_size, st_mtime_ns)`` of a regular file `path`, else None."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns) if stat.S_ISREG(st.st_mode) else None


def _outputs_there(
    out_dir: Path, name: str, suffixes: Sequence[str]
) -> dict[str, tuple[int, int, int, int]]:
    """The outputs of task `name` in `out_dir` before the run, by name: what may stay of them.

    Compared with the same files when the task fails (:func:`_stat_of`): those unchanged are
    an earlier run's (an output this run replaced is a new file: another inode).
    """
    there = {}
    for file in (f"{name}{s}" for s in (".txt", ".json", *suffixes)):
        was = _stat_of(out_dir / file)
        if was is not None:
            there[file] = was
    return there


def said_once(messages: list[tuple[str, str]], noun: str, level: str) -> list[str]:
    """``NAME: LEVEL: message`` lines for ``(name, message)`` pairs, alike messages said once.

    Messages in the same words, or that differ only where each names its own task, are one
    line (:func:`pftrack._text.said_alike`), said for their count and names:
    ``3 sequences (cam01..cam03): warning: ...``. `noun` names a task (``sequence``,
    ``file``); `level` is ``warning`` or ``error``. A task that says a message twice is
    named once.
    """
    lines = []
    for message, said_by in said_alike(messages):
        names = list(dict.fromkeys(said_by))
        who = (
            names[0]
            if len(names) == 1
            else f"{counted(len(names), noun)} ({listed_compactly(names)})"
        )
        lines.append(f"{who}: {level}: {message}")
    return lines


_STATUSES = ("done", "skipped", "failed", "cancelled")


def _pct(v: float) -> str:
    return f"{100.0 * v:.1f}"


def _int(v: float) -> str:
    return str(int(v))


# Columns of the table per kind: (header, key in the entry ("a.b" looks in a dict), format).
_COLUMNS: dict[str, list[tuple[str, str, Callable[[Any], str]]]] = {
    "track": [
        ("frames", "frames", _int),
        ("tracks", "tracks", _int),
        ("frames/s", "fps", lambda v: f"{v:.0f}"),
        ("HOTA%", "metrics.hota", _pct),
        ("MOTA%", "metrics.mota", _pct),
        ("IDF1%", "metrics.idf1", _pct),
        ("IDsw", "metrics.num_switches", _int),
    ],
    "recover": [
        ("rows in", "rows_in", _int),
        ("linked", "fragments_linked", _int),
        ("gaps", "gaps", _int),
        ("filled", "filled_rows", _int),
        ("ms", "seconds", lambda v: f"{1e3 * v:.1f}"),
    ],
    "smooth": [
        ("ids in", "ids_in", _int),
        ("rows in", "rows_in", _int),
        ("ids out", "ids_out", _int),
        ("rows out", "rows_out", _int),
        ("ms", "seconds", lambda v: f"{1e3 * v:.1f}"),
    ],
}


def _lookup(entry: dict[str, Any], key: str) -> Any:
    value: Any = entry
    for part in key.split("."):
        value = value.get(part) if isinstance(value, dict) else None
    return value


def _clean(value: Any) -> Any:
    """JSON-ready copy: NaN and infinities -> None, tuples -> lists."""
    if isinstance(value, dict):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _require_dask() -> None:
    """Import Dask distributed, or raise an ImportError that says how to install it."""
    try:
        import dask  # noqa: F401
        import distributed  # noqa: F401
    except ImportError as exc:  # only without the extra
        raise ImportError(
            f"batches run on Dask, which cannot be imported ({exc}): pip install "
            "'pftrack[dask]' (dask[distributed])",
            name=exc.name,
        ) from exc


@contextlib.contextmanager
def dask_client(
    client: Client | None = None, scheduler: str | None = None, n_workers: int | None = None
) -> Iterator[Client]:
    """A Dask client for a batch; whatever this starts, it closes.

    Parameters
    ----------
    client : distributed.Client, optional
        Use this client (left open).
    scheduler : str, optional
        Address of a running scheduler (``tcp://HOST:8786``), checked first
        (:func:`check_scheduler_address`).
    n_workers : int, optional
        Workers of a new ``LocalCluster``, each a process with one thread. Given, a local
        cluster is started even where Dask's ``scheduler-address`` setting
        (``DASK_SCHEDULER_ADDRESS``) names a scheduler. Default: that setting's scheduler,
        else a local cluster of one worker per core this process may use.

    Raises
    ------
    TypeError
        `client` is not a ``distributed.Client`` (an address goes in `scheduler`).
    ValueError
        A malformed or empty address; `client`, `scheduler` and `n_workers` that contradict
        each other (more than one given, or ``n_workers`` < 1); Dask's connect timeout or
        no-workers timeout that is not a duration (:func:`dask_seconds`); for a local
        cluster, a worker memory threshold that is no fraction (:func:`dask_fraction`).
    OSError
        The scheduler cannot be reached within Dask's ``distributed.comm.timeouts.connect``
        (30 s by default; ``DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT``), or Dask cannot
        connect by the address's protocol here (``tls://`` without Dask's TLS settings,
        ``ucx://`` without the package that provides it): one line naming the address (was:
        Dask's own message, "TLS expects a `ssl_context` argument", "Can't instantiate abstract
        class UCXConnector", naming neither). An address that is an HTTP server's (the
        dashboard's) or a Dask worker's is said to be one, with the scheduler's address where
        it tells it (:func:`_http_server`, :func:`_dask_server`).
        A local cluster that cannot start (Dask's temporary folder not writable, say): one
        line, Dask's cause.
    ImportError
        The scheduler or the workers cannot import pftrack (:func:`check_pftrack`).
    """
    _require_dask()
    import dask

    from pftrack.batch._plugin import SingleThreaded

    address = where_to_run(client, scheduler, n_workers)
    if n_workers is not None and n_workers < 1:
        raise ValueError(f"n_workers is {n_workers}, expected >= 1 for a cluster")
    # the waits this reads, and a local cluster's scheduler too: checked before any is used
    dask_seconds("distributed.comm.timeouts.connect", "30s")
    no_workers_timeout()
    if client is not None:
        check_pftrack(client, _address_of(client))
        _register(client, SingleThreaded(), _address_of(client))
        yield client
        return
    if address:
        named = address if scheduler is not None else _from_setting(address)
        refused = _refused(address)  # known at once: Dask would retry for its whole timeout
        if refused is not None:
            raise OSError(f"cannot connect to the Dask scheduler at {named}: {refused}")
        quiet = contextlib.ExitStack()
        try:
            connected = _new_client(address)  # timeout: distributed.comm.timeouts.connect
        except Exception as exc:  # noqa: BLE001 - whatever Dask raised: one line, the address
            # a Dask server that is no scheduler answers, then refuses the client's request (a
            # worker: a TypeError); one not reached at all (an OSError) is not asked again
            other = None if isinstance(exc, OSError) else _dask_server(address)
            problem = other or _connect_problem(address, exc)
            raise OSError(f"cannot connect to the Dask scheduler at {named}: {problem}") from None
        with quiet, connected as c:  # `quiet` ends after the client is closed
            check_pftrack(c, address)
            _register(c, SingleThreaded(), address)
            try:
                yield c
            finally:
                if c.status != "running":  # the scheduler went away: its end said by the batch
                    quiet.enter_context(_silenced(*_CLIENT_LOGGERS))
        return
    for key in MEMORY_FRACTIONS:  # read by the local workers as they start
        dask_fraction(key)
    n = n_workers if n_workers is not None else usable_cpus()
    stack = contextlib.ExitStack()
    try:
        # the cluster starts whole; its workers deaf to Ctrl-C, SIGTERM, and not running the
        # caller's script again: nor those its nannies start again later, for one that died
        # (the script is left out until the cluster is closed)
        with _interrupts_held():
            stack.enter_context(_main_left_out())
            stack.enter_context(
                dask.config.set({NO_MALLOC_TRIM: None, NO_PROFILER: False, **SLOWER_LOOPS})
            )
            try:
                cluster = stack.enter_context(
                    _new_cluster(
                        n_workers=n,
                        threads_per_worker=1,
                        processes=True,
                        host="127.0.0.1",
                        silence_logs=logging.ERROR,  # not the workers' warnings on cancelled tasks
                        dashboard_address=None,  # no dashboard; its HTTP routes on a free port,
                        scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},  # not 8787
                    )
                )
                c = stack.enter_context(_new_client(cluster))
                c.register_plugin(SingleThreaded(ignore_interrupt=True))
            except Exception as exc:  # noqa: BLE001 - whatever stopped Dask: one line
                # was: Dask's traceback, "RuntimeError: Cluster failed to start: ..." (its
                # temporary folder under a file, say); the cause says what failed
                cause = exc.__cause__ if isinstance(exc.__cause__, Exception) else exc
                workers = counted(n, "worker")
                raise OSError(
                    f"cannot start a local Dask cluster of {workers}: {one_line(cause)}"
                ) from None
        # a Ctrl-C (or SIGTERM) held while the cluster started is raised on leaving
        # _interrupts_held: the stack then closes the client and the whole cluster
        yield c
    finally:
        # and it closes whole too: a Ctrl-C in the middle (a second one, after the batch's
        # own, or one as a finished batch closes) left it half closed, for Dask's exit hook
        # to wait up to 10 s on and print a traceback when interrupted again; it is raised
        # once the cluster is closed
        with _interrupts_held():
            stack.close()


def _new_client(target: Any) -> Client:
    """``distributed.Client(target)``: one whose start fails is closed here, not left to the GC.

    Dask's constructor leaves the client it made behind when the connection fails with
    anything but an ``OSError`` or ``ImportError`` (a worker's port: a ``TypeError``; a
    protocol it cannot speak; Ctrl-C while it connects): connecting, the process's default
    client, its event loop's thread running; and with an ``OSError`` closed, but that thread
    running still. The garbage collector closed it later, wherever it ran: inside the start of
    a later local cluster in the same thread (Dask's ``LoopRunner`` lock held), its close then
    waited on that lock for ever (a hang of the tests; py-spy: ``LoopRunner.start`` ... ``gc``
    ... ``Client.__del__``, ``Client.close``, ``LoopRunner.stop``). So the client is made in two
    steps, to hold it when its ``__init__`` raises.

    `target`: a scheduler's address, or a cluster.
    """
    from distributed import Client

    c = Client.__new__(Client)
    try:
        Client.__init__(c, target)
    except BaseException:
        with _interrupts_held(spawns=False):  # a Ctrl-C meanwhile: raised once closed
            _close_failed(c)
        raise
    return c


def _new_cluster(**kwargs: Any) -> LocalCluster:
    """``distributed.LocalCluster(**kwargs)``: one whose start fails leaves nothing running.

    Dask's constructor, when the scheduler fails to start (Dask's temporary folder under a
    file, say), closes the cluster but leaves its event loop's thread running, with the loop's
    sockets, and the half-made scheduler's HTTP server listening (its port open until the
    garbage collector closes it, with a ``ResourceWarning``, "unclosed socket"). So the cluster
    is made in two steps, as :func:`_new_client` makes a client, to close what it started when
    its ``__init__`` raises; the half-made servers are those of the frames the exception went
    through (Dask keeps no other reference to them).
    """
    from distributed import LocalCluster

    cluster = LocalCluster.__new__(LocalCluster)
    try:
        LocalCluster.__init__(cluster, **kwargs)
    except BaseException as exc:
        with _interrupts_held(spawns=False):  # a Ctrl-C meanwhile: raised once closed
            _close_failed(cluster)
            _stop_half_made(exc)
        raise
    return cluster


def _stop_half_made(exc: BaseException) -> None:
    """Stop the HTTP servers of the Dask servers whose ``__init__`` `exc` (or its causes) left.

    Dask internals: a ``Scheduler`` (a ``Worker``, a ``Nanny``) starts its HTTP server
    (``http_server``, Tornado's) early in its ``__init__``; one that raises after it is found
    as ``self`` in a frame of the traceback. ``stop`` does nothing to a server stopped already.
    """
    from distributed.core import Server

    seen: set[int] = set()
    chained: BaseException | None = exc
    while chained is not None and id(chained) not in seen:
        seen.add(id(chained))
        tb = chained.__traceback__
        while tb is not None:
            server = tb.tb_frame.f_locals.get("self")
            http = getattr(server, "http_server", None) if isinstance(server, Server) else None
            if http is not None:
                with contextlib.suppress(Exception):
                    http.stop()
            tb = tb.tb_next
        chained = chained.__cause__ or chained.__context__


def _close_failed(c: Client | LocalCluster) -> None:
    """Close a Dask client or cluster whose start failed, and stop its event loop's thread.

    Dask internals: ``close`` may refuse (nothing started, or closed already: it then leaves
    the thread running), and the ``LoopRunner`` that runs the thread (``_loop_runner``) is
    stopped whatever it did; its ``stop`` does nothing when it is stopped already.
    """
    with contextlib.suppress(Exception):  # half made: what it lacks, Dask may trip on
        c.close()
    runner = getattr(c, "_loop_runner", None)
    if runner is not None:
        with contextlib.suppress(Exception):
            runner.stop()


#: Dask's settings of a TLS client (``tls://``, ``wss://``), as environment variables.
TLS_SETTINGS = (
    "$DASK_DISTRIBUTED__COMM__TLS__CA_FILE, $DASK_DISTRIBUTED__COMM__TLS__CLIENT__CERT and "
    "$DASK_DISTRIBUTED__COMM__TLS__CLIENT__KEY"
)


#: The port ``dask scheduler`` listens on without ``--port``.
DASK_PORT = 8786
#: Seconds a refused connection is tried again before :func:`dask_client` gives up (a
#: scheduler started a moment before the batch may not listen yet).
REFUSED_GRACE = 2.0


def _refused(address: str) -> str | None:
    """Why nothing can listen at the tcp:// `address`, if that is known at once.

    A host name that does not resolve, or a port that refuses the connection for
    :data:`REFUSED_GRACE` seconds; None otherwise (Dask's own connection, with its timeout,
    decides: a firewall that drops packets, a scheduler that is slow to answer). Was: 30 s,
    then "Timed out trying to connect".
    """
    from distributed.comm.addressing import parse_address, parse_host_port

    try:
        protocol, location = parse_address(address)
        if protocol != "tcp":  # tls: Dask's message says more (its settings, a handshake)
            return None
        host, port = parse_host_port(location)
    except (ValueError, TypeError):
        return None
    deadline = time.monotonic() + REFUSED_GRACE
    while True:
        try:
            with socket.create_connection((host, port), timeout=REFUSED_GRACE) as sock:
                return _silent(sock, host, port, address)
        except socket.gaierror:
            return f"host {host} not found (its name does not resolve)"
        except ConnectionRefusedError:
            if time.monotonic() < deadline:
                time.sleep(0.2)
                continue
            # Dask's own port needs no option; another one does (was: `dask scheduler` for
            # every port, which then listened on 8786, not where the batch looked)
            start = "dask scheduler" + ("" if port == DASK_PORT else f" --port {port}")
            return (
                f"connection refused: nothing listens on port {port} of {host} (start the "
                f"scheduler there first: {start})"
            )
        except OSError:
            return None


#: Seconds a tcp:// scheduler has to greet a new connection; None: Dask's connect timeout
#: (``distributed.comm.timeouts.connect``, 30 s by default). A Dask server speaks first (its
#: handshake, in milliseconds); a service that accepted the connection and says nothing (the
#: dashboard's port, an HTTP server) held ``Client(address)`` for ever (a user trial: Dask's
#: connect timeout does not cover the handshake).
GREETING_WAIT: float | None = None


def _greeting_wait() -> float:
    if GREETING_WAIT is not None:
        return GREETING_WAIT
    wait = dask_seconds("distributed.comm.timeouts.connect", "30s")
    return wait if wait else 30.0


#: Seconds of silence after which :func:`_silent` asks the port whether it speaks HTTP (a
#: Dask server greets at once), and how long it waits for that answer.
HTTP_ASK_AFTER = 2.0
HTTP_WAIT = 2.0


def _silent(sock: socket.socket, host: str, port: int, address: str) -> str | None:
    """Why the server at the other end of `sock` is no Dask scheduler: it says nothing.

    Silent for :data:`HTTP_ASK_AFTER` seconds, the port is asked, on a connection of its own,
    whether it speaks HTTP (:func:`_http_server`): the dashboard's port, or any web server, is
    then named as such at once (was: after Dask's whole connect timeout, 30 s, with a guess).
    Otherwise the rest of the wait is waited for a greeting, and a greeting must be Dask's
    whole handshake, within the same wait (:func:`_handshake`).
    """
    wait = _greeting_wait()
    start = time.monotonic()

    def left() -> float:
        return max(wait - (time.monotonic() - start), 0.001)

    sock.settimeout(min(wait, HTTP_ASK_AFTER))
    try:
        try:
            if sock.recv(1):
                return _handshake(address, host, port, left(), wait)
            said = "closed the connection without a word"
        except TimeoutError:
            http = _http_server(host, port, max(min(HTTP_WAIT, wait - HTTP_ASK_AFTER), 0.2))
            if http is not None:
                return http
            sock.settimeout(left())
            if sock.recv(1):
                return _handshake(address, host, port, left(), wait)
            said = "closed the connection without a word"
    except TimeoutError:
        said = f"said nothing within {wait:g} s"
    except OSError:
        return None  # reset, or the like: Dask's own connection says what it finds
    return (
        f"port {port} of {host} accepted the connection but {said}, as no Dask scheduler "
        "does (the dashboard's port? a scheduler listens on 8786 unless told otherwise)"
    )


def _handshake(address: str, host: str, port: int, timeout: float, wait: float) -> str | None:
    """Why the server at `address`, which began to greet, is no Dask server; None if it is one.

    Dask's own connection (``distributed.comm.connect``) within `timeout` seconds, in a thread
    of its own with its own event loop (the caller may run one): Dask waits for the rest of a
    greeting without a time limit, so a server that sent a byte and then nothing held
    ``Client(address)`` for ever, and one that greeted in another protocol failed with
    "MemoryError: Unable to allocate 6.09 EiB" (user trials). `wait` is the whole wait, as the
    message states it.
    """
    import asyncio

    from distributed.comm.core import connect

    async def greet() -> None:
        comm = await asyncio.wait_for(connect(address, timeout=timeout), timeout)
        await comm.close()

    failed: list[BaseException] = []

    def run() -> None:
        try:
            asyncio.run(greet())
        except BaseException as exc:  # noqa: BLE001 - told below, whatever Dask raised
            failed.append(exc)

    thread = threading.Thread(target=run, name="pftrack-handshake", daemon=True)
    thread.start()
    thread.join(timeout + 1.0)
    if not thread.is_alive() and not failed:
        return None
    if thread.is_alive() or isinstance(failed[0], (TimeoutError, asyncio.TimeoutError)):
        return (
            f"port {port} of {host} began to answer but did not finish Dask's handshake within "
            f"{wait:g} s (a frozen or overloaded scheduler, or no Dask server)"
        )
    if isinstance(failed[0], OSError):
        return None  # reset, closed, or the like: Dask's own connection says what it finds
    return (
        f"port {port} of {host} answered in a protocol that is not Dask's "
        f"({type(failed[0]).__name__} on its greeting): no Dask scheduler listens there"
    )


def _http_server(host: str, port: int, timeout: float = HTTP_WAIT) -> str | None:
    """What the HTTP server at `port` of `host` is, as no Dask scheduler; None if it is none.

    Asked for ``/json/identity.json``, which a Dask scheduler's dashboard answers with the
    scheduler's own address: the message then gives it. `timeout`: seconds to wait for the
    connection and for each part of the answer.
    """
    request = f"GET /json/identity.json HTTP/1.0\r\nHost: {host}:{port}\r\n\r\n".encode()
    data = b""
    try:
        with socket.create_connection((host, port), timeout=timeout) as http:
            http.sendall(request)
            while len(data) < 1 << 16:
                chunk = http.recv(1 << 14)
                if not chunk:
                    break
                data += chunk
    except OSError:  # timed out (no HTTP server), reset: nothing known
        if not data:
            return None
    if not data.startswith(b"HTTP/"):
        return None
    status = data.split(b"\r\n", 1)[0].decode("latin-1").strip()
    body = data.partition(b"\r\n\r\n")[2]
    try:
        identity = json.loads(body) if status.split(" ")[1:2] == ["200"] else None
    except ValueError:
        identity = None
    if isinstance(identity, dict) and identity.get("type") == "Scheduler":
        address = identity.get("address")
        if isinstance(address, str) and address:
            return (
                f"port {port} of {host} is the web dashboard (HTTP) of the Dask scheduler at "
                f"{address}, not the scheduler itself: give {address}"
            )
    return (
        f"port {port} of {host} is an HTTP server (it answered {status!r}: a dashboard, a web "
        "server), not a Dask scheduler, which speaks Dask's own protocol: give the "
        "scheduler's address (dask scheduler prints it as 'Scheduler at', port 8786 unless "
        "told otherwise)"
    )


#: Seconds :func:`_dask_server` waits for a Dask server to say what it is.
IDENTITY_WAIT = 5.0


def _dask_server(address: str) -> str | None:
    """What the Dask server at `address` is when it is not a scheduler (a worker), else None.

    ``Client(address)`` on a worker's port failed with the worker's own complaint,
    "Worker.identity() got an unexpected keyword argument 'n_workers'" (a user trial): the
    server is asked what it is (Dask's ``identity``, on a connection of its own, in a thread
    of its own: the caller may run an event loop), and a worker names its scheduler.
    """
    import asyncio

    from distributed.core import rpc

    async def ask() -> Any:
        async with rpc(address, timeout=IDENTITY_WAIT) as server:
            return await asyncio.wait_for(server.identity(), IDENTITY_WAIT)

    answer: list[Any] = []

    def run() -> None:
        with contextlib.suppress(Exception):
            answer.append(asyncio.run(ask()))

    thread = threading.Thread(target=run, name="pftrack-identity", daemon=True)
    thread.start()
    thread.join(2 * IDENTITY_WAIT)
    identity = answer[0] if answer else None
    if not isinstance(identity, dict) or not isinstance(identity.get("type"), str):
        return None
    kind = identity["type"]
    if kind == "Scheduler":
        return None
    if kind == "Worker":
        scheduler = identity.get("scheduler")
        if isinstance(scheduler, str) and scheduler:
            return (
                f"it is a Dask worker, not a scheduler (the worker's scheduler is at "
                f"{scheduler}): give {scheduler}"
            )
    if kind == "Nanny":
        return (
            "it is a Dask nanny (the process that watches over a worker), not a scheduler: "
            "give the scheduler's address (dask scheduler prints it as 'Scheduler at')"
        )
    return (
        f"it is a Dask {kind}, not a scheduler: give the scheduler's address (dask scheduler "
        "prints it as 'Scheduler at')"
    )


def _connect_problem(address: str, exc: Exception) -> str:
    """Why ``Client(address)`` failed, in one line, with what to do where that is known."""
    import dask

    text = one_line(exc)
    protocol = address.partition("://")[0] if "://" in address else "tcp"
    unset = dask.config.get("distributed.comm.tls.ca-file", None) is None
    if protocol in ("tls", "wss") and (unset or not isinstance(exc, OSError)):
        # tls: Dask's "TLS expects a `ssl_context` argument"; wss: timed out
        return (
            f"{text} ({protocol}:// needs Dask's TLS settings where pftrack runs: the CA file, "
            f"and the client's certificate and key: {TLS_SETTINGS}, or distributed.comm.tls "
            "in a Dask configuration file)"
        )
    if isinstance(exc, TimeoutError) and text == "TimeoutError":  # Dask's own wait_for
        # a server that greeted (checked before: _refused) and then said nothing more
        return (
            f"it completed Dask's handshake but did not answer the client within "
            f"{_greeting_wait():g} s (a frozen or overloaded scheduler, or another Dask server)"
        )
    if isinstance(exc, OSError):  # timed out, refused, unknown host, a TLS handshake
        return text
    if protocol == "ucx":
        return (
            f"{text} (ucx:// needs the distributed-ucxx package: this Dask has no UCX "
            "comm of its own)"
        )
    return text


#: What a scheduler imports to load a batch's tasks, and a worker to run them (the worker
#: plugin's module too): run by :func:`check_pftrack` with ``exec``, a built-in, which Dask
#: pickles by name (a function of pftrack's could not even be unpickled where it is missing).
PFTRACK_IMPORTS = "import pftrack.batch.engine, pftrack.batch.tasks, pftrack.batch._plugin"
#: The end of the error of a scheduler or workers that cannot import pftrack.
INSTALL_EVERYWHERE = "install pftrack where the scheduler and every worker run"


def _address_of(c: Client) -> str:
    return str(getattr(c.scheduler, "address", None) or "?")


def check_pftrack(c: Client, address: str, scheduler: bool = True) -> None:
    """Refuse a cluster whose scheduler or workers cannot import pftrack.

    The scheduler unpickles a batch's tasks (their functions and options are pftrack's) and
    the workers run them: without pftrack, registering the worker plugin failed with an
    80-line traceback, and a re-run (the plugin already registered) with every task failing
    with Dask's "Error during deserialization of the task graph", pftrack never named, or with
    the workers dying on the task. Checked with one round trip to the scheduler and one to the
    workers (those that have joined: later ones are checked by :func:`run_jobs` once it has
    waited for them).

    Parameters
    ----------
    c : distributed.Client
        Connected to the cluster.
    address : str
        The scheduler's address, as the error names it.
    scheduler : bool
        Check the scheduler too (else the workers only).

    Raises
    ------
    ImportError
        One line naming the scheduler's address (and the workers that failed), the import
        error, and what to do (``name`` is ``"pftrack"``); or the workers that run another
        pftrack release than this process (their outputs would be another release's, named
        as this one's in the sidecars).
    """
    if scheduler:
        try:
            c.run_on_scheduler(exec, PFTRACK_IMPORTS)
        except ImportError as exc:
            raise ImportError(
                f"the scheduler at {address} cannot import pftrack ({one_line(exc)}): "
                f"{INSTALL_EVERYWHERE}",
                name="pftrack",
            ) from None
    answers = c.run(exec, PFTRACK_IMPORTS, on_error="return")
    failed = {w: e for w, e in answers.items() if isinstance(e, BaseException)}
    if failed:
        first = next(iter(failed.values()))
        which = (
            "the workers"
            if len(failed) == len(answers)
            else f"{len(failed)} of the {len(answers)} workers ({', '.join(sorted(failed))})"
        )
        raise ImportError(
            f"{which} at {address} cannot import pftrack ({one_line(first)}): {INSTALL_EVERYWHERE}",
            name="pftrack",
        )
    # another release may track otherwise, and the sidecars name this one's (a user trial)
    releases = c.run(eval, "__import__('pftrack').__version__", on_error="return")
    other = {w: v for w, v in releases.items() if v != _version()}
    if other:
        shown = ", ".join(sorted({str(v) for v in other.values()}))
        which = (
            "the workers"
            if len(other) == len(releases)
            else f"{len(other)} of the {len(releases)} workers ({', '.join(sorted(other))})"
        )
        raise ImportError(
            f"{which} at {address} run pftrack {shown}, this is pftrack {_version()}: "
            f"{SAME_RELEASE}",
            name="pftrack",
        )


#: What to do about workers of another pftrack release than this process's.
SAME_RELEASE = (
    "install the same pftrack where this process and every worker run (a batch's outputs are "
    "those of one release)"
)


def _register(c: Client, plugin: Any, address: str) -> None:
    """Register the worker `plugin`; a failure (a worker's setup raised) is one line.

    Raises
    ------
    ImportError
        Naming the scheduler's address and the workers' error (Dask's text), and what to do.
    """
    try:
        c.register_plugin(plugin)
    except Exception as exc:  # noqa: BLE001 - Dask re-raises a worker's error as Exception(TEXT)
        raise ImportError(
            f"the workers at {address} cannot set up pftrack's worker plugin ({one_line(exc)}): "
            f"{INSTALL_EVERYWHERE}",
            name="pftrack",
        ) from None


#: The loggers through which Dask reports, with a traceback, the end of a client's attempts to
#: reconnect to a scheduler that went away when the client is closed.
_CLIENT_LOGGERS = ("distributed.client", "distributed.utils")


@contextlib.contextmanager
def _silenced(*names: str) -> Iterator[None]:
    """The loggers `names` say nothing meanwhile."""
    loggers = [logging.getLogger(name) for name in names]
    before = [lg.disabled for lg in loggers]
    for lg in loggers:
        lg.disabled = True
    try:
        yield
    finally:
        for lg, was in zip(loggers, before, strict=True):
            lg.disabled = was


class _Dropped(logging.Filter):
    """Drops the records whose message (its format) begins with one of `prefixes`."""

    def __init__(self, *prefixes: str) -> None:
        super().__init__()
        self.prefixes = prefixes

    def filter(self, record: logging.LogRecord) -> bool:
        return not str(record.msg).startswith(self.prefixes)


#: What Dask's client logs, as a warning, when the worker that held a finished task's result
#: died before the result was taken: the batch computes it again and waits (:func:`_taken`).
_RESULT_LOST = "Couldn't gather"


@contextlib.contextmanager
def _dropped(name: str, *prefixes: str) -> Iterator[None]:
    """The logger `name` drops the records that begin with one of `prefixes` meanwhile."""
    logger = logging.getLogger(name)
    drop = _Dropped(*prefixes)
    logger.addFilter(drop)
    try:
        yield
    finally:
        logger.removeFilter(drop)


@contextlib.contextmanager
def _main_left_out() -> Iterator[None]:
    """Worker processes spawned meanwhile do not import this process's main module.

    ``multiprocessing`` starts a worker of a local cluster as a new Python that imports the
    parent's main module (a script by its path, ``python -m`` by its name) before it takes
    work. A script without ``if __name__ == "__main__":`` then runs again in every worker, and
    its call of :func:`track_many` starts a cluster inside a worker that is still starting:
    every worker failed, with Dask's tracebacks over hundreds of lines. A guarded script's
    workers only imported what its top level imports (a deep-learning framework, say) for
    nothing: pftrack's tasks are functions of pftrack. Meanwhile the main module looks to
    ``multiprocessing`` as ``python -c`` does (no ``__spec__``, no ``__file__``); both are
    put back at the end. :func:`dask_client` holds it while its local cluster runs, not only
    while it starts: a nanny starts its worker again when it dies (a crash, the kernel's OOM
    killer), and that one ran the script too (a user trial: it never joined, and the tasks
    left failed after the 60 s wait for a worker).
    """
    import sys

    main = sys.modules.get("__main__")
    if main is None or (getattr(main, "__spec__", None) is None and not hasattr(main, "__file__")):
        yield  # an interactive session, python -c: nothing is imported again anyway
        return
    spec = main.__spec__
    had_file = "__file__" in vars(main)
    file = vars(main).get("__file__")
    main.__spec__ = None
    if had_file:
        del main.__file__
    try:
        yield
    finally:
        main.__spec__ = spec
        if had_file:
            main.__file__ = file


@contextlib.contextmanager
def _interrupts_held(spawns: bool = True) -> Iterator[None]:
    """Hold Ctrl-C (SIGINT) and SIGTERM in this thread meanwhile; one held is raised at the end.

    While a local cluster starts: a ``KeyboardInterrupt`` in the middle (Ctrl-C, or SIGTERM
    under ``pftrack``: :class:`~pftrack.cli._signals.Terminated`) would leave it half started
    (nannies that fail to start, Dask's exit hook asserting on the cluster's state, a traceback
    each). And the threads started meanwhile (Dask's event loop, then the threads that spawn
    the worker processes) inherit the blocked signals, as do the worker processes they spawn (a
    signal mask survives fork and exec): the workers, in the terminal's process group, never
    see its Ctrl-C, nor a SIGTERM sent to the group (``kill -TERM -PGID``, a service manager),
    not even while Python starts in them. This process, whose main thread unblocks them here,
    cancels the tasks and closes the cluster instead. The hold is
    :func:`~pftrack.io.atomic.interrupts_deferred`'s, which the atomic writers use too (its
    notes say how a signal taken by another thread is held as well).

    `spawns`: processes may be started meanwhile (a local cluster's workers). False when none
    is (a failed client closed: :func:`_new_client`), so as not to start multiprocessing's
    resource tracker, a process, for nothing.
    """
    if spawns and hasattr(signal, "pthread_sigmask"):
        # multiprocessing's resource tracker, started with the first worker process, unblocks
        # SIGINT and SIGTERM in the thread that starts it (resource_tracker.ensure_running):
        # now, before the hold, it is not started again in the thread that spawns the workers
        from multiprocessing import resource_tracker

        resource_tracker.ensure_running()
    with interrupts_deferred():
        yield


def scheduler_address(scheduler: str | None = None) -> str | None:
    """The scheduler a batch connects to: `scheduler`, else Dask's ``scheduler-address``.

    Both are checked (:func:`check_scheduler_address`); an empty setting counts as none.
    """
    if scheduler is not None:
        return check_scheduler_address(scheduler, "scheduler")
    try:
        import dask
    except ImportError:  # no Dask, no setting: the batch says how to install it if it needs it
        return None
    address = dask.config.get("scheduler-address", None)
    if address is None or address == "":
        return None
    return check_scheduler_address(address, "$DASK_SCHEDULER_ADDRESS (Dask's scheduler-address)")


def _from_setting(address: str) -> str:
    """`address`, Dask's ``scheduler-address`` setting, with where it comes from.

    For the errors of a scheduler that cannot be reached: a user trial's ``pftrack batch``
    without ``--scheduler`` said "cannot connect to the Dask scheduler at
    tcp://127.0.0.1:8797", an address given nowhere on its command line.
    """
    where = (
        "$DASK_SCHEDULER_ADDRESS"
        if os.environ.get("DASK_SCHEDULER_ADDRESS")
        else "Dask's scheduler-address setting, in a Dask configuration file"
    )
    return f"{address} (from {where}: unset it to run on a local cluster)"


#: Dask's comm protocols whose addresses are ``PROTOCOL://HOST:PORT``. ``tls`` and ``wss``
#: need Dask's TLS settings, ``ucx`` the distributed-ucxx package (:func:`dask_client` says so
#: when they are missing); ``inproc://`` is refused: a scheduler inside one process.
SCHEDULER_PROTOCOLS = ("tcp", "tls", "ws", "wss", "ucx")


def check_scheduler_address(address: object, what: str = "scheduler") -> str:
    """`address` if it is a scheduler's address, ``tcp://HOST:PORT``; else a one-line error.

    Checked before anything connects or runs (a re-run whose outputs are all complete too):
    ``tcp://127.0.0.1:8786x`` failed in Dask with "invalid literal for int()", port 99999 waited
    out the connect timeout, an empty address started a local cluster instead.

    Parameters
    ----------
    address : str
        ``PROTOCOL://HOST:PORT`` (protocol ``tcp``, ``tls``, ``ws``, ``wss`` or ``ucx``; none:
        ``tcp``; not ``inproc``), ``HOST`` a name, an IPv4 address or a bracketed IPv6 one
        (``[::1]``), ``PORT`` in 1..65535. Spaces around it are dropped.
    what : str
        Names the address in the error (``"--scheduler"``, ``"scheduler"``, ...).

    Returns
    -------
    str
        The address, stripped.

    Raises
    ------
    TypeError
        `address` is not a str.
    ValueError
        It is empty, or not of that form (the part that is wrong named).
    """
    if not isinstance(address, str):
        raise TypeError(
            f"{what} must be a str, tcp://HOST:PORT, got {type(address).__name__} {address!r}"
        )
    text = address.strip()
    if not text:
        raise ValueError(
            f"{what} is empty: give a running Dask scheduler's address, tcp://HOST:PORT"
        )
    expected = "expected tcp://HOST:PORT, PORT in 1..65535"
    named = f"{what} {text!r}"
    protocol, sep, rest = text.partition("://")
    if not sep:
        protocol, rest = "tcp", text
    if protocol == "inproc":  # was: taken, then Dask's "not enough values to unpack"
        raise ValueError(
            f"{named}: inproc:// names a scheduler inside one process, which a batch cannot "
            "reach by address; give a running scheduler's tcp://HOST:PORT (in Python, pass "
            "a client of an in-process cluster as client=)"
        )
    if protocol not in SCHEDULER_PROTOCOLS:
        known = ", ".join(f"{p}://" for p in SCHEDULER_PROTOCOLS)
        raise ValueError(f"{named}: unknown protocol {protocol}:// ({known}; {expected})")
    host, colon, port = rest.rpartition(":")
    if host.startswith("[") and host.endswith("]"):
        bare = host[1:-1]
        bad_host = not bare or any(c not in "0123456789abcdefABCDEF:." for c in bare)
    elif ":" in host and not any(c in "[]/" for c in host):
        raise ValueError(f"{named}: an IPv6 address goes in brackets, tcp://[::1]:8786")
    else:
        bad_host = not host or any(c.isspace() or c in "/?#@[]:" for c in host)
    if not colon or (not port and not bad_host):
        raise ValueError(f"{named}: no port ({expected})")
    if bad_host:
        problem = f"host {host!r} is not a host name or address" if host else "no host"
        raise ValueError(f"{named}: {problem} ({expected})")
    if not (port.isascii() and port.isdigit()):
        raise ValueError(f"{named}: port {port!r} is not a number ({expected})")
    if not 1 <= int(port) <= 65535:
        raise ValueError(f"{named}: port {int(port)} is out of range ({expected})")
    return text


def check_client(client: object) -> None:
    """Refuse a `client` that is not a connected ``distributed.Client`` (None passes).

    Raises
    ------
    TypeError
        Naming `client`, and how to connect to an address (``scheduler=``): a string address
        failed deep in Dask with "'str' object has no attribute 'register_plugin'".
    ValueError
        A client that is not connected (closed, or still connecting).
    """
    if client is None:
        return
    try:
        from distributed import Client
    except ImportError:  # no Dask: whatever it is, it is not a Client
        Client = None  # type: ignore[assignment,misc]  # noqa: N806
    if Client is not None and isinstance(client, Client):
        status = str(getattr(client, "status", "running"))
        if status != "running":  # was: "'NoneType' object has no attribute 'run_function'"
            raise ValueError(
                f"client is not connected (its status is {status!r}): pass a connected "
                "distributed.Client, or the scheduler's address as scheduler="
            )
        return
    hint = (
        f": to connect to a running scheduler by its address, pass scheduler={client!r} "
        "(or distributed.Client(ADDRESS) as client)"
        if isinstance(client, (str, os.PathLike))
        else ""
    )
    raise TypeError(
        f"client must be a distributed.Client or None, got {type(client).__name__}{hint}"
    )


def where_to_run(client: Client | None, scheduler: str | None, n_workers: int | None) -> str | None:
    """Check where a batch is to run; the address of the scheduler to connect to, if any.

    One of: `client` (its cluster), `scheduler` (checked with :func:`check_scheduler_address`),
    `n_workers` (a local cluster, or this process for 0), or none of them: Dask's
    ``scheduler-address`` setting (``DASK_SCHEDULER_ADDRESS``) if it names one, else a local
    cluster. Returns None but for a scheduler to connect to.

    Raises
    ------
    TypeError
        `client` is not a ``distributed.Client``.
    ValueError
        Two of them given (``n_workers`` would have been ignored, silently), or a bad address.
    """
    check_client(client)
    given = [
        name
        for name, value in (("client", client), ("scheduler", scheduler), ("n_workers", n_workers))
        if value is not None
    ]
    if len(given) > 1:
        raise ValueError(
            f"{' and '.join(given)} are both given: the tasks run on a client's cluster, on a "
            "scheduler's, or on a local cluster of n_workers (0: in this process); give one"
        )
    if client is not None or n_workers is not None:
        return None
    return scheduler_address(scheduler)


def fingerprint(paths: Sequence[Path]) -> list[dict[str, Any]]:
    """What a re-run compares to tell whether each input changed since its outputs were made.

    Parameters
    ----------
    paths : sequence of Path
        A task's inputs (:attr:`Job.reads`).

    Returns
    -------
    list of dict
        Per input: ``path``, and for a file its ``size`` and ``mtime_ns``; for a folder (of
        images) the number of its image files (``files``), their total ``size``, the newest
        ``mtime_ns`` and ``listing``, a SHA-256 of every image's name, size and ``mtime_ns`` in
        name order (so renamed or reordered images count as a change, which the three figures
        before it do not see); ``missing`` when it cannot be read (the task then fails on its
        own).
    """
    if isinstance(paths, (str, bytes, os.PathLike)) or not isinstance(paths, Iterable):
        raise TypeError(f"fingerprint: paths must be a sequence of paths, got {shown(paths)}")
    out: list[dict[str, Any]] = []
    for i, given in enumerate(paths):
        path = Path(path_arg(given, f"fingerprint: paths[{i}]"))  # was: an AttributeError
        entry: dict[str, Any] = {"path": str(path)}
        try:
            st = path.stat()
            if path.is_dir():
                images = sorted(
                    (e.name, e.stat())
                    for e in os.scandir(path)
                    if e.is_file() and os.path.splitext(e.name)[1].lower() in IMAGE_SUFFIXES
                )
                entry["files"] = len(images)
                entry["size"] = sum(s.st_size for _, s in images)
                entry["mtime_ns"] = max((s.st_mtime_ns for _, s in images), default=0)
                entry["listing"] = _listing_hash((n, s.st_size, s.st_mtime_ns) for n, s in images)
            else:
                entry["size"] = st.st_size
                entry["mtime_ns"] = st.st_mtime_ns
        except OSError:
            entry["missing"] = True
        out.append(entry)
    return out


def _listing_hash(listing: Iterable[tuple[str, int, int]]) -> str:
    """SHA-256 (hex) of a folder's (name, size, mtime_ns) triples, in the order given."""
    digest = hashlib.sha256()
    for name, size, mtime_ns in listing:
        digest.update(f"{name}\0{size}\0{mtime_ns}\n".encode("utf-8", "surrogateescape"))
    return digest.hexdigest()


#: Outputs up to this size are hashed whole by :func:`output_print`; a larger one (a rendered
#: video) by its first and last :data:`HASHED_ENDS` bytes. SHA-256 ran at 300-400 MB/s here
#: (SHA-NI; BLAKE2b 150 MB/s): 64 MiB took 0.13 s, a NAME.txt of 8 KB 0.07 ms.
HASHED_WHOLE = 64 << 20
#: Bytes hashed at each end of an output larger than :data:`HASHED_WHOLE`.
HASHED_ENDS = 1 << 20


def output_print(path: Path) -> dict[str, Any]:
    """What a re-run compares to tell whether an output is still the file a batch wrote.

    Parameters
    ----------
    path : Path
        An output (``DIR/NAME.txt``, ``DIR/NAME.mp4``).

    Returns
    -------
    dict
        ``name`` (the file's name in its folder), ``size`` and ``sha256``: the SHA-256 (hex) of
        the whole file when it has at most :data:`HASHED_WHOLE` bytes, else of its first and
        last :data:`HASHED_ENDS` bytes (with its size, a truncated, emptied or replaced video
        is told apart without reading it all).

    Raises
    ------
    OSError
        The file cannot be read.
    """
    digest = hashlib.sha256()
    with path.open("rb") as fh:
        size = os.fstat(fh.fileno()).st_size
        if size <= HASHED_WHOLE:
            while chunk := fh.read(HASHED_ENDS):
                digest.update(chunk)
        else:
            digest.update(fh.read(HASHED_ENDS))
            fh.seek(size - HASHED_ENDS)
            digest.update(fh.read(HASHED_ENDS))
    return {"name": path.name, "size": size, "sha256": digest.hexdigest()}


def _outputs_changed(out_dir: Path, outputs: list[str], written: Any) -> str | None:
    """Why the outputs of a complete-looking sidecar are not the files it wrote (None: they are).

    `written` is the sidecar's ``output_prints`` (:func:`output_print` of each output when it
    was written). Was: an output only had to exist, so one truncated, emptied or replaced by
    another file counted as complete, and a re-run skipped it with the earlier figures.
    """
    for name in outputs:
        if not (out_dir / name).is_file():
            return f"redone: its output {out_dir / name} is missing"
    if (
        not isinstance(written, list)
        or [w.get("name") if isinstance(w, dict) else None for w in written] != outputs
    ):
        return "redone: its sidecar records no fingerprint of its outputs (an older run)"
    for name, was in zip(outputs, written, strict=True):
        path = out_dir / name
        try:
            now = output_print(path)
        except OSError as exc:
            return f"redone: its output {path} cannot be read ({exc.strerror or exc})"
        if now["size"] != was.get("size"):
            return (
                f"redone: its output {path} changed since the last run wrote it ({now['size']} "
                f"bytes, written {was.get('size')})"
            )
        if now["sha256"] != was.get("sha256"):
            return (
                f"redone: its output {path} changed since the last run wrote it (the same size, "
                "other content)"
            )
    return None


def _sidecar(out_dir: Path, name: str) -> Path:
    return out_dir / f"{name}.json"


#: How every record a batch writes begins (``json.dumps(..., indent=2)`` of a dict whose first
#: key is ``kind``): a sidecar or ``summary.json`` whose text is cut short still begins so.
RECORD_START = '{\n  "kind": "'


def _cut_short(path: Path) -> str | None:
    """Why the file `path` is a batch's record cut short (truncated), or None.

    None when it is valid JSON, missing or unreadable, or when its text does not begin as a
    batch's record does (:data:`RECORD_START`): not a batch's, then, and not to be replaced.
    Batches write their records atomically, so one cut short was damaged afterwards (a copy
    stopped half-way, a full disk on another machine, an edit).
    """
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, ValueError):
        return None
    try:
        json.loads(text)
        return None
    except ValueError as exc:
        if text.startswith(RECORD_START) or RECORD_START.startswith(text):
            return f"{len(text.encode())} bytes, not valid JSON: {one_line(exc)}"
        return None


def _read_sidecar(out_dir: Path, name: str) -> dict[str, Any] | None:
    """The sidecar ``NAME.json`` as a dict; None when it is missing, unreadable or not one."""
    try:
        entry = json.loads(_sidecar(out_dir, name).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return entry if isinstance(entry, dict) else None


def _version() -> str:
    from pftrack import __version__

    return __version__


def _complete(
    out_dir: Path, job: Job, kind: str, settings: dict[str, Any], prints: list[dict[str, Any]]
) -> tuple[dict[str, Any] | None, str | None]:
    """The sidecar of `job` if its outputs are complete for these inputs and settings.

    Returns
    -------
    entry : dict or None
        The sidecar, or None: the job is to run.
    note : str or None
        Why a job done by an earlier run with these settings is to run again: another pftrack
        release made it (the sidecar's ``pftrack``), its inputs changed (their `prints`, from
        :func:`fingerprint`, differ from the sidecar's), or its outputs did (missing, or no
        longer the size and SHA-256 the sidecar records: :func:`output_print`).
    """
    entry = _read_sidecar(out_dir, job.name)
    if entry is None:
        sidecar = _sidecar(out_dir, job.name)
        damaged = _cut_short(sidecar)
        if damaged is not None:  # was: refused as a file no batch wrote (--force redid all)
            return None, f"redone: its sidecar {sidecar} was cut short ({damaged})"
        return None, None
    same = (
        entry.get("kind") == kind
        and entry.get("settings") == settings
        and entry.get("inputs") == [str(p) for p in job.reads]
        and entry.get("status") == "done"
    )
    outputs = entry.get("outputs")
    if not same or not isinstance(outputs, list) or not all(isinstance(o, str) for o in outputs):
        return None, None
    made_by = entry.get("pftrack")
    if made_by != _version():  # another release may track otherwise (a user trial: skipped)
        by = f"pftrack {made_by}" if isinstance(made_by, str) else "an older pftrack"
        return None, f"redone: made by {by}, this is pftrack {_version()}"
    earlier = entry.get("fingerprint")
    if earlier != prints:
        if not isinstance(earlier, list) or len(earlier) != len(prints):
            return None, "redone: its sidecar records no input sizes and times (an older run)"
        changed = [(p, q) for p, q in zip(prints, earlier, strict=True) if p != q]
        paths = ", ".join(p["path"] for p, _ in changed)
        if all(_older_print(p, q) for p, q in changed):
            return None, f"redone: its sidecar records an older kind of fingerprint of {paths}"
        return None, f"redone: {paths} changed since the last run"
    note = _outputs_changed(out_dir, outputs, entry.get("output_prints"))
    if note is not None:
        return None, note
    return entry, None


def _write(
    out_dir: Path,
    job: Job,
    result: TaskResult,
    kind: str,
    settings: dict[str, Any],
    prints: list[dict[str, Any]],
    on_commit: Callable[[dict[str, Any]], object] | None = None,
) -> dict[str, Any]:
    """Write one task's outputs, sidecar last (with the inputs' `prints`); return its entry.

    The sidecar is first replaced by one that says ``writing`` and names the outputs to come:
    stopped before the last step, the sequence is not complete for a re-run (an earlier run's
    sidecar would vouch for outputs that may be replaced), and its video is known as a batch's
    output (:func:`~pftrack.batch.inputs.find_sequences` passes it over). Then ``NAME.txt``,
    its video and the final sidecar are staged and renamed together
    (:func:`~pftrack.io.atomic.staged_outputs`): a Ctrl-C or SIGTERM while they are written
    leaves the earlier ones, and one during the renames is raised after the last (was: each
    written in turn; stopped between two, a new ``NAME.txt`` beside an earlier video).
    `on_commit` is called with the entry once they are in place, before such an interrupt is
    raised. A result with an `error` is written too, and its entry and sidecar say
    ``failed``: not complete either.
    """
    outputs = [f"{job.name}.txt", *(f"{job.name}{suffix}" for suffix in result.files)]
    head: dict[str, Any] = {
        "kind": kind, "settings": settings, "inputs": [str(p) for p in job.reads],
        "pftrack": _version(),
    }  # fmt: skip
    left = [o for o in _earlier_outputs(out_dir, job.name, kind) if o not in outputs]
    if left:  # an earlier run's video, not made again: still a batch's, never an input
        head["earlier_outputs"] = left
    writing = {**head, "name": job.name, "status": "writing", "outputs": outputs}
    _write_sidecar(out_dir, job.name, writing)
    status = "done" if result.error is None else "failed"  # failed: after its outputs were made
    entry = {"name": job.name, "status": status, **result.info, "outputs": outputs}
    if result.error is not None:
        entry.update(error=result.error, traceback=result.traceback)
    with staged_outputs(on_commit=None if on_commit is None else lambda: on_commit(entry)) as stage:
        staged = [stage(out_dir / o) for o in outputs]
        write_mot(staged[0], result.rows, exact=False if result.exact is None else result.exact)
        for path, data in zip(staged[1:], result.files.values(), strict=True):
            path.write_bytes(data)
        # what a re-run checks they still are (the staged files' bytes, under the outputs' names)
        written = [{**output_print(p), "name": o} for p, o in zip(staged, outputs, strict=True)]
        sidecar = {**head, "fingerprint": prints, **entry, "output_prints": written}
        stage(_sidecar(out_dir, job.name)).write_text(_sidecar_text(sidecar), encoding="utf-8")
    return entry


def _earlier_outputs(out_dir: Path, name: str, kind: str) -> list[str]:
    """The files an earlier run's sidecar lists (outputs and earlier ones) that are still there.

    A batch rendered into its input folder and then run without ``--render`` leaves the
    earlier ``NAME.mp4``; its new sidecar keeps naming it (``earlier_outputs``), or the video
    would count as an input of every later batch of that folder (``two inputs are both named
    NAME``).
    """
    entry = _read_sidecar(out_dir, name)
    if entry is None or entry.get("kind") != kind:
        return []
    listed = [*(entry.get("outputs") or []), *(entry.get("earlier_outputs") or [])]
    return [o for o in dict.fromkeys(listed) if isinstance(o, str) and (out_dir / o).is_file()]


def _write_sidecar(out_dir: Path, name: str, sidecar: dict[str, Any]) -> None:
    with atomic_write(_sidecar(out_dir, name)) as fh:
        fh.write(_sidecar_text(sidecar))


def _sidecar_text(sidecar: dict[str, Any]) -> str:
    return json.dumps(_clean(sidecar), indent=2) + "\n"


def _older_print(now: dict[str, Any], earlier: Any) -> bool:
    """Whether `earlier` is the same input's fingerprint taken by an older pftrack (other keys).

    An image folder's ``listing`` was added later: a sidecar without it is redone once, with
    a note that says so rather than that the folder changed.
    """
    return (
        isinstance(earlier, dict)
        and earlier.get("path") == now["path"]
        and "missing" not in now
        and "missing" not in earlier
        and set(earlier) != set(now)
    )


#: Seconds between two frame counts a task on a Dask worker sends to the client.
REPORT_EVERY = 0.5


def _worker_reporter(topic: str, name: str) -> Callable[[int], None] | None:
    """On a Dask worker: ``report(n)`` logs ``[name, n]`` under `topic`, twice a second at most."""
    try:
        from distributed import get_worker

        worker = get_worker()
    except (ImportError, ValueError):  # not on a worker
        return None
    last = -math.inf

    def report(n: int) -> None:
        nonlocal last
        now = time.monotonic()
        if now - last >= REPORT_EVERY:
            last = now
            worker.log_event(topic, [name, int(n)])  # sent from this thread by the worker's loop

    return report


class Outcome(NamedTuple):
    """What :func:`call_task` sends back: the task's result, or its failure as data.

    Attributes
    ----------
    result : TaskResult or None
        None when the task failed.
    error, traceback : str or None
        The failure's one line and traceback.
    host : str or None
        The host the task ran on (a failed entry of ``summary.json`` names it, as a done one
        does).
    missing : str or None
        The task failed on a file it could not find (``FileNotFoundError``): the file's name
        if the error carries one, else ``""``. The client tells a file its worker cannot see
        from one that does not exist (:func:`_failure`).
    seen : list of dict or None
        On a Dask worker: the :func:`fingerprint` of the task's inputs as the worker saw them
        before it ran, which the client compares with its own (:func:`_seen_otherwise`).
    release : str or None
        On a Dask worker: its pftrack release, which the client compares with its own (a
        worker that joined after :func:`check_pftrack` ran may run another).
    worker : str or None
        On a Dask worker: its address (the summary counts the workers that ran tasks).
    """

    result: TaskResult | None
    error: str | None = None
    traceback: str | None = None
    host: str | None = None
    missing: str | None = None
    seen: list[dict[str, Any]] | None = None
    release: str | None = None
    worker: str | None = None


def _worker_address() -> str | None:
    """The address of the Dask worker running this task, or None (not on a worker)."""
    try:
        from distributed import get_worker

        return str(get_worker().address)
    except (ImportError, ValueError, AttributeError):
        return None


def _worker_stop() -> Callable[[], None] | None:
    """On a Dask worker, ``stop()``: raises once the running task's future is cancelled.

    It raises :class:`~pftrack.batch.tasks.TaskCancelled`; None off a worker.
    Dask cannot stop a running thread: ``Client.cancel`` (the batch's Ctrl-C) and a client that
    goes away release the task, and the worker marks it ``cancelled`` but lets it run to its
    end, busy for nothing. The task looks at its own state in the worker (a dict look-up, no
    message to the scheduler: measured ~0.1 µs, every 25 frames) and stops. Dask internals
    (``Worker.state.tasks``, the running task's key): if they are not there, no check.
    """
    try:
        from dask.context import thread_state  # distributed.utils.thread_state is this one
        from distributed import get_worker

        tasks = get_worker().state.tasks
        key = thread_state.key
    except (ImportError, ValueError, AttributeError):  # not on a worker, or another Dask
        return None

    def stop() -> None:
        ts = tasks.get(key)
        if ts is None or ts.state in ("cancelled", "released", "forgotten"):
            raise TaskCancelled("cancelled while it ran (the batch was interrupted)")

    return stop


class _TaskWarnings:
    """The warnings of the tasks running in this process, each task's to its own list.

    ``warnings.catch_warnings`` is one state for the whole process: a Dask worker with several
    threads runs several tasks at once, and each task's ``catch_warnings(record=True)`` took
    the others' warnings, or restored the module in the wrong order. One recording serves them
    all (entered by the first task, left by the last), and each warning goes to the task of
    the thread that raised it; one from another thread (a read-ahead thread of ``pftrack batch
    --workers 0``) to the task running, when only one runs.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._logs: dict[int, list[warnings.WarningMessage]] = {}
        self._saved: warnings.catch_warnings[None] | None = None
        self._shown: Callable[..., None] = warnings.showwarning

    @contextlib.contextmanager
    def recording(self) -> Iterator[list[warnings.WarningMessage]]:
        """Meanwhile, the warnings this thread raises (every one: filter ``always``)."""
        log: list[warnings.WarningMessage] = []
        thread = threading.get_ident()
        with self._lock:
            if not self._logs:
                self._saved = warnings.catch_warnings()
                self._saved.__enter__()
                warnings.simplefilter("always")
                self._shown = warnings.showwarning
                warnings.showwarning = self._show
            before = self._logs.get(thread)  # a task within a task: its own, then the outer's
            self._logs[thread] = log
        try:
            yield log
        finally:
            with self._lock:
                if before is None:
                    del self._logs[thread]
                else:
                    self._logs[thread] = before
                if not self._logs and self._saved is not None:
                    self._saved.__exit__(None, None, None)
                    self._saved = None

    def _show(
        self,
        message: Warning | str,
        category: type[Warning],
        filename: str,
        lineno: int,
        file: Any = None,
        line: str | None = None,
    ) -> None:
        with self._lock:
            log = self._logs.get(threading.get_ident())
            if log is None and len(self._logs) == 1:
                (log,) = self._logs.values()
            if log is not None:
                log.append(warnings.WarningMessage(message, category, filename, lineno, file, line))
                return
        self._shown(message, category, filename, lineno, file, line)


#: The recording of :func:`call_task`'s warnings in this process.
_TASK_WARNINGS = _TaskWarnings()


def call_task(
    func: Callable[..., TaskResult],
    args: tuple[Any, ...],
    progress: Callable[[int], None] | tuple[str, str] | None = None,
    reads: Sequence[Path] | None = None,
) -> Outcome:
    """Run one task; an exception comes back as data (its line and traceback), not raised.

    So a failing input is reported in the summary without Dask logging it as a failed
    computation on the worker; a worker that dies still fails the future (``KilledWorker``).
    Warnings the task raises (no track found, boxes out of the frame, ...) would stay in a
    worker's log: they come back in the result's ``info["warnings"]``, one line each, in order,
    each once.

    `progress` receives the frames tracked so far (:func:`~pftrack.batch.tasks.reporting_frames`):
    a function (in this process), or ``(topic, name)`` on a Dask worker, whose counts then go
    to the client as Dask events (``Worker.log_event``) twice a second at most.

    On a Dask worker the task also stops itself once its future is cancelled (Ctrl-C on the
    client): every 25 frames it looks (:func:`_worker_stop`), and ends with
    :class:`~pftrack.batch.tasks.TaskCancelled`, its worker free for other work.

    With `reads` (the job's inputs, given on Dask), the outcome carries their
    :func:`fingerprint` as this process sees them, taken before the task reads them, and the
    host: the client tells a worker that sees other files than its own (:func:`_seen_otherwise`),
    and the worker's pftrack release: one that joined after :func:`check_pftrack` ran may run
    another, whose outputs the client does not write (:func:`_other_release`).
    """
    seen = fingerprint(reads) if reads is not None else None
    host = _host() if reads is not None else None
    release = _version() if reads is not None else None
    worker = _worker_address() if reads is not None else None
    report = _worker_reporter(*progress) if isinstance(progress, tuple) else progress
    stop = _worker_stop()
    with _TASK_WARNINGS.recording() as caught, reporting_frames(report, stop):
        try:
            result = func(*args)
        except Exception as exc:  # noqa: BLE001 - reported per task
            missing = None
            if isinstance(exc, FileNotFoundError):
                missing = str(exc.filename) if exc.filename else ""
            return Outcome(
                None, one_line(exc), traceback.format_exc(), _host(), missing, seen, release, worker
            )
    said = list(dict.fromkeys(" ".join(str(w.message).split()) for w in caught))
    if said:
        result = dataclasses.replace(result, info={**result.info, "warnings": said})
    return Outcome(result, host=host, seen=seen, release=release, worker=worker)


def _host() -> str:
    return socket.gethostname()


def _other_release(outcome: Outcome) -> str | None:
    """Why the outcome of a worker of another pftrack release is not written, or None.

    :func:`check_pftrack` sees the workers there when the batch starts; one that joins later
    (while the others are busy) was given tasks unchecked, and its outputs were written as this
    release's, which a re-run then skipped. A worker of a release that does not say its own
    (``release`` None) is not told apart.
    """
    if outcome.release is None or outcome.release == _version():
        return None
    return (
        f"made on worker {outcome.host} by pftrack {outcome.release}, this is pftrack "
        f"{_version()} (a worker that joined after the batch checked them): not written; "
        f"{SAME_RELEASE}"
    )


#: How the client words a file that a worker could not find but the client can.
UNSEEN = "not found on worker {host} (the client sees it: workers must see the same paths)"


def _seen_otherwise(job: Job, outcome: Outcome, here: list[dict[str, Any]]) -> str | None:
    """Why the worker of `outcome` read other inputs than this process sees, or None.

    `here`: the :func:`fingerprint` of ``job.reads`` taken before the tasks ran. Compared:
    whether each input exists, a file's size, a folder's number of images and their total
    size; not the times (a copy made on each machine has its own). An input that differs from
    `here` but not from what this process sees now changed while the batch ran: not the
    worker's view (its sidecar keeps `here`, so a re-run redoes it). Was: a worker whose copy
    differed (another video, fewer images under the same path) reported the sequence done with
    its own frames, written as the client's and skipped as complete by a re-run.
    """
    seen, host = outcome.seen, outcome.host
    if seen is None or host is None or len(seen) != len(here):
        return None
    if _difference(here, seen, host) is None:
        return None
    return _difference(fingerprint(job.reads), seen, host)  # changed meanwhile: None


def _difference(here: list[dict[str, Any]], seen: list[dict[str, Any]], host: str) -> str | None:
    """The first input whose fingerprints `here` and `seen` (on worker `host`) differ, said."""
    for mine, theirs in zip(here, seen, strict=True):
        if mine.get("missing"):
            continue  # the task fails (or not) on its own, as it would in this process
        path = mine["path"]
        if theirs.get("missing"):
            return f"{path}: {UNSEEN.format(host=host)}"
        counted = (theirs.get("files"), theirs.get("size"))
        if "files" in mine and (mine["files"], mine["size"]) != counted:
            return (
                f"{path}: another folder on worker {host} ({theirs.get('files')} images, "
                f"{theirs.get('size')} bytes there; {mine['files']} images, {mine['size']} "
                f"bytes here): {SAME_FILES}"
            )
        if "files" not in mine and mine.get("size") != theirs.get("size"):
            return (
                f"{path}: another file on worker {host} ({theirs.get('size')} bytes there, "
                f"{mine.get('size')} here): {SAME_FILES}"
            )
    return None


#: How the client ends the error of a task whose worker read other inputs than it sees.
SAME_FILES = "workers must see the same files at the same paths"


def _failure(job: Job, outcome: Outcome, remote: bool) -> str | None:
    """The error of a failed task as the client can tell it.

    A read path that is a broken symbolic link here is named as one (was: "No such file or
    directory", or "video source not found"), and so is a folder that cannot be looked into
    (was: "Permission denied: DIR/seqinfo.ini"). A file the task could not find on a worker
    (`remote`) while this process sees it is the worker's view that differs: said so, with
    the worker's host (was: "video source not found: PATH", as if it did not exist).
    """
    broken = [p for p in job.reads if p.is_symlink() and not p.exists()]
    loop = link_loop(broken[0]) if broken else None
    if loop is not None:  # was: "broken symbolic link: a -> b", b there, a link back to a
        return f"symbolic link loop: {loop}"
    if broken:
        return f"broken symbolic link: {broken[0]} -> {os.readlink(broken[0])}"
    unreadable = [
        text
        for p in job.reads
        if str(p) in (outcome.error or "") and (text := cannot_read(p)) is not None
    ]
    if unreadable:  # was: "Permission denied: DIR/seqinfo.ini", a file that need not exist
        return unreadable[0]
    unseen = _not_found_there(job, outcome) if remote else None
    if unseen is None:
        return outcome.error  # missing here too: the error as the task said it
    return f"{unseen}: {UNSEEN.format(host=outcome.host)}"


def _not_found_there(job: Job, outcome: Outcome) -> Path | None:
    """The file that the failed task of `outcome` could not find but this process sees, or None."""
    if outcome.missing is None or outcome.host is None or outcome.error is None:
        return None
    if outcome.missing:
        named = [Path(outcome.missing)]
    else:  # the path in the message (FrameSource's "video source not found: PATH")
        named = [p for p in (*job.reads, *job.guards) if str(p) in outcome.error]
    return next((p for p in named if p.exists()), None)


def _unseen_input(job: Job, outcome: Outcome, here: list[dict[str, Any]]) -> Path | None:
    """An input of `job` that the worker of `outcome` could not see but this process sees.

    `here`: the :func:`fingerprint` of ``job.reads`` taken before the tasks ran; the worker's
    own (``outcome.seen``) says which it could not read, and a failed task which file it could
    not find. None: the worker saw them all (or the task is not a Dask worker's).
    """
    if outcome.worker is None or outcome.host is None:
        return None
    seen = outcome.seen or []
    if len(seen) == len(here):
        for mine, theirs in zip(here, seen, strict=True):
            if theirs.get("missing") and not mine.get("missing") and Path(mine["path"]).exists():
                return Path(mine["path"])
    return _not_found_there(job, outcome) if outcome.result is None else None


#: How the messages name the output folder and a rendered video: the Python parameters
#: (``out_dir``, ``options.render``), or the options while a command runs the batch
#: (:func:`named_as_options`). Was ``--out`` from Python too (``track_many("a.avi", "b.avi")``:
#: "--out b.avi is a file").
_OUT_NAMES: contextvars.ContextVar[tuple[str, str]] = contextvars.ContextVar(
    "pftrack_batch_out_names", default=("out_dir", "options.render")
)


#: Called as ``say(name, warning)`` for each warning of a task as its outcome arrives
#: (:func:`warnings_as_they_come`); None: they are in the summary only.
_SAY_WARNING: contextvars.ContextVar[Callable[[str, str], None] | None] = contextvars.ContextVar(
    "pftrack_batch_say_warning", default=None
)


@contextlib.contextmanager
def warnings_as_they_come(say: Callable[[str, str], None]) -> Iterator[None]:
    """Meanwhile, ``say(name, warning)`` for each warning of a task as its outcome arrives.

    ``pftrack batch`` prints them so, each sequence's as it ends, before the table (was: all
    after the table, once the batch was over), as ``pftrack track`` prints its own as they are
    raised. Called on the thread that runs the batch; a skipped task's earlier warnings are
    not said (they are in the summary).
    """
    if not callable(say):  # was found out at the first warning, a traceback mid-batch
        raise TypeError(f"warnings_as_they_come: say is {shown(say)}, expected a callable")
    token = _SAY_WARNING.set(say)
    try:
        yield
    finally:
        _SAY_WARNING.reset(token)


@contextlib.contextmanager
def named_as_options() -> Iterator[None]:
    """Meanwhile, a batch's messages name ``--out`` and ``--render`` (``pftrack`` commands)."""
    token = _OUT_NAMES.set(("--out", "--render"))
    try:
        yield
    finally:
        _OUT_NAMES.reset(token)


def _batch_files(out_dir: Path, name: str) -> set[str]:
    """The files of `out_dir` an earlier batch's sidecar ``NAME.json`` names, itself included.

    Empty when there is no such sidecar (none, or a user's own file of that name).
    """
    entry = _read_sidecar(out_dir, name)
    if not (
        entry is not None
        and entry.get("name") == name
        and entry.get("kind") in ("track", "recover", "smooth")
        and isinstance(entry.get("outputs"), list)
    ):
        return set()
    listed = [*entry["outputs"], *(entry.get("earlier_outputs") or [])]
    return {_sidecar(out_dir, name).name, *(o for o in listed if isinstance(o, str))}


def _is_summary(path: Path) -> bool:
    """Whether the file `path` is a batch's ``summary.json`` (:meth:`BatchSummary.as_dict`)."""
    try:
        entry = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return isinstance(entry, dict) and {"kind", "counts", "settings"} <= set(entry)


def _check_outputs(
    jobs: Sequence[Job],
    out_dir: str | os.PathLike[str],
    suffixes: Sequence[str],
    force: bool = False,
) -> Path:
    """Before any work, writing nothing: no output overwrites an input or is a folder.

    Unless `force`, none replaces a file that no earlier batch wrote either (a user's
    ``NAME.txt`` beside ``NAME.avi`` in a folder that is also ``--out``).

    Returns `out_dir` as a Path (checked as given: an empty one is refused, not taken for the
    current folder).
    """
    out_name, render_name = _OUT_NAMES.get()
    out_dir = check_output_folder(out_dir, out_name)  # writable, or can be made, too
    # once: batches can be large; realpath, not resolve: a link loop met in a scanned folder
    # (a task that fails) made Python < 3.13's resolve raise RuntimeError, a traceback
    reads = {Path(os.path.realpath(p)) for job in jobs for p in job.reads}
    guarded = {_file_id(p) for job in jobs for p in job.guards} - {None}  # images: by inode
    names = [f"{job.name}{s}" for job in jobs for s in (".txt", ".json", *suffixes)]
    for name in [SUMMARY_NAME, *names]:
        target = out_dir / name
        if Path(os.path.realpath(target)) in reads or _file_id(target) in guarded:
            # which option makes it: a rendered video is --render's (was: always --out)
            rendered = any(name.endswith(s) for s in suffixes)
            what = f"{render_name}'s output {target}" if rendered else f"{out_name} {target}"
            raise ValueError(f"{what} is an input of this run; write elsewhere")
        if target.is_dir():
            raise ValueError(f"{out_name} {target} is a folder; it would be an output of this run")
    if force:
        return out_dir
    force_name = "--force" if out_name == "--out" else "force=True"
    summary = out_dir / SUMMARY_NAME
    if summary.exists() and not _is_summary(summary) and _cut_short(summary) is None:
        raise ValueError(
            f"{out_name} {summary} exists and is not a batch's summary; this run would replace "
            f"it: move it, write elsewhere, or give {force_name}"
        )
    from pftrack.io.video_writer import is_render  # here: it imports PyAV

    for job in jobs:
        ours = None  # read once a file of this job is found
        for name in (f"{job.name}{s}" for s in (".txt", ".json", *suffixes)):
            if not (out_dir / name).exists():
                continue
            if ours is None:
                ours = _batch_files(out_dir, job.name)
                if not ours and _cut_short(_sidecar(out_dir, job.name)) is not None:
                    # an earlier batch's sidecar, damaged: the job is redone, with a note
                    ours = {f"{job.name}{s}" for s in (".txt", ".json", *suffixes)}
            if name not in ours:
                why = f"no sidecar {job.name}.json of one names it"
                sidecar = _sidecar(out_dir, job.name)
                if _read_sidecar(out_dir, job.name) is None and sidecar.is_file():
                    # was: "no sidecar NAME.json", with one there
                    why = f"{job.name}.json is not JSON, nor the beginning of a batch's sidecar"
                raise ValueError(
                    f"{out_name} {out_dir / name} exists and no earlier batch wrote it ({why}); "
                    f"this run would replace it: move it, write elsewhere, or give {force_name}"
                )
            if any(name.endswith(s) for s in suffixes) and not replaceable(
                out_dir / name, is_render
            ):
                # named by a sidecar, but a video pftrack did not write put there since (was:
                # replaced without a word, where --render and pftrack render refuse it; the
                # rule of --render's check_replaceable, with the batch's message)
                raise ValueError(
                    f"{render_name}'s output {out_dir / name} is a video pftrack did not write "
                    "(a video of yours, put where an earlier batch's was?); this run would "
                    f"replace it: move it, write elsewhere, or give {force_name}"
                )
    return out_dir


def _file_id(path: Path) -> tuple[int, int] | None:
    """The ``(st_dev, st_ino)`` of the file `path` names (links followed); None if none."""
    try:
        st = path.stat()
    except OSError:
        return None
    return st.st_dev, st.st_ino


def _make_out_dir(out_dir: Path) -> None:
    """Create the output folder and check that it is writable (once the tasks can run)."""
    out_name = _OUT_NAMES.get()[0]
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:  # a read-only or special file system, a file on the way
        raise ValueError(
            f"{out_name} {out_dir}: cannot create the folder ({exc.strerror})"
        ) from None
    check_output(out_dir / SUMMARY_NAME, what=out_name)  # the folder is writable


@contextlib.contextmanager
def _held(out_dir: Path) -> Iterator[None]:
    """Hold `out_dir` while this batch writes into it: another batch there is refused.

    Two batches into one folder at once both ran every task and wrote over each other's
    outputs and sidecars (one's sidecar could vouch for the other's ``NAME.txt``). The hold is
    ``flock`` on the folder itself (no lock file left in it), released when the process ends,
    however it ends. A file system that takes no such lock (NFS's emulation refuses a folder
    opened to read) is not held.

    Raises
    ------
    ValueError
        Another batch holds the folder.
    """
    try:
        import fcntl
    except ImportError:  # not on a POSIX system: no hold
        yield
        return
    fd = os.open(out_dir, os.O_RDONLY)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise ValueError(
                f"{_OUT_NAMES.get()[0]} {out_dir}: another pftrack batch is writing into this "
                "folder: wait until it ends, or write elsewhere"
            ) from None
        except OSError:  # no locks on this file system
            pass
        yield
    finally:
        os.close(fd)


def run_jobs(
    jobs: Sequence[Job],
    out_dir: str | os.PathLike[str],
    *,
    kind: str,
    settings: dict[str, Any],
    suffixes: Sequence[str] = (),
    client: Client | None = None,
    scheduler: str | None = None,
    n_workers: int | None = None,
    force: bool = False,
    show_progress: bool | None = None,
) -> BatchSummary:
    """Run `jobs`, one task each, and write their outputs to `out_dir`.

    Parameters
    ----------
    jobs : sequence of Job
        The tasks (unique names).
    out_dir : path
        Output folder (created if missing).
    kind : {"track", "recover", "smooth"}
        What the jobs do (the table's columns).
    settings : dict
        JSON-ready settings shared by the jobs: stored in each sidecar, so that a re-run with
        other settings redoes the work.
    suffixes : sequence of str
        Extra outputs per job (``".mp4"``), checked before any work.
    client, scheduler, n_workers
        Where the tasks run, one of them at most (see :func:`dask_client`); ``n_workers=0``
        runs them one after the other in this process, without Dask. A cluster whose workers
        are all gone while tasks wait (none at the start, or all lost on the way) is waited for
        up to :func:`no_workers_timeout` seconds, with a warning at once; then the batch stops
        (none at the start: ``TimeoutError``) or the tasks left fail (lost on the way).
    force : bool
        Redo jobs whose outputs are complete.
    show_progress : bool, optional
        Progress bar over tasks on stderr (default: when stderr is a terminal).

    Returns
    -------
    BatchSummary
        Also written to ``out_dir/summary.json``. Failed tasks are in it with their error; the
        others finish.

    Raises
    ------
    ImportError
        Tasks are to run on Dask (`n_workers` is not 0) and Dask distributed is not installed
        (the message says how to install it); raised before any task runs or file is written.
    TypeError
        `client` is not a ``distributed.Client`` (an address goes in `scheduler`).
    ValueError
        A bad `scheduler` address (or Dask's ``scheduler-address`` setting), or more than one
        of `client`, `scheduler` and `n_workers` given; checked before anything else.
    PermissionError
        `out_dir` cannot take new files, or cannot be made (``check_output_folder``); checked
        before the cluster starts or the scheduler is connected to.
    ValueError
        Another batch is writing into `out_dir` (:func:`_held`); raised before any file is
        written.
    OSError
        The scheduler cannot be reached (see :func:`dask_client`), or it has no worker and none
        comes within :func:`no_workers_timeout` (a ``TimeoutError``); raised before `out_dir`
        is created or any file written.
    KeyboardInterrupt
        After cancelling the tasks still running and closing the cluster this started; the
        outputs written so far are complete. What the batch left (nothing, or how many tasks'
        outputs) is attached: :func:`interrupted_left`; once the run began, its summary too
        (:func:`interrupted_summary`), the finished tasks' entries and the rest cancelled.
    """
    _check_arguments(out_dir, n_workers, force, show_progress)
    address = where_to_run(client, scheduler, n_workers)  # checked even when nothing is to run
    start = time.perf_counter()
    out = _check_outputs(jobs, out_dir, suffixes, force)
    summary = BatchSummary(kind, out, settings=settings)
    entries: dict[str, dict[str, Any]] = {}
    notes: dict[str, str] = {}
    prints = {job.name: fingerprint(job.reads) for job in jobs}  # before the tasks read them
    found = {job.name: _outputs_there(out, job.name, suffixes) for job in jobs}
    pending: list[Job] = []
    refused = [job for job in jobs if job.refused is not None]  # certain to fail: not sent
    for job in jobs:
        if job.refused is not None:
            continue
        earlier, note = (
            (None, None) if force else _complete(out, job, kind, settings, prints[job.name])
        )
        if note:
            notes[job.name] = note
        if earlier is None:
            pending.append(job)
        else:
            drop = ("kind", "settings", "inputs", "fingerprint", "output_prints")
            keep = {k: v for k, v in earlier.items() if k not in drop}
            entries[job.name] = {**keep, "status": "skipped"}

    remote = False  # the tasks run on Dask workers: set once connected
    touched = False  # --out created (summary.json is written on the way out, whatever happens)
    written = 0  # tasks whose outputs this run wrote
    ran: set[str] = set()  # the workers that ran tasks (was: the count at the start alone)

    def record(job: Job, outcome: Outcome) -> None:
        def committed(entry: dict[str, Any]) -> None:  # its outputs in place: before a Ctrl-C
            nonlocal written  # that came during their renames is raised (_write)
            entries[job.name] = entry
            written += 1

        if outcome.worker is not None:
            ran.add(outcome.worker)
        other = _other_release(outcome) if remote else None
        if other is None and remote:
            other = _seen_otherwise(job, outcome, prints[job.name])
        if other is not None:  # not written: the outputs of files this process does not have
            outcome = Outcome(None, other, outcome.traceback, outcome.host)
        if outcome.result is not None:
            try:
                _write(out, job, outcome.result, kind, settings, prints[job.name], committed)
            except OSError as exc:  # a full disk: this task fails, the batch goes on (was:
                # stopped with exit status 2, "nothing ran", the task "cancelled"; a user trial)
                error = f"writing its outputs: {one_line(exc)}"
                outcome = Outcome(None, error, traceback.format_exc())
        if outcome.result is None:
            entries[job.name] = {
                "name": job.name,
                "status": "failed",
                "source": str(job.reads[0]) if job.reads else None,
                "error": _failure(job, outcome, remote),
                "traceback": outcome.traceback,
            }
            if outcome.host is not None:  # where it failed, as a done entry says where it ran
                entries[job.name]["host"] = outcome.host
            kept = [name for name, was in found[job.name].items() if _stat_of(out / name) == was]
            if kept:  # an earlier run's, as they were: said (was: beside the new outputs,
                # read by pftrack recover and eval of the folder as this run's, unsaid)
                entries[job.name]["kept"] = kept
        if job.name in notes:
            entries[job.name]["note"] = notes[job.name]
        say = _SAY_WARNING.get()
        if say is not None:  # as the task's outcome arrives, not with the table
            for warning in entries[job.name].get("warnings", ()):
                say(job.name, warning)

    for job in refused:  # before the cluster starts: the scheduler never sees them
        record(job, Outcome(None, job.refused))
        entries[job.name]["refused"] = True

    on_dask = bool(pending) and n_workers != 0
    if on_dask and client is None:
        _require_dask()  # before the summary: a missing extra changes no file
    desc = "sequences" if kind == "track" else "files"
    bar = {"total": len(pending), "desc": desc, "enable": show_progress}
    frames: _Frames | None = None
    # connected (or the local cluster started) before --out is touched; in a with statement of
    # its own: ExitStack.enter_context, interrupted (Ctrl-C) between entering the client and
    # noting its exit, left them open for the garbage collector to close (see _new_client)
    on: contextlib.AbstractContextManager[Client | None] = contextlib.nullcontext()
    if on_dask and (client is not None or address):
        on = dask_client(client, scheduler)  # None: the setting's address, named as such
    elif on_dask:  # a local cluster: no idle worker to start
        n = n_workers if n_workers is not None else usable_cpus()
        on = dask_client(n_workers=min(n, len(pending)))
    try:
        with on as c, contextlib.ExitStack() as stack:
            unusable: dict[str, str] | None = None
            if c is not None:
                remote = True
                unusable = stack.enter_context(_setup_failures(c))  # as soon as connected
                # a result lost with its worker is computed again and waited for (_taken): not
                # said in Dask's words, "Couldn't gather 1 keys, rescheduling (KEY,)", which a
                # user trial saw on stderr among the batch's lines after a worker's kill -9
                stack.enter_context(_dropped("distributed.client", _RESULT_LOST))
                info = c.scheduler_info()
                reported = str(info.get("address")) if info.get("address") else None
                summary.scheduler = address or reported  # the user's spelling of the address
                _wait_for_workers(c, summary.scheduler or "?", no_workers_timeout())
            if pending and enabled(show_progress) and all(job.count is not None for job in pending):
                # frames over all sequences; the clock starts once the cluster runs
                frames = stack.enter_context(_Frames(pending, desc, show_progress))
            _make_out_dir(out)
            stack.enter_context(_held(out))  # until summary.json is written
            made = _file_id(out)  # the folder written into: removed meanwhile, said at the end
            touched = True
            try:
                if c is not None:
                    wait = no_workers_timeout()
                    where = summary.scheduler or "?"
                    _run_on_dask(
                        c, _largest_first(pending, prints), record, summary.kind, bar, frames,
                        where, wait, unusable,
                        lambda job, outcome: _unseen_input(job, outcome, prints[job.name]),
                    )  # fmt: skip
                elif frames is not None:
                    for job in pending:
                        with _no_bars():
                            outcome = call_task(job.func, job.args, frames.reporter(job.name))
                        record(job, outcome)
                        frames.finish(job.name)
                elif pending:
                    for job in progress(pending, **bar):  # type: ignore[arg-type]
                        with _no_bars():
                            outcome = call_task(job.func, job.args)
                        record(job, outcome)
                # a Ctrl-C that code in C dropped after the last task's outputs were written
                # (each write checks it before): the batch ends as interrupted, as it came
                raise_if_interrupted()
            finally:
                for job in jobs:
                    entries.setdefault(job.name, {"name": job.name, "status": "cancelled"})
                summary.entries = [entries[job.name] for job in jobs]
                summary.seconds = time.perf_counter() - start
                summary.workers = len(ran)  # not the count at the start: those that ran tasks
                try:
                    summary.unwritten = _out_removed(out, made, summary)
                    if summary.unwritten is None:  # also after Ctrl-C: it lists what was left
                        with written_anyway(), atomic_write(out / SUMMARY_NAME) as fh:
                            fh.write(summary.to_json() + "\n")
                except OSError as exc:  # was: exit status 2 with this error alone, no table
                    summary.unwritten = (
                        f"{out / SUMMARY_NAME} not written ({exc.strerror or one_line(exc)}); "
                        "the outputs written before it are complete"
                    )
    except KeyboardInterrupt as exc:  # Ctrl-C, SIGTERM: say what it left, truthfully
        _say_interrupted(exc, out, kind, written if touched else None, summary.unwritten)
        if touched:  # its table, as a batch that ends prints it (was: in summary.json alone)
            exc.pftrack_batch_summary = summary  # type: ignore[attr-defined]
        raise
    return summary


def _largest_first(jobs: Sequence[Job], prints: dict[str, list[dict[str, Any]]]) -> list[Job]:
    """`jobs` in the order they go to a cluster: the most bytes read first, ties as given.

    The bytes a task reads (its inputs' sizes in their :func:`fingerprint`, taken already;
    a video's or an image folder's) stand for its work, the frames times their size, known
    without opening a video. Dask runs a batch's tasks in the order they were submitted: a long
    sequence given last ran alone at the end while the other workers idled (four short videos
    and a long one on two workers: the long one's whole run after the others). The outputs,
    the summary's order and the progress bar are the same either way.
    """

    def size(job: Job) -> int:
        return sum(int(entry.get("size", 0)) for entry in prints[job.name])

    return sorted(jobs, key=lambda job: -size(job))


def _out_removed(out: Path, made: tuple[int, int] | None, summary: BatchSummary) -> str | None:
    """Why `summary` is not written: `out` (`made` its file id) was removed meanwhile; or None.

    The outputs of the entries done or skipped that are not there now are named, lost. Was: the
    last line said "the outputs written before it are complete", of files gone with the folder;
    and a folder made again meanwhile (``rm -r out; mkdir out``) got a ``summary.json`` whose
    entries said ``done`` of outputs not there.
    """
    now = _file_id(out)
    if made is None or now == made:
        return None
    another = " (the folder there now is another one)" if now is not None else ""
    lost = [
        e["name"]
        for e in summary.entries
        if e["status"] in ("done", "skipped") and not _sidecar(out, e["name"]).exists()
    ]  # those written into a folder made again meanwhile are there
    noun = "sequence" if summary.kind == "track" else "file"
    if lost:
        what = f"the outputs of {counted(len(lost), noun)} ({listed(lost)}) went with it, and "
    else:
        what = "no output had been written in it; "
    again = " to make them again" if lost else ""
    return (
        f"{_OUT_NAMES.get()[0]} {out} was removed while the batch ran{another}: {what}"
        f"{SUMMARY_NAME} is not written; re-run the batch{again}"
    )


def _check_arguments(out_dir: object, n_workers: object, force: object, show: object) -> None:
    """Refuse arguments of :func:`run_jobs` of another type or range, naming them.

    Was: ``force="no"`` forced (files no batch wrote replaced), ``n_workers=2.5`` or ``True``
    ran, and ``n_workers="2"`` or ``out_dir=None`` failed in Python's words.
    """
    if not isinstance(out_dir, (str, bytes, os.PathLike)):
        raise TypeError(
            f"{_OUT_NAMES.get()[0]} must be a path (str or os.PathLike), got {shown(out_dir)}"
        )
    if n_workers is not None:
        if isinstance(n_workers, bool) or not isinstance(n_workers, numbers.Integral):
            raise TypeError(
                "n_workers must be an integer >= 0 or None, got "
                f"{type(n_workers).__name__} {n_workers!r}"
            )
        if n_workers < 0:
            raise ValueError(f"n_workers is {n_workers}, expected >= 0")
    flag(force, "force")
    if show is not None and not isinstance(show, bool):
        raise TypeError(f"show_progress must be True, False or None, got {shown(show)}")


@contextlib.contextmanager
def _no_bars() -> Iterator[None]:
    """Meanwhile, no new progress bar (a task run in this process: the batch's bar is drawn).

    As the worker plugin makes the workers quiet (:mod:`pftrack.batch._plugin`): the bars of
    the code a task calls (``auto: calibrating``, ``smoothing``) were drawn under the batch's.
    """
    was = quiet()
    set_quiet(True)
    try:
        yield
    finally:
        set_quiet(was)


def _say_interrupted(
    exc: KeyboardInterrupt, out: Path, kind: str, written: int | None, unwritten: str | None = None
) -> None:
    """Attach what an interrupted batch left to `exc` (printed by the command).

    `written`: the tasks whose outputs this run wrote; None when ``--out`` was not touched yet
    (stopped while connecting, or while the local cluster started). `unwritten`: why
    ``summary.json`` was not written (``BatchSummary.unwritten``: ``--out`` removed meanwhile,
    :func:`_out_removed`), said instead. Was: "the outputs written so far are complete" whatever
    was written, nothing at all included; and, with ``--out`` removed, "are written and
    complete", of outputs gone with it.
    """
    noun = "sequence" if kind == "track" else "file"
    if unwritten is not None:
        text = unwritten
    elif written is None:
        text = (
            f"nothing was written: it stopped before the run began ({_OUT_NAMES.get()[0]} "
            f"{out} untouched)"
        )
    elif written == 0:
        text = (
            f"no {noun} was finished; {out / SUMMARY_NAME} lists them as cancelled (re-run to "
            "run them)"
        )
    else:
        text = (
            f"the outputs of the {counted(written, noun)} finished are written and complete; "
            f"{out / SUMMARY_NAME} lists the rest as cancelled (re-run to finish them)"
        )
    exc.pftrack_batch_left = text  # type: ignore[attr-defined]


def interrupted_left(exc: BaseException) -> str | None:
    """What an interrupted batch left, as :func:`run_jobs` attached it to `exc` (or None)."""
    text = getattr(exc, "pftrack_batch_left", None)
    return text if isinstance(text, str) else None


def interrupted_summary(exc: BaseException) -> BatchSummary | None:
    """The summary of an interrupted batch, as :func:`run_jobs` attached it to `exc`.

    Its entries are those of ``summary.json`` (``done``, ``skipped``, ``failed``, the rest
    ``cancelled``); None when the batch stopped before its run began (nothing written).
    """
    summary = getattr(exc, "pftrack_batch_summary", None)
    return summary if isinstance(summary, BatchSummary) else None


#: Seconds a batch waits for a worker on a cluster that has none, unless Dask's
#: ``distributed.scheduler.no-workers-timeout`` says otherwise (:func:`no_workers_timeout`).
NO_WORKERS_WAIT = 60.0
#: Seconds between two counts of a cluster's workers while tasks wait on it.
WORKERS_POLL = 1.0
#: Seconds between two looks for finished tasks.
COMPLETED_POLL = 0.05
#: Seconds of the first wait for a finished task's result (:func:`_taken`); each next wait is
#: twice as long, so that a large result (a rendered video) has the time to come.
RESULT_WAIT = 1.0


def no_workers_timeout() -> float:
    """How long a batch waits for a worker on a cluster that has none, in seconds.

    Dask's ``distributed.scheduler.no-workers-timeout`` (a scheduler's setting, read here in
    this process: ``DASK_DISTRIBUTED__SCHEDULER__NO_WORKERS_TIMEOUT=120s``) when set, else
    :data:`NO_WORKERS_WAIT` (Dask's own default, none, waits forever).

    Raises
    ------
    ValueError
        The setting is not a duration.
    """
    seconds = dask_seconds("distributed.scheduler.no-workers-timeout", "60s")
    return NO_WORKERS_WAIT if seconds is None else seconds


def dask_seconds(key: str, example: str) -> float | None:
    """Dask's duration setting `key`, in seconds; None when it is not set.

    Raises
    ------
    ValueError
        The setting is not a finite duration >= 0: one line naming it, its environment
        variable and an `example` (was: Dask's traceback, "KeyError: 'Invalid time unit: abc
        ...'", from the connection or from a local cluster's start, for a setting the help
        names).
    """
    import dask
    from dask.utils import parse_timedelta

    value = dask.config.get(key, None)
    if value is None:
        return None
    try:
        seconds = float(parse_timedelta(value, default="s"))
    except (TypeError, ValueError, KeyError):
        seconds = math.nan
    if not seconds >= 0 or math.isinf(seconds):
        variable = "DASK_" + key.upper().replace(".", "__").replace("-", "_")
        raise ValueError(
            f"{key} is {brief(value)} (${variable}), expected a duration such as '{example}'"
        )
    return seconds


#: Dask's worker memory thresholds, fractions of a worker's memory limit (or False: none).
MEMORY_FRACTIONS = tuple(
    f"distributed.worker.memory.{k}" for k in ("target", "spill", "pause", "terminate")
)


def dask_fraction(key: str) -> float | None:
    """Dask's memory threshold `key`, a fraction from 0 to 1; None when off (False) or not set.

    Raises
    ------
    ValueError
        The setting is neither False nor a number from 0 to 1: one line naming it and its
        environment variable (was: each local worker's traceback, about 30 lines, and a bare
        ``MemoryError`` at the end).
    """
    import dask

    value = dask.config.get(key, None)
    if value is None or value is False:
        return None
    if isinstance(value, (int, float)) and not isinstance(value, bool) and 0 <= value <= 1:
        return float(value)
    variable = "DASK_" + key.upper().replace(".", "__").replace("-", "_")
    raise ValueError(
        f"{key} is {brief(value)} (${variable}), expected a fraction from 0 to 1 or False"
    )


def _n_workers(c: Client, timeout: float | None = None) -> int:
    """The scheduler's workers now, as the scheduler counts them (its ``identity``).

    Not ``len(c.scheduler_info()["workers"])``: the client refreshes that cache every 2 s
    (``distributed.client.scheduler-info-interval``) with an identity that lists no worker
    (Dask 2026.8), and one such refresh between ``scheduler_info``'s own fetch and its return
    gave an empty list (134 of 1098 calls at a 5 ms interval with 2 workers running): "the
    scheduler has lost all its workers" while they ran. The ``n_workers`` key, where the Dask
    has it, counts them all; an older Dask lists them all. With the connection going (an
    OSError), what the client last heard.

    Raises
    ------
    TimeoutError
        The scheduler did not answer within `timeout` seconds (None: no limit).
    """
    rpc = c.scheduler
    try:
        if rpc is None:
            info = c.scheduler_info()
        else:
            info = c.sync(rpc.identity, callback_timeout=timeout)
    except TimeoutError:
        raise
    except OSError:
        info = c.scheduler_info()
    n = info.get("n_workers")
    if isinstance(n, int) and n >= 0:
        return n
    return len(info.get("workers") or {})


def _no_workers(address: str, wait: float) -> str:
    return f"waiting up to {wait:g} s for one (start one: dask worker {address})"


def _wait_for_workers(c: Client, address: str, wait: float) -> int:
    """The cluster's workers, once it has one: none yet is said at once, and waited for.

    Workers that come after a wait are checked as :func:`dask_client` checks those there at
    the start: they can import pftrack (:func:`check_pftrack`).

    Raises
    ------
    TimeoutError
        None came within `wait` seconds.
    ImportError
        The workers that came cannot import pftrack.
    """
    n = _n_workers(c)
    if n:
        return n
    warn(f"the scheduler at {address} has no workers; {_no_workers(address, wait)}", stacklevel=4)
    deadline = time.monotonic() + wait
    while not (n := _n_workers(c)):
        if time.monotonic() >= deadline:
            raise TimeoutError(
                f"the scheduler at {address} has no workers: none came within {wait:g} s "
                f"(start them with: dask worker {address}; the wait is Dask's "
                "distributed.scheduler.no-workers-timeout, "
                "$DASK_DISTRIBUTED__SCHEDULER__NO_WORKERS_TIMEOUT)"
            )
        time.sleep(min(0.2, wait))
    check_pftrack(c, address, scheduler=False)
    return n


#: Seconds the scheduler has to answer a count of its workers while tasks wait on it. One that
#: does not (frozen: stopped, swapping, its event loop blocked) is said to be so, and waited for
#: as long as for a worker (:func:`no_workers_timeout`); was: waited for, silently, for ever.
ANSWER_WAIT = 5.0


@contextlib.contextmanager
def _setup_failures(c: Client) -> Iterator[dict[str, str]]:
    """The workers whose pftrack plugin fails to set up from now on: address -> error.

    Such a worker (one that cannot import pftrack, joining after :func:`check_pftrack` ran)
    dies on the first task it is given, Dask unable to unpickle it, too soon for the count of
    the workers to see it. Its plugin's setup says so on
    :data:`~pftrack.batch._plugin.SETUP_FAILED_TOPIC`, to which this subscribes.
    """
    from pftrack.batch._plugin import SETUP_FAILED_TOPIC

    failed: dict[str, str] = {}

    def on_event(event: Any) -> None:  # on the client's event loop
        with contextlib.suppress(TypeError, ValueError):
            worker, error = event[1]
            failed.setdefault(str(worker), str(error))

    c.subscribe_topic(SETUP_FAILED_TOPIC, on_event)
    try:
        yield failed
    finally:
        with contextlib.suppress(Exception):  # the cluster may be going away (Ctrl-C)
            c.unsubscribe_topic(SETUP_FAILED_TOPIC)


class _WorkersWatch:
    """While tasks wait on a cluster: tells when it has been without workers for too long.

    Or when its scheduler has not answered for that long (:data:`ANSWER_WAIT`): ``frozen``.
    """

    def __init__(
        self, c: Client, address: str, wait: float, unusable: dict[str, str] | None = None
    ) -> None:
        self.c, self.address, self.wait = c, address, wait
        self.since: float | None = None  # when the workers were last seen gone
        self.silent: float | None = None  # when the scheduler was first asked in vain
        self.frozen = False
        self._checked = -math.inf
        #: workers that joined but cannot import pftrack: address -> error, as they said it
        self.unusable = unusable if unusable is not None else {}
        self._said: set[str] = set()

    def _unusable(self) -> str:
        """The workers that joined but cannot import pftrack, said; or ``""``."""
        if not self.unusable:
            return ""
        workers = ", ".join(self.unusable)
        first = next(iter(self.unusable.values()))
        which = "a worker" if len(self.unusable) == 1 else f"{len(self.unusable)} workers"
        dies = "dies" if len(self.unusable) == 1 else "die"
        return (
            f"{which} that joined ({workers}) cannot import pftrack ({first}) and {dies} on the "
            f"first task given: {INSTALL_EVERYWHERE}"
        )

    def given_up(self) -> bool:
        """True once the cluster has had no worker for `wait` seconds (warns when they go).

        True too once the scheduler has not answered for `wait` seconds (warns once it has
        not answered for :data:`ANSWER_WAIT`). Warns too when workers come back, or the
        scheduler answers, after such a warning: the batch goes on.
        """
        now = time.monotonic()
        if now - self._checked < WORKERS_POLL:
            return False
        self._checked = now
        new = [w for w in self.unusable if w not in self._said]
        if new:  # said once each, here (the main thread), not on Dask's
            self._said.update(new)
            warn(f"the scheduler at {self.address}: {self._unusable()}", stacklevel=2)
        try:
            n = _n_workers(self.c, ANSWER_WAIT)
        except TimeoutError:
            if self.silent is None:
                self.silent = now
                warn(
                    f"the scheduler at {self.address} has not answered for {ANSWER_WAIT:g} s "
                    f"(frozen or overloaded?); waiting up to {self.wait:g} s for it",
                    stacklevel=2,
                )
            self.frozen = time.monotonic() - self.silent >= self.wait
            return self.frozen
        if self.silent is not None:  # said it was silent: say it answers (a trial)
            warn(
                f"the scheduler at {self.address} answers again after {now - self.silent:.0f} s; "
                "the batch goes on",
                stacklevel=2,
            )
        self.silent = None
        if n:
            if self.since is not None:  # said they were lost: say the batch goes on (a trial)
                warn(
                    f"the scheduler at {self.address} has {counted(n, 'worker')} again after "
                    f"{now - self.since:.0f} s; the batch goes on",
                    stacklevel=2,
                )
            self.since = None
            return False
        if self.since is None:
            self.since = now
            warn(
                f"the scheduler at {self.address} has lost all its workers; "
                f"{_no_workers(self.address, self.wait)}",
                stacklevel=2,
            )
        return now - self.since >= self.wait

    def killed(self, exc: BaseException, noun: str) -> str | None:
        """The error of a task that Dask's ``KilledWorker`` failed on a worker without pftrack.

        Such a worker (restarted by its nanny after pftrack was removed from its environment,
        or started without it) dies on every task it is given, and the task failed with Dask's
        generic "Attempted to run task ... on 4 different workers"; None: `exc` is no
        ``KilledWorker``, or its last worker is not one that said it cannot import pftrack.
        """
        if type(exc).__name__ != "KilledWorker":
            return None
        worker = getattr(getattr(exc, "last_worker", None), "address", None)
        if worker is None or str(worker) not in self.unusable:
            return None
        failures = getattr(exc, "allowed_failures", None)
        last = f", the last of {failures + 1} workers that did" if isinstance(failures, int) else ""
        return (
            f"pftrack missing on worker {worker} ({self.unusable[str(worker)]}): it joined "
            f"without pftrack (restarted by its nanny after pftrack was removed?) and died on "
            f"this {noun}{last} (Dask's KilledWorker); {INSTALL_EVERYWHERE}"
        )

    def error(self, noun: str) -> str:
        """The error of a task left waiting when :meth:`given_up`."""
        if self.frozen:
            return (
                f"the scheduler at {self.address} did not answer for {self.wait:g} s (frozen "
                f"or overloaded) before this {noun} finished (a re-run does the rest)"
            )
        unusable = self._unusable()
        if unusable:  # was: "start some", of a worker started and lost without a word
            return (
                f"no worker on the scheduler at {self.address} for {self.wait:g} s: its "
                f"workers were lost before this {noun} ran or finished; {unusable} (a re-run "
                "does the rest)"
            )
        return (
            f"no worker on the scheduler at {self.address} for {self.wait:g} s: its workers "
            f"were lost before this {noun} ran or finished (start some: dask worker "
            f"{self.address}; a re-run does the rest)"
        )


def _scheduler_lost(address: str, noun: str) -> str:
    """The error of a task whose future Dask cancelled because the scheduler went away.

    Was: left ``cancelled``, and a batch whose every task was lost so exited 0.
    """
    return (
        f"the connection to the scheduler at {address} was lost before this {noun} finished "
        "(the scheduler stopped, or the network failed; a re-run does the rest)"
    )


def _connection_lost(c: Client, fut: Any) -> bool:
    """Whether Dask cancelled the future `fut` because `c` lost its scheduler (not a cancel).

    Dask's reason for it (``scheduler-connection-lost``; a client that has reconnected since
    says so too), else, with a Dask that gives none, the client not connected.
    """
    try:
        fut.result(timeout=5)
    except KeyboardInterrupt:
        raise
    except BaseException as exc:  # noqa: BLE001 - Dask's FutureCancelledError: asyncio's kind
        reason = getattr(exc, "reason", None)
        if reason is not None:
            return bool(reason == "scheduler-connection-lost")
    return bool(c.status != "running")


def _completed(futures: Any, given_up: Callable[[], bool]) -> Iterator[Any]:
    """The futures of `futures` (``as_completed``) as they finish; stops early on `given_up`."""
    while True:
        ready = futures.next_batch(block=False)
        if ready:
            yield from ready
        elif futures.is_empty() or given_up():
            return
        else:
            time.sleep(COMPLETED_POLL)


def _taken(fut: Any, given_up: Callable[[], bool]) -> tuple[str, Any]:
    """The result of `fut`, a future seen finished, waited for in bounded steps.

    ``("finished", result)``; ``("lost", None)`` when `fut` is no longer finished (its result
    lost with its worker: Dask computes it again, or it failed or was cancelled meanwhile);
    ``("given up", None)`` when `given_up` says so between two steps (no worker for too long,
    the scheduler frozen). Was: ``fut.result()`` without a bound, which waited for ever when the
    worker holding the result died and no worker was left ("Couldn't gather 1 keys,
    rescheduling"). A step that times out cancels Dask's gather, hence steps twice as long
    each time (:data:`RESULT_WAIT`, 2, 4, ... s): a large result is taken at last.
    """
    wait = RESULT_WAIT
    while True:
        try:
            return "finished", fut.result(timeout=wait)
        except Exception as exc:  # noqa: BLE001 - whatever it is, once the future is no more done
            if fut.status != "finished":
                return "lost", None
            if not isinstance(exc, TimeoutError):
                raise
        if given_up():
            return "given up", None
        wait *= 2


class _Frames:
    """The bar of frames over all the sequences of a batch, and the counts that move it.

    Each task reports the frames it has tracked (in this process, or as Dask events from a
    worker); a finished task counts for all its frames (a failed one too: none are left to do),
    so that the time left is that of the work left. An input that cannot be read counts 0
    frames and is named in the label (``0/2 sequences, 1 unreadable``): the total stays that
    of the others (was: no total, no time left, for one unreadable video).
    """

    def __init__(self, pending: Sequence[Job], noun: str, enable: bool | None) -> None:
        self._counts = {job.name: job.count() if job.count is not None else None for job in pending}
        known = [n for n in self._counts.values() if n is not None]
        total = sum(known) if len(known) == len(self._counts) else None  # else no ETA
        self._unreadable = sum(n == 0 for n in known)
        self._noun = noun
        self._done: dict[str, int] = {}
        self._sum = 0
        self._finished = 0
        self._lock = threading.Lock()
        self.bar = Bar(total, desc=self._desc(), enable=enable, unit="frame")

    def _desc(self) -> str:
        unreadable = f", {self._unreadable} unreadable" if self._unreadable else ""
        return f"{self._finished}/{len(self._counts)} {self._noun}{unreadable}"

    def report(self, name: str, n: int) -> None:
        """Task `name` has tracked `n` frames."""
        with self._lock:
            if name in self._done and self._done[name] >= n:
                return  # a late event of a finished task, or out of order
            self._sum += n - self._done.get(name, 0)
            self._done[name] = n
            self.bar.set(self._sum)

    def reporter(self, name: str) -> Callable[[int], None]:
        """``report`` for the task `name` (in this process)."""
        return lambda n: self.report(name, n)

    def on_event(self, event: Any) -> None:
        """A Dask event ``(time, [name, n])`` from a worker's task."""
        name, n = event[1]
        self.report(str(name), int(n))

    def __enter__(self) -> _Frames:
        return self

    def __exit__(self, *exc: object) -> None:
        self.bar.close()

    def finish(self, name: str) -> None:
        """Task `name` is over (done, failed or cancelled)."""
        self.report(name, self._counts.get(name) or self._done.get(name, 0))
        with self._lock:
            self._finished += 1
            self.bar.describe(self._desc())


def _not_utf8(job: Job) -> str | None:
    r"""Why `job` cannot go to a Dask worker: a path whose name is not UTF-8, or None.

    Dask sends a task's arguments as MessagePack, whose text is UTF-8: a file name of other
    bytes (``caf\xe9.mp4`` from a Latin-1 disk, which Python holds with surrogate escapes)
    broke the connection for every task of the batch, each said to have lost the scheduler (a
    user trial). Such a task runs with ``--workers 0`` (in this process).
    """

    def names(value: Any) -> Iterator[str]:
        if isinstance(value, (str, os.PathLike)):
            yield os.fspath(value) if not isinstance(value, bytes) else ""
        elif isinstance(value, (tuple, list)):
            for v in value:
                yield from names(v)
        elif isinstance(value, dict):
            for k, v in value.items():
                yield from names(k)
                yield from names(v)

    for text in names((job.name, job.args, job.reads)):
        try:
            text.encode("utf-8")
        except UnicodeEncodeError:
            shown = os.fsencode(text).decode("utf-8", "backslashreplace")
            return (
                f"{shown}: the name is not UTF-8, which Dask cannot send to a worker; rename "
                "it, or run this batch in this process (--workers 0)"
            )
    return None


def _worker_addresses(c: Client) -> set[str] | None:
    """The addresses of the scheduler's workers now (None: it did not answer in time)."""
    rpc = c.scheduler
    if rpc is None:
        return None
    try:
        info = c.sync(rpc.identity, n_workers=-1, callback_timeout=ANSWER_WAIT)
    except Exception:  # noqa: BLE001 - frozen, gone, or an older Dask: the task fails as it did
        return None
    return set(info.get("workers") or {})


class _Blind:
    """Where to send again the tasks of workers that could not see their inputs.

    A worker that cannot see the inputs (another mount namespace, a share not mounted there)
    fails every task it is given, fast, so it took most of the queue while the good workers
    idled, and each of those sequences failed. Such a task goes again to the workers that have
    not failed to see its inputs (Dask's ``workers=`` restriction), and the worker is named
    once (a warning). The task fails, as before, once no worker is left to try.
    """

    def __init__(self, c: Client, address: str, unseen: Callable[[Job, Outcome], Path | None]):
        self.c, self.address, self.unseen = c, address, unseen
        self.tried: dict[str, set[str]] = {}  # job name -> the workers that could not see it
        self.last: dict[str, Outcome] = {}  # job name -> the latest such outcome
        self.named: set[str] = set()
        self._checked = -math.inf

    def elsewhere(self, job: Job, outcome: Outcome) -> set[str] | None:
        """The workers to send `job` to, its `outcome` from a worker blind to it; or None."""
        path = self.unseen(job, outcome)
        if path is None or outcome.worker is None:
            return None
        if outcome.worker not in self.named:
            self.named.add(outcome.worker)
            warn(
                f"the scheduler at {self.address}: the worker {outcome.worker} cannot see the "
                f"inputs this process sees ({path} not found on {outcome.host}): its tasks go "
                "to the other workers (workers must see the same paths)",
                stacklevel=3,
            )
        self.tried.setdefault(job.name, set()).add(outcome.worker)
        self.last[job.name] = outcome
        return self.others(job)

    def others(self, job: Job) -> set[str] | None:
        """The workers there now that have not failed to see `job`'s inputs; None: none."""
        now = _worker_addresses(self.c)
        left = None if now is None else now - self.tried.get(job.name, set())
        return left or None

    def stranded(self, sent: dict[Any, set[str]]) -> set[Any] | None:
        """The keys of `sent` (key -> the workers it may run on) whose workers are all gone.

        Checked once a second at most; None meanwhile. Such a task would wait for ever (Dask
        keeps it for those workers), as the watch of the workers counts the others.
        """
        now = time.monotonic()
        if not sent or now - self._checked < WORKERS_POLL:
            return None
        self._checked = now
        there = _worker_addresses(self.c)
        if there is None:
            return None
        return {key for key, allowed in sent.items() if not allowed & there}


def _run_on_dask(
    c: Client,
    pending: Sequence[Job],
    record: Callable[[Job, Outcome], None],
    kind: str,
    bar: dict[str, Any],
    frames: _Frames | None = None,
    address: str = "?",
    wait: float = NO_WORKERS_WAIT,
    unusable: dict[str, str] | None = None,
    unseen: Callable[[Job, Outcome], Path | None] | None = None,
) -> None:
    """Submit `pending` to Dask and record each result as it completes.

    With `frames`, the tasks' frame counts come as Dask events on a topic of this run. A
    cluster without workers for `wait` seconds (at `address`) fails the tasks left; the
    workers that joined but cannot import pftrack (`unusable`, from :func:`_setup_failures`)
    are named then, and as they come. With `unseen` (the input a task's worker could not see,
    :func:`_unseen_input`), such a task goes to the other workers (:class:`_Blind`).
    """
    from distributed import as_completed

    topic = f"pftrack-progress-{os.urandom(4).hex()}"
    if frames is not None:
        c.subscribe_topic(topic, frames.on_event)
    sendable = []
    for job in pending:
        unsent = _not_utf8(job)
        if unsent is None:
            sendable.append(job)
        else:  # it alone fails (was: every task, "the connection to the scheduler was lost")
            if frames is not None:
                frames.finish(job.name)
            record(job, Outcome(None, unsent))
    # the files' bar (no frames to count) moves as each job is recorded: once (was: as each
    # future came back, so a task sent again or computed again counted twice, 4/3)
    files = (
        None if frames is not None else Bar(len(sendable), desc=bar["desc"], enable=bar["enable"])
    )
    n_finished = 0

    def finished(job: Job) -> None:
        """`job` is over (recorded), whatever its outcome: the bar counts it."""
        nonlocal n_finished
        if frames is not None:
            frames.finish(job.name)
        elif files is not None:
            n_finished += 1
            files.set(n_finished)

    watch = _WorkersWatch(c, address, wait, unusable)
    blind = _Blind(c, address, unseen) if unseen is not None else None
    futures = {}
    sent: dict[Any, set[str]] = {}  # the keys sent to some workers only: key -> those workers

    def submit(job: Job, workers: set[str] | None = None) -> Any:
        key = f"pftrack-{kind}-{job.name}-{os.urandom(4).hex()}"
        where = (topic, job.name) if frames is not None else None
        fut = c.submit(
            call_task, job.func, job.args, where, job.reads, key=key, pure=False,
            workers=sorted(workers) if workers else None,
        )  # fmt: skip
        futures[fut.key] = (fut, job)
        if workers:
            sent[fut.key] = workers
        return fut

    for job in sendable:
        submit(job)
    noun = "sequence" if kind == "track" else "file"
    tracked = as_completed([f for f, _ in futures.values()])

    def given_up() -> bool:  # and the tasks sent to workers all gone since: to the others
        for key in (blind.stranded(sent) if blind is not None else None) or ():
            fut, job = futures.pop(key)
            del sent[key]
            fut.cancel()
            workers = blind.others(job) if blind is not None else None
            if workers:
                tracked.add(submit(job, workers))
            else:
                finished(job)
                record(job, blind.last[job.name] if blind is not None else Outcome(None))
        return watch.given_up()

    done = _completed(tracked, given_up)
    try:
        for fut in done:
            if fut.key not in futures:  # cancelled and sent again (its workers gone)
                continue
            status = fut.status
            if status not in ("finished", "error", "cancelled"):
                # finished, then its result lost with its worker before it was taken: Dask
                # computes it again ("lost", "pending"); was: left out, "cancelled", not written
                tracked.add(fut)
                continue
            taken, outcome = _taken(fut, watch.given_up) if status == "finished" else ("", None)
            if taken == "lost":  # lost with its worker as it was taken: as above
                tracked.add(fut)
                continue
            if taken == "given up":  # no worker left for it: failed below, as those waiting
                break
            _, job = futures.pop(fut.key)
            sent.pop(fut.key, None)
            workers = (
                blind.elsewhere(job, outcome) if blind is not None and outcome is not None else None
            )
            if workers:  # its worker could not see its inputs: to the others
                tracked.add(submit(job, workers))
                fut.release()
                continue
            finished(job)
            if outcome is not None:
                record(job, outcome)
            elif status == "error":  # the worker died (KilledWorker) or the like
                exc = fut.exception()
                # the scheduler's own no-workers-timeout: said as this process's watch says it
                lost = type(exc).__name__ == "NoWorkerError"
                error = watch.error(noun) if lost else watch.killed(exc, noun) or one_line(exc)
                record(job, Outcome(None, error))
            elif status == "cancelled" and _connection_lost(c, fut):  # Dask cancels them all
                record(job, Outcome(None, _scheduler_lost(address, noun)))
            fut.release()  # cancelled (by another client): left "cancelled" in the summary
        if futures:  # given up: no worker for too long
            c.cancel([f for f, _ in futures.values()], force=True)
            for _, job in list(futures.values()):
                finished(job)
                record(job, Outcome(None, watch.error(noun)))
            futures.clear()
    except BaseException:
        c.cancel([f for f, _ in futures.values()], force=True)
        raise
    finally:
        if files is not None:
            files.close()
        if frames is not None:
            with contextlib.suppress(Exception):  # the cluster may be going away (Ctrl-C)
                c.unsubscribe_topic(topic)
