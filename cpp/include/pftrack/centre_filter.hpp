// The tracker's centre filter (pftrack.tracking.motion.CentreKalman) on plain doubles: a
// constant-velocity Kalman filter of a track's centre, both axes sharing one covariance
// (p00, p01, p11), stepped one frame at a time (dt = 1). The same operations in the same order
// as the Python floats of pftrack.tracking.track (predict_tracks, follow_tracks_motion), so the
// same bits: no reassociation, and no fused multiply-add (GCC contracts a * b + c into one FMA
// in C++ whenever the target has it, e.g. with PFTRACK_NATIVE; clang within an expression: both
// are turned off for this header's functions below).
#pragma once

#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#elif defined(__GNUC__)
#pragma GCC push_options
#pragma GCC optimize("fp-contract=off")
#endif

namespace pftrack {

/// One track's centre filter: position, velocity, covariance of one axis (shared).
struct CentreState {
    double px, py, vx, vy, p00, p01, p11;
};

/// cv_predict over one frame with process noise `q` = (accel h)^2 (its products by dt = 1 are
/// exact, so they are left out, as in the Python).
inline void centre_predict(CentreState& s, double q) {
    s.px = s.px + s.vx;
    s.py = s.py + s.vy;
    const double p00 = s.p00 + 2.0 * s.p01 + s.p11 + q / 3.0;
    const double p01 = s.p01 + s.p11 + q / 2.0;
    const double p11 = s.p11 + q;
    s.p00 = p00;
    s.p01 = p01;
    s.p11 = p11;
}

/// cv_update of both axes with the measured centre (zx, zy) of variance `r2`. False (and `s`
/// unchanged) when the innovation's variance p00 + r2 is 0, where Python's division raises.
inline bool centre_update(CentreState& s, double zx, double zy, double r2) {
    const double var = s.p00 + r2;
    if (var == 0.0) return false;
    const double k0 = s.p00 / var, k1 = s.p01 / var;
    const double ex = zx - s.px, ey = zy - s.py;
    const double p00 = (1.0 - k0) * s.p00, p01 = (1.0 - k0) * s.p01, p11 = s.p11 - k1 * s.p01;
    s.px = s.px + k0 * ex;
    s.py = s.py + k0 * ey;
    s.vx = s.vx + k1 * ex;
    s.vy = s.vy + k1 * ey;
    s.p00 = p00;
    s.p01 = p01;
    s.p11 = p11;
    return true;
}

}  // namespace pftrack

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC pop_options
#endif
