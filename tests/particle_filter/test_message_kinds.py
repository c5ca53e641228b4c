"""One kind of error for one fault, each message naming its function (developer trial, 5 December).

Were: ``hsv_bins``' frame and mask messages named no function; a uint16 frame was refused
without saying how to make it uint8; ``_core.mask_bins`` raised ValueError for an int64 mask
where ``hsv_bins`` raises TypeError; ``step_filters`` raised ValueError for float32 particles
where ``ColourParticleFilter.step`` raises TypeError.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from pftrack import _core
from pftrack.particle_filter import (
    ColourParticleFilter,
    hsv_bins,
    multinomial_resample,
    propagate,
    residual_resample,
    stratified_resample,
    systematic_resample,
)
from pftrack.particle_filter.filter import reinitialise_filters, step_filters

_FRAME = np.random.default_rng(0).integers(0, 256, (60, 80, 3)).astype(np.uint8)
_IM = hsv_bins(_FRAME)


def _filter() -> ColourParticleFilter:
    return ColourParticleFilter([40, 30, 10, 20], np.ones(110), rng=0)


def _float32(name: str) -> ColourParticleFilter:
    f = _filter()
    setattr(f, name, getattr(f, name).astype(np.float32))
    return f


def _big_endian(name: str) -> ColourParticleFilter:
    f = _filter()
    setattr(f, name, getattr(f, name).astype(">f8"))
    return f


# a byte-swapped array is refused, as it must be (the core writes in place); was only "got
# dtype >f8", not what is wrong with it nor that the copy which mends it must be kept
SWAPPED = (
    ": big-endian, not this machine's byte order; pass a copy in its order, {0} = "
    "{0}.astype(np.float64), and read the result from it (a copy made for the call alone would "
    "take the result and be lost)"
)

IN_PLACE = "must be a C-contiguous, writeable float64 array (the step updates it in place), got"

# (call, error, the whole one-line message)
CASES = [
    (lambda: hsv_bins(_FRAME.astype(np.uint16) * 257), TypeError,
     "hsv_bins: frame dtype is uint16, expected uint8 (BGR, as cv2 reads it); a 16-bit frame? "
     "(frame >> 8).astype(np.uint8) keeps its top 8 bits"),
    (lambda: hsv_bins(_FRAME.astype(np.float32)), TypeError,
     "hsv_bins: frame dtype is float32, expected uint8 (BGR, as cv2 reads it)"),
    (lambda: hsv_bins(_FRAME[..., 0]), ValueError,
     "hsv_bins: frame must have shape (H, W, 3) (BGR), got (60, 80): a grey frame? "
     "cv2.cvtColor(frame, cv2.COLOR_GRAY2BGR) makes it BGR"),
    (lambda: hsv_bins(_FRAME, np.ones((60, 80), np.int64)), TypeError,
     "hsv_bins: mask dtype is int64, expected uint8 or bool"),
    (lambda: hsv_bins(_FRAME, np.ones((60, 81), np.uint8)), ValueError,
     "hsv_bins: mask shape is (60, 81), expected the frame's (60, 80)"),
    (lambda: hsv_bins(_FRAME, lazy=1), TypeError, "hsv_bins: lazy must be a bool, got int"),
    # ragged rows: were NumPy's "setting an array element with a sequence. The requested
    # array has an inhomogeneous shape ...", naming no function (integrator trial)
    (lambda: hsv_bins([[1, 1], [1]]), TypeError,
     "hsv_bins: frame is list, expected a (H, W, 3) uint8 BGR array"),
    (lambda: hsv_bins(_FRAME, [[1, 1], [1]]), ValueError,
     "hsv_bins: mask must be a rectangular array of numbers, got rows of different lengths"),
    *[(lambda fn=fn: fn([[0.5, 0.5], [1.0]], rng=0), ValueError,
       f"{fn.__name__}: weights must be a rectangular array of numbers, got rows of different "
       "lengths")
      for fn in (systematic_resample, stratified_resample, multinomial_resample,
                 residual_resample)],
    # the core's mask check, as every binding that takes a mask makes it (was ValueError)
    (lambda: _core.mask_bins(_IM, np.ones((60, 80), np.int64)), TypeError,
     "mask_bins: mask dtype is int64, expected uint8 or bool"),
    (lambda: _core.mask_bins(_IM, np.ones((60, 80), np.float32)), TypeError,
     "mask_bins: mask dtype is float32, expected uint8 or bool"),
    (lambda: _core.mask_bins(_IM, np.ones((60, 81), np.uint8)), ValueError,
     "mask_bins: mask must have the frame's (H, W) shape"),
    # the filter's own checks name it, as its step's do (were "box is ...", "reference
    # histogram must be ...": no function; integrator trial)
    (lambda: ColourParticleFilter([40, 30, 0, 20], np.ones(110)), ValueError,
     "ColourParticleFilter: box is [40.0, 30.0, 0.0, 20.0], expected finite (cx, cy, w, h) "
     "with w, h > 0, each value within ±1e+09 px"),
    (lambda: ColourParticleFilter([40, 30, 10, 20], np.zeros(110)), ValueError,
     "ColourParticleFilter: reference histogram must be finite, >= 0 and not all zero"),
    (lambda: ColourParticleFilter([40, 30, 10, 20], np.ones(110), velocity=[1.0]), ValueError,
     "ColourParticleFilter: velocity must have shape (2,) (vx, vy), got (1,): [1.0]"),
    (lambda: _filter().reinitialise([40, 30, 10, -1]), ValueError,
     "ColourParticleFilter.reinitialise: box is [40.0, 30.0, 10.0, -1.0], expected finite "
     "(cx, cy, w, h) with w, h > 0, each value within ±1e+09 px"),
    (lambda: reinitialise_filters([_filter(), _filter()], [[1, 1, 5, 5], [1, 1, 5, 0]],
                                  [[0, 0], [0, 0]]), ValueError,
     "reinitialise_filters: filters[1]: box is [1.0, 1.0, 5.0, 0.0], expected finite "
     "(cx, cy, w, h) with w, h > 0, each value within ±1e+09 px"),
    # the filter's step and the batch say the same, the batch naming the filter's place
    (lambda: _float32("particles").step(_IM), TypeError,
     f"ColourParticleFilter.particles {IN_PLACE} float32 (100, 6), C-contiguous"),
    (lambda: step_filters([_filter(), _float32("particles")], _IM), TypeError,
     f"step_filters: filters[1].particles {IN_PLACE} float32 (100, 6), C-contiguous"),
    (lambda: step_filters([_float32("weights")], _IM), TypeError,
     f"step_filters: filters[0].weights {IN_PLACE} float32 (100,), C-contiguous"),
    (lambda: step_filters([_filter(), _filter(), _float32("means")], _IM), TypeError,
     f"step_filters: filters[2].means {IN_PLACE} float32 (2, 3), C-contiguous"),
    (lambda: propagate(np.zeros((4, 6), ">f8"), np.zeros((4, 3))), TypeError,
     "propagate: particles must be a C-contiguous, writeable float64 array (updated in place, "
     "never copied), got dtype >f8" + SWAPPED.format("particles")),
    (lambda: _big_endian("particles").step(_IM), TypeError,
     f"ColourParticleFilter.particles {IN_PLACE} >f8 (100, 6), C-contiguous"
     + SWAPPED.format("filter.particles")),
    (lambda: step_filters([_filter(), _big_endian("means")], _IM), TypeError,
     f"step_filters: filters[1].means {IN_PLACE} >f8 (2, 3), C-contiguous"
     + SWAPPED.format("filter.means")),
]  # fmt: skip


@pytest.mark.parametrize(("call", "error", "message"), CASES)
def test_one_kind_for_one_fault_in_one_line(call, error, message):
    with pytest.raises(error, match=f"^{re.escape(message)}$"):
        call()


def test_a_refused_batch_steps_no_filter():
    good, bad = _filter(), _float32("particles")
    before = good.particles.copy()
    with pytest.raises(TypeError):
        step_filters([good, bad], _IM)
    np.testing.assert_array_equal(good.particles, before)
    assert good.last is None
    bad.particles = bad.particles.astype(np.float64)
    assert len(step_filters([good, bad], _IM)) == 2  # mended, both step
