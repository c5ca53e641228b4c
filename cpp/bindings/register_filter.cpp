#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "pftrack/sis.hpp"
#include "arrays.hpp"
#include "step_args.hpp"

namespace py = pybind11;
using namespace pftrack;

using bind::make_model;

namespace {

/// A list item that `fn` (sis_step_batch, reseed_batch) updates in place: float64,
/// C-contiguous, writeable, `cols` columns (a (rows,) vector when cols == 0).
py::array_t<double> batch_item(const py::handle& h, const char* what, py::ssize_t k,
                               py::ssize_t rows, py::ssize_t cols,
                               const char* fn = "sis_step_batch") {
    // every message (the item's name, the dtype's) built only on failure: this runs for each
    // object on every frame
    const auto name = [&] { return std::string(what) + "[" + std::to_string(k) + "]"; };
    // a wrong type or dtype is a TypeError and a layout it cannot write through a ValueError,
    // as from propagate, sis_step and mh_step (was a ValueError "particles[1] dtype is float32")
    if (!(py::isinstance<py::array>(h) &&
          bind::is_dtype<double>(py::reinterpret_borrow<py::array>(h).dtype()) &&
          (py::reinterpret_borrow<py::array>(h).flags() & py::array::c_style) != 0 &&
          py::reinterpret_borrow<py::array>(h).writeable()))
        bind::inplace_f64(h, fn, name().c_str(), cols == 0 ? 1 : 2);  // throws, naming it
    const auto a = py::reinterpret_borrow<py::array>(h);
    if (cols == 0) {
        if (!(a.ndim() == 1 && (rows < 0 || a.shape(0) == rows)))
            fail(fn, name() + " must have shape (N,), N the particles' rows");
    } else if (!(a.ndim() == 2 && a.shape(1) == cols && (rows < 0 || a.shape(0) == rows))) {
        fail(fn, name() + " must have shape (" +
                     (rows < 0 ? std::string("N") : std::to_string(rows)) + ", " +
                     std::to_string(cols) + ")");
    }
    return py::reinterpret_borrow<py::array_t<double>>(a);
}

}  // namespace

