"""The joint sampler's settings a TrackerConfig replaces with its filter's are refused, not dropped.

``joint_config`` gives the RJ-MCMC chain the per-object filters' sample count and AR(2) dynamics,
so that only the sampler differs between sis, mh and rjmcmc. Until 5 December 2026 an
``RJMCMCConfig(n_samples=500)`` (or `a`, `b`, `sigma`, `s_min`, `s_max`) given to TrackerConfig
was replaced without a word: the chain ran 100 samples (user trial of the samplers).
"""

from __future__ import annotations

import pytest

from pftrack.particle_filter import RJMCMCConfig
from pftrack.tracking import TrackerConfig
from pftrack.tracking.joint import joint_config

REPLACED = [
    ("n_samples", 500, "filter.n_particles"),
    ("a", (1.5, 1.5, 2.0), "filter.model"),
    ("b", (-0.5, -0.5, -1.0), "filter.model"),
    ("sigma", (1.0, 1.0, 0.01), "filter.model"),
    ("s_min", 0.9, r"filter.model.s_min"),
    ("s_max", 3.0, r"filter.model.s_max"),
]


@pytest.mark.parametrize(("name", "value", "where"), REPLACED)
@pytest.mark.parametrize("sampler", ["sis", "mh", "rjmcmc"])
def test_a_replaced_setting_is_refused(sampler, name, value, where):
    rj = RJMCMCConfig(**{name: value})
    expected = rf"^TrackerConfig: rjmcmc\.{name} is .*takes it from {where}"
    with pytest.raises(ValueError, match=expected):
        TrackerConfig(sampler=sampler, rjmcmc=rj)


def test_the_settings_the_chain_keeps_are_taken():
    """burn_in, move probabilities, lam, the birth and coverage terms reach the chain."""
    rj = RJMCMCConfig(burn_in=10, p_birth=0.2, p_death=0.2, p_update=0.5, p_swap=0.1, lam=5.0,
                      coverage=10.0, birth_gate=0.2, min_existence=0.4)  # fmt: skip
    joint = joint_config(TrackerConfig(sampler="rjmcmc", rjmcmc=rj))
    for name in ("burn_in", "p_birth", "p_death", "p_update", "p_swap", "lam", "coverage",
                 "birth_gate", "min_existence"):  # fmt: skip
        assert getattr(joint, name) == getattr(rj, name)
    assert joint.n_samples == TrackerConfig().filter.n_particles  # the filter's budget


def test_the_default_and_its_pixel_scaling_are_taken():
    cfg = TrackerConfig(sampler="rjmcmc")
    assert cfg.scaled_pixels(2.0).rjmcmc == RJMCMCConfig()  # replace() runs the check again
