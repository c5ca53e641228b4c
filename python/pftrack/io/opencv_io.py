r"""Files through OpenCV under any name the file system allows, bytes that are not UTF-8 too.

OpenCV's Python binding converts a ``str`` path to UTF-8. A name that is not valid UTF-8 (a
Latin-1 ``vid\xfe.mp4`` made on another system: Python keeps such bytes as surrogate escapes,
``os.fsdecode(b"vid\xfe.mp4")``) crashes the process in ``cv2.VideoCapture``,
``cv2.imread``, ``cv2.imwrite`` and ``cv2.VideoWriter`` (a segmentation fault, OpenCV 5.0).
pftrack never hands OpenCV such a name:

- images are written through memory (:func:`write_image`: ``cv2.imencode`` and an atomic
  write);
- videos are opened, and images read (:func:`read_image`, :func:`read_image_depth`),
  through a symbolic link with an ASCII name in the system's temporary folder
  (:func:`opencv_name`), removed as soon as OpenCV has opened or read the file: OpenCV keeps
  its own handle (images are not read from memory, ``cv2.imdecode``, which refuses a truncated
  JPEG that ``cv2.imread`` decodes);
- a stream URL that is not valid UTF-8 is refused (:func:`utf8_name`);
- text drawn with ``cv2.putText`` (a plot's title: the video's file name) is made printable
  ASCII first (:func:`text_for_opencv`).

What the image libraries under OpenCV print on stderr themselves, naming no file (libpng's
``libpng warning: iCCP: known incorrect sRGB profile``, libjpeg's ``Corrupt JPEG data: ...``),
a caller of :func:`read_image` or :func:`read_image_depth` may take as notes instead
(`notes`), to say it once, naming the image (:class:`pftrack.io.video.FrameSource` does).

A name that is valid UTF-8, which is almost every name, goes to OpenCV as the text its bytes
spell in UTF-8 (:func:`utf8_name`), which is not always the ``str`` Python made of them: under a
locale that is not UTF-8 (``LC_ALL=C``), ``"vidé.avi"`` on the command line is
``"vid\udcc3\udca9.avi"`` (its UTF-8 bytes as surrogate escapes), and that ``str`` crashes
OpenCV too.
"""

from __future__ import annotations

import atexit
import contextlib
import os
import re
import shutil
import tempfile
import threading
import unicodedata
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from pftrack._typing import PathLike
from pftrack.io.atomic import atomic_write

__all__ = [
    "is_utf8",
    "opencv_name",
    "printable",
    "read_image",
    "read_image_depth",
    "text_for_opencv",
    "utf8_name",
    "write_image",
]


def is_utf8(path: PathLike) -> bool:
    """Whether the bytes of `path` are valid UTF-8 (OpenCV's binding can take it)."""
    try:
        os.fsencode(os.fspath(path)).decode("utf-8")
    except UnicodeDecodeError:
        return False
    return True


def printable(path: PathLike) -> str:
    r"""`path` for a message: bytes that are not UTF-8 shown as ``\xfe`` escapes."""
    return os.fsencode(os.fspath(path)).decode("utf-8", "backslashreplace")


def utf8_name(path: PathLike, what: str = "path") -> str:
    """`path` as the ``str`` OpenCV's binding takes: the UTF-8 text of its bytes.

    Not ``os.fsdecode(path)``: under a locale that is not UTF-8, Python keeps the bytes of
    ``"vidé"`` as surrogate escapes, a ``str`` that crashes OpenCV; its bytes are UTF-8 all
    the same, and their text names the same file.

    Raises
    ------
    ValueError
        The bytes of `path` are not valid UTF-8.
    """
    try:
        return os.fsencode(os.fspath(path)).decode("utf-8")
    except UnicodeDecodeError:
        raise ValueError(
            f"{what} {printable(path)} is not valid UTF-8, which OpenCV's binding cannot take"
        ) from None


