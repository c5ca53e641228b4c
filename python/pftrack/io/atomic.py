"""Atomic file output: write next to the target, then rename over it in one step.

The temporary file is created with mode ``0o666`` filtered by the process umask, as ``open``
would create the target itself (``tempfile.mkstemp`` would make every output ``0o600``). When
it replaces an existing file it takes that file's permission bits instead (``mode & 0o7777``,
set on creation and again just before the rename), so a file the user restricted to
``0o600`` is never replaced by a world-readable one, nor readable while it is written.

An output that is a symbolic link replaces the file at the end of the link's chain (the link
stays a link). One that is not a regular file (a character or block device such as
``/dev/null``, a FIFO, a socket) or names a descriptor (``/dev/stdout``, ``/dev/fd/N``,
``/proc/self/fd/N``) is written *through*: opened and written like ``open`` would, never
replaced, so ``--out /dev/null`` discards and ``--out /dev/stdout`` prints (and a named pipe
stays a pipe). Such a write is not atomic: a failure can leave part of it written.

After a Ctrl-C that the ``pftrack`` console script noted (:mod:`pftrack._interrupt`; code in
C may have dropped its ``KeyboardInterrupt``), no writer puts its output in place: each raises
``KeyboardInterrupt`` before its rename (before opening a device or pipe it writes through,
and before each write into one), removing its temporary file, so the command ends as
interrupted. Nothing else sets that flag: a program that imports pftrack writes as before.

Several outputs of one run (:func:`staged_outputs`) are renamed in one step that Ctrl-C and
SIGTERM cannot split (:func:`interrupts_deferred`): one that comes meanwhile is raised after
the last rename. A rename that fails puts back every target renamed before it, from a hidden
backup (``.NAME.<hex>.old``, a hard link) removed afterwards: all new, or all as they were.
Only a ``kill -9`` during those renames can leave such a backup; the first write of a later
run into its folder warns of it in one line naming it, and leaves it (:func:`_say_left_backups`).
"""

from __future__ import annotations

import contextlib
import errno
import functools
import os
import re
import secrets
import shutil
import signal
import stat
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any, cast

from pftrack._interrupt import raise_if_interrupted
from pftrack._typing import PathLike
from pftrack._warn import warn_outside

#: The descriptor folders of Linux's /proc (``/dev/fd`` and ``/proc/self`` resolve to them).
_FD_FOLDER = re.compile(r"/proc/(\d+)(?:/task/\d+)?/fd")
#: Symbolic links followed before giving up (Linux's own limit).
_MAX_LINKS = 40


@dataclass(frozen=True)
class _Target:
    """Where an output goes.

    Attributes
    ----------
    path : Path
        The file replaced or written: the path as given, or the end of its symbolic links.
    through : bool
        Written through (opened and written), not replaced: an existing file that is not a
        regular file or a folder, or a descriptor.
    fd : int or None
        This process's descriptor the path names (``/dev/stdout``: 1), written through a copy
        of it so the output goes where the descriptor points, at its offset.
    """

    path: Path
    through: bool = False
    fd: int | None = None


def _is_stream(target: _Target) -> bool:
    """Whether `target` is a pipe, FIFO or socket (a reader at its other end), not a device."""
    try:
        mode = os.fstat(target.fd).st_mode if target.fd is not None else target.path.stat().st_mode
    except OSError:
        return True  # unknown: as before, last
    return stat.S_ISFIFO(mode) or stat.S_ISSOCK(mode)


def _write_through(items: list[tuple[Path, _Target]]) -> None:
    """Copy each staged file into its device, FIFO or descriptor."""
    for tmp_path, resolved in items:
        with _named(resolved.path):  # /dev/full: "No space left on device" named no file
            _copy_through(tmp_path, resolved, empty_ok=True)  # as a regular file: may be empty


def _names_folder(text: str) -> bool:
    """Whether `text` can only name a folder: a trailing slash, or ``.`` or ``..`` last."""
    return text.endswith(("/", os.sep)) or os.path.basename(text) in ("", ".", "..")


def _resolve(path: PathLike) -> _Target:
    """Where output `path` goes: its symbolic links followed, special files written through."""
    text = os.fsdecode(os.fspath(path))
    p, followed = text, False
    for _ in range(_MAX_LINKS):
        folder, name = os.path.split(p)
        fd_folder = _FD_FOLDER.fullmatch(os.path.realpath(folder or "."))
        if fd_folder is not None and name.isdigit():  # /dev/stdout, /dev/fd/1, /proc/self/fd/1
            own = int(fd_folder.group(1)) == os.getpid()
            return _Target(Path(p), through=True, fd=int(name) if own else None)
        if not os.path.islink(p):
            break
        link = os.path.join(folder, os.readlink(p))
        base = os.path.basename(link)
        p = (
            os.path.realpath(link)
            if base in ("", ".", "..")
            else os.path.join(os.path.realpath(os.path.dirname(link) or "."), base)
        )
        followed = True
    else:
        raise OSError(errno.ELOOP, os.strerror(errno.ELOOP), text)
    try:
        mode = os.stat(p).st_mode
    except OSError:  # a new file (or one the write itself will fail on, with its own message)
        return _Target(Path(p if followed else text))
    through = not (stat.S_ISREG(mode) or stat.S_ISDIR(mode))
    return _Target(Path(p if followed else text), through=through)


def writes_through(path: PathLike) -> bool:
    """Whether output `path` is written through rather than replaced (see the module's notes).

    True for an existing device, FIFO or socket, or a descriptor (``/dev/stdout``), also at
    the end of symbolic links; False for a regular file, a folder, or a path that does not exist.
    """
    return _resolve(path).through


class _CheckedWrites:
    """A written-through file (:func:`atomic_write`) that refuses each write after a Ctrl-C.

    Each ``write`` and ``writelines`` first calls :func:`~pftrack._interrupt.raise_if_interrupted`;
    anything else is the file's own. For a pipe written as it goes (a live ``pftrack track``
    run's online rows into ``--out /dev/stdout``): the abort (a second Ctrl-C) that code in C
    dropped stops the rows at the next write. Was: checked only before the pipe was opened,
    so the rows of every frame after such an abort still went into it.
    """

    def __init__(self, file: IO[Any]) -> None:
        self._file = file

    def write(self, data: Any) -> int:
        """Write `data`, unless a Ctrl-C was noted (then ``KeyboardInterrupt``)."""
        raise_if_interrupted()
        return int(self._file.write(data))

    def writelines(self, lines: Iterable[Any]) -> None:
        """Write `lines`, unless a Ctrl-C was noted (then ``KeyboardInterrupt``)."""
        raise_if_interrupted()
        self._file.writelines(lines)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._file, name)


def _open_through(target: _Target, mode: str) -> IO[Any]:
    """Open a written-through `target` for writing (a descriptor: a copy of it)."""
    if target.fd is None:
        return open(target.path, mode)  # noqa: SIM115 - the caller closes it
    for stream in (sys.stdout, sys.stderr):  # what was printed comes first
        with contextlib.suppress(AttributeError, OSError, ValueError):
            stream.flush()
    return os.fdopen(os.dup(target.fd), mode)


def _refuse_folder_name(path: PathLike, what: str = "output") -> None:
    """ValueError when `path` can only name a folder (``newdir/``), or is one (or a link to one).

    Checked before anything is written: a file would be written as ``newdir``, and renaming
    the temporary file over a folder failed with ``IsADirectoryError: [Errno 21] Is a
    directory: '/x/.io.b3faca0eaadd.tmp' -> '/x/io'``, naming the hidden file.
    """
    text = os.fsdecode(os.fspath(path))
    if _names_folder(text):
        raise ValueError(f"{what} {text} names a folder; give a file name")
    if os.path.isdir(text):
        raise ValueError(f"{what} {text} is a folder; give a file name")


