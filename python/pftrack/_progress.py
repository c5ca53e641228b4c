"""A small progress bar on stderr (no dependency); silent when stderr is not a terminal."""

from __future__ import annotations

import sys
import time
from collections.abc import Iterable, Iterator
from typing import TypeVar

T = TypeVar("T")


def progress(
    items: Iterable[T], *, total: int | None = None, desc: str = "", enable: bool | None = None
) -> Iterator[T]:
    """Yield `items`, drawing ``desc  37%|#####     | 290/795 [41.2 it/s]`` on stderr.

    Parameters
    ----------
    items : iterable
        What to iterate.
    total : int, optional
        Number of items if known (else only the count and rate are shown).
    desc : str
        Label in front of the bar.
    enable : bool, optional
        Force on or off; by default on only when stderr is a terminal.
    """
    show = sys.stderr.isatty() if enable is None else enable
    if not show:
        yield from items
        return
    start = last = time.perf_counter()
    n = 0
    for item in items:
        yield item
        n += 1
        now = time.perf_counter()
        if now - last > 0.1 or (total is not None and n == total):
            last = now
            rate = n / max(now - start, 1e-9)
            if total:
                frac = min(n / total, 1.0)
                bar = "#" * int(frac * 24)
                sys.stderr.write(f"\r{desc} {frac:4.0%}|{bar:<24}| {n}/{total} [{rate:.1f} it/s]")
            else:
                sys.stderr.write(f"\r{desc} {n} [{rate:.1f} it/s]")
            sys.stderr.flush()
    if n:
        sys.stderr.write("\n")
        sys.stderr.flush()
