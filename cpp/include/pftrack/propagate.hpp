// Second-order autoregressive dynamics over a box's centre and scale (the first paper's eq. 6-8).
//
// A particle is one row of 6 numbers: the current state (cx, cy, s) and the previous one
// (cx', cy', s'). The box of a particle is (cx, cy, s*w0, s*h0) for the track's base size (w0, h0).
//   eq. 7:  x_t = A x_{t-1} + B x_{t-2} + C w_t,  w_t ~ N(0, I)     (A = 2, B = -1: constant velocity)
//   eq. 8:  x_t = A m_{t-1} + B m_{t-2} + C w_t  with m the particle-set means
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "check.hpp"
#include "types.hpp"

namespace pftrack {

constexpr int kStateDim = 3;      // cx, cy, s
constexpr int kParticleCols = 6;  // current state, then previous state

struct Ar2Model {
    Eigen::Array3d a{2.0, 2.0, 2.0};     // A, per state component
    Eigen::Array3d b{-1.0, -1.0, -1.0};  // B
    Eigen::Array3d sigma{4.0, 4.0, 0.02};  // C: noise std of cx, cy (pixels) and s
    double s_min = 0.2;                  // scale is clamped to [s_min, s_max]
    double s_max = 5.0;
    bool use_means = false;              // eq. 8 instead of eq. 7

