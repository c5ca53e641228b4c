"""One kind of error for one fault in every entry that takes a frame, the core's too.

Developer trial, 6 December: the core's frame check raised ValueError for a float32 or uint16
frame where the Python layer raises TypeError for the same fault, and a list or None given to
a core entry gave pybind11's list of signatures. Now a wrong type or dtype is a TypeError and a
wrong shape or an empty frame a ValueError, in one line naming the function and the argument,
at every public entry and at the core's (``hsv_bins``, ``median_frames``,
``BackgroundModel.apply``, ``blend``, ``global_gain``, ``edge_support``).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

import pftrack
from pftrack import _core, detection
from pftrack.particle_filter import hsv_bins

_GOOD = np.random.default_rng(0).integers(0, 256, (24, 32, 3)).astype(np.uint8)  # not blank
_MASK = np.zeros((24, 32), np.uint8)
_BOXES = np.array([[4.0, 4.0, 10.0, 12.0]])


def _model() -> _core.BackgroundModel:
    m = _core.BackgroundModel()
    m.apply(_GOOD)
    return m


#: entry -> a call of it with `frame`, and the name its message starts with
ENTRIES: dict[str, tuple[Callable[[object], object], str]] = {
    "_core.hsv_bins": (lambda f: _core.hsv_bins(f), "hsv_bins: frame"),
    "_core.median_frames": (lambda f: _core.median_frames([_GOOD, f]),
                            "median_frames: frames[1]"),
    "_core.BackgroundModel.apply": (lambda f: _core.BackgroundModel().apply(f),
                                    "BackgroundModel.apply: frame"),
    "_core.BackgroundModel.blend": (lambda f: _model().blend(f, _MASK, 0.1),
                                    "BackgroundModel.blend: frame"),
    "_core.BackgroundModel.global_gain": (lambda f: _model().global_gain(f),
                                          "BackgroundModel.global_gain: frame"),
    "_core.BackgroundModel.mean_and_gain": (lambda f: _model().mean_and_gain(f),
                                            "BackgroundModel.mean_and_gain: frame"),
    "_core.BackgroundModel.edge_support": (lambda f: _model().edge_support(f, _MASK, _BOXES),
                                           "BackgroundModel.edge_support: frame"),
    "hsv_bins": (lambda f: hsv_bins(f), "hsv_bins: frame"),
    "PaperDetector.detect": (lambda f: detection.PaperDetector().detect(f),
                             "PaperDetector.detect: frame"),
    "Mog2Detector.detect": (lambda f: detection.Mog2Detector().detect(f),
                            "Mog2Detector.detect: frame"),
    "Tracker.update": (lambda f: pftrack.Tracker().update(np.zeros((0, 6)), f), "frame"),
    "MultiObjectTracker.update": (lambda f: pftrack.MultiObjectTracker(rng=0).update(f),
                                  "frame"),
}  # fmt: skip

#: a fault -> the frame that has it, and the error it must raise
FAULTS = {
    "float32": (_GOOD.astype(np.float32), TypeError, "dtype is float32, expected uint8"),
    "uint16": (_GOOD.astype(np.uint16) * 257, TypeError,
               "dtype is uint16, expected uint8 (BGR, as cv2 reads it); a 16-bit frame? "
               "(frame >> 8).astype(np.uint8) keeps its top 8 bits"),
    "big-endian uint16": (_GOOD.astype(">u2"), TypeError, "dtype is >u2, expected uint8"),
    "list": (_GOOD.tolist(), TypeError, None),
    "None": (None, TypeError, None),
    "grey": (_GOOD[..., 0].copy(), ValueError, None),
    "BGRA": (np.dstack([_GOOD, _GOOD[..., :1]]), ValueError, None),
}  # fmt: skip


@pytest.mark.parametrize("fault", list(FAULTS))
@pytest.mark.parametrize("entry", list(ENTRIES))
def test_one_fault_one_kind_of_error_at_every_entry(entry: str, fault: str) -> None:
    call, name = ENTRIES[entry]
    frame, kind, words = FAULTS[fault]
    with pytest.raises((TypeError, ValueError)) as e:
        call(frame)
    message = str(e.value)
    assert type(e.value) is kind, f"{entry}: {type(e.value).__name__}: {message}"
    assert "\n" not in message and "incompatible function arguments" not in message, message
    assert name in message, message
    if words is not None:
        assert words in message, message


def test_the_good_frame_is_taken_by_every_entry() -> None:
    for call, _ in ENTRIES.values():
        call(_GOOD)
