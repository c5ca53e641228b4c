"""pftrack.assignment against scipy.optimize.linear_sum_assignment: the same pairs, ties too."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import linear_sum_assignment as scipy_lsa

from pftrack.assignment import linear_sum_assignment


def _outcome(fn, cost, maximize=False):
    try:
        rows, cols = fn(cost, maximize=maximize)
    except ValueError:
        return "infeasible"
    return rows.tolist(), cols.tolist()


@pytest.mark.parametrize("maximize", [False, True])
@settings(max_examples=300, deadline=None)
@given(
    shape=st.tuples(st.integers(0, 9), st.integers(0, 9)),
    levels=st.integers(1, 4),
    forbid=st.floats(0.0, 0.6),
    seed=st.integers(0, 2**32 - 1),
)
def test_same_pairs_as_scipy_with_many_ties(shape, levels, forbid, seed, maximize):
    # few distinct values make many optimal assignments: the tie-breaking must match too; an
    # infinite cost forbids a pair (-inf when maximising: maximize= was missing, SciPy has it)
    rng = np.random.default_rng(seed)
    cost = rng.integers(0, levels, shape).astype(float)
    cost[rng.random(shape) < forbid] = -np.inf if maximize else np.inf
    assert _outcome(linear_sum_assignment, cost, maximize) == _outcome(scipy_lsa, cost, maximize)


@pytest.mark.parametrize("shape", [(1, 1), (5, 5), (3, 40), (40, 3), (60, 60)])
def test_same_pairs_as_scipy_on_continuous_costs(shape):
    cost = np.random.default_rng(sum(shape)).normal(size=shape)
    rows, cols = linear_sum_assignment(cost)
    ref_rows, ref_cols = scipy_lsa(cost)
    np.testing.assert_array_equal(rows, ref_rows)
    np.testing.assert_array_equal(cols, ref_cols)
    assert rows.dtype == np.intp


def test_accepts_integer_and_strided_input():
    cost = np.arange(36).reshape(6, 6)[::2, ::-1]
    np.testing.assert_array_equal(np.stack(linear_sum_assignment(cost)), np.stack(scipy_lsa(cost)))


@pytest.mark.parametrize(
    ("cost", "error", "match"),
    [
        (np.ones(3), ValueError, "2-D"),
        (np.array([[1.0, np.nan]]), ValueError, "NaN"),
        (np.array([[-np.inf, 1.0]]), ValueError, "NaN or -inf"),
        (np.array([[np.inf, np.inf]]), ValueError, "infeasible"),
        (np.ones((2, 2), complex), TypeError, "complex"),
        (np.array([["a"]]), TypeError, "dtype"),
    ],
)
def test_bad_input_is_refused_with_a_message(cost, error, match):
    with pytest.raises(error, match=match):
        linear_sum_assignment(cost)


@pytest.mark.parametrize("shape", [(1, 1), (5, 5), (3, 40), (40, 3), (60, 60)])
def test_maximize_on_continuous_and_integer_costs(shape):
    rng = np.random.default_rng(sum(shape))
    for cost in (rng.normal(size=shape), rng.integers(-5, 5, shape), rng.random(shape) > 0.5):
        got = linear_sum_assignment(cost, maximize=True)
        want = scipy_lsa(cost, maximize=True)
        np.testing.assert_array_equal(np.stack(got), np.stack(want))
        assert got[0].dtype == np.intp
    cost = rng.normal(size=shape)
    np.testing.assert_array_equal(  # the default is to minimise, as before
        np.stack(linear_sum_assignment(cost)), np.stack(linear_sum_assignment(-cost, True))
    )


def test_maximize_refusals():
    with pytest.raises(ValueError, match=r"cost has a \+inf entry, which maximize cannot take"):
        linear_sum_assignment([[np.inf, 1.0], [1.0, 1.0]], maximize=True)
    with pytest.raises(ValueError):  # SciPy refuses it too
        scipy_lsa([[np.inf, 1.0], [1.0, 1.0]], maximize=True)
    with pytest.raises(ValueError, match="NaN"):
        linear_sum_assignment([[np.nan, 1.0]], maximize=True)
    with pytest.raises(TypeError, match="maximize must be True or False, got str 'yes'"):
        linear_sum_assignment(np.eye(2), maximize="yes")  # type: ignore[arg-type]
