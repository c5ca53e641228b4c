"""Progress bars on stderr (tqdm): rate and time left; silent when stderr is not a terminal.

``pftrack --quiet`` calls :func:`set_quiet`, which silences every bar of the process.
"""

from __future__ import annotations

import sys
from collections.abc import Iterable, Iterator
from typing import TypeVar

T = TypeVar("T")

_quiet = False
DELAY = 0.5
"""Seconds before a bar appears: quick steps draw nothing."""


def set_quiet(quiet: bool = True) -> None:
    """Silence (or allow again) every progress bar of this process."""
    global _quiet
    _quiet = bool(quiet)


def enabled(enable: bool | None = None) -> bool:
    """Whether a bar asked for with `enable` is drawn: never when quiet; by default on a TTY."""
    if _quiet:
        return False
    if enable is None:
        return sys.stderr.isatty()
    return enable


def progress(
    items: Iterable[T],
    *,
    total: int | None = None,
    desc: str = "",
    enable: bool | None = None,
    unit: str = "it",
) -> Iterator[T]:
    """Yield `items`, drawing ``desc  37%|####    | 290/795 [00:07<00:12, 41.2 it/s]`` on stderr.

    The bar (tqdm's) shows the count, elapsed time, time left and rate; it appears once the
    loop has run for :data:`DELAY` seconds.

    Parameters
    ----------
    items : iterable
        What to iterate.
    total : int, optional
        Number of items if known (else only the count, time and rate are shown). tqdm takes
        it from ``len(items)`` when there is one.
    desc : str
        Label in front of the bar.
    enable : bool, optional
        Force on or off; by default on only when stderr is a terminal. :func:`set_quiet` wins.
    unit : str
        What one item is (``frame``, ``gap``, ...).
    """
    if not enabled(enable):
        yield from items
        return
    from tqdm import tqdm  # only when a bar is drawn: keeps `import pftrack` light

    with tqdm(
        items,
        total=total,
        desc=desc,
        unit=unit,
        file=sys.stderr,
        dynamic_ncols=True,
        mininterval=0.2,
        smoothing=0.1,
        delay=DELAY,
    ) as bar:
        yield from bar
