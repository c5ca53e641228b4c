"""Small text helpers of the messages and reports (no NumPy: ``pftrack --help`` imports this)."""

from __future__ import annotations

import re

__all__ = [
    "SaidBefore",
    "counted",
    "error_line",
    "listed",
    "listed_compactly",
    "on_one_line",
    "opening",
    "said_alike",
]


def on_one_line(text: str) -> str:
    r"""`text` on one line, a file name's bytes that are not UTF-8 as ``\xfe`` escapes.

    Python keeps such bytes of a name as surrogate escapes (``'vid\udcfe.mp4'``).
    """
    line = " ".join(text.split())
    try:
        return line.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
    except UnicodeEncodeError:  # another lone surrogate
        return line.encode("utf-8", "backslashreplace").decode("utf-8")


def error_line(exc: BaseException) -> str:
    """The error as one line, as ``pftrack`` prints it: an OSError as ``Is a directory: PATH``.

    Not Python's ``[Errno 21] Is a directory: 'PATH'``: an OSError that names a file is its
    reason and the file; messages lose their line breaks (:func:`on_one_line`). The commands'
    errors (``pftrack track: error: ...``) and each failed task of a batch say it so.
    """
    if isinstance(exc, OSError) and exc.filename and str(exc.filename) not in str(exc.strerror):
        text = f"{exc.strerror or exc}: {exc.filename}"
    else:
        text = str(exc)
    return on_one_line(text)


def counted(n: int, noun: str, plural: str | None = None) -> str:
    """``n noun``, in the plural unless `n` is 1: ``1 row``, ``2 rows``.

    `plural` for a noun whose plural is not ``noun + "s"`` (``counted(2, "box", "boxes")``).
    """
    return f"{n} {noun if n == 1 else plural or noun + 's'}"


def listed(names: list[str], shown: int = 3) -> str:
    """The first `shown` of `names`, comma-separated, then ``...`` if there are more.

    ``listed(["a", "b", "c", "d"])`` is ``a, b, c, ...``.
    """
    return ", ".join(names[:shown]) + (", ..." if len(names) > shown else "")


def _numbered(name: str) -> tuple[str, str, str] | None:
    """``(prefix, digits, suffix)`` of `name`'s last number (``cam07.v2`` has ``2``), or None."""
    m = re.fullmatch(r"(.*?)(\d+)(\D*)", name)
    return (m.group(1), m.group(2), m.group(3)) if m else None


def _follows(a: str, b: str) -> bool:
    """Whether `b` follows `a` in a numbered run: ``cam09``, ``cam10``; ``t9``, ``t10``."""
    na, nb = _numbered(a), _numbered(b)
    if na is None or nb is None or (na[0], na[2]) != (nb[0], nb[2]):
        return False
    padded = len(na[1]) == len(nb[1]) or not (na[1][0] == "0" or nb[1][0] == "0")
    return padded and int(nb[1]) == int(na[1]) + 1


def listed_compactly(names: list[str], shown: int = 4) -> str:
    """`names` comma-separated, each run of three or more numbered names as ``first..last``.

    Then ``...`` after `shown` items: ``listed_compactly(["cam01", "cam02", "cam03", "odd"])``
    is ``cam01..cam03, odd``; twelve cameras ``cam01`` to ``cam12`` are ``cam01..cam12``.
    """
    runs: list[list[str]] = []
    for name in names:
        if runs and _follows(runs[-1][-1], name):
            runs[-1].append(name)
        else:
            runs.append([name])
    items = [i for r in runs for i in ([f"{r[0]}..{r[-1]}"] if len(r) > 2 else r)]
    return ", ".join(items[:shown]) + (", ..." if len(items) > shown else "")


NAME = "NAME"  # where grouped messages named their own sequence or file


def _named(name: str) -> re.Pattern[str]:
    """`name` where a message names it, not inside a longer name.

    Not ``cam1`` in ``cam10``, nor ``MOT17-02`` in ``MOT17-02-DPM``; ``cam1`` in
    ``/data/cam1.avi``, yes.
    """
    return re.compile(rf"(?<![\w-]){re.escape(name)}(?![\w-])")


def said_alike(messages: list[tuple[str, str]]) -> list[tuple[str, list[str]]]:
    """``(name, message)`` pairs grouped where their messages differ only by their own names.

    ``cam1: ... sequence cam1 has no det/det.txt`` and ``cam2: ... sequence cam2 has ...``
    are one group, said ``... sequence NAME has no det/det.txt``: each place where the
    messages of a group name their own (differing) names reads ``NAME``; a place where they
    all read the first one's name (a word of the text that happens to be it) keeps it.
    Identical messages are a group too. Groups in the order of their first message.

    Returns
    -------
    list of (message, names)
        One per group: its text (the message itself for a group of one), and its names.
    """
    groups: list[tuple[str, list[str], list[str], set[int]]] = []  # name, parts, names, slots
    for name, message in messages:
        for first, parts, names, slots in groups:
            differ = _fits(first, parts, name, message)
            if differ is not None:
                names.append(name)
                slots |= differ
                break
        else:
            groups.append((name, _named(name).split(message), [name], set()))
    out = []
    for first, parts, names, slots in groups:
        text = parts[0]
        for k, part in enumerate(parts[1:]):
            text += (NAME if k in slots else first) + part
        out.append((text, names))
    return out


class SaidBefore:
    """Messages said one at a time, each matched against those said before for other names.

    :func:`said_alike` for messages that cannot wait for the last one (``pftrack batch``
    prints each sequence's warnings as it ends): :meth:`first` says whose earlier message a
    new one repeats, in the same words or differing only where each names its own name.
    """

    def __init__(self) -> None:
        self._said: list[tuple[str, list[str]]] = []  # a name, its message split at the name

    def first(self, name: str, message: str) -> str | None:
        """The name another message said in the same words was said for; None if none was.

        Such a message is remembered only when new: the first name stays the one named.
        `name`'s own message said again is new for this purpose (None): it repeats no other.
        """
        for first, parts in self._said:
            if _fits(first, parts, name, message) is not None:
                return first if first != name else None
        self._said.append((name, _named(name).split(message)))
        return None


def opening(text: str, words: int = 6) -> str:
    """The first `words` words of `text`, then ``...`` if it has more.

    ``opening("no track over 3 frames of the video: too short?", 4)`` is
    ``no track over 3 ...``.
    """
    split = text.split()
    return " ".join(split[:words]) + (" ..." if len(split) > words else "")


def _fits(first: str, parts: list[str], name: str, message: str) -> set[int] | None:
    """Where `message` reads `name` in place of the first message's `first`.

    `parts` is the first message split at its name; the places are indices of the splits.
    None when `message` differs otherwise.
    """
    if len(parts) == 1:  # the first message does not name its name: the same words, or not
        return set() if message == parts[0] else None
    if not (message.startswith(parts[0]) and message.endswith(parts[-1])):
        return None  # at once (was: a pattern built and matched for each pair: a batch of
        # 1000 sequences, each with its own warning, took 37 s to list them)
    either = f"({re.escape(first)}|{re.escape(name)})"
    m = re.fullmatch(either.join(re.escape(p) for p in parts), message, flags=re.DOTALL)
    if m is None:
        return None
    return {k for k in range(len(parts) - 1) if name != first and m.group(k + 1) == name}
