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
    // per frame: predicted and filtered mean (position, velocity) and covariance (p00, p01, p11)
    std::vector<double> pm(2 * T), pp(3 * T), fm(2 * T), fp(3 * T);
    for (Index k = 0; k < n; ++k) {
        const double qk = q[k], rk = r2[k];
        double m0 = z[k], m1 = 0.0;
        double p00 = rk, p01 = 0.0, p11 = velocity_sd * velocity_sd;
        for (std::size_t t = 0; t < T; ++t) {
            if (t > 0) {
                // x_t|t-1 = F x_t-1,  P_t|t-1 = F P F^T + Q
                m0 = m0 + m1;
                const double a = p00 + 2.0 * p01 + p11 + qk / 3.0;
                const double b = p01 + p11 + qk / 2.0;
                p11 = p11 + qk;
                p00 = a, p01 = b;
            }
            pm[2 * t] = m0, pm[2 * t + 1] = m1;
            pp[3 * t] = p00, pp[3 * t + 1] = p01, pp[3 * t + 2] = p11;
            const Index ti = static_cast<Index>(t);
            const bool measured = per_axis ? has[ti * n + k] != 0 : has[ti] != 0;
            if (measured && (t > 0 || update_first)) {
                // K = P H^T / (H P H^T + r2),  x += K (z - H x),  P = (I - K H) P
                const double s = p00 + rk, k0 = p00 / s, k1 = p01 / s;
                const double e = z[ti * n + k] - m0;
                m0 = m0 + k0 * e, m1 = m1 + k1 * e;
                const double n00 = (1.0 - k0) * p00, n01 = (1.0 - k0) * p01;
                p11 = p11 - k1 * p01;
                p00 = n00, p01 = n01;
            }
            fm[2 * t] = m0, fm[2 * t + 1] = m1;
            fp[3 * t] = p00, fp[3 * t + 1] = p01, fp[3 * t + 2] = p11;
        }
        // C_t = P_t|t F^T P_t+1|t^-1,  s_t = m_t|t + C_t (s_t+1 - m_t+1|t)
        double s0 = fm[2 * (T - 1)], s1 = fm[2 * (T - 1) + 1];
        out[static_cast<Index>(T - 1) * n + k] = s0;
        for (std::size_t t = T - 1; t-- > 0;) {
            const double a = fp[3 * t], b = fp[3 * t + 1], c = fp[3 * t + 2];
            const double u00 = a + b, u01 = b, u10 = b + c, u11 = c;
            const double x = pp[3 * (t + 1)], y = pp[3 * (t + 1) + 1], w = pp[3 * (t + 1) + 2];
            const double det = x * w - y * y;
            const double c00 = (u00 * w - u01 * y) / det, c01 = (u01 * x - u00 * y) / det;
            const double c10 = (u10 * w - u11 * y) / det, c11 = (u11 * x - u10 * y) / det;
            const double d0 = s0 - pm[2 * (t + 1)], d1 = s1 - pm[2 * (t + 1) + 1];
            s0 = fm[2 * t] + c00 * d0 + c01 * d1;
            s1 = fm[2 * t + 1] + c10 * d0 + c11 * d1;
            out[static_cast<Index>(t) * n + k] = s0;
        }
    }
}

}  // namespace pftrack
