// The paper's detector, per-pixel part: an adaptive background (running average, updated
// selectively where there is no foreground), the difference of each frame to it and to the previous
// frame, a noise-adaptive threshold, fused with the HSV binning of the same frame so that every
// frame is read once. Morphology and connected components follow in Python (OpenCV).
#pragma once

#include <algorithm>
#include <cmath>
#include <array>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "check.hpp"
#include "hsv.hpp"
#include "mask_scan.hpp"
#include "types.hpp"

// HsvLut::bins_of_row's AVX2 pass (byte shuffles, table gathers), chosen at run time: GCC's
// generic tuning never emits gathers from the plain loops, which are the fallback.
#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__)
#define PFTRACK_LUT_GATHER 1
#include <immintrin.h>
#endif

namespace pftrack {

/// `hsv_bin_of` as table look-ups, without branches: identical results (tests check all 2^24
/// colours), several times faster. The colour/grey decision and the saturation bin depend on
/// (max, min) only, the value bin on max only, the hue bin on (sector, numerator, max - min) only.
class HsvLut {
public:
    explicit HsvLut(const HsvBinning& p) : grey0_(p.n_h * p.n_s) {
        p.validate("HsvLut");
        sat_.assign(256 * 256, 0);
        const auto n_s = static_cast<std::uint32_t>(p.n_s);
        for (int mx = 0; mx < 256; ++mx) {
            // Same expressions as hsv_bin_of, so the same doubles and the same truncations.
            const double v = mx / 255.0;
            const int vb = std::min(static_cast<int>(v * p.n_v), p.n_v - 1);
            for (int mn = 0; mn <= mx; ++mn) {
                const double s = mx > 0 ? static_cast<double>(mx - mn) / mx : 0.0;
                sat_[mx * 256 + mn] =
                    (s > p.s_min && v > p.v_min)
                        ? (n_s << 16) | static_cast<std::uint32_t>(
                                            std::min(static_cast<int>(s * p.n_s), p.n_s - 1))
                        : static_cast<std::uint32_t>(grey0_ + vb);
            }
        }
        // 3 bytes past the last entry: the AVX2 look-up reads 4 bytes at each entry
        hue_.assign(3 * kHueStride + 3, 0);
        for (int sector = 0; sector < 3; ++sector)
            for (int d = 1; d < 256; ++d)
                for (int num = -d; num <= d; ++num) {
                    double h;
                    if (sector == 0) {  // max is r: num = g - b
                        h = 60.0 * num / d;
                        if (h < 0.0) h += 360.0;
                    } else if (sector == 1) {  // max is g: num = b - r
                        h = 60.0 * num / d + 120.0;
                    } else {  // max is b: num = r - g
                        h = 60.0 * num / d + 240.0;
                    }
                    hue_[sector * kHueStride + d * d + num + d] =
                        static_cast<std::uint8_t>(std::min(static_cast<int>(h * p.n_h / 360.0), p.n_h - 1));
                }
    }

    /// Bin from the table indices sat = max * 256 + min and hue = sector * kHueStride + d * d +
    /// num + d (see `bin`).
    /// Branch-free: (the saturation bin, n_s) of a colour pixel, (the grey bin, 0) of a grey
    /// one, packed in one entry of sat_, so the bin is sat's low half + hue bin * its high half.
    int bin_at(int sat, int hue) const {
        const std::uint32_t e = sat_[static_cast<size_t>(sat)];
        return static_cast<int>((e & 0xffffu) + hue_[static_cast<size_t>(hue)] * (e >> 16));
    }

    /// `bin` of each of the n pixels of a row of BGR bytes into `out`, where the CPU has AVX2:
    /// eight pixels a step, the table indices in 32-bit integer lanes (the same integers as
    /// `hsv_row_indices`' exact floats) and table gathers, one pass with no index buffers;
    /// reads the row's 3 n bytes and no more. Returns false (nothing written) without AVX2:
    /// the caller then takes `hsv_row_indices` and `bin_at`.
    bool bins_of_row(Index n, const std::uint8_t* px, std::int16_t* out) const {
#ifdef PFTRACK_LUT_GATHER
        if (!detail::avx2_usable()) return false;
        Index x = bins_of_row_avx2(n, px, out);
        for (; x < n; ++x)
            out[x] = static_cast<std::int16_t>(bin(px[3 * x], px[3 * x + 1], px[3 * x + 2]));
        return true;
#else
        (void)n, (void)px, (void)out;
        return false;
#endif
    }

    int bin(int b, int g, int r) const {
        const int mx = std::max(r, std::max(g, b));
        const int mn = std::min(r, std::min(g, b));
        // hsv_bin_of's order of tests: r first, then g, then b (ties go to the earlier one).
        const int sector = (mx == r) ? 0 : ((mx == g) ? 1 : 2);
        const int num = (mx == r) ? g - b : ((mx == g) ? b - r : r - g);
        const int d = mx - mn;
        return bin_at(mx * 256 + mn, sector * kHueStride + d * d + num + d);
    }

    static constexpr int kHueStride = 256 * 256;  // d * d + (num + d) < 256^2 for d < 256

private:
#ifdef PFTRACK_LUT_GATHER
    /// `bin_at` of 8 pixels' table indices: one gather from sat_ (its 32-bit entries) and one
    /// from hue_ (4 bytes at each entry, the low one kept), then bin_at's arithmetic in 32-bit
    /// lanes.
    __attribute__((target("avx2"))) __m256i bins8_avx2(__m256i si, __m256i hi) const {
        const auto* s_tab = reinterpret_cast<const int*>(sat_.data());
        const auto* h_tab = reinterpret_cast<const int*>(hue_.data());
        const __m256i e = _mm256_i32gather_epi32(s_tab, si, 4);
        const __m256i h =
            _mm256_and_si256(_mm256_i32gather_epi32(h_tab, hi, 1), _mm256_set1_epi32(0xff));
        return _mm256_add_epi32(_mm256_and_si256(e, _mm256_set1_epi32(0xffff)),
                                _mm256_mullo_epi32(h, _mm256_srli_epi32(e, 16)));
    }

    /// `bins_of_row` of the first n - n % 8 pixels (returned). Per 8 pixels, their 24 bytes
    /// (a 16-byte and an 8-byte load: nothing past them is read) are split into B, G, R lanes
    /// by byte shuffles; then `HsvLut::bin`'s integers: sat = max 256 + min, and hue = sector
    /// 65536 + d d + num + d with r tested first, then g (ties to the earlier channel).
    __attribute__((target("avx2"))) Index bins_of_row_avx2(Index n, const std::uint8_t* px,
                                                           std::int16_t* out) const {
        // byte k of the 24 is channel k % 3 of pixel k / 3: bytes 0-15 in `lo`, 16-23 in `hi`
        const __m128i b_lo = _mm_setr_epi8(0, 3, 6, 9, 12, 15, -1, -1, -1, -1, -1, -1, -1, -1,
                                           -1, -1);
        const __m128i b_hi = _mm_setr_epi8(-1, -1, -1, -1, -1, -1, 2, 5, -1, -1, -1, -1, -1, -1,
                                           -1, -1);
        const __m128i g_lo = _mm_setr_epi8(1, 4, 7, 10, 13, -1, -1, -1, -1, -1, -1, -1, -1, -1,
                                           -1, -1);
        const __m128i g_hi = _mm_setr_epi8(-1, -1, -1, -1, -1, 0, 3, 6, -1, -1, -1, -1, -1, -1,
                                           -1, -1);
        const __m128i r_lo = _mm_setr_epi8(2, 5, 8, 11, 14, -1, -1, -1, -1, -1, -1, -1, -1, -1,
                                           -1, -1);
        const __m128i r_hi = _mm_setr_epi8(-1, -1, -1, -1, -1, 1, 4, 7, -1, -1, -1, -1, -1, -1,
                                           -1, -1);
        const __m256i stride1 = _mm256_set1_epi32(kHueStride),
                      stride2 = _mm256_set1_epi32(2 * kHueStride);
        Index x = 0;
        for (; x + 8 <= n; x += 8) {
            const std::uint8_t* p = px + 3 * x;
            const __m128i lo = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
            const __m128i hi = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(p + 16));
            const __m256i b = _mm256_cvtepu8_epi32(
                _mm_or_si128(_mm_shuffle_epi8(lo, b_lo), _mm_shuffle_epi8(hi, b_hi)));
            const __m256i g = _mm256_cvtepu8_epi32(
                _mm_or_si128(_mm_shuffle_epi8(lo, g_lo), _mm_shuffle_epi8(hi, g_hi)));
            const __m256i r = _mm256_cvtepu8_epi32(
                _mm_or_si128(_mm_shuffle_epi8(lo, r_lo), _mm_shuffle_epi8(hi, r_hi)));
            const __m256i mx = _mm256_max_epi32(r, _mm256_max_epi32(g, b));
            const __m256i mn = _mm256_min_epi32(r, _mm256_min_epi32(g, b));
            const __m256i is_r = _mm256_cmpeq_epi32(mx, r), is_g = _mm256_cmpeq_epi32(mx, g);
            // num = g - b (max is r), else b - r (max is g), else r - g; sector 65536 likewise
            const __m256i num = _mm256_blendv_epi8(
                _mm256_blendv_epi8(_mm256_sub_epi32(r, g), _mm256_sub_epi32(b, r), is_g),
                _mm256_sub_epi32(g, b), is_r);
            const __m256i sector =
                _mm256_andnot_si256(is_r, _mm256_blendv_epi8(stride2, stride1, is_g));
            const __m256i d = _mm256_sub_epi32(mx, mn);
            const __m256i si = _mm256_or_si256(_mm256_slli_epi32(mx, 8), mn);
            const __m256i hu = _mm256_add_epi32(
                _mm256_add_epi32(sector, _mm256_mullo_epi32(d, d)), _mm256_add_epi32(num, d));
            const __m256i v = bins8_avx2(si, hu);  // bins < 2^15: the signed pack keeps them
            // packs works per 128-bit lane: 64-bit quarters 0 and 2 hold pixels 0-3 and 4-7
            const __m256i pk = _mm256_permute4x64_epi64(_mm256_packs_epi32(v, v), 0x08);
            _mm_storeu_si128(reinterpret_cast<__m128i*>(out + x), _mm256_castsi256_si128(pk));
        }
        return x;
    }
#endif