void register_filter(py::module_& m) {
    m.def(
        "propagate",
        [](const py::object& particles_in, Eigen::Ref<const RowMatrixXd> noise,
           const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& sigma,
           double s_min, double s_max, bool use_means, const Eigen::Vector3d& mean_prev,
           const Eigen::Vector3d& mean_prev2) {
            // written in place: checked here, one line (was pybind11's list of signatures)
            Eigen::Map<RowMatrixXd> particles =
                bind::inplace_matrix(particles_in, "propagate", "particles");
            const Ar2Model model = make_model(a, b, sigma, s_min, s_max, use_means);
            py::gil_scoped_release nogil;  // safe: Eigen views only
            propagate_ar2(particles, noise, model, mean_prev, mean_prev2);
        },
        py::arg("particles"), py::arg("noise"), py::arg("a"), py::arg("b"),
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
            require_weights(weights, fn, "weights", kParticleWeightsZero);
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
        [](const py::object& particles_in, const py::object& weights_in,
           const py::object& means_in, const BinnedImage& image,
           Eigen::Ref<const Eigen::VectorXd> ref, double w0, double h0,
           const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& sigma,
           double s_min, double s_max, bool use_means, double lam, const std::string& kernel,
           bool resample, std::uint64_t seed, std::uint64_t step, double min_samples) {
            // written in place: checked here, one line (was pybind11's list of signatures)
            Eigen::Map<RowMatrixXd> particles =
                bind::inplace_matrix(particles_in, "sis_step", "particles");
            Eigen::Map<Eigen::VectorXd> weights =
                bind::inplace_vector(weights_in, "sis_step", "weights");
            Eigen::Map<RowMatrixXd> means = bind::inplace_matrix(means_in, "sis_step", "means");
            SisParams prm = bind::make_step_params(w0, h0, a, b, sigma, s_min, s_max, use_means,
                                                   lam, kernel, resample, "sis_step");
            prm.min_samples = min_samples;  // checked by sis_step, with the other parameters
            SisResult r;
            {
                py::gil_scoped_release nogil;  // safe: Eigen views and the C++ image only
                r = sis_step(particles, weights, means, image.lazy_view(), ref, prm, seed, step);
            }
            return bind::step_result_dict(r);
        },
        py::arg("particles"), py::arg("weights"), py::arg("means"), py::arg("image"), py::arg("ref"), py::arg("w0"),
        py::arg("h0"), py::arg("a"), py::arg("b"), py::arg("sigma"), py::arg("s_min"),
        py::arg("s_max"), py::arg("use_means"), py::arg("lam"), py::arg("kernel"),
        py::arg("resample"), py::arg("seed"), py::arg("step"), py::arg("min_samples") = 0.0,
        "Resample, propagate, histogram, weigh, estimate; particles (N, 6), weights (N,), "
        "means (2, 3) updated in place. min_samples > 0 counts boxes of at least 4 min_samples "
        "pixels on a lattice (every k-th pixel, k = floor(sqrt(area / min_samples)), the area of "
        "the previous mean state's box).");

    m.def(
        "sis_step_batch",
        [](const py::list& particles, const py::list& weights, const py::list& means,
           const BinnedImage& image, const py::list& refs,
           Eigen::Ref<const Eigen::VectorXd> w0, Eigen::Ref<const Eigen::VectorXd> h0,
           const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& sigma,
           double s_min, double s_max, bool use_means, double lam, const std::string& kernel,
           bool resample, const std::vector<std::uint64_t>& seeds,
           const std::vector<std::uint64_t>& steps, double min_samples) {
            const char* fn = "sis_step_batch";
            const auto k = static_cast<py::ssize_t>(particles.size());
            require(static_cast<py::ssize_t>(weights.size()) == k &&
                        static_cast<py::ssize_t>(means.size()) == k &&
                        static_cast<py::ssize_t>(refs.size()) == k && w0.size() == k &&
                        h0.size() == k && static_cast<py::ssize_t>(seeds.size()) == k &&
                        static_cast<py::ssize_t>(steps.size()) == k,
                    fn, "particles, weights, means, refs, w0, h0, seeds and steps must all have "
                        "one entry per object");
            // Every array is checked with the GIL held, before any object steps: a bad entry
            // changes nothing.
            std::vector<py::array_t<double>> keep;
            keep.reserve(static_cast<size_t>(4 * k));
            std::vector<SisParams> prms;
            prms.reserve(static_cast<size_t>(k));
            for (py::ssize_t i = 0; i < k; ++i) {
                auto p = batch_item(particles[i], "particles", i, -1, kParticleCols);
                const py::ssize_t n = p.shape(0);
                keep.push_back(p);
                keep.push_back(batch_item(weights[i], "weights", i, n, 0));
                keep.push_back(batch_item(means[i], "means", i, 2, kStateDim));
                // cast (one copy) when not float64, but complex or text refused, as for sis_step
                const py::handle ri = refs[i];
                if (!(py::isinstance<py::array>(ri) &&
                      bind::real_kind(py::reinterpret_borrow<py::array>(ri).dtype().kind())))
                    bind::check_real(ri, fn, "refs[" + std::to_string(i) + "]");
                auto r = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(ri);
                if (!(r && r.ndim() == 1))
                    fail(fn, "refs[" + std::to_string(i) + "] must be a (B,) float array");
                keep.push_back(r);
                prms.push_back(bind::make_step_params(w0(i), h0(i), a, b, sigma, s_min, s_max,
                                                      use_means, lam, kernel, resample, fn));
                prms.back().min_samples = min_samples;
            }
            using MatMap = Eigen::Map<RowMatrixXd>;
            using VecMap = Eigen::Map<Eigen::VectorXd>;
            using ConstVecMap = Eigen::Map<const Eigen::VectorXd>;
            // ... and the values sis_step checks (particles, weights, means, the reference
            // against the image's bins), each named by its entry, once: then every object
            // steps unchecked (sis_step_checked)
            const BinImage img = image.lazy_view();
            std::vector<Eigen::VectorXd> sqrefs;
            sqrefs.reserve(static_cast<size_t>(k));
            for (py::ssize_t i = 0; i < k; ++i) {
                const auto& pa = keep[static_cast<size_t>(4 * i)];
                const auto& wa = keep[static_cast<size_t>(4 * i + 1)];
                const auto& ma = keep[static_cast<size_t>(4 * i + 2)];
                const auto& ra = keep[static_cast<size_t>(4 * i + 3)];
                try {
                    sqrefs.push_back(sis_checked(
                        Eigen::Map<const RowMatrixXd>(pa.data(), pa.shape(0), kParticleCols),
                        ConstVecMap(wa.data(), wa.shape(0)),
                        Eigen::Map<const RowMatrixXd>(ma.data(), 2, kStateDim), img,
                        ConstVecMap(ra.data(), ra.shape(0)), prms[static_cast<size_t>(i)], fn));
                } catch (const std::invalid_argument& e) {  // "fn: what" -> "fn: entry i: what"
                    const std::string what = e.what(), head = std::string(fn) + ": ";
                    fail(fn, "entry " + std::to_string(i) + ": " +
                                 (what.rfind(head, 0) == 0 ? what.substr(head.size()) : what));
                }
            }
            // columns: mean (3), map (3), map_index, ess, rho_max, rho_mean, fg_mean
            RowMatrixXd out(k, 11);
            {
                py::gil_scoped_release nogil;  // safe: raw buffers kept alive by `keep`
                // one for all objects and frames: no allocations per object or frame
                SisWorkspace& ws = thread_sis_workspace(img.n_bins);
                for (py::ssize_t i = 0; i < k; ++i) {
                    auto& pa = keep[static_cast<size_t>(4 * i)];
                    auto& wa = keep[static_cast<size_t>(4 * i + 1)];
                    auto& ma = keep[static_cast<size_t>(4 * i + 2)];
                    MatMap p(pa.mutable_data(), pa.shape(0), kParticleCols);
                    VecMap w(wa.mutable_data(), wa.shape(0));
                    MatMap mm(ma.mutable_data(), 2, kStateDim);
                    const SisResult r = sis_step_checked(
                        p, w, mm, img, sqrefs[static_cast<size_t>(i)],
                        prms[static_cast<size_t>(i)], seeds[static_cast<size_t>(i)],
                        steps[static_cast<size_t>(i)], &ws);
                    out.row(i) << r.estimate.mean.transpose(), r.estimate.map.transpose(),
                        static_cast<double>(r.estimate.map_index), r.ess, r.rho_max, r.rho_mean,
                        r.fg_mean;
                }
            }
            return out;
        },
        py::arg("particles"), py::arg("weights"), py::arg("means"), py::arg("image"),
        py::arg("refs"), py::arg("w0"), py::arg("h0"), py::arg("a"), py::arg("b"),
        py::arg("sigma"), py::arg("s_min"), py::arg("s_max"), py::arg("use_means"),
        py::arg("lam"), py::arg("kernel"), py::arg("resample"), py::arg("seeds"),
        py::arg("steps"), py::arg("min_samples") = 0.0,
        "sis_step for K objects on one image in one call (the GIL released): lists of K "
        "particles (N_k, 6), weights (N_k,), means (2, 3) updated in place, K refs; w0, h0, seeds, "
        "steps (K,). Returns (K, 11): mean (3), map (3), map_index, ess, rho_max, rho_mean, "
        "fg_mean; each row equal to sis_step's for the same object.");

    m.def(
        "reseed_batch",
        [](const py::list& particles, const py::list& weights, const py::list& means,
           Eigen::Ref<const RowMatrixXd> boxes, Eigen::Ref<const RowMatrixXd> velocities,
           Eigen::Ref<const Eigen::VectorXd> w0, Eigen::Ref<const Eigen::VectorXd> h0,
           Eigen::Ref<const RowMatrixXd> noise, double pos_sd, double s_sd, double s_min,
           double s_max) {
            const char* fn = "reseed_batch";
            const auto k = static_cast<py::ssize_t>(particles.size());
            require(static_cast<py::ssize_t>(weights.size()) == k &&
                        static_cast<py::ssize_t>(means.size()) == k && boxes.rows() == k &&
                        velocities.rows() == k && w0.size() == k && h0.size() == k,
                    fn, "particles, weights, means, boxes, velocities, w0 and h0 must all have "
                        "one entry per object");
            require(boxes.cols() == 4, fn, "boxes cols", boxes.cols(), "4 (cx, cy, w, h)");
            require(velocities.cols() == 2, fn, "velocities cols", velocities.cols(),
                    "2 (vx, vy)");
            require(noise.cols() == kStateDim, fn, "noise cols", noise.cols(), 3);
            require_finite(boxes, fn, "boxes");
            require_finite(velocities, fn, "velocities");
            require_finite(noise, fn, "noise");
            require((boxes.col(2).array() > 0.0).all() && (boxes.col(3).array() > 0.0).all(),
                    fn, "boxes must have w, h > 0");
            require(w0.allFinite() && h0.allFinite() && (w0.array() > 0.0).all() &&
                        (h0.array() > 0.0).all(),
                    fn, "w0 and h0 must be finite and > 0");
            require(std::isfinite(pos_sd) && pos_sd >= 0.0 && std::isfinite(s_sd) && s_sd >= 0.0,
                    fn, "pos_sd and s_sd must be finite and >= 0");
            require(std::isfinite(s_min) && std::isfinite(s_max) && s_min > 0.0 && s_min <= s_max,
                    fn, "scale bounds must satisfy 0 < s_min <= s_max");
            // every array checked with the GIL held, before any object is re-seeded
            std::vector<py::array_t<double>> keep;
            keep.reserve(static_cast<size_t>(3 * k));
            Index rows = 0;
            for (py::ssize_t i = 0; i < k; ++i) {
                auto p = batch_item(particles[i], "particles", i, -1, kParticleCols, fn);
                const py::ssize_t n = p.shape(0);
                require(n > 0, fn, "particles rows", n, ">= 1");
                rows += n;
                keep.push_back(p);
                keep.push_back(batch_item(weights[i], "weights", i, n, 0, fn));
                keep.push_back(batch_item(means[i], "means", i, 2, kStateDim, fn));
            }
            require(noise.rows() == rows, fn, "noise rows", noise.rows(),
                    "the particles' rows of all objects together");
            using MatMap = Eigen::Map<RowMatrixXd>;
            using VecMap = Eigen::Map<Eigen::VectorXd>;
            {
                py::gil_scoped_release nogil;  // safe: raw buffers kept alive by `keep`
                Index at = 0;
                for (py::ssize_t i = 0; i < k; ++i) {
                    auto& pa = keep[static_cast<size_t>(3 * i)];
                    auto& wa = keep[static_cast<size_t>(3 * i + 1)];
                    auto& ma = keep[static_cast<size_t>(3 * i + 2)];
                    const Index n = pa.shape(0);
                    reseed_particles(MatMap(pa.mutable_data(), n, kParticleCols),
                                     VecMap(wa.mutable_data(), n),
                                     MatMap(ma.mutable_data(), 2, kStateDim),
                                     boxes.row(i).transpose(), velocities.row(i).transpose(),
                                     w0(i), h0(i), noise.middleRows(at, n), pos_sd, s_sd, s_min,
                                     s_max);
                    at += n;
                }
            }
        },
        py::arg("particles"), py::arg("weights"), py::arg("means"), py::arg("boxes"),
        py::arg("velocities"), py::arg("w0"), py::arg("h0"), py::arg("noise"),
        py::arg("pos_sd"), py::arg("s_sd"), py::arg("s_min"), py::arg("s_max"),
        "Re-seed K particle sets around their boxes in place: lists of K particles (N_k, 6), "
        "weights (N_k,), means (2, 3); boxes (K, 4) cx, cy, w, h; velocities (K, 2); w0, h0 "
        "(K,); noise (sum N_k, 3) N(0, 1), object after object.");
}
