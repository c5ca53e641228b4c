"""The bindings refuse absurd sizes before allocating, and results that are not finite."""

from __future__ import annotations

import numpy as np
import pytest

from pftrack import _core

I2 = np.eye(2)
PROBLEM = (I2, I2, I2, I2, np.zeros(2), I2, np.ones(2))


@pytest.mark.parametrize(
    "call",
    [
        lambda: _core.counter_normals(0, 0, 2**62),
        lambda: _core.counter_uniforms(0, 0, 0, 2**62),
        lambda: _core.gdt_solve(*PROBLEM, 2**30),
        lambda: _core.gdt_sample(*PROBLEM, 100, 2**30, 0),
        # n (n - 1) / 2 pairwise slopes: 5e9 for 100 000 points (was std::bad_alloc, a
        # MemoryError, and the same from size_fit of as many samples)
        lambda: _core.theil_sen(np.arange(100_000.0), np.arange(100_000.0)),
        lambda: _core.size_fit(np.column_stack([np.arange(100_000.0)] * 3)),
        # (K, B) histograms: 10 000 boxes of an image of 32 767 bins (was std::bad_alloc)
        lambda: _core.box_histograms(
            _core.BinnedImage(np.zeros((2, 2), np.int16), 32767), np.ones((10_000, 4))
        ),
    ],
    ids=[
        "counter_normals",
        "counter_uniforms",
        "gdt_solve",
        "gdt_sample",
        "theil_sen",
        "size_fit",
        "box_histograms",
    ],
)
def test_huge_sizes_are_refused_not_allocated(call) -> None:
    with pytest.raises(ValueError, match="more than the limit"):
        call()


@pytest.mark.parametrize("scale, T", [(1.5, 2000), (5.0, 500), (1e200, 3)])
def test_an_unstable_model_is_an_error_not_a_nan_path(scale: float, T: int) -> None:
    A = scale * I2
    with pytest.raises(ValueError, match="not finite: A is unstable"):
        _core.gdt_solve(A, *PROBLEM[1:], T)
    with pytest.raises(ValueError, match="not finite: A is unstable"):
        _core.gdt_sample(A, *PROBLEM[1:], T, 2, 0)
    with pytest.raises(ValueError, match="not finite: A is unstable"):
        _core.gdt_solve_batch([(A, *PROBLEM[1:], T)])


def test_a_stable_long_gap_is_still_solved() -> None:
    F = np.array([[1.0, 1.0], [0.0, 1.0]])  # constant velocity: polynomial growth only
    out = _core.gdt_solve(F, 0.01 * I2, np.eye(1, 2), np.eye(1), np.zeros(2), I2, np.ones(1), 2000)
    assert out["path"].shape == (2001, 2) and np.all(np.isfinite(out["path"]))


def test_batch_items_of_the_wrong_kind_are_type_and_value_errors() -> None:
    with pytest.raises(TypeError, match="T must be an int, got float"):
        _core.gdt_solve_batch([(*PROBLEM, 3.0)])
    with pytest.raises(ValueError, match="problem 0 must be a tuple"):
        _core.gdt_solve_batch([[1]])
    with pytest.raises((TypeError, ValueError), match="not an array of numbers|convert string"):
        _core.gdt_solve_batch([("abc", *PROBLEM[1:], 3)])


@pytest.mark.parametrize(
    "states, weights",
    [
        ([[1e308, 0, 0]], [1e308]),  # the fuzz suite's find: w * x overflowed to inf
        ([[1e308, -1e308, 5], [1e308, -1e308, 7]], [1e300, 3e300]),
        ([[1.5e308, 0, 0], [1.5e308, 0, 0], [-1e308, 1, 2]], [1.0, 1.0, 2.0]),
    ],
)
def test_estimate_mean_is_finite_near_the_largest_double(states, weights) -> None:
    p = np.zeros((len(states), 6))
    p[:, :3] = states
    w = np.asarray(weights, dtype=float)
    mean, map_state, k = _core.estimate(p, w)
    assert np.all(np.isfinite(mean))
    c = w / w.sum()  # the reference: a convex combination, summed without overflow
    np.testing.assert_allclose(mean, (c[:, None] * (p[:, :3] / 1e300)).sum(axis=0) * 1e300)
    assert k == int(np.argmax(w)) and np.array_equal(map_state, p[k, :3])


def test_estimate_of_ordinary_input_is_the_plain_weighted_mean() -> None:
    rng = np.random.default_rng(7)
    p = rng.normal(0, 100, (50, 6))
    w = rng.uniform(0, 1, 50)
    total, acc = 0.0, [0.0, 0.0, 0.0]
    for i in range(len(w)):  # the kernel's order of additions: the same bits
        total += w[i]
        acc = [acc[d] + w[i] * p[i, d] for d in range(3)]
    np.testing.assert_array_equal(_core.estimate(p, w)[0], np.array(acc) / total)
