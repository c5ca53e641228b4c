// Resampling: indices of the particles kept, from weights and uniform draws made by the caller.
// Weights need not sum to 1. The CDF's last value is set to exactly 1 and every index is clamped
// to N-1, so round-off can never index past the end.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
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
/// The nonzero entries increase with k, so the running maximum is "the last nonzero entry",
/// selected with a mask: a compare-and-branch would mispredict on about half the entries (the
/// branch predictor only hides this when the very same input is resampled again and again).
inline void firsts_to_indices(int* idx, Index n) {
    std::uint32_t run = 0;
    for (Index i = 0; i < n; ++i) {
        const auto v = static_cast<std::uint32_t>(idx[i]);
        const std::uint32_t keep = 0u - static_cast<std::uint32_t>(v == 0);  // all ones if v == 0
        run = v | (run & keep);
        idx[i] = static_cast<int>(run);
    }
}

/// The first position p_k = (k + u0) / N at or above cdf[j] = acc / total is k = ceil(t),
/// t = N acc / total - u0 > -1, unless t lies within `margin` of an integer. Returns false in
/// that case (the caller settles it exactly); else sets k (k = N: no position reaches cdf[j]).
struct FirstPosition {
    double scale;       // N / total (or an estimate of it)
    double u1;          // u0 - 1: t + 1 in one subtraction
    double half_width;  // 0.5 - margin
    bool operator()(double acc, Index& k) const {
        const double t1 = acc * scale - u1;               // t + 1 > 0
        k = static_cast<Index>(t1);                       // floor(t + 1) = ceil(t) off integers
        const double frac = t1 - static_cast<double>(k);  // in [0, 1)
        return std::abs(frac - 0.5) < half_width;
    }
};

/// Exact first position at or above cdf[j] = acc / total by comparing p_k with it (what
/// numpy.searchsorted does), starting from the estimate `guess`; stores j + 1 there (max with
/// what is there: the store order is then free).
inline void settle_first(Index j, double acc, double total, double u0, Index guess, Index n,
                         int* idx) {
    const double dn = static_cast<double>(n);
    const double c = acc / total;  // the reference's cdf[j]
    const auto p = [&](Index i) { return (static_cast<double>(i) + u0) / dn; };
    Index k = std::min<Index>(std::max<Index>(guess, 0), n);
    while (k > 0 && p(k - 1) >= c) --k;
    while (k < n && p(k) < c) ++k;
    if (k < n) idx[k] = std::max(idx[k], static_cast<int>(j + 1));
}

/// The counting pass of systematic_resample with the exact total: for each j < N-1 stores j + 1
/// at idx[K_j], K_j = #{i : p_i < cdf[j]} the first position p_i = (i + u0) / N at or above
/// cdf[j] = acc[j] / total, acc the running sum of x (K_j = N: none, nothing stored). The
/// stores go in order of j, so each idx[k] ends with the largest j. `idx` holds N zeros on entry;
/// `x` is contiguous (Eigen::Ref<const VectorXd> has unit inner stride).
PFTRACK_NOINLINE inline void systematic_firsts_exact(const double* x, Index n, double total,
                                                     double u0, double margin, int* idx) {
    const FirstPosition first{static_cast<double>(n) / total, u0 - 1.0, 0.5 - margin};
    double acc = 0.0;
    for (Index j = 0; j + 1 < n; ++j) {
        acc += x[j];  // the same running sum, in the same order, as numpy.cumsum
        Index k;
        if (!first(acc, k))
            settle_first(j, acc, total, u0, k, n, idx);  // rare: within round-off of an integer
        else if (k < n)
            idx[k] = static_cast<int>(j + 1);
    }
}

