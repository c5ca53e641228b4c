"""The ``pftrack`` console script and ``python -m pftrack``: :func:`pftrack.cli.main`, wrapped.

Ctrl-C while the command line is imported (its first 0.05-0.1 s) raised a ``KeyboardInterrupt``
outside :func:`pftrack.cli.main`, which prints a traceback; here it ends as an interrupted
command does, in one line with exit status 130. Nothing is imported before the ``try`` but
this module: whatever is interrupted may be half loaded, so the handler loads nothing either.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence

__all__ = ["main"]

#: :data:`pftrack.cli._signals.EXIT_INTERRUPTED`, stated here: the module that states it may be
#: what was interrupted (a test checks they agree).
EXIT_INTERRUPTED = 130


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
        if argv is None:  # this process is the command (the console script, python -m pftrack)
            from pftrack._threads import one_blas_thread

            one_blas_thread()  # before anything loads NumPy
        from pftrack.cli import _signals
        from pftrack.cli import main as run

        # the process ends with the command: a Ctrl-C once its outputs are in place is ignored
        # to the exit (was: exit status 130, no word, after the output was written)
        _signals.PROCESS_ENDS = argv is None
        return run(argv)
    except KeyboardInterrupt:  # before the command's own handler: nothing was written yet
        words = sys.argv[1:] if argv is None else argv
        try:  # a line break ends a progress bar's line, drawn only on a terminal
            end = "\n" if sys.stderr.isatty() else ""
        except (AttributeError, OSError, ValueError):  # no stderr, or a closed one
            end = ""
        print(f"{end}{_command(words)}: interrupted; no output was changed", file=sys.stderr)
        return EXIT_INTERRUPTED
