import signal
import threading
import time

import pytest

from pftrack.io.prefetch import prefetch


def test_items_arrive_in_order_and_all():
    assert list(prefetch(range(1000), depth=3)) == list(range(1000))
    assert list(prefetch([], depth=1)) == []


def test_the_producer_runs_while_the_consumer_holds_an_item():
    produced_second = threading.Event()

    def source():
        yield 0
        yield 1
        produced_second.set()  # reached only if the producer ran ahead of the consumer
        yield 2

    it = prefetch(source(), depth=2)
    assert next(it) == 0
    assert produced_second.wait(timeout=10), "the producer did not read ahead"
    assert list(it) == [1, 2]


def test_an_error_in_the_producer_is_raised_where_it_happened():
    def source():
        yield 1
        raise OSError("disk gone")

    it = prefetch(source())
    assert next(it) == 1
    with pytest.raises(OSError, match="disk gone"):
        next(it)


def test_stopping_early_closes_the_source_and_the_thread():
    closed = threading.Event()

    def source():
        try:
            yield from range(10**9)
        finally:
            closed.set()

    before = threading.active_count()
    for i in prefetch(source(), depth=2):
        if i == 5:
            break
    assert closed.wait(timeout=10)
    assert threading.active_count() == before


@pytest.mark.parametrize("depth", [0, -1, 1.5, True])
def test_bad_depth_is_refused(depth):
    with pytest.raises(ValueError, match="depth"):
        prefetch([1], depth=depth)


def _ctrl_c_in(seconds: float) -> threading.Timer:
    """A Ctrl-C to the main thread after `seconds` (there: a blocked wait is cut short)."""
    main = threading.main_thread().ident
    assert main is not None
    timer = threading.Timer(seconds, signal.pthread_kill, (main, signal.SIGINT))
    timer.start()
    return timer


def test_a_ctrl_c_while_closing_waits_for_the_producer_then_is_raised():
    """Was: the KeyboardInterrupt cut the wait short and left the producer running.

    ``pftrack track`` Ctrl-C'd twice: the second one came while the first one's cleanup waited
    for the reader thread, which a process exiting meanwhile ended inside OpenCV's decoder:
    "terminate called without an active exception", SIGABRT.
    """
    reading, read = threading.Event(), threading.Event()

    def source():
        yield 1
        reading.set()
        time.sleep(0.6)  # a frame's decoding: the producer sees its stop after it
        read.set()
        yield 2

    it = prefetch(source(), depth=1)
    assert next(it) == 1
    assert reading.wait(timeout=10)
    timer = _ctrl_c_in(0.2)
    with pytest.raises(KeyboardInterrupt):
        it.close()
    timer.join()
    assert read.is_set()
    assert not [t for t in threading.enumerate() if t.name == "pftrack-prefetch" and t.is_alive()]
