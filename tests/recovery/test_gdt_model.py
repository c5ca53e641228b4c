"""``GdtModel`` refuses settings that are no model (developer trial, 6 December).

Were taken: a negative variance in ``q``, ``r`` or ``p_init_velocity`` failed only at the first
gap, in ``kalman_filter`` ("Q is not positive semi-definite", "S is singular"), naming no
setting; ``r = 0`` likewise ("R is not positive definite"); a negative or zero ``dt`` recovered
paths with the velocity's sign flipped or none at all, without a word.
"""

from __future__ import annotations

import numpy as np
import pytest

from pftrack.recovery import GdtModel, gdt_problem

BAD = [
    ({"q": (-1e-6, 1e-6, 1e-4, 1e-4)}, "GdtModel: q is (-1e-06, 1e-06, 0.0001, 0.0001), "
     "expected variances >= 0"),
    ({"r": (1e-6, -1.0)}, "GdtModel: r is (1e-06, -1.0), expected variances > 0"),
    ({"r": (0.0, 0.0)}, "GdtModel: r is (0.0, 0.0), expected variances > 0"),
    ({"p_init_velocity": -5.0}, "GdtModel: p_init_velocity is -5.0, expected >= 0"),
    ({"dt": -1.0}, "GdtModel: dt is -1.0, expected > 0"),
    ({"dt": 0}, "GdtModel: dt is 0.0, expected > 0"),
    ({"q": (np.nan, 0, 0, 0)}, "GdtModel: q is (nan, 0.0, 0.0, 0.0), expected finite values"),
    ({"r": (np.inf, 1.0)}, "GdtModel: r is (inf, 1.0), expected finite values"),
    ({"p_init_velocity": np.inf}, "GdtModel: p_init_velocity is inf, expected a finite number"),
    ({"p_init_velocity": 0, "q": (1, 1, 1e-4, 0)}, "GdtModel: p_init_velocity is 0 and q[3] "
     "(a velocity variance) is 0: the segment filter's covariance would be singular; give one "
     "of them > 0"),
]  # fmt: skip


@pytest.mark.parametrize(("kwargs", "message"), BAD, ids=[str(b[0]) for b in BAD])
def test_a_variance_out_of_range_is_refused_naming_it(
    kwargs: dict[str, object], message: str
) -> None:
    with pytest.raises(ValueError) as e:
        GdtModel(**kwargs)  # type: ignore[arg-type]
    assert str(e.value) == message


def test_the_edges_of_the_ranges_are_taken_and_recover() -> None:
    """0 is a variance (a noiseless component), and the paper's defaults stay as they are.

    ``p_init_velocity`` 0 with a velocity variance of ``q`` 0 is the one pair refused
    together: the velocity would be known exactly, a singular covariance (``Pi_0 is not
    positive definite`` at the first gap, naming neither).
    """
    t = np.arange(10.0)
    a, b = np.c_[t, 10 + 2 * t, 20 + t], np.c_[t + 20, 50 + 2 * t, 40 + t]
    edges = (GdtModel(q=(0, 0, 0, 0)), GdtModel(p_init_velocity=0), GdtModel(q=(0, 0, 1, 1e-4)))
    for model in (GdtModel(), *edges, GdtModel(dt=0.5)):
        path = gdt_problem(a, b, model).solve().path
        assert np.isfinite(path).all()
    assert GdtModel() == GdtModel(q=(1e-6, 1e-6, 1e-4, 1e-4), r=(1e-6, 1e-6), dt=1.0)
