"""A mask that is not an array is a one-line TypeError naming it, at every core entry.

The core's mask arguments (and the morphology's structuring element) were declared
``py::array``: None or a list gave pybind11's list of signatures (4 to 52 lines). They are
checked as the frames are (tests/core/test_frame_kinds.py): ``blend: mask is NoneType,
expected a numpy.ndarray (H, W) uint8 or bool``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from pftrack import _core

_GOOD = np.random.default_rng(0).integers(0, 256, (24, 32, 3)).astype(np.uint8)
_MASK = np.zeros((24, 32), np.uint8)
_MASK[4:16, 8:14] = 255
_BOXES = np.array([[8.0, 4.0, 6.0, 12.0]])
_ELEMENT = np.ones((3, 3), np.uint8)
_LINES = np.array([[0.5, 2.0], [0.2, 1.0]])


def _model() -> _core.BackgroundModel:
    m = _core.BackgroundModel()
    m.apply(_GOOD)
    return m


def _binned() -> _core.BinnedImage:
    return _core.hsv_bins(_GOOD)


def _centres() -> np.ndarray:
    return np.array([[11.0, 10.0, 6.0, 12.0]])


#: entry -> a call of it with `mask` in the argument tested, and its message's start
ENTRIES: dict[str, tuple[Callable[[object], object], str]] = {
    "BackgroundModel.blend": (lambda m: _model().blend(_GOOD, m, 0.1),
                              "BackgroundModel.blend: mask"),
    "BackgroundModel.edge_support": (lambda m: _model().edge_support(_GOOD, m, _BOXES),
                                     "BackgroundModel.edge_support: mask"),
    "mask_bins": (lambda m: _core.mask_bins(_binned(), m), "mask_bins: mask"),
    "close_mask": (lambda m: _core.close_mask(m, _ELEMENT), "close_mask: mask"),
    "close_mask element": (lambda m: _core.close_mask(_MASK, m), "close_mask: element"),
    "open_mask": (lambda m: _core.open_mask(m, _ELEMENT), "open_mask: mask"),
    "open_mask element": (lambda m: _core.open_mask(_MASK, m), "open_mask: element"),
    "refine_boxes": (lambda m: _core.refine_boxes(_BOXES, m, 0.1, 0.5), "refine_boxes: mask"),
    "blob_boxes": (lambda m: _core.blob_boxes(m, 0.0, 1.0, 0.1, 10.0, 0.1, 0.4, None, 0.5,
                                              0.5, 0.1), "blob_boxes: mask"),
    "extend_legs": (lambda m: _core.extend_legs(m, _BOXES, _LINES, 0.0, 0.5),
                    "extend_legs: mask"),
    "RJMCMCTracker.step": (lambda m: _core.RJMCMCTracker(n_samples=5, burn_in=1).step(
        _binned(), m, _centres(), seed=0, step=0), "rjmcmc_step: mask"),
    "RJMCMCTracker.prepare": (lambda m: _core.RJMCMCTracker().prepare(_binned(), m, _centres()),
                              "prepare: mask"),
}  # fmt: skip

FAULTS = {"None": (None, "NoneType"), "list": (_MASK.tolist(), "list"), "int": (0, "int")}


@pytest.mark.parametrize("fault", list(FAULTS))
@pytest.mark.parametrize("entry", list(ENTRIES))
def test_a_mask_that_is_no_array_is_one_line_naming_it(entry: str, fault: str) -> None:
    call, name = ENTRIES[entry]
    mask, kind = FAULTS[fault]
    with pytest.raises(TypeError) as e:
        call(mask)
    message = str(e.value)
    assert "\n" not in message and "incompatible function arguments" not in message, message
    assert message.startswith(f"{name} is {kind}, expected a numpy.ndarray ("), message
    assert message.endswith(") uint8 or bool"), message


def test_the_good_mask_is_taken_by_every_entry() -> None:
    for entry, (call, _) in ENTRIES.items():
        good = _ELEMENT if entry.endswith("element") else _MASK
        call(good)


def test_a_wrong_dtype_is_still_the_dtype_error() -> None:
    with pytest.raises(TypeError, match="^mask_bins: mask dtype is float64, expected uint8"):
        _core.mask_bins(_binned(), _MASK.astype(np.float64))
