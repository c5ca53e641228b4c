"""Type aliases shared across pftrack."""

from __future__ import annotations

from typing import Union

import numpy as np

RngLike = Union[np.random.Generator, int, None]
