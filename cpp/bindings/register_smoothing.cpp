// Bindings of rts_gaps.hpp: the `rts` recovery baseline over many gaps in one call.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include "pftrack/rts_gaps.hpp"

namespace py = pybind11;
using namespace pftrack;

void register_smoothing(py::module_& m) {
    m.def(
        "rts_gaps_batch",
        [](Eigen::Ref<const RowMatrixXd> points, Eigen::Ref<const Eigen::VectorXi> offsets,
           Eigen::Ref<const Eigen::VectorXi> n_before, double q, double r, double v0) {
            py::gil_scoped_release nogil;  // safe: Eigen views of NumPy buffers only
            return rts_gaps_batch(points, offsets, n_before, q, r, v0);
        },
        py::arg("points"), py::arg("offsets"), py::arg("n_before"), py::arg("q"), py::arg("r"),
        py::arg("v0"),
        "Smoothed (x, y) (M, 2) inside every gap; points (P, 3) frame, x, y, windows by offsets "
        "(G + 1,), n_before (G,) points of segment A per window.");
}
