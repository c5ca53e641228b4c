"""Minimum-cost assignment, compiled: SciPy's algorithm without importing SciPy.

`linear_sum_assignment` follows ``scipy.optimize.linear_sum_assignment`` step for step (Crouse's
shortest augmenting paths), so it returns the same pairs, ties included; the tracker uses it on
every frame, and `pftrack track` starts without paying SciPy's import (about 0.6 s).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack import _core
from pftrack._check import flag

__all__ = ["linear_sum_assignment"]


def linear_sum_assignment(
    cost: ArrayLike, maximize: bool = False
) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Pair rows with columns of `cost` at the least total cost (the greatest with `maximize`).

    Parameters
    ----------
    cost : (R, C) array_like of real numbers
        The cost of each pair; ``+inf`` forbids a pair (``-inf`` with `maximize`). NaN and
        ``-inf`` (``+inf`` with `maximize`) are refused.
    maximize : bool
        Maximise the total instead, as SciPy's ``maximize=True``: the least total of
        ``-cost``, so the same pairs as SciPy, ties included.

    Returns
    -------
    rows, cols : (min(R, C),) ndarray of intp
        The pairs, `rows` ascending, as SciPy returns them.

    Raises
    ------
    TypeError
        When `cost` is not real (complex, object, strings), or `maximize` is not a bool.
    ValueError
        When `cost` is not two-dimensional, holds NaN or ``-inf`` (``+inf`` with `maximize`),
        or allows no assignment at finite cost.
    """
    fn = "linear_sum_assignment"
    if maximize is not False:  # the tracker's per-frame call pays nothing for the check
        maximize = flag(maximize, f"{fn}: maximize")
    a = np.asarray(cost)
    if a.dtype.kind not in "biuf":
        raise TypeError(f"{fn}: cost dtype is {a.dtype}, expected real numbers")
    if a.ndim != 2:
        raise ValueError(f"{fn}: cost must be 2-D, got shape {a.shape}")
    c = np.ascontiguousarray(a, dtype=np.float64)
    if maximize:
        if np.isposinf(c).any():  # -inf once negated: the core's message would name -inf
            raise ValueError(f"{fn}: cost has a +inf entry, which maximize cannot take")
        c = -c
    rows, cols = _core.linear_sum_assignment(c)
    return rows.astype(np.intp), cols.astype(np.intp)
