// One fused step of a sequential-importance-sampling colour particle filter (the first paper's
// method 1, eq. 3-4 with the dynamic model as proposal, so w_t ~ p(z_t | x_t)):
//   resample (systematic) -> propagate (AR2) -> histogram per particle -> weigh -> estimate.
#pragma once

#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

#include "histogram.hpp"
#include "integral_histogram.hpp"
#include "likelihood.hpp"
#include "propagate.hpp"
#include "resample.hpp"
#include "rng.hpp"

namespace pftrack {

struct SisResult {
    Estimate estimate;
    double ess = 0.0;       // effective sample size 1 / sum w^2 of the new weights
    double rho_max = 0.0;   // best Bhattacharyya coefficient among the particles
    double rho_mean = 0.0;  // weight-averaged coefficient: how well the track is explained
    double fg_mean = 0.0;   // weight-averaged counted pixels (foreground) per particle box
};

/// Checks shared by sis_step and mh_step: particles (N, 6) finite and within the boxes'
/// +-1e9 px (pftrack._check.MAX_COORD: a filter's state is a box), weights (N,) valid, means
/// (2, 3) finite.
inline void check_particle_set(const Eigen::Ref<const RowMatrixXd>& particles,
                               const Eigen::Ref<const Eigen::VectorXd>& weights,
                               const Eigen::Ref<const RowMatrixXd>& means, const char* fn) {
    // one pass without early exit when all is well (|x| < 1e9 is false for NaN and inf); the
    // checks that name the first bad value (three passes) only when it is not
    bool within = particles.rows() > 0 && particles.cols() == kParticleCols;
    for (Index i = 0; within && i < particles.rows(); ++i) {
        const double* row = particles.row(i).data();
        bool ok = true;
        for (int d = 0; d < kParticleCols; ++d) ok &= std::abs(row[d]) < 1e9;
        within = ok;
    }
    if (!within) {
        check_particles(particles, fn);
        require_bounded(particles, 1e9, fn, "particles");
    }
    require(weights.size() == particles.rows(), fn, "weights size", weights.size(),
            particles.rows());
    require_weights(weights, fn, "weights", kParticleWeightsZero);
    require(means.rows() == 2 && means.cols() == kStateDim, fn,
            "means must be (2, 3): particle-set means at t-1 and t-2");
    require_finite(means, fn, "means");
}

/// Systematic resampling of the rows of `particles` by `weights`, with the stream's uniform of
/// index 2^64 - 1 (outside the range the normals use). Weights are left to the caller.
/// `kept`: scratch for the rows kept (resized to the particles' shape).
inline void resample_systematic_in_place(Eigen::Ref<RowMatrixXd> particles,
                                         const Eigen::Ref<const Eigen::VectorXd>& weights,
                                         const CounterRng& rng, RowMatrixXd& kept) {
    const IndexVector idx = systematic_resample(weights, rng.uniform(~std::uint64_t(0)));
    const Index n = particles.rows();
    kept.resize(n, kParticleCols);
    // rows of kParticleCols doubles copied as bytes: the same values, where Eigen's row
    // assignment through a Ref with an outer stride cost 0.15 M instructions of the bench's
    // 11.8 M an update (docs/results.md, "Cost of update at stop 73")
    constexpr size_t kRowBytes = kParticleCols * sizeof(double);
    const Index ld = particles.outerStride();
    double* rows = particles.data();
    for (Index i = 0; i < n; ++i)
        std::memcpy(kept.data() + i * kParticleCols, rows + idx(i) * ld, kRowBytes);
    if (ld == kParticleCols) {
        std::memcpy(rows, kept.data(), static_cast<size_t>(n) * kRowBytes);
    } else {
        for (Index i = 0; i < n; ++i)
            std::memcpy(rows + i * ld, kept.data() + i * kParticleCols, kRowBytes);
    }
}

inline void resample_systematic_in_place(Eigen::Ref<RowMatrixXd> particles,
                                         const Eigen::Ref<const Eigen::VectorXd>& weights,
                                         const CounterRng& rng) {
    RowMatrixXd kept;
    resample_systematic_in_place(particles, weights, rng, kept);
}

struct SisParams {
    Ar2Model model;
    double lambda = 20.0;
    Kernel kernel = Kernel::kUniform;
    double w0 = 1.0;  // base box size: box = (cx, cy, s*w0, s*h0)
    double h0 = 1.0;
    bool resample = true;
    // Count each box on a lattice that keeps at least this many points of the box of the
    // previous mean state (lattice_step); 0: every pixel.
    double min_samples = 0.0;

