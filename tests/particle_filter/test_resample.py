"""Resamplers: NumPy reference, filterpy semantics, statistics, round-off edge cases."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from pftrack import _core
from pftrack.particle_filter import (
    multinomial_resample,
    residual_resample,
    stratified_resample,
    systematic_resample,
)
from tests.reference import kernels as ref

RESAMPLERS = {
    "systematic": systematic_resample,
    "stratified": stratified_resample,
    "multinomial": multinomial_resample,
    "residual": residual_resample,
}

weights_st = hnp.arrays(
    np.float64, st.integers(1, 200), elements=st.floats(0, 1e3, allow_subnormal=False)
).filter(lambda w: w.sum() > 0)


@settings(max_examples=100, deadline=None)
@given(weights_st, st.floats(0, 1, exclude_max=True))
def test_systematic_matches_reference(w, u0):
    np.testing.assert_array_equal(_core.systematic_resample(w, u0), ref.systematic_resample(w, u0))


@settings(max_examples=100, deadline=None)
@given(weights_st, st.integers(0, 2**32 - 1))
def test_draw_based_resamplers_match_reference(w, seed):
    u = np.random.default_rng(seed).random(len(w))
    np.testing.assert_array_equal(_core.stratified_resample(w, u), ref.stratified_resample(w, u))
    np.testing.assert_array_equal(_core.multinomial_resample(w, u), ref.multinomial_resample(w, u))
    np.testing.assert_array_equal(_core.residual_resample(w, u), ref.residual_resample(w, u))


@pytest.mark.parametrize("name", RESAMPLERS)
def test_invariants(name):
    fn = RESAMPLERS[name]
    n = 50
    idx = fn(np.ones(n), rng=1)
    # filterpy's dtypes: np.searchsorted's int64 for multinomial, np.zeros(N, "i") for the rest
    assert idx.dtype == (np.int64 if name == "multinomial" else np.int32) and idx.shape == (n,)
    if name in ("systematic", "stratified", "residual"):
        np.testing.assert_array_equal(np.sort(idx), np.arange(n))  # equal weights keep everyone
    w = np.zeros(n)
    w[17] = 3.0
    np.testing.assert_array_equal(fn(w, rng=2), np.full(n, 17))  # all weight on k -> all k


@pytest.mark.parametrize(
    ("name", "w", "u"),
    [
        ("multinomial", [0.0, 0.0, 1.0, 3.0], [0.0, 0.1, 0.5, 0.9]),
        # N w = 0, 1, 1.5, 1.5: three copies, then one draw from the residuals 0, 0, .5, .5
        ("residual", [0.0, 1.0, 1.5, 1.5], [0.0, 0.0, 0.0, 0.0]),
    ],
)
def test_a_draw_of_zero_never_picks_a_particle_of_weight_zero(name, w, u):
    """Regression: a uniform draw of exactly 0.0 (``Generator.random()`` returns it once in
    2**53 draws) picked particle 0 whatever its weight: ``searchsorted(cdf, 0)``, filterpy's
    search, is the first cdf value >= 0, cdf[0] even when it is 0. It now takes the first
    particle of weight > 0 (residual: of residual > 0); every other draw is filterpy's."""
    w, u = np.array(w), np.array(u)
    idx = getattr(_core, f"{name}_resample")(w, u)
    assert (w[idx] > 0).all(), idx
    if name == "residual":
        np.testing.assert_array_equal(idx, [1, 2, 3, 2])
    else:
        np.testing.assert_array_equal(idx, [2, 2, 3, 3])
    np.testing.assert_array_equal(idx, getattr(ref, f"{name}_resample")(w, u))


@pytest.mark.parametrize("name", RESAMPLERS)
def test_round_off_never_indexes_past_the_end(name):
    n = 1000
    w = np.full(n, (1 - 1e-16) / n)
    w[-1] = 0.0  # the last particle can never be chosen...
    u = np.full(n, np.nextafter(1.0, 0.0))  # ...even with draws right at the top
    core = {"systematic": lambda: _core.systematic_resample(w, u[0]),
            "stratified": lambda: _core.stratified_resample(w, u),
            "multinomial": lambda: _core.multinomial_resample(w, u),
            "residual": lambda: _core.residual_resample(w, u)}[name]()  # fmt: skip
    assert core.max() < n
    assert core.min() >= 0


