// Resampling: indices of the particles kept, from weights and uniform draws made by the caller.
// Weights need not sum to 1. The CDF's last value is set to exactly 1 and every index is clamped
// to N-1, so round-off can never index past the end.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "check.hpp"
#include "types.hpp"

namespace pftrack {

using IndexVector = Eigen::Matrix<int, Eigen::Dynamic, 1>;

/// Normalised cumulative sum with cdf[N-1] == 1 exactly.
inline std::vector<double> normalised_cdf(const Eigen::Ref<const Eigen::VectorXd>& w, double sum) {
    std::vector<double> cdf(static_cast<size_t>(w.size()));
    double acc = 0.0;
    for (Index i = 0; i < w.size(); ++i) {
        acc += w(i);
        cdf[static_cast<size_t>(i)] = acc / sum;
    }
    cdf.back() = 1.0;
    return cdf;
}

inline void check_uniforms(const Eigen::Ref<const Eigen::VectorXd>& u, Index need, const char* fn) {
    require(u.size() >= need, fn, "u size", u.size(), "at least N");
    for (Index i = 0; i < need; ++i)
        require(u(i) >= 0.0 && u(i) < 1.0, fn, "u values", u(i), "in [0, 1)");
}

/// Ordered positions p_0 < p_1 < ... in [0, 1) to indices: the first i with p < cdf[i]
/// (numpy.searchsorted(cdf, p, side="right"), as filterpy's loops do), by one merge pass.
template <class Positions>
inline IndexVector merge_positions(const std::vector<double>& cdf, Index n_out, Positions pos) {
    const int last = static_cast<int>(cdf.size()) - 1;
    IndexVector idx(n_out);
    int j = 0;
    for (Index i = 0; i < n_out; ++i) {
        const double p = pos(i);
        while (j < last && cdf[static_cast<size_t>(j)] <= p) ++j;
        idx(i) = j;
    }
    return idx;
}

/// Systematic resampling (Kitagawa 1996): positions (i + u0) / N with one draw u0 in [0, 1).
inline IndexVector systematic_resample(const Eigen::Ref<const Eigen::VectorXd>& weights, double u0) {
    const char* fn = "systematic_resample";
    const double sum = require_weights(weights, fn);
    require(u0 >= 0.0 && u0 < 1.0, fn, "u0", u0, "in [0, 1)");
    const auto cdf = normalised_cdf(weights, sum);
    const Index n = weights.size();
    const double dn = static_cast<double>(n);
    return merge_positions(cdf, n, [&](Index i) { return (static_cast<double>(i) + u0) / dn; });
}

/// Stratified resampling: positions (i + u_i) / N, one draw per stratum.
inline IndexVector stratified_resample(const Eigen::Ref<const Eigen::VectorXd>& weights,
                                       const Eigen::Ref<const Eigen::VectorXd>& u) {
    const char* fn = "stratified_resample";
    const double sum = require_weights(weights, fn);
    const Index n = weights.size();
    check_uniforms(u, n, fn);
    const auto cdf = normalised_cdf(weights, sum);
    const double dn = static_cast<double>(n);
    return merge_positions(cdf, n, [&](Index i) { return (static_cast<double>(i) + u(i)) / dn; });
}

/// Index of the first cdf value >= p (binary search), clamped to N-1.
inline int search_cdf(const std::vector<double>& cdf, double p) {
    const auto it = std::lower_bound(cdf.begin(), cdf.end(), p);
    return static_cast<int>(std::min<std::ptrdiff_t>(it - cdf.begin(),
                                                     static_cast<std::ptrdiff_t>(cdf.size()) - 1));
}

/// Multinomial resampling: index i for each draw u_i, in the order of the draws
/// (filterpy.monte_carlo.multinomial_resample's semantics).
inline IndexVector multinomial_resample(const Eigen::Ref<const Eigen::VectorXd>& weights,
                                        const Eigen::Ref<const Eigen::VectorXd>& u) {
    const char* fn = "multinomial_resample";
    const double sum = require_weights(weights, fn);
    const Index n = weights.size();
    check_uniforms(u, n, fn);
    const auto cdf = normalised_cdf(weights, sum);
    IndexVector idx(n);
    for (Index i = 0; i < n; ++i) idx(i) = search_cdf(cdf, u(i));
    return idx;
}

/// Residual resampling (Liu & Chen 1998): floor(N w_i) copies of each i, then the remaining
/// R = N - sum floor(N w_i) drawn multinomially from the residuals, using u_0 .. u_{R-1}.
inline IndexVector residual_resample(const Eigen::Ref<const Eigen::VectorXd>& weights,
                                     const Eigen::Ref<const Eigen::VectorXd>& u) {
    const char* fn = "residual_resample";
    const double sum = require_weights(weights, fn);
    const Index n = weights.size();
    check_uniforms(u, n, fn);
    IndexVector idx(n);
    Eigen::VectorXd residual(n);
    Index k = 0;
    for (Index i = 0; i < n; ++i) {
        const double nw = static_cast<double>(n) * weights(i) / sum;
        Index copies = static_cast<Index>(std::floor(nw));
        copies = std::min(copies, n - k);
        for (Index c = 0; c < copies; ++c) idx(k++) = static_cast<int>(i);
        residual(i) = std::max(0.0, nw - static_cast<double>(copies));
    }
    if (k < n) {
        double rsum = residual.sum();
        if (!(rsum > 0.0)) {  // round-off left nothing: fall back to the weights themselves
            residual = weights;
            rsum = sum;
        }
        const auto cdf = normalised_cdf(residual, rsum);
        for (Index j = 0; k < n; ++j) idx(k++) = search_cdf(cdf, u(j));
    }
    return idx;
}

}  // namespace pftrack
