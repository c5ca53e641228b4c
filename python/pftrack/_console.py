"""The ``pftrack`` console script and ``python -m pftrack``: :func:`pftrack.cli.main`, wrapped.

Ctrl-C while the command line is imported (its first 0.05-0.1 s) raised a ``KeyboardInterrupt``
outside :func:`pftrack.cli.main`, which prints a traceback; here it ends as an interrupted
command does, in one line with exit status 130. Nothing is imported before the ``try`` but
this module (a Ctrl-C there is Python's: its traceback); whatever is interrupted may be half
loaded, so the handler loads nothing either (:mod:`pftrack._interrupt`, which imports
nothing, is loaded first in the ``try``, before the handler is set).
"""

from __future__ import annotations

import sys
from collections.abc import Sequence

__all__ = ["main"]

#: :data:`pftrack.cli._signals.EXIT_INTERRUPTED`, stated here: the module that states it may be
#: what was interrupted (a test checks they agree).
EXIT_INTERRUPTED = 130
#: :data:`pftrack.cli._signals.EXIT_TERMINATED`, likewise.
EXIT_TERMINATED = 143


def _on_sigint(signum: int, frame: object) -> None:
    """Python's own SIGINT handler (``signal.default_int_handler``), remembering the interrupt.

    Code in C may drop the ``KeyboardInterrupt`` raised here, or turn it into an error of its
    own: the flag (:mod:`pftrack._interrupt`) ends such an error as interrupted (below), and
    the atomic writers read it before they put an output in place.
    """
    from pftrack import _interrupt  # loaded: main imports it before it sets this handler

    _interrupt.remember()
    if _interrupt.put_off_in_imports(frame, signum):  # raised at the next line
        return  # outside importlib's frames, not into C that prints it
    raise KeyboardInterrupt


def _on_sigterm(signum: int, frame: object) -> None:
    """SIGTERM before the command's own handler (:mod:`pftrack.cli._signals`) is set.

    Was: the default action, the process killed where it stood (status -15, no word) when
    SIGTERM came in the first 0.1-0.2 s of a loaded machine. Once, as the command's handler.
    """
    import signal

    from pftrack import _interrupt  # loaded: main imports it before it sets this handler

    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    raise _interrupt.Terminated


def _command(argv: Sequence[str]) -> str:
    """``pftrack CMD`` for the command `argv` names (its first non-option word), or ``pftrack``."""
    word = next((a for a in argv if not a.startswith("-")), None)
    return "pftrack" if word is None else f"pftrack {word}"


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``pftrack`` command (:func:`pftrack.cli.main`); return its exit status.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments (default: ``sys.argv[1:]``). Without them the process is the command's
        own: BLAS is kept at one thread (:func:`pftrack._threads.one_blas_thread`; library
        calls leave the caller's process alone) and the process ends with the command.

    Returns
    -------
    int
        The command's exit status; 130 after Ctrl-C before the command handles it itself
        (while the command line is imported or its arguments parsed).
    """
    try:
        from pftrack import _interrupt  # what the handler and the errors below read

        if argv is None:  # this process is the command (the console script, python -m pftrack)
            import signal

            _interrupt.clear()  # this process's command begins
            if signal.getsignal(signal.SIGINT) is signal.default_int_handler:  # not SIG_IGN
                signal.signal(signal.SIGINT, _on_sigint)
            if signal.getsignal(signal.SIGTERM) is signal.SIG_DFL:
                signal.signal(signal.SIGTERM, _on_sigterm)
            from pftrack._threads import one_blas_thread

            one_blas_thread()  # before anything loads NumPy
        from pftrack.cli import _signals
        from pftrack.cli import main as run

        # the process ends with the command: a Ctrl-C once its outputs are in place is ignored
        # to the exit (was: exit status 130, no word, after the output was written)
        _signals.PROCESS_ENDS = argv is None
        status = run(argv)
        if argv is None:  # every command (was: `pftrack track` alone)
            import gc

            # The interpreter's exit runs the cyclic collector over every object while it
            # tears the modules down: 0.15-0.2 s of a `track` run at load, 0.04 s quiet, for
            # memory the process gives back anyway. Frozen, the objects are left out of those
            # passes (every output is closed and stdout flushed by the command; atexit
            # handlers still run).
            gc.freeze()
        return status
    except Exception:
        from pftrack import _interrupt  # (loaded first in the try: cannot fail here)

        if not _interrupt.interrupted():
            raise  # a defect of pftrack's: its traceback is what a report needs
        # Ctrl-C, turned into another error by code in C (an import of NumPy's): as below
        print(f"{_line_end()}{_command(_words(argv))}: interrupted; no output was changed",
              file=sys.stderr)  # fmt: skip
        return EXIT_INTERRUPTED
    except KeyboardInterrupt as e:  # before the command's own handler: nothing was written yet
        from pftrack import _interrupt  # (loaded first in the try: cannot fail here)

        how = "terminated (SIGTERM)" if isinstance(e, _interrupt.Terminated) else "interrupted"
        print(f"{_line_end()}{_command(_words(argv))}: {how}; no output was changed",
              file=sys.stderr)  # fmt: skip
        return EXIT_TERMINATED if how != "interrupted" else EXIT_INTERRUPTED
    finally:
        if argv is None:  # the process exits as it ends: SIGTERM kills it, as it did
            import signal

            # and Ctrl-C is ignored: the command is over, and a KeyboardInterrupt now was a
            # traceback, or cut short the exit's wait for threads still stopping, which aborted
            # the process (a thread left inside OpenCV: pftrack.cli._signals)
            signal.signal(signal.SIGINT, signal.SIG_IGN)
            if signal.getsignal(signal.SIGTERM) is _on_sigterm:
                signal.signal(signal.SIGTERM, signal.SIG_DFL)
        _handled()


def _handled() -> None:
    """Tell CPython that no ``KeyboardInterrupt`` went unhandled: the command handled each.

    CPython notes a ``KeyboardInterrupt`` that leaves code run by ``exec`` or ``eval`` of a
    string (a dataclass's generated ``__init__``, a namedtuple's ``__new__``, as modules load)
    as unhandled, even where a caller catches it, and ``python -m`` ends such a process by
    SIGINT after its exit, whatever status it exits with (``Py_RunMain``'s check, for
    ``runpy``; a script or ``-c`` that calls ``sys.exit`` leaves before it). ``python -m
    pftrack recover``, Ctrl-C'd 0.2-0.5 s in, said ``interrupted``, returned 130 and was then
    killed by SIGINT (returncode -2) in up to 1 run in 10. Every ``exec`` of a string starts
    by clearing that note: one of nothing clears it.
    """
    exec("")  # noqa: S102 - a constant: nothing is run


def _words(argv: Sequence[str] | None) -> Sequence[str]:
    """The command's words: `argv`, or the process's own."""
    return sys.argv[1:] if argv is None else argv


def _line_end() -> str:
    """A line break to end a progress bar's line, drawn only on a terminal; else ``""``."""
    try:
        return "\n" if sys.stderr.isatty() else ""
    except (AttributeError, OSError, ValueError):  # no stderr, or a closed one
        return ""
