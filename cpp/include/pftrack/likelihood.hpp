// Colour likelihood: Bhattacharyya coefficient and distance between histograms, and particle
// weights p(z | x) ~ exp(-lambda D^2) (the first paper's eq. 9-10) normalised in log space.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "check.hpp"
#include "types.hpp"

namespace pftrack {

/// rho[q*, q] = sum_n sqrt(q*(n) q(n)); rows of `hists` against `ref`. `sqrt_ref` = sqrt(ref).
/// Four partial sums so that the square roots pipeline (and vectorise). A negative, NaN or
/// infinite entry makes the result non-finite (sqrt(-x) and NaN * 0 are NaN).
inline double bhattacharyya_coefficient_row(const double* hist, const double* sqrt_ref, int n) {
    double r0 = 0.0, r1 = 0.0, r2 = 0.0, r3 = 0.0;
    int k = 0;
    for (; k + 4 <= n; k += 4) {
        r0 += std::sqrt(hist[k]) * sqrt_ref[k];
        r1 += std::sqrt(hist[k + 1]) * sqrt_ref[k + 1];
        r2 += std::sqrt(hist[k + 2]) * sqrt_ref[k + 2];
        r3 += std::sqrt(hist[k + 3]) * sqrt_ref[k + 3];
    }
    for (; k < n; ++k) r0 += std::sqrt(hist[k]) * sqrt_ref[k];
    return (r0 + r1) + (r2 + r3);
}

/// sum_k sqrt(counts_k) * sqrt_ref_k over integer counts, in four partial sums.
inline double sqrt_count_dot(const std::int32_t* counts, const double* sqrt_ref, int n) {
    double r0 = 0.0, r1 = 0.0, r2 = 0.0, r3 = 0.0;
    int k = 0;
    for (; k + 4 <= n; k += 4) {
        r0 += std::sqrt(static_cast<double>(counts[k])) * sqrt_ref[k];
        r1 += std::sqrt(static_cast<double>(counts[k + 1])) * sqrt_ref[k + 1];
        r2 += std::sqrt(static_cast<double>(counts[k + 2])) * sqrt_ref[k + 2];
        r3 += std::sqrt(static_cast<double>(counts[k + 3])) * sqrt_ref[k + 3];
    }
    for (; k < n; ++k) r0 += std::sqrt(static_cast<double>(counts[k])) * sqrt_ref[k];
    return (r0 + r1) + (r2 + r3);
}

/// D = sqrt(1 - rho) (eq. 10), with rho clipped to [0, 1] against round-off.
inline double bhattacharyya_distance_from_rho(double rho) {
    return std::sqrt(std::max(0.0, 1.0 - std::min(rho, 1.0)));
}

/// Reference histogram: (B,), finite, >= 0, positive sum. Returns sqrt(ref / sum(ref)).
template <class Derived>
inline Eigen::VectorXd sqrt_reference(const Eigen::MatrixBase<Derived>& ref, Index n_bins,
                                      const char* fn) {
    require(ref.size() == n_bins, fn, "ref size", ref.size(), n_bins);
    const double sum =
        require_weights(ref, fn, "ref", "an empty reference histogram: no bin counted");
    return (ref.derived().array() / sum).sqrt().matrix();
}

/// Histogram rows: finite and >= 0.
template <class Derived>
inline void check_histograms(const Eigen::MatrixBase<Derived>& h, const char* fn) {
    for (Index i = 0; i < h.rows(); ++i)
        for (Index k = 0; k < h.cols(); ++k)
            if (!(std::isfinite(h(i, k)) && h(i, k) >= 0.0)) {
                std::ostringstream s;
                s << "hists[" << i << ", " << k << "] is " << h(i, k)
                  << ", expected a finite value >= 0";
                fail(fn, s.str());
            }
}

/// rho of each row of `hists` (K, B) against `ref` (B,), each normalised to sum 1 as `ref` is:
/// rho_i = sum_k sqrt(h_ik q_k) / sqrt(sum_k h_ik), so counts and frequencies give the same rho,
/// and a row of zeros (no pixel counted) has rho 0. `hists` maps row-major rows without a copy
/// (a column-major argument gets one temporary copy from Eigen::Ref).
/// `fn` names the caller in errors.
template <class DerivedRef>
inline Eigen::VectorXd bhattacharyya_coefficient(const Eigen::Ref<const RowMatrixXd>& h,
                                                 const Eigen::MatrixBase<DerivedRef>& ref,
                                                 const char* fn = "bhattacharyya_coefficient") {
    const Eigen::VectorXd sq = sqrt_reference(ref, h.cols(), fn);
    const int n = static_cast<int>(h.cols());
    Eigen::VectorXd rho(h.rows());
    for (Index i = 0; i < h.rows(); ++i) {
        const double* row = h.row(i).data();
        double total = 0.0;
        for (int k = 0; k < n; ++k) total += row[k];
        const double r = bhattacharyya_coefficient_row(row, sq.data(), n);
        if (!(std::isfinite(r) && std::isfinite(total))) {
            check_histograms(h, fn);  // a negative or non-finite entry: throws, naming it
            fail(fn, "hists row " + std::to_string(i) +
                         " sum is not finite (overflow: the counts are finite but their total "
                         "exceeds the largest double, 1.8e308; scale them down)");
        }
        rho(i) = total > 0.0 ? r / std::sqrt(total) : 0.0;
    }
    return rho;
}

/// Normalises log weights in place to weights summing to 1: w_i = exp(l_i - max l) / sum.
/// Entries of -inf get weight 0; all -inf is an error.
inline void normalise_log_weights(Eigen::Ref<Eigen::VectorXd> logw, const char* fn) {
    require(logw.size() > 0, fn, "log weights are empty");
    double mx = -std::numeric_limits<double>::infinity();
    for (Index i = 0; i < logw.size(); ++i) {
        require(!std::isnan(logw(i)) && logw(i) < std::numeric_limits<double>::infinity(), fn,
                "log_weights has NaN or +inf");
        mx = std::max(mx, logw(i));
    }
    require(std::isfinite(mx), fn, "all log weights are -inf");
    double sum = 0.0;
    for (Index i = 0; i < logw.size(); ++i) {
        logw(i) = std::exp(logw(i) - mx);
        sum += logw(i);
    }
    logw /= sum;
}

/// Normalised weights w ~ exp(-lambda D^2) = exp(-lambda (1 - rho)) from coefficients rho.
inline Eigen::VectorXd weights_from_rho(const Eigen::Ref<const Eigen::VectorXd>& rho, double lambda,
                                        const char* fn) {
    Eigen::VectorXd logw(rho.size());
    for (Index i = 0; i < rho.size(); ++i) {
        const double d = bhattacharyya_distance_from_rho(rho(i));
        logw(i) = -lambda * d * d;
    }
    normalise_log_weights(logw, fn);
    return logw;
}

inline void check_lambda(double lambda, const char* fn) {
    require(std::isfinite(lambda) && lambda >= 0.0, fn, "lambda", lambda, "finite and >= 0");
}

}  // namespace pftrack
