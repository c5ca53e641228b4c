// One constant-velocity axis: state (position, velocity), F = [[1, 1], [0, 1]], white-noise
// acceleration Q = q [[1/3, 1/2], [1/2, 1]] per frame, position measured with variance r
// (pftrack.kalman's model). The covariance recursions that the RTS kernels (rts_smooth.hpp,
// rts_gaps.hpp) share, each operation in the order of pftrack.kalman's NumPy code, so that the
// kernels equal it bit for bit where the compiler does not fuse a multiply and an add.
#pragma once

namespace pftrack::cv_axis {

/// The covariance [[p00, p01], [p01, p11]].
struct Cov {
    double p00, p01, p11;
};

/// P_t|t-1 = F P F^T + Q.
inline Cov predict(const Cov& p, double q) {
    return {p.p00 + 2.0 * p.p01 + p.p11 + q / 3.0, p.p01 + p.p11 + q / 2.0, p.p11 + q};
}

/// Kalman gain K = P H^T / (H P H^T + r) of a position measurement, H = [1, 0].
struct Gain {
    double k0, k1;
};

inline Gain gain(const Cov& p, double r) {
    const double s = p.p00 + r;
    return {p.p00 / s, p.p01 / s};
}

/// P = (I - K H) P.
inline Cov updated(const Cov& p, const Gain& k) {
    return {(1.0 - k.k0) * p.p00, (1.0 - k.k0) * p.p01, p.p11 - k.k1 * p.p01};
}

/// RTS smoother gain C = P_t|t F^T P_t+1|t^-1 (row-major c00, c01, c10, c11).
struct SmootherGain {
    double c00, c01, c10, c11;
};

inline SmootherGain smoother_gain(const Cov& filtered, const Cov& predicted_next) {
    const double a = filtered.p00, b = filtered.p01, c = filtered.p11;
    const double u00 = a + b, u01 = b, u10 = b + c, u11 = c;
    const double x = predicted_next.p00, y = predicted_next.p01, w = predicted_next.p11;
    const double det = x * w - y * y;
    if (!(det > 0.0)) {
        // singular: one combination known exactly (no process noise, no initial velocity
        // variance: a constant position): the pseudo-inverse, M / trace(M)^2 at rank <= 1
        const double s = x + w, k = s > 0.0 ? 1.0 / (s * s) : 0.0;
        const double ix = x * k, iy = y * k, iw = w * k;
        return {u00 * ix + u01 * iy, u00 * iy + u01 * iw, u10 * ix + u11 * iy,
                u10 * iy + u11 * iw};
    }
    return {(u00 * w - u01 * y) / det, (u01 * x - u00 * y) / det, (u10 * w - u11 * y) / det,
            (u11 * x - u10 * y) / det};
}

}  // namespace pftrack::cv_axis
