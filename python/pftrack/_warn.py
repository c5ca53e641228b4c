"""Warnings held until a frame's state is whole, so that a warning made an error tears nothing.

Under ``python -W error`` (or ``warnings.simplefilter("error")``) a warning raises where it
is given. A tracker that warns half-way through a frame (a negative confidence, a moving
camera, a grey video) would then stop with its state half-changed, and every later ``update``
was refused as interrupted. The per-frame methods hold their warnings instead (:class:`Held`)
and give them once the frame is taken whole: an error then leaves a usable tracker.

The holding is per thread, and nested holds give their warnings to the outermost one (the
:class:`~pftrack.Tracker` around its :class:`~pftrack.MultiObjectTracker`), which gives them
from its caller's line.
"""

from __future__ import annotations

import sys
import threading
import warnings
from types import FrameType

__all__ = ["Held", "warn", "warn_outside"]

_local = threading.local()


def warn(message: str, category: type[Warning] = UserWarning, stacklevel: int = 1) -> None:
    """``warnings.warn(message, category, stacklevel)``, or held inside this thread's :class:`Held`.

    `stacklevel` counts from the caller of this function, as ``warnings.warn``'s; a held
    warning is given from the line :meth:`Held.release` names.
    """
    pending: list[tuple[str, type[Warning]]] | None = getattr(_local, "pending", None)
    if pending is None:
        warnings.warn(message, category, stacklevel=stacklevel + 1)
    else:
        pending.append((message, category))


def warn_outside(message: str, category: type[Warning] = UserWarning) -> None:
    """:func:`warn`, from the first line of the stack outside the pftrack package.

    For a warning whose call may come through any number of pftrack's own frames (a
    :class:`~pftrack.io.video.FrameSource` read by the user's loop, ``list()``, or
    :func:`~pftrack.track_path`): the user's line either way. Inside a :class:`Held`, held.
    """
    frame = sys._getframe(1)  # this function's caller: warn's stacklevel 2
    level = 2
    while frame.f_back is not None and _inside(frame):
        frame, level = frame.f_back, level + 1
    warn(message, category, stacklevel=level)


def _inside(frame: FrameType) -> bool:
    """Whether `frame` runs code of the pftrack package."""
    name = str(frame.f_globals.get("__name__", ""))
    return name == "pftrack" or name.startswith("pftrack.")


class Held:
    """``with Held() as held: ...`` holds this thread's :func:`warn` calls; then ``release``.

    The outermost hold of a thread collects every warning given inside it (inner holds'
    too); leaving the block by an exception drops them (the call did not complete, and
    its own error says what went wrong). :meth:`release` gives them, once the caller's state
    is whole; an inner hold's ``release`` gives nothing (its outer hold will).
    """

    __slots__ = ("outermost", "pending")

    def __enter__(self) -> Held:
        outer: list[tuple[str, type[Warning]]] | None = getattr(_local, "pending", None)
        self.outermost = outer is None
        self.pending: list[tuple[str, type[Warning]]] = [] if outer is None else outer
        if outer is None:
            _local.pending = self.pending
        return self

    def __exit__(self, *exc: object) -> None:
        if self.outermost:
            _local.pending = None

    def release(self, stacklevel: int) -> None:
        """Give the held warnings, from the line `stacklevel` names (as ``warnings.warn``'s).

        Call it after the block, once the state is whole. Every one is given: under ``-W
        error`` the first one made an error is raised once all are given, the others made
        errors added to it as notes (``add_note``, Python 3.11 on), so that none is lost (a
        once-a-run warning is not given again).
        """
        if not self.outermost:
            return
        pending, self.pending = self.pending, []
        first: Warning | None = None
        for message, category in pending:
            try:
                warnings.warn(message, category, stacklevel=stacklevel + 1)
            except Warning as raised:  # made an error by the filters: the rest still given
                if first is None:
                    first = raised
                elif hasattr(first, "add_note"):  # Python 3.11 on
                    first.add_note(f"{category.__name__}: {message}")
        if first is not None:
            raise first
