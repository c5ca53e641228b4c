"""MOTChallenge text files: ``frame,id,left,top,width,height,conf,x,y,z`` one box a line.

Frames count from 1. Detection files use id -1. pftrack reads comma- or whitespace-separated
files with 6 to 10 columns (missing columns become ``conf=1, x=y=z=-1``; so do empty ones at
the end of a line, ``...,0.9,,,``; an empty field anywhere else is refused, never skipped) and
always writes 10: values of up to 10 significant digits (what MOTChallenge files and trackers
hold) come out unchanged, in their shortest form (``88.00`` as ``88``); longer values are
rounded to 2 decimals (values pftrack computed) unless marked ``exact`` (values read from a
file such as ``np.savetxt``'s, written in their shortest round-trip form; :func:`mot_text`).
"""

from __future__ import annotations

import itertools
import os
import re
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack import _check, _core
from pftrack._check import (
    BOX_VALUES,
    MAX_FRAME,
    MOT_DEFAULTS,
    exactly,
    first_bad_box,
    frames_from_1,
    mot_rows,
    path_arg,
    shown,
)
from pftrack._stats import median, percentile
from pftrack._typing import F64, PathLike
from pftrack._warn import warn
from pftrack.io.atomic import atomic_write, refuse_dash, refuse_loop

#: Column indices of a MOTChallenge row.
FRAME, ID, LEFT, TOP, WIDTH, HEIGHT, CONF, X, Y, Z = range(10)
_DEFAULTS = (np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, *MOT_DEFAULTS)
_NAMES = ("frame", "id", "left", "top", "width", "height", "conf", "x", "y", "z")


#: The first bytes of compressed files, and the compression's name (bzip2: "BZh" and a level).
_COMPRESSED = (
    (b"\x1f\x8b", "gzip"),
    (b"PK\x03\x04", "zip"),
    (b"\xfd7zXZ\x00", "xz"),
    (b"\x28\xb5\x2f\xfd", "zstd"),
    *((b"BZh" + bytes([c]), "bzip2") for c in b"123456789"),
)


#: Byte-order marks of UTF-16 text, as Windows PowerShell 5's ``>`` and ``Out-File`` write a
#: program's output: such a file is read in its encoding (was: refused as "not a text file (it
#: holds NUL bytes)"). UTF-32's marks begin with UTF-16's and two NUL bytes: that is not read.
_UTF16_BOMS = (b"\xff\xfe", b"\xfe\xff")
_UTF32_BOMS = (b"\xff\xfe\0\0", b"\0\0\xfe\xff")


def _encoding(head: bytes) -> str:
    """The encoding of a MOT file whose first bytes are `head`: UTF-16 by its BOM, else UTF-8.

    ``utf-8-sig``: a UTF-8 BOM is skipped, never read as part of the first field.
    """
    if head[:2] in _UTF16_BOMS and head[:4] not in _UTF32_BOMS:
        return "utf-16"
    return "utf-8-sig"


def _file_encoding(p: Path) -> str:
    """:func:`_encoding` of the file `p`."""
    with p.open("rb") as fh:
        return _encoding(fh.read(4))


def _refuse_binary(p: Path, what: str) -> None:
    """ValueError when `p` is compressed or not text (its first 8 KiB hold a NUL byte).

    UTF-16 text with its byte-order mark is text (:func:`_encoding`), NUL bytes and all.
    """
    with p.open("rb") as fh:
        head = fh.read(8192)
    for magic, kind in _COMPRESSED:
        if head.startswith(magic):
            raise ValueError(f"{what} {p} is {kind}-compressed, not text; decompress it first")
    if b"\0" in head and _encoding(head) != "utf-16":
        raise ValueError(f"{what} {p} is not a text file (it holds NUL bytes)")


def _data_lines(path: Path) -> Iterator[tuple[int, str]]:
    """(1-based line number, stripped text) of every line that holds a row."""
    with path.open("r", encoding=_file_encoding(path), errors="replace") as fh:
        for lineno, line in enumerate(fh, start=1):
            text = line.strip()
            if text and not text.startswith("#"):
                yield lineno, text


def _split(text: str) -> list[str]:
    """The fields of a row, empty ones kept: separated by commas, spaces or both.

    A comma ends a field, so two commas in a row (or a comma at either end) hold an empty
    field (``""``); a run of spaces or tabs is one separator (aligned columns), and spaces
    around a comma are none. Trailing empty fields (``1,1,10,10,20,40,``) are kept too:
    :func:`_fields` drops them.
    """
    if "," not in text:
        return text.split()
    parts = text.split(",")
    if " " not in text and "\t" not in text:
        return parts  # the common case: one split
    fields: list[str] = []
    for part in parts:
        fields.extend(part.split() or [""])
    return fields


def _fields(text: str) -> list[str]:
    """The fields of a row, without the empty ones that end it (trailing commas).

    An empty field before a non-empty one stays (``""``): :func:`_parse_line` refuses it.
    """
    fields = _split(text)
    while fields and not fields[-1]:
        fields.pop()
    return fields


def first_row_fields(path: PathLike) -> int:
    """How many fields the file's first row has (0 without a row): 6 means no score column."""
    first = next(_data_lines(Path(path)), None)
    return 0 if first is None else len(_fields(first[1]))


def is_mot_text(path: PathLike) -> bool:
    """Whether `path` holds MOTChallenge rows: its first row has 6 or more fields, 6 numbers.

    Read as :func:`read_mot` reads it (its encoding, a UTF-16 file with its byte-order mark
    included; blank lines and ``#`` comments passed over; its fields and numbers), so a file
    it is true of is one ``read_mot`` takes as rows, and a file of no row (empty, comments
    only) counts too. A binary file (NUL bytes in its first 8 KiB, UTF-16 aside) is not; an
    unreadable path neither. What a tracks ``--out`` may replace (docs/io.md).
    """
    p = Path(path)
    try:
        with p.open("rb") as fh:
            head = fh.read(8192)
        if b"\0" in head and _encoding(head) != "utf-16":
            return False
        first = next(_data_lines(p), None)
    except OSError:
        return False
    if first is None:
        return True
    fields = _fields(first[1])
    return len(fields) >= 6 and all(_NUMBER.fullmatch(f) for f in fields[:6])


