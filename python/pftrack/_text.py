"""Small text helpers of the messages and reports (no NumPy: ``pftrack --help`` imports this)."""

from __future__ import annotations

__all__ = ["counted", "listed"]


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