    int grey0_;                     // first grey bin, n_h * n_s
    std::vector<std::uint32_t> sat_;  // [max * 256 + min] -> n_s << 16 | saturation bin if a
                                      // colour pixel, else the grey bin n_h n_s + value bin

    std::vector<std::uint8_t> hue_;   // [sector][d * d + num + d], d = max - min -> hue bin
};

/// Settings of `BackgroundModel`. Thresholds are on the max-over-channels absolute difference,
/// in grey levels.
struct BackgroundConfig {
    double alpha = 0.05;      // running-average rate where the pixel is background (selective update)
    double alpha_fg = 0.005;  // slow rate where it is foreground (absorbs stopped objects; 0 = off)
    int n_learn = 30;         // frames 2 .. n_learn update every pixel at max(1 / k, alpha) (k-th
                              // frame): a running mean that averages out objects of the first
                              // frame (their "ghosts"); 0 or 1 = selective from the start
    double k_noise = 4.0;     // threshold = k_noise * median background difference of the last frame
    double t_min = 25.0;      // ... clamped to [t_min, t_max]
    double t_max = 60.0;
    double low_ratio = 0.5;   // a pixel that also moved (frame difference > threshold) is
                              // foreground from low_ratio * threshold on (hysteresis)
    double shadow_lo = 0.5;   // a pixel darker than the background, with brightness ratio
                              // sum(I) / sum(B) in [shadow_lo, 1) ...
    double shadow_chroma = 0.03;  // ... and chromaticity |I_c / sum(I) - B_c / sum(B)| <=
                                  // shadow_chroma for every c, is a shadow: background, not
                                  // learnt (rate alpha_fg). shadow_lo = 1 turns this off.

    void validate(const char* fn) const {
        require(alpha > 0.0 && alpha <= 1.0, fn, "alpha", alpha, "in (0, 1]");
        require(alpha_fg >= 0.0 && alpha_fg <= 1.0, fn, "alpha_fg", alpha_fg, "in [0, 1]");
        require(n_learn >= 0, fn, "n_learn", n_learn, ">= 0");
        require(k_noise >= 0.0 && k_noise <= 1e6, fn, "k_noise", k_noise, "in [0, 1e6]");
        require(t_min >= 0.0 && t_min <= 255.0, fn, "t_min", t_min, "in [0, 255]");
        require(t_max >= t_min && t_max <= 255.0, fn, "t_max", t_max, "in [t_min, 255]");
        require(low_ratio >= 0.0 && low_ratio <= 1.0, fn, "low_ratio", low_ratio, "in [0, 1]");
        require(shadow_lo >= 0.0 && shadow_lo <= 1.0, fn, "shadow_lo", shadow_lo, "in [0, 1]");
        require(shadow_chroma >= 0.0 && shadow_chroma <= 1.0, fn, "shadow_chroma", shadow_chroma,
                "in [0, 1]");
    }
};

namespace detail {

/// The HsvLut indices of one pixel (HsvLut::bin's sat and hue), in float (exact on these small
/// integers) and without branches, so that the loops calling it vectorise.
inline __attribute__((always_inline)) void hsv_indices(float b, float g, float r,
                                                       std::int32_t& sat, std::int32_t& hue) {
    const float hue_stride = static_cast<float>(HsvLut::kHueStride);
    const float mx = std::max(r, std::max(g, b));
    const float mn = std::min(r, std::min(g, b));
    // sector 0 if max is r, else 1 if g, else 2; num = g - b, b - r, r - g resp. (0/1 blends)
    const float not_r = static_cast<float>(mx != r), not_g = static_cast<float>(mx != g);
    const float sector = not_r * (1.0f + not_g);
    const float num =
        (1.0f - not_r) * (g - b) + not_r * ((1.0f - not_g) * (b - r) + not_g * (r - g));
    const float d = mx - mn;
    sat = static_cast<std::int32_t>(mx * 256.0f + mn);
    hue = static_cast<std::int32_t>(sector * hue_stride + (d * d + (num + d)));
}

/// The HsvLut indices of one row of BGR bytes (see `hsv_indices`).
PFTRACK_VECTOR_CLONES static void hsv_row_indices(Index n, const std::uint8_t* __restrict px,
                                                  std::int32_t* __restrict si,
                                                  std::int32_t* __restrict hi) {
    for (Index x = 0; x < n; ++x)
        hsv_indices(static_cast<float>(px[3 * x]), static_cast<float>(px[3 * x + 1]),
                    static_cast<float>(px[3 * x + 2]), si[x], hi[x]);
}

/// The shadow bounds of `mask_byte`'s test (BackgroundConfig's shadow_lo, shadow_chroma).
struct ShadowBounds {
    float lo;
    float chroma;
};

/// d_bg = max_c |frame_c - background_c| of one pixel, floor(d_bg) clamped to 255 into `di`,
/// and the candidate flag (1 or 0) into `cand`; returns whether the pixel is a candidate.
inline __attribute__((always_inline)) bool difference(float b, float g, float r, float qb,
                                                      float qg, float qr, float dprev, float t,
                                                      float t_low, std::int32_t& di, float& cand) {
    const float d_bg = std::max(std::abs(b - qb), std::max(std::abs(g - qg), std::abs(r - qr)));
    di = static_cast<std::int32_t>(std::min(d_bg, 255.0f));
    const bool is_cand = (d_bg > t) | ((dprev > t) & (d_bg > t_low));
    cand = is_cand ? 1.0f : 0.0f;
    return is_cand;
}

/// The mask byte of one pixel: 0 for no candidate, 127 for a candidate that is a shadow (darker
/// by a bounded ratio, same chromaticity: |I_c sB - B_c sI| <= k sI sB for every c), 255 for
/// foreground. Every test is computed (float32, in the order of the scalar test it replaced),
/// so that the loops calling it vectorise.
inline __attribute__((always_inline)) std::uint8_t mask_byte(bool is_cand, float b, float g,
                                                             float r, float qb, float qg,
                                                             float qr, ShadowBounds sh) {
    const float s_i = b + g + r, s_b = qb + qg + qr;
    const float tol = sh.chroma * s_i * s_b;
    const bool shadow = (s_i < s_b) & (s_i >= sh.lo * s_b) & (s_i > 0.0f) &
                        (std::abs(b * s_b - qb * s_i) <= tol) &
                        (std::abs(g * s_b - qg * s_i) <= tol) &
                        (std::abs(r * s_b - qr * s_i) <= tol);
    // 255 - 128 = 127 for a shadow; times 0 or 1 (arithmetic: a select does not vectorise)
    return static_cast<std::uint8_t>(static_cast<std::int32_t>(is_cand) *
                                     (255 - 128 * static_cast<std::int32_t>(shadow)));
}

/// Pixels a chunk of `row_candidates` holds: the shadow test runs only in the chunks with a
/// candidate (most chunks have none: 65-89 % of the 32-pixel chunks on the bench's scene,
/// PETS09 and TUD-Campus). 16 since stop 70: 0.054 M fewer instructions a PETS09 frame than 32
/// with the update in the differences' loop (8 took 0.46 M more: callgrind, det70's harness).
constexpr Index kCandidateChunk = 16;

/// Per pixel of one row, in float (exact on these small integers): floor(d_bg) clamped to 255,
/// the candidate flag (1 or 0) and the mask byte (`difference`, `mask_byte`). Chunk by chunk of
/// `kCandidateChunk` pixels, each loop branch-free (vectorised): the differences, then the
/// shadow test only where the chunk has a candidate (the mask is 0 wherever there is none, so
/// the bytes are those of the test run on every pixel). With `kUpdate`, the differences' loop
/// also writes the selective update (`background_row_update`'s arithmetic) into `ub, ug, ur`,
/// the next frame's background: another buffer than `qb, qg, qr`, which the shadow test of the
/// chunk reads after it (one pass over the row's floats instead of two).
template <bool kUpdate>
inline __attribute__((always_inline)) void row_candidates(
    Index n, const float* __restrict fb, const float* __restrict fg, const float* __restrict fr,
    const float* __restrict qb, const float* __restrict qg, const float* __restrict qr,
    const float* __restrict dprev, float t, float t_low, ShadowBounds sh,
    std::int32_t* __restrict di, float* __restrict cand, std::uint8_t* __restrict m, float a_bg,
    float a_fg, float* __restrict ub, float* __restrict ug, float* __restrict ur) {
    Index x0 = 0;
    for (; x0 + kCandidateChunk <= n; x0 += kCandidateChunk) {
        std::int32_t any = 0;
        for (Index x = x0; x < x0 + kCandidateChunk; ++x) {
            const bool is_cand = difference(fb[x], fg[x], fr[x], qb[x], qg[x], qr[x], dprev[x],
                                            t, t_low, di[x], cand[x]);
            any |= static_cast<std::int32_t>(is_cand);
            if constexpr (kUpdate) {
                const float a = is_cand ? a_fg : a_bg;
                ub[x] = qb[x] + a * (fb[x] - qb[x]);
                ug[x] = qg[x] + a * (fg[x] - qg[x]);
                ur[x] = qr[x] + a * (fr[x] - qr[x]);
            }
        }
        if (any == 0) {
            std::memset(m + x0, 0, static_cast<size_t>(kCandidateChunk));
            continue;
        }
        for (Index x = x0; x < x0 + kCandidateChunk; ++x)
            m[x] = mask_byte(cand[x] != 0.0f, fb[x], fg[x], fr[x], qb[x], qg[x], qr[x], sh);
    }
    for (Index x = x0; x < n; ++x) {
        const bool is_cand =
            difference(fb[x], fg[x], fr[x], qb[x], qg[x], qr[x], dprev[x], t, t_low, di[x],
                       cand[x]);
        m[x] = mask_byte(is_cand, fb[x], fg[x], fr[x], qb[x], qg[x], qr[x], sh);
        if constexpr (kUpdate) {
            const float a = is_cand ? a_fg : a_bg;
            ub[x] = qb[x] + a * (fb[x] - qb[x]);
            ug[x] = qg[x] + a * (fg[x] - qg[x]);
            ur[x] = qr[x] + a * (fr[x] - qr[x]);
        }
    }
}

/// `row_candidates` without the update (a caller's hold mask: `background_row_update_held`).
PFTRACK_VECTOR_CLONES static void background_row_candidates(
    Index n, const float* __restrict fb, const float* __restrict fg, const float* __restrict fr,
    const float* __restrict qb, const float* __restrict qg, const float* __restrict qr,
    const float* __restrict dprev, float t, float t_low, ShadowBounds sh,
    std::int32_t* __restrict di, float* __restrict cand, std::uint8_t* __restrict m) {
    row_candidates<false>(n, fb, fg, fr, qb, qg, qr, dprev, t, t_low, sh, di, cand, m, 0.0f,
                          0.0f, nullptr, nullptr, nullptr);
}

/// `row_candidates` with the update into `ub, ug, ur` (a = a_fg where cand, else a_bg).
PFTRACK_VECTOR_CLONES static void background_row_candidates_update(
    Index n, const float* __restrict fb, const float* __restrict fg, const float* __restrict fr,
    const float* __restrict qb, const float* __restrict qg, const float* __restrict qr,
    const float* __restrict dprev, float t, float t_low, ShadowBounds sh,
    std::int32_t* __restrict di, float* __restrict cand, std::uint8_t* __restrict m, float a_bg,
    float a_fg, float* __restrict ub, float* __restrict ug, float* __restrict ur) {
    row_candidates<true>(n, fb, fg, fr, qb, qg, qr, dprev, t, t_low, sh, di, cand, m, a_bg, a_fg,
                         ub, ug, ur);
}

/// The HsvLut indices (sat, hue) of one row's float planes (see `hsv_indices`).
PFTRACK_VECTOR_CLONES static void hsv_plane_indices(Index n, const float* __restrict fb,
                                                    const float* __restrict fg,
                                                    const float* __restrict fr,
                                                    std::int32_t* __restrict si,
                                                    std::int32_t* __restrict hi) {
    for (Index x = 0; x < n; ++x) hsv_indices(fb[x], fg[x], fr[x], si[x], hi[x]);
}

/// One row of BGR bytes -> float planes b, g, r and d_prev = max_c |I_c - I'_c| against the
/// previous frame's row, kept planar (B, G, R rows of bytes: read at unit stride, so only the
/// frame is deinterleaved); the row's bytes then become the previous frame's.
PFTRACK_VECTOR_CLONES static void background_row_split(
    Index n, const std::uint8_t* __restrict px, std::uint8_t* __restrict pb,
    std::uint8_t* __restrict pg, std::uint8_t* __restrict pr, float* __restrict fb,
    float* __restrict fg, float* __restrict fr, float* __restrict dprev) {
    for (Index x = 0; x < n; ++x) {
        const int b = px[3 * x], g = px[3 * x + 1], r = px[3 * x + 2];
        fb[x] = static_cast<float>(b);
        fg[x] = static_cast<float>(g);
        fr[x] = static_cast<float>(r);
        dprev[x] = static_cast<float>(std::max(
            std::abs(b - pb[x]), std::max(std::abs(g - pg[x]), std::abs(r - pr[x]))));
        pb[x] = static_cast<std::uint8_t>(b);
        pg[x] = static_cast<std::uint8_t>(g);
        pr[x] = static_cast<std::uint8_t>(r);
    }
}

/// The selective update with a hold row, from this frame's background `qb, qg, qr` into the
/// next one's `ub, ug, ur`: background_c + a (frame_c - background_c), a = 0 where cand and
/// hold != 0 (a tracked object's pixels, kept out of the background), else a_fg where cand,
/// else a_bg.
PFTRACK_VECTOR_CLONES static void background_row_update_held(
    Index n, const float* __restrict fb, const float* __restrict fg, const float* __restrict fr,
    const float* __restrict qb, const float* __restrict qg, const float* __restrict qr,
    const float* __restrict cand, const std::uint8_t* __restrict hold, float a_bg, float a_fg,
    float* __restrict ub, float* __restrict ug, float* __restrict ur) {
    for (Index x = 0; x < n; ++x) {
        const float a = cand[x] != 0.0f ? (hold[x] != 0 ? 0.0f : a_fg) : a_bg;
        ub[x] = qb[x] + a * (fb[x] - qb[x]);
        ug[x] = qg[x] + a * (fg[x] - qg[x]);
        ur[x] = qr[x] + a * (fr[x] - qr[x]);
    }
}

#ifdef PFTRACK_LUT_GATHER
/// |a - c| of 16 bytes: (a -sat c) | (c -sat a).
__attribute__((target("avx2"), always_inline)) inline __m128i absdiff_u8(__m128i a, __m128i c) {
    return _mm_or_si128(_mm_subs_epu8(a, c), _mm_subs_epu8(c, a));
}

/// Bytes 8 half .. 8 half + 7 of v as 8 floats.
__attribute__((target("avx2"), always_inline)) inline __m256 bytes8_floats(__m128i v, int half) {
    return _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(half == 0 ? v : _mm_unpackhi_epi64(v, v)));
}