    void validate(const char* fn) const {
        model.validate(fn);
        check_lambda(lambda, fn);
        require(std::isfinite(w0) && std::isfinite(h0) && w0 > 0.0 && h0 > 0.0, fn,
                "base box size (w0, h0) must be finite and > 0");
        require(std::isfinite(min_samples) && min_samples >= 0.0, fn,
                "min_samples must be finite and >= 0");
    }
};

/// sis_step's checks of one object's values (`fn` names it in the errors): the square root
/// of its reference histogram, which the step reads.
inline Eigen::VectorXd sis_checked(const Eigen::Ref<const RowMatrixXd>& particles,
                                   const Eigen::Ref<const Eigen::VectorXd>& weights,
                                   const Eigen::Ref<const RowMatrixXd>& means, const BinImage& img,
                                   const Eigen::Ref<const Eigen::VectorXd>& ref,
                                   const SisParams& prm, const char* fn) {
    check_particle_set(particles, weights, means, fn);
    prm.validate(fn);
    check_bin_image(img, fn);
    return sqrt_reference(ref, img.n_bins, fn);
}

/// Scratch space that successive steps on images of `n_bins` bins reuse (sis_step_batch: one
/// for all objects of the frame): the box counts', and the per-particle arrays', resized per
/// step (no allocation when the particle count stays).
struct SisWorkspace {
    explicit SisWorkspace(int n_bins) : scratch(n_bins), table(n_bins) {}
    HistogramScratch scratch;
    IntegralHistogram table;
    RowMatrixXd kept, boxes;  // resampled rows; particle boxes (cx, cy, w, h)
    Eigen::VectorXd rho, counted, logw;
};

/// The calling thread's workspace for images of `n_bins` bins, kept from call to call: one
/// made per call (per frame, in sis_step_batch) allocated its table anew, up to megabytes.
inline SisWorkspace& thread_sis_workspace(int n_bins) {
    thread_local std::unique_ptr<SisWorkspace> ws;
    if (!ws || ws->table.n_bins() != n_bins) ws = std::make_unique<SisWorkspace>(n_bins);
    return *ws;
}

/// sis_step of values `sis_checked` accepted (`sqref`: what it returned). `ws`: scratch space
/// of the caller's for img.n_bins bins, else the thread's (thread_sis_workspace).
inline SisResult sis_step_checked(Eigen::Ref<RowMatrixXd> particles,
                                  Eigen::Ref<Eigen::VectorXd> weights,
                                  Eigen::Ref<RowMatrixXd> means, const BinImage& img,
                                  const Eigen::VectorXd& sqref, const SisParams& prm,
                                  std::uint64_t seed, std::uint64_t step,
                                  SisWorkspace* ws = nullptr) {
    if (ws == nullptr || ws->table.n_bins() != img.n_bins) ws = &thread_sis_workspace(img.n_bins);
    const char* fn = "sis_step";
    const Index n = particles.rows();
    const CounterRng rng(seed, step);
    // 1. resample
    if (prm.resample) {
        resample_systematic_in_place(particles, weights, rng, ws->kept);
        weights.setConstant(1.0 / static_cast<double>(n));
    }
    // 2. propagate
    const Eigen::Vector3d m1 = means.row(0).transpose();
    const Eigen::Vector3d m2 = means.row(1).transpose();
    double w[kStateDim];
    for (Index i = 0; i < n; ++i) {
        for (int d = 0; d < kStateDim; ++d)
            w[d] = rng.normal(static_cast<std::uint64_t>(i) * kStateDim + static_cast<std::uint64_t>(d));
        ar2_step(particles.row(i).data(), w, prm.model, m1.data(), m2.data());
    }
    // 3-4. histogram and weigh: log w_i = log w_i(resampled) - lambda D_i^2
    //    (the particles' boxes overlap: box_coefficients may count them from one integral
    //    histogram of their union)
    RowMatrixXd& boxes = ws->boxes;
    boxes.resize(n, 4);
    double* box = boxes.data();  // written in place (a comma initialiser a row cost more)
    for (Index i = 0; i < n; ++i, box += 4) {
        const double* row = particles.row(i).data();
        box[0] = row[0];
        box[1] = row[1];
        box[2] = row[2] * prm.w0;
        box[3] = row[2] * prm.h0;
    }
    //    Large boxes are counted on a lattice, one step for all particles (from the box of the
    //    previous mean state): the cost per particle stays near min_samples points.
    const Index lattice = lattice_step(m1(2) * prm.w0, m1(2) * prm.h0, prm.min_samples);
    Eigen::VectorXd &rho = ws->rho, &counted = ws->counted, &logw = ws->logw;
    rho.resize(n);
    counted.resize(n);
    logw.resize(n);
    box_coefficients(img, boxes, sqref.data(), prm.kernel, BoxPath::kAuto, rho.data(),
                     counted.data(), lattice, &ws->scratch, &ws->table);
    //    resampled, every weight is 1/N: one log for all (the same call, so the same bits)
    const double log_uniform = prm.resample ? std::log(weights(0)) : 0.0;
    for (Index i = 0; i < n; ++i) {
        const double d = bhattacharyya_distance_from_rho(rho(i));
        logw(i) = (prm.resample ? log_uniform : std::log(weights(i))) - prm.lambda * d * d;
    }
    normalise_log_weights(logw, fn);
    weights = logw;
    // 5. estimate
    SisResult r;
    r.estimate = estimate_state(particles, weights);
    r.ess = 1.0 / weights.squaredNorm();
    r.rho_max = rho.maxCoeff();
    r.rho_mean = weights.dot(rho);
    r.fg_mean = weights.dot(counted);
    means.row(1) = means.row(0);
    means.row(0) = r.estimate.mean.transpose();
    return r;
}

/// Advances one particle set by one frame. `particles` (N, 6), `weights` (N,) and `means` (2, 3):
/// rows m_{t-1}, m_{t-2}) are updated in place. Draws come from CounterRng(seed, step).
inline SisResult sis_step(Eigen::Ref<RowMatrixXd> particles, Eigen::Ref<Eigen::VectorXd> weights,
                          Eigen::Ref<RowMatrixXd> means, const BinImage& img,
                          const Eigen::Ref<const Eigen::VectorXd>& ref, const SisParams& prm,
                          std::uint64_t seed, std::uint64_t step) {
    const Eigen::VectorXd sqref = sis_checked(particles, weights, means, img, ref, prm, "sis_step");
    return sis_step_checked(particles, weights, means, img, sqref, prm, seed, step);
}

}  // namespace pftrack
