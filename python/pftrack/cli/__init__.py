"""The ``pftrack`` command line: parses arguments and wires the library together.

One module per sub-command (``demo``, ``track``, ``render``, ``smooth``, ``eval``, ``recover``,
``experiment``), each with ``add_parser(sub)`` and a ``run(args) -> int``; the library is
imported only when a command runs.
"""

from __future__ import annotations

import argparse
import codecs
import contextlib
import contextvars
import os
import sys
import warnings
from collections.abc import Callable, Iterator, Sequence
from typing import TYPE_CHECKING, Any, NoReturn

from pftrack import __version__
from pftrack._text import error_line as _one_line
from pftrack._text import on_one_line as _shown
from pftrack.cli import batch, demo, evaluate, experiment, recover, render, smooth, track
from pftrack.cli._options import HelpFormatter
from pftrack.cli._signals import (
    NOTHING_CHANGED,
    Terminated,
    exit_status,
    ignore_interrupts_to_exit,
    interrupts_held,
    line_end,
    outcome,
    set_outcome,
    sigterm_raises,
)

if TYPE_CHECKING:
    from _typeshed import SupportsWrite

__all__ = ["build_parser", "main"]

EPILOG = """\
examples:
  pftrack demo                                   # synthetic scene: track, render, score, recover
  pftrack track video.avi --out tracks.txt --render annotated.mp4 --plot paths.png
  pftrack track MOT17-04/ --detections auto --out tracks.txt        # a MOTChallenge sequence
  pftrack track 0 --out live.txt --render live.mp4                  # camera 0; Ctrl-C ends it
  pftrack track seq/img1 --detections det.txt --out tracks.txt      # drop-in for any detector
  pftrack batch MOT17/train/ --out results/ --detections auto       # many, on Dask
  pftrack eval --gt gt.txt --res tracks.txt --scale 0.625
  pftrack recover tracks.txt --out filled.txt --link                # default method: auto
  pftrack smooth bytetrack.txt --out smoothed.txt                   # any tracker's output
  pftrack render video.avi smoothed.txt --out smoothed.mp4          # any tracks file, drawn
"""


#: The arguments :func:`main` parses, up to a ``--`` (after it nothing is taken for an option).
_ARGV: contextvars.ContextVar[Sequence[str]] = contextvars.ContextVar("_ARGV", default=())