def text_for_opencv(text: str) -> str:
    r"""`text` as printable ASCII, all that ``cv2.putText`` can draw: give it nothing else.

    ``cv2.putText`` crashes the process (a segmentation fault, OpenCV 5.0) on a ``str`` that
    cannot be encoded as UTF-8, such as a file name whose bytes are not UTF-8 (Python keeps
    them as surrogate escapes: ``os.fsdecode(b"v\xe9deo.mp4")``). Such bytes are shown as
    ``\xe9`` escapes (as in messages: :func:`printable`), accents are
    dropped (``"vidé"``: ``"vide"``), and any other character that is not printable ASCII is
    drawn as ``?`` (as the font would draw it).
    """
    try:  # surrogate escapes back to the bytes they stand for
        raw = text.encode("utf-8", "surrogateescape")
    except UnicodeEncodeError:  # a lone surrogate that escapes no byte
        raw = text.encode("utf-8", "backslashreplace")
    folded = unicodedata.normalize("NFKD", raw.decode("utf-8", "backslashreplace"))
    return "".join(
        c if " " <= c <= "~" else "" if unicodedata.combining(c) else "?" for c in folded
    )


@contextlib.contextmanager
def opencv_name(path: PathLike) -> Iterator[str]:
    """A name OpenCV can open for file `path`, valid while the block runs.

    `path` itself when it is valid UTF-8 (its text, :func:`utf8_name`); else a symbolic link to
    it with an ASCII name (and `path`'s extension, when that is ASCII) in a new folder of the
    system's temporary folder, removed with its folder when the block ends. Open the file
    (``cv2.VideoCapture``, ``cv2.VideoWriter``) inside the block: OpenCV keeps its own handle
    afterwards.

    Raises
    ------
    ValueError
        `path` is not valid UTF-8 and neither is the temporary folder.
    """
    text = os.fsdecode(os.fspath(path))
    if is_utf8(text):
        yield utf8_name(text)
        return
    scratch = tempfile.mkdtemp(prefix="pftrack-")
    try:
        suffix = Path(text).suffix
        link = os.path.join(scratch, "file" + (suffix if suffix.isascii() else ""))
        name = utf8_name(link, "temporary folder")
        os.symlink(os.path.abspath(text), link)
        yield name
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


#: A line the image libraries under OpenCV print on stderr themselves: libpng's warnings and
#: errors, libjpeg's warnings (the texts of its jerror.h's ``JWRN_*``; its errors OpenCV
#: handles without a word).
_DECODER_LINE = re.compile(
    rb"(libpng (?:warning|error): [^\n]*|Corrupt JPEG data: [^\n]*|Premature end of JPEG file"
    rb"|Invalid SOS parameters for sequential JPEG|Inconsistent progression sequence [^\n]*"
    rb"|Unknown Adobe color transform code [^\n]*|Warning: unknown JFIF revision number [^\n]*"
    rb"|Application transferred too many scanlines)\n?"
)
_HELD = threading.Lock()  # one thread at a time holds file descriptor 2
_HOLDERS: dict[int, Any] = {}  # process id -> the temporary file stderr is held in
# A fork waits for a read holding file descriptor 2 to end (one image: milliseconds), so that
# the child starts with its stderr the parent's own and the lock free. Was: a fork while a
# thread read an image folder gave the child the lock taken for good (its first image read
# hung) and its stderr the parent's temporary file.
if hasattr(os, "register_at_fork"):  # not on Windows
    os.register_at_fork(
        before=_HELD.acquire, after_in_parent=_HELD.release, after_in_child=_HELD.release
    )


def _holder() -> Any:
    """The temporary file of this process for what stderr gets during a decode, emptied.

    One per process, made once (was: a new temporary file for every image read, a frame's
    worth of system calls); a forked child makes its own, not writing into its parent's. It is
    closed at exit (was: left to the garbage collector, a ResourceWarning under ``-X dev``).
    """
    held = _HOLDERS.get(os.getpid())
    if held is None:
        for inherited in _HOLDERS.values():  # a parent's, over fork: the child's copy closed
            inherited.close()
        _HOLDERS.clear()
        held = _HOLDERS[os.getpid()] = tempfile.TemporaryFile()
        atexit.register(held.close)
    held.seek(0)
    held.truncate()
    return held


@contextlib.contextmanager
def _decoder_notes(notes: list[str]) -> Iterator[None]:
    """The image libraries' lines on stderr during the block into `notes`, instead of stderr.

    What is written to file descriptor 2 while the block runs is held; then each line the image
    libraries printed (:data:`_DECODER_LINE`) goes to `notes`, the rest (another thread's
    progress bar, a warning) to stderr as it was. Without a file descriptor 2: nothing held.
    """
    with _HELD:
        try:
            saved = os.dup(2)
        except OSError:
            yield
            return
        try:
            held = _holder()
            os.dup2(held.fileno(), 2)
            try:
                yield
            finally:
                os.dup2(saved, 2)
            held.seek(0)
            text = held.read()
        finally:
            os.close(saved)

    def take(match: re.Match[bytes]) -> bytes:
        notes.append(match.group(1).decode("utf-8", "replace"))
        return b""

    rest = _DECODER_LINE.sub(take, text)
    if rest:
        with contextlib.suppress(OSError):
            os.write(2, rest)


