"""Atomic file output: write next to the target, then rename over it in one step."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

from pftrack._typing import PathLike


@contextlib.contextmanager
def atomic_write(
    path: PathLike, mode: str = "w", *, suffix: str | None = None
) -> Iterator[IO[Any]]:
    """Open a temporary file beside `path`; on success it replaces `path` atomically.

    If the block raises, the temporary file is removed and `path` is left exactly as it was,
    so a crash or a bad input never destroys a user's earlier output.

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
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=suffix or ".tmp", dir=folder)
    try:
        with os.fdopen(fd, mode) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


@contextlib.contextmanager
def atomic_path(path: PathLike) -> Iterator[Path]:
    """Yield a temporary path (same folder, same extension) that replaces `path` on success.

    For writers that want a file name rather than a handle (``cv2.VideoWriter``, ``cv2.imwrite``).
    """
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise FileNotFoundError(f"output folder does not exist: {folder}")
    fd, tmp = tempfile.mkstemp(prefix=f".{target.stem}.", suffix=target.suffix, dir=folder)
    os.close(fd)
    try:
        yield Path(tmp)
        if not Path(tmp).exists() or Path(tmp).stat().st_size == 0:
            raise OSError(f"nothing was written for {target}")
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
