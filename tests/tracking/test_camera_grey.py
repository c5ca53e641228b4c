"""The camera check's scaled grey frame in one pass: ``_core.grey_halved`` (camera.hpp).

``grey_halved(frame)`` is OpenCV's ``cv2.resize(cv2.cvtColor(frame, COLOR_BGR2GRAY)[:2 h, :2 w],
(w, h), INTER_AREA)`` with ``h, w = H // 2, W // 2``, to the bit: held here to OpenCV and to a
plain NumPy reference (the fixed-point grey, then the rounded mean of each 2x2 block), through
the AVX2 pass and, with ``_core._set_avx2(False)``, the portable loop that CPUs without AVX2
run. ``camera._grey`` takes it for its first halving (or a scale of exactly 1/2) and must give
the frames the two OpenCV calls gave.
"""

from __future__ import annotations

from collections.abc import Iterator

import cv2
import numpy as np
import pytest
from numpy.typing import NDArray

from pftrack import _core
from pftrack.tracking import camera


@pytest.fixture(params=[True, False], ids=["avx2", "portable"])
def avx2(request: pytest.FixtureRequest) -> Iterator[bool]:
    """With the AVX2 pass allowed (where the CPU has it), then with the portable loop only."""
    before = _core._set_avx2(request.param)
    yield request.param
    _core._set_avx2(before)


def reference(frame: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """Grey (15-bit fixed point, OpenCV 5's weights, rounded), then 2x2 means rounded."""
    h, w = frame.shape[0] // 2, frame.shape[1] // 2
    b, g, r = (frame[: 2 * h, : 2 * w, k].astype(np.int64) for k in range(3))
    grey = (b * 3735 + g * 19235 + r * 9798 + (1 << 14)) >> 15
    blocks = grey[0::2, 0::2] + grey[0::2, 1::2] + grey[1::2, 0::2] + grey[1::2, 1::2]
    return ((blocks + 2) >> 2).astype(np.uint8)


def opencv(frame: NDArray[np.uint8]) -> NDArray[np.uint8]:
    h, w = frame.shape[0] // 2, frame.shape[1] // 2
    grey = cv2.cvtColor(np.ascontiguousarray(frame), cv2.COLOR_BGR2GRAY)
    return np.asarray(cv2.resize(grey[: 2 * h, : 2 * w], (w, h), interpolation=cv2.INTER_AREA))


def every_colour() -> NDArray[np.uint8]:
    v = np.arange(1 << 24, dtype=np.uint32)
    return np.stack([v & 255, (v >> 8) & 255, v >> 16], -1).astype(np.uint8).reshape(4096, 4096, 3)


def test_every_colour_as_opencv_and_numpy(avx2: bool) -> None:
    img = every_colour()
    out = _core.grey_halved(img)
    assert out.dtype == np.uint8 and out.shape == (2048, 2048)
    np.testing.assert_array_equal(out, opencv(img))
    np.testing.assert_array_equal(out, reference(img))
    # each colour alone: the 2x2 blocks of one colour give its grey (rows of 2 pixels doubled)
    one = np.repeat(np.repeat(img[:64], 2, axis=0), 2, axis=1)
    np.testing.assert_array_equal(_core.grey_halved(one), opencv(one))


def test_odd_sizes_tails_and_strided_rows(avx2: bool) -> None:
    rng = np.random.default_rng(73)
    for h in (2, 3, 4, 5, 17, 36):
        for w in range(2, 72):  # every vector count and scalar tail of an output row
            frame = rng.integers(0, 256, (h, w, 3), dtype=np.uint8)
            out = _core.grey_halved(frame)
            np.testing.assert_array_equal(out, reference(frame), err_msg=f"{h}x{w}")
            np.testing.assert_array_equal(out, opencv(frame), err_msg=f"{h}x{w}")
    big = rng.integers(0, 256, (61, 97, 3), dtype=np.uint8)
    view = big[3:50, 5:90]  # rows strided, pixels packed
    assert not view.flags.c_contiguous
    np.testing.assert_array_equal(_core.grey_halved(view), opencv(view))
    # extremes: saturated and black blocks, every channel alone at 255
    for colour in ((0, 0, 0), (255, 255, 255), (255, 0, 0), (0, 255, 0), (0, 0, 255)):
        flat = np.zeros((6, 50, 3), np.uint8) + np.array(colour, np.uint8)
        np.testing.assert_array_equal(_core.grey_halved(flat), opencv(flat))


def test_one_line_errors() -> None:
    with pytest.raises(TypeError, match="grey_halved: frame dtype is float32"):
        _core.grey_halved(np.zeros((4, 4, 3), np.float32))
    with pytest.raises(TypeError, match="grey_halved: frame is list"):
        _core.grey_halved([[0, 0, 0]])  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"must have shape \(H, W, 3\)"):
        _core.grey_halved(np.zeros((4, 4), np.uint8))
    with pytest.raises(ValueError, match="at least 2x2"):
        _core.grey_halved(np.zeros((1, 9, 3), np.uint8))
    with pytest.raises(ValueError, match="pixels must be packed"):
        _core.grey_halved(np.zeros((4, 8, 3), np.uint8)[:, ::2])


def old_grey(frame: NDArray[np.uint8], factor: float) -> NDArray[np.uint8]:
    """camera._grey before grey_halved: OpenCV's grey, halvings and last resize."""
    g = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY)
    if factor != 1.0:
        size = (max(1, round(g.shape[1] * factor)), max(1, round(g.shape[0] * factor)))
        while g.shape[1] >= 4 * size[0] and g.shape[0] >= 4 * size[1]:
            half = (g.shape[1] // 2, g.shape[0] // 2)
            g = cv2.resize(g[: 2 * half[1], : 2 * half[0]], half, interpolation=cv2.INTER_AREA)
        g = cv2.resize(g, size, interpolation=cv2.INTER_AREA)
    return np.asarray(g, dtype=np.uint8)


@pytest.mark.parametrize(
    "shape",
    [(360, 480), (576, 768), (720, 1280), (361, 481), (720, 960), (500, 2), (500, 1), (4, 4),
     (8, 6), (2160, 3840), (241, 640)],
)  # fmt: skip
def test_the_cameras_grey_is_opencvs(shape: tuple[int, int], avx2: bool) -> None:
    """camera._grey (the fused first halving where it applies) gives the old calls' frame."""
    assert camera._fused_grey()  # this OpenCV's grey is the kernel's: the fused path is taken
    frame = np.random.default_rng(shape[0] * 7 + shape[1]).integers(
        0, 256, (*shape, 3), dtype=np.uint8
    )
    measure = camera._Measure(camera.CameraConfig())
    for f in (frame, frame[:, ::-1]):  # packed, and pixels not packed (OpenCV's calls only)
        factor, got = measure.grey(f)
        want = old_grey(np.ascontiguousarray(f), factor)
        assert got.dtype == np.uint8 and got.shape == want.shape
        np.testing.assert_array_equal(got, want)
        for other in (0.5, 0.25, 0.3):
            np.testing.assert_array_equal(camera._grey(f, other), old_grey(f, other))
