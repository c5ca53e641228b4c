"""Ctrl-C and ``kill``: a command stopped by SIGTERM unwinds as one stopped by Ctrl-C.

Every output is staged and renamed at the end (:mod:`pftrack.io.atomic`), and each writer
removes its temporary file when an exception passes through it: a ``KeyboardInterrupt`` leaves
the user's files as they were and no temporary file. SIGTERM (``kill PID``, a service manager,
``timeout``) killed the process where it stood, leaving the temporary files of the video being
rendered (``..t.<hex>.<hex>.mp4``, ``.t.<hex>.mp4``). While a command runs, SIGTERM raises
:class:`Terminated`, a ``KeyboardInterrupt``, so it takes the same path. A Ctrl-C that code
in C dropped is noted all the same (:mod:`pftrack._interrupt`): the writers refuse to put an
output in place after it (:func:`pftrack._interrupt.raise_if_interrupted`).
"""

from __future__ import annotations

import contextlib
import signal
import sys
import threading
from collections.abc import Iterator
from typing import Any

from pftrack._interrupt import Terminated, put_off_in_imports

__all__ = [
    "EXIT_INTERRUPTED",
    "EXIT_TERMINATED",
    "Terminated",
    "exit_status",
    "hold_interrupts",
    "ignore_interrupts_to_exit",
    "interrupts_held",
    "line_end",
    "outcome",
    "set_outcome",
    "sigterm_raises",
]

#: Exit status after Ctrl-C (128 + SIGINT, as shells report it).
EXIT_INTERRUPTED = 130
#: Exit status after SIGTERM (128 + SIGTERM, as shells report a process it killed).
EXIT_TERMINATED = 143


def exit_status(exc: KeyboardInterrupt) -> int:
    """143 when `exc` came from SIGTERM, else 130 (Ctrl-C)."""
    return EXIT_TERMINATED if isinstance(exc, Terminated) else EXIT_INTERRUPTED


#: What an interrupted command says it left, unless it says otherwise (:func:`set_outcome`).
NOTHING_CHANGED = "no output was changed"


def set_outcome(exc: BaseException, text: str | None) -> None:
    """Say what the command that `exc` ends left behind, in place of "no output was changed".

    ``main`` prints it after ``interrupted;`` (or ``terminated (SIGTERM);``), and after an
    error's message. A live ``pftrack track`` run has written rows before it ends: the
    message says where they are. None says nothing (the default stands).
    """
    if text is not None:
        exc.pftrack_outcome = text  # type: ignore[attr-defined]


def outcome(exc: BaseException) -> str | None:
    """What :func:`set_outcome` said for `exc`; None when nothing was."""
    text = getattr(exc, "pftrack_outcome", None)
    return text if isinstance(text, str) else None


def line_end() -> str:
    """A line break when stderr is a terminal (to end a progress bar's line first), else ``""``."""
    try:
        return "\n" if sys.stderr is not None and sys.stderr.isatty() else ""
    except (AttributeError, OSError, ValueError):  # a replaced or closed stream
        return ""


def _raise_terminated(signum: int, frame: Any) -> None:
    if put_off_in_imports(frame, signum):  # raised into C that imports, Terminated
        return  # was printed as a traceback: this handler, still set, runs at the next line
    # once: the command is unwinding (its writers removing their temporary files, its reader
    # threads stopping), and a second SIGTERM raised in that cleanup left a reader thread
    # inside a C++ read as the process exited, which aborted or crashed it ("FATAL: exception
    # not rethrown", a segmentation fault). ``timeout`` sends two: one to the process, one to
    # its process group. sigterm_raises restores the handler when the command ends.
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    raise Terminated


#: Set by the ``pftrack`` console script (:mod:`pftrack._console`): the process ends with the
#: command, so interrupts held by :func:`hold_interrupts` stay ignored until it exits.
PROCESS_ENDS = False
_held = [False]  # hold_interrupts was called in this command


def _stopping_signals() -> list[signal.Signals]:
    return [getattr(signal, name) for name in ("SIGINT", "SIGTERM") if hasattr(signal, name)]


def hold_interrupts() -> None:
    """From here to the command's end, Ctrl-C and SIGTERM are ignored: its work is done.

    A command calls it just before its outputs are put in place (the end of its
    :func:`~pftrack.io.atomic.staged_outputs` block), or once its one output is: what is left
    is renaming, printing the summary and exiting. A late Ctrl-C ended such a run with exit
    status 130 and no word after the output was written (or "no output was changed" when it
    was); now the run finishes, exit status 0 with its summary. :func:`sigterm_raises`
    restores the handlers when the command ends, unless :data:`PROCESS_ENDS`. Only in the
    main thread (elsewhere it does nothing).
    """
    if threading.current_thread() is not threading.main_thread():
        return
    for sig in _stopping_signals():
        signal.signal(sig, signal.SIG_IGN)
    _held[0] = True


def ignore_interrupts_to_exit() -> None:
    """After the command has handled its interrupt: further Ctrl-C is ignored to the exit.

    Only where the process ends with the command (:data:`PROCESS_ENDS`) and in the main
    thread. What is left is saying the outcome and exiting, which joins the threads still
    stopping (a reader's, the spread bootstrap's): a second Ctrl-C there printed a traceback,
    or cut that join short and the process aborted ("terminate called without an active
    exception") with a thread inside OpenCV.
    """
    if PROCESS_ENDS and threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)


def interrupts_held() -> bool:
    """Whether the running command called :func:`hold_interrupts`: its outputs are in place."""
    return _held[0]


@contextlib.contextmanager
def sigterm_raises() -> Iterator[None]:
    """While the block runs, SIGTERM raises :class:`Terminated`; the previous handlers after.

    Only in the main thread (Python runs signal handlers there; another thread cannot set
    one), and only where the platform has SIGTERM. SIGINT's handler is restored too, after
    :func:`hold_interrupts` (not when :data:`PROCESS_ENDS`: then they stay ignored to the end).
    """
    if threading.current_thread() is not threading.main_thread() or not hasattr(signal, "SIGTERM"):
        yield
        return
    previous = {sig: signal.getsignal(sig) for sig in _stopping_signals()}
    signal.signal(signal.SIGTERM, _raise_terminated)
    _held[0] = False
    try:
        yield
    finally:
        if not (_held[0] and PROCESS_ENDS):
            for sig, handler in previous.items():
                if handler is not None:  # None: set outside Python, cannot be restored
                    signal.signal(sig, handler)
        _held[0] = False
