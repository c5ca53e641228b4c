"""Python's ``%`` formatting of MOTChallenge lines: the reference of ``_core.mot_lines``.

This is the code ``pftrack.io.mot._lines`` ran before the C++ kernel, kept to hold the kernel
to it byte for byte.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pftrack.io.mot import _REPR, _printable

F64 = NDArray[np.float64]


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
