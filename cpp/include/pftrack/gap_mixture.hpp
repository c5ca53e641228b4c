// Gap recovery as a mixture over walk/stand hypotheses, for one coordinate.
//
// The path is a linear-Gaussian state-space model x_t = F x_{t-1} + w_t, w_t ~ N(0, Q), observed
// as z_t = x_t[0] + v_t, v_t ~ N(0, r), with state (position, velocity) or (position, velocity,
// acceleration). A window of observations z_0..z_{n-1} (NaN = not observed) holds the end of
// segment A at index fa and the start of segment B at fb; the gap has T = fb - fa steps.
// Hypothesis (t1, t2), 0 <= t1 < t2 <= T - 1, says the object stands still from gap step t1 + 1
// to t2 + 1: on those steps F becomes diag(1, 0, ...) (velocity and acceleration reset to 0) and
// Q becomes diag(Q[0][0], 0, ...) (the position wanders a little), and on step t2 + 1 a fresh
// velocity of variance v2 starts. (-1, -1) is "walks through the gap".
//
// For every hypothesis one Kalman filter and Rauch-Tung-Striebel smoother run over the window
// (the filter over the part before the gap, and the smoother gains where hypotheses agree, are
// shared; gap_mixture_many also shares the covariances of windows of one shape); the result is
// the smoothed positions inside the gap and the log-likelihood of the window's observations, so
// that the caller can weight the hypotheses by their evidence. For a
// linear-Gaussian model the smoothed mean inside the gap is the goal-directed path conditioned
// on the filtered states at both ends.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "pftrack/check.hpp"
#include "pftrack/parallel.hpp"
#include "pftrack/types.hpp"

