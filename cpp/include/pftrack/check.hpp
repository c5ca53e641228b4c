// Argument checks whose messages name the function, the argument, what it is and what was expected:
//   "bhattacharyya_weights: hist cols is 99, expected 110 (one per bin)"
// The core throws std::invalid_argument only; pybind11 turns it into ValueError.
#pragma once

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include <Eigen/Core>

namespace pftrack {

[[noreturn]] inline void fail(const char* fn, const std::string& message) {
    throw std::invalid_argument(std::string(fn) + ": " + message);
}

template <class Got, class Want>
inline void require(bool ok, const char* fn, const char* what, const Got& got, const Want& want) {
    if (ok) return;
    std::ostringstream s;
    s << what << " is " << got << ", expected " << want;
    fail(fn, s.str());
}

inline void require(bool ok, const char* fn, const std::string& message) {
    if (!ok) fail(fn, message);
}

/// Largest array one call may allocate, in elements (2^28 doubles: 2 GiB). Sizes computed from
/// the arguments are checked against it before allocation, so an absurd size is refused with a
/// message instead of ending in std::bad_alloc (MemoryError) or an out-of-memory kill.
constexpr double kMaxElements = 268435456.0;

/// `count` (computed in double, so products cannot overflow) within kMaxElements.
inline void require_size(double count, const char* fn, const std::string& what) {
    if (count <= kMaxElements) return;
    std::ostringstream s;
    s << what << " needs " << count << " values, more than the limit of " << kMaxElements
      << " (2 GiB); use a smaller size";
    fail(fn, s.str());
}

/// Run lengths of rows stacked into one array of `total` rows: every length >= 0 and their sum
/// `total`, summed in 64 bits (an int32 sum wraps: lengths {2^31 - 1, 2^31 - 1, 8} passed a check
/// against 6 rows, then a run read far past the end, or its scratch ended in bad_alloc).
inline void require_lengths(const Eigen::Ref<const Eigen::VectorXi>& lengths, Eigen::Index total,
                            const char* fn, const char* what) {
    long long sum = 0;
    for (Eigen::Index i = 0; i < lengths.size(); ++i) {
        if (lengths(i) < 0) {
            std::ostringstream s;
            s << what << "[" << i << "] is " << lengths(i) << ", expected >= 0";
            fail(fn, s.str());
        }
        sum += lengths(i);
    }
    if (sum != static_cast<long long>(total)) {
        std::ostringstream s;
        s << "sum(" << what << ") is " << sum << ", expected " << total
          << " (the rows they split)";
        fail(fn, s.str());
    }
}

/// Every entry finite; the message gives the first bad position.
template <class Derived>
inline void require_finite(const Eigen::DenseBase<Derived>& a, const char* fn, const char* what) {
    for (Eigen::Index i = 0; i < a.rows(); ++i)
        for (Eigen::Index j = 0; j < a.cols(); ++j)
            if (!std::isfinite(static_cast<double>(a(i, j)))) {
                std::ostringstream s;
                s << what << " has a non-finite value " << a(i, j) << " at [" << i;
                if (a.cols() > 1) s << ", " << j;
                s << "]";
                fail(fn, s.str());
            }
}

/// Every value of `a` finite and within +-`limit` (strictly): coordinates a box may have.
template <typename Derived>
inline void require_bounded(const Eigen::DenseBase<Derived>& a, double limit, const char* fn,
                            const char* what) {
    require_finite(a, fn, what);
    for (Eigen::Index i = 0; i < a.rows(); ++i)
        for (Eigen::Index j = 0; j < a.cols(); ++j)
            if (!(std::abs(static_cast<double>(a(i, j))) < limit)) {
                std::ostringstream s;
                s << what << " has a value " << a(i, j) << " at [" << i;
                if (a.cols() > 1) s << ", " << j;
                s << "] beyond +-" << limit << " px";
                fail(fn, s.str());
            }
}

/// What particle weights summing to 0 mean inside the particle filter (sis_step, mh_step,
/// estimate): every particle's likelihood underflowed or was never counted.
inline constexpr const char* kParticleWeightsZero =
    "all weights are 0: reference histogram empty, or every particle outside the image?";

/// Weights: non-empty, finite, non-negative, positive finite sum. Returns the sum.
/// `if_zero` says what a zero sum means for these values (default: only that every value is 0;
/// the particle filter passes kParticleWeightsZero, a resampler called by a user none).
template <class Derived>
inline double require_weights(const Eigen::DenseBase<Derived>& w, const char* fn,
                              const char* what = "weights", const char* if_zero = nullptr) {
    require(w.size() > 0, fn, std::string(what) + " is empty");
    double sum = 0.0;
    for (Eigen::Index i = 0; i < w.size(); ++i) {
        const double v = w(i);
        if (!std::isfinite(v) || v < 0.0) {
            std::ostringstream s;
            s << what << "[" << i << "] is " << v << ", expected a finite value >= 0";
            fail(fn, s.str());
        }
        sum += v;
    }
    if (!std::isfinite(sum))  // each weight is finite: their total overflowed
        fail(fn, std::string(what) + " sum is not finite (overflow: the weights are finite but "
                                     "their total exceeds the largest double, 1.8e308; scale "
                                     "them down, e.g. divide by their maximum)");
    if (!(sum > 0.0)) {
        const std::string name(what);
        fail(fn, name + (name == "weights" ? " sum" : " sums") + " to 0 (" +
                     (if_zero != nullptr ? if_zero : "every value is 0; at least one must be > 0") +
                     ")");
    }
    return sum;
}

}  // namespace pftrack
