"""Resampling schemes, drop-in replacements for ``filterpy.monte_carlo``.

Each takes weights and returns the indices of the particles kept, like filterpy's functions of
the same names, plus an explicit `rng`. Unlike filterpy, weights need not sum to 1, and round-off
can never produce an index >= N (the CDF's last value is set to 1 and indices are clamped).

Given the same uniform draws, :func:`systematic_resample`, :func:`stratified_resample` and
:func:`multinomial_resample` return filterpy's indices, but for a multinomial draw of exactly
0.0 (``Generator.random()`` gives one in 2**53): filterpy's ``searchsorted`` then picks
particle 0 even when its weight is 0, these the first particle of weight > 0 (as they do the
residual draws of :func:`residual_resample`), and up to round-off: these divide the
running sum of the weights by their total, filterpy compares it as it is, so where the
weights' sum is not exactly 1 a draw within an ulp or two of a CDF step may pick the
neighbouring particle (``[0.1] * 10``: the multinomial draw ``np.nextafter(0.2, 1)`` is
particle 1 here, 2 in filterpy). :func:`residual_resample` differs on
purpose: filterpy 2.0.0 draws the remainder from ``weights - floor(N*weights)`` where Liu &
Chen's residuals are ``N*weights - floor(N*weights)`` (see its Notes), so only the
``floor(N*w_i)`` deterministic copies agree.

Randomness: filterpy draws from NumPy's global state (``np.random.seed``); these never do.
With ``rng=None`` each call draws fresh OS entropy, so ``np.random.seed`` does not make them
reproducible: pass `rng` (a seed or a Generator). A ``numpy.random.RandomState`` is taken
too (``numpy.random.default_rng`` wraps its bit generator, sharing its state): the same
draws as filterpy seeded alike, ``rng=np.random.RandomState(0)`` giving the indices of
``np.random.seed(0)`` then filterpy's function (residual resampling and round-off aside).
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack import _core
from pftrack._check import generator, rectangular, refuse_masked_weights
from pftrack._typing import RngLike

__all__ = [
    "multinomial_resample",
    "residual_resample",
    "stratified_resample",
    "systematic_resample",
]


#: Weights a resampler takes, at most one fewer: the indices are int32 (filterpy's ``"i"``).
MAX_WEIGHTS = 2**31 - 1


def _weights(weights: ArrayLike, fn: str) -> NDArray[np.float64]:
    """`weights` as a C-contiguous float64 array; errors start with `fn`, as the core's do."""
    if isinstance(weights, Iterator):  # NumPy makes a 0-d object array of it: "dtype object"
        raise TypeError(
            f"{fn}: weights must be an array or a sequence, got {type(weights).__name__} "
            "(an iterator: make it a list or an array first)"
        )
    refuse_masked_weights(weights, fn)
    w = rectangular(weights, f"{fn}: weights")
    if np.iscomplexobj(w):
        raise TypeError(f"{fn}: weights must be real, got dtype {w.dtype}")
    if w.dtype.kind not in "biuf":  # timedelta64 is a NumPy integer, not a number of ours
        raise TypeError(f"{fn}: weights must be numeric, got dtype {w.dtype}")
    if w.ndim != 1:
        raise ValueError(f"{fn}: weights must be 1-D (N,), got shape {w.shape}")
    if w.size >= MAX_WEIGHTS:  # before a copy of them (16 GB), and int32 indices overflow
        raise ValueError(f"{fn}: weights size is {w.size}, expected < 2^31 - 1")
    return np.ascontiguousarray(w, dtype=np.float64)