def _blocking(folder: Path) -> Path | None:
    """What stops `folder` from being a folder: a file at its place or above it, or None.

    The path itself or its nearest existing parent, when that is not a folder (``notes.txt``
    of ``notes.txt/x``). None when `folder` is a folder, or only missing (its nearest existing
    parent is one).
    """
    p = folder
    while not os.path.lexists(p) and p.parent != p:
        p = p.parent
    return None if os.path.isdir(p) else p


def _not_a_folder(path: Path) -> str:
    """``PATH is a file, not a folder`` (``is not a folder``: a device, a broken link)."""
    return f"{path} is a file, not a folder" if path.is_file() else f"{path} is not a folder"


def _missing_folder(folder: Path, target: PathLike) -> OSError:
    """The error of output `target`, whose `folder` is not a folder: missing, or a file.

    Was: ``output folder does not exist: notes.txt`` for ``notes.txt/x.txt``, where
    ``notes.txt`` exists, as a file.
    """
    blocker = _blocking(folder)
    if blocker is not None:
        return NotADirectoryError(
            f"output {os.fsdecode(os.fspath(target))}: {_not_a_folder(blocker)}"
        )
    return FileNotFoundError(f"output folder does not exist: {folder}")


#: Longest file name (bytes) of the usual file systems (ext4, XFS, APFS, NTFS in UTF-16 units).
NAME_MAX = 255


def _temp_name(prefix: str, token: str, suffix: str) -> str:
    """``prefix + token + suffix``, the prefix cut so that the name fits in :data:`NAME_MAX`.

    The prefix holds the target's name: a target of 240-255 bytes, a valid name, made a
    temporary name too long for the file system (was: "no file can be made in folder .
    (File name too long)").
    """
    name = f"{prefix}{token}{suffix}"
    excess = len(os.fsencode(name)) - NAME_MAX
    if excess > 0:
        cut = os.fsencode(prefix)[: max(1, len(os.fsencode(prefix)) - excess)]
        name = f"{cut.decode('utf-8', errors='ignore') or '.'}{token}{suffix}"
    return name


def _create_beside(folder: Path, prefix: str, suffix: str, made: list[str]) -> tuple[int, str]:
    """Create a new, unique file in `folder`; the kernel applies the umask to ``0o666``.

    Its path is appended to `made` before the file is created, and taken off again only when
    the creation failed: the caller removes what `made` holds if anything goes wrong, even a
    ``KeyboardInterrupt`` (Ctrl-C, SIGTERM) raised as ``os.open`` returns, before its result
    reaches anyone (Python checks for signals there).
    """
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0)
    for _ in range(100):
        path = os.path.join(folder, _temp_name(prefix, secrets.token_hex(6), suffix))
        made.append(path)
        try:
            return os.open(path, flags, 0o666), path
        except FileExistsError:
            made.pop()  # another's file
            continue
        except OSError:
            made.pop()  # no file was created
            raise
    raise FileExistsError(f"cannot create a temporary file in {folder}")


def _remove(made: Iterable[str]) -> None:
    """Remove the files :func:`_create_beside` made (those gone already are passed over).

    A ``KeyboardInterrupt`` (Ctrl-C, SIGTERM) raised while it removes them does not stop it:
    each file is still removed, and the interrupt is raised afterwards. A ``kill`` sent the
    moment a command's check of its output folder had made its probe file left that file
    behind (CI, at load 8: the interrupt came between the probe's creation and its removal).
    """
    _despite_interrupts(functools.partial(_unlink, path) for path in made)


def _unlink(path: str) -> None:
    """Remove file `path`; one gone already, or never made, is passed over."""
    with contextlib.suppress(OSError):
        os.unlink(path)


def _despite_interrupts(steps: Iterable[Callable[[], object]]) -> None:
    """Take each of `steps`; a ``KeyboardInterrupt`` meanwhile is raised once all are taken.

    The step it came in is taken again (it came before or after the step's work: doing it
    twice must be harmless), so no step is skipped.
    """
    stopped: BaseException | None = None
    for step in steps:
        while True:
            try:
                step()
            except KeyboardInterrupt as exc:  # before or after the step's work: again
                stopped = exc
                continue
            break
    if stopped is not None:
        raise stopped


def _existing_mode(target: Path) -> int | None:
    """The permission bits (``mode & 0o7777``) of the file `target` names; None if none does."""
    try:
        st = os.stat(target)
    except OSError:
        return None
    return stat.S_IMODE(st.st_mode) if stat.S_ISREG(st.st_mode) else None


def _keep_mode(tmp: str | int, target: Path) -> None:
    """Give `tmp` (a path or an open descriptor) the permission bits of an existing `target`.

    A new file (no `target` yet) keeps the umask default it was created with.
    """
    mode = _existing_mode(target)
    if mode is not None and (isinstance(tmp, str) or os.chmod in os.supports_fd):
        os.chmod(tmp, mode)


def _folder_of(target: Path, path: PathLike) -> Path:
    """The folder output `path` (resolved to the file `target`) is written in, which must exist.

    Raises
    ------
    OSError
        No such folder, or a file on the way (:func:`_missing_folder`).
    """
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise _missing_folder(folder, path)
    return folder


def _put_in_place(tmp: str, target: Path, path: PathLike) -> None:
    """Rename the finished temporary file `tmp` over `target`, with `target`'s permission bits.

    The bits are given again here, as a writer may have made `tmp` anew; an OSError names
    output `path`, not `tmp` (:func:`_named`). After a Ctrl-C that the ``pftrack`` process
    noted (:mod:`pftrack._interrupt`), it raises ``KeyboardInterrupt`` instead: code in C may
    have dropped the interrupt, and the command would have replaced `target` as if none came.
    """
    raise_if_interrupted()
    with _named(path, hidden=True):
        _keep_mode(tmp, target)
        os.replace(tmp, target)


@contextlib.contextmanager
def _named(path: PathLike, *, hidden: bool = False) -> Iterator[None]:
    """Name output `path` in an OSError that names no file (a full disk: ``[Errno 28] ...``).

    With `hidden` (making, or renaming, the hidden temporary file), in any OSError with an
    errno: it names that file, a name the user never gave (was ``[Errno 30] Read-only file
    system: '/x/.old.txt.f806e9cd1123.tmp'``, now ``'/x/old.txt'``). The class follows the
    errno, as ``OSError(errno, ...)`` picks it (``PermissionError`` for EACCES).
    """
    try:
        yield
    except OSError as exc:
        if exc.errno is None or (exc.filename is not None and not hidden):
            raise
        named = OSError(exc.errno, exc.strerror, os.fsdecode(os.fspath(path)))
        raise named from (None if hidden else exc)