def _decode(path: PathLike, flags: int, notes: list[str] | None) -> Any:
    """``cv2.imread(path, flags)`` under any name: the array, or None if it cannot be read.

    A name that is not UTF-8 is read through :func:`opencv_name`'s link, by ``cv2.imread``
    too: ``cv2.imdecode`` of the file's bytes refuses a truncated JPEG that ``cv2.imread``
    decodes (the rest grey), and a folder tracked under one name failed under another. From
    memory only when the temporary folder's name is not UTF-8 either.
    """
    with contextlib.nullcontext() if notes is None else _decoder_notes(notes):
        try:
            with opencv_name(path) as name:
                return cv2.imread(name, flags)
        except ValueError:  # no name OpenCV can take
            pass
        try:
            data = np.fromfile(os.fspath(path), dtype=np.uint8)
        except (OSError, ValueError):
            return None
        return cv2.imdecode(data, flags) if data.size else None


def read_image(
    path: PathLike, flags: int = cv2.IMREAD_COLOR, *, notes: list[str] | None = None
) -> NDArray[np.uint8] | None:
    """The image at `path` as ``cv2.imread`` reads it (any name); None if it cannot be read.

    With `notes`, what the image's decoder prints on stderr itself (``libpng warning: iCCP:
    too short``) is appended to it instead, a line each.
    """
    image = _decode(path, flags, notes)
    return None if image is None else np.asarray(image, dtype=np.uint8)


def read_image_depth(path: PathLike, *, notes: list[str] | None = None) -> NDArray[Any] | None:
    """The image at `path` in BGR at the depth it is stored in (any name); None if unreadable.

    ``cv2.IMREAD_COLOR | cv2.IMREAD_ANYDEPTH``: a 16-bit PNG or TIFF is uint16 (``cv2.imread``'s
    colour read keeps its high byte); an 8-bit image is uint8, the pixels :func:`read_image`
    gives. `notes` as :func:`read_image`'s.
    """
    image = _decode(path, cv2.IMREAD_COLOR | cv2.IMREAD_ANYDEPTH, notes)
    return None if image is None else np.asarray(image)


def write_image(
    path: PathLike,
    image: NDArray[Any],
    params: Sequence[int] = (),
    *,
    ext: str | None = None,
    mark: bool = False,
) -> Path:
    """Write `image` as ``cv2.imwrite`` would (the same bytes), atomically; return `path`.

    Encoded in memory (``cv2.imencode``), then written by :func:`~pftrack.io.atomic.atomic_write`:
    any name, and a device or descriptor (``/dev/stdout``) is written through.

    Parameters
    ----------
    path : str or os.PathLike
        The output file.
    image : ndarray
        What ``cv2.imwrite`` takes (BGR uint8, ...).
    params : sequence of int
        Encoder parameters (``[cv2.IMWRITE_PNG_COMPRESSION, 9]``).
    ext : str, optional
        The format (``".png"``); default: `path`'s extension.
    mark : bool
        Whether a PNG or JPEG carries pftrack's mark (:func:`pftrack.io.marks.mark_image`,
        the same pixels), which lets a later run replace it: ``--plot``'s and ``--figure``'s.

    Raises
    ------
    ValueError
        OpenCV has no encoder for the format, or cannot encode `image` in it.
    """
    suffix = Path(path).suffix if ext is None else ext
    try:  # no format's name is not ASCII ("."), and a surrogate escape would crash OpenCV
        ok, buf = cv2.imencode(suffix if suffix.isascii() else ".", image, list(params))
    except cv2.error:
        ok = False
    if not ok:
        raise ValueError(
            f"OpenCV cannot write image {printable(path)} (format {suffix or '(none)'!r})"
        )
    data = buf.tobytes()
    if mark:
        from pftrack.io.marks import mark_image

        data = mark_image(data)
    with atomic_write(path, "wb") as fh:
        fh.write(data)
    return Path(path)
