// The still camera's measurement (python/pftrack/tracking/camera.py): Lucas-Kanade flow of a few
// corners at one level, and the closed-form similarity fit of matched points.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pftrack/check.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

// grey_halved's AVX2 pass, chosen at run time (the CPU's flag and background.hpp's
// detail::avx2_allowed, which a test turns off to hold the portable loop to the same reference)
#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__)
#define PFTRACK_GREY_AVX2 1
#include <immintrin.h>

#include "pftrack/background.hpp"
#endif

namespace pftrack {

/// A grey uint8 image: `rows` x `cols` pixels, row `r` at `data + r * stride`.
struct GreyImage {
    const std::uint8_t* data;
    int rows;
    int cols;
    std::ptrdiff_t stride;
    const std::uint8_t* row(int r) const { return data + static_cast<std::ptrdiff_t>(r) * stride; }
};

namespace flow_detail {

/// Index `p` of a row or column of `len` mapped into [0, len) by reflection about the edge
/// pixels (OpenCV's BORDER_REFLECT_101: -1 -> 1, len -> len - 2), repeated for short sides.
inline int reflect_101(int p, int len) {
    if (len == 1) return 0;
    while (p < 0 || p >= len) p = p < 0 ? -p : 2 * len - 2 - p;
    return p;
}

/// OpenCV's cvFloor and cvRound of a float (round half to even, as cvtss2si).
inline int floor_f(float v) {
    const int i = static_cast<int>(v);
    return i - (static_cast<float>(i) > v ? 1 : 0);
}
inline int round_f(float v) { return static_cast<int>(std::lrint(v)); }

constexpr int kWBits = 14;                            // bilinear weights in 1/2^14
constexpr float kFltScale = 1.f / (1 << 20);          // the sums' scale (OpenCV's FLT_SCALE)
inline int descale(int x, int n) { return (x + (1 << (n - 1))) >> n; }

/// The four bilinear weights of fractional offsets (a, b), in 1/2^14, summing to 2^14.
struct Weights {
    int w00, w01, w10, w11;
    Weights(float a, float b) {
        w00 = round_f((1.f - a) * (1.f - b) * static_cast<float>(1 << kWBits));
        w01 = round_f(a * (1.f - b) * static_cast<float>(1 << kWBits));
        w10 = round_f((1.f - a) * b * static_cast<float>(1 << kWBits));
        w11 = (1 << kWBits) - w00 - w01 - w10;
    }
};

#if defined(__SSE2__)
/// Two int16 weights (lo, hi) in every 32-bit lane, for `_mm_madd_epi16` of (left, right) pairs.
inline __m128i weight_pair(int lo, int hi) {
    return _mm_set1_epi32(static_cast<int>((static_cast<unsigned>(hi) << 16) |
                                           (static_cast<unsigned>(lo) & 0xffffu)));
}

/// Eight bilinear values of 16-bit pixels (v00, v01: a row and its right neighbours; v10, v11:
/// the next row's) with the weight pairs `qw0`, `qw1`, rounded by `qdelta` and shifted right by
/// `shift`: OpenCV's SSE2 steps, in its order, packed to int16.
inline __m128i bilinear8(__m128i v00, __m128i v01, __m128i v10, __m128i v11, __m128i qw0,
                         __m128i qw1, __m128i qdelta, int shift) {
    const __m128i t0 = _mm_add_epi32(
        _mm_add_epi32(_mm_madd_epi16(_mm_unpacklo_epi16(v00, v01), qw0), qdelta),
        _mm_madd_epi16(_mm_unpacklo_epi16(v10, v11), qw1));
    const __m128i t1 = _mm_add_epi32(
        _mm_add_epi32(_mm_madd_epi16(_mm_unpackhi_epi16(v00, v01), qw0), qdelta),
        _mm_madd_epi16(_mm_unpackhi_epi16(v10, v11), qw1));
    const __m128i c = _mm_cvtsi32_si128(shift);
    return _mm_packs_epi32(_mm_sra_epi32(t0, c), _mm_sra_epi32(t1, c));
}
#endif

/// One step's mismatch sums of a window: J, the next image's window (win_h + 1 rows of `bs`
/// bytes), bilinear at weights `v`, less the previous window's values `iv` (int16, rows of
/// `ws`), times its derivatives `dv` (Ix, Iy pairs, rows of 2 ws). The first `simd_w` columns
/// of a row go to two sets of four float lanes as OpenCV's SSE loop sums them (qb0: pixels 0
/// and 1 of each 8, paired with 4 and 5, lanes [x, y, x, y]; qb1: pixels 2 and 3 with 6 and 7),
/// whose lane-by-lane sum is written to `s`; the rest go to `b1`, `b2` one by one. Every integer
/// is exact; the float adds are OpenCV's, in its order.
inline void sums_of_window(const std::uint8_t* jb, int bs, const std::int16_t* iv,
                           const std::int16_t* dv, int ws, int win_w, int win_h, int simd_w,
                           const Weights& v, float* s, float& b1, float& b2) {
#if defined(__SSE2__)
    const __m128i z = _mm_setzero_si128();
    const __m128i qw0 = weight_pair(v.w00, v.w01), qw1 = weight_pair(v.w10, v.w11);
    const __m128i qdelta = _mm_set1_epi32(1 << (kWBits - 5 - 1));
    __m128 qb0 = _mm_setzero_ps(), qb1 = _mm_setzero_ps();
    const auto ld = [&](const std::uint8_t* q) {
        return _mm_unpacklo_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(q)), z);
    };
#else
    float q0[4] = {0, 0, 0, 0}, q1[4] = {0, 0, 0, 0};
#endif
    for (int y = 0; y < win_h; ++y) {
        const std::uint8_t* j0 = jb + y * bs;
        const std::uint8_t* j1 = j0 + bs;
        const std::int16_t* ir = iv + y * ws;
        const std::int16_t* dr = dv + y * ws * 2;
        int x = 0;
        for (; x < simd_w; x += 8) {
#if defined(__SSE2__)
            const __m128i v00 = ld(j0 + x), v01 = ld(j0 + x + 1);
            const __m128i v10 = ld(j1 + x), v11 = ld(j1 + x + 1);
            const __m128i diff0 =
                _mm_sub_epi16(bilinear8(v00, v01, v10, v11, qw0, qw1, qdelta, kWBits - 5),
                              _mm_loadu_si128(reinterpret_cast<const __m128i*>(ir + x)));
            const __m128i diff2 = _mm_unpacklo_epi16(diff0, diff0);  // d0 d0 d1 d1 ...
            const __m128i diff1 = _mm_unpackhi_epi16(diff0, diff0);  // d4 d4 d5 d5 ...
            const __m128i d0 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(dr + 2 * x));
            const __m128i d1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(dr + 2 * x + 8));
            const __m128i g0 = _mm_unpacklo_epi16(d0, d1), g1 = _mm_unpackhi_epi16(d0, d1);
            const __m128i e0 = _mm_unpacklo_epi16(diff2, diff1);
            const __m128i e1 = _mm_unpackhi_epi16(diff2, diff1);
            qb0 = _mm_add_ps(qb0, _mm_cvtepi32_ps(_mm_madd_epi16(e0, g0)));
            qb1 = _mm_add_ps(qb1, _mm_cvtepi32_ps(_mm_madd_epi16(e1, g1)));
#else
            int d[8];
            for (int t = 0; t < 8; ++t)
                d[t] = descale(j0[x + t] * v.w00 + j0[x + t + 1] * v.w01 + j1[x + t] * v.w10 +
                                   j1[x + t + 1] * v.w11, kWBits - 5) - ir[x + t];
            const std::int16_t* g = dr + 2 * x;
            for (int u = 0; u < 2; ++u) {
                const int a = u, b = 2 + u;  // pixels of qb0 and of qb1
                q0[2 * u] += static_cast<float>(d[a] * g[2 * a] + d[a + 4] * g[2 * a + 8]);
                q0[2 * u + 1] += static_cast<float>(d[a] * g[2 * a + 1] + d[a + 4] * g[2 * a + 9]);
                q1[2 * u] += static_cast<float>(d[b] * g[2 * b] + d[b + 4] * g[2 * b + 8]);
                q1[2 * u + 1] += static_cast<float>(d[b] * g[2 * b + 1] + d[b + 4] * g[2 * b + 9]);
            }
#endif
        }
        for (; x < win_w; ++x) {
            const int d = descale(j0[x] * v.w00 + j0[x + 1] * v.w01 + j1[x] * v.w10 +
                                      j1[x + 1] * v.w11, kWBits - 5) - ir[x];
            b1 += static_cast<float>(d * dr[2 * x]);
            b2 += static_cast<float>(d * dr[2 * x + 1]);
        }
    }