@contextlib.contextmanager
def atomic_write(
    path: PathLike, mode: str = "w", *, suffix: str | None = None
) -> Iterator[IO[Any]]:
    """Open a temporary file beside `path`; on success it replaces `path` atomically.

    If the block raises, the temporary file is removed and `path` is left exactly as it was,
    so a crash or a bad input never destroys a user's earlier output. A new file follows the
    umask; one that replaces an existing file gets that file's permission bits.

    Parameters
    ----------
    path : str or os.PathLike
        Final destination. Its folder must exist.
    mode : {"w", "wb"}
        Text or binary.
    suffix : str, optional
        Suffix of the temporary file (some writers, e.g. OpenCV's, pick a format by extension).

    Notes
    -----
    A symbolic link `path` replaces the file the link leads to; a device, FIFO, socket or
    descriptor (``/dev/null``, ``/dev/stdout``) is opened and written, not replaced, and not
    atomically (see the module's notes).

    Raises
    ------
    ValueError
        `path` can only name a folder (a trailing slash, ``.``), or is an existing folder.
    OSError
        The temporary file cannot be made, written or renamed (a read-only file system, a
        folder without write permission, a full disk): the error names `path`, never the
        temporary file, and `path` is left as it was.
    """
    _refuse_folder_name(path)
    resolved = _resolve(path)
    if resolved.through:
        raise_if_interrupted()  # written as it goes: refused before it begins (_put_in_place)
        with _named(path), _open_through(resolved, mode) as fh:
            yield cast("IO[Any]", _CheckedWrites(fh))  # and before each write
        return
    target = resolved.path
    folder = _folder_of(target, path)
    _say_left_backups(folder)
    made: list[str] = []
    try:  # the file is made inside: removed whenever the block is left by an exception
        with _named(path, hidden=True):  # a read-only file system, a folder not writable
            fd, tmp = _create_beside(folder, f".{target.name}.", suffix or ".tmp", made)
            _keep_mode(fd, target)
        with _named(path), os.fdopen(fd, mode) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        _put_in_place(tmp, target, path)
    except BaseException:
        _remove(made)
        raise


@contextlib.contextmanager
def atomic_path(path: PathLike) -> Iterator[Path]:
    """Yield a temporary path (same folder, same extension) that replaces `path` on success.

    For writers that want a file name rather than a handle (``cv2.VideoWriter``, ``cv2.imwrite``).
    Permissions as for :func:`atomic_write`: an existing file's are kept. A symbolic link
    replaces the file it leads to; a device, FIFO or descriptor gets the finished file's bytes
    written into it (the temporary file is then in the system's temporary folder).
    """
    _refuse_folder_name(path)
    resolved = _resolve(path)
    if resolved.through:
        with tempfile.TemporaryDirectory(prefix="pftrack-") as scratch:
            tmp_path = Path(scratch) / f"out{Path(path).suffix}"
            yield tmp_path
            raise_if_interrupted()  # as _put_in_place
            with _named(path):
                _copy_through(tmp_path, resolved)
        return
    target = resolved.path
    folder = _folder_of(target, path)
    _say_left_backups(folder)
    made: list[str] = []
    try:  # the file is made inside: removed whenever the block is left by an exception
        with _named(path, hidden=True):  # a read-only file system, a folder not writable
            fd, tmp = _create_beside(folder, f".{target.stem}.", Path(path).suffix, made)
            try:
                _keep_mode(fd, target)
            finally:
                os.close(fd)
        yield Path(tmp)
        if not Path(tmp).exists() or Path(tmp).stat().st_size == 0:
            raise OSError(f"nothing was written for {target}")
        _put_in_place(tmp, target, path)
    except BaseException:
        _remove(made)
        raise


@dataclass
class SideFile:
    """A hidden text file beside an output, holding what a run has so far (:func:`side_file`).

    Attributes
    ----------
    path : Path
        Where the lines are: the hidden file while the block runs; once it has raised, the
        file they were kept in (see :attr:`kept`).
    lines : int
        Lines written so far (:meth:`write_lines`).
    kept : Path or None
        After the block raised with lines written: the file that holds them. None otherwise
        (the side file is then removed).
    """

    file: IO[str]
    path: Path
    lines: int = 0
    kept: Path | None = None

    def write_lines(self, lines: Iterable[str]) -> None:
        """Append `lines` (without their line ends), then flush them to the file.

        An OSError that names no file (a full disk) names the side file.
        """
        with _named(self.path):
            for line in lines:
                self.file.write(line + "\n")
                self.lines += 1
            self.file.flush()


#: Names :func:`side_file` tries for the lines of a failed run before keeping its hidden name.
PARTIAL_NAMES = 100


def partial_name(path: PathLike, k: int = 1) -> Path:
    """The `k`-th name :func:`side_file` tries for a failed run's lines, beside output `path`.

    ``tracks.txt`` gives ``tracks.partial.txt``, then (``k`` = 2, 3, ...)
    ``tracks.partial-2.txt``, ...; a symbolic link's target names the folder.
    """
    target = _resolve(path).path
    tag = "partial" if k == 1 else f"partial-{k}"
    return target.with_name(f"{target.stem}.{tag}{target.suffix}")


def _keep(tmp: Path, path: PathLike) -> Path:
    """Give the side file `tmp` the first free :func:`partial_name` of `path`; return its name.

    A hard link then the removal of `tmp`: an existing file is never replaced. Where links
    cannot be made (some file systems), or every name is taken, `tmp` keeps its own name.
    """
    for k in range(1, PARTIAL_NAMES + 1):
        wanted = partial_name(path, k)
        try:
            os.link(tmp, wanted)
        except FileExistsError:
            continue
        except OSError:
            return tmp
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        return wanted
    return tmp


@contextlib.contextmanager
def side_file(path: PathLike, suffix: str = ".part") -> Iterator[SideFile]:
    """A new hidden text file beside output `path` for a run's lines as they come; see below.

    The file, ``.NAME.<hex>.part``, is made in the folder `path` is written to (the end of
    its symbolic links) with the permission bits of an existing `path`, as
    :func:`atomic_write`'s temporary file; `path` itself is not touched. When the block ends
    normally, the file is removed (the caller has written its finished output by then). When
    it raises (an error, Ctrl-C, SIGTERM), a file holding lines is kept, under the first
    :func:`partial_name` no file has (``tracks.partial.txt``, ``tracks.partial-2.txt``, ...;
    no existing file is replaced), else under its hidden name; :attr:`SideFile.kept` says
    which. One without lines is removed.

    Parameters
    ----------
    path : str or os.PathLike
        The output the lines stand in for. Not a device, pipe or descriptor (those are written
        through: :func:`writes_through`).
    suffix : str
        Suffix of the hidden file.

    Raises
    ------
    ValueError
        `path` can only name a folder (a trailing slash, ``.``), or is written through.
    FileNotFoundError
        Its folder does not exist.
    """
    _refuse_folder_name(path)
    resolved = _resolve(path)
    if resolved.through:
        raise ValueError(f"{os.fsdecode(os.fspath(path))} is written through; no side file")
    target = resolved.path
    folder = _folder_of(target, path)
    made: list[str] = []
    side: SideFile | None = None
    try:  # the file is made inside: removed whenever the block is left without lines
        fd, tmp = _create_beside(folder, f".{target.name}.", suffix, made)
        _keep_mode(fd, target)
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            side = SideFile(fh, Path(tmp))
            yield side
    except BaseException:
        if side is not None and side.lines:
            side.kept = side.path = _keep(side.path, path)
        else:
            _remove(made)
        raise
    _remove(made)


def _copy_through(tmp: Path, target: _Target, *, empty_ok: bool = False) -> None:
    """Write the finished file `tmp` into the written-through `target`.

    OSError when `tmp` is missing or empty, unless `empty_ok` (then nothing is written).
    """
    if not tmp.exists() or tmp.stat().st_size == 0:
        if empty_ok:
            with _open_through(target, "wb"):  # opened as a regular file would be replaced
                return
        raise OSError(f"nothing was written for {target.path}")
    with tmp.open("rb") as src, _open_through(target, "wb") as dst:
        shutil.copyfileobj(src, dst)


