"""Where each thread of ``pftrack track`` spends its wall time (issue 17).

Runs ``pftrack -q track SOURCE --out OUT`` in this process with timers around the parts of the
run, kept per thread: decoding (``VideoCapture.read``, ``grab``, ``set``), the working frame and
the camera's grey made on the reading thread, the detector (``PaperDetector.detect``,
``foreground``), ``Tracker.update``, the start-up (``bootstrap_frames``, ``Tracker.prime``), the
offline pass (``Tracker.finalize``), and the waits of the hand-over between threads
(``queue.Queue.get``: for an item; ``put``: for room). Each thread's CPU time is read as it
ends. The two ``pftrack-prefetch`` threads are told apart by what they did: the one that
detected is the detector's, the one that decoded the reader's.

A thread whose wall time is mostly its own work, while the others wait for it in ``get``, is
the run's critical path; two threads that both wait a lot show a hand-over that costs more than
the work (or a machine busy with other processes: the timers measure wall time). The timers
add a few microseconds a call, the same for any version of pftrack: the figures are for
comparing two versions run alternately, not absolute costs.

Usage (from the repository root)::

    python -m experiments.thread_times /tmp/speed/p720.avi [--out tracks.txt] [-- --no-link]
"""

from __future__ import annotations

import argparse
import queue
import tempfile
import threading
import time
from collections import defaultdict
from collections.abc import Callable, Iterator, Sequence
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pftrack.io.video as video
import pftrack.tracking.run as run
from pftrack.cli import main as pftrack_main
from pftrack.detection.paper import PaperDetector
from pftrack.tracking.api import Tracker
from pftrack.tracking.camera import CameraMotion


@dataclass
class ThreadTimes:
    """One thread's timed parts: seconds and calls per part, its CPU and wall time."""

    name: str
    seconds: dict[str, float] = field(default_factory=lambda: defaultdict(float))
    calls: dict[str, int] = field(default_factory=lambda: defaultdict(int))
    cpu: float | None = None  # None: still running when the run ended (the main thread)
    wall: float | None = None

    @property
    def role(self) -> str:
        """The thread's name, and for a prefetch thread what it did (detector or reader)."""
        if self.name != "pftrack-prefetch":
            return self.name
        if "detect" in self.calls or "foreground" in self.calls:
            return "pftrack-prefetch (detector)"
        return "pftrack-prefetch (reader)"


