// Noise estimation for goal-directed recovery: Kalman prediction-error log-likelihood of a
// constant-velocity path driven by continuous white-noise acceleration (intensity q, per frame)
// and measured with variance r, for one coordinate of many runs and many (q, r) pairs.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pftrack/check.hpp"
#include "pftrack/types.hpp"

namespace pftrack {

/// z: the runs' coordinates stacked; lengths: points per run (runs shorter than 4 are skipped).
/// Each run is conditioned on its first two points (x = z_1, v = z_1 - z_0, with the covariance
/// that implies); the likelihood sums the remaining innovations. Returns one value per pair.
inline Eigen::VectorXd noise_loglik_grid(const Eigen::Ref<const Eigen::VectorXd>& z,
                                         const Eigen::Ref<const Eigen::VectorXi>& lengths,
                                         const Eigen::Ref<const Eigen::VectorXd>& q,
                                         const Eigen::Ref<const Eigen::VectorXd>& r) {
    const char* fn = "noise_loglik_grid";
    require(q.size() == r.size(), fn, "len(r)", r.size(), q.size());
    require_lengths(lengths, z.size(), fn, "lengths");
    require_finite(z, fn, "z");
    for (Index g = 0; g < q.size(); ++g)
        require(q(g) > 0 && r(g) > 0 && std::isfinite(q(g)) && std::isfinite(r(g)), fn,
                "q and r must be finite and > 0 (pair " + std::to_string(g) + ")");
    Eigen::VectorXd ll = Eigen::VectorXd::Zero(q.size());
    const Index longest = lengths.size() ? std::max<Index>(lengths.maxCoeff(), 0) : 0;
    // Every run starts from the same covariance, so the innovation variance s_i (and log s_i)
    // and the gains k_i depend on the pair and the step only: computed once per pair, shared by
    // the runs, with the operations of the per-run recursion (the same bits). Once the
    // covariance repeats exactly, every later step repeats it: steps from `fixed` on reuse it.
    const auto steps = static_cast<std::size_t>(std::max<Index>(longest, 2));
    std::vector<double> S(steps), logS(steps), K0(steps), K1(steps);
    for (Index g = 0; g < q.size(); ++g) {
        const double qg = q(g), rg = r(g);
        double p00 = rg, p01 = rg, p11 = 2.0 * rg + qg / 3.0;
        Index fixed = longest;
        for (Index i = 2; i < longest; ++i) {
            // predict: x' = x + v, v' = v, Q = q [[1/3, 1/2], [1/2, 1]]
            const auto u = static_cast<std::size_t>(i);
            const double a00 = p00 + 2.0 * p01 + p11 + qg / 3.0;
            const double a01 = p01 + p11 + qg / 2.0;
            const double a11 = p11 + qg;
            const double s = a00 + rg;
            S[u] = s;
            logS[u] = std::log(s);
            const double k0 = a00 / s, k1 = a01 / s;
            K0[u] = k0;
            K1[u] = k1;
            const double n00 = (1.0 - k0) * a00, n01 = (1.0 - k0) * a01, n11 = a11 - k1 * a01;
            if (n00 == p00 && n01 == p01 && n11 == p11) {
                fixed = i;
                break;
            }
            p00 = n00;
            p01 = n01;
            p11 = n11;
        }
        double total = 0.0;
        Index start = 0;
        for (Index k = 0; k < lengths.size(); ++k) {
            const Index len = lengths(k);
            const double* zz = z.data() + start;
            start += len;
            if (len < 4) continue;
            double m0 = zz[1], m1 = zz[1] - zz[0];
            for (Index i = 2; i < len; ++i) {
                const auto u = static_cast<std::size_t>(std::min(i, fixed));
                m0 += m1;
                const double s = S[u];
                const double v = zz[i] - m0;
                total -= 0.5 * (logS[u] + v * v / s);
                m0 += K0[u] * v;
                m1 += K1[u] * v;
            }
        }
        ll(g) = total;
    }
    return ll;
}

}  // namespace pftrack