def link_loop(path: PathLike) -> str | None:
    """``a -> b -> a`` when `path`'s symbolic links lead to each other, else None.

    The links `path` leads through, as ``readlink`` gives them, up to the first one met again;
    for a loop on the way to `path` (a folder above it), that it lies beyond one.
    """
    path = Path(os.fspath(path))
    try:
        os.stat(path)
        return None
    except OSError as exc:
        if exc.errno != errno.ELOOP:
            return None
    chain, seen, p = [str(path)], set(), path
    while p.is_symlink() and len(chain) < 10:
        key = os.path.abspath(p)
        if key in seen:
            return " -> ".join(chain)
        seen.add(key)
        target = os.readlink(p)
        chain.append(target)
        p = p.parent / target
    if len(chain) > 1:
        return " -> ".join([*chain, "..."])
    return "a folder on its way is one"


def refuse_loop(path: PathLike, what: str) -> None:
    """Refuse an input `path` whose symbolic links lead to each other, or to nothing.

    Was: ``video source not found: a`` for ``a -> b -> a`` (with ``b`` there, a link), and for
    a link whose target was moved or deleted (``ls`` lists ``a``), as ``pftrack batch`` names
    it. Paths that may be such loops are compared with ``os.path.realpath``, which stops at a
    loop, not ``Path.resolve``, which raised a RuntimeError there (a traceback) before Python
    3.13.

    Raises
    ------
    ValueError
        ``WHAT PATH: symbolic link loop (a -> b -> a), ...``.
    FileNotFoundError
        ``WHAT not found: PATH is a broken symbolic link (to TARGET)``.
    """
    loop = link_loop(path)
    if loop is not None:
        raise ValueError(
            f"{what} {os.fspath(path)}: symbolic link loop ({loop}), which leads to no file or "
            "folder; point the link at one"
        )
    if os.path.islink(path) and not os.path.exists(path):
        raise FileNotFoundError(
            f"{what} not found: {os.fspath(path)} is a broken symbolic link (to "
            f"{os.readlink(path)})"
        )


def refuse_dash(
    path: PathLike, what: str, *, output: bool = False, name: str = "file", or_else: str = ""
) -> None:
    """Refuse ``-`` for an output folder, or for an input that does not exist by that name.

    Output files refuse it in :func:`check_output`; a folder cannot be standard output, and
    the inputs are read by name (a tracks file twice, to name a bad line). Was: a folder named
    ``-`` created, or ``tracks file not found: -``. An input file that is named ``-`` is read.

    Parameters
    ----------
    path : str or os.PathLike
        What was given.
    what : str
        How the message names it (``"--out"``, ``"tracks file"``).
    output : bool
        An output folder (standard output), else an input (standard input).
    name : str
        What to give instead (``"folder"``, ``"file"``, ``"video, image folder or sequence
        folder"``).
    or_else : str
        Added to the message (``", or /dev/stdout"`` for an output file).

    Raises
    ------
    ValueError
        `path` is ``-`` (as an input: and no such file exists).
    """
    if os.fsdecode(os.fspath(path)) != "-" or (not output and os.path.lexists("-")):
        return
    stream = "standard output" if output else "standard input"
    raise ValueError(
        f"{what} -: {stream} is not supported by name '-'; give a {name} name{or_else}"
    )


def check_output_folder(path: PathLike, what: str) -> Path:
    """Check, before any work, an output folder option (``--out-dir``); return it as a Path.

    The folder need not exist (:func:`made_folder` creates it).

    Raises
    ------
    ValueError
        It is empty (``Path("")`` is the current folder: was, the outputs written there), ``-``
        (standard output), or an existing file.
    NotADirectoryError
        It lies under a file (``notes.txt/out``).
    PermissionError
        It cannot take new files, or cannot be made where it is to be (the nearest existing
        folder above it is not writable).
    """
    text = os.fsdecode(os.fspath(path))
    if not text:
        raise ValueError(f"{what} is empty; give a folder name")
    refuse_dash(text, what, output=True, name="folder")
    target = Path(text)
    blocker = _blocking(target)
    if blocker == target and target.exists():  # its own place holds a file (not a folder)
        raise ValueError(f"{what} {target} is a file; give a folder")
    if blocker is not None:  # a file above it: was "cannot create the folder (Not a directory)"
        raise NotADirectoryError(f"{what} {target}: {_not_a_folder(blocker)}")
    _check_folder_writable(target, what)
    return target


def _check_folder_writable(target: Path, what: str) -> None:
    """Refuse output folder `target` if it cannot take new files, or cannot be made.

    Checked where it is, or for a missing one where it is to be made (the nearest folder above
    it that exists), by making a folder there and removing it (``access()`` says yes to root on
    a read-only file system). Was: ``pftrack batch`` found out only once its local cluster had
    started, seconds later, and a missing folder under ``/proc/sys`` was "cannot create the
    folder (No such file or directory)".
    """
    folder = target
    while not folder.is_dir():
        if folder.parent == folder:
            return  # no folder above it at all: its creation says why
        folder = folder.parent
    try:  # tried before access(), whose no does not say why (a read-only file system)
        with interrupts_deferred():  # the probe is gone before a Ctrl-C or a kill is raised
            os.rmdir(tempfile.mkdtemp(prefix=".pftrack-probe-", dir=folder))
    except OSError as exc:
        why = _cause(exc)
    else:
        if os.access(folder, os.W_OK | os.X_OK):
            return
        why = os.strerror(errno.EACCES)
    if folder == target:
        raise PermissionError(
            f"{what} {target}: the folder is not writable ({why}): no output can be "
            "written in it; write elsewhere"
        )
    raise PermissionError(
        f"{what} {target}: cannot create the folder: {folder} is not writable ({why}); "
        "write elsewhere"
    )


def _remove_empty(folders: Iterable[Path]) -> None:
    """Remove `folders` (deepest first) while they are empty; stop at the first that is not."""
    for folder in folders:
        try:
            os.rmdir(folder)
        except OSError:
            return


@contextlib.contextmanager
def made_folder(path: PathLike, what: str) -> Iterator[Path]:
    """Create output folder `path` (its missing parents too) for the block's outputs.

    When the block raises (an error, Ctrl-C, SIGTERM), the folders created here that are still
    empty are removed again, so a run that wrote nothing leaves nothing (a folder that existed
    before is kept). Was: ``pftrack demo`` interrupted left its new ``--out-dir`` behind, empty,
    while saying that no output was changed.

    Raises
    ------
    ValueError
        The folder cannot be created (a read-only file system), naming `what`.
    """
    target = Path(path)
    new = [p for p in (target, *target.parents) if not os.path.lexists(p)]  # deepest first
    try:
        target.mkdir(parents=True, exist_ok=True)
    except OSError as exc:  # a read-only or special file system, a file on the way
        _remove_empty(new)
        raise ValueError(f"{what} {target}: cannot create the folder ({exc.strerror})") from None
    try:
        yield target
    except BaseException:
        _remove_empty(new)
        raise


