"""Input and output: MOTChallenge files, video and image folders, atomic writes."""

from __future__ import annotations

from pftrack._lazy import lazy_exports
from pftrack.io.atomic import atomic_path, atomic_write
from pftrack.io.mot import group_by_frame, read_mot, write_mot

__all__ = ["atomic_path", "atomic_write", "group_by_frame", "read_mot", "write_mot"]

# a public submodule loads on first use after a bare ``import pftrack`` (``pftrack.io.x``)
_, __getattr__, __dir__ = lazy_exports(__name__, {}, globals())