def systematic_resample(
    weights: ArrayLike, rng: RngLike | np.random.RandomState = None
) -> NDArray[np.int32]:
    """Indices of the particles kept by systematic resampling.

    One uniform offset ``u0`` places N evenly spaced positions ``(i + u0) / N`` on the CDF;
    particle i is copied ``floor(N w_i)`` or ``ceil(N w_i)`` times. The lowest-variance scheme
    and the default in pftrack.

    Parameters
    ----------
    weights : (N,) array_like of float
        Non-negative particle weights; need not sum to 1.
    rng : numpy.random.Generator, numpy.random.RandomState, int or None
        Source of the single uniform offset: ``default_rng(rng).random()`` (None: fresh OS
        entropy; pass a Generator when resampling often, it is cheaper than building one).

    Returns
    -------
    (N,) ndarray of int32
        Sorted indices into the particle array.

    Raises
    ------
    TypeError
        `weights` not real numbers (text, objects, complex numbers, an iterator) or a
        ``numpy.ma.MaskedArray`` with a masked value (pass ``weights.filled(0)``), or `rng`
        not a Generator, a RandomState, a seed or None (a bool, a float, a string).
    ValueError
        `weights` not 1-D (N,) with 1 <= N < 2**31 - 1, an entry negative or not finite, all
        entries 0, or a sum that overflows; a negative seed.

    Notes
    -----
    A seed or a Generator gives exactly ``default_rng(rng).random()`` as the offset, so results
    are reproducible; there is no module-level generator (``np.random.seed`` does not reach
    it: None is fresh OS entropy). A RandomState gives filterpy's offset for the same state.
    The kernel runs in O(N) without a data-dependent branch per particle and returns the same
    indices as ``numpy.searchsorted`` on the normalised cumulative sum (side="right", clamped
    to N-1), i.e. as filterpy.

    References
    ----------
    .. [1] Kitagawa, G. (1996). Monte Carlo filter and smoother for non-Gaussian nonlinear
       state space models. Journal of Computational and Graphical Statistics 5(1), 1-25.

    Examples
    --------
    >>> import numpy as np
    >>> from pftrack import systematic_resample
    >>> systematic_resample([0.1, 0.2, 0.3, 0.4], rng=0)
    array([1, 2, 3, 3], dtype=int32)
    >>> particles = np.array([10.0, 20.0, 30.0, 40.0])
    >>> particles[systematic_resample([1, 2, 3, 4], rng=0)]  # weights need not sum to 1
    array([20., 30., 40., 40.])
    """
    w = _weights(weights, "systematic_resample")
    return _core.systematic_resample(w, generator(rng, "systematic_resample: rng").random())


def stratified_resample(
    weights: ArrayLike, rng: RngLike | np.random.RandomState = None
) -> NDArray[np.int32]:
    """Indices kept by stratified resampling: one uniform draw in each of N equal strata.

    Parameters
    ----------
    weights : (N,) array_like of float
        Non-negative particle weights; need not sum to 1.
    rng : numpy.random.Generator, numpy.random.RandomState, int or None
        Source of the N uniform draws.

    Returns
    -------
    (N,) ndarray of int32
        Sorted indices into the particle array.

    Raises
    ------
    TypeError
        `weights` not real numbers (text, objects, complex numbers, an iterator) or a
        ``numpy.ma.MaskedArray`` with a masked value (pass ``weights.filled(0)``), or `rng`
        not a Generator, a RandomState, a seed or None (a bool, a float, a string).
    ValueError
        `weights` not 1-D (N,) with 1 <= N < 2**31 - 1, an entry negative or not finite, all
        entries 0, or a sum that overflows; a negative seed.

    References
    ----------
    .. [1] Douc, R., Cappé, O. & Moulines, E. (2005). Comparison of resampling schemes for
       particle filtering. ISPA 2005, 64-69.

    Examples
    --------
    >>> from pftrack import stratified_resample
    >>> stratified_resample([0.1, 0.2, 0.3, 0.4], rng=0)
    array([1, 2, 2, 3], dtype=int32)
    """
    w = _weights(weights, "stratified_resample")
    return _core.stratified_resample(w, generator(rng, "stratified_resample: rng").random(len(w)))