/// `background_row_split` then `background_row_candidates_update` of the first n - n % 16
/// pixels of a row (returned), by hand in AVX2, for a pass without bins or hold row: per
/// `kCandidateChunk` (16) pixels, the 48 bytes split into B, G, R by byte shuffles, d_prev as
/// the bytes' largest absolute difference (an integer: the same float), and the planes widened
/// to floats in registers, so the B, G, R and d_prev floats are not written and read back
/// (GCC's stride-3 deinterleave and its widening were 5 instructions a pixel, the float
/// planes' stores and loads 1 more). The same float operations, in the same order and without
/// FMA, as `difference` and the update: the same bits. The B, G, R floats and the candidate
/// flags are written only in a chunk with a candidate, whose shadow test (`mask_byte`) reads
/// them; `dprev` is not written.
__attribute__((target("avx2"))) inline Index background_row_fused_avx2(
    Index n, const std::uint8_t* __restrict px, std::uint8_t* __restrict pb,
    std::uint8_t* __restrict pg, std::uint8_t* __restrict pr, const float* __restrict qb,
    const float* __restrict qg, const float* __restrict qr, float t, float t_low,
    ShadowBounds sh, std::int32_t* __restrict di, float* __restrict fb, float* __restrict fg,
    float* __restrict fr, float* __restrict cand, std::uint8_t* __restrict m, float a_bg,
    float a_fg, float* __restrict ub, float* __restrict ug, float* __restrict ur) {
    static_assert(kCandidateChunk == 16, "one chunk is one 16-pixel step");
    // byte k of the 48 is channel k % 3 of pixel k / 3: bytes 0-15 in `lo`, 16-31 in `mid`,
    // 32-47 in `hi`; each channel is the OR of three shuffles (-1: a zero byte)
    const __m128i b_lo = _mm_setr_epi8(0, 3, 6, 9, 12, 15, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1);
    const __m128i b_mid =
        _mm_setr_epi8(-1, -1, -1, -1, -1, -1, 2, 5, 8, 11, 14, -1, -1, -1, -1, -1);
    const __m128i b_hi = _mm_setr_epi8(-1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, 1, 4, 7, 10, 13);
    const __m128i g_lo = _mm_setr_epi8(1, 4, 7, 10, 13, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1);
    const __m128i g_mid = _mm_setr_epi8(-1, -1, -1, -1, -1, 0, 3, 6, 9, 12, 15, -1, -1, -1, -1, -1);
    const __m128i g_hi = _mm_setr_epi8(-1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, 2, 5, 8, 11, 14);
    const __m128i r_lo = _mm_setr_epi8(2, 5, 8, 11, 14, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1);
    const __m128i r_mid =
        _mm_setr_epi8(-1, -1, -1, -1, -1, 1, 4, 7, 10, 13, -1, -1, -1, -1, -1, -1);
    const __m128i r_hi = _mm_setr_epi8(-1, -1, -1, -1, -1, -1, -1, -1, -1, -1, 0, 3, 6, 9, 12, 15);
    const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
    const __m256 vt = _mm256_set1_ps(t), vt_low = _mm256_set1_ps(t_low);
    const __m256 v255 = _mm256_set1_ps(255.0f), one = _mm256_set1_ps(1.0f);
    const __m256 va_bg = _mm256_set1_ps(a_bg), va_fg = _mm256_set1_ps(a_fg);
    Index x = 0;
    for (; x + kCandidateChunk <= n; x += kCandidateChunk) {
        const std::uint8_t* p = px + 3 * x;
        const __m128i lo = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
        const __m128i mid = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 16));
        const __m128i hi = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 32));
        const __m128i b = _mm_or_si128(_mm_or_si128(_mm_shuffle_epi8(lo, b_lo),
                                                    _mm_shuffle_epi8(mid, b_mid)),
                                       _mm_shuffle_epi8(hi, b_hi));
        const __m128i g = _mm_or_si128(_mm_or_si128(_mm_shuffle_epi8(lo, g_lo),
                                                    _mm_shuffle_epi8(mid, g_mid)),
                                       _mm_shuffle_epi8(hi, g_hi));
        const __m128i r = _mm_or_si128(_mm_or_si128(_mm_shuffle_epi8(lo, r_lo),
                                                    _mm_shuffle_epi8(mid, r_mid)),
                                       _mm_shuffle_epi8(hi, r_hi));
        // d_prev = max_c |I_c - I'_c| in bytes
        const __m128i ob = _mm_loadu_si128(reinterpret_cast<const __m128i*>(pb + x));
        const __m128i og = _mm_loadu_si128(reinterpret_cast<const __m128i*>(pg + x));
        const __m128i orr = _mm_loadu_si128(reinterpret_cast<const __m128i*>(pr + x));
        const __m128i dp = _mm_max_epu8(absdiff_u8(b, ob),
                                           _mm_max_epu8(absdiff_u8(g, og), absdiff_u8(r, orr)));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(pb + x), b);  // I' <- I
        _mm_storeu_si128(reinterpret_cast<__m128i*>(pg + x), g);
        _mm_storeu_si128(reinterpret_cast<__m128i*>(pr + x), r);
        __m256 cf[2], ff[2][3];
        for (int half = 0; half < 2; ++half) {
            const Index i = x + 8 * half;  // pixels i .. i + 7
            const __m256 vb = bytes8_floats(b, half), vg = bytes8_floats(g, half),
                         vr = bytes8_floats(r, half), vdp = bytes8_floats(dp, half);
            const __m256 wb = _mm256_loadu_ps(qb + i), wg = _mm256_loadu_ps(qg + i),
                         wr = _mm256_loadu_ps(qr + i);
            // `difference`: frame_c - background_c, also the update's
            const __m256 eb = _mm256_sub_ps(vb, wb), eg = _mm256_sub_ps(vg, wg),
                         er = _mm256_sub_ps(vr, wr);
            const __m256 d = _mm256_max_ps(
                _mm256_and_ps(eb, abs_mask),
                _mm256_max_ps(_mm256_and_ps(eg, abs_mask), _mm256_and_ps(er, abs_mask)));
            _mm256_storeu_si256(reinterpret_cast<__m256i*>(di + i),
                                _mm256_cvttps_epi32(_mm256_min_ps(d, v255)));
            const __m256 c = _mm256_or_ps(
                _mm256_cmp_ps(d, vt, _CMP_GT_OQ),
                _mm256_and_ps(_mm256_cmp_ps(vdp, vt, _CMP_GT_OQ),
                              _mm256_cmp_ps(d, vt_low, _CMP_GT_OQ)));
            // the update: background_c + a (frame_c - background_c), a_fg where a candidate
            const __m256 a = _mm256_blendv_ps(va_bg, va_fg, c);
            _mm256_storeu_ps(ub + i, _mm256_add_ps(wb, _mm256_mul_ps(a, eb)));
            _mm256_storeu_ps(ug + i, _mm256_add_ps(wg, _mm256_mul_ps(a, eg)));
            _mm256_storeu_ps(ur + i, _mm256_add_ps(wr, _mm256_mul_ps(a, er)));
            cf[half] = c;
            ff[half][0] = vb;
            ff[half][1] = vg;
            ff[half][2] = vr;
        }
        if (_mm256_movemask_ps(_mm256_or_ps(cf[0], cf[1])) == 0) {
            _mm_storeu_si128(reinterpret_cast<__m128i*>(m + x), _mm_setzero_si128());
            continue;
        }
        for (int half = 0; half < 2; ++half) {
            const Index i = x + 8 * half;
            _mm256_storeu_ps(fb + i, ff[half][0]);
            _mm256_storeu_ps(fg + i, ff[half][1]);
            _mm256_storeu_ps(fr + i, ff[half][2]);
            _mm256_storeu_ps(cand + i, _mm256_and_ps(cf[half], one));
        }
        for (Index i = x; i < x + kCandidateChunk; ++i)
            m[i] = mask_byte(cand[i] != 0.0f, fb[i], fg[i], fr[i], qb[i], qg[i], qr[i], sh);
    }
    return x;
}

