"""sorted_quantile (the birth threshold's quantile) against np.quantile, float for float."""

from __future__ import annotations

import numpy as np
import pytest

from pftrack.tracking.tracker import MultiObjectTracker, sorted_quantile


@pytest.mark.parametrize("seed", range(5))
def test_equals_numpy_quantile(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for n in [*range(1, 30), 57, 200, 1000]:
        x = rng.random(n)
        if seed % 2:  # few distinct values: ties, equal neighbours
            x = np.round(x, 1)
        s = np.sort(x)
        for q in (0.0, 0.1, 0.25, 0.5, 0.75, 0.9, 1.0, float(rng.random()), 0, 1):
            got = sorted_quantile(s, q)
            assert type(got) is float
            assert got == float(np.quantile(x, q)), (n, q)


def test_tracker_birth_threshold_uses_it() -> None:
    tracker = MultiObjectTracker(rng=0)
    rules = tracker.config.lifecycle
    assert rules.birth_quantile is not None
    seen = []
    for k, scores in enumerate(
        [np.array([0.3, 0.9]), np.array([0.5]), np.array([0.2, 0.8, 0.4])], start=1
    ):
        tracker.frame_index = k
        seen.append(scores)
        tracker._learn_birth(scores, np.zeros(len(scores), np.int64))
        level = tracker.birth_threshold()
        quantile = float(np.quantile(np.concatenate(seen), rules.birth_quantile))
        want = min(rules.birth_score, quantile)
        assert level == want
