"""Many boxes in one frame: the association's steps, sparse (stop 70) against dense (stop 69).

pytest bench/test_association.py --benchmark-enable --benchmark-only --benchmark-group-by=group

Boxes spread over a 1920x1080 frame, people's sizes (40-200 px tall), one in five a jittered
twin of another (a detector without non-maximum suppression): the births' twin rule
(``first_of_twins``, every box a candidate, as on a run's first frame) at 100, 1 000 and 10 000
boxes, and ``associate`` with a track on every fifth box (100 and 1 000 boxes). Each group holds
the step and its dense reference (tests/reference/association.py), which give the same result
(tests/tracking/test_association_scale.py). The dense twin rule at 10 000 boxes holds about
1.9 GB for a few seconds; ``associate``'s assignment at 10 000 boxes and 2 000 tracks takes
tens of seconds either way (docs/tracking.md, "Many detections in one frame") and is left out.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from pytest_benchmark.fixture import BenchmarkFixture

from pftrack._typing import F64
from pftrack.tracking import AssociationConfig, association
from tests.reference import association as dense


def crowd(n: int, seed: int = 0) -> F64:
    """`n` boxes ``left, top, w, h`` over a 1920x1080 frame, one in five a twin of another."""
    rng = np.random.default_rng(seed)
    k = n - n // 5
    h = rng.uniform(40, 200, k)
    w = h * rng.uniform(0.3, 0.6, k)
    b = np.c_[rng.uniform(0, 1920 - w), rng.uniform(0, 1080 - h), w, h]
    twins = b[rng.integers(0, k, n - k)] + rng.normal(0, 4, (n - k, 4)) * [1, 1, 0.5, 0.5]
    return np.vstack([b, np.abs(twins)])


@pytest.mark.parametrize("n", [100, 1000, 10000])
@pytest.mark.parametrize("how", ["sparse", "dense"])
def test_first_of_twins(benchmark: BenchmarkFixture, n: int, how: str) -> None:
    boxes = crowd(n)
    labels = np.zeros(n, np.int64)
    explained = np.zeros(n, np.bool_)
    everyone = list(range(n))
    step: Callable[..., list[int]] = (
        association.first_of_twins if how == "sparse" else dense.first_of_twins
    )
    benchmark.group = f"first_of_twins n={n}"
    rounds = 1 if n >= 10000 and how == "dense" else None  # 1.9 GB a call
    if rounds:
        kept = benchmark.pedantic(step, (boxes, labels, everyone, explained, 0.3), rounds=1)
    else:
        kept = benchmark(step, boxes, labels, everyone, explained, 0.3)
    # twins refused (and, at 10 000 boxes, most boxes: they overlap by more than 0.3)
    assert 0 < len(kept) < n


@pytest.mark.parametrize("n", [100, 1000])
@pytest.mark.parametrize("how", ["sparse", "dense"])
def test_associate(benchmark: BenchmarkFixture, n: int, how: str) -> None:
    boxes = crowd(n)
    rng = np.random.default_rng(1)
    tracks = boxes[::5] + rng.normal(0, 3, (len(boxes[::5]), 4)) * [1, 1, 0, 0]
    nt = len(tracks)
    references = rng.dirichlet(np.ones(110), nt)
    hists = rng.dirichlet(np.ones(110), n)
    args = (tracks, tracks[:, 3], np.zeros(nt, np.int64), references, boxes, hists,
            AssociationConfig(), None)  # fmt: skip
    step = association.associate if how == "sparse" else dense.associate
    benchmark.group = f"associate n={n} tracks={nt}"
    result = benchmark(step, *args)
    assert len(result.matches) > nt // 2