#if defined(__SSE2__)
    _mm_storeu_ps(s, _mm_add_ps(qb0, qb1));
#else
    for (int k = 0; k < 4; ++k) s[k] = q0[k] + q1[k];
#endif
}

#if defined(__SSE2__)
/// The window's lanes of Ix Ix, Ix Iy and Iy Iy (OpenCV's qA11, qA12, qA22).
struct Lanes {
    __m128 a11 = _mm_setzero_ps(), a12 = _mm_setzero_ps(), a22 = _mm_setzero_ps();
};

/// Eight columns of a row of the previous window, as OpenCV's SSE loop makes them: the pixels'
/// bilinear values (s0, s1: this row and the next, bytes) descaled to 1/32 into `iv`, the
/// derivatives' (g0, g1: Ix, Iy pairs) descaled into `dv`, and their products added to the
/// lanes, pixels 0-3 then 4-7 (lane k: pixel k, then k + 4).
inline void window_block(const std::uint8_t* s0, const std::uint8_t* s1, const std::int16_t* g0,
                         const std::int16_t* g1, const Weights& w, std::int16_t* iv,
                         std::int16_t* dv, Lanes& lanes) {
    const __m128i z = _mm_setzero_si128();
    const __m128i qw0 = weight_pair(w.w00, w.w01), qw1 = weight_pair(w.w10, w.w11);
    const __m128i qdelta = _mm_set1_epi32(1 << (kWBits - 5 - 1));
    const __m128i qdelta_d = _mm_set1_epi32(1 << (kWBits - 1));
    const auto ld8 = [&](const std::uint8_t* q) {
        return _mm_unpacklo_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(q)), z);
    };
    const auto ld16 = [](const std::int16_t* q) {
        return _mm_loadu_si128(reinterpret_cast<const __m128i*>(q));
    };
    const __m128i v00 = ld8(s0), v01 = ld8(s0 + 1), v10 = ld8(s1), v11 = ld8(s1 + 1);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(iv),
                     bilinear8(v00, v01, v10, v11, qw0, qw1, qdelta, kWBits - 5));
    for (int half = 0; half < 2; ++half) {
        const int o = 8 * half;  // int16 offset of pixels 4-7
        const __m128i d00 = ld16(g0 + o), d01 = ld16(g0 + o + 2);
        const __m128i d10 = ld16(g1 + o), d11 = ld16(g1 + o + 2);
        const __m128i g = bilinear8(d00, d01, d10, d11, qw0, qw1, qdelta_d, kWBits);
        _mm_storeu_si128(reinterpret_cast<__m128i*>(dv + o), g);  // Ix0 Iy0 Ix1 Iy1 ...
        const __m128 fy = _mm_cvtepi32_ps(_mm_srai_epi32(g, 16));
        const __m128 fx = _mm_cvtepi32_ps(_mm_srai_epi32(_mm_slli_epi32(g, 16), 16));
        lanes.a22 = _mm_add_ps(lanes.a22, _mm_mul_ps(fy, fy));
        lanes.a12 = _mm_add_ps(lanes.a12, _mm_mul_ps(fx, fy));
        lanes.a11 = _mm_add_ps(lanes.a11, _mm_mul_ps(fx, fx));
    }
}
#endif

