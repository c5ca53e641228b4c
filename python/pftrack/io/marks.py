"""The marks that tell a file pftrack wrote from a user's (docs/io.md: what an output replaces).

Every output option replaces only an absent path, an empty file, a device or pipe (written
through), or a file of its kind that pftrack wrote; any other existing file is refused before
any work, unless the command's ``--force`` is given. Each kind carries a mark:

- a picture (``--plot``, ``--figure``): a PNG's ``tEXt`` chunk ``Software`` = ``pftrack``
  before its pixels, a JPEG's comment segment (``COM``) ``pftrack`` (:func:`mark_image`);
- a JSON file (``--json``): its first key, ``"written_by": "pftrack ..."`` (:data:`JSON_MARK`);
- a CSV file (``eval --csv``): the header :func:`pftrack.eval.sequences.scores_csv` writes
  (``sequence,hota,...``), its first line;
- a video (``--render``, ``render --out``): :func:`pftrack.io.video_writer.is_render`;
- a tracks file (``--out`` of ``track``, ``recover``, ``smooth``): MOTChallenge text has no
  room for a mark that every MOTChallenge tool reads, and their users re-run a tracker into
  the file of its last run, so any file of MOTChallenge rows is replaceable (another tracker's
  too): one whose first row :func:`pftrack.io.mot.read_mot` would read as such
  (:func:`pftrack.io.mot.is_mot_text`).
"""

from __future__ import annotations

import re
import struct
import zlib
from collections.abc import Mapping

from pftrack._typing import PathLike

__all__ = [
    "CSV_MARK",
    "JSON_MARK",
    "is_marked_csv",
    "is_marked_image",
    "is_marked_json",
    "json_marked",
    "mark_image",
]

#: The key and the start of the value every JSON file pftrack writes begins with.
JSON_MARK = ("written_by", "pftrack")
#: How every CSV file pftrack writes begins (``pftrack eval --csv``'s header).
CSV_MARK = "sequence,hota,"
#: The text of an image's mark (a PNG's ``Software`` tEXt chunk, a JPEG's comment).
IMAGE_MARK = b"pftrack"
_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_PNG_TEXT = b"Software\0" + IMAGE_MARK
_JSON_START = re.compile(rb'\A\s*\{\s*"written_by"\s*:\s*"pftrack')
_HEAD = 1 << 16  # bytes read of a file to find its mark


def _head(path: PathLike) -> bytes:
    with open(path, "rb") as f:
        return f.read(_HEAD)


def _png_chunk(kind: bytes, data: bytes) -> bytes:
    crc = zlib.crc32(kind + data) & 0xFFFFFFFF
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", crc)


def mark_image(data: bytes) -> bytes:
    """`data`, an encoded PNG or JPEG, with pftrack's mark; any other format as it is.

    The pixels are unchanged: a PNG gets a ``tEXt`` chunk after its ``IHDR``, a JPEG a
    ``COM`` segment after its ``APP0`` (JFIF) segment, or after its start where it has none.
    """
    if data[:8] == _PNG_SIGNATURE and data[12:16] == b"IHDR":
        end = 8 + 12 + struct.unpack(">I", data[8:12])[0]
        return data[:end] + _png_chunk(b"tEXt", _PNG_TEXT) + data[end:]
    if data[:2] == b"\xff\xd8":
        at = 2
        if data[2:4] == b"\xff\xe0":
            at = 4 + struct.unpack(">H", data[4:6])[0]
        comment = b"\xff\xfe" + struct.pack(">H", 2 + len(IMAGE_MARK)) + IMAGE_MARK
        return data[:at] + comment + data[at:]
    return data


def _png_marked(head: bytes) -> bool:
    at = 8
    while at + 8 <= len(head):
        size = struct.unpack(">I", head[at : at + 4])[0]
        kind = head[at + 4 : at + 8]
        if kind in (b"IDAT", b"IEND"):
            return False
        if kind == b"tEXt" and head[at + 8 : at + 8 + size] == _PNG_TEXT:
            return True
        at += 12 + size
    return False


def _jpeg_marked(head: bytes) -> bool:
    at = 2
    while at + 4 <= len(head) and head[at] == 0xFF:
        kind = head[at + 1]
        if kind == 0xDA:  # start of scan: no mark before the pixels
            return False
        size = struct.unpack(">H", head[at + 2 : at + 4])[0]
        if kind == 0xFE and head[at + 4 : at + 2 + size] == IMAGE_MARK:
            return True
        at += 2 + size
    return False


def is_marked_image(path: PathLike) -> bool:
    """Whether the picture at `path` carries pftrack's mark (:func:`mark_image`)."""
    try:
        head = _head(path)
    except OSError:
        return False
    if head[:8] == _PNG_SIGNATURE:
        return _png_marked(head)
    if head[:2] == b"\xff\xd8":
        return _jpeg_marked(head)
    return False


def is_marked_json(path: PathLike) -> bool:
    """Whether the JSON file at `path` begins with pftrack's key (:data:`JSON_MARK`)."""
    try:
        return _JSON_START.match(_head(path)) is not None
    except OSError:
        return False


def is_marked_csv(path: PathLike) -> bool:
    """Whether the CSV file at `path` begins with the header pftrack writes (:data:`CSV_MARK`)."""
    try:
        return _head(path).startswith(CSV_MARK.encode())
    except OSError:
        return False


def json_marked(doc: Mapping[str, object], command: str) -> dict[str, object]:
    """`doc` with pftrack's mark as its first key: ``"written_by": "pftrack VERSION COMMAND"``."""
    from pftrack import __version__

    return {JSON_MARK[0]: f"{JSON_MARK[1]} {__version__} {command}", **doc}
