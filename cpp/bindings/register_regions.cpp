// Binding of regions.hpp (the stretches square regions cut from the observed runs,
// python/pftrack/recovery/calibrate.py::_region_blocks).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "pftrack/check.hpp"
#include "pftrack/regions.hpp"
#include "arrays.hpp"

namespace py = pybind11;
using namespace pftrack;

namespace {

/// `a` as a C-contiguous array of T (one copy only when strided), after a TypeError for another
/// dtype.
template <typename T>
py::array_t<T, py::array::c_style> typed(const py::array& a, const char* fn, const char* what,
                                         const char* dtype) {
    if (!bind::is_dtype<T>(a.dtype()))
        throw py::type_error(std::string(fn) + ": " + what + " dtype is " + bind::dtype_name(a) +
                             ", expected " + dtype);
    return py::array_t<T, py::array::c_style>::ensure(a);
}

/// Every value of the (rows, 2) array finite (the message names the first bad row).
void require_finite_rows(const double* v, py::ssize_t rows, const char* fn, const char* what) {
    for (py::ssize_t k = 0; k < 2 * rows; ++k)
        if (!std::isfinite(v[k]))
            fail(fn, std::string(what) + " has a non-finite value at row " + std::to_string(k / 2));
}

py::array_t<std::int64_t> as_array(const std::vector<std::int64_t>& v) {
    return py::array_t<std::int64_t>(static_cast<py::ssize_t>(v.size()), v.data());
}

}  // namespace

void register_regions(py::module_& m) {
    m.def(
        "region_blocks",
        [](const py::array& xy, const py::array& sizes, const py::array& centres, double side,
           std::int64_t work, int decimals) {
            const char* fn = "region_blocks";
            const auto p = typed<double>(xy, fn, "xy", "float64");
            const auto s = typed<std::int64_t>(sizes, fn, "sizes", "int64");
            const auto c = typed<double>(centres, fn, "centres", "float64");
            require(p.ndim() == 2 && p.shape(1) == 2, fn, "xy must be of shape (n, 2)");
            require(s.ndim() == 1, fn, "sizes must be a 1-D array");
            require(c.ndim() == 2 && c.shape(1) == 2, fn, "centres must be of shape (squares, 2)");
            require(std::isfinite(side) && side > 0.0, fn, "side", side, "finite and > 0");
            require(work >= 0, fn, "work", work, ">= 0");
            require(0 <= decimals && decimals <= 22, fn, "decimals", decimals, "in 0..22");
            const py::ssize_t n = p.shape(0), runs = s.shape(0), squares = c.shape(0);
            const std::int64_t* sp = s.data();
            std::int64_t sum = 0;
            for (py::ssize_t r = 0; r < runs; ++r) {
                require(sp[r] >= 0 && sp[r] <= n - sum, fn,
                        "sizes must be >= 0 and sum to the " + std::to_string(n) + " rows of xy");
                sum += sp[r];
            }
            require(sum == n, fn,
                    "sizes sum to " + std::to_string(sum) + ", expected the " + std::to_string(n) +
                        " rows of xy");
            require_finite_rows(p.data(), n, fn, "xy");
            require_finite_rows(c.data(), squares, fn, "centres");
            RegionStretches got;
            {
                py::gil_scoped_release nogil;  // safe: plain buffers, kept alive by p, s, c
                got = region_blocks(p.data(), n, sp, runs, c.data(), squares, side, work,
                                    decimals);
            }
            return py::make_tuple(as_array(got.run), as_array(got.start), as_array(got.length));
        },
        py::arg("xy"), py::arg("sizes"), py::arg("centres"), py::arg("side"), py::arg("work"),
        py::arg("decimals"),
        "(run, start, length) int64 of the stretches of runs of `sizes` (int64) of points xy "
        "(n, 2) float64 inside squares of `side` centred on centres (squares, 2) float64, square "
        "by square while their bands of x hold at most `work` points (the first always), "
        "distances rounded to `decimals` as np.round rounds them.");
}
