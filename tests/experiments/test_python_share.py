"""experiments.python_share: the compiled-call timer counts the outermost call only."""

from __future__ import annotations

import itertools

import pytest

import experiments.python_share as share


def test_timer_counts_outermost_call_once(monkeypatch: pytest.MonkeyPatch) -> None:
    clock = itertools.count()  # each reading of the clock is one second later
    monkeypatch.setattr(share.time, "perf_counter", lambda: float(next(clock)))
    timer = share.CompiledTimer()
    inner = timer.wrap(lambda: 1)
    outer = timer.wrap(lambda: inner() + 1)
    assert outer() == 2
    assert timer.seconds == 1.0  # the outer call's two readings; the inner one reads none
    timer.reset()
    assert timer.seconds == 0.0
    assert inner() == 1
    assert timer.seconds == 1.0
