// Counter-based random numbers: value k of a stream is a pure function of (key, k), so results
// never depend on the order in which particles are visited or on the number of threads.
// (SplitMix64 finaliser as the mixing function; Box-Muller for normals. std::normal_distribution
// is avoided on purpose: its algorithm differs between standard libraries.)
#pragma once

#include <cmath>
#include <cstdint>

namespace pftrack {

inline std::uint64_t mix64(std::uint64_t z) {
    z += 0x9E3779B97F4A7C15ULL;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

class CounterRng {
public:
    CounterRng(std::uint64_t seed, std::uint64_t stream) : key_(mix64(seed ^ mix64(stream + 0x5851F42D4C957F2DULL))) {}

    std::uint64_t bits(std::uint64_t k) const { return mix64(key_ ^ mix64(k)); }

    /// Uniform on [0, 1), 53 random bits.
    double uniform(std::uint64_t k) const {
        return static_cast<double>(bits(k) >> 11) * 0x1.0p-53;
    }

    /// Standard normal, value k of the stream (uses bits 2k and 2k + 1).
    double normal(std::uint64_t k) const {
        const double u1 = 1.0 - uniform(2 * k);  // (0, 1]
        const double u2 = uniform(2 * k + 1);
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
    }

private:
    std::uint64_t key_;
};

}  // namespace pftrack