@pytest.mark.parametrize("name", RESAMPLERS)
def test_expected_copies(name):
    """E[copies of i] = N w_i; averaged over many runs it lands within a few standard errors."""
    rng = np.random.default_rng(7)
    n = 40
    w = rng.random(n) ** 3
    w /= w.sum()
    runs = 2000
    counts = np.zeros(n)
    for _ in range(runs):
        counts += np.bincount(RESAMPLERS[name](w, rng=rng), minlength=n)
    mean = counts / runs
    # multinomial has the largest variance: N w (1 - w) per run
    se = np.sqrt(n * w * (1 - w) / runs) + 1e-9
    assert np.all(np.abs(mean - n * w) < 5 * se + 1e-12)


@pytest.mark.parametrize("n", [9, 11, 49, 100, 1000, 4097])
def test_residual_keeps_every_particle_of_equal_weights(n):
    # 1/N summed N times is 1 + a few ulps (or N * (1/N) < 1): N w_i falls just below 1, and a
    # plain floor() would give no deterministic copy at all, drawing all N at random
    for w in (np.full(n, 1.0 / n), np.full(n, 0.1)):
        np.testing.assert_array_equal(residual_resample(w, rng=0), np.arange(n))
    w = np.tile([2.0 / n, 0.0], n // 2)  # two copies each of every other particle
    if n % 2 == 0:
        np.testing.assert_array_equal(residual_resample(w, rng=0), np.repeat(np.arange(0, n, 2), 2))


@pytest.mark.parametrize("name", ["systematic", "residual"])
def test_low_variance_schemes_copy_floor_or_ceil(name):
    rng = np.random.default_rng(3)
    w = rng.random(64)
    w /= w.sum()
    for _ in range(50):
        c = np.bincount(RESAMPLERS[name](w, rng=rng), minlength=64)
        assert np.all(c >= np.floor(64 * w))
        if name == "systematic":
            assert np.all(c <= np.ceil(64 * w))


def _filterpy_draws(mc, name: str, w: np.ndarray, seed: int) -> np.ndarray:
    """filterpy's `name` resampling of `w` after ``np.random.seed(seed)``; the global state is
    restored afterwards."""
    state = np.random.get_state()
    try:
        np.random.seed(seed)
        out: np.ndarray = getattr(mc, f"{name}_resample")(w)
        return out
    finally:
        np.random.set_state(state)


@pytest.mark.parametrize("name", RESAMPLERS)
def test_drop_in_for_filterpy(name):
    """Same semantics as filterpy.monte_carlo: given the same uniform draws, the same indices."""
    mc = pytest.importorskip("filterpy.monte_carlo")
    w = np.random.default_rng(11).random(300)
    w /= w.sum()
    theirs = _filterpy_draws(mc, name, w, 5)
    state = np.random.get_state()
    try:
        np.random.seed(5)
        if name == "systematic":
            mine = _core.systematic_resample(w, np.random.random())
        elif name == "residual":
            k = int(np.floor(len(w) * w).sum())
            mine = _core.residual_resample(
                w, np.concatenate([np.random.random(len(w) - k), np.zeros(k)])
            )
        else:
            mine = getattr(_core, f"{name}_resample")(w, np.random.random(len(w)))
    finally:
        np.random.set_state(state)
    if name == "residual":
        # filterpy draws the remainder from `weights - num_copies` instead of the residuals
        # `N*weights - num_copies` (Liu & Chen's definition, which we follow): only the
        # deterministic floor(N w) copies can agree.
        k = int(np.floor(len(w) * w).sum())
        np.testing.assert_array_equal(mine[:k], theirs[:k])
        return
    np.testing.assert_array_equal(mine, theirs)


@pytest.mark.parametrize("name", ["systematic", "stratified", "multinomial"])
def test_a_random_state_gives_filterpys_draws(name):
    """What docs/api.md promises: ``rng=np.random.RandomState(s)`` is filterpy after
    ``np.random.seed(s)``, through the public functions (residual resampling differs)."""
    mc = pytest.importorskip("filterpy.monte_carlo")
    w = np.random.default_rng(12).random(200)
    w /= w.sum()
    theirs = _filterpy_draws(mc, name, w, 8)
    mine = RESAMPLERS[name](w, rng=np.random.RandomState(8))
    np.testing.assert_array_equal(mine, theirs)
    assert mine.dtype == theirs.dtype  # a user trial: multinomial's was int32, filterpy's int64


def test_seeded_results_are_reproducible():
    w = np.random.default_rng(0).random(500)
    for fn in RESAMPLERS.values():
        np.testing.assert_array_equal(fn(w, rng=42), fn(w, rng=42))
        np.testing.assert_array_equal(fn(w, rng=np.random.default_rng(9)), fn(w, rng=9))


@pytest.mark.parametrize(
    ("n", "kind", "u0"),
    [
        (10_000, "random", 0.37),  # quarters on estimated sums
        (60_000, "random", 0.9),  # still quarters, widest margin
        (100_000, "random", 0.37),  # exact-total pass (N too large for the estimated margin)
        (1001, "zero runs", 0.6),  # quarters whose stores meet at one position
        (10_000, "equal", 0.0),  # every threshold on an integer: settled exactly, list overflows
        (10_000, "equal", 0.5),
        (4096, "dyadic", 0.25),  # integer weights: thresholds land on integers
        (5000, "sparse", np.nextafter(1.0, 0.0)),
    ],
)
def test_systematic_matches_reference_at_scale(n, kind, u0):
    rng = np.random.default_rng(n)
    w = {
        "random": lambda: rng.random(n),
        "equal": lambda: np.ones(n),
        "dyadic": lambda: rng.integers(0, 4, n).astype(float),
        "sparse": lambda: rng.random(n) * (rng.random(n) < 0.1),
        "zero runs": lambda: np.r_[rng.random(300), np.zeros(400), rng.random(1), np.zeros(300)],
    }[kind]()
    np.testing.assert_array_equal(_core.systematic_resample(w, u0), ref.systematic_resample(w, u0))


@pytest.mark.parametrize("name", RESAMPLERS)
def test_rng_is_default_rng_and_there_is_no_global_state(name):
    """A Generator is used as given (its stream advances), a seed is default_rng(seed), and
    None draws fresh entropy: no module-level generator to share or to fork."""
    from pftrack.particle_filter import resample as rs

    fn = RESAMPLERS[name]
    w = np.random.default_rng(8).random(400)
    g, h = np.random.default_rng(3), np.random.default_rng(3)
    first = fn(w, rng=g)
    np.testing.assert_array_equal(first, fn(w, rng=h))
    np.testing.assert_array_equal(fn(w, rng=g), fn(w, rng=h))  # both streams moved on alike
    assert g.random() == h.random()
    np.testing.assert_array_equal(fn(w, rng=5), fn(w, rng=np.random.default_rng(5)))
    unseeded = fn(w)
    assert unseeded.shape == (400,) and unseeded.min() >= 0 and unseeded.max() < 400
    assert not any(isinstance(v, np.random.Generator) for v in vars(rs).values())


@pytest.mark.parametrize("kind", ["random", "equal", "dyadic", "zero runs"])
@pytest.mark.parametrize("u_kind", ["random", "zero", "top", "eighths"])
def test_stratified_matches_reference_at_scale(kind, u_kind):
    rng = np.random.default_rng(17)
    n = 3000
    w = {
        "random": lambda: rng.random(n),
        "equal": lambda: np.ones(n),
        "dyadic": lambda: rng.integers(0, 4, n).astype(float),
        "zero runs": lambda: np.r_[rng.random(1000), np.zeros(1000), rng.random(1000)],
    }[kind]()
    u = {
        "random": lambda: rng.random(n),
        "zero": lambda: np.zeros(n),
        "top": lambda: np.full(n, np.nextafter(1.0, 0.0)),
        "eighths": lambda: rng.integers(0, 8, n) / 8,
    }[u_kind]()
    np.testing.assert_array_equal(_core.stratified_resample(w, u), ref.stratified_resample(w, u))


@pytest.mark.parametrize("fn", list(RESAMPLERS.values()))
@pytest.mark.parametrize("flag", [True, False, np.True_])
def test_rng_refuses_a_bool(fn, flag):
    # True was taken as the seed 1: other settings refuse a bool for a number
    match = (
        f"{fn.__name__}: rng must be a numpy.random.Generator (or RandomState), an int >= 0 or "
        f"None, got {type(flag).__name__} {flag!r}"
    )
    with pytest.raises(TypeError, match=match.replace("(", r"\(").replace(")", r"\)")):
        fn([0.5, 0.5], flag)


def test_other_rngs_refuse_a_bool_too():
    from pftrack.particle_filter import ColourParticleFilter, RJMCMCFilter

    with pytest.raises(TypeError, match="rng must be .*, got bool True"):
        ColourParticleFilter([20.0, 20, 10, 10], np.ones(110), rng=True)
    with pytest.raises(TypeError, match="RJMCMCFilter: rng must be .*, got bool False"):
        RJMCMCFilter(rng=False)


def test_filterpy_agrees_up_to_round_off(monkeypatch):
    """What docs/api.md qualifies: the same draws give filterpy's indices up to round-off.

    filterpy's multinomial searches the running sum as it is (``[0.1] * 10``'s ends at
    1 - 1.1e-16; its last value is set to 1), pftrack divides it by the total, so a draw one
    ulp above a step picks the particle before it. Where the running sum is exact
    (``[0.125] * 8``) every draw agrees. A user trial found one index of 10^7 apart where the
    docs promised none.
    """
    pytest.importorskip("filterpy.monte_carlo")
    from filterpy.monte_carlo import resampling  # noqa: PLC0415 (after the skip)

    for w, apart in ((np.full(10, 0.1), True), (np.full(8, 0.125), False)):
        u = np.append(np.nextafter(np.cumsum(w)[:-1], 1.0), 0.5)  # just above each step
        monkeypatch.setattr(resampling, "random", lambda n, u=u: u[:n])
        theirs = resampling.multinomial_resample(w)
        mine = _core.multinomial_resample(w, u)
        assert mine[-1] == theirs[-1]  # the draw 0.5, far from any step
        if apart:
            np.testing.assert_array_equal(mine[:-1], np.arange(len(w) - 1))
            np.testing.assert_array_equal(theirs[:-1], np.arange(1, len(w)))
        else:
            np.testing.assert_array_equal(mine, theirs)


def test_too_many_weights_refused_before_any_copy():
    """A user trial: ``systematic_resample(np.broadcast_to(1.0, (2**31,)))`` copied 16 GB
    before the core refused the size, and the multinomial and residual kernels had no size
    check (their int32 indices would wrap). Refused first now, under a 2 GB address space."""
    code = textwrap.dedent(
        """
        import resource, numpy as np
        from pftrack import particle_filter as pf
        w = np.broadcast_to(np.float32(1.0), (2**31,))  # no memory: one value, stride 0
        resource.setrlimit(resource.RLIMIT_AS, (2 * 2**30, 2 * 2**30))
        for name in ("systematic", "stratified", "multinomial", "residual"):
            try:
                getattr(pf, name + "_resample")(w, rng=0)
            except ValueError as e:
                print(e)
        """
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    lines = out.stdout.splitlines()
    assert len(lines) == 4, out.stderr[-500:]
    for name, line in zip(
        ("systematic", "stratified", "multinomial", "residual"), lines, strict=True
    ):
        assert line == f"{name}_resample: weights size is 2147483648, expected < 2^31 - 1"