def data_line_numbers(path: PathLike) -> list[int]:
    """The file's line number of each row :func:`read_mot` returns, for error messages."""
    return [n for n, _ in _data_lines(Path(path))]


def data_line(path: PathLike, k: int) -> tuple[int, str]:
    """The file's line number and text of row `k` (0-based) :func:`read_mot` returns.

    For an error message that quotes the line as the file writes it: a value read as a double
    may not be (an id past 2**53).
    """
    return next(itertools.islice(_data_lines(Path(path)), k, None))


#: The frame numberings a MOT file may be read in (:class:`MotFile`, ``--det-base``): 1 is
#: MOTChallenge's (det.txt, gt.txt, every tracker's export read here), 0 a decoder's index,
#: KITTI's, Python's ``enumerate``.
FRAME_BASES = (0, 1)


class MotFile(os.PathLike[str]):
    """A MOT file's path together with the number its frames count from.

    What ``--det-base 0`` hands to the readers: :func:`read_mot`, and through it
    :func:`pftrack.load_detections`, :func:`pftrack.tracking.run.track_path` and ``pftrack
    batch``'s tasks, read the file's frame ``k`` as frame ``k - first_frame + 1``, the
    MOTChallenge numbering every other part of pftrack uses. A plain path reads from 1. The
    numbering travels with the path (not a setting of the reader) so that every function
    handed it reads it alike, and a note that guesses the numbering (:func:`zero_based_note`)
    says nothing of a file whose numbering was stated.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    first_frame : {0, 1}
        The number of the video's first frame in the file.

    Examples
    --------
    >>> dets = pftrack.load_detections(MotFile("det0.txt", first_frame=0))  # doctest: +SKIP
    """

    def __init__(self, path: PathLike, first_frame: int = 1) -> None:
        self.path = os.fspath(path_arg(path, "MotFile: path"))
        self.first_frame = frame_base(first_frame, "MotFile: first_frame")

    def __fspath__(self) -> str:
        """The file's path."""
        return self.path

    def __str__(self) -> str:
        """The path, as messages name the file."""
        return self.path

    def __repr__(self) -> str:
        """``MotFile('det0.txt', first_frame=0)``."""
        return f"MotFile({self.path!r}, first_frame={self.first_frame})"

    def __eq__(self, other: object) -> bool:
        """Equal paths read from the same frame."""
        if not isinstance(other, MotFile):
            return NotImplemented
        return (self.path, self.first_frame) == (other.path, other.first_frame)

    def __hash__(self) -> int:
        """As the pair it compares."""
        return hash((self.path, self.first_frame))

    def __reduce__(self) -> tuple[type[MotFile], tuple[str, int]]:
        """Pickled as its two fields (a batch task's detections go to Dask's workers)."""
        return (MotFile, (self.path, self.first_frame))


