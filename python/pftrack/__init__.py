"""pftrack: colour particle-filter multi-object tracking and trajectory recovery."""

from __future__ import annotations

try:
    from pftrack import _core  # noqa: F401
except ImportError as exc:  # pragma: no cover - only without a build
    raise ImportError(
        "pftrack's compiled core (pftrack._core) is not built: install with `pip install .` "
        "or, for development, `pip install --no-build-isolation -ve .`"
    ) from exc

__version__ = "0.1.0"
__all__ = ["__version__"]
