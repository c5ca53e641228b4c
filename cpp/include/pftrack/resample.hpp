// Resampling: indices of the particles kept, from weights and uniform draws made by the caller.
// Weights need not sum to 1. The CDF's last value is set to exactly 1 and every index is clamped
// to N-1, so round-off can never index past the end.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
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

#if defined(__GNUC__) || defined(__clang__)
#define PFTRACK_NOINLINE __attribute__((noinline))
#elif defined(_MSC_VER)
#define PFTRACK_NOINLINE __declspec(noinline)
#else
#define PFTRACK_NOINLINE
#endif

/// Sum of x_0, x_1, ... added in order (the last value of numpy.cumsum); `lowest` gets
/// min(0, x_i). Kept out of line, like the loops below that redo the running sum: inlined into a
/// caller that makes calls, GCC 12 spilled the sum to the stack, putting a store-to-load round
/// trip (~6x slower) on the add chain that bounds these loops.
PFTRACK_NOINLINE inline double sequential_sum(const double* x, Index n, Index stride,
                                              double& lowest) {
    double acc = 0.0;
    double lo = 0.0;
    for (Index i = 0; i < n; ++i) {
        const double v = x[i * stride];
        lo = std::min(lo, v);
        acc += v;
    }
    lowest = lo;
    return acc;
}

/// Checks the weights without a branch per element (a NaN or infinite weight makes the sum
/// non-finite, a negative one the minimum negative) and returns their sequential sum. On bad
/// weights require_weights throws, naming the first bad one.
inline double checked_sequential_sum(const Eigen::Ref<const Eigen::VectorXd>& w, const char* fn) {
    if (w.size() == 0) fail(fn, "weights is empty");
    double lowest = 0.0;
    const double acc = sequential_sum(w.data(), w.size(), w.innerStride(), lowest);
    if (lowest >= 0.0 && acc > 0.0 && acc <= std::numeric_limits<double>::max()) return acc;
    return require_weights(w, fn);  // throws
}

inline void check_uniforms(const Eigen::Ref<const Eigen::VectorXd>& u, Index need, const char* fn) {
    require(u.size() >= need, fn, "u size", u.size(), "at least N");
    for (Index i = 0; i < need; ++i)
        require(u(i) >= 0.0 && u(i) < 1.0, fn, "u values", u(i), "in [0, 1)");
}

/// Ordered positions p_0 <= p_1 <= ... in [0, 1] to indices: the first i with p < cdf[i]
/// (numpy.searchsorted(cdf, p, side="right"), as filterpy's loops do), by one merge pass.
template <class Positions>
inline void merge_positions(const double* cdf, Index n_cdf, Index n_out, Positions pos, int* idx) {
    const Index last = n_cdf - 1;
    Index j = 0;
    for (Index i = 0; i < n_out; ++i) {
        const double p = pos(i);
        while (j < last && cdf[j] <= p) ++j;
        idx[i] = static_cast<int>(j);
    }
}

/// In place: on entry idx[k] = j + 1 for the largest j < N-1 whose cdf[j] has its first
/// position at or above it at k (0 where none). The firsts are ordered like the cdf, so the
/// nonzero entries increase with k. Then idx_i = #{j < N-1 : cdf[j] <= p_i}
/// = max_{k <= i} idx[k], which is numpy.searchsorted(cdf, p_i, side="right") clamped to N-1.
/// A branch-free running maximum: no data-dependent branch, no read-modify-write chain.
inline void firsts_to_indices(int* idx, Index n) {
    int run = 0;
    for (Index i = 0; i < n; ++i) {
        const int v = idx[i];
        run += (v - run) & -static_cast<int>(v > run);
        idx[i] = run;
    }
}

/// Sum of x_0 .. x_{n-1} in four interleaved partial sums (fast; within ~(n/4 + 2) eps of the
/// sequential sum's value, relatively, for x >= 0), and min(0, x_i) in `lowest`. A NaN or
/// infinite x makes the sum non-finite.
PFTRACK_NOINLINE inline double blocked_sum(const double* x, Index n, double& lowest) {
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
    double l0 = 0.0, l1 = 0.0, l2 = 0.0, l3 = 0.0;
    Index i = 0;
    for (; i + 4 <= n; i += 4) {
        s0 += x[i];
        s1 += x[i + 1];
        s2 += x[i + 2];
        s3 += x[i + 3];
        l0 = std::min(l0, x[i]);
        l1 = std::min(l1, x[i + 1]);
        l2 = std::min(l2, x[i + 2]);
        l3 = std::min(l3, x[i + 3]);
    }
    for (; i < n; ++i) {
        s0 += x[i];
        l0 = std::min(l0, x[i]);
    }
    lowest = std::min(std::min(l0, l1), std::min(l2, l3));
    return (s0 + s1) + (s2 + s3);
}