/// `histogram_row_avx2`'s rare step: the bytes of `d` at the set bits of `bits` counted in
/// `h`. Out of line: the call on a rare step costs less than the inlined code's register
/// traffic on every step (`detect` on PETS09 frames 20-59: 167.50 against 167.87 M
/// instructions; either way GCC moves the four counters between registers every step).
__attribute__((target("avx2"), noinline)) inline void count_large(__m256i d, std::uint32_t bits,
                                                                  std::int32_t* h) {
    alignas(32) std::uint8_t bytes[32];
    _mm256_store_si256(reinterpret_cast<__m256i*>(bytes), d);
    for (; bits != 0; bits &= bits - 1) ++h[bytes[__builtin_ctz(bits)]];
}

/// Histogram bins `histogram_row_avx2` counts in vector lanes: at PETS09's noise 95 % of
/// floor(d_bg) values are below 8 (frames 20-199); the rest are counted one by one.
constexpr int kSmallBins = 8;

/// The first n - n % 32 values of a row's floor(d_bg) (`di`, each in 0..255) counted (returned):
/// values 0..7 into `sums`, the others into `h`. 32 values a step, packed to bytes (in lane
/// order, which a count ignores); per pair of bins 2t, 2t + 1 one byte shuffle maps a value to
/// 0x01 (bin 2t), 0x10 (bin 2t + 1) or 0, added to a byte of two 4-bit counters: 2
/// instructions per two bins per 32 values, against 2 a value for the scalar increments
/// (`histogram_row`). A step holding a value of 8 or more increments it in `h` from the bytes.
/// Every 15 steps (before a 4-bit counter can wrap) and at the row's end the counters are
/// summed out: sums[t][0] += the low nibbles' sums (bin 2t), sums[t][1] += the bytes' (bin 2t
/// plus 16 times bin 2t + 1), each as 4 partial sums (`vpsadbw`).
__attribute__((target("avx2"))) inline Index histogram_row_avx2(
    const std::int32_t* __restrict di, Index n, std::uint64_t (*__restrict sums)[2][4],
    std::int32_t* __restrict h) {
    static_assert(kSmallBins == 8, "four shuffles of two bins each");
    const __m256i zero = _mm256_setzero_si256();
    const __m256i low = _mm256_set1_epi8(0x0f);
    // + 0x78 saturated: a value v < 8 becomes 8 + v (bit 7 clear, v + 8 in the low nibble), a
    // larger one gets bit 7 set, which a shuffle maps to 0 and `movemask` picks out
    const __m256i shift = _mm256_set1_epi8(0x78);
    // shuffle t: byte 8 + v (of each 16-byte lane) is 0x01 for v = 2t, 0x10 for v = 2t + 1
    alignas(32) std::uint8_t tables[4][32] = {};
    for (int t = 0; t < 4; ++t)
        for (int lane = 0; lane < 32; lane += 16) {
            tables[t][lane + 8 + 2 * t] = 0x01;
            tables[t][lane + 8 + 2 * t + 1] = 0x10;
        }
    const __m256i t0 = _mm256_load_si256(reinterpret_cast<const __m256i*>(tables[0]));
    const __m256i t1 = _mm256_load_si256(reinterpret_cast<const __m256i*>(tables[1]));
    const __m256i t2 = _mm256_load_si256(reinterpret_cast<const __m256i*>(tables[2]));
    const __m256i t3 = _mm256_load_si256(reinterpret_cast<const __m256i*>(tables[3]));
    const Index whole = n - n % 32;
    Index x = 0;
    while (x < whole) {
        const Index end = std::min(whole, x + 15 * 32);  // a 4-bit counter gains 1 at most a step
        __m256i c0 = zero, c1 = zero, c2 = zero, c3 = zero;
        for (; x < end; x += 32) {
            const auto* p = reinterpret_cast<const __m256i*>(di + x);
            // int32 -> int16 -> uint8 with saturation: 0..255 unchanged
            const __m256i d = _mm256_packus_epi16(
                _mm256_packs_epi32(_mm256_loadu_si256(p), _mm256_loadu_si256(p + 1)),
                _mm256_packs_epi32(_mm256_loadu_si256(p + 2), _mm256_loadu_si256(p + 3)));
            const __m256i s = _mm256_adds_epu8(d, shift);
            c0 = _mm256_add_epi8(c0, _mm256_shuffle_epi8(t0, s));
            c1 = _mm256_add_epi8(c1, _mm256_shuffle_epi8(t1, s));
            c2 = _mm256_add_epi8(c2, _mm256_shuffle_epi8(t2, s));
            c3 = _mm256_add_epi8(c3, _mm256_shuffle_epi8(t3, s));
            auto bits = static_cast<std::uint32_t>(_mm256_movemask_epi8(s));  // values >= 8
            if (__builtin_expect(bits != 0, 0)) count_large(d, bits, h);
        }
        const __m256i cs[4] = {c0, c1, c2, c3};
        for (int t = 0; t < 4; ++t) {
            auto* lo = reinterpret_cast<__m256i*>(sums[t][0]);
            auto* all = reinterpret_cast<__m256i*>(sums[t][1]);
            _mm256_storeu_si256(lo, _mm256_add_epi64(_mm256_loadu_si256(lo),
                                                     _mm256_sad_epu8(_mm256_and_si256(cs[t], low),
                                                                     zero)));
            _mm256_storeu_si256(all, _mm256_add_epi64(_mm256_loadu_si256(all),
                                                      _mm256_sad_epu8(cs[t], zero)));
        }
    }
    return x;
}

/// For each 4-bit mask k of kept lanes, the 32-bit lane indices that move the kept doubles of a
/// 4-double vector to its front, in order (`gain_row_avx2`'s left-pack); the rest are 0.
struct PackTable {
    std::int32_t lanes[16][8];
};
constexpr PackTable make_pack_table() {
    PackTable t{};
    for (int k = 0; k < 16; ++k) {
        int o = 0;
        for (int i = 0; i < 4; ++i)
            if (k & (1 << i)) {
                t.lanes[k][o++] = 2 * i;
                t.lanes[k][o++] = 2 * i + 1;
            }
    }
    return t;
}
inline constexpr PackTable kPackTable = make_pack_table();

