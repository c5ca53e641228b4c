"""Python's ``%`` formatting of MOTChallenge lines: the reference of ``_core.mot_lines``, and
the NumPy search for the fewest decimals: the reference of ``_core.fewest_decimals``.

This is the code ``pftrack.io.mot._lines`` and ``_decimals`` ran before the C++ kernels, kept
to hold the kernels to it byte for byte.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pftrack.io.mot import _REPR, _printable

F64 = NDArray[np.float64]


_POW10 = np.array([float(f"1e{k}") for k in range(23)])  # exact doubles


def decimals(v: F64, limit: float, most: int) -> NDArray[np.int64]:
    """The fewest decimals ``d <= most`` that print each of `v` exactly, or -1 (in NumPy)."""
    x = v.ravel()
    d = np.full(x.size, -1, np.int64)
    idx: NDArray[np.intp] | None = None  # where x is in v; None: everywhere
    for k in range(most + 1):
        if k:
            n = x * _POW10[k]
            np.rint(n, out=n)
            small = np.abs(n) < limit
            n /= _POW10[k]
        else:  # the same, without multiplying and dividing by 1
            n = np.rint(x)
            small = np.abs(n) < limit
        ok = n == x
        ok &= small
        d[ok if idx is None else idx[ok]] = k
        small &= ~ok  # the rest: |n| only grows with k
        idx = np.flatnonzero(small) if idx is None else idx[small]
        if not idx.size:
            break
        x = x[small]
    return d


def _fmt(d: int) -> str:
    """The ``%`` format of a value with `d` decimals (``_REPR``: its shortest form)."""
    return "%r" if d == _REPR else f"%.{d}f"


def mot_lines(ids: F64, values: F64, decimals: NDArray[np.int64]) -> str:
    """Lines ``frame,id,v1,...,v8``: ``%d`` of ids (M, 2), ``%.{d}f`` or ``%r`` of values (M, 8)."""
    if not len(ids):
        return ""
    pattern = decimals @ (np.int64(1) << (5 * np.arange(8, dtype=np.int64)))  # 5 bits a column
    fmts = {
        int(k): ",".join(["%d", "%d"] + [_fmt(k >> 5 * j & 31) for j in range(8)]) + "\n"
        for k in np.unique(pattern).tolist()
    }
    flat = np.column_stack([ids, values]).ravel().tolist()
    # one % over all values: a third less time than one % per row
    return "".join([fmts[k] for k in pattern.tolist()]) % tuple(flat)


def lines(a: F64, exact: NDArray[np.bool_] | None = None) -> str:
    """``pftrack.io.mot._lines`` as it was: checked rows (M, 10) to text, in pure Python."""
    if not len(a):
        return ""
    values, dec = _printable(a, exact)
    return mot_lines(a[:, :2], values, dec)