class Timers:
    """Timers per thread, around methods patched for the length of :meth:`installed`."""

    def __init__(self) -> None:
        self._live: dict[int, ThreadTimes] = {}  # by thread ident (reused once a thread ends)
        self._ended: list[ThreadTimes] = []
        self._lock = threading.Lock()

    @property
    def threads(self) -> list[ThreadTimes]:
        """Every thread timed: the ended ones, then those still running (the main thread)."""
        with self._lock:
            return [*self._ended, *self._live.values()]

    def _mine(self) -> ThreadTimes:
        ident = threading.get_ident()
        with self._lock:
            if ident not in self._live:
                self._live[ident] = ThreadTimes(threading.current_thread().name)
            return self._live[ident]

    def _end(self, cpu: float, wall: float) -> None:
        """The calling thread ends: its CPU and wall time, and its ident freed for the next."""
        mine = self._mine()
        mine.cpu, mine.wall = cpu, wall
        with self._lock:
            self._ended.append(self._live.pop(threading.get_ident()))

    def add(self, part: str, seconds: float) -> None:
        """Count `seconds` of `part` on the calling thread."""
        mine = self._mine()
        mine.seconds[part] += seconds
        mine.calls[part] += 1

    def timed(self, part: str, fn: Callable[..., Any]) -> Callable[..., Any]:
        """`fn`, its calls timed as `part`."""

        def call(*args: Any, **kwargs: Any) -> Any:
            start = time.perf_counter()
            try:
                return fn(*args, **kwargs)
            finally:
                self.add(part, time.perf_counter() - start)

        return call

    @contextmanager
    def installed(self) -> Iterator[None]:
        """The timers in place (and each thread's CPU read as it ends); the originals after."""
        patches: list[tuple[Any, str, str]] = [
            (queue.Queue, "get", "wait for an item (Queue.get)"),
            (queue.Queue, "put", "wait for room (Queue.put)"),
            (PaperDetector, "detect", "detect"),
            (PaperDetector, "foreground", "foreground"),
            (Tracker, "update", "Tracker.update"),
            (Tracker, "working_frame", "working_frame"),
            (Tracker, "prime", "Tracker.prime"),
            (Tracker, "finalize", "Tracker.finalize (offline pass)"),
            (CameraMotion, "grey", "camera grey"),
            (run, "bootstrap_frames", "bootstrap_frames"),
        ]
        timers = self

        def capture(*args: Any, **kwargs: Any) -> Any:
            return _TimedCapture(opened(*args, **kwargs), timers)

        def thread_run(thread: threading.Thread) -> None:
            start = time.perf_counter()
            try:
                thread_started(thread)
            finally:
                timers._end(time.thread_time(), time.perf_counter() - start)

        opened, thread_started = video._file_capture, threading.Thread.run
        with ExitStack() as undo:
            for owner, name, part in patches:
                original = getattr(owner, name)
                undo.callback(setattr, owner, name, original)
                setattr(owner, name, self.timed(part, original))
            undo.callback(setattr, video, "_file_capture", opened)
            video._file_capture = capture
            undo.callback(setattr, threading.Thread, "run", thread_started)
            threading.Thread.run = thread_run  # type: ignore[method-assign,assignment]
            yield


class _TimedCapture:
    """A ``cv2.VideoCapture`` whose ``read``, ``grab`` and ``set`` (a seek) are timed."""

    def __init__(self, cap: Any, timers: Timers) -> None:
        self._cap = cap
        for name in ("read", "grab", "set"):
            setattr(self, name, timers.timed(f"VideoCapture.{name}", getattr(cap, name)))

    def __getattr__(self, name: str) -> Any:
        return getattr(self._cap, name)


def report(timers: Timers, wall: float) -> str:
    """The threads' table: each part's seconds and calls, each thread's CPU and wall time."""
    lines = [f"whole run {wall:.3f} s wall (in this process, imports excluded)"]
    for times in sorted(timers.threads, key=lambda t: t.role):
        alive = "" if times.wall is None else f", alive {times.wall:.3f} s"
        cpu = "" if times.cpu is None else f", CPU {times.cpu:.3f} s"
        lines.append(f"{times.role}{alive}{cpu}")
        for part, s in sorted(times.seconds.items(), key=lambda kv: -kv[1]):
            lines.append(f"  {s:8.3f} s {times.calls[part]:6d} calls  {part}")
    return "\n".join(lines)


def measure(source: str, out: str, extra: Sequence[str] = ()) -> tuple[Timers, float]:
    """Run ``pftrack -q track source --out out *extra`` with the timers; they and its wall time."""
    timers = Timers()
    with timers.installed():
        start = time.perf_counter()
        status = pftrack_main(["-q", "track", source, "--out", out, *extra])
        wall = time.perf_counter() - start
    if status != 0:
        raise RuntimeError(f"pftrack track {source} exited with status {status}")
    return timers, wall


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m experiments.thread_times",
        description="Per-thread wall time of the parts of a `pftrack -q track` run.",
        allow_abbrev=False,
    )
    parser.add_argument("source", help="the video (or image folder) to track")
    parser.add_argument("--out", help="the track file (default: a temporary file, removed)")
    parser.add_argument("extra", nargs="*", help="more `pftrack track` options, after --")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        out = args.out or str(Path(tmp) / "tracks.txt")
        timers, wall = measure(args.source, out, args.extra)
    print(report(timers, wall))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