/// `BackgroundModel::global_gain`'s samples of one row, 4 a step, where the CPU has AVX2: the
/// pixels x = 0, step, 2 step, ... of `px` (BGR bytes) and `q` (a background row's three float
/// planes of `cols`), while a step's last pixel is at most cols - 2 (its 4-byte load reads one
/// byte past the pixel, inside the row). Per pixel the same integers and doubles as the scalar
/// loop: si = B + G + R added to `levels`; sb = (double(q_b) + double(q_g)) + double(q_r); the
/// ratio si / sb (one division of doubles) kept, in order, at `ratios` + `count` where
/// !(sb < min_sum) and !(sb <= 0) (unordered compares: a NaN keeps or drops as the scalar
/// test does). Writes 4 doubles at `ratios` + `count` a step (room for 3 beyond the kept ones).
/// Returns the first x not done, which the scalar loop continues from.
__attribute__((target("avx2"))) inline Index gain_row_avx2(const std::uint8_t* px, const float* q,
                                                           Index cols, Index step, double min_sum,
                                                           double* ratios, std::size_t& count,
                                                           std::int64_t& levels) {
    const __m128i byte = _mm_set1_epi32(0xff);
    const __m256d ms = _mm256_set1_pd(min_sum), zero = _mm256_setzero_pd();
    __m256i lv = _mm256_setzero_si256();
    std::size_t n = count;
    const Index s = step, s3 = 3 * step;
    const auto bytes4 = [](const std::uint8_t* p) {  // B, G, R and the next byte
        std::int32_t v;
        std::memcpy(&v, p, 4);
        return v;
    };
    Index x = 0;
    for (; x + 3 * step <= cols - 2; x += 4 * step) {
        // scalar loads into lanes, not gathers: AMD's Zen cores microcode a gather (on this
        // machine's EPYC a gather version counted fewer instructions and ran twice as long)
        const std::uint8_t* b = px + 3 * x;
        const __m128i v = _mm_setr_epi32(bytes4(b), bytes4(b + s3), bytes4(b + 2 * s3),
                                         bytes4(b + 3 * s3));
        const __m128i si = _mm_add_epi32(
            _mm_add_epi32(_mm_and_si128(v, byte), _mm_and_si128(_mm_srli_epi32(v, 8), byte)),
            _mm_and_si128(_mm_srli_epi32(v, 16), byte));
        lv = _mm256_add_epi64(lv, _mm256_cvtepi32_epi64(si));
        const float* q0 = q + x;
        const float* q1 = q0 + cols;
        const float* q2 = q1 + cols;
        const __m256d b0 = _mm256_cvtps_pd(_mm_setr_ps(q0[0], q0[s], q0[2 * s], q0[3 * s]));
        const __m256d b1 = _mm256_cvtps_pd(_mm_setr_ps(q1[0], q1[s], q1[2 * s], q1[3 * s]));
        const __m256d b2 = _mm256_cvtps_pd(_mm_setr_ps(q2[0], q2[s], q2[2 * s], q2[3 * s]));
        const __m256d sb = _mm256_add_pd(_mm256_add_pd(b0, b1), b2);
        const __m256d keep = _mm256_and_pd(_mm256_cmp_pd(sb, ms, _CMP_NLT_UQ),
                                           _mm256_cmp_pd(sb, zero, _CMP_NLE_UQ));
        const int k = _mm256_movemask_pd(keep);
        const __m256d r = _mm256_div_pd(_mm256_cvtepi32_pd(si), sb);  // dropped lanes unused
        const __m256i order =
            _mm256_loadu_si256(reinterpret_cast<const __m256i*>(kPackTable.lanes[k]));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(ratios + n),
                            _mm256_permutevar8x32_epi32(_mm256_castpd_si256(r), order));
        n += static_cast<std::size_t>(__builtin_popcount(static_cast<unsigned>(k)));
    }
    alignas(32) std::int64_t l[4];
    _mm256_store_si256(reinterpret_cast<__m256i*>(l), lv);
    levels += (l[0] + l[1]) + (l[2] + l[3]);
    count = n;
    return x;
}
#endif

}  // namespace detail

/// Adaptive background with the paper's selective update. The first frame (or `set_background`)
/// initialises it; every later frame goes through `apply`, which in one read of the frame
///   (a) bins each pixel (`hsv_bin_of`'s bins, via HsvLut),
///   (b) d_bg = max_c |frame_c - background_c|, d_prev = max_c |frame_c - previous_c|,
///   (c) candidate = d_bg > T or (d_prev > T and d_bg > low_ratio * T); a candidate that is a
///       shadow (see BackgroundConfig) is not foreground; mask 255 foreground, 127 shadow,
///       0 background (OpenCV MOG2's convention),
///   (d) background_c += a (frame_c - background_c), a = alpha where not a candidate, alpha_fg
///       where a candidate (foreground or shadow), 0 where a candidate under the caller's
///       `hold` mask (if given); a = max(1 / k, alpha) everywhere but there for the
///       k-th frame while k <= n_learn (float32 arithmetic, in this order, so a NumPy
///       reference matches bit for bit),
///   (e) stores the frame as the previous one, and counts floor(d_bg) in a 256-bin histogram.
/// T for the next frame = clamp(k_noise * median(d_bg), t_min, t_max), the median read from that
/// histogram with linear interpolation inside its bin: a robust noise level, since most pixels
/// are background. The first frame's threshold is t_min.
///
/// Layout: the background and the previous frame are stored planar per row (B row, G row, R
/// row) so that the per-pixel arithmetic runs in unit-stride, branch-free loops the compiler
/// vectorises; `background_bgr` gives the background interleaved, `state` the previous frame.
class BackgroundModel {
public:
    BackgroundModel(const BackgroundConfig& config, const HsvBinning& binning)
        : config_(config), binning_(binning), lut_((binning.validate("BackgroundModel"), binning)) {
        config_.validate("BackgroundModel");
        threshold_ = config_.t_min;
    }

    const BackgroundConfig& config() const { return config_; }
    const HsvBinning& binning() const { return binning_; }
    bool initialized() const { return rows_ > 0; }
    Index rows() const { return rows_; }
    Index cols() const { return cols_; }
    long frame_count() const { return frame_count_; }
    double threshold() const { return threshold_; }
    double threshold_scale() const { return threshold_scale_; }
    const std::array<std::int64_t, 256>& difference_histogram() const { return hist_; }
    /// The background as stored: planar per row, channel c of pixel (y, x) at
    /// [(y * 3 + c) * cols + x] (see `background_bgr` for the interleaved copy).
    const float* background_planar() const { return background_.data(); }

    /// The background, interleaved BGR, into `out` (rows x cols x 3 floats).
    void background_bgr(float* out) const {
        relayout(background_.data(), out, rows_, cols_, false);
    }

    void reset() {
        rows_ = cols_ = 0;
        frame_count_ = 0;
        background_.clear();
        next_.clear();
        previous_.clear();
        threshold_scale_ = 1.0;
        threshold_ = config_.t_min;
        hist_.fill(0);
    }

    /// Set the background (rows x cols x 3 floats, BGR); the previous frame becomes its rounding.
    /// No learning phase follows.
    void set_background(const float* bgr, Index rows, Index cols) {
        allocate(rows, cols);
        learning_ = false;  // a given background needs no learning phase
        for (Index y = 0; y < rows; ++y)
            for (Index x = 0; x < cols; ++x)
                for (int c = 0; c < 3; ++c) {
                    const float v = bgr[(y * cols + x) * 3 + c];
                    background_[static_cast<size_t>((y * 3 + c) * cols + x)] = v;
                    previous_[static_cast<size_t>((y * 3 + c) * cols + x)] =
                        static_cast<std::uint8_t>(std::min(std::max(v, 0.0f), 255.0f) + 0.5f);
                }
    }

    /// Faster update where the caller found a ghost (foreground that is really uncovered
    /// background): background_c += rate (frame_c - background_c) where mask != 0, in float32
    /// in this order. The frame (rows x cols BGR, `row_stride` bytes a row) and the mask
    /// (rows x cols, `mask_stride` bytes a row) must match the model's size.
    void blend(const std::uint8_t* bgr, Index row_stride, const std::uint8_t* mask,
               Index mask_stride, double rate) {
        require(initialized(), "BackgroundModel.blend", "the model has no background yet");
        require(rate >= 0.0 && rate <= 1.0, "BackgroundModel.blend", "rate", rate, "in [0, 1]");
        const float a = static_cast<float>(rate);
        for (Index y = 0; y < rows_; ++y) {
            const std::uint8_t* px = bgr + y * row_stride;
            const std::uint8_t* m = mask + y * mask_stride;
            float* q = background_.data() + y * cols_ * 3;
            for (Index x = 0; x < cols_; ++x) {
                if (!m[x]) continue;
                for (int c = 0; c < 3; ++c) {
                    float& b = q[c * cols_ + x];
                    b = b + a * (static_cast<float>(px[3 * x + c]) - b);
                }
            }
        }
    }