def frame_base(value: object, what: str) -> int:
    """`value` as one of :data:`FRAME_BASES`, or a one-line TypeError / ValueError naming `what`."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{what} must be 0 or 1, got {shown(value)}")
    if int(value) not in FRAME_BASES:
        raise ValueError(
            f"{what} is {int(value)}, expected 0 (frames numbered from 0) or 1 (MOTChallenge's "
            "numbering, from 1)"
        )
    return int(value)


def stated_base(path: object) -> int | None:
    """The first frame `path` states (a :class:`MotFile`), or None for a plain path."""
    return path.first_frame if isinstance(path, MotFile) else None


def read_mot(
    path: PathLike,
    *,
    what: str = "MOT file",
    warn_extra: bool = False,
    first_frame: int | None = None,
) -> NDArray[np.float64]:
    """Read a MOTChallenge file into an ``(M, 10)`` float64 array.

    Parameters
    ----------
    path : str or os.PathLike
        The file. Blank lines and lines starting with ``#`` are skipped.
    what : str
        How errors name the file ("detection file", "ground truth", ...).
    warn_extra : bool
        Warn when lines have more than 10 columns (they are read, the rest dropped).
    first_frame : {0, 1}, optional
        The number the file's frames count from; rows are returned numbered from 1 (a file
        numbered from 0 gets 1 added to every frame). None: the :class:`MotFile`'s, else 1.

    Returns
    -------
    (M, 10) ndarray of float64
        Rows in file order, frames from 1. An empty file gives shape ``(0, 10)``.

    Raises
    ------
    TypeError
        `path` is not a str or os.PathLike (bytes are decoded).
    FileNotFoundError
        If `path` does not exist.
    ValueError
        If it is a folder, or not a regular file (a device such as ``/dev/null``, a named pipe,
        a socket: the file may be read twice, to name a bad line). On a malformed line,
        naming the file and the 1-based line number: fewer than 6 fields, an empty field
        (``1,,7,...``: two commas in a row) in the first 6 columns or before a non-empty one
        (empty fields at the end of a line, ``...,0.9,,,`` or a trailing comma, are absent
        columns: their defaults), a non-number (a first row with a word in it ends with
        :data:`HEADER_HINT`: a header line?, or :data:`KITTI_HINT` for KITTI's tracking
        labels; fields separated by semicolons end with :data:`SEMICOLON_HINT`), a
        non-finite value in any of the first 10 columns (a NaN score too), a frame that is
        not an integer in ``1..2**31-1``, a negative width or height, or a box value beyond
        ±1e9 px. A UTF-8 byte-order mark is skipped; UTF-16 text with its byte-order mark
        (what Windows PowerShell's ``>`` writes) is read in its encoding. A compressed file
        (gzip, zip, bzip2, xz, zstd) or one with NUL bytes in its first 8 KiB (not text),
        naming the file.

    Warns
    -----
    UserWarning
        With `warn_extra`, once, naming the file and its most columns on a line, when that is
        more than 10: columns 11 and beyond are not kept.
    """
    base = (
        stated_base(path)
        if first_frame is None
        else frame_base(first_frame, "read_mot: first_frame")
    )
    p = Path(path_arg(path, "read_mot: path"))
    _check.text(what, "read_mot: what", none=False)  # it names the file in every message below
    if not p.is_file():
        if p.is_dir():
            raise ValueError(f"{what} {p} is a folder, not a file")
        if p.exists():
            raise ValueError(f"{what} {p} is not a regular file (a device, pipe or socket)")
        refuse_dash(p, what)
        refuse_loop(p, what)
        raise FileNotFoundError(f"{what} not found: {p}")
    try:
        return _read_rows(p, what, warn_extra, 1 if base is None else base)
    except OSError as exc:
        if exc.filename is not None:  # open()'s errors name the file already
            raise
        # a read that fails part-way (a failing disk, a network file system, /proc/self/mem)
        # raised "[Errno 5] Input/output error", naming no file: now "Input/output error: PATH"
        raise OSError(exc.errno, exc.strerror or str(exc), str(p)) from None


def _read_rows(p: Path, what: str, warn_extra: bool, base: int = 1) -> NDArray[np.float64]:
    """:func:`read_mot` of the regular file `p`, once its path is checked; frames from `base`."""
    _refuse_binary(p, what)
    fast = _read_fast(p, 1 - base)
    if fast is not None:
        return fast
    rows: list[list[float]] = []
    numbers: list[int] = []  # the line of each row
    error: str | None = None  # the first line that is no row, which ends the reading
    most = 0  # the most columns on a line, with warn_extra (the fast reader takes <= 10)
    for lineno, text in _data_lines(p):
        if warn_extra:
            most = max(most, len(_fields(text)))
        values = _parse_line(text, what, 1 - base)
        if isinstance(values, str):
            error = f"{p}:{lineno}: {values}"
            if not rows and _WORD.search(text) and _split(text)[0].strip() == "":
                error += INDEX_HEADER_HINT  # ",frame,id,...": pandas' to_csv with its index
            elif (
                not rows
                and values.startswith(f"{what} line has a non-number")
                and _WORD.search(text)
                and not values.endswith(SEMICOLON_HINT)  # one hint: ';' said already
            ):  # the first row a word: pandas' to_csv, a spreadsheet's export; or KITTI's
                error += KITTI_HINT if _kitti(text) else HEADER_HINT
            break
        rows.append(values)
        numbers.append(lineno)
    a = np.asarray(rows, dtype=np.float64).reshape(-1, 10)
    # boxes after the loop, all at once (one NumPy call per line took 2/3 more time); a bad
    # box on a line before `error`'s is the first bad line
    bad_box = first_bad_box(a[:, LEFT : HEIGHT + 1])  # the rule of the API's rows too
    if bad_box is not None:
        lineno = numbers[bad_box[0]]
        text = next(t for n, t in _data_lines(p) if n == lineno)
        raise ValueError(f"{p}:{lineno}: {bad_box[2]}: {text[:80]!r}")
    if error is not None:
        raise ValueError(error)
    if most > 10:
        warn(
            f"{what} {p} has lines of {most} columns: columns past 10 are not kept",
            UserWarning,
            stacklevel=3,  # read_mot's caller
        )
    return a


def no_rows(path: PathLike) -> str:
    """How a MOT file that :func:`read_mot` read as no row is described: a message's end.

    ``is empty (0 bytes)`` or ``holds no row (only blank or comment lines)``. A tracks file
    of no row is a tracker's finding (nothing tracked: ``pftrack track`` writes one, with a
    warning); a ground truth of no row has nothing to score against (docs/io.md).
    """
    p = Path(path)
    empty = p.is_file() and p.stat().st_size == 0
    return "is empty (0 bytes)" if empty else "holds no row (only blank or comment lines)"


def read_ground_truth(path: PathLike) -> F64:
    """:func:`read_mot` of a ground truth to score against, refused if it holds no row.

    What ``pftrack eval --gt`` and ``pftrack batch`` read (was: an empty one scored, every
    result box a false positive, exit 0). A tracks file of no row is read by :func:`read_mot`
    as a tracker's finding instead.

    Raises
    ------
    ValueError
        As :func:`read_mot`; or the file holds no row (:func:`no_rows` says how).
    """
    gt = read_mot(path, what="ground truth")
    if not len(gt):
        raise ValueError(
            f"ground truth {path} {no_rows(path)}: nothing to score against (a cut download "
            "or copy?)"
        )
    return gt


#: What a refused first row with a word in it (``frame,id,bb_left,...``) is told.
HEADER_HINT = " (a header line? delete it, or start it with # to keep it as a comment)"
#: What a refused first row with a word and an empty first field is told: the header of
#: pandas' ``to_csv`` with its index (``,frame,id,...``, then ``0,1,-1,...``), whose rows would
#: be refused as frame 0 once the header was deleted (was: "an empty column 1 (frame)").
INDEX_HEADER_HINT = (
    " (a header line, above rows that begin with an index column? pandas' to_csv writes both "
    "by default: write the file with to_csv(path, header=False, index=False))"
)
#: What a refused frame 0 is told on a line of 11 fields whose second is a frame (1 or more):
#: a first column of row numbers, pandas' index (``to_csv(path, header=False)``).
INDEX_HINT = (
    "; or does each line begin with an index column (11 fields, frames in the second)? "
    "pandas' to_csv writes one by default: write the file with to_csv(path, header=False, "
    "index=False)"
)
#: What a refused frame 0 of a detection file adds inside the hint's brackets: the option that
#: reads it as it is (was: only the awk that rewrites it, stop 73).
DET_BASE_HINT = (
    "; or read it as numbered from 0: --det-base 0 (pftrack track, batch), "
    "MotFile(path, first_frame=0) in Python"
)
#: A word: two letters in a row, which no number has (``1e5``, ``inf`` is refused as such).
_WORD = re.compile(r"[A-Za-z_]{2,}")

#: What a refused first row laid out as KITTI's tracking labels is told (not HEADER_HINT).
KITTI_HINT = (
    " (KITTI tracking labels? pftrack reads MOTChallenge rows frame,id,left,top,width,height "
    "with frames from 1: convert them, width = right - left, height = bottom - top)"
)

#: What a row whose fields are separated by semicolons is told.
SEMICOLON_HINT = (
    " (fields separated by ';', as a spreadsheet's CSV export with decimal commas writes them? "
    "pftrack reads fields separated by commas, spaces or tabs, and decimal points)"
)


def _kitti(text: str) -> bool:
    """Whether `text` is laid out as a KITTI tracking label: ``frame id type`` and 14 numbers.

    ``frame id type truncated occluded alpha left top right bottom h w l x y z rotation_y``
    and, in a tracker's results, a score: a word third among 17 or 18 fields.
    """
    f = text.split()
    return (
        len(f) in (17, 18)
        and not _NUMBER.fullmatch(f[2])
        and all(_NUMBER.fullmatch(v) for v in f[:2] + f[3:])
    )


def _semicolons(text: str) -> str:
    """:data:`SEMICOLON_HINT` when `text` splits into 6 fields or more at semicolons, else ""."""
    return SEMICOLON_HINT if len(text.split(";")) >= 6 else ""


#: A number as MOTChallenge files write them: ASCII digits, a point, an exponent (``float()``
#: alone also takes ``1_0`` for 10 and other scripts' digits, ``１００``: a user trial).
_NUMBER = re.compile(
    r"\s*[+-]?(?:\d+\.?\d*(?:e[+-]?\d+)?|\.\d+(?:e[+-]?\d+)?|inf(?:inity)?|nan)\s*",
    re.ASCII | re.IGNORECASE,
)


def _parse_line(text: str, what: str, shift: int = 0) -> list[float] | str:
    """The 10 values of a line of a MOTChallenge file, or what is wrong with it (boxes aside).

    Missing columns get their defaults. The boxes are :func:`read_mot`'s to check. `shift`
    is added to the frame (1 for a file numbered from 0: :class:`MotFile`).
    """
    fields = _fields(text)
    # an empty field is refused, never skipped (the values after it would shift into its
    # column): in the first 6 columns (a trailing comma there too), or before a value
    # (columns past 10 are not kept: theirs do not matter)
    kept = fields[:10] if len(fields) >= 6 else _split(text)[:6]
    if "" in kept:
        c = kept.index("")
        why = (
            ", which needs a number"
            if c < 6
            else " before a value in a later column (optional columns may be left empty only "
            "at the end of a line)"
        )
        return f"{what} line has an empty column {c + 1} ({_NAMES[c]}){why}: {text[:80]!r}"
    if len(fields) < 6:
        return (
            f"{what} line has {len(fields)} fields, expected at least 6 "
            f"(frame,id,left,top,width,height[,conf,x,y,z]): {text[:80]!r}{_semicolons(text)}"
        )
    if not all(_NUMBER.fullmatch(f.strip()) for f in fields[:10]):  # any space, as loadtxt
        return f"{what} line has a non-number: {text[:80]!r}{_semicolons(text)}"
    values = [float(f) for f in fields[:10]]
    bad = [c for c, v in enumerate(values) if not np.isfinite(v)]
    if bad:  # every column is used: conf as a score, columns 8-10 written back
        c = bad[0]
        said = fields[c].strip().lower().lstrip("+-")
        kind = "NaN or inf" if said[:1] in ("i", "n") else "beyond a float's range"
        return (
            f"{what} line has a non-finite value ({kind}) in column {c + 1} ({_NAMES[c]}): "
            f"{text[:80]!r}"
        )
    frame = values[FRAME] + shift
    values[FRAME] = frame
    if shift and (frame < 1 or frame != int(frame) or frame > MAX_FRAME):
        return (
            f"frame is {fields[0]}, expected an integer in 0..{MAX_FRAME - shift} (the file is "
            "read as numbered from 0, --det-base 0)"
        )
    if frame < 1 or frame != int(frame) or frame > MAX_FRAME:
        hint = frames_from_1(frame, "the first value of each line")
        if frame == 0 and what == "detection file":
            hint = hint[:-1] + DET_BASE_HINT + ")"
        if frame == 0 and len(fields) == 11 and _NUMBER.fullmatch(fields[1]):
            second = float(fields[1])
            if second >= 1 and second == int(second):  # row 0 of an index, then frame 1, ...
                hint = hint[:-1] + INDEX_HINT + ")"
        return f"frame is {fields[0]}, expected an integer in 1..{MAX_FRAME} {hint}"
    values.extend(_DEFAULTS[len(values) :])
    return values


def _read_fast(p: Path, shift: int = 0) -> NDArray[np.float64] | None:
    """The rows of a well-formed file in one vectorised parse, or None.

    None sends the file to the line-by-line reader, which names the first bad line. A UTF-8
    file of the common layout (numbers only, one separator, the same columns on every line) is
    parsed by ``_core.parse_mot_text`` in one C++ pass, to the same doubles as
    :func:`_loadtxt` (``tests/io/test_mot_parse.py``): 8 ms against 95 ms for the 61 981 rows
    of a 500-track file (``bench/test_io.py``); any other goes to :func:`_loadtxt`. The checks
    after the parse are the same for both.
    """
    data = p.read_bytes()
    encoding = _encoding(data[:4])
    a = _core.parse_mot_text(data) if encoding == "utf-8-sig" else None
    if a is None:
        a = _loadtxt(p, encoding)
        if a is None:
            return None
    n = a.shape[1]
    if not 6 <= n <= 10:
        return None
    if shift:  # a file numbered from 0 (MotFile): its frames from 1, as every reader's
        a[:, FRAME] += shift
    fr = a[:, FRAME]
    finite = bool(np.all(np.isfinite(a)))  # every column: a NaN score too
    if not (finite and np.all(fr >= 1) and np.all(fr == np.floor(fr))) or np.any(fr > MAX_FRAME):
        return None
    if first_bad_box(a[:, LEFT : HEIGHT + 1]) is not None:
        return None  # the line reader names the line
    if n < 10:
        a = np.hstack([a, np.tile(np.asarray(_DEFAULTS[n:]), (len(a), 1))])
    return a


def _loadtxt(p: Path, encoding: str) -> NDArray[np.float64] | None:
    """The rows of `p` as ``np.loadtxt`` reads them (M, K), (0, 10) without a row, or None.

    The delimiter is a comma when the first line holding a field has one, else blanks; None for
    what loadtxt refuses (a comment, an empty field, a ragged line, a word, bytes not of
    `encoding`).
    """
    try:
        with p.open("r", encoding=encoding) as fh:
            first = ""
            for line in fh:
                if line.strip():
                    first = line
                    break
        if not first:
            return np.zeros((0, 10))
        a = np.loadtxt(
            p, delimiter="," if "," in first else None, ndmin=2, encoding=encoding, comments=None
        )
    except (ValueError, UnicodeDecodeError):
        return None
    return a


#: A value is written exactly when it needs at most this many significant digits (every number
#: a MOTChallenge file holds as text, a tracker's ``%.6f`` of a 4-digit pixel position too,
#: and a computed value that happens to be that short, such as the midpoint 53.485 of two
#: 2-decimal sizes); others (what pftrack computes) are rounded to 2 decimals.
EXACT_DIGITS = 10
MOST_DECIMALS = 22
"""Most decimals a value is written with: ``10**22`` is the largest power of ten a double holds
exactly."""


def _decimals(v: F64, limit: float, most: int) -> NDArray[np.int64]:
    """The fewest decimals ``d <= most`` that print each of `v` exactly, or -1.

    ``d`` prints ``v`` exactly when ``v`` is the double nearest to ``n / 10**d`` for the integer
    ``n = rint(v * 10**d)`` and ``|n| < limit`` (<= 2**52, so ``%.{d}f`` prints the digits of
    ``n``): the division of two exact doubles is correctly rounded, as is parsing the text back.
    One C++ call (``_core.fewest_decimals``; its NumPy statement is ``tests/reference/text.py``).
    """
    flat = np.ascontiguousarray(v, dtype=np.float64).ravel()
    return _core.fewest_decimals(flat, limit, most)


#: The "decimals" code of a value written in its shortest round-trip form (``%r``).
_REPR = 31


def _single_digits(v: F64) -> tuple[F64, NDArray[np.int64]]:
    """Each of `v` that is exactly a float32 as its shortest decimal, and its decimals.

    The decimal is the one with the fewest decimals that reads back as that float32; the
    decimals are -1 for the others (left as they are).

    A detector's or tracker's float32 score or box put in a float64 array (``0.9955`` as
    float32 is ``0.9955000281333923``) is then written ``0.9955``, the value the float32
    holds (its shortest form has at most 9 significant digits), not rounded to 2 decimals
    as a computed double is (``1``). A value pftrack computes in float64 lands on a float32
    about once in 2**29. The decimal is the nearest one at each number of decimals in turn,
    kept at the first that reads back as the float32 (at most :data:`MOST_DECIMALS`; a float32
    below that, 1e-30, is left to the rounding).
    """
    with np.errstate(over="ignore"):  # beyond float32's range: inf, never equal to v
        single = v.astype(np.float32)
    todo = np.flatnonzero(single.astype(np.float64) == v)
    dec = np.full(len(v), -1, np.int64)
    if not len(todo):  # pftrack's own rows: no copy
        return v, dec
    out = v.copy()
    for k in range(MOST_DECIMALS + 1):
        if not len(todo):
            break
        scale = 10.0**k
        n = np.rint(v[todo] * scale)
        r = n / scale  # the double nearest n / 10**k: both exact, the division correctly rounded
        ok = (np.abs(n) < 10.0**EXACT_DIGITS) & (r.astype(np.float32) == single[todo])
        out[todo[ok]] = r[ok]
        dec[todo[ok]] = _decimals(r[ok], 10.0**EXACT_DIGITS, MOST_DECIMALS)
        todo = todo[~ok]
    out[dec < 0] = v[dec < 0]
    return out, dec


def _printable(a: F64, exact: NDArray[np.bool_] | None) -> tuple[F64, NDArray[np.int64]]:
    """The values written for columns 3-10 of `a` (M, 10) and the decimals of each.

    A value with at most :data:`EXACT_DIGITS` significant digits is written exactly, with the
    fewest decimals (a value of 1e16 or more, always an integer, in its shortest round-trip
    form: ``1e+308``); so is any value `exact` (M, 10) marks, in its shortest round-trip form
    (code :data:`_REPR`: ``%r``, the digits Python's ``repr`` gives) when it needs more; a
    value that is exactly a float32 (a detector's score), as the float32's digits
    (:func:`_single_digits`: ``0.9955``); any other is rounded to 2 decimals as ``%.2f``
    rounds it, then written with the fewest decimals that value needs. So a file read back
    writes the same text (``88.00`` is written ``88`` the first time already) and the values a
    file held are written unchanged.
    """
    v = np.array(a[:, 2:], dtype=np.float64).ravel()  # a copy of its own: changed in place
    d = _decimals(v, 10.0**EXACT_DIGITS, MOST_DECIMALS)
    whole = np.abs(v) >= 2.0**52  # every such double is an integer (and v * 100 may overflow)
    huge = np.abs(v) >= 1e16  # 17 digits or more as an integer: 1e+308, not 309 digits
    d[whole & ~huge & (d < 0)] = 0
    d[huge] = _REPR
    if exact is not None:
        d[exact[:, 2:].ravel() & (d < 0)] = _REPR
    rest = d < 0
    if rest.any():  # a float32 in a double: the float32's digits (0.9955, not 1)
        v[rest], d[rest] = _single_digits(v[rest])
        rest = d < 0
    if rest.any():
        p = v[rest] * 100.0
        r = np.rint(p) / 100.0
        tie = np.flatnonzero(p - np.floor(p) == 0.5)  # the product rounded to a tie: as %.2f
        r[tie] = [float(f"{x:.2f}") for x in v[rest][tie].tolist()]
        dr = _decimals(r, 1e15, 2)
        dr[dr < 0] = np.where(r[dr < 0] == np.floor(r[dr < 0]), 0, 2)  # beyond ±1e13
        v[rest], d[rest] = r, dr
    v += 0.0  # -0.0 -> 0.0: never "-0" (in place: no third copy of the values at the peak)
    return v.reshape(len(a), -1), d.reshape(len(a), -1)


def _lines(a: F64, exact: NDArray[np.bool_] | None = None) -> str:
    """The MOTChallenge lines of checked (M, 10) rows, in their order.

    The values and decimals come from :func:`_printable`; the text from the C++ kernel
    ``_core.mot_lines``, byte for byte what Python's ``%`` gives with ``%d`` for frame and id
    and ``%.{d}f`` or ``%r`` (code :data:`_REPR`) for each value (held to it by
    ``tests/reference/text.py``): 8 ms for the 69 120 rows of the 500-track file once
    recovered, and 10 ms more for :func:`_printable` (timeit, best of 7, 3 December); the ``%``
    took about 120 ms to format the 61 981 rows of the file before recovery.
    """
    if not len(a):
        return ""
    values, dec = _printable(a, exact)
    return _core.mot_lines(a[:, :2], values, dec)


def _checked(rows: NDArray[np.float64] | Iterable[Iterable[float]], who: str) -> F64:
    """`rows` (M, 6..10) as (M, 10) float64 with the default columns added, or a ValueError.

    Refused: what :func:`read_mot` refuses of a file, so that every file written reads back
    (frames in ``1..2**31-1``; boxes by its rule, :func:`pftrack._check.first_bad_box`,
    applied to the values given, before any rounding); ids must be integers too.
    """
    # ragged rows or text: one line naming them (any iterable of rows, as np.asarray takes);
    # the layout as every function taking rows checks it, the default columns added
    a = mot_rows(cast("ArrayLike", rows), who)
    if not np.all(np.isfinite(a)):
        k = int(np.flatnonzero(~np.all(np.isfinite(a), axis=1))[0])
        raise ValueError(f"{who}: row {k} has NaN or inf: {a[k].tolist()}")
    ids = a[:, :2]
    if np.any(ids != np.round(ids)) or np.any(np.abs(ids) > 2**53):
        k = int(np.flatnonzero(np.any((ids != np.round(ids)) | (np.abs(ids) > 2**53), axis=1))[0])
        raise ValueError(f"{who}: row {k} has a frame or id that is not an integer: "
                         f"{a[k, :2].tolist()}")  # fmt: skip
    fr = a[:, FRAME]
    if np.any((fr < 1) | (fr > MAX_FRAME)):
        k = int(np.flatnonzero((fr < 1) | (fr > MAX_FRAME))[0])
        raise ValueError(
            f"{who}: row {k} has frame {exactly(fr[k])}, expected an integer in 1..{MAX_FRAME} "
            f"{frames_from_1(fr[k])}"
        )
    bad = first_bad_box(a[:, LEFT : HEIGHT + 1])  # what read_mot refuses is never written
    if bad is not None:
        k, c, problem = bad
        raise ValueError(
            f"{who}: row {k} (frame {a[k, FRAME]:g}, id {a[k, ID]:g}) has {BOX_VALUES[c]} "
            f"{a[k, LEFT + c]:g}: {problem}"
        )
    return a


def check_mot_rows(rows: NDArray[np.float64] | Iterable[Iterable[float]], who: str) -> None:
    """Refuse, as :func:`write_mot` would, rows that could not be written or read back.

    For a caller that writes the rows later, elsewhere (a batch task, whose client writes its
    outputs): the refusal then comes where the rows are made.

    Parameters
    ----------
    rows : (M, 6..10) array_like
        The rows.
    who : str
        How the error names the caller.

    Raises
    ------
    ValueError
        What :func:`write_mot` refuses (see :func:`mot_text`), naming the first bad row.
    """
    _checked(rows, who)


#: What `exact` of :func:`mot_text` and :func:`write_mot` may be.
Exact = bool | NDArray[np.bool_] | Iterable[bool] | Iterable[Iterable[bool]]


def _exact_mask(exact: Exact, n: int, who: str) -> NDArray[np.bool_] | None:
    """`exact` as an (n, 10) bool mask (None: nothing marked), or a Type/ValueError."""
    if exact is False:
        return None
    e = np.asarray(exact)
    if e.dtype != np.bool_:
        raise TypeError(f"{who}: exact must be a bool or bool array, got dtype {e.dtype}")
    if e.ndim == 0:
        return np.full((n, 10), bool(e))
    if e.shape == (n,):
        return np.repeat(e[:, None], 10, axis=1)
    if e.ndim == 2 and e.shape[0] == n and 6 <= e.shape[1] <= 10:
        return np.hstack([e, np.ones((n, 10 - e.shape[1]), bool)])  # defaults: short anyway
    raise ValueError(
        f"{who}: exact has shape {e.shape}, expected a bool, ({n},) or ({n}, 6..10) as rows"
    )


def mot_text(rows: NDArray[np.float64] | Iterable[Iterable[float]], *, exact: Exact = False) -> str:
    """The MOTChallenge lines :func:`write_mot` writes for `rows` (M, 6..10), in their order.

    Frame and id as integers; every other value exactly when it has at most
    :data:`EXACT_DIGITS` significant digits (every value a file written with up to 10 digits
    held), else rounded to 2 decimals (values pftrack computed), but for a value that is
    exactly a float32 (a detector's score put in a float64 array), written as the float32's
    digits (``0.9955``, at most 9 significant); with the fewest decimals either way (``88``,
    ``0.99502``, ``12.35``). So the text of what :func:`read_mot` reads of
    it is the same. Missing columns get the defaults ``conf=1, x=y=z=-1``.

    Parameters
    ----------
    rows : (M, 6..10) array_like
        The rows.
    exact : bool or (M,) or (M, 6..10) array_like of bool
        Values never rounded: the marked values (True: all; (M,): whole rows; (M, K): one
        per value of `rows`) are written exactly, those needing more than
        :data:`EXACT_DIGITS` digits in their shortest round-trip form (``repr``:
        ``499.1234567891234``, ``1.2345678901234567e-05``), so reading them back gives the
        same doubles. For values read from a file (``np.savetxt``'s ``%.18e`` writes 19
        digits): what ``pftrack recover`` and ``smooth`` pass for the values they keep.

    Raises
    ------
    ValueError
        Rows not ``(M, 6..10)``, a NaN or infinite value, a frame or id that is not an
        integer, a frame outside ``1..2**31-1`` or a box :func:`read_mot` refuses (a negative
        width or height, a value beyond ±1e9 px), or `exact` of another shape.
    """
    a = _checked(rows, "mot_text")
    return _lines(a, _exact_mask(exact, len(a), "mot_text"))


def as_written(rows: NDArray[np.float64] | Iterable[Iterable[float]]) -> F64:
    """`rows` (M, 6..10) as (M, 10) float64, with the values :func:`write_mot` writes.

    Computed values rounded to 2 decimals, as :func:`mot_text` rounds them, the rows in their
    order: what :func:`read_mot` reads back from the file, for scoring rows as ``pftrack
    eval`` scores the written file.

    Raises
    ------
    ValueError
        What :func:`mot_text` refuses.
    """
    a = _checked(rows, "as_written")
    lines = [line.split(",") for line in _lines(a).splitlines()]
    return np.array(lines, dtype=np.float64).reshape(len(a), 10)


def format_mot_row(row: Iterable[float], *, exact: bool = False) -> str:
    """One MOTChallenge line (10 columns, no newline), as :func:`mot_text` writes it."""
    a = _checked([list(row)], "format_mot_row")
    return _lines(a, _exact_mask(exact, 1, "format_mot_row"))[:-1]


def write_mot(
    path: PathLike,
    rows: NDArray[np.float64] | Iterable[Iterable[float]],
    *,
    exact: Exact = False,
) -> None:
    """Write rows (M, 6..10) as a MOTChallenge file, atomically, sorted by (frame, id).

    Columns beyond those given get the defaults ``conf=1, x=y=z=-1``. Every value must be
    finite, frames and ids integers, frames in ``1..2**31-1`` and boxes such as
    :func:`read_mot` reads (no negative width or height, no value beyond ±1e9 px:
    :func:`pftrack._check.first_bad_box`); a ValueError names the first bad row otherwise,
    before anything is written (an existing file at `path` is left as it was).
    Values are written as :func:`mot_text` writes them: a value of at most
    :data:`EXACT_DIGITS` significant digits (every value of a file written with up to 10
    digits, as MOTChallenge files and trackers write them) comes out unchanged, in its
    shortest form, and writing what :func:`read_mot` reads of a written file gives the same
    bytes. Longer values are rounded to 2 decimals (pftrack's computed boxes) unless marked
    by `exact` (as in :func:`mot_text`): ``write_mot(out, read_mot(f), exact=True)`` writes
    every value of any file unchanged. A value that is exactly a float32 (a detector's score
    or box, float32 as detectors give them) is written as the float32's digits, ``0.9955``,
    not rounded (at most 9 significant digits).

    Parameters
    ----------
    path : str or os.PathLike
        The file, in an existing folder (:func:`~pftrack.io.atomic.atomic_write`: a new
        file follows the umask, an existing one keeps its permissions, a symbolic link's
        target is replaced, a device or FIFO such as ``/dev/null`` is written through; a
        folder is refused).
    rows : (M, 6..10) array_like
        The rows, or an iterable of rows (a generator is read once).
    exact : bool or (M,) or (M, 6..10) array_like of bool
        Values written exactly, never rounded (default: none), as in :func:`mot_text`.

    Raises
    ------
    ValueError
        What :func:`mot_text` refuses, or `path` is a folder.
    TypeError
        `exact` is not of bool; `path` is not a str or os.PathLike (bytes are decoded).
    OSError
        The folder does not exist (FileNotFoundError naming it), or the hidden temporary file
        cannot be made, written or renamed (a read-only file system: the error names `path`,
        left as it was).
    """
    a = _checked(rows, "write_mot")  # first: rows and path swapped say "rows is a path"
    path = path_arg(path, "write_mot: path")
    mask = _exact_mask(exact, len(a), "write_mot")
    order = np.lexsort((a[:, ID], a[:, FRAME]))
    if np.any(order[1:] < order[:-1]):  # rows already in order (fill_gaps's) are not copied
        a = a[order]
        mask = None if mask is None else mask[order]
    text = _lines(a, mask)
    with atomic_write(path) as fh:
        fh.write(text)


#: How far a box's centre may lie from the median of a file's box centres, in multiples of
#: their spread (the interquartile range, or the median box size when larger), before
#: :func:`far_boxes_note` says it: at 100, a 1920-pixel frame's tracks would need a box 50 000
#: px or more away, no camera's pixels (stop 71's trial: a tracker's boxes at x = 1e7).
FAR_SPREAD = 100.0


def far_boxes_note(rows: NDArray[np.float64]) -> str | None:
    """What to say of tracks rows whose boxes lie far from where the others lie, or None.

    Another tracker's diverged boxes (``1e+07`` among boxes of a 480-pixel frame) pass every
    check of :func:`read_mot` (values up to ±1e9 px), and filling and smoothing carry them
    along their tracks: a smoothed track took rows at x = -50 to x = 2e6. A row is far when
    its box's centre is more than :data:`FAR_SPREAD` times the rows' spread from their
    median centre, on either axis (quartiles: a quarter of the rows may be far and still be
    found). Fewer than 4 rows are not judged.
    """
    if len(rows) < 4:
        return None
    far = np.zeros(len(rows), dtype=bool)
    within: list[str] = []
    for left, size in ((LEFT, WIDTH), (TOP, HEIGHT)):
        centre = rows[:, left] + rows[:, size] / 2
        # pftrack._stats': np.percentile and np.median import numpy.ma (15-20 ms of CPU)
        q1, mid, q3 = (percentile(centre, q) for q in (25, 50, 75))
        spread = max(q3 - q1, median(rows[:, size]), 1.0)
        far |= np.abs(centre - mid) > FAR_SPREAD * spread
        within.append(f"{q1:.0f}..{q3:.0f}")
    if not far.any():
        return None
    n, k = int(far.sum()), int(np.flatnonzero(far)[0])
    r = rows[k]
    return (
        f"{n} row{'s' * (n != 1)} with a box {FAR_SPREAD:g} times the others' spread or more "
        f"from them (the first: frame {r[FRAME]:.0f}, id {r[ID]:.0f}, left {r[LEFT]:g}, top "
        f"{r[TOP]:g}, {r[WIDTH]:g}x{r[HEIGHT]:g}; half the centres lie within x {within[0]}, "
        f"y {within[1]}): a tracker's diverged boxes, or values in other units? Filling and "
        "smoothing carry them along their tracks: mend or drop them first"
    )


def say_far_boxes(rows: NDArray[np.float64], name: object) -> None:
    """Warn ``NAME: <far_boxes_note>`` when :func:`far_boxes_note` has something to say.

    The one warning of ``pftrack recover`` and ``smooth`` (one file, or each file of a batch)
    of tracks rows read from `name`.
    """
    far = far_boxes_note(rows)
    if far is not None:  # was: carried along the tracks without a word
        warn(f"{name}: {far}")


def group_by_frame(rows: NDArray[np.float64]) -> dict[int, NDArray[np.float64]]:
    """Split rows by frame number: ``{frame: (k, 10) rows}``.

    Raises
    ------
    TypeError
        If `rows` is not an array (None, a number, text, a list of rows).
    ValueError
        If it holds rows but is not 2-D (was: an IndexError of NumPy's for a 3-D array).
    """
    if not isinstance(rows, np.ndarray):
        if isinstance(rows, (list, tuple)) and not rows:
            return {}  # no rows, as before
        raise TypeError(f"group_by_frame: rows must be an (M, 10) array, got {shown(rows)}")
    if len(rows) == 0:
        return {}
    if rows.ndim != 2 or rows.shape[1] <= FRAME:
        raise ValueError(f"group_by_frame: rows has shape {rows.shape}, expected (M, 10)")
    order = np.argsort(rows[:, FRAME], kind="stable")
    r = rows[order]
    frames, starts = np.unique(r[:, FRAME].astype(np.int64), return_index=True)
    ends = list(starts[1:]) + [len(r)]
    return {int(f): r[s:e] for f, s, e in zip(frames, starts, ends, strict=True)}


#: The share of the frames between a detection file's first and last frame that must hold a row
#: for its ending one frame short of the video to be said (:func:`zero_based_note`): every
#: det.txt here has rows on every frame of its range (PETS09, TUD-Campus, ADL-Rundle-6,
#: ETH-Sunnyday, KITTI-17); a detector that finds nothing on many frames may end anywhere.
DENSE_SHARE = 0.9
#: The fewest frames with rows that :func:`zero_based_note` judges.
DENSE_FRAMES = 10


def zero_based_note(
    frames: Iterable[int],
    n_frames: int,
    path: object,
    *,
    what: str = "detections",
    mended: str = "det1.txt",
) -> str | None:
    """What to say of detections that may count frames from 0 without a row on frame 0, or None.

    A file numbered from 0 (KITTI's labels, a decoder's index, Python's ``enumerate``) whose
    first detection is on frame 3, say, passes every check: read as MOTChallenge's frames from
    1, every box lands one frame late, on a video one frame longer than the file's last frame.
    With a row on frame 0 it is refused (:func:`read_mot`). Said when the file's last frame is
    the video's last but one (`n_frames` - 1) while it holds rows on nearly every frame of its
    range (:data:`DENSE_SHARE`, at least :data:`DENSE_FRAMES` frames): a detector that finds
    something on almost every frame and nothing on the last is rare; the same file numbered
    from 1 would reach the video's last frame. Nothing is said when the count is unknown
    (`n_frames` 0: a camera, a stream) or the file reaches the last frame, nor of a file whose
    numbering was stated (a :class:`MotFile`: ``--det-base``).

    Parameters
    ----------
    frames : iterable of int
        The frames (as numbered in the file) that hold at least one detection.
    n_frames : int
        The video's frames, 0 when unknown.
    path : object
        How the note names the file.
    what : str
        What its rows are (``"detections"``; ``"rows"`` for the tracks ``pftrack render``
        draws: a box on the frame before its own alike).
    mended : str
        The name the mend's command writes.
    """
    if stated_base(path) is not None:  # --det-base given, MotFile: the user's word stands
        return None
    held = np.unique(np.fromiter(frames, dtype=np.int64))
    if n_frames < 2 or len(held) < DENSE_FRAMES or held[-1] != n_frames - 1:
        return None
    first, last = int(held[0]), int(held[-1])
    if len(held) < DENSE_SHARE * (last - first + 1):
        return None
    detections = what == "detections"  # read by track and batch, which take --det-base
    option = (
        "read it with --det-base 0 (MotFile(path, first_frame=0) in Python) or "
        if detections
        else ""
    )
    stated = " (--det-base 1 says so, and silences this)" if detections else ""
    return (
        f"{path}: {what} on {len(held)} of frames {first}-{last}, and none on the video's "
        f"last frame, {n_frames}: numbered from 0 (KITTI, a decoder's index, enumerate)? "
        "pftrack reads MOTChallenge frames, which count from 1, and would draw every box on "
        f"the frame before its own; if so, {option}add 1 to every frame (awk -F, -v OFS=, "
        f"'{{$1+=1}}1' {path} > {mended}); if the file counts from 1, nothing is wrong{stated}"
    )
