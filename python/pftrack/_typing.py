"""Type aliases shared across pftrack: each is defined here once."""

from __future__ import annotations

import os
from typing import TypeAlias

import numpy as np
from numpy.typing import NDArray

RngLike: TypeAlias = np.random.Generator | int | None
"""What every function that draws accepts: a generator, a seed, or None (fresh entropy)."""

PathLike: TypeAlias = str | os.PathLike[str]
"""A file or folder path."""

F64: TypeAlias = NDArray[np.float64]
"""A float64 array (shapes are given in each docstring)."""

__all__ = ["F64", "PathLike", "RngLike"]
