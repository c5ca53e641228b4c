"""Fuzz every public function of ``pftrack._core`` and the main Python API.

The default run tries a short profile (a few dozen examples per target); ``pytest -m slow``
runs the long one, at least 10 000 examples in all (CI runs it: see .ci/run). Both are
derandomised, so CI passes or fails on the code alone; ``PFTRACK_FUZZ_RANDOM=1`` gives the long
run a fresh seed each time, to hunt for new failures (run it as a separate, non-gating job).

The long run is split over two files, so that CI's two processes (``-n 2 --dist loadfile``, a
file each) share it: the first half of the targets here, the second in test_fuzz_long_2.py (the
halves took 356 s and 353 s of a serial run's 709 s on a busy machine; it was all on one
process). Hypothesis derives a derandomised run's seed from the test's node id, so the first
half draws the examples it drew before the split, the second half others, as many.
"""

from __future__ import annotations

import math
import os

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.fuzz.harness import Target, check_call
from tests.fuzz.targets_api import TARGETS as API_TARGETS
from tests.fuzz.targets_core import TARGETS as CORE_TARGETS

TARGETS = CORE_TARGETS + API_TARGETS
IDS = [t.name for t in TARGETS]
LONG_TOTAL = 10_000  # examples over all targets, in the slow run
LONG_EACH = math.ceil(LONG_TOTAL / len(TARGETS))
RANDOM = os.environ.get("PFTRACK_FUZZ_RANDOM", "") not in ("", "0")
#: The long run's targets in this file and in test_fuzz_long_2.py.
HALVES = (TARGETS[: len(TARGETS) // 2], TARGETS[len(TARGETS) // 2 :])


def _run(target: Target, data: st.DataObject) -> None:
    fn, args, kwargs = data.draw(target.calls, label="call")
    check_call(fn, args, kwargs, finite=target.finite)


@pytest.mark.parametrize("target", TARGETS, ids=IDS)
@settings(settings.get_profile("fuzz-short"))
@given(data=st.data())
def test_fuzz_short(target: Target, data: st.DataObject) -> None:
    _run(target, data)


@pytest.mark.slow
@pytest.mark.parametrize("target", HALVES[0], ids=[t.name for t in HALVES[0]])
@settings(settings.get_profile("fuzz-short"), max_examples=LONG_EACH, derandomize=not RANDOM)
@given(data=st.data())
def test_fuzz_long(target: Target, data: st.DataObject) -> None:
    _run(target, data)


def test_every_core_function_is_fuzzed() -> None:
    from pftrack import _core

    public = {n for n in dir(_core) if not n.startswith("_")}
    assert public <= {t.name for t in CORE_TARGETS}, public - {t.name for t in CORE_TARGETS}
