// Rauch-Tung-Striebel smoothing of independent constant-velocity axes over a run of frames
// (pftrack.kalman.rts_smooth): the offline pass smooths every track's box with it, one call per
// track, and `pftrack smooth` thousands of them.
//
// Each axis is x_t = F x_{t-1} + w_t with state (position, velocity), F = [[1, 1], [0, 1]] and
// white-noise-acceleration Q = q [[1/3, 1/2], [1/2, 1]], observed as z_t = x_t[0] + v_t,
// v_t ~ N(0, r2) on the frames that have a measurement. The filter starts at
// N([z_0, 0], diag(r2, velocity_sd^2)). Every operation is the NumPy code's, in its order
// (tests/reference/smoothing.py), so the two agree to the last bit where the compiler does not
// fuse a multiply and an add.
#pragma once

#include <cstdint>
#include <vector>

#include "pftrack/cv_axis.hpp"
#include "pftrack/types.hpp"

namespace pftrack {

/// Smoothed positions `out` (T x n, row-major) of the measurements `z` (T x n, row-major; rows
/// without a measurement are never read). `has` is (T) when `per_axis` is false, else (T x n):
/// non-zero where a frame has a measurement; the first frame must have one on every axis (the
/// caller checks). `q`, `r2`: (n) per axis. `update_first`: also update with z_0 at frame 0.
inline void rts_smooth(const double* z, const std::uint8_t* has, bool per_axis, Index steps,
                       Index n, const double* q, const double* r2, double velocity_sd,
                       bool update_first, double* out) {
    if (steps <= 0 || n <= 0) return;
    const auto T = static_cast<std::size_t>(steps);
    // per frame: predicted and filtered mean (position, velocity) and covariance
    std::vector<double> pm(2 * T), fm(2 * T);
    std::vector<cv_axis::Cov> pp(T), fp(T);
    for (Index k = 0; k < n; ++k) {
        const double qk = q[k], rk = r2[k];
        double m0 = z[k], m1 = 0.0;
        cv_axis::Cov p{rk, 0.0, velocity_sd * velocity_sd};
        for (std::size_t t = 0; t < T; ++t) {
            if (t > 0) {
                m0 = m0 + m1;  // x_t|t-1 = F x_t-1
                p = cv_axis::predict(p, qk);
            }
            pm[2 * t] = m0, pm[2 * t + 1] = m1;
            pp[t] = p;
            const Index ti = static_cast<Index>(t);
            const bool measured = per_axis ? has[ti * n + k] != 0 : has[ti] != 0;
            if (measured && (t > 0 || update_first)) {
                const cv_axis::Gain g = cv_axis::gain(p, rk);  // x += K (z - H x)
                const double e = z[ti * n + k] - m0;
                m0 = m0 + g.k0 * e, m1 = m1 + g.k1 * e;
                p = cv_axis::updated(p, g);
            }
            fm[2 * t] = m0, fm[2 * t + 1] = m1;
            fp[t] = p;
        }
        // s_t = m_t|t + C_t (s_t+1 - m_t+1|t)
        double s0 = fm[2 * (T - 1)], s1 = fm[2 * (T - 1) + 1];
        out[static_cast<Index>(T - 1) * n + k] = s0;
        for (std::size_t t = T - 1; t-- > 0;) {
            const cv_axis::SmootherGain c = cv_axis::smoother_gain(fp[t], pp[t + 1]);
            const double d0 = s0 - pm[2 * (t + 1)], d1 = s1 - pm[2 * (t + 1) + 1];
            s0 = fm[2 * t] + c.c00 * d0 + c.c01 * d1;
            s1 = fm[2 * t + 1] + c.c10 * d0 + c.c11 * d1;
            out[static_cast<Index>(t) * n + k] = s0;
        }
    }
}

}  // namespace pftrack