    /// Global gain of a frame (rows x cols BGR, `row_stride` bytes a row) against the
    /// background: the median, over the pixels of every `step`-th row and column whose
    /// background sum B_b + B_g + B_r is at least `min_sum`, of (I_b + I_g + I_r) / (B_b + B_g +
    /// B_r), in double (numpy.median's value: the mean of the two middle ratios for an even
    /// count). Most pixels are background, so a global illumination change shows as a gain far
    /// from 1 while people move it little. 1 when no pixel qualifies. With `mean`, also
    /// `sampled_mean` of the frame at `step` into *mean (the same double; the same grid read
    /// once: the detector asks both of every frame).
    double global_gain(const std::uint8_t* bgr, Index row_stride, Index step, double min_sum,
                       double* mean = nullptr) {
        require(initialized(), "BackgroundModel.global_gain", "the model has no background yet");
        require(step >= 1, "BackgroundModel.global_gain", "step", static_cast<double>(step), ">= 1");
        const Index per_row = (cols_ - 1) / step + 1;
        // room for every sample and the 3 doubles past the kept ones that gain_row_avx2 writes;
        // grown, never shrunk (a resize that shrank and grew again would zero-fill each frame)
        const auto room = static_cast<size_t>(((rows_ - 1) / step + 1) * per_row + 4);
        if (ratios_.size() < room) ratios_.resize(room);
        double* ratios = ratios_.data();
        size_t count = 0;
        std::int64_t levels = 0;  // every sampled pixel's, as sampled_mean sums them
        bool avx2 = false;
#ifdef PFTRACK_LUT_GATHER
        avx2 = detail::avx2_usable();
#endif
        for (Index y = 0; y < rows_; y += step) {
            const std::uint8_t* px = bgr + y * row_stride;
            const float* q = background_.data() + y * cols_ * 3;
            Index x = 0;
#ifdef PFTRACK_LUT_GATHER
            // 38 instructions a pixel in the loop below, 17 there (the detector samples 2700
            // pixels of a PETS09 frame)
            if (avx2) x = detail::gain_row_avx2(px, q, cols_, step, min_sum, ratios, count, levels);
#endif
            for (; x < cols_; x += step) {
                // the sum of three bytes, exact in int and in double: the same ratio as the sum
                // taken in double
                const int si = px[3 * x] + px[3 * x + 1] + px[3 * x + 2];
                levels += si;
                const double sb = static_cast<double>(q[x]) + static_cast<double>(q[cols_ + x]) +
                                  static_cast<double>(q[2 * cols_ + x]);
                if (sb < min_sum || sb <= 0.0) continue;
                ratios[count++] = static_cast<double>(si) / sb;
            }
        }
        if (mean != nullptr) {
            const Index n = ((rows_ - 1) / step + 1) * ((cols_ - 1) / step + 1) * 3;
            *mean = static_cast<double>(levels) / static_cast<double>(n);
        }
        const size_t n = count;
        if (n == 0) return 1.0;
        const size_t k = n / 2;
        std::nth_element(ratios, ratios + k, ratios + n);
        const double hi = ratios[k];
        if (n % 2 == 1) return hi;
        const double lo = *std::max_element(ratios, ratios + k);
        return 0.5 * (lo + hi);
    }

    /// background_c *= gain for every pixel and channel (float32: b = b * float(gain)), clipped
    /// to [0, 255]: follows a global illumination change measured by `global_gain`.
    void scale(double gain) {
        require(initialized(), "BackgroundModel.scale", "the model has no background yet");
        require(std::isfinite(gain) && gain > 0.0, "BackgroundModel.scale", "gain", gain,
                "finite, > 0");
        const float g = static_cast<float>(gain);
        for (float& b : background_) b = std::min(b * g, 255.0f);
    }

    /// Scale the threshold's grey-level bounds: T is clamped to [s t_min, s t_max] (each at
    /// most 255) from now on, and the current T becomes clamp(T s / s_old) in the new bounds.
    /// Follows a global illumination change (`scale`): at a gain of 0.4 a person's contrast
    /// against the background is 0.4 times what it was, and so is the noise. `reset` sets 1.
    void set_threshold_scale(double s) {
        require(std::isfinite(s) && s > 0.0 && s <= 1e6, "BackgroundModel.set_threshold_scale",
                "s", s, "finite, in (0, 1e6]");
        const double t = threshold_ * (s / threshold_scale_);
        threshold_scale_ = s;
        threshold_ = std::min(std::max(t, t_lo()), t_hi());
    }

    /// One frame (rows x cols BGR, `row_stride` bytes a row). Writes `bins` (rows x cols; none
    /// when null: the caller bins only the pixels it keeps, with `hsv_bins_image`) and `mask`
    /// (rows x cols, 255 = foreground, 127 = shadow, 0 = background), both packed. `hold`
    /// (rows x cols, `hold_stride` bytes a row; none when null): candidates where it is not 0
    /// are not learnt at all (rate 0 instead of alpha_fg; the caller's tracked objects that
    /// stopped), the other pixels as usual. Ignored on the first frame.
    void apply(const std::uint8_t* bgr, Index rows, Index cols, Index row_stride, std::int16_t* bins,
               std::uint8_t* mask, const std::uint8_t* hold = nullptr, Index hold_stride = 0) {
        if (!initialized()) {
            first_frame(bgr, rows, cols, row_stride, bins, mask);
            return;
        }
        require(rows == rows_ && cols == cols_, "BackgroundModel.apply",
                "frame shape changed from (" + std::to_string(rows_) + ", " + std::to_string(cols_) +
                    ", 3) to (" + std::to_string(rows) + ", " + std::to_string(cols) +
                    ", 3); call reset() before a new video");
        const float t = static_cast<float>(threshold_);
        const float t_low = static_cast<float>(config_.low_ratio * threshold_);
        // learning phase: the k-th frame (k = frame_count_ + 1 <= n_learn) updates everywhere
        const bool learning = learning_ && frame_count_ + 1 <= config_.n_learn;
        const double a_learn = std::max(1.0 / static_cast<double>(frame_count_ + 1), config_.alpha);
        const float a_bg = static_cast<float>(learning ? a_learn : config_.alpha);
        const float a_fg = static_cast<float>(learning ? a_learn : config_.alpha_fg);
        const float s_lo = static_cast<float>(config_.shadow_lo);
        const float s_chroma = static_cast<float>(config_.shadow_chroma);
        // Eight interleaved histograms: consecutive pixels mostly fall in the same bin, and
        // incrementing one counter back to back would serialise on store-to-load forwarding.
        std::array<std::array<std::int32_t, 256>, 8> h8{};
        // histogram_row_avx2's sums of its counters (bins 0..7)
        std::uint64_t small[detail::kSmallBins / 2][2][4] = {};
        bool hist_avx2 = false;
#ifdef PFTRACK_LUT_GATHER
        hist_avx2 = detail::avx2_usable();
#endif
        const Index n3 = cols * 3;
        const auto ns = static_cast<size_t>(cols);
        scratch_f_.resize(5 * ns);
        scratch_i_.resize(3 * ns);
        float* __restrict fb = scratch_f_.data();
        float* __restrict fg = fb + ns;
        float* __restrict fr = fg + ns;
        float* __restrict dprev = fr + ns;
        float* __restrict cand = dprev + ns;
        std::int32_t* __restrict si = scratch_i_.data();
        std::int32_t* __restrict hi = si + ns;
        std::int32_t* __restrict di = hi + ns;
        const detail::ShadowBounds sh{s_lo, s_chroma};
        // The next frame's background goes into a second buffer (swapped in at the end), so
        // that the differences' loop can write the update while the shadow test after it still
        // reads this frame's background.
        next_.resize(background_.size());
        // the hand-written AVX2 row pass: only without bins (their pass reads the float planes
        // of every pixel) and without a hold row (its update reads the candidate flags)
        bool fused = false;
#ifdef PFTRACK_LUT_GATHER
        fused = bins == nullptr && hold == nullptr && detail::avx2_usable();
#endif
        // Each row in three or four loops over L1-resident row buffers: (1), (2), (3) are
        // vectorised by the compiler (the shadow test of (2) too, over every pixel of each
        // 16-pixel chunk that has a candidate, skipped in the others: cheaper than branching
        // pixel by pixel); (4) does the table look-ups and the histogram, which cannot be.
        for (Index y = 0; y < rows; ++y) {
            const std::uint8_t* __restrict px = bgr + y * row_stride;
            const float* __restrict qb = background_.data() + y * n3;
            const float* __restrict qg = qb + cols;
            const float* __restrict qr = qg + cols;
            float* __restrict ub = next_.data() + y * n3;
            std::uint8_t* __restrict prev = previous_.data() + y * n3;  // planar, as qb
            std::int16_t* __restrict o = bins != nullptr ? bins + y * cols : nullptr;
            std::uint8_t* __restrict m = mask + y * cols;
            // (1) + (2) without bins or hold row, where the CPU has AVX2: by hand, 16 pixels a
            //     step, the frame's floats kept in registers; the row's last cols % 16 pixels
            //     by the loops below
            Index done = 0;
#ifdef PFTRACK_LUT_GATHER
            if (fused)
                done = detail::background_row_fused_avx2(
                    cols, px, prev, prev + cols, prev + 2 * cols, qb, qg, qr, t, t_low, sh, di, fb,
                    fg, fr, cand, m, a_bg, a_fg, ub, ub + cols, ub + 2 * cols);
#endif
            if (done == cols) {
                count_row(h8, small, hist_avx2, di, cols);
                continue;
            }
            // (1) deinterleave into float planes, d_prev; I' <- I
            detail::background_row_split(cols - done, px + 3 * done, prev + done,
                                         prev + cols + done, prev + 2 * cols + done, fb + done,
                                         fg + done, fr + done, dprev + done);
            // (2) per pixel: d_bg, candidates, mask, and (without a hold row) the selective
            //     update background_c + a (frame_c - background_c) into the next buffer
            if (hold == nullptr)
                detail::background_row_candidates_update(
                    cols - done, fb + done, fg + done, fr + done, qb + done, qg + done, qr + done,
                    dprev + done, t, t_low, sh, di + done, cand + done, m + done, a_bg, a_fg,
                    ub + done, ub + cols + done, ub + 2 * cols + done);
            else
                detail::background_row_candidates(cols, fb, fg, fr, qb, qg, qr, dprev, t, t_low,
                                                  sh, di, cand, m);
            // (3) table indices (with bins)
            if (o != nullptr) detail::hsv_plane_indices(cols, fb, fg, fr, si, hi);
            // (4) bins by table look-up, histogram of floor(d_bg)
            if (o != nullptr)
                for (Index x = 0; x < cols; ++x)
                    o[x] = static_cast<std::int16_t>(lut_.bin_at(si[x], hi[x]));
            count_row(h8, small, hist_avx2, di, cols);
            // (5) with a hold row, the selective update (a = 0 under the hold) into the next buffer
            if (hold != nullptr)
                detail::background_row_update_held(cols, fb, fg, fr, qb, qg, qr, cand,
                                                   hold + y * hold_stride, a_bg, a_fg, ub,
                                                   ub + cols, ub + 2 * cols);
        }
        background_.swap(next_);
        for (size_t i = 0; i < 256; ++i) {
            std::int64_t c = 0;
            for (const auto& h : h8) c += h[i];
            if (i < static_cast<size_t>(detail::kSmallBins)) {
                // bin 2t: the low nibbles' sum; bin 2t + 1: (the bytes' sum - that) / 16
                std::uint64_t lo = 0, all = 0;
                for (int q = 0; q < 4; ++q) {
                    lo += small[i / 2][0][q];
                    all += small[i / 2][1][q];
                }
                c += static_cast<std::int64_t>(i % 2 == 0 ? lo : (all - lo) / 16);
            }
            hist_[i] = c;
        }
        threshold_ = next_threshold();
        ++frame_count_;
    }