#if defined(__SSE2__)
/// Scharr derivatives of 12 pixels of a row inside the image, as calcScharrDeriv's: `u`, `o`,
/// `d` point at the column left of the first pixel in the rows above, at and below it (14
/// columns read); writes 12 (Ix, Iy) pairs to `g`. Integers, exact in int16.
inline void scharr_row_12(const std::uint8_t* u, const std::uint8_t* o, const std::uint8_t* d,
                          std::int16_t* g) {
    const __m128i z = _mm_setzero_si128(), c3 = _mm_set1_epi16(3), c10 = _mm_set1_epi16(10);
    alignas(16) std::int16_t t0[16], t1[16];
    for (int c0 : {0, 6}) {  // columns 0-7 and 6-13
        const auto ld = [&](const std::uint8_t* q) {
            return _mm_unpacklo_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(q + c0)), z);
        };
        const __m128i a = ld(u), m = ld(o), b = ld(d);
        _mm_storeu_si128(reinterpret_cast<__m128i*>(t0 + c0),
                         _mm_add_epi16(_mm_mullo_epi16(_mm_add_epi16(a, b), c3),
                                       _mm_mullo_epi16(m, c10)));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(t1 + c0), _mm_sub_epi16(b, a));
    }
    for (int x0 : {0, 4}) {  // pixels 0-7 and 4-11
        const auto ld = [](const std::int16_t* q) {
            return _mm_loadu_si128(reinterpret_cast<const __m128i*>(q));
        };
        const __m128i gx = _mm_sub_epi16(ld(t0 + x0 + 2), ld(t0 + x0));
        const __m128i gy = _mm_add_epi16(
            _mm_mullo_epi16(_mm_add_epi16(ld(t1 + x0), ld(t1 + x0 + 2)), c3),
            _mm_mullo_epi16(ld(t1 + x0 + 1), c10));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(g + 2 * x0), _mm_unpacklo_epi16(gx, gy));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(g + 2 * x0 + 8), _mm_unpackhi_epi16(gx, gy));
    }
}
#endif

}  // namespace flow_detail

