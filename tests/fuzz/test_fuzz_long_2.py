"""The second half of the long fuzz run's targets (tests/fuzz/test_fuzz.py has the first): a
file of its own, so that CI's two processes (``--dist loadfile``) share the slow run."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.fuzz.harness import Target
from tests.fuzz.test_fuzz import HALVES, LONG_EACH, RANDOM, _run


@pytest.mark.slow
@pytest.mark.parametrize("target", HALVES[1], ids=[t.name for t in HALVES[1]])
@settings(settings.get_profile("fuzz-short"), max_examples=LONG_EACH, derandomize=not RANDOM)
@given(data=st.data())
def test_fuzz_long(target: Target, data: st.DataObject) -> None:
    _run(target, data)


def test_the_halves_hold_every_target_once() -> None:
    from tests.fuzz.test_fuzz import TARGETS

    assert [t.name for t in HALVES[0] + HALVES[1]] == [t.name for t in TARGETS]
    assert abs(len(HALVES[0]) - len(HALVES[1])) <= 1
