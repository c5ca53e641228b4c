"""Adapters that put :class:`pftrack.Tracker` behind other libraries' tracker interfaces.

- :mod:`pftrack.integrations.supervision`: ``update_with_detections(sv.Detections, frame)``,
  as supervision's own trackers (``pip install "pftrack[supervision]"``).

Each adapter imports its library only when used, so ``import pftrack`` never needs it.
"""