/// Lucas-Kanade optical flow of `n` points `pts` (x, y pairs) of `prev` into `next` (same size)
/// on the images alone (no pyramid), as OpenCV's ``calcOpticalFlowPyrLK(prev, next, pts, None,
/// winSize=(win_w, win_h), maxLevel=0, criteria=(COUNT | EPS, max_count, epsilon), flags=0,
/// minEigThreshold=min_eig)`` computes it on x86-64 (its SSE path), to the bit: the same integer
/// bilinear weights and descaled window values, the float sums of the same integer products in
/// the same order (four lanes over the first multiple of 8 columns of a row, then the rest one
/// by one), the same steps and stops, the point refused when its window or its place leaves
/// the image by more than a window. Pixels beyond the edges are reflected (BORDER_REFLECT_101,
/// the pyramid's border); derivatives are 0 there. Only the derivatives inside each point's
/// window are computed, where OpenCV makes them for the whole image: that is the saving.
/// Writes the points' places to `out` (2n floats) and 1/0 (followed or not) to `status`.
inline void still_flow(const GreyImage& prev, const GreyImage& next, const float* pts, int n,
                       float* out, std::uint8_t* status, int win_w, int win_h, int max_count,
                       double epsilon, float min_eig) {
    using namespace flow_detail;
    const float half_w = static_cast<float>(win_w - 1) * 0.5f;
    const float half_h = static_cast<float>(win_h - 1) * 0.5f;
    const double eps2 = epsilon * epsilon;
    const int area = win_w * win_h;
    const int simd_w = (win_w / 8) * 8;  // columns summed in four lanes
    const int bw = win_w + 1;            // a window's columns with the bilinear neighbour
    const int bs = (bw + 8 + 15) / 16 * 16;  // bytes a row of a copied window (room to load 8)
    const int ws = simd_w + 8 + (win_w - simd_w);  // int16 a row of the window's values
    std::vector<std::uint8_t> ibuf(static_cast<std::size_t>((win_h + 1) * bs), 0), jbuf(ibuf);
    std::vector<std::int16_t> deriv(static_cast<std::size_t>((win_h + 1) * bw * 2));
    std::vector<std::int16_t> ival(static_cast<std::size_t>(win_h * ws), 0);
    std::vector<std::int16_t> dval(static_cast<std::size_t>(win_h * ws * 2), 0);
    std::vector<int> t0(static_cast<std::size_t>(bw + 2)), t1(t0.size());
    const int ps = bw + 2 + 8;  // bytes a row of an edge window's neighbourhood (room to load 8)
    std::vector<std::uint8_t> patch(static_cast<std::size_t>((win_h + 3) * ps), 0);
    // the window's pixels (win_h + 1 rows of bw) at (x0, y0), reflected beyond the edges
    const auto copy_window = [&](const GreyImage& img, int x0, int y0, std::uint8_t* buf) {
        const bool inside = x0 >= 0 && x0 + bw <= img.cols;
        for (int y = 0; y <= win_h; ++y) {
            const std::uint8_t* row = img.row(reflect_101(y0 + y, img.rows));
            std::uint8_t* dst = buf + y * bs;
            if (inside) {
                for (int x = 0; x < bw; ++x) dst[x] = row[x0 + x];
            } else {
                for (int x = 0; x < bw; ++x) dst[x] = row[reflect_101(x0 + x, img.cols)];
            }
        }
    };
    for (int p = 0; p < n; ++p) {
        status[p] = 1;
        float px = pts[2 * p], py = pts[2 * p + 1];
        float nx = px, ny = py;  // no initial guess: the flow starts at the point itself
        out[2 * p] = nx;
        out[2 * p + 1] = ny;
        px -= half_w;
        py -= half_h;
        const int ipx = floor_f(px), ipy = floor_f(py);
        if (ipx < -win_w || ipx >= prev.cols || ipy < -win_h || ipy >= prev.rows) {
            status[p] = 0;
            continue;
        }
        const Weights w(px - static_cast<float>(ipx), py - static_cast<float>(ipy));
        copy_window(prev, ipx, ipy, ibuf.data());
        // Scharr derivatives of the window's cells, rows smoothed (3, 10, 3) and differenced
        // down, then across columns. Inside the image the rows are read in place; a window at
        // an edge reads a copy of its neighbourhood reflected as calcScharrDeriv reflects
        // (-1 -> 1, n -> n - 2: BORDER_REFLECT_101), and its cells outside the image are 0.
        const bool inside =
            ipx >= 1 && ipx + bw < prev.cols && ipy >= 1 && ipy + win_h + 1 < prev.rows;
        if (!inside) {
            for (int y = 0; y < win_h + 3; ++y) {
                const std::uint8_t* row = prev.row(reflect_101(ipy - 1 + y, prev.rows));
                std::uint8_t* dst = &patch[static_cast<std::size_t>(y * ps)];
                for (int c = 0; c < bw + 2; ++c) dst[c] = row[reflect_101(ipx - 1 + c, prev.cols)];
            }
        }
        for (int y = 0; y <= win_h; ++y) {
            const std::uint8_t* u = inside ? prev.row(ipy + y - 1) + ipx - 1
                                           : &patch[static_cast<std::size_t>(y * ps)];
            const std::uint8_t* o = inside ? u + prev.stride : u + ps;
            const std::uint8_t* d = inside ? o + prev.stride : o + ps;
            std::int16_t* g = &deriv[static_cast<std::size_t>(y * bw * 2)];
#if defined(__SSE2__)
            if (bw == 12) {  // the 11 x 11 window: 14 columns in two loads of 8
                scharr_row_12(u, o, d, g);
            } else
#endif
            {
                for (int c = 0; c < bw + 2; ++c) {
                    t0[c] = 3 * (u[c] + d[c]) + 10 * o[c];
                    t1[c] = d[c] - u[c];
                }
                for (int x = 0; x < bw; ++x) {
                    g[2 * x] = static_cast<std::int16_t>(t0[x + 2] - t0[x]);
                    g[2 * x + 1] =
                        static_cast<std::int16_t>(3 * (t1[x] + t1[x + 2]) + 10 * t1[x + 1]);
                }
            }
            if (!inside) {
                const int r = ipy + y;
                for (int x = 0; x < bw; ++x) {
                    const int c = ipx + x;
                    if (r < 0 || r >= prev.rows || c < 0 || c >= prev.cols)
                        g[2 * x] = g[2 * x + 1] = 0;
                }
            }
        }
        float a11 = 0, a12 = 0, a22 = 0;   // the tail columns, one by one
        float l11[4] = {0, 0, 0, 0}, l12[4] = {0, 0, 0, 0}, l22[4] = {0, 0, 0, 0};  // the lanes
#if defined(__SSE2__)
        Lanes lanes;
#endif
        for (int y = 0; y < win_h; ++y) {
            const std::uint8_t *s0 = &ibuf[static_cast<std::size_t>(y * bs)], *s1 = s0 + bs;
            const std::int16_t* g0 = &deriv[static_cast<std::size_t>(y * bw * 2)];
            const std::int16_t* g1 = g0 + bw * 2;
            std::int16_t* iv = &ival[static_cast<std::size_t>(y * ws)];
            std::int16_t* dv = &dval[static_cast<std::size_t>(y * ws * 2)];
            int x0 = 0;
#if defined(__SSE2__)
            for (; x0 < simd_w; x0 += 8) window_block(s0 + x0, s1 + x0, g0 + 2 * x0, g1 + 2 * x0,
                                                      w, iv + x0, dv + 2 * x0, lanes);
#endif
            for (int x = x0; x < win_w; ++x) {
                iv[x] = static_cast<std::int16_t>(descale(
                    s0[x] * w.w00 + s0[x + 1] * w.w01 + s1[x] * w.w10 + s1[x + 1] * w.w11,
                    kWBits - 5));
                const int gx = descale(g0[2 * x] * w.w00 + g0[2 * x + 2] * w.w01 +
                                           g1[2 * x] * w.w10 + g1[2 * x + 2] * w.w11, kWBits);
                const int gy = descale(g0[2 * x + 1] * w.w00 + g0[2 * x + 3] * w.w01 +
                                           g1[2 * x + 1] * w.w10 + g1[2 * x + 3] * w.w11, kWBits);
                dv[2 * x] = static_cast<std::int16_t>(gx);
                dv[2 * x + 1] = static_cast<std::int16_t>(gy);
                // products below 2^24: exact in float; only the sums' order rounds
                const float fx = static_cast<float>(gx), fy = static_cast<float>(gy);
                if (x < simd_w) {
                    const int l = x & 3;
                    l11[l] += fx * fx;
                    l12[l] += fx * fy;
                    l22[l] += fy * fy;
                } else {
                    a11 += static_cast<float>(gx * gx);
                    a12 += static_cast<float>(gx * gy);
                    a22 += static_cast<float>(gy * gy);
                }
            }
        }
#if defined(__SSE2__)
        _mm_storeu_ps(l11, lanes.a11);
        _mm_storeu_ps(l12, lanes.a12);
        _mm_storeu_ps(l22, lanes.a22);
#endif
        // the lanes summed as OpenCV's v_reduce_sum on SSE does: (l0 + l2) + (l1 + l3)
        a11 += (l11[0] + l11[2]) + (l11[1] + l11[3]);
        a12 += (l12[0] + l12[2]) + (l12[1] + l12[3]);
        a22 += (l22[0] + l22[2]) + (l22[1] + l22[3]);
        const float A11 = a11 * kFltScale, A12 = a12 * kFltScale, A22 = a22 * kFltScale;
        float det = A11 * A22 - A12 * A12;
        const float eig = (A22 + A11 - std::sqrt((A11 - A22) * (A11 - A22) + 4.f * A12 * A12)) /
                          static_cast<float>(2 * area);
        if (eig < min_eig || det < 1.1920929e-07f) {  // FLT_EPSILON
            status[p] = 0;
            continue;
        }
        det = 1.f / det;
        nx -= half_w;
        ny -= half_h;
        float prev_dx = 0, prev_dy = 0;
        for (int j = 0; j < max_count; ++j) {
            const int inx = floor_f(nx), iny = floor_f(ny);
            if (inx < -win_w || inx >= next.cols || iny < -win_h || iny >= next.rows) {
                status[p] = 0;
                break;
            }
            const Weights v(nx - static_cast<float>(inx), ny - static_cast<float>(iny));
            copy_window(next, inx, iny, jbuf.data());
            float b1 = 0, b2 = 0;
            float s[4] = {0, 0, 0, 0};  // OpenCV's qb0 + qb1, lane by lane
            sums_of_window(jbuf.data(), bs, ival.data(), dval.data(), ws, win_w, win_h, simd_w,
                           v, s, b1, b2);
            b1 += s[0] + s[2];
            b2 += s[1] + s[3];
            b1 *= kFltScale;
            b2 *= kFltScale;
            const float ddx = (A12 * b2 - A22 * b1) * det;
            const float ddy = (A12 * b1 - A11 * b2) * det;
            nx += ddx;
            ny += ddy;
            out[2 * p] = nx + half_w;
            out[2 * p + 1] = ny + half_h;
            if (static_cast<double>(ddx) * ddx + static_cast<double>(ddy) * ddy <= eps2) break;
            if (j > 0 && std::abs(ddx + prev_dx) < 0.01 && std::abs(ddy + prev_dy) < 0.01) {
                out[2 * p] -= ddx * 0.5f;
                out[2 * p + 1] -= ddy * 0.5f;
                break;
            }
            prev_dx = ddx;
            prev_dy = ddy;
        }
        if (status[p]) {  // OpenCV's error pass refuses a place whose window left the image
            const int ex = floor_f(out[2 * p] - half_w), ey = floor_f(out[2 * p + 1] - half_h);
            if (ex < -win_w || ex >= next.cols || ey < -win_h || ey >= next.rows) status[p] = 0;
        }
    }
}