    /// floor(d_bg) of a row's n pixels (`di`) counted into `h8`, pixel x into copy x mod 8:
    /// eight at a time, each copy's address fixed (was 9 instructions a pixel, the copy's
    /// address computed from x; now about 2.4).
    static void histogram_row(std::array<std::array<std::int32_t, 256>, 8>& h8,
                              const std::int32_t* di, Index n) {
        Index x = 0;
        for (; x + 8 <= n; x += 8)
            for (size_t q = 0; q < 8; ++q)
                ++h8[q][static_cast<size_t>(di[x + static_cast<Index>(q)])];
        for (; x < n; ++x) ++h8[static_cast<size_t>(x & 7)][static_cast<size_t>(di[x])];
    }

    /// A row's floor(d_bg) (`di`, n values) counted: by `detail::histogram_row_avx2` (into
    /// `small` and `h8[0]`) where `avx2`, the row's last n % 32 and every value otherwise by
    /// `histogram_row`.
    static void count_row(std::array<std::array<std::int32_t, 256>, 8>& h8,
                          std::uint64_t (*small)[2][4], bool avx2, const std::int32_t* di, Index n) {
        Index done = 0;
#ifdef PFTRACK_LUT_GATHER
        if (avx2) done = detail::histogram_row_avx2(di, n, small, h8[0].data());
#else
        (void)small;
        (void)avx2;
#endif
        histogram_row(h8, di + done, n - done);
    }

    /// Everything a model has learnt (not its settings, not per-call scratch): what a pickled
    /// model carries. `restore` checks a state's sizes before taking it.
    struct State {
        Index rows = 0, cols = 0;
        long frame_count = 0;
        bool learning = false;
        double threshold = 0.0, threshold_scale = 1.0;
        std::vector<float> background;
        std::vector<std::uint8_t> previous;
        std::array<std::int64_t, 256> hist{};
    };

    /// The previous frame goes out interleaved (BGR bytes, as the frame and as the states of
    /// models before it was kept planar), so that pickles keep their layout.
    State state() const {
        return State{rows_,           cols_,       frame_count_,
                     learning_,       threshold_,  threshold_scale_,
                     background_,     relaid(previous_, rows_, cols_, false), hist_};
    }

    void restore(State s) {
        const char* fn = "BackgroundModel.__setstate__";
        require(s.rows >= 0 && s.cols >= 0 && (s.rows == 0) == (s.cols == 0), fn, "size",
                s.rows * s.cols, "rows and cols both 0 or both > 0");
        const auto n = static_cast<size_t>(s.rows * s.cols * 3);
        require(s.background.size() == n && s.previous.size() == n, fn, "background size",
                s.background.size(), n);
        require(s.frame_count >= 0, fn, "frame_count", s.frame_count, ">= 0");
        require(std::isfinite(s.threshold) && std::isfinite(s.threshold_scale) &&
                    s.threshold_scale > 0.0,
                fn, "threshold scale", s.threshold_scale, "finite and > 0");
        rows_ = s.rows;
        cols_ = s.cols;
        frame_count_ = s.frame_count;
        learning_ = s.learning;
        threshold_ = s.threshold;
        threshold_scale_ = s.threshold_scale;
        background_ = std::move(s.background);
        previous_ = relaid(s.previous, rows_, cols_, true);
        hist_ = s.hist;
    }

private:
    /// Rows of B, G, R planes (rows x 3 x cols: channel c of pixel (y, x) at
    /// [(y * 3 + c) * cols + x]) into interleaved BGR (rows x cols x 3) at `out`, or back
    /// when `to_planar`. Not a per-frame path: pickling, and the background for Python.
    template <class T>
    static void relayout(const T* in, T* out, Index rows, Index cols, bool to_planar) {
        for (Index y = 0; y < rows; ++y)
            for (int c = 0; c < 3; ++c)
                for (Index x = 0; x < cols; ++x) {
                    const Index planar = (y * 3 + c) * cols + x, bgr = (y * cols + x) * 3 + c;
                    if (to_planar)
                        out[planar] = in[bgr];
                    else
                        out[bgr] = in[planar];
                }
    }

    static std::vector<std::uint8_t> relaid(const std::vector<std::uint8_t>& in, Index rows,
                                            Index cols, bool to_planar) {
        std::vector<std::uint8_t> out(in.size());
        relayout(in.data(), out.data(), rows, cols, to_planar);
        return out;
    }

    void allocate(Index rows, Index cols) {
        rows_ = rows;
        cols_ = cols;
        background_.resize(static_cast<size_t>(rows * cols * 3));
        previous_.resize(static_cast<size_t>(rows * cols * 3));
        threshold_ = t_lo();
        hist_.fill(0);
    }

    void first_frame(const std::uint8_t* bgr, Index rows, Index cols, Index row_stride,
                     std::int16_t* bins, std::uint8_t* mask) {
        allocate(rows, cols);
        learning_ = true;
        for (Index y = 0; y < rows; ++y) {
            const std::uint8_t* px = bgr + y * row_stride;
            for (Index x = 0; x < cols; ++x) {
                for (int c = 0; c < 3; ++c) {
                    background_[static_cast<size_t>((y * 3 + c) * cols + x)] =
                        static_cast<float>(px[3 * x + c]);
                    previous_[static_cast<size_t>((y * 3 + c) * cols + x)] = px[3 * x + c];
                }
                if (bins != nullptr)
                    bins[y * cols + x] = static_cast<std::int16_t>(
                        lut_.bin(px[3 * x], px[3 * x + 1], px[3 * x + 2]));
            }
        }
        std::fill(mask, mask + rows * cols, std::uint8_t(0));
        ++frame_count_;
    }

    double next_threshold() const {
        const double half = 0.5 * static_cast<double>(rows_ * cols_);
        double cum = 0.0, median = 255.0;
        for (int i = 0; i < 256; ++i) {
            const double c = static_cast<double>(hist_[static_cast<size_t>(i)]);
            if (cum + c >= half) {
                median = i + (half - cum) / c;
                break;
            }
            cum += c;
        }
        return std::min(std::max(config_.k_noise * median, t_lo()), t_hi());
    }

    // the threshold's bounds, scaled by set_threshold_scale (t_min, t_max at scale 1)
    double t_lo() const { return std::min(threshold_scale_ * config_.t_min, 255.0); }
    double t_hi() const { return std::min(threshold_scale_ * config_.t_max, 255.0); }

    BackgroundConfig config_;
    HsvBinning binning_;
    HsvLut lut_;
    Index rows_ = 0, cols_ = 0;
    long frame_count_ = 0;
    bool learning_ = false;  // started from a frame (not set_background): learning phase on
    double threshold_ = 0.0;
    double threshold_scale_ = 1.0;  // set_threshold_scale
    std::vector<float> background_;      // planar rows: [y][channel][x]
    std::vector<float> next_;  // apply's scratch: the next frame's background, swapped in
    std::vector<std::uint8_t> previous_;  // planar rows, as the background: [y][channel][x]
    std::array<std::int64_t, 256> hist_{};
    std::vector<double> ratios_;  // global_gain's sampled frame / background ratios
    std::vector<float> scratch_f_;  // row scratch: B, G, R planes, d_prev, candidate flag
    std::vector<std::int32_t> scratch_i_;  // row scratch: table indices, histogram bins
};

