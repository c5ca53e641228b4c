"""The fuzz harness: arbitrary values, valid-looking values, and the one check every call passes.

A call passes when it returns finite numbers, or raises :class:`ValueError` or
:class:`TypeError` with a message. Anything else (a crash, ``MemoryError``, ``RuntimeError``,
``IndexError``, a warning, a NaN in the result) fails the test, and Hypothesis shrinks the
arguments to a small example.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

SPECIAL = [np.nan, np.inf, -np.inf, 1e308, -1e308, 5e-324, 0.0, -0.0]
DTYPES = [np.float64, np.float32, np.int32, np.int64, np.uint8, np.int16, np.bool_, np.complex128]
HUGE_INTS = [2**31, 2**62, 2**63 - 1, 2**64, -(2**62), -1]


@st.composite
def layout(draw: st.DrawFn, a: np.ndarray) -> np.ndarray:
    """The same values as C order, Fortran order, or a non-contiguous view."""
    kind = draw(st.sampled_from(["C", "F", "strided"]))
    if kind == "F":
        return np.asfortranarray(a)
    if kind == "strided" and a.ndim > 0:
        return np.stack([a, a], axis=-1)[..., 0]
    return a


@st.composite
def floats_array(
    draw: st.DrawFn, shape: tuple[int, ...], lo: float = -1e3, hi: float = 1e3
) -> np.ndarray:
    """A float64 array in [lo, hi], sometimes with one special value, in any memory layout."""
    a = draw(hnp.arrays(np.float64, shape, elements=st.floats(lo, hi, width=64)))
    if a.size and draw(st.integers(0, 9)) == 0:
        a.flat[draw(st.integers(0, a.size - 1))] = draw(st.sampled_from(SPECIAL))
    out: np.ndarray = draw(layout(a))
    return out


def any_array() -> st.SearchStrategy[np.ndarray]:
    """Any small array: any dtype, 0 to 3 dimensions, empty sides, NaN and inf included."""
    return hnp.arrays(
        st.sampled_from(DTYPES), hnp.array_shapes(min_dims=0, max_dims=3, min_side=0, max_side=6)
    ).flatmap(lambda a: layout(a))


def garbage() -> st.SearchStrategy[Any]:
    """A value of the wrong kind: None, text, huge or negative ints, special floats, arrays."""
    return st.one_of(
        st.none(),
        st.text(max_size=3),
        st.sampled_from(HUGE_INTS),
        st.sampled_from(SPECIAL),
        st.complex_numbers(max_magnitude=10),
        st.floats(-5, 5),
        any_array(),
    )


def maybe(valid: st.SearchStrategy[Any]) -> st.SearchStrategy[Any]:
    """Mostly `valid`, sometimes garbage (Hypothesis shrinks towards the valid branch)."""
    return st.one_of(valid, valid, valid, valid, garbage())


def _nonfinite(out: Any, path: str = "result") -> str | None:
    if isinstance(out, np.ndarray):
        if out.dtype.kind in "fc" and not np.all(np.isfinite(out)):
            return f"{path} has non-finite values"
        if out.dtype == object:
            for k, v in enumerate(out.ravel()):
                bad = _nonfinite(v, f"{path}[{k}]")
                if bad:
                    return bad
        return None
    if isinstance(out, float | np.floating | complex) and not np.isfinite(out):
        return f"{path} is {out}"
    if isinstance(out, dict):
        for k, v in out.items():
            bad = _nonfinite(v, f"{path}[{k!r}]")
            if bad:
                return bad
    if isinstance(out, list | tuple):
        for k, v in enumerate(out):
            bad = _nonfinite(v, f"{path}[{k}]")
            if bad:
                return bad
    return None


@dataclass(frozen=True)
class Target:
    """One function under fuzz: a strategy of calls and what its results may hold."""

    name: str
    calls: st.SearchStrategy[tuple[Callable[..., Any], tuple[Any, ...], dict[str, Any]]]
    finite: bool = True  # every float in the result must be finite


def check_call(fn: Callable[..., Any], args: tuple[Any, ...], kwargs: dict[str, Any],
               finite: bool = True) -> Any:  # fmt: skip
    """Call `fn`; pass on a finite result or a ValueError/TypeError with a message."""
    try:
        out = fn(*args, **kwargs)
    except (ValueError, TypeError) as exc:
        message = str(exc).strip()
        assert message, f"{type(exc).__name__} without a message"
        assert not message.startswith("std::"), f"C++ exception text leaked: {message}"
        return None
    if finite:
        bad = _nonfinite(out)
        assert bad is None, f"{getattr(fn, '__name__', fn)}: {bad} (silent)"
    return out


def call(fn: Callable[..., Any], *args: st.SearchStrategy[Any],
         **kwargs: st.SearchStrategy[Any]) -> st.SearchStrategy[Any]:  # fmt: skip
    """A strategy of ``(fn, args, kwargs)`` from strategies of each argument."""
    return st.tuples(st.just(fn), st.tuples(*args), st.fixed_dictionaries(kwargs))


def ints(lo: int, hi: int) -> st.SearchStrategy[int]:
    """Valid ints in [lo, hi]."""
    return st.integers(lo, hi)


def fl(lo: float, hi: float) -> st.SearchStrategy[float]:
    """Valid finite floats in [lo, hi]."""
    return st.floats(lo, hi, width=64)