/// The counting pass of systematic_resample: for each j < N-1 stores j + 1 at idx[K_j], where
/// K_j = #{i : p_i < cdf[j]} is the first position p_i = (i + u0) / N at or above
/// cdf[j] = acc[j] / total, acc the running sum of x (K_j = N: none, nothing stored). `idx` holds
/// N zeros on entry; `x` is contiguous (Eigen::Ref<const VectorXd> has unit inner stride).
///
/// K_j = ceil(t_j), t_j = acc[j] * N / total - u0, except within round-off of an integer, where
/// exact comparisons of p_i with cdf[j] settle it. `scale_total` is `total` (kKnown) or an
/// estimate of it whose error `margin` covers; then the exact comparisons, which need the exact
/// total (the running sum's last value), wait in a short list until the end of the pass.
/// Returns false (and leaves `idx` dirty) if that list overflows.
template <bool kKnown>
PFTRACK_NOINLINE bool systematic_firsts(const double* x, Index n, double scale_total, double u0,
                                        double margin, int* idx) {
    constexpr int kMaxDeferred = 64;
    Index deferred_j[kMaxDeferred];
    double deferred_acc[kMaxDeferred];
    int n_deferred = 0;
    const double dn = static_cast<double>(n);
    const double scale = dn / scale_total;  // finite: checked by the caller
    const double half_width = 0.5 - margin;
    const double u1 = u0 - 1.0;  // t + 1 in one subtraction
    const auto settle = [&](Index j, double acc, double total) {
        const double c = acc / total;  // the reference's cdf[j]
        const auto p = [&](Index i) { return (static_cast<double>(i) + u0) / dn; };
        Index k = std::min<Index>(static_cast<Index>(std::max(acc * scale - u1, 0.0)), n);
        while (k > 0 && p(k - 1) >= c) --k;
        while (k < n && p(k) < c) ++k;
        if (k < n) idx[k] = std::max(idx[k], static_cast<int>(j + 1));
    };
    double acc = 0.0;
    for (Index j = 0; j + 1 < n; ++j) {
        acc += x[j];  // the same running sum, in the same order, as numpy.cumsum
        // real threshold: p_k >= cdf[j]  <=>  k >= t = N acc / total - u0, and t > -1
        const double t1 = acc * scale - u1;               // t + 1 > 0
        const Index k = static_cast<Index>(t1);           // floor(t + 1) = ceil(t) off integers
        const double frac = t1 - static_cast<double>(k);  // in [0, 1)
        if (!(std::abs(frac - 0.5) < half_width)) {       // rare: settle it exactly
            if (kKnown) {
                settle(j, acc, scale_total);
            } else {
                if (n_deferred == kMaxDeferred) return false;
                deferred_j[n_deferred] = j;
                deferred_acc[n_deferred++] = acc;
            }
        } else if (k < n) {
            idx[k] = static_cast<int>(j + 1);
        }
    }
    if (!kKnown) {
        const double total = acc + x[n - 1];  // the sequential total
        // |t' - t| <= (N + 1)(|total / scale_total - 1| + 3 eps), plus the comparison's own
        // round-off 6 eps (N + 3): the margin must cover twice that, or the pass is redone.
        constexpr double kEps = std::numeric_limits<double>::epsilon();
        const double dev = (dn + 1.0) * (std::abs(total / scale_total - 1.0) + 3.0 * kEps) +
                           6.0 * kEps * (dn + 3.0);
        if (!(2.0 * dev <= margin)) return false;
        for (int d = 0; d < n_deferred; ++d) settle(deferred_j[d], deferred_acc[d], total);
    }
    return true;
}

/// Systematic resampling (Kitagawa 1996): positions p_i = (i + u0) / N with one draw u0 in
/// [0, 1); index i is the first j with p_i < cdf[j], cdf[j] = acc[j] / acc[N-1] with acc the
/// running sum of the weights and cdf[N-1] = 1, clamped to N-1. The same result as
/// numpy.searchsorted(cdf, p, side="right") (and filterpy's loop), computed without a
/// data-dependent branch per particle (see systematic_firsts). The exact total, the running
/// sum's last value, is only known at the end of that pass, so for N up to ~40 000 the pass runs on
/// a fast blocked estimate of it (with a margin for the difference) instead of first paying a
/// second add-latency-bound pass; larger N, or a failed check, use the exact total.
inline IndexVector systematic_resample(const Eigen::Ref<const Eigen::VectorXd>& weights, double u0) {
    const char* fn = "systematic_resample";
    constexpr double kEps = std::numeric_limits<double>::epsilon();
    constexpr double kMax = std::numeric_limits<double>::max();
    require(u0 >= 0.0 && u0 < 1.0, fn, "u0", u0, "in [0, 1)");
    const Index n = weights.size();
    if (n == 0) fail(fn, "weights is empty");
    require(n < std::numeric_limits<int>::max(), fn, "weights size", n, "< 2^31 - 1");
    const double* x = weights.data();
    const double dn = static_cast<double>(n);
    IndexVector idx = IndexVector::Zero(n);
    // ceil(t) is exact at >= 6 eps (N + 3) from integers (three roundings on each side of
    // p_k >= cdf[j]); a blocked total adds <= (N + 1)(1.25 N + 5) eps. Margins: 2.5x and 2x.
    const double margin_exact = 16.0 * kEps * (dn + 4.0);
    const double margin_blocked = margin_exact + 2.0 * kEps * (dn + 1.0) * (1.25 * dn + 5.0);
    double lowest = 0.0;
    const double blocked = blocked_sum(x, n, lowest);
    if (lowest >= 0.0 && blocked > 0.0 && dn / blocked <= kMax && margin_blocked < 1e-6) {
        if (systematic_firsts<false>(x, n, blocked, u0, margin_blocked, idx.data())) {
            firsts_to_indices(idx.data(), n);
            return idx;
        }
        idx.setZero();
    }
    const double total = checked_sequential_sum(weights, fn);  // throws on bad weights
    if (!(dn / total <= kMax)) {  // subnormal total: plain merge
        const auto cdf = normalised_cdf(weights, total);
        merge_positions(cdf.data(), n, n, [&](Index i) { return (static_cast<double>(i) + u0) / dn; },
                        idx.data());
        return idx;
    }
    systematic_firsts<true>(x, n, total, u0, margin_exact, idx.data());
    firsts_to_indices(idx.data(), n);
    return idx;
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
    IndexVector idx(n);
    merge_positions(cdf.data(), n, n, [&](Index i) { return (static_cast<double>(i) + u(i)) / dn; },
                    idx.data());
    return idx;
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
