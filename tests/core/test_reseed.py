"""_core.reseed_batch against the NumPy reference (tests/reference/kernels.py: reseed)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pftrack import _core
from tests.reference import kernels as ref


def _sets(sizes: list[int]) -> tuple[list[np.ndarray], list[np.ndarray], list[np.ndarray]]:
    """Particle sets full of garbage that the re-seed must overwrite everywhere."""
    return (
        [np.full((n, 6), -7.0) for n in sizes],
        [np.full(n, -7.0) for n in sizes],
        [np.full((2, 3), -7.0) for _ in sizes],
    )


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.integers(1, 9), min_size=0, max_size=4),
    st.integers(0, 2**32 - 1),
    st.floats(0, 10),
    st.floats(0, 1),
    st.floats(0.05, 1),
    st.floats(1, 6),
)
def test_reseed_batch_matches_reference(sizes, seed, pos_sd, s_sd, s_min, s_max):
    rng = np.random.default_rng(seed)
    k = len(sizes)
    # sizes far from the base size, so that the scale's clamps are reached too
    boxes = np.column_stack([rng.uniform(-50, 500, (k, 2)), rng.uniform(0.5, 300, (k, 2))])
    velocities = rng.normal(0, 5, (k, 2))
    w0, h0 = rng.uniform(1, 100, k), rng.uniform(1, 100, k)
    noise = rng.standard_normal((sum(sizes), 3))
    particles, weights, means = _sets(sizes)
    _core.reseed_batch(
        particles, weights, means, boxes, velocities, w0, h0, noise, pos_sd, s_sd, s_min, s_max
    )
    at = 0
    for i, n in enumerate(sizes):
        p, w, m = ref.reseed(
            boxes[i], velocities[i], w0[i], h0[i], noise[at : at + n], pos_sd, s_sd, s_min, s_max
        )
        at += n
        np.testing.assert_array_equal(particles[i], p)  # the same floats, not close ones
        np.testing.assert_array_equal(weights[i], w)
        np.testing.assert_array_equal(means[i], m)


def test_reseed_batch_clamps_the_scale():
    particles, weights, means = _sets([50])
    noise = np.random.default_rng(0).standard_normal((50, 3))
    box = np.array([[10.0, 10.0, 100.0, 100.0]])  # scale 10 for a base size of 10 x 10
    args = (box, np.zeros((1, 2)), np.array([10.0]), np.array([10.0]), noise, 1.0, 5.0, 0.5, 2.0)
    _core.reseed_batch(particles, weights, means, *args)
    assert means[0][0, 2] == means[0][1, 2] == 2.0
    s = particles[0][:, 2]
    assert s.min() == 0.5 and s.max() == 2.0  # both bounds reached by a spread of 5
    np.testing.assert_array_equal(particles[0][:, 5], s)


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"noise": np.zeros((4, 3))}, "noise rows is 4"),
        ({"noise": np.zeros((5, 2))}, "noise cols is 2"),
        ({"boxes": np.array([[0.0, 0.0, 0.0, 1.0]])}, "w, h > 0"),
        ({"boxes": np.array([[np.nan, 0.0, 1.0, 1.0]])}, "boxes"),
        ({"velocities": np.array([[np.inf, 0.0]])}, "velocities"),
        ({"w0": np.array([0.0])}, "w0 and h0"),
        ({"pos_sd": -1.0}, "pos_sd and s_sd"),
        ({"s_min": 3.0}, "scale bounds"),
        ({"w0": np.ones(2)}, "one entry per object"),
        # a TypeError now (was ValueError "particles[0] dtype is float32"), as from sis_step
        (
            {"particles": [np.zeros((5, 6), np.float32)]},
            r"^reseed_batch: particles\[0\] must be a C-contiguous, .* got dtype float32$",
        ),
        ({"weights": [np.zeros(4)]}, r"weights\[0\] must have shape \(N,\)"),
        ({"means": [np.zeros((3, 3))]}, r"means\[0\] must have shape \(2, 3\)"),
    ],
)
def test_reseed_batch_refuses_bad_input_before_writing(change, match):
    particles, weights, means = _sets([5])
    kw = {
        "particles": particles,
        "weights": weights,
        "means": means,
        "boxes": np.array([[1.0, 2.0, 3.0, 4.0]]),
        "velocities": np.zeros((1, 2)),
        "w0": np.ones(1),
        "h0": np.ones(1),
        "noise": np.zeros((5, 3)),
        "pos_sd": 1.0,
        "s_sd": 0.1,
        "s_min": 0.2,
        "s_max": 2.0,
    }
    kw.update(change)
    kind = TypeError if "dtype" in match or "real" in match else ValueError
    with pytest.raises(kind, match=match):
        _core.reseed_batch(**kw)
    assert (particles[0] == -7.0).all() and (weights[0] == -7.0).all()  # nothing written
