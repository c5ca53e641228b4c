// Skipping the background of a mask: most of a foreground mask's bytes are 0.
#pragma once

#include <atomic>
#include <cstdint>
#include <cstring>

#include "types.hpp"

#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__)
#define PFTRACK_SCAN_AVX2 1
#include <immintrin.h>
#endif

namespace pftrack {
namespace detail {

/// Whether the hand-written AVX2 passes may run where the CPU has AVX2 (background.hpp's
/// `background_row_fused_avx2`, `histogram_row_avx2`, `HsvLut::bins_of_row`, and so
/// `hsv_bins_image`'s; camera.hpp's `grey_halved`; this file's `skip_zero_avx2`; morphology's
/// packed passes through their binding): true unless a test turns it off
/// (`pftrack._core._set_avx2`) to hold the portable loops, which other CPUs run, to the same
/// reference on the same machine. Here, the lowest header that needs it (blobs.hpp includes
/// this file, not background.hpp).
inline std::atomic<bool>& avx2_allowed() {
    static std::atomic<bool> allowed{true};
    return allowed;
}

/// Whether an AVX2 pass runs now: the CPU has AVX2 and no test turned the passes off
/// (`avx2_allowed`). `skip_zero_words`' callers ask once per mask, not once per run.
inline bool avx2_usable() {
#ifdef PFTRACK_SCAN_AVX2
    return __builtin_cpu_supports("avx2") && avx2_allowed().load(std::memory_order_relaxed);
#else
    return false;
#endif
}

#ifdef PFTRACK_SCAN_AVX2
/// `skip_zero_words`' 64-byte steps: x advanced by 64 while p[x, x + 64) is all 0 (two loads,
/// an OR and a `vptest`: 7 instructions per 64 bytes, where GCC made the portable 32-byte test
/// 14 per 32, the words copied through the stack); at a step that holds a non-zero byte, the
/// first 8-byte word holding one (the portable answer), flagged by `found`.
__attribute__((target("avx2"))) inline Index skip_zero_avx2(const std::uint8_t* p, Index x,
                                                              Index n, bool& found) {
    found = false;
    while (x + 64 <= n) {
        const __m256i a = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p + x));
        const __m256i b = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p + x + 32));
        const __m256i o = _mm256_or_si256(a, b);
        if (_mm256_testz_si256(o, o)) {
            x += 64;
            continue;
        }
        const __m256i z = _mm256_setzero_si256();
        const auto za = static_cast<std::uint32_t>(_mm256_movemask_epi8(_mm256_cmpeq_epi8(a, z)));
        const auto zb = static_cast<std::uint32_t>(_mm256_movemask_epi8(_mm256_cmpeq_epi8(b, z)));
        const std::uint64_t zero = za | (std::uint64_t{zb} << 32);  // bit k: byte x + k is 0
        found = true;
        return x + (static_cast<Index>(__builtin_ctzll(~zero)) & ~Index{7});
    }
    return x;
}
#endif

/// The first x' >= x, in steps of 8 bytes, at which p[x', x' + 8) is not all 0 or x' + 8 > n:
/// where a loop testing one 8-byte word a step stops. With `avx2` (`avx2_usable()`), 64 bytes a
/// step first (`skip_zero_avx2`); then four words a step (a quarter of the tests and branches
/// on a mask's empty rows), then one.
inline Index skip_zero_words(const std::uint8_t* p, Index x, Index n, bool avx2 = false) {
#ifdef PFTRACK_SCAN_AVX2
    if (avx2) {
        bool found;
        x = skip_zero_avx2(p, x, n, found);
        if (found) return x;
    }
#else
    (void)avx2;
#endif
    std::uint64_t w[4];
    while (x + 32 <= n) {
        std::memcpy(w, p + x, 32);
        if ((w[0] | w[1] | w[2] | w[3]) != 0) break;
        x += 32;
    }
    while (x + 8 <= n) {
        std::memcpy(w, p + x, 8);
        if (w[0] != 0) break;
        x += 8;
    }
    return x;
}

}  // namespace detail
}  // namespace pftrack