    void validate(const char* fn) const {
        require(a.allFinite() && b.allFinite(), fn, "dynamics A and B must be finite");
        require(sigma.allFinite() && (sigma >= 0.0).all(), fn, "sigma must be finite and >= 0");
        require(std::isfinite(s_min) && std::isfinite(s_max) && s_min > 0.0 && s_min <= s_max, fn,
                "scale bounds must satisfy 0 < s_min <= s_max");
    }
};

inline void check_particles(const Eigen::Ref<const RowMatrixXd>& p, const char* fn) {
    require(p.rows() > 0, fn, "particles rows", p.rows(), ">= 1");
    require(p.cols() == kParticleCols, fn, "particles cols", p.cols(),
            "6 (cx, cy, s, previous cx, cy, s)");
    require_finite(p, fn, "particles");
}

/// One AR(2) step for particle row `row` with standard-normal draws `w` (3 values).
/// `m1`, `m2`: particle-set means at t-1 and t-2 (used when model.use_means).
inline void ar2_step(double* row, const double* w, const Ar2Model& m, const double* m1,
                     const double* m2) {
    for (int d = 0; d < kStateDim; ++d) {
        const double x1 = m.use_means ? m1[d] : row[d];
        const double x2 = m.use_means ? m2[d] : row[kStateDim + d];
        double x = m.a[d] * x1 + m.b[d] * x2 + m.sigma[d] * w[d];
        if (d == 2) x = std::clamp(x, m.s_min, m.s_max);
        row[kStateDim + d] = row[d];
        row[d] = x;
    }
}

/// Propagates every particle in place with the given standard-normal noise (N, 3).
inline void propagate_ar2(Eigen::Ref<RowMatrixXd> particles,
                          const Eigen::Ref<const RowMatrixXd>& noise, const Ar2Model& m,
                          const Eigen::Vector3d& m1, const Eigen::Vector3d& m2) {
    const char* fn = "propagate";
    check_particles(particles, fn);
    m.validate(fn);
    require(noise.rows() == particles.rows(), fn, "noise rows", noise.rows(), particles.rows());
    require(noise.cols() == kStateDim, fn, "noise cols", noise.cols(), 3);
    require_finite(noise, fn, "noise");
    require(m1.allFinite() && m2.allFinite(), fn, "particle-set means must be finite");
    for (Index i = 0; i < particles.rows(); ++i)
        ar2_step(particles.row(i).data(), noise.row(i).data(), m, m1.data(), m2.data());
}

/// Re-seeds one particle set around a box (ColourParticleFilter.reinitialise), in place.
/// `box` is (cx, cy, w, h), its scale s0 = sqrt((w / w0) (h / h0)) clamped to [s_min, s_max];
/// particle i, with the standard-normal draws noise.row(i), becomes
///   (cx + pos_sd w_i0, cy + pos_sd w_i1, s) with s = s0 + s_sd w_i2 clamped to [s_min, s_max],
///   and one velocity (vx, vy) back the previous state (cx_i - vx, cy_i - vy, s);
/// weights 1/N, means (cx, cy, s0) and (cx - vx, cy - vy, s0). The floats of the NumPy reseed
/// (tests/reference/kernels.py: reseed): each clamp is max, then min, as NumPy's.
/// Unchecked: the caller (reseed_batch's binding) checks shapes and values.
inline void reseed_particles(Eigen::Ref<RowMatrixXd> particles, Eigen::Ref<Eigen::VectorXd> weights,
                             Eigen::Ref<RowMatrixXd> means, const Eigen::Vector4d& box,
                             const Eigen::Vector2d& velocity, double w0, double h0,
                             const Eigen::Ref<const RowMatrixXd>& noise, double pos_sd,
                             double s_sd, double s_min, double s_max) {
    const double s0 = std::min(std::max(std::sqrt((box(2) / w0) * (box(3) / h0)), s_min), s_max);
    const Index n = particles.rows();
    for (Index i = 0; i < n; ++i) {
        double* row = particles.row(i).data();
        const double* w = noise.row(i).data();
        row[0] = box(0) + pos_sd * w[0];
        row[1] = box(1) + pos_sd * w[1];
        row[2] = std::min(std::max(s0 + s_sd * w[2], s_min), s_max);
        row[3] = row[0] - velocity(0);
        row[4] = row[1] - velocity(1);
        row[5] = row[2];
    }
    weights.setConstant(1.0 / static_cast<double>(n));
    means.row(0) << box(0), box(1), s0;
    means.row(1) << box(0) - velocity(0), box(1) - velocity(1), s0;
}

struct Estimate {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();  // weighted mean state
    Eigen::Vector3d map = Eigen::Vector3d::Zero();   // state of the maximum-weight particle (eq. 2)
    Index map_index = 0;
};

/// Weighted mean and maximum-weight estimates of the current state (first 3 columns).
inline Estimate estimate_state(const Eigen::Ref<const RowMatrixXd>& particles,
                               const Eigen::Ref<const Eigen::VectorXd>& weights) {
    Estimate e;
    double best = -1.0;
    double sum = 0.0;
    for (Index i = 0; i < particles.rows(); ++i) {
        const double w = weights(i);
        sum += w;
        for (int d = 0; d < kStateDim; ++d) e.mean[d] += w * particles(i, d);
        if (w > best) {
            best = w;
            e.map_index = i;
        }
    }
    e.mean /= sum;
    if (!std::isfinite(sum) || !e.mean.allFinite() || sum < std::numeric_limits<double>::min()) {
        // w * x or the sum overflowed (weights or states near 1e308), or every weight is
        // subnormal (w * x kept a few bits: 1e-3 px off): again as a convex combination,
        // sum_i c_i x_i with c_i = (w_i / w_max) / sum_j (w_j / w_max), whose partial sums
        // never exceed max |x_i|. Only then: other inputs keep their exact bits.
        const double w_max = weights.maxCoeff();
        double scaled_sum = 0.0;
        for (Index i = 0; i < particles.rows(); ++i) scaled_sum += weights(i) / w_max;
        e.mean.setZero();
        for (Index i = 0; i < particles.rows(); ++i) {
            const double c = (weights(i) / w_max) / scaled_sum;
            for (int d = 0; d < kStateDim; ++d) e.mean[d] += c * particles(i, d);
        }
    }
    e.map = particles.row(e.map_index).head<kStateDim>().transpose();
    return e;
}

}  // namespace pftrack
