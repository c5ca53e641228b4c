"""The samplers' settings are refused when made, in one line naming the class and the field.

Each case ran before the check (trial H): it failed at the first step with a pybind11
signature dump, or gave no estimate at all.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from pftrack.kalman import wna_Q_xy
from pftrack.particle_filter import (
    Ar2Model,
    BinnedImage,
    ColourParticleFilter,
    FilterConfig,
    MHColourParticleFilter,
    RJMCMCConfig,
    RJMCMCFilter,
    box_histograms,
    estimate,
    hsv_bins,
)
from pftrack.tracking import CameraConfig

NAN = math.nan
INT = r"expected an integer in \[{}, 2147483647\]"
INT_TYPE = r"must be an integer in \[{}, 2147483647\], got"

# (field, value, error, message); "# was: ..." what happened before the check
RJ_REFUSED = [
    # was: the core's "burn_in is -1" at the first step
    ("burn_in", -1, ValueError, INT.format(0)),
    # was: pybind11's "incompatible constructor arguments" (10**12, 1.5)
    ("burn_in", 10**12, ValueError, INT.format(0)),
    ("burn_in", 1.5, TypeError, INT_TYPE.format(0)),  # a wrong type: TypeError (was ValueError)
    # was: accepted (True counts as 1 sample)
    ("n_samples", True, TypeError, INT_TYPE.format(1)),
    ("n_samples", "200", TypeError, INT_TYPE.format(1) + " str '200'"),
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
    ("min_samples", -1, ValueError, r"expected an integer in \[0, 2147483647\]"),
    ("min_samples", 2048.0, TypeError, "int"),
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


@pytest.mark.parametrize("n_iter", [10**12, 0])
def test_mh_filter_refuses_n_iter_outside_the_cores_int(n_iter):
    # was: 10**12 a pybind11 "incompatible function arguments" dump at the step
    with pytest.raises(ValueError, match=r"MHColourParticleFilter: n_iter is .*\[1, 2147483647\]"):
        MHColourParticleFilter([40, 30, 12, 20], np.ones(110), n_iter=n_iter)


@pytest.mark.parametrize("n_iter", [True, 1.0, "2"])
def test_mh_filter_refuses_an_n_iter_that_is_not_an_int(n_iter):
    # was: True accepted, then ValueError for True, 1.0 and "2" (TypeError: a wrong type, as
    # Ar2Model(sigma_xy="4") and RJMCMCConfig(lam="1") refuse theirs)
    with pytest.raises(
        TypeError,
        match=rf"^MHColourParticleFilter: n_iter must be an integer in \[1, 2147483647\], got "
        rf"{type(n_iter).__name__} {re.escape(repr(n_iter))}$",
    ):
        MHColourParticleFilter([40, 30, 12, 20], np.ones(110), n_iter=n_iter)


_IM = hsv_bins(np.zeros((8, 10, 3), np.uint8))
_MASK = np.ones((8, 10), np.uint8)
_PARTS = np.ones((3, 6))

# (call, error, message): the whole message, one line; "# was: ..." what happened before
WRONG_KIND = [
    # was ValueError for these wrong types, where a number setting ("4") gave TypeError
    (lambda: FilterConfig(n_particles="5"), TypeError,
     "FilterConfig: n_particles must be an integer in [1, 1000000], got str '5'"),
    (lambda: FilterConfig(n_particles=5.0), TypeError,
     "FilterConfig: n_particles must be an integer in [1, 1000000], got float 5.0"),
    (lambda: FilterConfig(n_particles=0), ValueError,
     "FilterConfig: n_particles is 0, expected an integer in [1, 1000000]"),
    # the tracker's integer settings likewise (was ValueError)
    (lambda: CameraConfig(refresh_frames=2.5), TypeError,
     "CameraConfig: refresh_frames must be an integer >= 1, got float 2.5"),
    (lambda: CameraConfig(refresh_frames=0), ValueError,
     "CameraConfig: refresh_frames is 0, expected an integer >= 1"),
    # was AttributeError: 'str' object has no attribute 'kernel'
    (lambda: RJMCMCFilter("x"), TypeError,
     "RJMCMCFilter: config must be an RJMCMCConfig, got str 'x'"),
    # was ValueError (the core's "rjmcmc_step: mask dtype is float32"), hsv_bins' TypeError
    (lambda: RJMCMCFilter(rng=0).step(_IM, _MASK.astype(np.float32), []), TypeError,
     "RJMCMCFilter.step: mask dtype is float32, expected uint8 or bool"),
    # was pybind11's list of signatures, over several lines
    (lambda: box_histograms(_IM, [5, 4, 2, 2], kernel=None), TypeError,
     "box_histograms: kernel must be 'uniform' or 'epanechnikov', got NoneType None"),
    # was NumPy's "could not convert string to float: np.str_('a')", no function named
    (lambda: estimate(_PARTS, np.array(["a", "b", "c"])), TypeError,
     "estimate: weights must hold real numbers, got dtype <U1"),
    # was "estimate: particles cols is 1" for one (6,) row
    (lambda: estimate(_PARTS[0], [1.0]), ValueError,
     "estimate: particles shape is (6,), expected (N, 6) with N >= 1: one row (cx, cy, s, "
     "previous cx, cy, s) per particle"),
    (lambda: estimate(_PARTS, [1.0, 2.0]), ValueError,
     "estimate: weights shape is (2,), expected (3,): one weight per particle"),
    # was TypeError: object of type 'float' has no len()
    (lambda: wna_Q_xy(1.0), ValueError,
     "wna_Q_xy: q is 1, expected 2 values (x, y): one density per axis"),
    # was "bins value is 1.5, expected in [-1, n_bins)" (which 1.5 is)
    (lambda: BinnedImage(np.full((2, 2), 1.5), 110), ValueError,
     "BinnedImage: bins value is 1.5, expected an integer: bins must be an integer array of "
     "bin indices in [-1, n_bins)"),
]  # fmt: skip


@pytest.mark.parametrize(("call", "error", "message"), WRONG_KIND)
def test_a_wrong_type_is_a_type_error_and_every_message_one_line(call, error, message):
    with pytest.raises(error, match=f"^{re.escape(message)}$"):
        call()
    assert estimate(_PARTS, [1.0, 1.0, 1.0])[0].tolist() == [1.0, 1.0, 1.0]  # still taken
    assert wna_Q_xy([1.0, 0.5]).shape == (4, 4)