def check_output(
    path: PathLike,
    *,
    what: str = "output",
    suffixes: tuple[str, ...] | None = None,
    inputs: tuple[PathLike, ...] = (),
    within: PathLike | None = None,
    tracks: bool = False,
) -> Path:
    """Check, before any work, that `path` can be written; return it as a :class:`Path`.

    Parameters
    ----------
    path : str or os.PathLike
        The output file.
    what : str
        How error messages name it (e.g. ``"--render"``).
    suffixes : tuple of str, optional
        Accepted extensions, lower case with the dot (e.g. ``(".mp4", ".avi")``).
    inputs : tuple of paths
        Files the run reads: the output must not be one of them.
    within : str or os.PathLike, optional
        The output folder `what` names, when `path` is a file the command names in it
        (``pftrack demo --out-dir DIR``'s ``DIR/tracks.txt``): a folder in the way is then
        blamed on the path inside `within`, not taken for the user's file name.
    tracks : bool
        Whether `path` takes a tracks file (MOTChallenge text: ``--out`` of ``pftrack track``,
        ``recover`` and ``smooth``): an existing file there that is not text (NUL bytes in its
        first 8 KiB: a video, a picture) is then refused, so that ``--out annotated.mp4``
        typed for ``--render annotated.mp4`` does not replace the video with text (was:
        replaced without a word). Which text file is replaced is :func:`check_replaceable`'s
        (:func:`pftrack.io.mot.is_mot_text`: MOTChallenge rows, or ``--force``).

    Raises
    ------
    ValueError
        The path is empty; the extension is not supported; for a tracks file (`tracks`), an
        existing file that is not text; the path is a folder, or can only
        name one (a trailing slash: ``newdir/``); it is ``-`` (standard output: give
        ``/dev/stdout``); or it names an input.
    FileNotFoundError
        Its folder does not exist.
    NotADirectoryError
        Its folder is a file (``notes.txt/x.txt``), or lies under one.
    PermissionError
        Its folder (or the existing file) is not writable: checked by creating (and removing)
        a file beside it.
    OSError
        Its symbolic links cannot be followed (a loop: ``a`` to ``b`` to ``a``), naming `what`.

    Notes
    -----
    A symbolic link is checked where it leads: the folder of the file at its end must be
    writable. A device, FIFO, socket or descriptor (``/dev/null``, ``/dev/stdout``) is written
    through (see the module's notes): it must be writable itself, its folder need not be.
    """
    text = os.fsdecode(os.fspath(path))
    if not text:  # Path("") is ".": was "--out . is a folder; give a file name"
        raise ValueError(f"{what} is empty; give a file name")
    target = Path(path)
    refuse_dash(text, what, output=True, or_else=", or /dev/stdout")
    if target.is_dir():
        if within is not None:  # not the user's name: was "--out-dir d/tracks.txt is a folder;
            # give a file name"
            raise ValueError(
                f"{what} {os.fsdecode(os.fspath(within))}: {target} is a folder, where this "
                f"command writes a file; move it, or give another {what}"
            )
        raise ValueError(f"{what} {target} is a folder; give a file name")
    _refuse_folder_name(text, what)
    try:
        resolved = _resolve(text)
    except OSError as exc:  # links that lead to each other: was "Too many levels ...: loopA"
        raise OSError(f"{what} {target}: {exc.strerror or exc}") from None
    if suffixes is not None:
        output_format(text, suffixes, what)  # a device without extension: the first
    written = resolved.path
    if resolved.through:
        if resolved.fd is None and not os.access(written, os.W_OK):
            raise PermissionError(f"{what} {target}: not writable")
    else:
        _check_folder(written, what, target)
    if _one_of(target, inputs):
        raise ValueError(f"{what} {target} is an input of this run; write elsewhere")
    if tracks and not resolved.through:
        _refuse_binary(written, what, text)
    return target


def check_replaceable(
    path: PathLike,
    what: str,
    ours: Callable[[Path], bool],
    *,
    force: bool = False,
    yours: str = "pftrack did not write (a video of yours?)",
) -> None:
    """Refuse to replace a non-empty file at `path` that `ours` says pftrack did not write.

    The one rule of every output option (docs/io.md, "What an output may replace"): an absent
    path, an empty file, a device or pipe, or a file `ours` accepts is replaced; any other is
    refused, unless `force` (the command's ``--force``). `ours`: a test of the output's kind
    (:func:`pftrack.io.video_writer.is_render`, :mod:`pftrack.io.marks`); `yours` what such
    a file is, and may be, for the message. Called after :func:`check_output` and
    :func:`check_distinct`, whose messages say more.

    Raises
    ------
    ValueError
        Such a file, naming `what` (was: a user's file replaced, exit status 0).
    """
    if force or replaceable(path, ours):
        return
    raise ValueError(
        f"{what} {os.fsdecode(os.fspath(path))} is an existing file that {yours}, "
        "and would be replaced: move it, give another name, or pass --force"
    )


def replaceable(path: PathLike, ours: Callable[[Path], bool]) -> bool:
    """Whether an output may replace what is at `path` without ``--force``.

    :func:`check_replaceable`'s rule, for a caller with its own message (``pftrack batch``'s
    renders): an absent path, an empty file, a device or pipe, one that cannot be read (the
    write says so), or a file `ours` accepts.
    """
    try:
        written = _resolve(os.fsdecode(os.fspath(path)))
        if written.through or not written.path.is_file() or written.path.stat().st_size == 0:
            return True  # nothing there to lose
    except OSError:  # unreadable: the write says so
        return True
    return ours(written.path)


def _refuse_binary(written: Path, what: str, text: str) -> None:
    """Refuse to replace an existing file that is not text with tracks (:func:`check_output`)."""
    try:
        with open(written, "rb") as f:
            head = f.read(8192)
    except OSError:  # none there yet (or unreadable: the write says so)
        return
    if b"\0" in head:
        raise ValueError(
            f"{what} {text} is an existing file that is not text (a video? a picture?), and "
            f"{what} writes the tracks as MOTChallenge text over it: give a .txt name "
            "(--render and pftrack render write videos, --plot pictures)"
        )


def _one_of(target: Path, files: Iterable[PathLike]) -> bool:
    """Whether `target` is one of `files` (as :func:`_same_file`, one ``stat`` per file).

    For the thousands of images of an input folder: the target is looked at once.
    """
    try:
        st = os.stat(target)
    except OSError:
        st = None
    target_path: str | None = None  # realpath: a link loop is a path, not an error
    for f in files:
        try:
            other = os.stat(f)
        except OSError:  # a missing input: compared by its resolved path
            target_path = target_path or os.path.realpath(target)
            if os.path.realpath(f) == target_path:
                return True
            continue
        if st is not None and (other.st_dev, other.st_ino) == (st.st_dev, st.st_ino):
            return True  # the same file: links, hard links, bind mounts, "..", "./"
    return False


def output_format(path: PathLike, suffixes: tuple[str, ...], what: str = "output") -> str:
    """The format output `path` is written in: its extension, one of `suffixes` (lower case).

    A device, pipe or descriptor without an extension (``/dev/null``, ``/dev/stdout``, a named
    pipe ``fifo``) takes the first of `suffixes`, the default format: its name cannot say one.

    Raises
    ------
    ValueError
        Any other extension that is not one of `suffixes`.
    """
    text = os.fsdecode(os.fspath(path))
    suffix = Path(text).suffix.lower()
    if suffix in suffixes:
        return suffix
    if not suffix and _resolve(text).through:
        return suffixes[0]
    raise ValueError(
        f"{what} {text}: unsupported extension {Path(text).suffix or '(none)'!r}, expected "
        f"one of {', '.join(suffixes)}"
    )


