#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include "pftrack/likelihood.hpp"

namespace py = pybind11;
using namespace pftrack;

void register_likelihood(py::module_& m) {
    m.def(
        "bhattacharyya_coefficient",
        [](Eigen::Ref<const RowMatrixXd> hists, Eigen::Ref<const Eigen::VectorXd> ref) {
            py::gil_scoped_release nogil;  // safe: Eigen views only
            return bhattacharyya_coefficient(hists, ref);
        },
        py::arg("hists"), py::arg("ref"),
        "rho (K,) of histograms (K, B) against ref (B,), each row and ref normalised to sum 1.");

    m.def(
        "bhattacharyya_distance",
        [](Eigen::Ref<const RowMatrixXd> hists, Eigen::Ref<const Eigen::VectorXd> ref) {
            py::gil_scoped_release nogil;  // safe: Eigen views only
            Eigen::VectorXd d = bhattacharyya_coefficient(hists, ref, "bhattacharyya_distance");
            for (Index i = 0; i < d.size(); ++i) d(i) = bhattacharyya_distance_from_rho(d(i));
            return d;
        },
        py::arg("hists"), py::arg("ref"), "D = sqrt(1 - rho) (K,) of histograms (K, B).");

    m.def(
        "bhattacharyya_weights",
        [](Eigen::Ref<const RowMatrixXd> hists, Eigen::Ref<const Eigen::VectorXd> ref,
           double lambda) {
            const char* fn = "bhattacharyya_weights";
            check_lambda(lambda, fn);
            py::gil_scoped_release nogil;  // safe: Eigen views only
            require(hists.rows() > 0, fn, "hists rows", hists.rows(), ">= 1");
            return weights_from_rho(bhattacharyya_coefficient(hists, ref, fn), lambda, fn);
        },
        py::arg("hists"), py::arg("ref"), py::arg("lam") = 20.0,
        "Normalised weights (K,) ~ exp(-lam D^2).");
}
