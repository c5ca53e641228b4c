// One step of a Metropolis-Hastings colour particle filter, one filter per object (the first
// paper's method 2, algorithm 3, eq. 5):
//   resample (systematic) -> for each particle i, a Markov chain of n_iter Metropolis-Hastings
//   iterations over (x, j), a state and the parent j in the resampled set it was predicted from,
//   whose target is the filtering posterior with the particle approximation of the prediction
//   (Khan, Balch & Dellaert 2005):
//       pi(x, j) ~ p(z | x) (1/N) p(x | x_{t-1}^j)               (colour likelihood x AR2 dynamics)
//   started at parent j = i with a draw of its dynamics; each iteration proposes x* ~ q(x* | x) and
//   accepts with
//       a = [p(z|x*) p(x*|x_{t-1}) q(x|x*)] / [p(z|x) p(x|x_{t-1}) q(x*|x)]        (eq. 5)
//   (accept when u < a, u ~ U[0, 1); otherwise the chain keeps x).
//
// Chain length: `n_iter` is the number of MH iterations PER PARTICLE (so a step evaluates the
// likelihood N (n_iter + 1) times: the start of each chain, then one proposal per iteration).
// The first `burn_in` iterations of each chain are burn-in: they are left out of the reported
// acceptance rate and of the mean estimate, which averages the states of the N chains over the
// n_iter - burn_in kept iterations. The new particle set is the chains' final states, with equal
// weights 1/N.
//
// Proposals q(x* | x):
//   kDynamics:   j* uniform in the resampled set, x* ~ p(x* | x_{t-1}^j*) = N(A x_{t-1}^j* +
//                B x_{t-2}^j*, C^2), independent of (x, j), so q(x, j | x*, j*) = (1/N) p(x | x_{t-1}^j)
//                and eq. 5 reduces to p(z|x*) / p(z|x): the chain can move to a better parent
//                (after MCMC all weights are equal, so resampling alone would never select);
//   kRandomWalk: x* = x + tau * w, w ~ N(0, I), same parent, symmetric, so eq. 5 reduces to
//                p(z|x*) p(x*|x_{t-1}^j) / [p(z|x) p(x|x_{t-1}^j)].
// Both are computed with every term of eq. 5 written out (log space), not with the reduced form.
// The dynamics density is the Gaussian truncated to s in [s_min, s_max]: a proposal outside the
// scale bounds has target 0 and is rejected. A component with C = 0 is deterministic.
// Histograms: with base.min_samples > 0 every box of the step is counted on the lattice sis_step
// uses (lattice_step of the previous mean state's box, one step for all evaluations of the
// frame), so a box has the same coefficient as in sis_step; min_samples 0 counts every pixel.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "sis.hpp"

namespace pftrack {

enum class MhProposal { kDynamics = 0, kRandomWalk = 1 };

struct MhParams {
    SisParams base;                                // dynamics, lambda, kernel, w0, h0, resample
    int n_iter = 1;                                // MH iterations per particle (>= 1)
    int burn_in = 0;                               // in [0, n_iter)
    MhProposal proposal = MhProposal::kDynamics;
    Eigen::Array3d rw_sigma{2.0, 2.0, 0.01};       // tau of the random-walk proposal

