"""Progress bars on stderr (tqdm): rate and time left; silent when stderr is not a terminal.

``pftrack --quiet`` calls :func:`set_quiet`, which silences every bar of the process.
"""

from __future__ import annotations

import os
import sys
import threading
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any, TypeVar

T = TypeVar("T")

Report = Callable[[float], None]
"""A callback told the fraction of a piece of work done so far, from 0 to 1 (``on_progress``)."""

REPORTS = 200
"""How many times :func:`reporting` reports over its items, about (under twice as many)."""

_quiet = False
DELAY = 0.5
"""Seconds before a bar appears: quick steps draw nothing."""


def set_quiet(quiet: bool = True) -> None:
    """Silence (or allow again) every progress bar of this process."""
    global _quiet
    _quiet = bool(quiet)


def quiet() -> bool:
    """Whether :func:`set_quiet` silenced the process (``pftrack --quiet``)."""
    return _quiet


_asked: ContextVar[bool | None] = ContextVar("pftrack_bars", default=None)


@contextmanager
def bars(enable: bool | None) -> Iterator[None]:
    """Within: every bar whose own call leaves `enable` at None is drawn as `enable` says.

    For a function whose ``show_progress`` covers work it calls without passing it on, as
    ``track_frames`` covers the tracker's offline pass. None changes nothing.
    """
    token = _asked.set(enable if enable is not None else _asked.get())
    try:
        yield
    finally:
        _asked.reset(token)


def enabled(enable: bool | None = None) -> bool:
    """Whether a bar asked for with `enable` is drawn: never when quiet; by default on a TTY."""
    if _quiet:
        return False
    if enable is None:
        enable = _asked.get()
    if enable is None:
        try:  # no stderr (started with it closed, 2>&-): no bar, no crash
            return sys.stderr.isatty()
        except (AttributeError, OSError, ValueError):
            return False
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
    with _tqdm(items, total=total, desc=desc, unit=unit) as bar:
        yield from bar


def check_report(report: object, fn: str) -> None:
    """Refuse an ``on_progress`` of `fn` that is neither None nor callable (TypeError)."""
    if report is not None and not callable(report):
        raise TypeError(
            f"{fn}: on_progress is {type(report).__name__}, expected a callable (told the "
            "fraction done) or None"
        )


def part(report: Report | None, start: float, stop: float) -> Report | None:
    """`report` for a part of the work: the part's fractions 0 to 1 told as `start` to `stop`.

    None for None: a loop that nobody follows reports nothing.
    """
    if report is None:
        return None
    return lambda f: report(start * (1 - f) + stop * f)  # exactly `stop` at 1


def reporting(
    items: Sequence[T], report: Report | None, start: float = 0.0, stop: float = 1.0
) -> Iterable[T]:
    """Iterate `items`, telling `report` the fraction done, `start` to `stop`, as they go.

    ``report`` is called after the body of every ``len(items) // REPORTS``-th item, and after
    the last one with `stop`: under ``2 * REPORTS`` calls, whatever the length (a scorer's
    frames: a bar moved without a call per frame; the items are yielded by the chunk, 0.05
    microseconds an item). With `report` None, `items` itself.
    """
    if report is None or not items:
        return items
    return _reporting(items, report, start, stop)


def _reporting(items: Sequence[T], report: Report, start: float, stop: float) -> Iterator[T]:
    n = len(items)
    every = max(1, n // REPORTS)
    for lo in range(0, n, every):
        yield from items[lo : lo + every]  # the loop's bodies run here: done below
        f = min(lo + every, n) / n
        report(start * (1 - f) + stop * f)


def _tqdm(items: Iterable[Any] | None = None, **kwargs: Any) -> Any:
    """A tqdm bar on stderr with pftrack's settings.

    tqdm is imported only when a bar is drawn: it keeps ``import pftrack`` light.
    """
    from tqdm import tqdm

    bar = tqdm(
        items,
        file=sys.stderr,
        dynamic_ncols=True,
        mininterval=0.2,
        smoothing=0.1,
        delay=DELAY,
        **kwargs,
    )
    if bar.dynamic_ncols:  # tqdm's own reads a terminal of 0 lines as "no room for a bar"
        bar.dynamic_ncols = screen_shape
        bar.ncols, bar.nrows = screen_shape(bar.fp)
    return bar


def screen_shape(stream: Any) -> tuple[int | None, int | None]:
    """The ``(columns, lines)`` a bar on `stream` may use; None where the terminal does not say.

    tqdm's size check. A terminal whose size is unset reports 0 columns and 0 lines (the
    pseudo-terminal of ``script``, of some CI runners and containers): tqdm took that as -1
    lines and hid every bar as if it were below the screen's last line (`pftrack batch`
    drew nothing). An unknown size is None here: tqdm's defaults (a bar of 10 characters,
    20 lines).
    """
    try:
        cols, lines = os.get_terminal_size(stream.fileno())
    except (AttributeError, OSError, ValueError):  # not a terminal, closed, replaced
        return None, None
    return (cols - 1 if cols > 1 else None), (lines - 1 if lines > 1 else None)


class Bar:
    """A bar moved by hand (:meth:`set`), from any thread; draws nothing when disabled.

    For progress that does not come from one loop: the frames of a batch's sequences, reported
    by the tasks as they run. Drawn as :func:`progress` draws, once :data:`DELAY` has passed.

    Parameters
    ----------
    total : int, optional
        The count at the end (None: only the count, time and rate are shown).
    desc : str
        Label in front of the bar (:meth:`describe` changes it).
    enable : bool, optional
        As :func:`progress`'s.
    unit : str
        What one count is.
    """

    def __init__(
        self, total: int | None, *, desc: str = "", enable: bool | None = None, unit: str = "it"
    ) -> None:
        self._bar: Any = None
        self._lock = threading.Lock()
        if enabled(enable):
            self._bar = _tqdm(total=total, desc=desc, unit=unit)

    @property
    def enabled(self) -> bool:
        """Whether the bar is drawn."""
        return self._bar is not None

    def set(self, n: int) -> None:
        """Move the bar to count `n`."""
        if self._bar is not None:
            with self._lock:
                self._bar.update(n - self._bar.n)

    def describe(self, desc: str) -> None:
        """Change the label."""
        if self._bar is not None:
            with self._lock:
                self._bar.set_description_str(desc, refresh=False)

    def close(self) -> None:
        """Remove the bar from the terminal's last line (it is left drawn)."""
        if self._bar is not None:
            with self._lock:
                self._bar.close()

    def __enter__(self) -> Bar:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
