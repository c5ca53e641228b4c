"""Read ahead on a thread: decoding overlaps tracking.

OpenCV releases the GIL while it decodes, so a video read on a second thread costs the tracker
almost nothing: `prefetch` keeps a few frames decoded ahead of the consumer.
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Generator, Iterable
from typing import TypeVar

from pftrack._check import brief
from pftrack._threads import join_through_interrupts

__all__ = ["prefetch"]

T = TypeVar("T")

_DONE = object()


class _Failed:
    def __init__(self, error: BaseException) -> None:
        self.error = error


def prefetch(items: Iterable[T], depth: int = 4) -> Generator[T, None, None]:
    """Iterate over `items` with a producer thread that stays up to `depth` items ahead.

    The items arrive in order; an exception raised by the producer is raised here, at the
    position where it happened. Closing the returned generator early (``break``, an error in the
    consumer) stops the producer and closes `items`' iterator on the producer's thread.

    Parameters
    ----------
    items : iterable
        What to read ahead: frames from a video, for instance.
    depth : int
        How many items may wait decoded (memory: `depth` frames).

    Yields
    ------
    The items of `items`, in order.
    """
    if isinstance(depth, bool) or not isinstance(depth, int) or depth < 1:
        raise ValueError(f"prefetch: depth must be a positive int, got {brief(depth)}")
    return _read_ahead(items, depth)


def _read_ahead(items: Iterable[T], depth: int) -> Generator[T, None, None]:
    buffer: queue.Queue[object] = queue.Queue(maxsize=depth)
    stop = threading.Event()
    finished = threading.Event()  # the producer's last act

    def put(item: object) -> bool:
        # wait for room, but give up when the consumer has gone
        while not stop.is_set():
            try:
                buffer.put(item, timeout=0.05)
                return True
            except queue.Full:
                continue
        return False

    def produce() -> None:
        it = iter(items)
        try:
            for item in it:
                if not put(item):
                    break
            else:
                put(_DONE)
        except BaseException as error:  # handed to the consumer, raised there
            put(_Failed(error))
        finally:
            try:
                close = getattr(it, "close", None)
                if close is not None:
                    close()
            finally:
                finished.set()

    thread = threading.Thread(target=produce, name="pftrack-prefetch", daemon=True)
    thread.start()
    try:
        while True:
            item = buffer.get()
            if item is _DONE:
                return
            if isinstance(item, _Failed):
                raise item.error
            yield item  # type: ignore[misc]
    finally:
        stop.set()
        join_through_interrupts(thread, finished)  # not left running by a second Ctrl-C
