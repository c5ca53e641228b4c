"""Minimum-cost assignment, compiled: SciPy's algorithm without importing SciPy.

`linear_sum_assignment` follows ``scipy.optimize.linear_sum_assignment`` step for step (Crouse's
shortest augmenting paths), so it returns the same pairs, ties included; the tracker uses it on
every frame, and `pftrack track` starts without paying SciPy's import (about 0.6 s).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack import _core

__all__ = ["linear_sum_assignment"]


def linear_sum_assignment(cost: ArrayLike) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Pair rows with columns of `cost` at the least total cost.

    Parameters
    ----------
    cost : (R, C) array_like of real numbers
        The cost of each pair; ``+inf`` forbids a pair. NaN and ``-inf`` are refused.

    Returns
    -------
    rows, cols : (min(R, C),) ndarray of intp
        The pairs, `rows` ascending, as SciPy returns them.

    Raises
    ------
    TypeError
        When `cost` is not real (complex, object, strings).
    ValueError
        When `cost` is not two-dimensional, holds NaN or ``-inf``, or allows no assignment at
        finite cost.
    """
    a = np.asarray(cost)
    if a.dtype.kind not in "biuf":
        raise TypeError(f"linear_sum_assignment: cost dtype is {a.dtype}, expected real numbers")
    if a.ndim != 2:
        raise ValueError(f"linear_sum_assignment: cost must be 2-D, got shape {a.shape}")
    rows, cols = _core.linear_sum_assignment(np.ascontiguousarray(a, dtype=np.float64))
    return rows.astype(np.intp), cols.astype(np.intp)
