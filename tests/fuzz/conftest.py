"""Hypothesis settings of the fuzz suite: one profile, `fuzz-short`; the slow test overrides it."""

from __future__ import annotations

import os

from hypothesis import HealthCheck, settings

# The short profile keeps the default run quick: 30 examples per target, derandomised (the same
# examples every run). PFTRACK_FUZZ_EXAMPLES=N changes the count (e.g. to hunt locally).
settings.register_profile(
    "fuzz-short",
    max_examples=int(os.environ.get("PFTRACK_FUZZ_EXAMPLES", "30")),
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                           HealthCheck.filter_too_much],
)  # fmt: skip