class Parser(argparse.ArgumentParser):
    """argparse's parser, refusing bad usage in one line (``pftrack track: error: ...``).

    argparse prints the command's whole usage before the error line; ``--help`` still shows
    it. Sub-commands' parsers are of this class too (``add_subparsers`` makes them of the
    parser's own class). Long options are taken only as spelt in full (``allow_abbrev=False``,
    here for every parser and sub-command's): ``--ren out.mp4`` was taken for ``--render``,
    silently, and an option added later could change what an abbreviation means.
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> NoReturn:
        """Print ``PROG: error: MESSAGE`` and exit with status 2.

        A file named with a leading ``-`` (``-clip.mp4``), which argparse takes for an option,
        is named with the way to give it (was: ``the following arguments are required:
        source``, of a source given).
        """
        unknown = self._unknown_options()
        if unknown:  # said first: argparse checks required arguments before unknown ones
            name = unknown[0]
            if not message.startswith("unrecognized arguments"):
                message = f"unrecognized arguments: {' '.join(unknown)}; {message}"
            full = sorted(o for o in self._option_string_actions if o.startswith(name))
            if full:  # was: taken for it, silently (argparse's allow_abbrev)
                message += f" ({name} is not taken for {' or '.join(full)}: spell options in full)"
        dashed = [a for a in _ARGV.get() if a.startswith("-") and a != "-" and os.path.lexists(a)]
        if dashed:
            message += (
                f" ({dashed[0]} is a file, read as an option: give it as ./{dashed[0]}, or "
                "after -- at the end)"
            )
        self.exit(2, f"{self.prog}: error: {message}\n")

    def _unknown_options(self) -> list[str]:
        """The long options of :func:`main`'s arguments this command's parser does not take.

        Only for a parser without sub-commands (a command's, not ``pftrack``'s own).
        """
        if any(isinstance(a, argparse._SubParsersAction) for a in self._actions):
            return []
        return [
            a.split("=")[0]
            for a in _ARGV.get()
            if a.startswith("--") and a.split("=")[0] not in self._option_string_actions
        ]

    def _print_message(self, message: str, file: SupportsWrite[str] | None = None) -> None:
        """Print help, usage or the version; a failed write says so, as commands' output does.

        argparse's own ignores it: ``pftrack --help > /dev/full`` printed nothing and exited
        0. A closed pipe (``| head``) still ends quietly, as Unix tools do.
        """
        if not message:
            return
        stream: Any = file or sys.stderr  # a text stream (argparse passes sys.stdout or stderr)
        try:
            stream.write(message)
            stream.flush()
        except OSError as exc:
            with contextlib.suppress(OSError, ValueError):  # nothing left to flush at exit
                os.dup2(os.open(os.devnull, os.O_WRONLY), stream.fileno())
            if isinstance(exc, BrokenPipeError) or stream is sys.stderr:
                return
            print(f"{self.prog}: error: {_stdout_failed(exc)}", file=sys.stderr)
            sys.exit(2)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every sub-command."""
    parser = Parser(
        prog="pftrack",
        description="Track many people or objects in video with one colour particle filter "
        "each, and recover the parts of their paths that tracking lost.",
        epilog=EPILOG,
        formatter_class=HelpFormatter,
    )
    parser.add_argument(
        "-q", "--quiet", action="store_true",
        help="no progress bars (they are drawn only when stderr is a terminal anyway)",
    )  # fmt: skip
    parser.add_argument("--version", action="version", version=f"pftrack {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for command in (demo, track, render, batch, smooth, evaluate, recover, experiment):
        command.add_parser(sub)
    return parser


def _one_line_warning(prog: str) -> Callable[..., None]:
    """A ``warnings.showwarning`` printing ``PROG: warning: ...`` (no source line).

    `prog` names the command as its parser does: ``pftrack track``, ``pftrack experiment gaps``.
    Above a progress bar being drawn (tqdm's ``write``), not through it. Printed while the
    command works (``track`` prints its warnings as they are raised): a closed stderr (``2>&-``,
    a pipe whose reader left) costs the message, never the outputs.
    """

    def show(message: Warning | str, *_: object, **__: object) -> None:
        said_above_bar(f"{prog}: warning: {_shown(str(message))}")

    return show


def said_above_bar(line: str) -> None:
    """`line` on stderr, above a progress bar being drawn (tqdm's ``write``), not through it.

    A closed stderr (``2>&-``, a pipe whose reader left) costs the line, never the outputs.
    """
    err = sys.stderr
    if err is None:  # started with stderr closed (was: the line printed on stdout)
        return
    tqdm = sys.modules.get("tqdm")  # imported only when a bar is drawn
    try:
        if tqdm is not None:
            tqdm.tqdm.write(line, file=err)
        else:
            print(line, file=err)
    except (OSError, ValueError):  # a broken pipe, a closed file
        pass


#: OpenCV's and FFmpeg's own log lines (``[ WARN:0@0.030] global cap.cpp:212 open ...``,
#: ``[tcp @ 0x...] Connection ... refused``) before pftrack's one-line error on a source they
#: cannot open: off for the command's process, unless the environment sets them. OpenCV reads
#: its variable when cv2 is imported, FFmpeg's when OpenCV first opens a file or stream.
QUIET_OPENCV = {"OPENCV_LOG_LEVEL": "SILENT", "OPENCV_FFMPEG_LOGLEVEL": "-8"}  # -8: AV_LOG_QUIET


#: The error handler of stdout while a command runs (:func:`_names_on_stdout`).
NAMES_ON_STDOUT = "pftrack.names"


def _write_names(exc: UnicodeError) -> tuple[bytes, int]:
    r"""Encode what stdout's encoding cannot: surrogate escapes as their bytes, else ``\xf6``."""
    if not isinstance(exc, UnicodeEncodeError):
        raise exc
    out = bytearray()
    for c in exc.object[exc.start : exc.end]:
        if "\udc80" <= c <= "\udcff":  # a byte of a file name that is not UTF-8
            out.append(ord(c) - 0xDC00)
        else:
            out += c.encode("ascii", "backslashreplace")
    return bytes(out), exc.end


codecs.register_error(NAMES_ON_STDOUT, _write_names)


@contextlib.contextmanager
def _names_on_stdout() -> Iterator[None]:
    r"""While a command runs, stdout writes any file name, whatever its encoding.

    A name's bytes that are not UTF-8, which Python keeps as surrogate escapes, are written as
    they are: a UTF-8 stdout refuses them (``errors="strict"`` outside the C locale), and
    ``track ... --out $'x\xfe.txt'`` failed on its summary line, after writing its outputs;
    ``ls`` and the shell print the bytes, and so does pftrack. A character that stdout's
    encoding has not (``PYTHONIOENCODING=ascii``: ``rö.txt``) is written as a ``\xf6`` escape:
    ``recover tö.txt --out rö.txt`` failed likewise (exit status 2).
    """
    stream = sys.stdout
    reconfigure = getattr(stream, "reconfigure", None)
    errors = getattr(stream, "errors", None)
    if reconfigure is None or errors not in ("strict", "surrogateescape"):
        yield
        return
    try:
        reconfigure(errors=NAMES_ON_STDOUT)
    except (AttributeError, OSError, ValueError):  # a stream that cannot change
        yield
        return
    try:
        yield
    finally:
        with contextlib.suppress(AttributeError, OSError, ValueError):
            stream.reconfigure(errors=errors)  # type: ignore[union-attr]


def _stdout_failed(exc: OSError) -> str:
    """``cannot write to standard output (No space left on device)``: what a failed write says."""
    return f"cannot write to standard output ({exc.strerror or exc})"


class StdoutError(OSError):
    """Standard output refused the command's report: ``cannot write to standard output ...``.

    An OSError from a ``print`` names no file (``[Errno 28] No space left on device`` for
    ``pftrack eval ... > /dev/full``): the user could not tell it from a failed output file.
    A closed pipe (:class:`BrokenPipeError`) is not one of these: it ends the command quietly.
    """


class _NamedStdout:
    """``sys.stdout`` while a command runs: a write or flush that fails raises StdoutError.

    Everything else is the stream's own (``fileno``, ``isatty``, ``encoding``, ...).
    """

    def __init__(self, stream: Any) -> None:
        self._stream = stream

    def _failed(self, exc: OSError) -> StdoutError:
        error = StdoutError(_stdout_failed(exc))
        error.errno = exc.errno
        if interrupts_held():  # the report comes after the outputs (recover, smooth, track)
            set_outcome(error, "the outputs were written before it")
        return error

    def write(self, text: str) -> int:
        """Write `text` to the stream."""
        try:
            return int(self._stream.write(text))
        except BrokenPipeError:
            raise
        except OSError as exc:
            raise self._failed(exc) from None

    def flush(self) -> None:
        """Flush the stream."""
        try:
            self._stream.flush()
        except BrokenPipeError:
            raise
        except OSError as exc:
            raise self._failed(exc) from None

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


@contextlib.contextmanager
def _stdout_named() -> Iterator[None]:
    """While a command runs, a failed write to stdout says so (:class:`StdoutError`)."""
    stream = sys.stdout
    if stream is None:
        yield
        return
    sys.stdout = _NamedStdout(stream)
    try:
        yield
    finally:
        sys.stdout = stream


@contextlib.contextmanager
def _quiet_opencv() -> Iterator[None]:
    """While a command runs, OpenCV and FFmpeg log nothing (variables the user set are kept).

    The variables are set before cv2 is imported (the command imports it only when it runs); a
    cv2 already imported by a caller of :func:`main` in its own process gets its log level set,
    and both are restored afterwards. A cv2 first imported by the command keeps the silent
    level: the command's process ends with it.
    """
    before = {name: os.environ.get(name) for name in QUIET_OPENCV}
    for name, value in QUIET_OPENCV.items():
        os.environ.setdefault(name, value)
    cv2 = sys.modules.get("cv2")
    level = None
    if cv2 is not None and before["OPENCV_LOG_LEVEL"] is None:
        level = cv2.utils.logging.getLogLevel()
        cv2.utils.logging.setLogLevel(cv2.utils.logging.LOG_LEVEL_SILENT)
    try:
        yield
    finally:
        for name in QUIET_OPENCV:
            if before[name] is None:
                os.environ.pop(name, None)
        if cv2 is not None and level is not None:
            cv2.utils.logging.setLogLevel(level)


def _command_parser(parser: argparse.ArgumentParser, args: argparse.Namespace) -> Any:
    """The parser of the (sub-)command `args` selected: ``pftrack experiment gaps``'s, ..."""
    while True:
        subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
        name = getattr(args, subs[0].dest, None) if subs else None
        if name is None or name not in subs[0].choices:
            return parser
        parser = subs[0].choices[name]


#: Options whose empty value their own check refuses, saying more: outputs ("give a file
#: name"), --scheduler ("give a running Dask scheduler's address") and a video source.
_OWN_CHECK = frozenset(
    {"out", "out_dir", "render", "plot", "json", "csv", "figure", "scheduler", "source"}
)


def _empty_argument(command: argparse.ArgumentParser, args: argparse.Namespace) -> str | None:
    """The option (or positional argument) of `command` given as an empty string, if any.

    No option of pftrack takes an empty value; a path given as ``''`` (an unset shell
    variable) was the current folder, or an option silently left off. Outputs are left to
    their own check (:func:`pftrack.io.atomic.check_output`: "give a file name").
    """
    for action in command._actions:
        if action.dest in _OWN_CHECK:
            continue
        value = getattr(args, action.dest, None)
        if value == "" or (isinstance(value, list) and "" in value):
            return action.option_strings[-1] if action.option_strings else action.dest.upper()
    return None


def _opencv_error(exc: BaseException) -> bool:
    """Whether `exc` is OpenCV's ``cv2.error`` (told without importing cv2: ``--help`` does not).

    OpenCV raises it on input it cannot handle (an image or a size its functions refuse); a
    path pftrack does not check first then ends in one line, exit 2, not a traceback.
    """
    kind = type(exc)
    return kind.__name__ == "error" and kind.__module__.split(".")[0] == "cv2"


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``pftrack`` script; returns the exit status."""
    parser = build_parser()
    given = sys.argv[1:] if argv is None else list(argv)
    token = _ARGV.set(given[: given.index("--")] if "--" in given else given)
    try:
        args, extra = parser.parse_known_args(given)
        command = _command_parser(parser, args)
        if extra:  # named by the command's own parser: its usage, "pftrack smooth: error: ..."
            command.error(f"unrecognized arguments: {' '.join(extra)}")
    finally:
        _ARGV.reset(token)
    empty = _empty_argument(command, args)
    if empty is not None:  # was: --detections '' ignored, '' as a folder the current one
        print(f"{command.prog}: error: {empty} is empty; give a value", file=sys.stderr)
        return 2
    # "pftrack experiment gaps: error: ..." as argparse names it (was: "pftrack experiment")
    prog = str(command.prog)
    if args.quiet:
        from pftrack._progress import set_quiet

        set_quiet(True)
    try:
        with warnings.catch_warnings(), _quiet_opencv(), _names_on_stdout(), sigterm_raises():
            warnings.showwarning = _one_line_warning(prog)
            with _stdout_named():
                status = int(args.func(args))
                if sys.stdout is not None:  # a buffered stdout's last lines: a closed pipe or
                    sys.stdout.flush()  # a full device fails here
        return status
    except BrokenPipeError:  # output piped into `head` and the like: stop quietly
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    except (OSError, ValueError, TypeError) as exc:  # OSError: missing, unwritable, full disk
        left = outcome(exc)  # a live track run's rows so far: where they are
        said = f"; {_shown(left)}" if left else ""
        print(f"{prog}: error: {_one_line(exc)}{said}", file=sys.stderr)
        return 2
    except Warning as exc:  # made an error by the filters (python -W error -m pftrack ...)
        left = outcome(exc)
        said = f"; {_shown(left)}" if left else ""
        # one line, not a traceback (was: the traceback of the warning's line; its status, 1)
        print(f"{prog}: error: {_one_line(exc)} (a warning, made an error){said}", file=sys.stderr)
        return 1
    except MemoryError as exc:
        left = outcome(exc)
        said = f"; {_shown(left)}" if left else ""
        print(f"{prog}: error: out of memory{said}", file=sys.stderr)
        return 2
    except Exception as exc:
        if not _opencv_error(exc):
            raise  # a defect of pftrack's: its traceback is what a report needs
        left = outcome(exc)
        said = f"; {_shown(left)}" if left else ""
        print(f"{prog}: error: {_one_line(exc)}{said}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:  # outputs are atomic: nothing half-written is left behind
        ignore_interrupts_to_exit()  # handled: a second Ctrl-C would cut the exit short
        how = "terminated (SIGTERM)" if isinstance(exc, Terminated) else "interrupted"
        left = _shown(outcome(exc) or NOTHING_CHANGED)
        # the line break ends a progress bar's line, drawn only on a terminal
        print(f"{line_end()}{prog}: {how}; {left}", file=sys.stderr)
        return exit_status(exc)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