/// The similarity ``[[a, -b, tx], [b, a, ty]]`` minimising the squared distances from it applied
/// to `src` (n points, x y pairs) to `dst`, in closed form: the residuals are linear in
/// (a, b, tx, ty), so this is the minimum that OpenCV's Levenberg-Marquardt refinement in
/// ``estimateAffinePartial2D`` iterates towards (its result differs in the last bits). Centred on
/// the means, a = sum(x X + y Y) / sum(x^2 + y^2), b = sum(x Y - y X) / sum(x^2 + y^2). Writes the
/// six values row by row to `out`; returns false (nothing written) when the points of `src` all
/// coincide (n < 2, or no spread).
inline bool similarity_fit(const float* src, const float* dst, int n, double* out) {
    if (n < 2) return false;
    double mx = 0, my = 0, mX = 0, mY = 0;
    for (int i = 0; i < n; ++i) {
        mx += src[2 * i];
        my += src[2 * i + 1];
        mX += dst[2 * i];
        mY += dst[2 * i + 1];
    }
    mx /= n;
    my /= n;
    mX /= n;
    mY /= n;
    double ss = 0, sa = 0, sb = 0;
    for (int i = 0; i < n; ++i) {
        const double x = src[2 * i] - mx, y = src[2 * i + 1] - my;
        const double X = dst[2 * i] - mX, Y = dst[2 * i + 1] - mY;
        ss += x * x + y * y;
        sa += x * X + y * Y;
        sb += x * Y - y * X;
    }
    if (!(ss > 0)) return false;
    const double a = sa / ss, b = sb / ss;
    out[0] = a;
    out[1] = -b;
    out[2] = mX - (a * mx - b * my);
    out[3] = b;
    out[4] = a;
    out[5] = mY - (b * mx + a * my);
    return true;
}

