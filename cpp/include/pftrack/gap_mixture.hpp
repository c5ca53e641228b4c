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
// shared); the result is the smoothed positions inside the gap and the log-likelihood of the
// window's observations, so that the caller can weight the hypotheses by their evidence. For a
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

template <int D>
GapMixtureResult gap_mixture(const Eigen::Ref<const Eigen::VectorXd>& z, Index fa, Index fb,
                             const Eigen::Ref<const RowMatrixXd>& F_in,
                             const Eigen::Ref<const RowMatrixXd>& Q_in, double r,
                             const Eigen::Ref<const Eigen::VectorXd>& p0,
                             const Eigen::Ref<const Eigen::VectorXi>& t1s,
                             const Eigen::Ref<const Eigen::VectorXi>& t2s, double v2) {
    using Mat = Eigen::Matrix<double, D, D>;
    using Vec = Eigen::Matrix<double, D, 1>;
    const Index n = z.size(), T = fb - fa, H = t1s.size();
    const Mat F = F_in, Q = Q_in;
    Mat stand = Mat::Zero();
    stand(0, 0) = 1.0;
    Mat q_stand = Mat::Zero();
    q_stand(0, 0) = Q(0, 0);
    Mat q_restart = q_stand;
    q_restart(1, 1) = v2;

    // Filter over the window up to the end of segment A: the same for every hypothesis.
    Vec m = Vec::Zero();
    m(0) = z(0);
    Mat P = p0.asDiagonal();
    double ll_prefix = 0.0;
    int seen = 0;
    auto update = [&](Vec& mm, Mat& PP, double zt, double& ll) {
        const double s = PP(0, 0) + r;
        const double v = zt - mm(0);
        if (seen >= D) ll -= 0.5 * (std::log(kTwoPi * s) + v * v / s);
        ++seen;
        const Vec k = PP.col(0) / s;
        mm += k * v;
        PP -= k * PP.row(0);
        PP = 0.5 * (PP + PP.transpose()).eval();
    };
    for (Index t = 0; t <= fa; ++t) {
        if (t > 0) {
            m = F * m;
            P = F * P * F.transpose() + Q;
        }
        if (std::isfinite(z(t))) update(m, P, z(t), ll_prefix);
    }
    const int seen_prefix = seen;

    GapMixtureResult out{RowMatrixXd(H, T - 1), Eigen::VectorXd(H)};
    const Index len = n - fa;  // window steps from the end of A on
    // The walking filter over the rest of the window, kept: a stand hypothesis (t1, t2) is the
    // same filter up to gap step t1, so it starts from there instead of from the end of A.
    std::vector<Vec> walk_m(len), walk_mp(len);
    std::vector<Mat> walk_P(len), walk_Pp(len);
    std::vector<double> walk_ll(len);
    std::vector<int> walk_seen(len);
    walk_m[0] = walk_mp[0] = m;
    walk_P[0] = walk_Pp[0] = P;
    walk_ll[0] = ll_prefix;
    walk_seen[0] = seen_prefix;
    for (Index j = 1; j < len; ++j) {
        Vec mj = F * walk_m[j - 1];
        Mat Pj = F * walk_P[j - 1] * F.transpose() + Q;
        walk_mp[j] = mj;
        walk_Pp[j] = Pj;
        double ll = walk_ll[j - 1];
        seen = walk_seen[j - 1];
        if (std::isfinite(z(fa + j))) update(mj, Pj, z(fa + j), ll);
        walk_m[j] = mj;
        walk_P[j] = Pj;
        walk_ll[j] = ll;
        walk_seen[j] = seen;
    }

    std::vector<Vec> mp(len), ms(len);
    std::vector<Mat> Pp(len), Ps(len);
    std::vector<const Mat*> Fs(len, &F);
    // Smoother gains C_j = Ps[j] F_{j+1}' pinv(Pp[j+1]) depend on covariances only, which do not
    // depend on the observed values. Before gap step t1 every hypothesis has the walking filter's
    // (walk_gain, computed once); while standing (t1 <= j < t2) they depend on (t1, j) only
    // (stand_gain, kept for the last t1 seen: hypotheses come grouped by t1). The same
    // expression on the same operands: the same bits as computing them per hypothesis.
    std::vector<Mat> walk_gain(len), stand_gain(len);
    std::vector<char> have_walk(len, 0);
    std::vector<int> stand_t1(len, -2);
    for (Index h = 0; h < H; ++h) {
        const int t1 = t1s(h), t2 = t2s(h);
        const Index first = t1 < 0 ? len : t1 + 1;  // first step that differs from walking
        // Before `first` the walking filter's arrays are read directly (walk_*); only the
        // last walking step, where the hypothesis branches off, is copied.
        ms[first - 1] = walk_m[first - 1];
        Ps[first - 1] = walk_P[first - 1];
        Vec mh = ms[first - 1];
        Mat Ph = Ps[first - 1];
        double ll = walk_ll[first - 1];
        seen = walk_seen[first - 1];
        for (Index j = first; j < len; ++j) {  // window index fa + j, gap step j
            const Mat* Fj = &F;
            const Mat* Qj = &Q;
            if (j <= t2 + 1) {
                Fj = &stand;
                Qj = j == t2 + 1 ? &q_restart : &q_stand;
            }
            Fs[j] = Fj;
            mh = (*Fj) * mh;
            Ph = (*Fj) * Ph * Fj->transpose() + *Qj;
            mp[j] = mh;
            Pp[j] = Ph;
            if (std::isfinite(z(fa + j))) update(mh, Ph, z(fa + j), ll);
            ms[j] = mh;
            Ps[j] = Ph;
        }
        for (Index j = len - 2; j >= 1; --j) {
            const auto u = static_cast<std::size_t>(j);
            if (j + 1 < first) {  // walking up to here: Ps[j], Pp[j + 1], Fs[j + 1] are walk's
                if (!have_walk[u]) {
                    const Mat C = walk_P[j] * F.transpose() * psd_pinv<D>(walk_Pp[j + 1]);
                    walk_gain[u] = C;
                    have_walk[u] = 1;
                }
                ms[j] = walk_m[j];
                ms[j] += walk_gain[u] * (ms[j + 1] - walk_mp[j + 1]);
            } else if (j < t2) {  // standing from t1 + 1 to j + 1 <= t2: depends on (t1, j)
                if (stand_t1[u] != t1) {
                    const Mat C = Ps[j] * Fs[j + 1]->transpose() * psd_pinv<D>(Pp[j + 1]);
                    stand_gain[u] = C;
                    stand_t1[u] = t1;
                }
                ms[j] += stand_gain[u] * (ms[j + 1] - mp[j + 1]);
            } else {
                const Mat C = Ps[j] * Fs[j + 1]->transpose() * psd_pinv<D>(Pp[j + 1]);
                ms[j] += C * (ms[j + 1] - mp[j + 1]);
            }
        }
        for (Index j = 1; j < T; ++j) out.paths(h, j - 1) = ms[j](0);
        out.loglik(h) = ll;
    }
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
    std::vector<GapMixtureResult> out(jobs.size());
    parallel_for(static_cast<Index>(jobs.size()), threads, [&](Index j) {
        const GapMixtureJob& g = jobs[static_cast<std::size_t>(j)];
        const auto k = static_cast<std::size_t>(g.model);
        const RowMatrixXd& F = models.F[k];
        out[static_cast<std::size_t>(j)] =
            F.rows() == 2
                ? detail::gap_mixture<2>(g.z, g.fa, g.fb, F, models.Q[k], models.r[k],
                                         models.p0[k], g.t1s, g.t2s, models.v2[k])
                : detail::gap_mixture<3>(g.z, g.fa, g.fb, F, models.Q[k], models.r[k],
                                         models.p0[k], g.t1s, g.t2s, models.v2[k]);
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
