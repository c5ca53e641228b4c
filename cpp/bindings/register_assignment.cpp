#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "pftrack/assignment.hpp"

namespace py = pybind11;
using namespace pftrack;

void register_assignment(py::module_& m) {
    m.def(
        "linear_sum_assignment",
        [](Eigen::Ref<const RowMatrixXd> cost) {
            py::gil_scoped_release nogil;  // safe: Eigen views only
            return linear_sum_assignment(cost);
        },
        py::arg("cost"),
        "Minimum-cost assignment of cost (R, C): (rows, cols) int32, as scipy.optimize's.");
}
