"""An array a core entry updates in place, of another dtype or layout: one line naming it.

``propagate``, ``sis_step`` and ``mh_step`` write into `particles` (and `weights`, `means`),
never into a copy. Given a long double, a big-endian ``>f8``, a float32 or a read-only array,
they gave pybind11's "incompatible function arguments" with the whole signature (about 10
lines, the dtype unnamed). Now a wrong type or dtype is a TypeError naming the dtype and a
layout that cannot be written through a ValueError, in one line, as the public wrappers
(:func:`pftrack.particle_filter.propagate`) give them. Read-only inputs (`noise`, `ref`) are
cast, one copy, as ever.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from pftrack import _core
from pftrack.particle_filter import Ar2Model

MODEL = Ar2Model()
V3 = np.zeros(3)


def _good() -> dict[str, np.ndarray]:
    return {
        "particles": np.tile([50.0, 40.0, 1.0, 50.0, 40.0, 1.0], (8, 1)),
        "weights": np.full(8, 1 / 8),
        "means": np.tile([50.0, 40.0, 1.0], (2, 1)),
    }


def _call(entry: str, arrays: dict[str, Any]) -> None:
    if entry == "propagate":
        _core.propagate(arrays["particles"], np.ones((8, 3)), MODEL.a, MODEL.b, MODEL.sigma,
                        MODEL.s_min, MODEL.s_max, False, V3, V3)  # fmt: skip
        return
    frame = np.full((80, 100, 3), 90, np.uint8)
    image = _core.hsv_bins(frame, None)
    ref = _core.box_histograms(image, np.array([[50.0, 40.0, 12.0, 20.0]]))[0] + 1e-3
    args = (arrays["particles"], arrays["weights"], arrays["means"], image, ref, 12.0, 20.0,
            MODEL.a, MODEL.b, MODEL.sigma, MODEL.s_min, MODEL.s_max, False, 20.0, "uniform",
            True, 5, 0)  # fmt: skip
    getattr(_core, entry)(*args)


CASES = [(e, a) for e in ("propagate", "sis_step", "mh_step") for a in _good()
         if e != "propagate" or a == "particles"]  # fmt: skip


@pytest.mark.parametrize("entry", ["propagate", "sis_step", "mh_step"])
def test_the_good_arrays_are_updated_in_place(entry: str) -> None:
    arrays = _good()
    before = arrays["particles"].copy()
    _call(entry, arrays)
    assert not np.array_equal(arrays["particles"], before)


@pytest.mark.parametrize(("entry", "arg"), CASES)
@pytest.mark.parametrize("dtype", ["longdouble", ">f8", "float32", "int64"])
def test_another_dtype_is_a_one_line_type_error_naming_it(entry: str, arg: str, dtype: str) -> None:
    arrays = _good()
    arrays[arg] = arrays[arg].astype(dtype)
    with pytest.raises(TypeError) as exc:
        _call(entry, arrays)
    message = str(exc.value)
    assert message.startswith(
        f"{entry}: {arg} must be a C-contiguous, writeable float64 array (updated in place, "
        f"never copied), got dtype {np.dtype(dtype)}"
    ), message
    assert "\n" not in message and "incompatible function arguments" not in message
    if dtype == ">f8":
        assert "not this machine's byte order" in message


@pytest.mark.parametrize(("entry", "arg"), CASES)
@pytest.mark.parametrize("fault", ["list", "read-only", "not C-contiguous", "1 dimension more"])
def test_a_layout_it_cannot_write_through_is_one_line(entry: str, arg: str, fault: str) -> None:
    arrays = _good()
    a = arrays[arg]
    if fault == "list":
        arrays[arg] = a.tolist()
    elif fault == "read-only":
        a.flags.writeable = False
    elif fault == "not C-contiguous":
        arrays[arg] = np.repeat(a, 2, axis=-1)[..., ::2]
    else:
        arrays[arg] = a[None]
    kind = TypeError if fault == "list" else ValueError
    with pytest.raises(kind) as exc:
        _call(entry, arrays)
    message = str(exc.value)
    assert message.startswith(f"{entry}: {arg} must "), message
    assert "\n" not in message and "incompatible function arguments" not in message
    want = {
        "list": "got list",
        "read-only": "got a read-only one",
        "not C-contiguous": "got one not C-contiguous",
        "1 dimension more": "dimension",
    }
    assert want[fault] in message


def test_read_only_inputs_are_cast_as_before() -> None:
    """`noise` is read only: a long double or ``>f8`` is cast (one copy), the same result."""
    results = []
    for dtype in ("float64", "longdouble", ">f8"):
        p = _good()["particles"]
        noise = np.linspace(-1, 1, 24).reshape(8, 3).astype(dtype)
        _core.propagate(p, noise, MODEL.a, MODEL.b, MODEL.sigma, MODEL.s_min, MODEL.s_max,
                        False, V3, V3)  # fmt: skip
        results.append(p)
    np.testing.assert_array_equal(results[0], results[1])
    np.testing.assert_array_equal(results[0], results[2])