def _check_folder(written: Path, what: str, target: Path) -> None:
    """`written`'s folder exists and takes a new file (the atomic write's temporary file)."""
    folder = written.parent if str(written.parent) else Path(".")
    if not folder.is_dir():
        blocker = _blocking(folder)
        if blocker is not None:  # was "folder notes.txt does not exist": it does, as a file
            raise NotADirectoryError(f"{what} {target}: {_not_a_folder(blocker)}")
        raise FileNotFoundError(f"{what} {target}: folder {folder} does not exist")
    made: list[str] = []
    with interrupts_deferred():  # the probe is gone before a Ctrl-C or a kill is raised
        try:  # tried first: access() says yes to root on a special file system, and its no
            # does not say why (a read-only file system)
            fd, _ = _create_beside(folder, f".{written.name}.", ".probe", made)
            os.close(fd)
        except OSError as exc:
            if exc.errno in (errno.EACCES, errno.EPERM, errno.EROFS):
                raise PermissionError(f"{what} {target}: not writable ({_cause(exc)})") from None
            raise PermissionError(
                f"{what} {target}: no file can be made in folder {folder} ({_cause(exc)})"
            ) from None
        finally:
            _remove(made)
    if not os.access(folder, os.W_OK | os.X_OK) or (
        written.exists() and not os.access(written, os.W_OK)
    ):
        raise PermissionError(f"{what} {target}: not writable")


def _cause(exc: OSError) -> str:
    """Why an output check's probe failed, for its message: a read-only file system by name.

    Was "not writable", or "(Permission denied)" from ``pftrack demo``, on a read-only file
    system: ``access()`` said no, which does not say why.
    """
    if exc.errno == errno.EROFS:
        return "read-only file system"
    return exc.strerror or str(exc)


#: What :func:`interrupts_deferred` holds: Ctrl-C, and SIGTERM, which the ``pftrack`` command
#: turns into a ``KeyboardInterrupt`` too (:mod:`pftrack.cli._signals`).
_DEFERRED_SIGNALS = frozenset(
    getattr(signal, name) for name in ("SIGINT", "SIGTERM") if hasattr(signal, name)
)


@contextlib.contextmanager
def interrupts_deferred() -> Iterator[None]:
    """Meanwhile Ctrl-C (SIGINT) and SIGTERM wait; each one that came is raised when it ends.

    For a step an interrupt must not split: making and removing a probe file, renaming a
    run's outputs one after the other (:func:`staged_outputs`), starting or closing a local
    Dask cluster (``pftrack.batch.engine``). The signals are blocked in the main thread, and
    their handlers replaced by one that notes them: a signal mask is per thread, so a signal
    sent to the process is taken by another thread that has it unblocked
    (OpenBLAS's and OpenCV's, started when NumPy and cv2 load; a render thread), and Python
    then runs its handler in the main thread at the next chance, inside the block. At the end
    the mask and the handlers are restored and each signal noted is sent again, to the handler
    it was meant for (``KeyboardInterrupt``, :class:`~pftrack._interrupt.Terminated`, or a
    process ended by a SIGTERM no handler takes, as it would have been a moment earlier).
    Only in the main thread, where Python runs signal handlers (elsewhere it does nothing: the
    interrupt is raised in the main thread, not in this one), and where the platform can
    block signals.
    """
    if not hasattr(signal, "pthread_sigmask") or (
        threading.current_thread() is not threading.main_thread()
    ):
        yield
        return
    noted: list[int] = []
    handlers: dict[int, Any] = {}
    for signum in _DEFERRED_SIGNALS:
        if signal.getsignal(signum) is not None:  # None: set outside Python, left alone
            handlers[signum] = signal.signal(signum, lambda n, _: noted.append(n))
    old = signal.pthread_sigmask(signal.SIG_BLOCK, _DEFERRED_SIGNALS)
    try:
        yield
    finally:
        # a signal held in this thread is taken as the mask is restored, and noted there
        # (pthread_sigmask runs the handlers before it returns)
        signal.pthread_sigmask(signal.SIG_SETMASK, old)
        _restore(handlers)
        for signum in dict.fromkeys(noted):  # KeyboardInterrupt (Terminated) from here
            signal.raise_signal(signum)


def _restore(handlers: Mapping[int, Any]) -> None:
    """Set each signal's handler back; an interrupt meanwhile is raised once all are back.

    A signal that comes now, once its own handler is back, raises between two of these
    steps: the handlers after it would stay :func:`interrupts_deferred`'s, which only note.
    """
    _despite_interrupts(functools.partial(signal.signal, n, h) for n, h in handlers.items())


def _same_file(a: Path, b: Path) -> bool:
    """Whether `a` and `b` name one file: the same path once resolved, or one file on disk."""
    if a.exists() and b.exists() and os.path.samefile(a, b):
        return True  # hard links, bind mounts
    return os.path.realpath(a) == os.path.realpath(b)


def _is_devnull(path: Path) -> bool:
    """Whether `path` is (or leads to) the null device."""
    try:
        return os.path.samefile(path, os.devnull)
    except OSError:
        return False


def check_distinct(outputs: Mapping[str, PathLike | None]) -> None:
    """Check, before any work, that no two outputs of one run are the same file.

    Parameters
    ----------
    outputs : mapping of str to path or None
        Each output by the name error messages give it (e.g. ``"--render"``); None: not written.

    Raises
    ------
    ValueError
        Two of them name one file (one would overwrite the other), naming both. The null
        device (``/dev/null``, or a link to it) may take several.
    """
    seen: list[tuple[str, Path]] = []
    for what, path in outputs.items():
        if path is None:
            continue
        target = Path(path)
        if _is_devnull(target):  # discarded: any number of outputs may go there
            continue
        for other_what, other in seen:
            if _same_file(target, other):
                raise ValueError(
                    f"{other_what} {other} and {what} {target} are the same file; give each "
                    "output its own"
                )
        seen.append((what, target))


def _remove_nested(tmp: Path) -> None:
    """Remove the temporary files an atomic writer made beside staged file `tmp` for it.

    A writer given a staged path writes it atomically in turn (``VideoWriter``:
    ``..t.<hex>.<hex>.mp4`` for ``.t.<hex>.mp4``); interrupted between making its file and
    handing it over (Ctrl-C, SIGTERM), nobody else knows that file. Its name starts with
    ``.`` and `tmp`'s stem, whose random part no other file has.

    The writer's own clean-up covers a signal between creating its file and entering its
    ``try`` (:func:`_create_beside` lists the file first). It cannot cover one raised after
    its generator has yielded, before a caller holds what would close it: in
    ``contextlib``'s ``__enter__`` once ``next(gen)`` returns, in ``ExitStack.enter_context``
    before the exit is pushed, in ``VideoWriter.__init__``, in ``TrackRenderer.__init__``
    once its render thread runs (the thread then keeps the writer alive for good), or
    before the caller's ``renderer = ...`` binds the result. The file then waits for the
    suspended generator to be collected: once the exception is dropped, or never (the
    thread's case). Measured by raising ``KeyboardInterrupt`` at each of the 979 bytecode
    steps of ``stage()`` and ``TrackRenderer(...)`` (every place a signal's exception can
    come, and more): without this function the nested file outlived this clean-up at 102,
    3 of them for good; with it, at none.
    """
    with contextlib.suppress(OSError):
        for entry in os.scandir(tmp.parent):
            if entry.name.startswith(f".{tmp.stem}."):
                with contextlib.suppress(OSError):
                    os.unlink(entry.path)


def _as_targets(exc: OSError, staged: Iterable[tuple[str, Path]]) -> OSError | None:
    """`exc` naming the target of each staged temporary file it names; None if it names none.

    A writer filling a staged file reports its own errors (``No space left on device:
    'out/.o.2833ba0ccefe.txt'``) with a name the user never gave.
    """
    text = str(exc)
    hit = False
    for tmp, target in staged:
        if tmp in text:
            text, hit = text.replace(tmp, os.fsdecode(target)), True
    if not hit:
        return None
    if exc.errno is not None and exc.filename is not None:
        name = os.fsdecode(exc.filename)
        for tmp, target in staged:
            name = name.replace(tmp, os.fsdecode(target))
        return OSError(exc.errno, exc.strerror, name)
    return OSError(text)


