"""Input checks shared by the public entry points."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from pftrack._typing import F64

__all__ = ["real_array"]


def real_array(values: ArrayLike, what: str) -> F64:
    """`values` as a float64 array, refusing what is not real numbers.

    NumPy would cast complex numbers to their real part with only a warning, and fail on text
    with a message that does not say which argument was wrong.

    Parameters
    ----------
    values : array_like
        Booleans, integers or floats.
    what : str
        How the error names the argument (``"detections"``, ...).

    Raises
    ------
    TypeError
        Complex numbers, text, or objects that are not numbers.
    """
    raw = np.asarray(values)
    if raw.dtype.kind not in "biuf":
        raise TypeError(f"{what} must hold real numbers, got dtype {raw.dtype}")
    return raw.astype(np.float64, copy=False)