namespace grey_detail {

// OpenCV's BGR -> grey of 8-bit pixels (cvtColor COLOR_BGR2GRAY in OpenCV 5: 0.114 B + 0.587 G
// + 0.299 R in 15-bit fixed point, rounded), the same integer for all 2^24 colours (tested);
// camera.py checks it against the cv2 it runs with before taking this path.
constexpr int kGreyB = 3735, kGreyG = 19235, kGreyR = 9798, kGreyShift = 15;

inline int grey_of(const std::uint8_t* px) {
    return (px[0] * kGreyB + px[1] * kGreyG + px[2] * kGreyR + (1 << (kGreyShift - 1))) >> kGreyShift;
}

/// Output pixels [from, n) of one row of grey_halved: rows `a` and `b` of BGR pixels.
inline void halved_row_scalar(const std::uint8_t* a, const std::uint8_t* b, int from, int n,
                              std::uint8_t* out) {
    for (int x = from; x < n; ++x) {
        const std::uint8_t* p = a + 6 * x;
        const std::uint8_t* q = b + 6 * x;
        // resize INTER_AREA by exactly 2 (OpenCV's fast area path): (sum of 4 + 2) >> 2
        out[x] = static_cast<std::uint8_t>(
            (grey_of(p) + grey_of(p + 3) + grey_of(q) + grey_of(q + 3) + 2) >> 2);
    }
}

#ifdef PFTRACK_GREY_AVX2
/// The greys of 8 BGR pixels at `px` (24 bytes, no more read) in 32-bit lanes, in order: pixels
/// 0-3 from the low 16 bytes, 4-7 from bytes 8-23, each lane's bytes spread by one shuffle
/// into (B, G) and (R, 1) 16-bit pairs, whose multiply-adds give grey_of's sums.
__attribute__((target("avx2"), always_inline)) inline __m256i grey8_avx2(const std::uint8_t* px) {
    const __m256i v = _mm256_inserti128_si256(
        _mm256_castsi128_si256(_mm_loadu_si128(reinterpret_cast<const __m128i*>(px))),
        _mm_loadu_si128(reinterpret_cast<const __m128i*>(px + 8)), 1);
    const __m256i bg_at = _mm256_setr_epi8(0, -1, 1, -1, 3, -1, 4, -1, 6, -1, 7, -1, 9, -1, 10, -1,
                                           4, -1, 5, -1, 7, -1, 8, -1, 10, -1, 11, -1, 13, -1, 14, -1);
    const __m256i r_at = _mm256_setr_epi8(2, -1, -1, -1, 5, -1, -1, -1, 8, -1, -1, -1, 11, -1, -1, -1,
                                          6, -1, -1, -1, 9, -1, -1, -1, 12, -1, -1, -1, 15, -1, -1, -1);
    const __m256i bg = _mm256_shuffle_epi8(v, bg_at);
    const __m256i r1 = _mm256_or_si256(_mm256_shuffle_epi8(v, r_at), _mm256_set1_epi32(1 << 16));
    const __m256i sum = _mm256_add_epi32(
        _mm256_madd_epi16(bg, _mm256_set1_epi32(kGreyB | (kGreyG << 16))),
        _mm256_madd_epi16(r1, _mm256_set1_epi32(kGreyR | ((1 << (kGreyShift - 1)) << 16))));
    return _mm256_srli_epi32(sum, kGreyShift);
}

/// The 2x2 sums of 8 output pixels (16 input pixels of rows `a` and `b`, 48 bytes each, nothing
/// past them read), in 32-bit lanes in the order 0, 1, 4, 5 | 2, 3, 6, 7 (hadd pairs within
/// each 128-bit lane).
__attribute__((target("avx2"), always_inline)) inline __m256i sums8_avx2(const std::uint8_t* a,
                                                                        const std::uint8_t* b) {
    const __m256i v0 = _mm256_add_epi32(grey8_avx2(a), grey8_avx2(b));            // pixels 0-7
    const __m256i v1 = _mm256_add_epi32(grey8_avx2(a + 24), grey8_avx2(b + 24));  // 8-15
    return _mm256_hadd_epi32(v0, v1);
}

/// halved_row_scalar's first output pixels, 16 a step (32 input pixels of each row, 96 bytes,
/// nothing past them read); returns how many were written.
__attribute__((target("avx2"))) inline int halved_row_avx2(const std::uint8_t* a,
                                                          const std::uint8_t* b, int n,
                                                          std::uint8_t* out) {
    // after the packs, the low 16 bytes hold outputs 0 1 4 5 8 9 12 13 | 2 3 6 7 10 11 14 15
    const __m128i order = _mm_setr_epi8(0, 1, 8, 9, 2, 3, 10, 11, 4, 5, 12, 13, 6, 7, 14, 15);
    const __m256i two = _mm256_set1_epi16(2);
    int x = 0;
    for (; x + 16 <= n; x += 16) {
        const std::uint8_t* p = a + 6 * x;
        const std::uint8_t* q = b + 6 * x;
        // sums of four greys are at most 1020: 16-bit lanes from here, rounded as (s + 2) >> 2
        const __m256i s = _mm256_packus_epi32(sums8_avx2(p, q), sums8_avx2(p + 48, q + 48));
        const __m256i m = _mm256_srli_epi16(_mm256_add_epi16(s, two), 2);
        const __m256i bytes = _mm256_permute4x64_epi64(_mm256_packus_epi16(m, m), 0x08);
        _mm_storeu_si128(reinterpret_cast<__m128i*>(out + x),
                         _mm_shuffle_epi8(_mm256_castsi256_si128(bytes), order));
    }
    return x;
}
#endif

}  // namespace grey_detail

