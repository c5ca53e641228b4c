#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "pftrack/mot_parse.hpp"
#include "pftrack/mot_text.hpp"
#include "arrays.hpp"

namespace py = pybind11;
using namespace pftrack;

namespace {

/// `a` as a C-contiguous (rows, cols) array of T (one copy only when strided), after a
/// TypeError for another dtype and a ValueError for another shape.
template <typename T>
py::array_t<T, py::array::c_style> table(const py::array& a, const char* fn, const char* what,
                                         py::ssize_t rows, py::ssize_t cols, const char* dtype) {
    if (!bind::is_dtype<T>(a.dtype()))
        throw py::type_error(std::string(fn) + ": " + what + " dtype is " + bind::dtype_name(a) +
                             ", expected " + dtype);
    if (!(a.ndim() == 2 && a.shape(0) == rows && a.shape(1) == cols)) {
        std::string got = "(";
        for (py::ssize_t k = 0; k < a.ndim(); ++k)
            got += (k ? ", " : "") + std::to_string(a.shape(k));
        got += a.ndim() == 1 ? ",)" : ")";
        fail(fn, std::string(what) + " has shape " + got + ", expected (" + std::to_string(rows) +
                     ", " + std::to_string(cols) + ")");
    }
    return py::array_t<T, py::array::c_style>::ensure(a);
}

}  // namespace

void register_text(py::module_& m) {
    m.def(
        "parse_mot_text",
        [](const py::bytes& text) {
            const std::string_view view = text;  // the bytes object's own buffer, no copy
            py::gil_scoped_release nogil;  // safe: bytes are immutable, kept alive by `text`
            return parse_mot_text(view);
        },
        py::arg("text"),
        "The rows (M, 6..10) float64 of a MOTChallenge file's bytes of the common layout (as "
        "np.loadtxt reads them), or None for any other text.");
    m.def(
        "mot_lines",
        [](const py::array& ids, const py::array& values, const py::array& decimals) {
            const char* fn = "mot_lines";
            require(ids.ndim() == 2, fn, "ids must be a (M, 2) array of frame and id");
            const py::ssize_t rows = ids.shape(0);
            const auto i = table<double>(ids, fn, "ids", rows, 2, "float64");
            const auto v = table<double>(values, fn, "values", rows, 8, "float64");
            const auto d = table<std::int64_t>(decimals, fn, "decimals", rows, 8, "int64");
            std::string text;
            {
                py::gil_scoped_release nogil;  // safe: plain buffers, kept alive by i, v, d
                text = mot_lines(i.data(), v.data(), d.data(), static_cast<std::int64_t>(rows));
            }
            // ASCII only: the fastest decode into a str
            PyObject* s = PyUnicode_DecodeASCII(text.data(), static_cast<py::ssize_t>(text.size()),
                                                nullptr);
            if (!s) throw py::error_already_set();
            return py::reinterpret_steal<py::str>(s);
        },
        py::arg("ids"), py::arg("values"), py::arg("decimals"),
        "MOTChallenge lines of ids (M, 2) float64, values (M, 8) float64, decimals (M, 8) int64.");
    m.def(
        "fewest_decimals",
        [](const py::array& values, double limit, int most) {
            const char* fn = "fewest_decimals";
            if (!bind::is_dtype<double>(values.dtype()))
                throw py::type_error(std::string(fn) + ": values dtype is " +
                                     bind::dtype_name(values) + ", expected float64");
            require(values.ndim() == 1, fn, "values must be a 1-D array");
            require(limit > 0.0 && limit <= 9007199254740992.0, fn, "limit", limit,
                    "in (0, 2**53]");
            require(0 <= most && most <= kMostDecimals, fn, "most", most, "in 0..22");
            const auto v = py::array_t<double, py::array::c_style>::ensure(values);
            const py::ssize_t n = v.shape(0);
            py::array_t<std::int64_t> out(n);
            std::int64_t* o = out.mutable_data();
            {
                py::gil_scoped_release nogil;  // safe: plain buffers, kept alive by v, out
                fewest_decimals(v.data(), static_cast<std::int64_t>(n), limit, most, o);
            }
            return out;
        },
        py::arg("values"), py::arg("limit"), py::arg("most"),
        "Fewest decimals d <= most (int64, -1: none) printing each float64 value exactly with "
        "|rint(v 10^d)| < limit.");
}
