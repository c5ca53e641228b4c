#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>

#include "pftrack/sis.hpp"
#include "step_args.hpp"

namespace py = pybind11;
using namespace pftrack;

using bind::make_model;

void register_filter(py::module_& m) {
    m.def(
        "propagate",
        [](Eigen::Ref<RowMatrixXd> particles, Eigen::Ref<const RowMatrixXd> noise,
           const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& sigma,
           double s_min, double s_max, bool use_means, const Eigen::Vector3d& mean_prev,
           const Eigen::Vector3d& mean_prev2) {
            const Ar2Model model = make_model(a, b, sigma, s_min, s_max, use_means);
            py::gil_scoped_release nogil;  // safe: Eigen views only
            propagate_ar2(particles, noise, model, mean_prev, mean_prev2);
        },
        py::arg("particles").noconvert(), py::arg("noise"), py::arg("a"), py::arg("b"),
        py::arg("sigma"), py::arg("s_min"), py::arg("s_max"), py::arg("use_means"),
        py::arg("mean_prev"), py::arg("mean_prev2"),
        "AR(2) step in place; particles (N, 6) float64 C-contiguous, noise (N, 3) N(0, 1).");

    m.def(
        "counter_uniforms",
        [](std::uint64_t seed, std::uint64_t stream, std::uint64_t start, Index n) {
            require(n >= 0, "counter_uniforms", "n", n, ">= 0");
            require_size(static_cast<double>(n), "counter_uniforms", "n");
            const CounterRng rng(seed, stream);
            Eigen::VectorXd u(n);
            for (Index i = 0; i < n; ++i) u(i) = rng.uniform(start + static_cast<std::uint64_t>(i));
            return u;
        },
        py::arg("seed"), py::arg("stream"), py::arg("start"), py::arg("n"),
        "Uniforms k = start .. start+n-1 of the counter-based stream (for tests and references).");
    m.def(
        "counter_normals",
        [](std::uint64_t seed, std::uint64_t stream, Index n) {
            require(n >= 0, "counter_normals", "n", n, ">= 0");
            require_size(static_cast<double>(n), "counter_normals", "n");
            const CounterRng rng(seed, stream);
            Eigen::VectorXd z(n);
            for (Index i = 0; i < n; ++i) z(i) = rng.normal(static_cast<std::uint64_t>(i));
            return z;
        },
        py::arg("seed"), py::arg("stream"), py::arg("n"),
        "Normals k = 0 .. n-1 of the counter-based stream (sis_step's propagation noise).");

    m.def(
        "estimate",
        [](Eigen::Ref<const RowMatrixXd> particles, Eigen::Ref<const Eigen::VectorXd> weights) {
            const char* fn = "estimate";
            check_particles(particles, fn);
            require(weights.size() == particles.rows(), fn, "weights size", weights.size(),
                    particles.rows());
            require_weights(weights, fn);
            Estimate e;
            {
                py::gil_scoped_release nogil;  // safe: Eigen views only
                e = estimate_state(particles, weights);
            }
            return py::make_tuple(Eigen::Vector3d(e.mean), Eigen::Vector3d(e.map), e.map_index);
        },
        py::arg("particles"), py::arg("weights"), "(mean (3,), map (3,), map_index).");

    m.def(
        "sis_step",
        [](Eigen::Ref<RowMatrixXd> particles, Eigen::Ref<Eigen::VectorXd> weights,
           Eigen::Ref<RowMatrixXd> means, const BinnedImage& image,
           Eigen::Ref<const Eigen::VectorXd> ref, double w0, double h0,
           const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& sigma,
           double s_min, double s_max, bool use_means, double lam, const std::string& kernel,
           bool resample, std::uint64_t seed, std::uint64_t step) {
            const SisParams prm = bind::make_step_params(w0, h0, a, b, sigma, s_min, s_max, use_means,
                                                         lam, kernel, resample, "sis_step");
            SisResult r;
            {
                py::gil_scoped_release nogil;  // safe: Eigen views and the C++ image only
                r = sis_step(particles, weights, means, image.view(), ref, prm, seed, step);
            }
            return bind::step_result_dict(r);
        },
        py::arg("particles").noconvert(), py::arg("weights").noconvert(),
        py::arg("means").noconvert(), py::arg("image"), py::arg("ref"), py::arg("w0"),
        py::arg("h0"), py::arg("a"), py::arg("b"), py::arg("sigma"), py::arg("s_min"),
        py::arg("s_max"), py::arg("use_means"), py::arg("lam"), py::arg("kernel"),
        py::arg("resample"), py::arg("seed"), py::arg("step"),
        "Resample, propagate, histogram, weigh, estimate; particles (N, 6), weights (N,), "
        "means (2, 3) updated in place.");
}