namespace pftrack {

struct GapMixtureResult {
    RowMatrixXd paths;       // (H, T - 1): smoothed positions of gap steps 1..T-1
    Eigen::VectorXd loglik;  // (H,): log-likelihood of the window's observations
};

namespace detail {

constexpr double kTwoPi = 6.283185307179586;

/// Pseudo-inverse of a symmetric positive semi-definite matrix (a standing object's velocity
/// has zero predicted variance, so the RTS gain needs it).
template <int D>
Eigen::Matrix<double, D, D> psd_pinv(const Eigen::Matrix<double, D, D>& P) {
    // Walking steps: well conditioned, the closed-form inverse is exact enough and cheap.
    const double scale = P.diagonal().prod();
    if (scale > 0.0 && P.determinant() > 1e-9 * scale) return P.inverse();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, D, D>> es(P);
    const auto& ev = es.eigenvalues();
    const double tol = 1e-12 * std::max(1.0, ev.cwiseAbs().maxCoeff());
    Eigen::Matrix<double, D, 1> inv;
    for (int i = 0; i < D; ++i) inv(i) = ev(i) > tol ? 1.0 / ev(i) : 0.0;
    return es.eigenvectors() * inv.asDiagonal() * es.eigenvectors().transpose();
}

/// `gap_mixture` of G windows that share everything but their observed values: the same
/// length, the same unobserved indices (NaN), fa, fb, model and hypotheses. The covariances,
/// gains and innovation variances depend on those only, so they are computed once for the G
/// windows and only the means and log-likelihoods per window (the calibration's validation
/// gaps of a bucket have the real gap's length and context: 227 of the 300 of PETS09-S2L1's
/// offline pass fall in 6 shapes of 32-42 windows). Every window's result is the same, bit for
/// bit, as a call with it alone: the same expressions on the same operands, in the same order.
/// zs[g] is window g (the mask is read from zs[0]); outs[g] receives its result.
template <int D>
void gap_mixture_shared(const std::vector<const Eigen::VectorXd*>& zs, Index fa, Index fb,
                        const Eigen::Ref<const RowMatrixXd>& F_in,
                        const Eigen::Ref<const RowMatrixXd>& Q_in, double r,
                        const Eigen::Ref<const Eigen::VectorXd>& p0,
                        const Eigen::Ref<const Eigen::VectorXi>& t1s,
                        const Eigen::Ref<const Eigen::VectorXi>& t2s, double v2,
                        const std::vector<GapMixtureResult*>& outs) {
    using Mat = Eigen::Matrix<double, D, D>;
    using Vec = Eigen::Matrix<double, D, 1>;
    const std::size_t G = zs.size();
    const Eigen::VectorXd& mask = *zs[0];  // which values are observed: every window's
    const Index n = mask.size(), T = fb - fa, H = t1s.size();
    const Mat F = F_in, Q = Q_in;
    Mat stand = Mat::Zero();
    stand(0, 0) = 1.0;
    Mat q_stand = Mat::Zero();
    q_stand(0, 0) = Q(0, 0);
    Mat q_restart = q_stand;
    q_restart(1, 1) = v2;

    // One observation: the covariance update (shared) and, for every window g, its mean's
    // (the innovation v counted in the log-likelihood after the first D observations).
    int seen = 0;
    auto update = [&](Mat& PP, Index t, Vec* mm, std::size_t mstride, double* ll,
                      std::size_t lstride) {
        const double s = PP(0, 0) + r;
        const bool counted = seen >= D;
        const double log_s = counted ? std::log(kTwoPi * s) : 0.0;
        ++seen;
        const Vec k = PP.col(0) / s;
        for (std::size_t g = 0; g < G; ++g) {
            Vec& m = mm[g * mstride];
            const double v = (*zs[g])(t) - m(0);
            if (counted) ll[g * lstride] -= 0.5 * (log_s + v * v / s);
            m += k * v;
        }
        PP -= k * PP.row(0);
        PP = 0.5 * (PP + PP.transpose()).eval();
    };

    // Filter over the window up to the end of segment A: the same for every hypothesis.
    std::vector<Vec> m(G, Vec::Zero());
    for (std::size_t g = 0; g < G; ++g) m[g](0) = (*zs[g])(0);
    Mat P = p0.asDiagonal();
    std::vector<double> ll_prefix(G, 0.0);
    for (Index t = 0; t <= fa; ++t) {
        if (t > 0) {
            for (std::size_t g = 0; g < G; ++g) m[g] = F * m[g];
            P = F * P * F.transpose() + Q;
        }
        if (std::isfinite(mask(t))) update(P, t, m.data(), 1, ll_prefix.data(), 1);
    }
    const int seen_prefix = seen;

    for (std::size_t g = 0; g < G; ++g) *outs[g] = {RowMatrixXd(H, T - 1), Eigen::VectorXd(H)};
    const Index len = n - fa;  // window steps from the end of A on
    const auto L = static_cast<std::size_t>(len);
    // The walking filter over the rest of the window, kept: a stand hypothesis (t1, t2) is the
    // same filter up to gap step t1, so it starts from there instead of from the end of A.
    // Per window g: entries g * L + j.
    std::vector<Vec> walk_m(G * L), walk_mp(G * L);
    std::vector<double> walk_ll(G * L);
    std::vector<Mat> walk_P(L), walk_Pp(L);
    std::vector<int> walk_seen(L);
    for (std::size_t g = 0; g < G; ++g) {
        walk_m[g * L] = walk_mp[g * L] = m[g];
        walk_ll[g * L] = ll_prefix[g];
    }
    walk_P[0] = walk_Pp[0] = P;
    walk_seen[0] = seen_prefix;
    for (Index j = 1; j < len; ++j) {
        const auto u = static_cast<std::size_t>(j);
        for (std::size_t g = 0; g < G; ++g) {
            walk_m[g * L + u] = F * walk_m[g * L + u - 1];
            walk_mp[g * L + u] = walk_m[g * L + u];
            walk_ll[g * L + u] = walk_ll[g * L + u - 1];
        }
        Mat Pj = F * walk_P[u - 1] * F.transpose() + Q;
        walk_Pp[u] = Pj;
        seen = walk_seen[u - 1];
        if (std::isfinite(mask(fa + j)))
            update(Pj, fa + j, walk_m.data() + u, L, walk_ll.data() + u, L);
        walk_P[u] = Pj;
        walk_seen[u] = seen;
    }

    std::vector<Vec> mp(G * L), ms(G * L), mh(G);
    std::vector<double> ll(G);
    std::vector<Mat> Pp(L), Ps(L);
    std::vector<const Mat*> Fs(L, &F);
    // Smoother gains C_j = Ps[j] F_{j+1}' pinv(Pp[j+1]) depend on covariances only, which do not
    // depend on the observed values. Before gap step t1 every hypothesis has the walking filter's
    // (walk_gain, computed once); while standing (t1 <= j < t2) they depend on (t1, j) only
    // (stand_gain, kept for the last t1 seen: hypotheses come grouped by t1). The same
    // expression on the same operands: the same bits as computing them per hypothesis.
    std::vector<Mat> walk_gain(L), stand_gain(L);
    std::vector<char> have_walk(L, 0);
    std::vector<int> stand_t1(L, -2);
    for (Index h = 0; h < H; ++h) {
        const int t1 = t1s(h), t2 = t2s(h);
        const Index first = t1 < 0 ? len : t1 + 1;  // first step that differs from walking
        const auto f1 = static_cast<std::size_t>(first - 1);
        // Before `first` the walking filter's arrays are read directly (walk_*); only the
        // last walking step, where the hypothesis branches off, is copied.
        for (std::size_t g = 0; g < G; ++g) {
            ms[g * L + f1] = walk_m[g * L + f1];
            mh[g] = ms[g * L + f1];
            ll[g] = walk_ll[g * L + f1];
        }
        Ps[f1] = walk_P[f1];
        Mat Ph = Ps[f1];
        seen = walk_seen[f1];
        for (Index j = first; j < len; ++j) {  // window index fa + j, gap step j
            const auto u = static_cast<std::size_t>(j);
            const Mat* Fj = &F;
            const Mat* Qj = &Q;
            if (j <= t2 + 1) {
                Fj = &stand;
                Qj = j == t2 + 1 ? &q_restart : &q_stand;
            }
            Fs[u] = Fj;
            for (std::size_t g = 0; g < G; ++g) {
                mh[g] = (*Fj) * mh[g];
                mp[g * L + u] = mh[g];
            }
            Ph = (*Fj) * Ph * Fj->transpose() + *Qj;
            Pp[u] = Ph;
            if (std::isfinite(mask(fa + j))) update(Ph, fa + j, mh.data(), 1, ll.data(), 1);
            for (std::size_t g = 0; g < G; ++g) ms[g * L + u] = mh[g];
            Ps[u] = Ph;
        }
        for (Index j = len - 2; j >= 1; --j) {
            const auto u = static_cast<std::size_t>(j);
            if (j + 1 < first) {  // walking up to here: Ps[j], Pp[j + 1], Fs[j + 1] are walk's
                if (!have_walk[u]) {
                    const Mat C = walk_P[u] * F.transpose() * psd_pinv<D>(walk_Pp[u + 1]);
                    walk_gain[u] = C;
                    have_walk[u] = 1;
                }
                for (std::size_t g = 0; g < G; ++g) {
                    Vec& x = ms[g * L + u];
                    x = walk_m[g * L + u];
                    x += walk_gain[u] * (ms[g * L + u + 1] - walk_mp[g * L + u + 1]);
                }
            } else if (j < t2) {  // standing from t1 + 1 to j + 1 <= t2: depends on (t1, j)
                if (stand_t1[u] != t1) {
                    const Mat C = Ps[u] * Fs[u + 1]->transpose() * psd_pinv<D>(Pp[u + 1]);
                    stand_gain[u] = C;
                    stand_t1[u] = t1;
                }
                for (std::size_t g = 0; g < G; ++g)
                    ms[g * L + u] += stand_gain[u] * (ms[g * L + u + 1] - mp[g * L + u + 1]);
            } else {
                const Mat C = Ps[u] * Fs[u + 1]->transpose() * psd_pinv<D>(Pp[u + 1]);
                for (std::size_t g = 0; g < G; ++g)
                    ms[g * L + u] += C * (ms[g * L + u + 1] - mp[g * L + u + 1]);
            }
        }
        for (std::size_t g = 0; g < G; ++g) {
            for (Index j = 1; j < T; ++j)
                outs[g]->paths(h, j - 1) = ms[g * L + static_cast<std::size_t>(j)](0);
            outs[g]->loglik(h) = ll[g];
        }
    }
}

template <int D>
GapMixtureResult gap_mixture(const Eigen::Ref<const Eigen::VectorXd>& z, Index fa, Index fb,
                             const Eigen::Ref<const RowMatrixXd>& F_in,
                             const Eigen::Ref<const RowMatrixXd>& Q_in, double r,
                             const Eigen::Ref<const Eigen::VectorXd>& p0,
                             const Eigen::Ref<const Eigen::VectorXi>& t1s,
                             const Eigen::Ref<const Eigen::VectorXi>& t2s, double v2) {
    const Eigen::VectorXd window = z;
    GapMixtureResult out;
    gap_mixture_shared<D>({&window}, fa, fb, F_in, Q_in, r, p0, t1s, t2s, v2, {&out});
    return out;
}

}  // namespace detail

/// Checks the arguments of `gap_mixture` (see there); raises ValueError naming `fn`.
inline void check_gap_mixture(const Eigen::Ref<const Eigen::VectorXd>& z, Index fa, Index fb,
                              const Eigen::Ref<const RowMatrixXd>& F,
                              const Eigen::Ref<const RowMatrixXd>& Q, double r,
                              const Eigen::Ref<const Eigen::VectorXd>& p0,
                              const Eigen::Ref<const Eigen::VectorXi>& t1s,
                              const Eigen::Ref<const Eigen::VectorXi>& t2s, double v2,
                              const char* fn = "gap_mixture") {
    const Index n = z.size(), d = F.rows();
    require(d == 2 || d == 3, fn, "state dimension (rows of F)", d, "2 or 3");
    require(F.cols() == d, fn, "F cols", F.cols(), d);
    require(Q.rows() == d && Q.cols() == d, fn, "Q must be (d, d) like F");
    require(p0.size() == d, fn, "len(p0)", p0.size(), d);
    // messages are built only on failure (a string per call, or per hypothesis, costs more
    // than the checks)
    if (!(0 <= fa && fa < fb && fb < n))
        fail(fn, "need 0 <= fa < fb < len(z), got fa=" + std::to_string(fa) +
                     ", fb=" + std::to_string(fb) + ", len(z)=" + std::to_string(n));
    require(fb - fa >= 2, fn, "the gap has no lost step (fb - fa must be >= 2)");
    require(std::isfinite(z(0)) && std::isfinite(z(fa)) && std::isfinite(z(fb)), fn,
            "z[0], z[fa] and z[fb] must be observed (finite)");
    require_finite(F, fn, "F");
    require_finite(Q, fn, "Q");
    require_finite(p0, fn, "p0");
    require((Q - Q.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * (1.0 + Q.cwiseAbs().maxCoeff()),
            fn, "Q must be symmetric");
    for (Index i = 0; i < d; ++i)
        require(Q(i, i) >= 0.0 && p0(i) >= 0.0, fn, "Q and p0 must have non-negative variances");
    require(std::isfinite(r) && r > 0.0, fn, "r", r, "a finite value > 0");
    require(std::isfinite(v2) && v2 >= 0.0, fn, "v2", v2, "a finite value >= 0");
    require(t1s.size() == t2s.size(), fn, "len(t2s)", t2s.size(), t1s.size());
    require(t1s.size() > 0, fn, "no hypothesis given (t1s is empty)");
    const Index T = fb - fa;
    for (Index h = 0; h < t1s.size(); ++h) {
        const int t1 = t1s(h), t2 = t2s(h);
        const bool none = t1 == -1 && t2 == -1;
        if (!(none || (0 <= t1 && t1 < t2 && t2 <= T - 1)))
            fail(fn, "hypothesis " + std::to_string(h) + " is (" + std::to_string(t1) + ", " +
                         std::to_string(t2) + "), expected (-1, -1) or 0 <= t1 < t2 <= T-1 = " +
                         std::to_string(T - 1));
    }
}

/// Smoothed gap positions and window log-likelihood under each walk/stand hypothesis (see the
/// file comment). F, Q: (d, d) with d = 2 or 3; p0: (d,) prior variances of the state at z_0
/// (mean (z_0, 0, ...)); t1s, t2s: (H,) stand intervals, (-1, -1) for none; v2: variance of the
/// velocity after standing. The first d observations are not counted in the log-likelihood.
inline GapMixtureResult gap_mixture(const Eigen::Ref<const Eigen::VectorXd>& z, Index fa, Index fb,
                                    const Eigen::Ref<const RowMatrixXd>& F,
                                    const Eigen::Ref<const RowMatrixXd>& Q, double r,
                                    const Eigen::Ref<const Eigen::VectorXd>& p0,
                                    const Eigen::Ref<const Eigen::VectorXi>& t1s,
                                    const Eigen::Ref<const Eigen::VectorXi>& t2s, double v2) {
    check_gap_mixture(z, fa, fb, F, Q, r, p0, t1s, t2s, v2);
    if (F.rows() == 2) return detail::gap_mixture<2>(z, fa, fb, F, Q, r, p0, t1s, t2s, v2);
    return detail::gap_mixture<3>(z, fa, fb, F, Q, r, p0, t1s, t2s, v2);
}

/// One `gap_mixture` problem of a batch: a window of one coordinate, its gap, its hypotheses,
/// and which of the batch's models (F, Q, r, p0, v2) it uses.
struct GapMixtureJob {
    Eigen::VectorXd z;
    Index fa = 0, fb = 0;
    Index model = 0;
    Eigen::VectorXi t1s, t2s;
};

/// The models of a batch, indexed by `GapMixtureJob::model`.
struct GapMixtureModels {
    std::vector<RowMatrixXd> F, Q;
    std::vector<double> r, v2;
    std::vector<Eigen::VectorXd> p0;
};

/// `gap_mixture` of every job, on up to `threads` threads: the results are those of one
/// `gap_mixture` call per job, in the jobs' order, whatever the number of threads. Every job is
/// checked (naming it) before any runs.
inline std::vector<GapMixtureResult> gap_mixture_many(const std::vector<GapMixtureJob>& jobs,
                                                      const GapMixtureModels& models,
                                                      int threads) {
    const char* fn = "gap_mixture_many";
    const auto K = static_cast<Index>(models.r.size());
    require(models.F.size() == models.r.size() && models.Q.size() == models.r.size() &&
                models.p0.size() == models.r.size() && models.v2.size() == models.r.size(),
            fn, "F, Q, r, p0 and v2 must have one entry per model");
    require(threads >= 1, fn, "threads", threads, ">= 1");
    for (std::size_t j = 0; j < jobs.size(); ++j) {
        const GapMixtureJob& g = jobs[j];
        const std::string what = std::string(fn) + ", job " + std::to_string(j);
        if (!(0 <= g.model && g.model < K))
            fail(what.c_str(), "uses model " + std::to_string(g.model) + ", expected 0 <= model < " +
                         std::to_string(K));
        const auto k = static_cast<std::size_t>(g.model);
        check_gap_mixture(g.z, g.fa, g.fb, models.F[k], models.Q[k], models.r[k], models.p0[k],
                          g.t1s, g.t2s, models.v2[k], what.c_str());
    }
    // Jobs of one shape (window length, unobserved indices, fa, fb, model, hypotheses) share
    // their covariances (detail::gap_mixture_shared), in pieces of at most `most` jobs so that
    // the threads still get several pieces each; the results are the same whatever the pieces.
    const std::size_t most =
        std::max<std::size_t>(16, jobs.size() / (4 * static_cast<std::size_t>(threads)) + 1);
    std::vector<std::string> keys(jobs.size());
    for (std::size_t j = 0; j < jobs.size(); ++j) {
        const GapMixtureJob& g = jobs[j];
        const Index head[5] = {g.model, g.fa, g.fb, g.z.size(), g.t1s.size()};
        std::string& key = keys[j];
        key.append(reinterpret_cast<const char*>(head), sizeof(head));
        key.append(reinterpret_cast<const char*>(g.t1s.data()),
                   static_cast<std::size_t>(g.t1s.size()) * sizeof(int));
        key.append(reinterpret_cast<const char*>(g.t2s.data()),
                   static_cast<std::size_t>(g.t2s.size()) * sizeof(int));
        for (Index t = 0; t < g.z.size(); ++t) key.push_back(std::isfinite(g.z(t)) ? '1' : '0');
    }
    std::vector<std::size_t> order(jobs.size());
    for (std::size_t j = 0; j < order.size(); ++j) order[j] = j;
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return keys[a] < keys[b]; });
    std::vector<std::vector<std::size_t>> pieces;
    for (std::size_t i = 0; i < order.size(); ++i) {
        if (i == 0 || keys[order[i]] != keys[order[i - 1]] || pieces.back().size() == most)
            pieces.emplace_back();
        pieces.back().push_back(order[i]);
    }
    std::vector<GapMixtureResult> out(jobs.size());
    parallel_for(static_cast<Index>(pieces.size()), threads, [&](Index p) {
        const std::vector<std::size_t>& piece = pieces[static_cast<std::size_t>(p)];
        std::vector<const Eigen::VectorXd*> zs;
        std::vector<GapMixtureResult*> outs;
        for (const std::size_t j : piece) {
            zs.push_back(&jobs[j].z);
            outs.push_back(&out[j]);
        }
        const GapMixtureJob& g = jobs[piece[0]];
        const auto k = static_cast<std::size_t>(g.model);
        const RowMatrixXd& F = models.F[k];
        if (F.rows() == 2)
            detail::gap_mixture_shared<2>(zs, g.fa, g.fb, F, models.Q[k], models.r[k],
                                          models.p0[k], g.t1s, g.t2s, models.v2[k], outs);
        else
            detail::gap_mixture_shared<3>(zs, g.fa, g.fb, F, models.Q[k], models.r[k],
                                          models.p0[k], g.t1s, g.t2s, models.v2[k], outs);
    });
    return out;
}