#: Suffix of the hidden backup (``.NAME.<hex>.old``) that keeps a target's earlier contents
#: while :func:`staged_outputs` renames a run's outputs into place.
BACKUP_SUFFIX = ".old"
#: A backup's name: ``.NAME.`` (cut to fit ``NAME_MAX``), 12 hex digits, :data:`BACKUP_SUFFIX`.
_BACKUP_NAME = re.compile(r"\.(.*)\.[0-9a-f]{12}" + re.escape(BACKUP_SUFFIX), re.DOTALL)
#: The folders whose left backups this process has said (each is said once, not per write).
_LOOKED: set[str] = set()
_LOOKED_LOCK = threading.Lock()


def _say_left_backups(folder: Path) -> None:
    """Warn, one line each, of the backups (``.NAME.<hex>.old``) a killed run left in `folder`.

    And of its temporary files (:data:`_TEMP_NAME`) unwritten for :data:`STALE_SECONDS` or
    more (:func:`_left_temporary`), which only such a run leaves.

    Only a ``kill -9`` (or a power cut) during :func:`staged_outputs`' renames leaves one; it
    may hold a target's earlier contents, and without hard links it is their only copy (the
    target itself was moved there). Nothing reads or removes it: the user is told, once per
    folder and process, on the first write into that folder, and the file is left as it is
    (was: kept without a word).
    """
    key = os.path.realpath(folder)
    with _LOOKED_LOCK:
        if key in _LOOKED:
            return
        _LOOKED.add(key)
    try:
        with os.scandir(folder) as entries:
            names = sorted(e.name for e in entries if e.is_file(follow_symlinks=False))
    except OSError:
        return  # not readable: the write says what is wrong, if anything
    now = time.time()
    for name in names:
        found = _BACKUP_NAME.fullmatch(name)
        if found is not None:
            warn_outside(_left_backup(folder / name, folder / found.group(1)))
        elif _TEMP_NAME.fullmatch(name) and not name.endswith(_KEPT_SUFFIXES):
            with contextlib.suppress(OSError):  # gone meanwhile: its run finished
                age = now - os.lstat(folder / name).st_mtime
                if age >= STALE_SECONDS:
                    warn_outside(_left_temporary(folder / name, age))


#: How long a temporary file (:data:`_TEMP_NAME`) must have gone unwritten before
#: :func:`_say_left_backups` calls it left: a run writing its video writes it every frame, and
#: its other temporaries exist only while they are written, at its end.
STALE_SECONDS = 600.0
#: The hidden names pftrack's writers give their temporary files: ``.NAME.<hex>SUFFIX``
#: (:func:`atomic_write`, :func:`atomic_path`, :func:`staged_outputs`), ``..NAME.<hex>.<hex>
#: SUFFIX`` (a video written into a staged file), ``.NAME.<hex>.probe`` (the output check's).
_TEMP_NAME = re.compile(r"\.\.?.+\.[0-9a-f]{12}(\.[0-9a-f]{12})?(\.[^.]+)?", re.DOTALL)
#: Suffixes of hidden files said otherwise: backups (above), and a live run's online rows
#: kept on purpose after a second Ctrl-C (``.part``, :func:`side_file`; the run says where).
_KEPT_SUFFIXES = (BACKUP_SUFFIX, ".part")


def _left_temporary(path: Path, age: float) -> str:
    """The one line :func:`_say_left_backups` gives for a temporary file left `age` s ago.

    Ctrl-C and SIGTERM remove a run's temporary files; ``kill -9``, the out-of-memory killer
    or a power cut cannot, and each left one stayed unsaid beside the outputs, never read nor
    removed (a trial at stop 74: ``.r.<hex>.mp4`` and ``..r.<hex>.<hex>.mp4``, 6 MB, for a
    ``track --render`` killed 4 s in; a later run left them as they were).
    """
    hours = age / 3600
    when = f"{hours:.0f} h" if hours >= 1 else f"{age / 60:.0f} min"
    return (
        f"{path} is a partial file of a pftrack run that stopped writing it {when} ago (killed: "
        "kill -9, out of memory, a power cut) and left it; nothing reads it: delete it, unless "
        "a run that is still going (paused?) writes there"
    )


def _left_backup(backup: Path, target: Path) -> str:
    """The one line :func:`_say_left_backups` gives for `backup`, a backup of `target`."""
    said = f"{backup} was left by a pftrack run killed while it replaced {target.name}"
    try:
        a, b = os.lstat(backup), os.lstat(target)
    except FileNotFoundError:  # no hard links there: the target itself was moved to it
        return f"{said}, and is that file's only copy: move it back (mv {backup} {target})"
    except OSError:
        return f"{said}; it is kept: delete it once {target.name} is as you want it"
    if (a.st_dev, a.st_ino) == (b.st_dev, b.st_ino):
        return f"{said}, and is another name for {target.name} as it is: delete it, nothing is lost"
    return (
        f"{said}, and holds its earlier contents: delete it, or move it back over "
        f"{target.name} to have them again"
    )


def _back_up(target: Path, listed: list[str]) -> tuple[str | None, bool]:
    """Keep what `target` holds reachable under a new hidden name beside it.

    Returns that name (None: nothing kept) and whether `target` was moved there.

    A hard link (no copy, and `target` stays in place); where the file system makes none
    (``EPERM``, ``EOPNOTSUPP``, too many links), `target` itself is renamed to the new name,
    over an empty file :func:`_create_beside` made for it. The name is appended to `listed`
    before it is made, as :func:`_create_beside` does. None when there is nothing to keep: no
    `target`, or a folder (its rename fails, and says why). A symbolic link put in the
    target's place is kept as a link.
    """
    try:
        st = os.lstat(target)
    except FileNotFoundError:
        return None, False
    if stat.S_ISDIR(st.st_mode):
        return None, False
    folder = target.parent if str(target.parent) else Path(".")
    prefix = f".{target.name}."
    for _ in range(100):
        path = os.path.join(folder, _temp_name(prefix, secrets.token_hex(6), BACKUP_SUFFIX))
        listed.append(path)
        try:
            if os.link in os.supports_follow_symlinks:  # a link put there: the link itself
                os.link(target, path, follow_symlinks=False)
            else:
                os.link(target, path)
        except FileExistsError:
            listed.pop()  # another's file (a backup a kill -9 left)
            continue
        except OSError:
            listed.pop()  # no hard links here: the target itself moves
            break
        return path, False
    else:
        raise FileExistsError(f"cannot create a backup file in {folder}")
    fd, path = _create_beside(folder, prefix, BACKUP_SUFFIX, listed)
    os.close(fd)
    os.replace(target, path)
    return path, True