/// The BGR image `bgr` (rows of 3-byte pixels, row r at bgr + r * stride) in grey and halved:
/// out (out_rows, out_cols, rows out_stride apart) is OpenCV's cv2.resize(cv2.cvtColor(bgr,
/// COLOR_BGR2GRAY)[:2 out_rows, :2 out_cols], (out_cols, out_rows), INTER_AREA) to the bit,
/// in one pass without the full-size grey image (the camera check's scaled frame: 0.6 M
/// instructions a 480 x 360 frame in OpenCV's two calls). The input holds at least 2 out_rows
/// rows of 2 out_cols pixels.
inline void grey_halved(const std::uint8_t* bgr, std::ptrdiff_t stride, int out_rows, int out_cols,
                        std::uint8_t* out, std::ptrdiff_t out_stride) {
#ifdef PFTRACK_GREY_AVX2
    const bool avx2 = detail::avx2_usable();
#endif
    for (int y = 0; y < out_rows; ++y) {
        const std::uint8_t* a = bgr + static_cast<std::ptrdiff_t>(2 * y) * stride;
        const std::uint8_t* b = a + stride;
        std::uint8_t* o = out + static_cast<std::ptrdiff_t>(y) * out_stride;
        int x = 0;
#ifdef PFTRACK_GREY_AVX2
        if (avx2) x = grey_detail::halved_row_avx2(a, b, out_cols, o);
#endif
        grey_detail::halved_row_scalar(a, b, x, out_cols, o);
    }
}

}  // namespace pftrack