/// The same counting pass without first paying for the exact total (a sequential sum, bound by
/// the add latency): the j < N-1 are split into four quarters run side by side, each with its
/// own running sum started from `offsets` (sums of the earlier quarters), and `total` is an
/// estimate. Sums of non-negative terms in any order are within gamma_N = N eps/(1 - N eps) of
/// the exact value, so t moves by at most ~4 eps N (N + 1), which `margin` covers; the rare j
/// near an integer wait in a short list for one exact sequential pass at the end. Returns false
/// if that list overflows (the caller redoes it all with the exact total).
PFTRACK_NOINLINE inline bool systematic_firsts_split(const double* x, Index n, Index quarter,
                                                     const double* offsets, double total,
                                                     double u0, double margin, int* idx) {
    constexpr int kMaxDeferred = 64;
    Index deferred[kMaxDeferred];
    int n_deferred = 0;
    const FirstPosition first{static_cast<double>(n) / total, u0 - 1.0, 0.5 - margin};
    const auto step = [&](Index j, double acc) {
        Index k;
        if (!first(acc, k)) {
            if (n_deferred == kMaxDeferred) return false;
            deferred[n_deferred++] = j;
        } else if (k < n) {
            idx[k] = static_cast<int>(j + 1);
        }
        return true;
    };
    const Index L = quarter;
    double a0 = offsets[0], a1 = offsets[1], a2 = offsets[2], a3 = offsets[3];
    bool ok = true;
    for (Index m = 0; m < L; ++m) {
        a0 += x[m];
        a1 += x[L + m];
        a2 += x[2 * L + m];
        a3 += x[3 * L + m];
        ok &= step(m, a0);
        ok &= step(L + m, a1);
        ok &= step(2 * L + m, a2);
        ok &= step(3 * L + m, a3);
    }
    for (Index j = 4 * L; j + 1 < n; ++j) {  // the last quarter's tail, after everything else
        a3 += x[j];
        ok &= step(j, a3);
    }
    if (!ok) return false;
    // Quarters ran side by side, so at the one position where quarter q's first store and an
    // earlier quarter's last stores can meet, the earlier (smaller) j may have landed last:
    // put back quarter q's largest j for its first position.
    for (int q = 1; q < 4; ++q) {
        double acc = offsets[q];
        Index kf = -1;
        int v = 0;
        for (Index j = q * L; j < (q + 1) * L; ++j) {
            acc += x[j];
            Index k;
            if (!first(acc, k)) continue;  // deferred: settled below
            if (k >= n || (kf >= 0 && k != kf)) break;
            kf = k;
            v = static_cast<int>(j + 1);
        }
        if (kf >= 0) idx[kf] = std::max(idx[kf], v);
    }
    if (n_deferred > 0) {  // exact running sums and total, in numpy.cumsum's order
        std::sort(deferred, deferred + n_deferred);
        double acc = 0.0;
        double exact[kMaxDeferred];
        int d = 0;
        for (Index j = 0; j < n; ++j) {
            acc += x[j];
            while (d < n_deferred && deferred[d] == j) exact[d++] = acc;
        }
        const double scale = static_cast<double>(n) / acc;
        for (d = 0; d < n_deferred; ++d)
            settle_first(deferred[d], exact[d], acc, u0,
                         static_cast<Index>(std::max(exact[d] * scale - u0, 0.0)), n, idx);
    }
    return true;
}

/// Sums of the four quarters [qL, (q+1)L) of x (L = quarter), each in its own running sum, and
/// of the rest; min(0, x_i) in `lowest`. A NaN or infinite x makes a sum non-finite.
PFTRACK_NOINLINE inline double quarter_sums(const double* x, Index n, Index quarter, double* sums,
                                            double& lowest) {
    const Index L = quarter;
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
    double l0 = 0.0, l1 = 0.0, l2 = 0.0, l3 = 0.0;
    for (Index m = 0; m < L; ++m) {
        s0 += x[m];
        s1 += x[L + m];
        s2 += x[2 * L + m];
        s3 += x[3 * L + m];
        l0 = std::min(l0, x[m]);
        l1 = std::min(l1, x[L + m]);
        l2 = std::min(l2, x[2 * L + m]);
        l3 = std::min(l3, x[3 * L + m]);
    }
    double rest = 0.0;
    for (Index j = 4 * L; j < n; ++j) {
        rest += x[j];
        l0 = std::min(l0, x[j]);
    }
    sums[0] = s0;
    sums[1] = s1;
    sums[2] = s2;
    sums[3] = s3;
    lowest = std::min(std::min(l0, l1), std::min(l2, l3));
    return ((s0 + s1) + (s2 + s3)) + rest;
}

/// Systematic resampling (Kitagawa 1996): positions p_i = (i + u0) / N with one draw u0 in
/// [0, 1); index i is the first j with p_i < cdf[j], cdf[j] = acc[j] / acc[N-1] with acc the
/// running sum of the weights and cdf[N-1] = 1, clamped to N-1. The same result as
/// numpy.searchsorted(cdf, p, side="right") (and filterpy's loop), in O(N) without a
/// data-dependent branch per particle: the first position at or above cdf[j] is
/// ceil(N cdf[j] - u0), estimated with a multiply and settled by exact comparisons of p_i with
/// cdf[j] only when the estimate lies within round-off of an integer (practically never). Up to
/// N ~ 65 000 the pass runs in four independent quarters on estimated sums
/// (systematic_firsts_split); larger N (whose margin would be too wide), or a list overflow,
/// take the exact sequential total first (systematic_firsts_exact).
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
    // p_k >= cdf[j]); estimated sums add <= ~4 eps N (N + 1). Margins: 2.5x those.
    const double margin_exact = 16.0 * kEps * (dn + 4.0);
    const double margin_split = 10.0 * kEps * (dn + 3.0) * (dn + 3.0);
    const Index quarter = (n - 1) / 4;
    if (quarter >= 16 && margin_split < 1e-5) {
        double sums[4], lowest = 0.0;
        const double total = quarter_sums(x, n, quarter, sums, lowest);
        const double offsets[4] = {0.0, sums[0], sums[0] + sums[1], (sums[0] + sums[1]) + sums[2]};
        if (lowest >= 0.0 && total > 0.0 && dn / total <= kMax) {
            if (systematic_firsts_split(x, n, quarter, offsets, total, u0, margin_split,
                                        idx.data())) {
                firsts_to_indices(idx.data(), n);
                return idx;
            }
            idx.setZero();
        }
    }
    const double total = checked_sequential_sum(weights, fn);  // throws on bad weights
    if (!(dn / total <= kMax)) {  // subnormal total: plain merge
        const auto cdf = normalised_cdf(weights, total);
        merge_positions(cdf.data(), n, n, [&](Index i) { return (static_cast<double>(i) + u0) / dn; },
                        idx.data());
        return idx;
    }
    systematic_firsts_exact(x, n, total, u0, margin_exact, idx.data());
    firsts_to_indices(idx.data(), n);
    return idx;
}