/// Kalman prediction-error log-likelihood of one coordinate of many runs, for K models
/// (F_k, Q_k, r_k) with state dimension 2 or 3. Each run starts at (z_0, 0, ...) with variance
/// `big` on every state entry; its first d innovations are not counted. Runs shorter than d + 2
/// are skipped. F, Q: (K * d, d) stacked.
inline Eigen::VectorXd state_loglik_batch(const Eigen::Ref<const Eigen::VectorXd>& z,
                                          const Eigen::Ref<const Eigen::VectorXi>& lengths,
                                          const Eigen::Ref<const RowMatrixXd>& F,
                                          const Eigen::Ref<const RowMatrixXd>& Q,
                                          const Eigen::Ref<const Eigen::VectorXd>& r, double big,
                                          int threads = 1) {
    const char* fn = "state_loglik_batch";
    const Index K = r.size();
    require(K > 0, fn, "no model given (r is empty)");
    const Index d = F.cols();
    require(d == 2 || d == 3, fn, "state dimension (cols of F)", d, "2 or 3");
    require(F.rows() == K * d && Q.rows() == K * d && Q.cols() == d, fn,
            "F and Q must be (K * d, d) with K = len(r)");
    require_lengths(lengths, z.size(), fn, "lengths");
    require_finite(z, fn, "z");
    require_finite(F, fn, "F");
    require_finite(Q, fn, "Q");
    for (Index k = 0; k < K; ++k)
        require(std::isfinite(r(k)) && r(k) > 0.0, fn,
                "r must be finite and > 0 (model " + std::to_string(k) + ")");
    require(std::isfinite(big) && big > 0.0, fn, "big", big, "a finite value > 0");
    require(threads >= 1, fn, "threads", threads, ">= 1");
    Eigen::VectorXd ll(K);
    const Index longest = lengths.size() ? lengths.maxCoeff() : 0;
    auto run_all = [&](auto dim) {
        constexpr int D = decltype(dim)::value;
        using Mat = Eigen::Matrix<double, D, D>;
        using Vec = Eigen::Matrix<double, D, 1>;
        // Every run starts from the same covariance, so the innovation variances s_i and gains
        // g_i depend on the model and the step only: computed once per model, shared by the runs.
        // The models are filtered B at a time over each run: B independent chains of dependent
        // operations the CPU overlaps, each with its own operations in its own order (the same
        // bits as one model at a time); the last K % B models one at a time.
        // The blocks are independent (each writes its own ll entries): they run on up to
        // `threads` threads, each block with its own scratch.
        constexpr Index B = 4;
        const auto steps = static_cast<std::size_t>(std::max<Index>(longest, 0));
        // models k0 .. k0 + NB - 1 together (NB = B, then 1 for the last K % B models)
        auto block = [&](Index k0, auto nb) {
            constexpr Index NB = decltype(nb)::value;
            std::vector<double> S(NB * steps), logS(NB * steps);
            std::vector<Vec, Eigen::aligned_allocator<Vec>> G(NB * steps);
            Mat Fb[NB];
            Index fixed[NB];
            for (Index b = 0; b < NB; ++b) {
                const Index k = k0 + b;
                const std::size_t at = static_cast<std::size_t>(b) * steps;
                const Mat Fk = F.block(k * D, 0, D, D), Qk = Q.block(k * D, 0, D, D);
                const double rk = r(k);
                Fb[b] = Fk;
                Mat P = Mat::Identity() * big;
                // Once the filtered covariance repeats exactly, every later step repeats the
                // last one: steps from `fixed` on reuse its s, log s and gain.
                fixed[b] = longest;
                for (Index i = 0; i < longest; ++i) {
                    const auto u = at + static_cast<std::size_t>(i);
                    const Mat before = P;
                    if (i > 0) P = Fk * P * Fk.transpose() + Qk;
                    const double s = P(0, 0) + rk;
                    S[u] = s;
                    logS[u] = std::log(detail::kTwoPi * s);
                    const Vec g = P.col(0) / s;
                    G[u] = g;
                    P -= g * P.row(0);
                    P = 0.5 * (P + P.transpose()).eval();
                    if (i > 0 && P == before) {
                        fixed[b] = i;
                        break;
                    }
                }
            }
            double total[NB] = {};
            Index start = 0;
            for (Index run = 0; run < lengths.size(); ++run) {
                const Index len = lengths(run);
                const double* zz = z.data() + start;
                start += len;
                if (len < D + 2) continue;
                Vec m[NB];
                for (Index b = 0; b < NB; ++b) {
                    m[b] = Vec::Zero();
                    m[b](0) = zz[0];
                }
                for (Index i = 0; i < len; ++i) {
                    for (Index b = 0; b < NB; ++b) {
                        const auto u = static_cast<std::size_t>(b) * steps +
                                       static_cast<std::size_t>(std::min(i, fixed[b]));
                        if (i > 0) m[b] = Fb[b] * m[b];
                        const double v = zz[i] - m[b](0);
                        if (i >= D) total[b] -= 0.5 * (logS[u] + v * v / S[u]);
                        m[b] += G[u] * v;
                    }
                }
            }
            for (Index b = 0; b < NB; ++b)
                ll(k0 + b) =
                    std::isfinite(total[b]) ? total[b] : -std::numeric_limits<double>::infinity();
        };
        const Index full = K / B;  // blocks of B models, then the last K % B one at a time
        parallel_for(full + K % B, threads, [&](Index i) {
            if (i < full) block(i * B, std::integral_constant<Index, B>{});
            else block(full * B + (i - full), std::integral_constant<Index, 1>{});
        });
    };
    if (d == 2) run_all(std::integral_constant<int, 2>{});
    else run_all(std::integral_constant<int, 3>{});
    return ll;
}

}  // namespace pftrack
