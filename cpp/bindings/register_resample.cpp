#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include "pftrack/resample.hpp"

namespace py = pybind11;
using namespace pftrack;

void register_resample(py::module_& m) {
    m.def(
        "systematic_resample",
        [](Eigen::Ref<const Eigen::VectorXd> weights, double u0) {
            py::gil_scoped_release nogil;  // safe: Eigen views only
            return systematic_resample(weights, u0);
        },
        py::arg("weights"), py::arg("u0"), "Indices (N,) int32; u0 in [0, 1).");
    m.def(
        "stratified_resample",
        [](Eigen::Ref<const Eigen::VectorXd> weights, Eigen::Ref<const Eigen::VectorXd> u) {
            py::gil_scoped_release nogil;  // safe: Eigen views only
            return stratified_resample(weights, u);
        },
        py::arg("weights"), py::arg("u"), "Indices (N,) int32; u (N,) in [0, 1).");
    m.def(
        "multinomial_resample",
        [](Eigen::Ref<const Eigen::VectorXd> weights, Eigen::Ref<const Eigen::VectorXd> u) {
            py::gil_scoped_release nogil;  // safe: Eigen views only
            return multinomial_resample(weights, u);
        },
        py::arg("weights"), py::arg("u"), "Indices (N,) int32 in draw order; u (N,) in [0, 1).");
    m.def(
        "residual_resample",
        [](Eigen::Ref<const Eigen::VectorXd> weights, Eigen::Ref<const Eigen::VectorXd> u) {
            py::gil_scoped_release nogil;  // safe: Eigen views only
            return residual_resample(weights, u);
        },
        py::arg("weights"), py::arg("u"), "Indices (N,) int32; u (N,) in [0, 1), first R used.");
}
