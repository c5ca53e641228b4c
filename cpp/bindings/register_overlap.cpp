#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "pftrack/overlap.hpp"

namespace py = pybind11;
using namespace pftrack;

void register_overlap(py::module_& m) {
    m.def(
        "overlap_pairs",
        [](Eigen::Ref<const RowMatrixXd> a, Eigen::Ref<const RowMatrixXd> b) {
            py::gil_scoped_release nogil;  // safe: Eigen views only
            return overlap_pairs(a, b);
        },
        py::arg("a"), py::arg("b"),
        "Pairs (i, j) int64 of boxes a (n, 4) and b (m, 4), xywh, whose interiors meet; "
        "increasing (i, j).");
    m.def(
        "padded_assignment",
        [](Eigen::Ref<const RowMatrixXd> cost, double tau, double forbidden) {
            py::gil_scoped_release nogil;  // safe: Eigen views only
            return padded_assignment(cost, tau, forbidden);
        },
        py::arg("cost"), py::arg("tau"), py::arg("forbidden"),
        "linear_sum_assignment of the association's padded (T + D, D + T) matrix of cost (T, D) "
        "without making it: (rows, cols) int32.");
}
