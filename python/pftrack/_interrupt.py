"""Whether the ``pftrack`` process was Ctrl-C'd: a flag that outlives a dropped interrupt.

Code in C may turn the ``KeyboardInterrupt`` that Python raises for Ctrl-C into an error of
its own, or drop it: NumPy's import, interrupted, raised ``ImportError: ... PyCapsule_Import
could not import module "datetime"`` (a traceback, exit status 1), and an interrupt dropped
somewhere in the imports let ``pftrack recover`` write its output (exit status 0, no word).
The console script's SIGINT handler (:mod:`pftrack._console`) calls :func:`remember` before it
raises; the atomic writers (:mod:`pftrack.io.atomic`) call :func:`raise_if_interrupted` before
they put an output in place, so a command whose Ctrl-C was lost changes no file.

Nothing else sets the flag: a program that imports pftrack (no ``pftrack`` console script) is
never refused a write. This module imports nothing, so every layer may read it (the handler
runs while anything may be half loaded).
"""

from __future__ import annotations

TYPE_CHECKING = False  # typing's, without importing it (this module imports nothing)
if TYPE_CHECKING:
    from types import FrameType

__all__ = [
    "IMPORT_MACHINERY",
    "Terminated",
    "clear",
    "interrupted",
    "put_off_in_imports",
    "raise_if_interrupted",
    "remember",
    "written_anyway",
]


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread where the command stands (:mod:`pftrack.cli._signals`).

    Stated here, where nothing is imported, so that the console script's handler
    (:mod:`pftrack._console`) raises it while the command line is still being imported.
    """


#: Where importlib's frozen frames say they are (``<frozen importlib._bootstrap>``, ...).
IMPORT_MACHINERY = "<frozen importlib."


#: How long a signal put off in importlib's frames waits before its handler runs again (s).
PUT_OFF = 0.002


def put_off_in_imports(frame: object, signum: int) -> bool:
    """Put `signum` off and return True if a handler's `frame` is importlib's own.

    A signal handler that gets True returns without raising.

    An exception a handler raises there may be raised into C that imports and prints it (a
    traceback, then that import's own error): a late import (``import cv2`` in a command's
    body, an extension's init importing NumPy: OpenCV's ``import_array``) at the moment of a
    Ctrl-C or a SIGTERM. The handler of `signum` runs again :data:`PUT_OFF` seconds later, from
    a one-shot timer (SIGALRM), at whatever line the main thread then stands on; in importlib's
    frames again, it is put off again. Was: the signal raised again at once, which Python
    handles inside ``signal.raise_signal``, within the same import's frames (the traceback came
    back, one frame deeper: CI, 7 December). Where there is no such timer (Windows), it is
    raised again at once, as before.
    """
    code = getattr(frame, "f_code", None)
    if code is None or not code.co_filename.startswith(IMPORT_MACHINERY):
        return False
    import signal  # loaded: a handler was set with it

    if not hasattr(signal, "setitimer"):
        signal.raise_signal(signum)
        return True
    _put_off.add(signum)
    if signal.getsignal(signal.SIGALRM) is not _again:
        previous = signal.signal(signal.SIGALRM, _again)
        _alarm_before[0] = signal.SIG_DFL if previous is None else previous
    signal.setitimer(signal.ITIMER_REAL, PUT_OFF)
    return True


_put_off: set[int] = set()  # the signals put_off_in_imports holds, run by _again
_alarm_before: list[object] = [None]  # SIGALRM's handler before _again, set back by it


def _again(_alarm: int, frame: FrameType | None) -> None:
    """The timer's end: each signal put off runs its handler now, at the main thread's line."""
    import signal

    signal.signal(signal.SIGALRM, _alarm_before[0])  # type: ignore[arg-type]
    held = sorted(_put_off)
    _put_off.clear()
    for signum in held:
        handler = signal.getsignal(signum)
        if callable(handler):
            handler(signum, frame)


_interrupted = [False]
_anyway = [0]  # written_anyway blocks open


def remember() -> None:
    """Note that Ctrl-C came (the ``pftrack`` console script's SIGINT handler calls it)."""
    _interrupted[0] = True


def interrupted() -> bool:
    """Whether Ctrl-C came since the ``pftrack`` process's command began (:func:`remember`)."""
    return _interrupted[0]


def clear() -> None:
    """Forget the Ctrl-C noted: the command has handled it (a batch writing its summary)."""
    _interrupted[0] = False


def raise_if_interrupted() -> None:
    """Raise ``KeyboardInterrupt`` if Ctrl-C came (:func:`interrupted`), perhaps lost on its way.

    Called where an output is put in place: the writer then removes its temporary file and
    the command ends as interrupted (exit status 130, "no output was changed").
    """
    if _interrupted[0] and not _anyway[0]:
        raise KeyboardInterrupt


class written_anyway:  # noqa: N801 - used as a function: ``with written_anyway():``
    """Meanwhile, :func:`raise_if_interrupted` raises nothing, though the flag is set.

    For what a run writes *because* it was interrupted: a batch's ``summary.json``, which
    lists the sequences it cancelled. The flag is kept (:func:`interrupted` still says so). A
    class, not ``contextlib``: this module imports nothing.
    """

    def __enter__(self) -> None:
        _anyway[0] += 1

    def __exit__(self, *exc: object) -> None:
        _anyway[0] -= 1
