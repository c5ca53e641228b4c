"""Adapters that put :class:`pftrack.Tracker` behind other libraries' tracker interfaces.

- :mod:`pftrack.integrations.supervision`: ``update_with_detections(sv.Detections, frame)``,
  as supervision's own trackers (``pip install "pftrack[supervision]"``).

Each adapter imports its library only when used, so ``import pftrack`` never needs it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from pftrack._lazy import lazy_exports

if TYPE_CHECKING:
    from pftrack.integrations import supervision as supervision

__all__: list[str] = []

# pftrack.integrations.supervision after a bare `import pftrack`, loaded on first use
_MODULE_OF, __getattr__, __dir__ = lazy_exports(__name__, {}, globals())
