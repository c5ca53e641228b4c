// Bindings of rts_gaps.hpp (the `rts` recovery baseline over many gaps in one call) and
// rts_smooth.hpp (the smoother of pftrack.kalman.rts_smooth).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <string>

#include "pftrack/check.hpp"
#include "pftrack/rts_gaps.hpp"
#include "pftrack/rts_smooth.hpp"

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

    m.def(
        "rts_smooth",
        [](py::array_t<double, py::array::c_style | py::array::forcecast> z,
           py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast> has,
           py::array_t<double, py::array::c_style | py::array::forcecast> q,
           py::array_t<double, py::array::c_style | py::array::forcecast> r2, double velocity_sd,
           bool update_first) {
            const char* fn = "rts_smooth";
            require(z.ndim() == 2, fn, "z must be of shape (T, n)");
            const py::ssize_t steps = z.shape(0), n = z.shape(1);
            require(q.ndim() == 1 && q.shape(0) == n && r2.ndim() == 1 && r2.shape(0) == n, fn,
                    "q and r2 must be of shape (n,), n = " + std::to_string(n) + " columns of z");
            const bool per_axis = has.ndim() == 2;
            require((has.ndim() == 1 && has.shape(0) == steps) ||
                        (per_axis && has.shape(0) == steps && has.shape(1) == n),
                    fn, "has must be of shape (T,) or (T, n) as z " + std::to_string(steps) + " x " +
                            std::to_string(n));
            require(steps > 0, fn, "the first frame must have a measurement (z is empty)");
            require(std::isfinite(velocity_sd) && velocity_sd >= 0.0, fn, "velocity_sd",
                    velocity_sd, "finite and >= 0");
            const double* zp = z.data();
            const std::uint8_t* hp = has.data();
            const double *qp = q.data(), *rp = r2.data();
            for (py::ssize_t k = 0; k < (per_axis ? n : 1); ++k)
                require(hp[k] != 0, fn, "the first frame must have a measurement");
            for (py::ssize_t k = 0; k < n; ++k)
                require(std::isfinite(qp[k]) && qp[k] >= 0.0 && std::isfinite(rp[k]) && rp[k] > 0.0,
                        fn, "q must be finite and >= 0, r2 finite and > 0");
            // every measured z must be finite (the others are never read)
            for (py::ssize_t t = 0; t < steps; ++t)
                for (py::ssize_t k = 0; k < n; ++k)
                    if (hp[per_axis ? t * n + k : t] != 0 && !std::isfinite(zp[t * n + k]))
                        fail(fn, "z is not finite at frame " + std::to_string(t) + ", axis " +
                                     std::to_string(k) + ", which has a measurement");
            py::array_t<double> out({steps, n});
            double* op = out.mutable_data();
            bool finite = true;
            {
                py::gil_scoped_release nogil;  // safe: buffers owned by the arrays held here
                rts_smooth(zp, hp, per_axis, steps, n, qp, rp, velocity_sd, update_first, op);
                for (py::ssize_t i = 0; i < steps * n; ++i) finite = finite && std::isfinite(op[i]);
            }
            // extreme q, r2, velocity_sd or coordinates can make a covariance singular
            require(finite, fn, "the smoothed positions are not finite (q, r2, velocity_sd or z "
                                "too extreme)");
            return out;
        },
        py::arg("z"), py::arg("has"), py::arg("q"), py::arg("r2"), py::arg("velocity_sd"),
        py::arg("update_first"),
        "Smoothed positions (T, n) of independent constant-velocity axes: z (T, n), has (T,) or "
        "(T, n) bool/uint8 (rows without a measurement are never read), q and r2 (n,).");
}