namespace detail {

/// count[e] += v[e] < cand[e] (its own function: `__restrict` on the arguments is what lets
/// the compiler vectorise it).
inline void count_less(const std::uint8_t* __restrict v, const std::uint8_t* __restrict cand,
                       std::uint16_t* __restrict count, Index n) {
    for (Index e = 0; e < n; ++e)
        count[e] = static_cast<std::uint16_t>(count[e] + (v[e] < cand[e] ? 1 : 0));
}

/// For each of the n elements: the k-th smallest (0-based) of the m <= 65535 values
/// frames[0][e], ..., frames[m-1][e], by a binary search on the value's bits (the largest x with
/// #{v < x} <= k), 8 passes over the m values, each vectorised over the elements.
PFTRACK_VECTOR_CLONES static void kth_smallest_u8(const std::uint8_t* const* frames, Index m,
                                                   Index n, Index k, std::uint8_t* __restrict out,
                                                   std::uint8_t* __restrict cand,
                                                   std::uint16_t* __restrict count) {
    const auto kk = static_cast<std::uint16_t>(k);
    for (Index e = 0; e < n; ++e) out[e] = 0;
    for (int bit = 7; bit >= 0; --bit) {
        const auto step = static_cast<std::uint8_t>(1 << bit);
        for (Index e = 0; e < n; ++e) {
            cand[e] = static_cast<std::uint8_t>(out[e] | step);  // the lower bits are still 0
            count[e] = 0;
        }
        for (Index f = 0; f < m; ++f) count_less(frames[f], cand, count, n);
        for (Index e = 0; e < n; ++e) out[e] = count[e] <= kk ? cand[e] : out[e];
    }
}

/// count[e] += v[e] <= lo[e] (its own function for `__restrict`, as `count_less`).
inline void count_at_most(const std::uint8_t* __restrict v, const std::uint8_t* __restrict lo,
                          std::uint16_t* __restrict count, Index n) {
    for (Index e = 0; e < n; ++e)
        count[e] = static_cast<std::uint16_t>(count[e] + (v[e] <= lo[e] ? 1 : 0));
}

/// above[e] = min(above[e], v[e] > lo[e] ? v[e] : 255), likewise.
inline void least_above(const std::uint8_t* __restrict v, const std::uint8_t* __restrict lo,
                        std::uint8_t* __restrict above, Index n) {
    for (Index e = 0; e < n; ++e)
        above[e] = std::min(above[e], static_cast<std::uint8_t>(v[e] > lo[e] ? v[e] : 255));
}

/// For each of the n elements, the k-th smallest (0-based) of the m values, given `lo`, the
/// (k - 1)-th: lo itself when more than k values are at most lo, else the least value above
/// it. One pass over the m values.
PFTRACK_VECTOR_CLONES static void next_up_u8(const std::uint8_t* const* frames, Index m, Index n,
                                              Index k, const std::uint8_t* __restrict lo,
                                              std::uint8_t* __restrict out,
                                              std::uint16_t* __restrict count) {
    for (Index e = 0; e < n; ++e) {
        count[e] = 0;
        out[e] = 255;
    }
    for (Index f = 0; f < m; ++f) {
        count_at_most(frames[f], lo, count, n);
        least_above(frames[f], lo, out, n);
    }
    const auto kk = static_cast<std::uint16_t>(k);
    for (Index e = 0; e < n; ++e) out[e] = count[e] > kk ? lo[e] : out[e];
}

}  // namespace detail

/// Per-element median of m >= 1 images of n bytes each (`frames[f]` points at image f's row
/// `y`, see the binding): numpy.median's value, the middle one for odd m, the mean of the two
/// middle ones for even m (exact in float32: a half-integer). `lo`, `hi`, `cand`, `count` are
/// scratch of
/// n elements; m <= 65535.
inline void median_u8(const std::uint8_t* const* frames, Index m, Index n, float* out,
                      std::uint8_t* lo, std::uint8_t* hi, std::uint8_t* cand,
                      std::uint16_t* count) {
    detail::kth_smallest_u8(frames, m, n, (m - 1) / 2, lo, cand, count);
    if (m % 2 == 1) {
        for (Index e = 0; e < n; ++e) out[e] = static_cast<float>(lo[e]);
        return;
    }
    // the next one up, in one pass instead of a second selection: lo again when more than
    // m / 2 values are at most lo, else the least value above lo
    detail::next_up_u8(frames, m, n, m / 2, lo, hi, count);
    for (Index e = 0; e < n; ++e)
        out[e] = 0.5f * (static_cast<float>(lo[e]) + static_cast<float>(hi[e]));
}

namespace detail {

/// One row of `mask_bins` (restrict-qualified arguments: the loop vectorises).
PFTRACK_VECTOR_CLONES static void mask_bins_row(const std::int16_t* __restrict src,
                                                const std::uint8_t* __restrict m,
                                                std::int16_t* __restrict o, Index cols) {
    // branch-free: -1 (all bits set) where the mask is 0, the bin where it is not
    for (Index x = 0; x < cols; ++x)
        o[x] = static_cast<std::int16_t>(src[x] | -static_cast<std::int16_t>(m[x] == 0));
}

/// `mask_bins_row` in place: o[x] = -1 where m[x] is 0.
PFTRACK_VECTOR_CLONES static void mask_bins_in_place(std::int16_t* __restrict o,
                                                     const std::uint8_t* __restrict m, Index n) {
    for (Index x = 0; x < n; ++x)
        o[x] = static_cast<std::int16_t>(o[x] | -static_cast<std::int16_t>(m[x] == 0));
}

}  // namespace detail

/// `HsvLut::bin` of every pixel of a BGR frame (rows x cols, `row_stride` bytes a row) into
/// `out` (rows x cols, packed), -1 where `mask` (if not null, `mask_stride` bytes a row) is 0: a
/// whole row by `HsvLut::bins_of_row` (AVX2), else the table indices of the row by the
/// vectorised `hsv_row_indices`, then the look-ups (the same bins as `HsvLut::bin` pixel by
/// pixel, several times faster). With a mask, only the 8-pixel groups that hold a masked pixel
/// are binned: a foreground mask leaves most pixels out, and most rows empty (skipped 32, then
/// 8 bytes at a time: `skip_zero_words`); each run of such groups by `bins_of_row`, then -1
/// where the mask is 0 (without AVX2: the masked pixels one by one). `out_stride` is in
/// elements: the bins of one rectangle of a larger image (each pixel's bin depends on that pixel
/// only, so any rectangle gets the bins the whole image would).
inline void hsv_bins_image(const HsvLut& lut, const std::uint8_t* bgr, Index rows, Index cols,
                           Index row_stride, const std::uint8_t* mask, Index mask_stride,
                           std::int16_t* out, Index out_stride) {
    std::vector<std::int32_t> si, hi;  // the table indices of a row, without AVX2
    const bool avx2 = mask != nullptr && detail::avx2_usable();
    for (Index y = 0; y < rows; ++y) {
        std::int16_t* o = out + y * out_stride;
        const std::uint8_t* px = bgr + y * row_stride;
        if (mask == nullptr) {
            if (lut.bins_of_row(cols, px, o)) continue;
            si.resize(static_cast<size_t>(cols));
            hi.resize(static_cast<size_t>(cols));
            detail::hsv_row_indices(cols, px, si.data(), hi.data());
            for (Index x = 0; x < cols; ++x)
                o[x] = static_cast<std::int16_t>(lut.bin_at(si[static_cast<size_t>(x)],
                                                            hi[static_cast<size_t>(x)]));
            continue;
        }
        const std::uint8_t* m = mask + y * mask_stride;
        std::fill(o, o + cols, std::int16_t(-1));
        Index x = 0;
        while (x < cols) {
            x = detail::skip_zero_words(m, x, cols, avx2);  // most rows are background
            if (x + 8 <= cols) {
                std::uint64_t word;
                // a run of 8-pixel groups that each hold a masked pixel (a blob's row): binned
                // whole by `bins_of_row` (AVX2: about 5 instructions a pixel, against 25 for
                // one pixel's `bin`), then -1 where the mask is 0
                Index end = x + 8;
                while (end + 8 <= cols) {
                    std::memcpy(&word, m + end, 8);
                    if (word == 0) break;
                    end += 8;
                }
                if (lut.bins_of_row(end - x, px + 3 * x, o + x)) {
                    detail::mask_bins_in_place(o + x, m + x, end - x);
                    x = end;
                    continue;
                }
            }
            const Index stop = std::min(x + 8, cols);
            for (; x < stop; ++x)
                if (m[x] != 0)
                    o[x] = static_cast<std::int16_t>(
                        lut.bin(px[3 * x], px[3 * x + 1], px[3 * x + 2]));
        }
    }
}

/// `hsv_bins_image` into a packed `out` (rows x cols).
inline void hsv_bins_image(const HsvLut& lut, const std::uint8_t* bgr, Index rows, Index cols,
                           Index row_stride, const std::uint8_t* mask, Index mask_stride,
                           std::int16_t* out) {
    hsv_bins_image(lut, bgr, rows, cols, row_stride, mask, mask_stride, out, cols);
}

/// The mean level of every `step`-th pixel of every `step`-th row, over its three channels:
/// numpy's ``frame[::step, ::step].mean()`` as the same double (its float64 sum of these
/// integers is exact in any order, below 2^53, and is divided by the count as here). Any
/// strides, in bytes (rows `s_row`, pixels `s_px`, channels `s_ch`; negative ones too).
/// The light's darkness test of every frame (python/pftrack/detection/light.py `is_dark`):
/// about a tenth of NumPy's strided reduction's time.
inline double sampled_mean(const std::uint8_t* bgr, Index rows, Index cols, Index s_row,
                           Index s_px, Index s_ch, Index step) {
    std::int64_t sum = 0;
    for (Index y = 0; y < rows; y += step) {
        const std::uint8_t* row = bgr + y * s_row;
        std::int64_t s = 0;
        for (Index x = 0; x < cols; x += step) {
            const std::uint8_t* p = row + x * s_px;
            s += static_cast<std::int64_t>(p[0]) + p[s_ch] + p[2 * s_ch];
        }
        sum += s;
    }
    const Index n = ((rows - 1) / step + 1) * ((cols - 1) / step + 1) * 3;  // rows, cols >= 1
    return static_cast<double>(sum) / static_cast<double>(n);
}

/// Bins with background set to -1: out = mask == 0 ? -1 : bins.
inline void mask_bins(const std::int16_t* bins, Index rows, Index cols, const std::uint8_t* mask,
                      Index mask_stride, std::int16_t* out) {
    for (Index y = 0; y < rows; ++y) {
        detail::mask_bins_row(bins + y * cols, mask + y * mask_stride, out + y * cols, cols);
    }
}

}  // namespace pftrack
