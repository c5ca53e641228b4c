#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "arrays.hpp"
#include "pftrack/camera.hpp"

namespace py = pybind11;
using namespace pftrack;

namespace {

/// `obj` as a (H, W) uint8 grey image packed along rows, or a one-line TypeError/ValueError.
GreyImage grey_image(const py::handle& obj, const char* fn, const char* what, py::array& keep) {
    keep = bind::ndarray(obj, fn, what, "(H, W) uint8");
    if (!bind::is_u8(keep.dtype()))
        throw py::type_error(std::string(fn) + ": " + what + " dtype is " +
                             bind::dtype_name(keep) + ", expected uint8");
    if (keep.ndim() != 2) fail(fn, std::string(what) + " must have shape (H, W)");
    if (!(keep.shape(0) > 0 && keep.shape(1) > 0)) fail(fn, std::string(what) + " is empty");
    if (!(keep.strides(1) == 1 && keep.strides(0) > 0))
        fail(fn, std::string(what) + " must be packed along rows (use numpy.ascontiguousarray)");
    return GreyImage{static_cast<const std::uint8_t*>(keep.data()),
                     static_cast<int>(keep.shape(0)), static_cast<int>(keep.shape(1)),
                     static_cast<std::ptrdiff_t>(keep.strides(0))};
}

using PointsF32 = py::array_t<float, py::array::c_style | py::array::forcecast>;

/// `pts` as n points (x, y) float32: shape (n, 2) or (n, 1, 2), OpenCV's corner layout.
int point_count(const PointsF32& pts, const char* fn, const char* what) {
    const bool ok = (pts.ndim() == 2 && pts.shape(1) == 2) ||
                    (pts.ndim() == 3 && pts.shape(1) == 1 && pts.shape(2) == 2);
    if (!ok) fail(fn, std::string(what) + " must have shape (N, 2) or (N, 1, 2)");
    const int n = static_cast<int>(pts.shape(0));
    const float* v = pts.data();
    for (int i = 0; i < 2 * n; ++i)  // the flow converts coordinates to int: keep them in range
        if (!(std::abs(v[i]) <= 1e8f))
            fail(fn, std::string(what) + " must be finite and within 1e8 (got " +
                         std::to_string(v[i]) + ")");
    return n;
}

}  // namespace

void register_camera(py::module_& m) {
    m.def(
        "grey_halved",
        [](const py::object& frame_in) {
            const char* fn = "grey_halved";
            const py::array frame = bind::bgr_image(frame_in, fn, "frame");
            const py::ssize_t rows = frame.shape(0) / 2, cols = frame.shape(1) / 2;
            if (rows == 0 || cols == 0) fail(fn, "frame must be at least 2x2 pixels");
            py::array_t<std::uint8_t> out({rows, cols});
            const auto* in = static_cast<const std::uint8_t*>(frame.data());
            const std::ptrdiff_t stride = frame.strides(0);
            std::uint8_t* o = out.mutable_data();
            {
                py::gil_scoped_release nogil;  // safe: `frame` and `out` are held above
                grey_halved(in, stride, static_cast<int>(rows), static_cast<int>(cols), o,
                            static_cast<std::ptrdiff_t>(cols));
            }
            return out;
        },
        py::arg("frame"),
        "Grey (H // 2, W // 2) uint8 of BGR frame (H, W, 3) uint8: OpenCV's cvtColor to grey "
        "then INTER_AREA halving of the even part, to the bit, in one pass.");
    m.def(
        "still_flow",
        [](const py::object& prev_in, const py::object& next_in, const PointsF32& pts,
           int win_size, int max_count, double epsilon, double min_eig) {
            const char* fn = "still_flow";
            py::array prev_keep, next_keep;
            const GreyImage prev = grey_image(prev_in, fn, "prev", prev_keep);
            const GreyImage next = grey_image(next_in, fn, "next", next_keep);
            if (prev.rows != next.rows || prev.cols != next.cols)
                fail(fn, "prev and next differ in size");
            require(win_size >= 3 && win_size <= 255, fn, "win_size", win_size, "in [3, 255]");
            // as OpenCV reads its criteria: at most 100 steps, epsilon in [0, 10]
            max_count = std::min(std::max(max_count, 0), 100);
            epsilon = std::min(std::max(epsilon, 0.0), 10.0);
            const int n = point_count(pts, fn, "pts");
            py::array_t<float> out({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(2)});
            py::array_t<bool> ok(n);
            {
                py::gil_scoped_release nogil;  // safe: plain buffers kept alive above
                still_flow(prev, next, pts.data(), n, out.mutable_data(),
                           reinterpret_cast<std::uint8_t*>(ok.mutable_data()), win_size,
                           win_size, max_count, epsilon, static_cast<float>(min_eig));
            }
            return std::make_pair(out, ok);
        },
        py::arg("prev"), py::arg("next"), py::arg("pts"), py::arg("win_size") = 11,
        py::arg("max_count") = 30, py::arg("epsilon") = 0.01, py::arg("min_eig") = 1e-4,
        "Lucas-Kanade flow at one level of pts (N, 2) float32 of grey prev (H, W) uint8 into "
        "next: places (N, 2) float32 and followed (N,) bool, OpenCV's to the bit.");
    m.def(
        "similarity_fit",
        [](const PointsF32& src, const PointsF32& dst) -> py::object {
            const char* fn = "similarity_fit";
            const int n = point_count(src, fn, "src");
            if (point_count(dst, fn, "dst") != n) fail(fn, "src and dst differ in length");
            py::array_t<double> out({static_cast<py::ssize_t>(2), static_cast<py::ssize_t>(3)});
            if (!similarity_fit(src.data(), dst.data(), n, out.mutable_data())) return py::none();
            return std::move(out);
        },
        py::arg("src"), py::arg("dst"),
        "Least-squares similarity (2, 3) float64 from src (N, 2) to dst (N, 2) float32, closed "
        "form; None when src has no spread.");
}
