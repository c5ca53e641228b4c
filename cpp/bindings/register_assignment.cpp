#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "pftrack/assignment.hpp"
#include "pftrack/association.hpp"

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
    m.def(
        "sparse_assignment",
        [](Eigen::Ref<const IndexVector> r, Eigen::Ref<const IndexVector> c,
           Eigen::Ref<const Eigen::VectorXd> cost, std::int64_t n_ends, std::int64_t n_starts,
           double unjoined) {
            py::gil_scoped_release nogil;  // safe: Eigen views only
            return sparse_assignment(r, c, cost, n_ends, n_starts, unjoined);
        },
        py::arg("r"), py::arg("c"), py::arg("cost"), py::arg("n_ends"), py::arg("n_starts"),
        py::arg("unjoined"),
        "Least-cost joins of ends r[k] to starts c[k] over these pairs only, each end also "
        "left unjoined at `unjoined`: (ends, starts) int64 of the joins, ends ascending.");
    m.def(
        "association_cost",
        [](Eigen::Ref<const RowMatrixXd> track_boxes, Eigen::Ref<const Eigen::VectorXd> heights,
           Eigen::Ref<const Eigen::VectorXd> coasted, Eigen::Ref<const RowMatrixXd> rho,
           Eigen::Ref<const RowMatrixXd> boxes, double match_distance, double colour_weight,
           double match_iou, double forbidden) {
            py::gil_scoped_release nogil;  // safe: Eigen views only
            return association_cost(track_boxes, heights, coasted, rho, boxes, match_distance,
                                    colour_weight, match_iou, forbidden);
        },
        py::arg("track_boxes"), py::arg("heights"), py::arg("coasted"), py::arg("rho"),
        py::arg("boxes"), py::arg("match_distance"), py::arg("colour_weight"),
        py::arg("match_iou"), py::arg("forbidden"),
        "Gated pairing cost (T, D) of track boxes (T, 4) and detection boxes (D, 4), xywh; "
        "heights, coasted (T,); rho (T, D); `forbidden` where the gate forbids a pair.");
}
