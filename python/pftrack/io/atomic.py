"""Atomic file output: write next to the target, then rename over it in one step.

The temporary file is created with mode ``0o666`` filtered by the process umask, as ``open``
would create the target itself (``tempfile.mkstemp`` would make every output ``0o600``). When
it replaces an existing file it takes that file's permission bits instead (``mode & 0o7777``,
set on creation and again just before the rename), so a file the user restricted to
``0o600`` is never replaced by a world-readable one, nor readable while it is written.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import stat
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import IO, Any

from pftrack._typing import PathLike


def _create_beside(folder: Path, prefix: str, suffix: str) -> tuple[int, str]:
    """Create a new, unique file in `folder`; the kernel applies the umask to ``0o666``."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0)
    for _ in range(100):
        path = os.path.join(folder, f"{prefix}{secrets.token_hex(6)}{suffix}")
        try:
            return os.open(path, flags, 0o666), path
        except FileExistsError:
            continue
    raise FileExistsError(f"cannot create a temporary file in {folder}")


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
    """
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise FileNotFoundError(f"output folder does not exist: {folder}")
    fd, tmp = _create_beside(folder, f".{target.name}.", suffix or ".tmp")
    try:
        _keep_mode(fd, target)
        with os.fdopen(fd, mode) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        _keep_mode(tmp, target)
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


@contextlib.contextmanager
def atomic_path(path: PathLike) -> Iterator[Path]:
    """Yield a temporary path (same folder, same extension) that replaces `path` on success.

    For writers that want a file name rather than a handle (``cv2.VideoWriter``, ``cv2.imwrite``).
    Permissions as for :func:`atomic_write`: an existing file's are kept.
    """
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise FileNotFoundError(f"output folder does not exist: {folder}")
    fd, tmp = _create_beside(folder, f".{target.stem}.", target.suffix)
    try:
        try:
            _keep_mode(fd, target)
        finally:
            os.close(fd)
        yield Path(tmp)
        if not Path(tmp).exists() or Path(tmp).stat().st_size == 0:
            raise OSError(f"nothing was written for {target}")
        _keep_mode(tmp, target)  # again: a writer may have made the file anew
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def check_output(
    path: PathLike,
    *,
    what: str = "output",
    suffixes: tuple[str, ...] | None = None,
    inputs: tuple[PathLike, ...] = (),
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

    Raises
    ------
    ValueError
        The extension is not supported, the path is a folder, or it names an input.
    FileNotFoundError
        Its folder does not exist.
    PermissionError
        Its folder (or the existing file) is not writable: checked by creating (and removing)
        a file beside it.
    """
    target = Path(path)
    if suffixes is not None and target.suffix.lower() not in suffixes:
        raise ValueError(
            f"{what} {target}: unsupported extension {target.suffix or '(none)'!r}, expected "
            f"one of {', '.join(suffixes)}"
        )
    if target.is_dir():
        raise ValueError(f"{what} {target} is a folder; give a file name")
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise FileNotFoundError(f"{what} {target}: folder {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK) or (
        target.exists() and not os.access(target, os.W_OK)
    ):
        raise PermissionError(f"{what} {target}: not writable")
    try:  # access() says yes to root on a read-only or special file system: try it
        fd, probe = _create_beside(folder, f".{target.name}.", ".probe")
    except OSError as exc:
        raise PermissionError(
            f"{what} {target}: folder {folder} is not writable ({exc.strerror or exc})"
        ) from None
    os.close(fd)
    os.unlink(probe)
    for source in inputs:
        if _same_file(target, Path(source)):
            raise ValueError(f"{what} {target} is an input of this run; write elsewhere")
    return target


def _same_file(a: Path, b: Path) -> bool:
    """Whether `a` and `b` name one file: the same path once resolved, or one file on disk."""
    if a.exists() and b.exists() and os.path.samefile(a, b):
        return True  # hard links, bind mounts
    return a.resolve() == b.resolve()


def check_distinct(outputs: Mapping[str, PathLike | None]) -> None:
    """Check, before any work, that no two outputs of one run are the same file.

    Parameters
    ----------
    outputs : mapping of str to path or None
        Each output by the name error messages give it (e.g. ``"--render"``); None: not written.

    Raises
    ------
    ValueError
        Two of them name one file (one would overwrite the other), naming both.
    """
    seen: list[tuple[str, Path]] = []
    for what, path in outputs.items():
        if path is None:
            continue
        target = Path(path)
        for other_what, other in seen:
            if _same_file(target, other):
                raise ValueError(
                    f"{other_what} {other} and {what} {target} are the same file; give each "
                    "output its own"
                )
        seen.append((what, target))


@contextlib.contextmanager
def staged_outputs() -> Iterator[Callable[[PathLike], Path]]:
    """Several outputs of one run, all replaced at the end or none at all.

    Yields ``stage(path) -> Path``: a temporary path beside `path`, with its extension, for a
    writer to fill. When the block ends normally every staged file is renamed over its target;
    when it raises (an error, ``KeyboardInterrupt``), every temporary file is removed and every
    target is left as it was, so an interrupted run never leaves a new tracks file beside an old
    video, or a half-written file anywhere.

    Examples
    --------
    >>> with staged_outputs() as stage:  # doctest: +SKIP
    ...     write_mot(stage("tracks.txt"), rows)
    ...     write_annotated_video(stage("video.mp4"), frames, rows)
    """
    staged: list[tuple[str, Path]] = []

    def stage(path: PathLike) -> Path:
        target = Path(path)
        folder = target.parent if str(target.parent) else Path(".")
        if not folder.is_dir():
            raise FileNotFoundError(f"output folder does not exist: {folder}")
        fd, tmp = _create_beside(folder, f".{target.stem}.", target.suffix or ".tmp")
        staged.append((tmp, target))
        try:
            _keep_mode(fd, target)
        finally:
            os.close(fd)
        return Path(tmp)

    try:
        yield stage
        for tmp, target in staged:
            _keep_mode(tmp, target)  # again: a writer may have made the file anew
        for tmp, target in staged:
            os.replace(tmp, target)
    except BaseException:
        for tmp, _ in staged:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        raise
