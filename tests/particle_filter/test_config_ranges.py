"""The samplers' settings are refused when made, in one line naming the class and the field.

Each case ran before the check (trial H): it failed at the first step with a pybind11
signature dump, or gave no estimate at all.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pftrack.particle_filter import (
    Ar2Model,
    ColourParticleFilter,
    FilterConfig,
    MHColourParticleFilter,
    RJMCMCConfig,
    hsv_bins,
)

NAN = math.nan
INT = r"expected an integer in \[{}, 2147483647\]"

# (field, value, error, message); "# was: ..." what happened before the check
RJ_REFUSED = [
    # was: the core's "burn_in is -1" at the first step
    ("burn_in", -1, ValueError, INT.format(0)),
    # was: pybind11's "incompatible constructor arguments" (10**12, 1.5)
    ("burn_in", 10**12, ValueError, INT.format(0)),
    ("burn_in", 1.5, ValueError, INT.format(0)),
    # was: accepted (True counts as 1 sample)
    ("n_samples", True, ValueError, INT.format(1)),
    ("n_samples", 0, ValueError, INT.format(1)),
    ("p_birth", NAN, ValueError, "expected a finite value >= 0"),
    ("p_birth", -1.0, ValueError, "expected a finite value >= 0"),
    ("p_birth", 0.0, ValueError, "both > 0 or both 0"),
    ("p_swap", "0.1", TypeError, "must be a number"),
    ("lam", NAN, ValueError, "expected a finite value >= 0"),
    ("interaction", NAN, ValueError, "expected a finite value >= 0"),
    ("birth_sigma_xy", 0.0, ValueError, "expected a finite value > 0"),
    ("birth_gate", NAN, ValueError, "expected a finite value > 0"),
    ("survival", 2.0, ValueError, r"expected a value in \(0, 1\]"),
    ("survival", 0.0, ValueError, r"expected a value in \(0, 1\]"),
    # was: no estimate ever reported (NaN, 2), silently
    ("min_existence", NAN, ValueError, r"expected a value in \[0, 1\]"),
    ("min_existence", 2.0, ValueError, r"expected a value in \[0, 1\]"),
    ("kernel", "x", ValueError, "expected 'uniform' or 'epanechnikov'"),
    ("a", (1.0, 2.0), ValueError, r"expected 3 finite values \(cx, cy, s\)"),
    ("b", (1.0, NAN, 1.0), ValueError, r"expected 3 finite values \(cx, cy, s\)"),
    ("sigma", (4.0, 4.0, 0.0), ValueError, r"expected 3 finite values > 0"),
    ("a", ("1", "2", "3"), TypeError, "must hold real numbers"),
    ("s_max", math.inf, ValueError, r"expected a finite value >= s_min \(0.2\)"),
    ("s_max", 0.1, ValueError, r"expected a finite value >= s_min \(0.2\)"),
    ("s_min", 0.0, ValueError, "expected a finite value > 0"),
]


@pytest.mark.parametrize(
    ("name", "value", "error", "message"),
    RJ_REFUSED,
    ids=[f"{n}={v!r}" for n, v, _, _ in RJ_REFUSED],
)
def test_rjmcmc_config_refuses_a_setting_out_of_range(name, value, error, message):
    with pytest.raises(error, match=rf"^RJMCMCConfig: {name}.*{message}") as info:
        RJMCMCConfig(**{name: value})
    assert "\n" not in str(info.value)


def test_rjmcmc_config_refuses_a_chain_longer_than_the_core_counts():
    # was: burn_in + n_samples overflowed the core's int
    with pytest.raises(ValueError, match=r"RJMCMCConfig: burn_in \+ n_samples .* at most"):
        RJMCMCConfig(burn_in=2**31 - 1, n_samples=1)
    assert RJMCMCConfig(burn_in=0, n_samples=2**31 - 1).n_samples == 2**31 - 1


def test_rjmcmc_defaults_and_zero_birth_and_death_are_taken():
    c = RJMCMCConfig()
    assert (c.burn_in, c.n_samples, c.survival, c.min_existence) == (50, 200, 0.95, 0.5)
    assert RJMCMCConfig(p_birth=0.0, p_death=0.0).p_birth == 0.0


AR2_REFUSED = [
    # was: accepted, then the step's pybind11 "incompatible function arguments"
    ("use_means", "no", TypeError, "must be True or False"),
    # was: a standalone filter's estimate beyond ±1e9 px (1e13 after 50 steps)
    ("sigma_xy", 1e12, ValueError, r"expected a value in \[0, 1e\+06\]"),
    # was: boxes 4e6 px wide after 50 steps (s_max=1e300)
    ("s_max", 1e300, ValueError, r"expected a value in \(0, 1000\]"),
    # was: an estimate of 1e293 px after 50 steps (velocity_gain=1e6)
    ("velocity_gain", 1.5, ValueError, r"expected a value in \[0, 1\]"),
    ("scale_gain", 2.0, ValueError, r"expected a value in \[0, 1\]"),
]


@pytest.mark.parametrize(
    ("name", "value", "error", "message"),
    AR2_REFUSED,
    ids=[f"{n}={v!r}" for n, v, _, _ in AR2_REFUSED],
)
def test_ar2_model_refuses_a_value_that_leaves_the_filters_domain(name, value, error, message):
    with pytest.raises(error, match=rf"^Ar2Model: {name} .*{message}"):
        Ar2Model(**{name: value})


def test_ar2_model_bounds_are_taken_and_keep_a_filter_in_its_domain():
    frame = np.zeros((120, 160, 3), np.uint8)
    frame[40:80, 60:80] = (0, 0, 200)
    img = hsv_bins(frame)
    model = Ar2Model(sigma_xy=1e6, s_max=1e3, velocity_gain=1.0, scale_gain=1.0, use_means=False)
    f = ColourParticleFilter([70, 60, 20, 40], np.ones(110), FilterConfig(model=model), rng=0)
    for _ in range(10):
        box = f.step(img).box_cxcywh
    assert (np.abs(box) < 1e9).all()
    assert np.abs(f.particles).max() < 1e9


@pytest.mark.parametrize("n_iter", [10**12, True, 1.0, 0])
def test_mh_filter_refuses_n_iter_outside_the_cores_int(n_iter):
    # was: 10**12 a pybind11 "incompatible function arguments" dump at the step; True accepted
    with pytest.raises(ValueError, match=r"MHColourParticleFilter: n_iter is .*\[1, 2147483647\]"):
        MHColourParticleFilter([40, 30, 12, 20], np.ones(110), n_iter=n_iter)
