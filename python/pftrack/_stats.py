"""NumPy's median, percentile and unique values, the same numbers, without ``numpy.ma``.

``np.median``, ``np.percentile`` (``np.quantile``) and ``np.unique`` without its ``return_``
options import ``numpy.ma`` on their first call: NumPy asks ``np.ma.isMaskedArray`` of a
median's result and ``np.ma.is_masked`` of unique's input, and a percentile calls unique. That
import is 15-20 ms of CPU in every ``pftrack track`` run (the built-in detector's priming asks
for a median in its first second) for arrays that are never masked. The functions here take
NumPy's own steps (``np.partition`` at the same order statistics, ``np.mean`` of the middle
pair, NumPy's linear interpolation) and give the same floats; they are tested against NumPy's
on random, tied, integer, float32 and NaN input
(tests/test_stats.py).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["median", "median_along", "percentile", "unique_values"]


def _plain(values: ArrayLike, kinds: str = "biuf") -> NDArray[Any] | None:
    """`values` as a non-empty array of one of `kinds`; None for anything else.

    An ndarray subclass (a masked array: asked without touching ``np.ma``) is None too.
    """
    if isinstance(values, np.ndarray) and type(values) is not np.ndarray:
        return None
    a = np.asarray(values)
    return a if a.size and a.dtype.kind in kinds else None


def median(values: ArrayLike) -> float:
    """``float(np.median(values))``: the same float, ``numpy.ma`` left unimported.

    The middle value of an odd count, ``np.mean`` of the two middle ones of an even count, NaN
    when any value is NaN. Empty, complex or masked input goes to ``np.median`` itself (its
    warning and its NaN for an empty one).
    """
    a = _plain(values)
    if a is None:
        return float(np.median(np.asanyarray(values)))
    n = a.size
    half = n // 2
    kth = [half] if n % 2 else [half - 1, half]
    inexact = a.dtype.kind == "f"
    part = np.partition(a.ravel(), [*kth, n - 1] if inexact else kth)
    if inexact and math.isnan(part[n - 1]):  # NaN sorts last
        return math.nan
    return float(part[half]) if n % 2 else float(np.mean(part[half - 1 : half + 1]))


def median_along(values: ArrayLike, axis: int) -> NDArray[np.float64]:
    """``np.median(values, axis=axis)`` of a float64 array: the same floats, no ``numpy.ma``.

    ``np.partition`` along `axis` at the middle order statistics (and the last, for NaN),
    ``np.mean`` of the middle slice along `axis`, NaN where a lane holds a NaN.
    """
    a = _plain(values, "f")
    if a is None or a.dtype != np.float64:
        out: NDArray[np.float64] = np.median(np.asanyarray(values), axis=axis)
        return out
    n = a.shape[axis]
    half = n // 2
    kth = [half] if n % 2 else [half - 1, half]
    part = np.partition(a, [*kth, n - 1], axis=axis)
    middle = [slice(None)] * a.ndim
    middle[axis] = slice(half, half + 1) if n % 2 else slice(half - 1, half + 1)
    result: NDArray[np.float64] = np.mean(part[tuple(middle)], axis=axis)
    nan = np.isnan(np.take(part, n - 1, axis=axis))
    if nan.any():
        result[nan] = np.nan
    return result


def percentile(values: ArrayLike, q: float) -> float:
    """``float(np.percentile(values, q))`` (the linear method): the same float, no ``numpy.ma``.

    NumPy's partition (at the first and last values, ``floor((n - 1) q / 100)`` and the next
    one; the last one twice past it), interpolated as NumPy's ``_lerp`` does (from the upper
    one when the weight is at least 1/2); NaN when any value is NaN. Integers of up to 32 bits
    (exact as floats) and float64; anything else (float32, whose differences NumPy takes in
    float32; empty, boolean, complex, masked) goes to ``np.percentile``.
    """
    a = _plain(values, "iuf")
    exact = a is not None and (a.dtype == np.float64 or a.dtype.kind in "iu" and a.itemsize <= 4)
    if a is None or not exact or not 0 <= q <= 100:
        return float(np.percentile(np.asanyarray(values), q))
    n = a.size
    v = (n - 1) * (q / 100)
    top = v >= n - 1  # NumPy then takes the last value twice, its index -1 in the weight
    below = n - 1 if top else math.floor(v)
    above = n - 1 if top else below + 1
    part = np.partition(a.ravel(), sorted({0, n - 1, below, above}))  # NumPy's own partition
    if a.dtype.kind == "f" and math.isnan(part[n - 1]):  # NaN sorts last
        return math.nan
    lo, hi = float(part[below]), float(part[above])
    if not (math.isfinite(lo) and math.isfinite(hi)):  # NumPy's NaN and warnings for infinity
        return float(np.percentile(np.asanyarray(values), q))
    gamma = v + 1 if top else v - below
    diff = hi - lo
    return hi - diff * (1 - gamma) if gamma >= 0.5 else lo + diff * gamma


def unique_values(values: ArrayLike) -> NDArray[Any]:
    """``np.unique(values)``: the sorted distinct values of the flattened array, no ``numpy.ma``.

    Asked with ``return_inverse`` (whose path never asks about masks); the inverse is dropped.
    """
    out: NDArray[Any] = np.unique(np.asarray(values), return_inverse=True)[0]
    return out