def multinomial_resample(
    weights: ArrayLike, rng: RngLike | np.random.RandomState = None
) -> NDArray[np.int64]:
    """Indices kept by multinomial resampling: N independent draws from the weights.

    The indices come in the order of the draws (as in filterpy), not sorted.

    Parameters
    ----------
    weights : (N,) array_like of float
        Non-negative particle weights; need not sum to 1.
    rng : numpy.random.Generator, numpy.random.RandomState, int or None
        Source of the N uniform draws.

    Returns
    -------
    (N,) ndarray of int64
        As filterpy's (``np.searchsorted``); the other three schemes give int32, as theirs do.

    Raises
    ------
    TypeError
        `weights` not real numbers (text, objects, complex numbers, an iterator) or a
        ``numpy.ma.MaskedArray`` with a masked value (pass ``weights.filled(0)``), or `rng`
        not a Generator, a RandomState, a seed or None (a bool, a float, a string).
    ValueError
        `weights` not 1-D (N,) with 1 <= N < 2**31 - 1, an entry negative or not finite, all
        entries 0, or a sum that overflows; a negative seed.

    References
    ----------
    .. [1] Gordon, N., Salmond, D. & Smith, A. (1993). Novel approach to nonlinear/non-Gaussian
       Bayesian state estimation. IEE Proceedings F 140(2), 107-113.

    Examples
    --------
    >>> from pftrack import multinomial_resample
    >>> idx = multinomial_resample([0.1, 0.2, 0.3, 0.4], rng=0)
    >>> idx, idx.dtype
    (array([3, 1, 0, 0]), dtype('int64'))
    """
    w = _weights(weights, "multinomial_resample")
    u = generator(rng, "multinomial_resample: rng").random(len(w))
    return _core.multinomial_resample(w, u).astype(np.int64)  # filterpy's dtype


def residual_resample(
    weights: ArrayLike, rng: RngLike | np.random.RandomState = None
) -> NDArray[np.int32]:
    """Indices kept by residual resampling.

    ``floor(N w_i)`` copies of each particle, then the remaining ``R`` drawn multinomially from
    the residuals ``N w_i - floor(N w_i)``. ``N w_i`` within the round-off of normalising the
    weights (about ``N`` ulps) below an integer counts as that integer: equal weights keep every
    particle once, as they do in exact arithmetic.

    Parameters
    ----------
    weights : (N,) array_like of float
        Non-negative particle weights; need not sum to 1.
    rng : numpy.random.Generator, numpy.random.RandomState, int or None
        Source of the uniform draws for the residual part.

    Returns
    -------
    (N,) ndarray of int32
        Indices into the particle array: the deterministic copies in particle order, then the
        remainder in the order of the draws.

    Raises
    ------
    TypeError
        `weights` not real numbers (text, objects, complex numbers, an iterator) or a
        ``numpy.ma.MaskedArray`` with a masked value (pass ``weights.filled(0)``), or `rng`
        not a Generator, a RandomState, a seed or None (a bool, a float, a string).
    ValueError
        `weights` not 1-D (N,) with 1 <= N < 2**31 - 1, an entry negative or not finite, all
        entries 0, or a sum that overflows; a negative seed.

    Notes
    -----
    Not filterpy's indices for the same draws, on purpose. filterpy 2.0.0's
    ``residual_resample`` takes the residuals as ``weights - num_copies`` instead of
    ``N*weights - num_copies``: with weights summing to 1 they are negative for every particle
    copied at least once, so its cumulative sum is not monotone and the remainder lands on the
    wrong particles. Its expected copies are not ``N w_i`` (a particle with ``N w_i = 0.9998``
    was never drawn over 2000 runs), while these are (``tests/particle_filter/test_resample.py``,
    ``test_expected_copies``); the ``floor(N w_i)`` deterministic copies, which come first,
    are the same in both.

    References
    ----------
    .. [1] Liu, J. S. & Chen, R. (1998). Sequential Monte Carlo methods for dynamic systems.
       JASA 93(443), 1032-1044.

    Examples
    --------
    >>> from pftrack import residual_resample
    >>> residual_resample([0.1, 0.2, 0.3, 0.4], rng=0)  # N w = 0.4, 0.8, 1.2, 1.6
    array([2, 3, 2, 1], dtype=int32)
    """
    w = _weights(weights, "residual_resample")
    return _core.residual_resample(w, generator(rng, "residual_resample: rng").random(len(w)))
