"""_core.association_cost against the NumPy reference (tests/reference/kernels.py)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pftrack import _core
from tests.reference import kernels as ref


def _case(seed: int, nt: int, nd: int) -> tuple[np.ndarray, ...]:
    """Tracks and detections near one another: overlapping, touching, apart, some identical."""
    rng = np.random.default_rng(seed)
    tracks = np.column_stack([rng.uniform(0, 60, (nt, 2)), rng.uniform(0, 40, (nt, 2))])
    dets = np.column_stack([rng.uniform(0, 60, (nd, 2)), rng.uniform(0, 40, (nd, 2))])
    if nt and nd:
        dets[0] = tracks[0]  # IoU 1, distance 0
    dets[rng.random(nd) < 0.2, 2] = 0.0  # boxes without area: an empty union
    heights = rng.uniform(5, 50, nt)
    coasted = rng.integers(0, 12, nt)
    rho = rng.random((nt, nd))
    return tracks, heights, coasted, rho, dets


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 6), st.integers(0, 6), st.floats(0, 2),
       st.floats(0, 1), st.floats(0.1, 3))  # fmt: skip
def test_association_cost_matches_reference(seed, nt, nd, colour_weight, match_iou, distance):
    tracks, heights, coasted, rho, dets = _case(seed, nt, nd)
    args = (tracks, heights, coasted, rho, dets, distance, colour_weight, match_iou, 1e6)
    got = _core.association_cost(*args)
    assert got.shape == (nt, nd)
    np.testing.assert_array_equal(got, ref.association_cost(*args))  # the same floats


def test_association_cost_gates():
    tracks = np.array([[0.0, 0.0, 10.0, 20.0]])
    dets = np.array([[0.0, 0.0, 10.0, 20.0], [100.0, 0.0, 10.0, 20.0], [30.0, 0.0, 10.0, 20.0]])
    cost = _core.association_cost(
        tracks, np.array([20.0]), np.array([0]), np.ones((1, 3)), dets, 1.0, 0.5, 0.3, 1e6
    )
    assert cost[0, 0] == 0.0  # the same box and colour
    assert cost[0, 1] == cost[0, 2] == 1e6  # apart, beyond the 20 px radius: gated out
    # the radius grows with the frames coasted, at most to 20 (1 + 0.25 * 8) = 60 px: the box
    # 30 px away is gated in, at 1 - IoU + 30 / 60
    coasted = _core.association_cost(
        tracks, np.array([20.0]), np.array([50]), np.ones((1, 3)), dets, 1.0, 0.5, 0.3, 1e6
    )
    assert coasted[0, 2] == 1.0 + 0.5 and coasted[0, 1] == 1e6


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"track_boxes": np.zeros((2, 3))}, "track_boxes cols is 3"),
        ({"boxes": np.array([[np.nan, 0.0, 1.0, 1.0]])}, "boxes has a non-finite value"),
        ({"boxes": np.array([[0.0, 0.0, -1.0, 1.0]])}, "w, h >= 0"),
        ({"heights": np.zeros(2)}, "radius"),
        ({"heights": np.ones(3)}, "heights size is 3"),
        ({"coasted": np.array([0, -1])}, "coasted must be >= 0"),
        ({"rho": np.ones((2, 2))}, r"rho must have shape \(T, D\)"),
        ({"match_distance": np.inf}, "radius"),
    ],
)
def test_association_cost_refuses_bad_input(change, match):
    kw = {
        "track_boxes": np.ones((2, 4)),
        "heights": np.ones(2),
        "coasted": np.zeros(2),
        "rho": np.ones((2, 1)),
        "boxes": np.ones((1, 4)),
        "match_distance": 1.0,
        "colour_weight": 0.5,
        "match_iou": 0.3,
        "forbidden": 1e6,
    }
    kw.update(change)
    with pytest.raises(ValueError, match=match):
        _core.association_cost(**kw)