def _commit(staged: list[tuple[str, Path, str]]) -> None:
    """Rename each staged file over its target; one that fails puts every target back.

    Parameters
    ----------
    staged : list of (str, Path, str)
        Each temporary file, the target it replaces, and the output as the caller named it.

    Each existing target is first kept under a backup name (:func:`_back_up`). When all are
    renamed, the backups are removed. When a step fails (a folder put in a target's place
    meanwhile), each target renamed before it gets its earlier file back (the same file:
    its bytes, mode, owner and other hard links), a target that did not exist is removed
    again, and the backups are removed; then an OSError of the failure's class names the
    output that failed. A backup that cannot be put back (its place taken meanwhile) is
    kept, and the message says where. Run under :func:`interrupts_deferred`: no interrupt
    comes between two of these steps.
    """
    listed: list[str] = []  # every backup, from before it exists
    backups: list[tuple[str | None, bool]] = []  # each target's, and whether it was moved
    renamed = 0  # targets replaced
    try:
        for _, target, _ in staged:
            backups.append(_back_up(target, listed))
        for tmp, target, _ in staged:
            os.replace(tmp, target)
            renamed += 1
    except BaseException as exc:
        kept = _roll_back(staged, backups, listed, renamed)
        if not isinstance(exc, OSError):
            raise
        failed = len(backups) if len(backups) < len(staged) else renamed  # the step that failed
        raise _commit_error(exc, staged[failed][2], kept) from None
    _remove(listed)


def _roll_back(
    staged: list[tuple[str, Path, str]],
    backups: list[tuple[str | None, bool]],
    listed: list[str],
    renamed: int,
) -> list[tuple[str, str]]:
    """Put every target of a failed :func:`_commit` back as it was; remove the backups.

    The first `renamed` targets were replaced: each gets its backup back, or is removed when
    it had none (a new output). The others were not: a backup made by moving the target is
    moved back, one made by a hard link is removed. Returns the (output, backup) pairs whose
    backup could not be put back (kept).
    """
    kept: list[tuple[str, str]] = []
    for k in reversed(range(len(staged))):
        _, target, name = staged[k]
        backup, moved = backups[k] if k < len(backups) else (None, False)
        try:
            if k < renamed and backup is None:
                os.unlink(target)  # a new output: there was none before
            elif backup is not None and (k < renamed or moved):
                os.replace(backup, target)  # the earlier file back, whole
        except OSError:
            if backup is not None:
                kept.append((name, backup))
    _remove(b for b in listed if all(b != backup for _, backup in kept))
    return kept


def _commit_error(exc: OSError, name: str, kept: list[tuple[str, str]]) -> OSError:
    """The one-line error of a failed :func:`_commit`: the output that failed, and why."""
    why = exc.strerror or str(exc)
    if kept:
        left = ", ".join(f"{n}, whose earlier contents are kept in {b}" for n, b in kept)
        text = f"cannot replace output {name} ({why}); every output file was put back but {left}"
    else:
        text = f"cannot replace output {name} ({why}); no output file was changed"
    try:
        err = type(exc)(text)
    except Exception:  # noqa: BLE001 - a class that takes other arguments
        err = OSError(text)
    err.errno = exc.errno
    return err


@contextlib.contextmanager
def staged_outputs(
    on_commit: Callable[[], object] | None = None,
) -> Iterator[Callable[..., Path]]:
    """Several outputs of one run, all replaced at the end or none at all.

    Yields ``stage(path, suffix=None) -> Path``: a temporary path beside `path`, with its
    extension (or `suffix`: the format of a device, :func:`output_format`), for a writer to
    fill. When the block ends normally every staged file is renamed over its target;
    when it raises (an error, ``KeyboardInterrupt``), every temporary file is removed and every
    target is left as it was, so an interrupted run never leaves a new tracks file beside an old
    video, or a half-written file anywhere. The renames are one step that Ctrl-C and SIGTERM
    cannot split (:func:`interrupts_deferred`): one that comes while they run is raised once
    the last is done, so the targets are then all new (was: a ``KeyboardInterrupt`` between two
    renames left some new and some old). `on_commit`, if given, is called right after the last
    rename, before such an interrupt is raised: the caller learns that its outputs are in place.
    Before the renames each existing target is kept under a hidden backup name beside it,
    ``.NAME.<hex>.old`` (a hard link, no copy; where the file system makes none, the target
    itself is renamed there): a rename that fails (a folder put in a target's place meanwhile)
    puts every target renamed before it back (the earlier file itself: its bytes and mode),
    removes those that did not exist, and raises an OSError naming the output that failed
    (``cannot replace output v.mp4 (Is a directory); no output file was changed``; was: the
    targets renamed before it stayed new, the earlier ones lost). The backups are removed
    whatever the outcome, also after a Ctrl-C or SIGTERM; only a ``kill -9`` during the
    renames can leave one (with the earlier contents; without hard links, the only copy of a
    target then missing), which no later run reads or removes: a hidden name, never an input,
    never chosen again. The first write of a later run into its folder (this function's, or
    :func:`atomic_write`'s, :func:`atomic_path`'s) warns of each such file in one line naming
    it and the output it belongs to, once per folder and process (was: nobody said so). A
    symbolic link replaces the file it leads to; a device, FIFO or descriptor gets its file's
    bytes written into it: a device before the renames (one that fails, ``/dev/full``, leaves
    every target as it was), a pipe, FIFO or socket after them (its reader may wait for the
    files, or stop early).

    Examples
    --------
    >>> with staged_outputs() as stage:  # doctest: +SKIP
    ...     write_mot(stage("tracks.txt"), rows)
    ...     write_annotated_video(stage("video.mp4"), frames, rows)
    """
    staged: list[tuple[str, Path]] = []
    given: dict[str, str] = {}  # each staged file's output as the caller named it
    made: list[str] = []  # every temporary file beside a target, from before it exists
    through: list[tuple[Path, _Target]] = []  # devices, FIFOs, descriptors: written at the end
    scratch: list[str] = []  # the temporary folder of their files, made when first needed

    def stage(path: PathLike, suffix: str | None = None) -> Path:
        _refuse_folder_name(path)
        resolved = _resolve(path)
        suffix = Path(path).suffix if suffix is None else suffix
        if resolved.through:
            if not scratch:
                scratch.append(tempfile.mkdtemp(prefix="pftrack-"))
            tmp_path = Path(scratch[0]) / f"out{len(through)}{suffix}"
            through.append((tmp_path, resolved))
            return tmp_path
        target = resolved.path
        folder = _folder_of(target, path)
        _say_left_backups(folder)
        with _named(path, hidden=True):  # a read-only file system, a folder not writable
            fd, tmp = _create_beside(folder, f".{target.stem}.", suffix or ".tmp", made)
        staged.append((tmp, target))
        given[tmp] = os.fsdecode(os.fspath(path))
        try:
            _keep_mode(fd, target)
        finally:
            os.close(fd)
        return Path(tmp)

    try:
        yield stage
        raise_if_interrupted()  # a Ctrl-C that code in C dropped: no target is touched
        # devices first (/dev/full: one that fails leaves every file target as it was; were
        # written last, and --out was replaced by a run that then failed: a user trial); pipes,
        # FIFOs and sockets last, after the renames, as ever: their reader may wait for the
        # files (a script that reads the tracks, then the FIFO), or stop early (| head), which
        # must not lose the files
        streams = [_is_stream(resolved) for _, resolved in through]
        _write_through([item for item, late in zip(through, streams, strict=True) if not late])
        for tmp, target in staged:
            _keep_mode(tmp, target)  # again: a writer may have made the file anew
        with interrupts_deferred():  # one step: a Ctrl-C or SIGTERM is raised after the last
            _commit([(tmp, target, given[tmp]) for tmp, target in staged])
            if on_commit is not None:
                on_commit()
        _write_through([item for item, late in zip(through, streams, strict=True) if late])
    except BaseException as exc:
        _remove(made)
        for tmp in made:
            _remove_nested(Path(tmp))
        if isinstance(exc, OSError):  # a writer's full disk names the file the user gave
            renamed = _as_targets(exc, staged)
            if renamed is not None:
                raise renamed from None
        raise
    finally:
        if scratch:
            shutil.rmtree(scratch[0], ignore_errors=True)