/// The counting pass of stratified_resample (positions p_i = (i + u_i) / N): stores j + 1 at
/// idx[K_j], K_j the first i with p_i >= cdf[j] = acc[j] / total, for j < N-1 in order. With
/// t = N acc / total, cdf[j] lies in stratum s = floor(t), so K_j is s or s + 1: s + 1 when
/// s + u_s < t. Both comparisons (t against the integers, s + u_s against t) are settled by
/// the estimate unless within `margin` of a tie; then exactly, as numpy.searchsorted compares.
PFTRACK_NOINLINE inline void stratified_firsts(const double* x, const double* u, Index n,
                                               double total, double margin, int* idx) {
    const double dn = static_cast<double>(n);
    const double scale = dn / total;
    const auto p = [&](Index i) { return (static_cast<double>(i) + u[i]) / dn; };
    double acc = 0.0;
    for (Index j = 0; j + 1 < n; ++j) {
        acc += x[j];  // numpy.cumsum's order
        const double t = acc * scale;                    // N cdf[j], >= 0
        const Index st = static_cast<Index>(t);          // the stratum, off integers
        const double frac = t - static_cast<double>(st);
        const Index sc = std::min<Index>(st, n - 1);     // a valid index either way
        const double d = (static_cast<double>(sc) + u[sc]) - t;  // N (p_s - cdf[j]), estimated
        Index k = st + (d < 0.0 ? 1 : 0);
        if (!(std::abs(frac - 0.5) < 0.5 - margin && std::abs(d) > margin && st < n)) {
            const double c = acc / total;  // rare: settle it exactly
            k = std::min<Index>(st, n);
            while (k > 0 && p(k - 1) >= c) --k;
            while (k < n && p(k) < c) ++k;
        }
        if (k < n) idx[k] = static_cast<int>(j + 1);  // K is nondecreasing in j
    }
}

/// Stratified resampling: positions (i + u_i) / N, one draw per stratum. The same result as
/// numpy.searchsorted(cdf, positions, side="right") clamped to N-1, by the counting pass above
/// (no data-dependent branch per particle) and firsts_to_indices.
inline IndexVector stratified_resample(const Eigen::Ref<const Eigen::VectorXd>& weights,
                                       const Eigen::Ref<const Eigen::VectorXd>& u) {
    const char* fn = "stratified_resample";
    constexpr double kEps = std::numeric_limits<double>::epsilon();
    const Index n = weights.size();
    const double total = checked_sequential_sum(weights, fn);  // throws on bad weights
    require(n < std::numeric_limits<int>::max(), fn, "weights size", n, "< 2^31 - 1");
    check_uniforms(u, n, fn);
    const double dn = static_cast<double>(n);
    IndexVector idx = IndexVector::Zero(n);
    if (!(dn / total <= std::numeric_limits<double>::max())) {  // subnormal total: plain merge
        const auto cdf = normalised_cdf(weights, total);
        merge_positions(cdf.data(), n, n,
                        [&](Index i) { return (static_cast<double>(i) + u(i)) / dn; }, idx.data());
        return idx;
    }
    // t is within 3 eps (N + 1) of N acc / total, and each side of p_s >= cdf[j] within one
    // rounding: ties closer than ~5 eps (N + 2) are settled exactly (margin 3x that).
    stratified_firsts(weights.data(), u.data(), n, total, 16.0 * kEps * (dn + 4.0), idx.data());
    firsts_to_indices(idx.data(), n);
    return idx;
}

/// Index of the first cdf value >= p (binary search; numpy.searchsorted(cdf, p), filterpy's
/// search), clamped to N-1; for p = 0 the first cdf value > 0, so that a draw of exactly 0
/// (Generator.random() can return it) never picks a leading particle of weight 0 (the first
/// value >= 0 is cdf[0], whatever its weight). For p > 0 the first value >= p has weight > 0.
inline int search_cdf(const std::vector<double>& cdf, double p) {
    const auto it = p > 0.0 ? std::lower_bound(cdf.begin(), cdf.end(), p)
                            : std::upper_bound(cdf.begin(), cdf.end(), 0.0);
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
    // N w_i / sum w carries the round-off of the sum (up to about N ulps): a weight that is an
    // integer multiple of 1/N up to that round-off (1/N itself, summed N times to 1 + 1e-16)
    // must still get its copies, or equal weights would be drawn at random
    const double up = 1.0 + static_cast<double>(n + 2) * std::numeric_limits<double>::epsilon();
    for (Index i = 0; i < n; ++i) {
        const double nw = static_cast<double>(n) * weights(i) / sum;
        Index copies = static_cast<Index>(std::floor(nw * up));
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