    void validate(const char* fn) const {
        base.validate(fn);
        require(n_iter >= 1, fn, "n_iter", n_iter, ">= 1");
        require(burn_in >= 0 && burn_in < n_iter, fn, "burn_in", burn_in, "in [0, n_iter)");
        require(rw_sigma.allFinite() && (rw_sigma >= 0.0).all(), fn,
                "rw_sigma must be finite and >= 0");
    }
};

struct MhResult : SisResult {
    double acceptance = 0.0;  // accepted / proposed over the post-burn-in iterations
};

/// log p(x | x_{t-1}) of the AR2 dynamics up to a constant: Gaussian around `mu` with std `sigma`,
/// truncated to the scale bounds; -inf outside them or off a deterministic (sigma = 0) component.
inline double ar2_log_density(const double* x, const double* mu, const Ar2Model& m) {
    if (x[2] < m.s_min || x[2] > m.s_max) return -std::numeric_limits<double>::infinity();
    double lp = 0.0;
    for (int d = 0; d < kStateDim; ++d) {
        const double r = x[d] - mu[d];
        if (m.sigma[d] > 0.0) {
            const double z = r / m.sigma[d];
            lp -= 0.5 * z * z;
        } else if (r != 0.0) {
            return -std::numeric_limits<double>::infinity();
        }
    }
    return lp;
}

namespace detail {

/// Colour log-likelihood log p(z | x) = -lambda D^2 (eq. 9) of one state; also returns rho and the
/// counted pixels.
struct MhEval {
    double loglik, rho, counted;
};

inline MhEval mh_evaluate(HistogramScratch& scratch, std::vector<double>& hist, const BinImage& img,
                          const double* sqref, const double* x, const SisParams& p,
                          Index lattice) {
    MhEval e;
    // as sis_step counts the box: on its lattice when `lattice` > 1 (the same points, the same
    // coefficient of their counts, counted = points x step^2), else every pixel
    e.rho = state_coefficient(img, x[0], x[1], x[2] * p.w0, x[2] * p.h0, sqref, p.kernel, lattice,
                              scratch, hist, e.counted);
    const double d = bhattacharyya_distance_from_rho(e.rho);
    e.loglik = -p.lambda * d * d;
    return e;
}

}  // namespace detail

/// Advances one particle set by one frame with per-particle MH chains. `particles` (N, 6),
/// `weights` (N,) and `means` (2, 3) are updated in place, as in sis_step. All draws come from
/// CounterRng(seed, step): particle i, chain position j (0 = start, 1..n_iter = proposals) uses
/// normals k + {0, 1, 2}, k = 4 (i (n_iter + 1) + j), the acceptance uniform 2 (k + 3) and the
/// parent uniform 2 (k + 3) + 1 (the resampling uniform is the one of index 2^64 - 1).
inline MhResult mh_step(Eigen::Ref<RowMatrixXd> particles, Eigen::Ref<Eigen::VectorXd> weights,
                        Eigen::Ref<RowMatrixXd> means, const BinImage& img,
                        const Eigen::Ref<const Eigen::VectorXd>& ref, const MhParams& prm,
                        std::uint64_t seed, std::uint64_t step) {
    const char* fn = "mh_step";
    check_particle_set(particles, weights, means, fn);
    const Index n = particles.rows();
    prm.validate(fn);
    check_bin_image(img, fn);
    const Eigen::VectorXd sqref = sqrt_reference(ref, img.n_bins, fn);
    const Ar2Model& model = prm.base.model;

    const CounterRng rng(seed, step);
    if (prm.base.resample) resample_systematic_in_place(particles, weights, rng);

    // Predictions mu_j = A x_{t-1}^j + B x_{t-2}^j of every (resampled) parent j   (eq. 7 / eq. 8)
    RowMatrixXd mu(n, kStateDim);
    const RowMatrixXd parents = particles.leftCols(kStateDim);
    for (Index j = 0; j < n; ++j)
        for (int d = 0; d < kStateDim; ++d) {
            const double x1 = model.use_means ? means(0, d) : particles(j, d);
            const double x2 = model.use_means ? means(1, d) : particles(j, kStateDim + d);
            mu(j, d) = model.a[d] * x1 + model.b[d] * x2;
        }

    HistogramScratch scratch(img.n_bins);
    std::vector<double> hist(static_cast<size_t>(img.n_bins));
    // Large boxes are counted on a lattice, as in sis_step: one step for every evaluation of the
    // frame, from the box of the previous mean state (min_samples 0: every pixel, step 1).
    const Index lattice =
        lattice_step(means(0, 2) * prm.base.w0, means(0, 2) * prm.base.h0, prm.base.min_samples);
    const std::uint64_t per_particle = static_cast<std::uint64_t>(prm.n_iter) + 1;
    Eigen::Vector3d mean_sum = Eigen::Vector3d::Zero();
    Eigen::VectorXd rho(n), counted(n), logpost(n);
    std::int64_t accepted = 0, proposed = 0;
    for (Index i = 0; i < n; ++i) {
        const auto slot = [&](std::uint64_t j) {
            return 4 * (static_cast<std::uint64_t>(i) * per_particle + j);
        };
        // chain start: parent j = i, x ~ p(x | x_{t-1}^i) (scale clamped, as in the SIS filter)
        Index par = i;
        double x[kStateDim], xs[kStateDim];
        for (int d = 0; d < kStateDim; ++d)
            x[d] = mu(par, d) + model.sigma[d] * rng.normal(slot(0) + static_cast<std::uint64_t>(d));
        x[2] = std::clamp(x[2], model.s_min, model.s_max);
        detail::MhEval cur = detail::mh_evaluate(scratch, hist, img, sqref.data(), x, prm.base, lattice);
        double cur_lp = ar2_log_density(x, mu.row(par).data(), model);
        for (int it = 1; it <= prm.n_iter; ++it) {
            const std::uint64_t k = slot(static_cast<std::uint64_t>(it));
            Index par_s = par;
            if (prm.proposal == MhProposal::kDynamics)
                par_s = std::min<Index>(n - 1, static_cast<Index>(rng.uniform(2 * (k + 3) + 1) *
                                                                  static_cast<double>(n)));
            for (int d = 0; d < kStateDim; ++d) {
                const double w = rng.normal(k + static_cast<std::uint64_t>(d));
                xs[d] = prm.proposal == MhProposal::kDynamics ? mu(par_s, d) + model.sigma[d] * w
                                                              : x[d] + prm.rw_sigma[d] * w;
            }
            const double prop_lp = ar2_log_density(xs, mu.row(par_s).data(), model);
            bool accept = false;
            detail::MhEval prop{};
            if (std::isfinite(prop_lp)) {
                prop = detail::mh_evaluate(scratch, hist, img, sqref.data(), xs, prm.base, lattice);
                // log q(x | x*) - log q(x* | x): dynamics proposal -> (1/N) p(x|x_{t-1}^j) /
                // [(1/N) p(x*|x_{t-1}^j*)]; random walk -> 0 (symmetric Gaussian, same parent).
                const double log_q_ratio =
                    prm.proposal == MhProposal::kDynamics ? cur_lp - prop_lp : 0.0;
                // log a = log p(z|x*) + log p(x*|x_{t-1}) + log q(x|x*)
                //       - log p(z|x)  - log p(x|x_{t-1})  - log q(x*|x)        (eq. 5)
                // A current state of target 0 (a start clamped onto a scale bound where a
                // deterministic component puts no mass) is left by any proposal of positive
                // target: a = +inf, where the terms above would give inf - inf = NaN.
                const double log_a =
                    std::isfinite(cur_lp)
                        ? (prop.loglik + prop_lp) - (cur.loglik + cur_lp) + log_q_ratio
                        : std::numeric_limits<double>::infinity();
                const double u = rng.uniform(2 * (k + 3));
                accept = log_a >= 0.0 || u < std::exp(log_a);
            }
            if (accept) {
                for (int d = 0; d < kStateDim; ++d) x[d] = xs[d];
                par = par_s;
                cur = prop;
                cur_lp = prop_lp;
            }
            if (it > prm.burn_in) {
                ++proposed;
                accepted += accept ? 1 : 0;
                mean_sum += Eigen::Vector3d(x[0], x[1], x[2]);
            }
        }
        double* row = particles.row(i).data();
        for (int d = 0; d < kStateDim; ++d) {
            row[kStateDim + d] = parents(par, d);
            row[d] = x[d];
        }
        rho(i) = cur.rho;
        counted(i) = cur.counted;
        logpost(i) = cur.loglik + (std::isfinite(cur_lp) ? cur_lp : -1e300);
    }
    weights.setConstant(1.0 / static_cast<double>(n));

    MhResult r;
    r.estimate.mean = mean_sum / static_cast<double>(proposed);
    logpost.maxCoeff(&r.estimate.map_index);
    r.estimate.map = particles.row(r.estimate.map_index).head<kStateDim>().transpose();
    r.ess = static_cast<double>(n);
    r.rho_max = rho.maxCoeff();
    r.rho_mean = rho.mean();
    r.fg_mean = counted.mean();
    r.acceptance = static_cast<double>(accepted) / static_cast<double>(proposed);
    means.row(1) = means.row(0);
    means.row(0) = r.estimate.mean.transpose();
    return r;
}

}  // namespace pftrack
