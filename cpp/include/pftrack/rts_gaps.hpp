// The `rts` recovery baseline for many gaps in one call: a constant-velocity Kalman filter and
// Rauch-Tung-Striebel smoother per gap window (pftrack.recovery.baselines.rts_batch).
//
// Each axis is x_t = F x_{t-1} + w_t with state (position, velocity), F = [[1, 1], [0, 1]] and
// white-noise-acceleration Q = q [[1/3, 1/2], [1/2, 1]] per frame, observed as z_t = x_t[0] + v_t,
// v_t ~ N(0, r). A gap's window is the last points of segment A and the first points of segment
// B; frames without a point (the gap, holes inside a window) are predicted only. The filter starts
// at the first point with velocity 0 of variance v0 and position variance r; x and y share one
// covariance, so the recursion runs once for both axes.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <vector>

#include <Eigen/Core>

#include "pftrack/check.hpp"
#include "pftrack/cv_axis.hpp"
#include "pftrack/types.hpp"

namespace pftrack {

namespace detail {

/// Integral frame number of `points` row `k` (checked finite and integral by the caller).
inline std::int64_t frame_at(const Eigen::Ref<const RowMatrixXd>& points, Eigen::Index k) {
    return static_cast<std::int64_t>(points(k, 0));
}

}  // namespace detail

/// Smoothed (x, y) of every frame inside every gap, gap after gap: (M, 2) with M the sum over
/// gaps of (first frame of B - last frame of A - 1).
///
/// `points` (P, 3) rows (frame, x, y); gap g's window is rows offsets[g] .. offsets[g+1] - 1 of
/// which the first n_before[g] (>= 1) are segment A and the rest (>= 1) segment B, frames
/// strictly increasing through the window. q, r, v0 > 0. Throws std::invalid_argument naming the
/// first bad argument (non-finite or fractional frame, frames out of order, an empty side, a
/// window longer than the allocation limit) or when the result is not finite.
inline RowMatrixXd rts_gaps_batch(const Eigen::Ref<const RowMatrixXd>& points,
                                  const Eigen::Ref<const Eigen::VectorXi>& offsets,
                                  const Eigen::Ref<const Eigen::VectorXi>& n_before, double q,
                                  double r, double v0) {
    constexpr const char* fn = "rts_gaps_batch";
    require(points.cols() == 3, fn, "points cols", points.cols(), "3 (frame, x, y)");
    require(offsets.size() >= 1, fn, "offsets size", offsets.size(), ">= 1 (gaps + 1)");
    const Eigen::Index G = offsets.size() - 1;
    require(n_before.size() == G, fn, "n_before size", n_before.size(), G);
    require(std::isfinite(q) && q > 0.0, fn, "q", q, "finite and > 0");
    require(std::isfinite(r) && r > 0.0, fn, "r", r, "finite and > 0");
    require(std::isfinite(v0) && v0 > 0.0, fn, "v0", v0, "finite and > 0");
    require(offsets(0) == 0, fn, "offsets[0]", offsets(0), 0);
    require(offsets(G) == points.rows(), fn, "offsets[-1]", offsets(G),
            "the number of points rows");
    require_finite(points, fn, "points");
    for (Eigen::Index k = 0; k < points.rows(); ++k)
        if (points(k, 0) != std::floor(points(k, 0)) || std::abs(points(k, 0)) > 4.5e15) {
            std::ostringstream s;
            s << "frame " << points(k, 0) << " at row " << k << " is not an integer";
            fail(fn, s.str());
        }
    // Check every window and count the output rows before allocating anything.
    double total = 0.0;
    double longest = 0.0;
    for (Eigen::Index g = 0; g < G; ++g) {
        const int lo = offsets(g), hi = offsets(g + 1), na = n_before(g);
        if (lo > hi || hi > points.rows()) {
            std::ostringstream s;
            s << "offsets[" << g << "], offsets[" << g + 1 << "] are " << lo << ", " << hi
              << ", expected non-decreasing within [0, " << points.rows() << "]";
            fail(fn, s.str());
        }
        if (na < 1 || na > hi - lo - 1) {
            std::ostringstream s;
            s << "n_before[" << g << "] is " << na << ", expected 1.." << hi - lo - 1
              << " (gap " << g << " has " << hi - lo << " points; both sides need one)";
            fail(fn, s.str());
        }
        for (int k = lo + 1; k < hi; ++k)
            if (points(k, 0) <= points(k - 1, 0)) {
                std::ostringstream s;
                s << "gap " << g << ": frame " << points(k, 0) << " at row " << k
                  << " does not follow frame " << points(k - 1, 0);
                fail(fn, s.str());
            }
        total += points(lo + na, 0) - points(lo + na - 1, 0) - 1.0;
        longest = std::max(longest, points(hi - 1, 0) - points(lo, 0) + 1.0);
    }
    require_size(2.0 * total, fn, "the output");
    require_size(14.0 * longest, fn, "the longest window");

    RowMatrixXd out(static_cast<Eigen::Index>(total), 2);
    // Per step: predicted mean (x0, x1, y0, y1) and covariance (x and y share it), filtered same.
    std::vector<double> pm, fm;
    std::vector<cv_axis::Cov> pp, fp;
    const auto n_long = static_cast<std::size_t>(longest);
    pm.resize(4 * n_long);
    fm.resize(4 * n_long);
    pp.resize(n_long);
    fp.resize(n_long);
    Eigen::Index row = 0;
    for (Eigen::Index g = 0; g < G; ++g) {
        const int lo = offsets(g), hi = offsets(g + 1);
        const std::int64_t f0 = detail::frame_at(points, lo);
        const std::int64_t fa = detail::frame_at(points, lo + n_before(g) - 1);
        const std::int64_t fb = detail::frame_at(points, lo + n_before(g));
        const auto T = static_cast<std::size_t>(detail::frame_at(points, hi - 1) - f0 + 1);
        double mx = points(lo, 1), my = points(lo, 2), vx = 0.0, vy = 0.0;
        cv_axis::Cov p{r, 0.0, v0};
        int k = lo;  // next observed row
        for (std::size_t t = 0; t < T; ++t) {
            if (t > 0) {
                // x_t|t-1 = F x_t-1,  P_t|t-1 = F P F^T + Q
                mx += vx;
                my += vy;
                p = cv_axis::predict(p, q);
            }
            pm[4 * t] = mx, pm[4 * t + 1] = vx, pm[4 * t + 2] = my, pm[4 * t + 3] = vy;
            pp[t] = p;
            if (k < hi && detail::frame_at(points, k) == f0 + static_cast<std::int64_t>(t)) {
                // K = P H^T / (H P H^T + r),  x += K (z - H x),  P = (I - K H) P
                const cv_axis::Gain g = cv_axis::gain(p, r);
                const double ex = points(k, 1) - mx, ey = points(k, 2) - my;
                mx += g.k0 * ex, vx += g.k1 * ex;
                my += g.k0 * ey, vy += g.k1 * ey;
                p = cv_axis::updated(p, g);
                ++k;
            }
            fm[4 * t] = mx, fm[4 * t + 1] = vx, fm[4 * t + 2] = my, fm[4 * t + 3] = vy;
            fp[t] = p;
        }
        // RTS: C_t = P_t|t F^T P_t+1|t^-1,  s_t = m_t|t + C_t (s_t+1 - m_t+1|t)
        double sx = fm[4 * (T - 1)], svx = fm[4 * (T - 1) + 1];
        double sy = fm[4 * (T - 1) + 2], svy = fm[4 * (T - 1) + 3];
        for (std::size_t t = T - 1; t-- > 0;) {
            const cv_axis::SmootherGain c = cv_axis::smoother_gain(fp[t], pp[t + 1]);
            const double dx0 = sx - pm[4 * (t + 1)], dx1 = svx - pm[4 * (t + 1) + 1];
            const double dy0 = sy - pm[4 * (t + 1) + 2], dy1 = svy - pm[4 * (t + 1) + 3];
            sx = fm[4 * t] + c.c00 * dx0 + c.c01 * dx1;
            svx = fm[4 * t + 1] + c.c10 * dx0 + c.c11 * dx1;
            sy = fm[4 * t + 2] + c.c00 * dy0 + c.c01 * dy1;
            svy = fm[4 * t + 3] + c.c10 * dy0 + c.c11 * dy1;
            const std::int64_t f = f0 + static_cast<std::int64_t>(t);
            if (f > fa && f < fb) {
                const Eigen::Index i = row + static_cast<Eigen::Index>(f - fa - 1);
                out(i, 0) = sx;
                out(i, 1) = sy;
            }
        }
        row += static_cast<Eigen::Index>(fb - fa - 1);
    }
    // Extreme q, r, v0 or coordinates can make a covariance singular in floating point.
    if (!out.allFinite()) {
        std::ostringstream s;
        s << "the smoothed path is not finite (q " << q << ", r " << r << ", v0 " << v0
          << " or the coordinates are too extreme)";
        fail(fn, s.str());
    }
    return out;
}

}  // namespace pftrack
