// Checks on NumPy arrays that only the binding layer can make (dtype, ndim, strides), with
// messages in the core's style: "hsv_bins: frame dtype is float64, expected uint8".
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

#include "pftrack/check.hpp"

namespace pftrack::bind {

namespace py = pybind11;

inline std::string dtype_name(const py::array& a) { return py::str(a.dtype()).cast<std::string>(); }

// These run on every call (every frame, in tracking): each message, py::str of a dtype
// included, is built only when its check fails.

/// A (H, W, 3) uint8 image whose pixels are packed (3 bytes a pixel, 1 a channel); rows may be
/// strided (views of a larger image are fine).
inline void check_bgr_image(const py::array& a, const char* fn, const char* what) {
    if (!a.dtype().is(py::dtype::of<std::uint8_t>()))
        require(false, fn, (std::string(what) + " dtype").c_str(), dtype_name(a),
                "uint8 (BGR, as cv2 reads it)");
    if (!(a.ndim() == 3 && a.shape(2) == 3))
        fail(fn, std::string(what) + " must have shape (H, W, 3)");
    if (!(a.shape(0) > 0 && a.shape(1) > 0)) fail(fn, std::string(what) + " is empty");
    if (!(a.strides(2) == 1 && a.strides(1) == 3 && a.strides(0) > 0))
        fail(fn, std::string(what) + " pixels must be packed (use numpy.ascontiguousarray)");
}

/// A mask's dtype: uint8 or bool.
inline void check_mask_dtype(const py::array& m, const char* fn) {
    if (!m.dtype().is(py::dtype::of<std::uint8_t>()) && !m.dtype().is(py::dtype::of<bool>()))
        require(false, fn, "mask dtype", dtype_name(m), "uint8 or bool");
}

/// A (H, W) mask of uint8 or bool, matching the image's size, packed along rows.
inline void check_mask(const py::array& m, py::ssize_t rows, py::ssize_t cols, const char* fn) {
    check_mask_dtype(m, fn);
    if (!(m.ndim() == 2 && m.shape(0) == rows && m.shape(1) == cols))
        fail(fn, "mask must have the frame's (H, W) shape");
    if (!(m.strides(1) == 1 && m.strides(0) > 0))
        fail(fn, "mask must be packed along rows (use numpy.ascontiguousarray)");
}

}  // namespace pftrack::bind
