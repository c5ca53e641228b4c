// Grey-level erosion and dilation of a mask by a structuring element whose rows are single runs
// (rectangles, OpenCV's ellipses and crosses): the values of cv2.erode / cv2.dilate with their
// default border (pixels outside the image never win: 255 for an erosion, 0 for a dilation) and
// default anchor (the element's centre, (kw / 2, kh / 2)). Min and max are exact, so only the
// order of the work differs from OpenCV's:
//   * each source row is reduced over each distinct run of the element, by doubling: extrema over
//     2, 4, 8, ... pixels, then a run of w pixels as two overlapping power-of-two windows;
//   * each output row is the extremum of the element rows' runs, read from a ring of the last
//     source rows.
// For the detector's 11 x 11 ellipse at 1280 x 720 that is 16 vector operations a pixel, against
// the 97 of OpenCV's generic (non-separable) path.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#endif

#include "check.hpp"
#include "types.hpp"

namespace pftrack {

/// One row of a structuring element: the columns [lo, hi] of its run at row offset dy, all
/// relative to the anchor.
struct ElementRow {
    Index dy = 0;
    Index lo = 0;
    Index hi = 0;
};

/// The rows of a kh x kw element (row-major bytes, non-zero = in) as runs about its centre.
/// Throws std::invalid_argument if a row's pixels are not one run or no pixel is set.
inline std::vector<ElementRow> element_rows(const std::uint8_t* k, Index kh, Index kw,
                                            const char* fn) {
    require(kh >= 1 && kw >= 1, fn, "element must have shape (kh, kw) with kh, kw >= 1");
    const Index ay = kh / 2, ax = kw / 2;
    std::vector<ElementRow> out;
    for (Index y = 0; y < kh; ++y) {
        const std::uint8_t* row = k + y * kw;
        Index lo = -1, hi = -1;
        for (Index x = 0; x < kw; ++x)
            if (row[x] != 0) {
                if (lo < 0) lo = x;
                hi = x;
            }
        if (lo < 0) continue;
        for (Index x = lo; x <= hi; ++x)
            if (row[x] == 0)
                fail(fn, "element row " + std::to_string(y) + " is not one run of set pixels");
        out.push_back({y - ay, lo - ax, hi - ax});
    }
    require(!out.empty(), fn, "element has no set pixel");
    return out;
}

enum class MorphOp { erode, dilate };

namespace detail {

/// o[i] = max (dilate) or min (erode) of a[i] and b[i], i < n.
PFTRACK_VECTOR_CLONES static void extremum_row(bool dilate, const std::uint8_t* __restrict a,
                                               const std::uint8_t* __restrict b,
                                               std::uint8_t* __restrict o, Index n) {
    if (dilate)
        for (Index i = 0; i < n; ++i) o[i] = std::max(a[i], b[i]);
    else
        for (Index i = 0; i < n; ++i) o[i] = std::min(a[i], b[i]);
}

/// o[i] = extremum of o[i] and a[i], i < n.
PFTRACK_VECTOR_CLONES static void extremum_into(bool dilate, const std::uint8_t* __restrict a,
                                                std::uint8_t* __restrict o, Index n) {
    if (dilate)
        for (Index i = 0; i < n; ++i) o[i] = std::max(o[i], a[i]);
    else
        for (Index i = 0; i < n; ++i) o[i] = std::min(o[i], a[i]);
}

/// Whether the n bytes at p are all 0 (an OR reduction, vectorised).
PFTRACK_VECTOR_CLONES static bool all_zero(const std::uint8_t* __restrict p, Index n) {
    std::uint8_t any = 0;
    for (Index i = 0; i < n; ++i) any = static_cast<std::uint8_t>(any | p[i]);
    return any == 0;
}

}  // namespace detail

/// Scratch of `morphology`, reused from call to call.
struct MorphScratch {
    std::vector<std::uint8_t> pow2, ring;
    std::vector<std::uint8_t> zero;  // per ring slot: its source row was all 0 (not reduced)
};

/// dst (rows x cols, packed) = erosion (min) or dilation (max) of src (rows x cols,
/// `src_stride` bytes a row) by the element `el`: dst(y, x) = extremum over (dy, dx) in the
/// element of src(y + dy, x + dx), pixels outside the image left out. `dst` must not alias `src`.
///
/// A foreground mask is mostly empty rows, which are not reduced: an all-0 source row gives 0
/// for every run that holds the anchor column (dx = 0: the pixel itself is 0), so a dilation
/// leaves it out of its maxima and an erosion's output row is 0 wherever it contributes (when
/// every run holds the anchor, as the rectangles, ellipses and crosses of OpenCV do; else every
/// row is reduced). Min and max being exact, the values are those of the full pass.
inline void morphology(const std::uint8_t* src, Index src_stride, std::uint8_t* dst, Index rows,
                       Index cols, const std::vector<ElementRow>& el, MorphOp op,
                       MorphScratch& s) {
    const bool dil = op == MorphOp::dilate;
    const std::uint8_t identity = dil ? 0 : 255;
    // the distinct runs (lo, hi), and each element row's run
    std::vector<std::pair<Index, Index>> runs;
    std::vector<Index> run_of;
    Index ext = 0, dy_min = el.front().dy, dy_max = el.front().dy, width = 1;
    for (const ElementRow& r : el) {
        const std::pair<Index, Index> key{r.lo, r.hi};
        const auto it = std::find(runs.begin(), runs.end(), key);
        run_of.push_back(static_cast<Index>(it - runs.begin()));
        if (it == runs.end()) runs.push_back(key);
        ext = std::max({ext, -r.lo, r.hi});
        dy_min = std::min(dy_min, r.dy);
        dy_max = std::max(dy_max, r.dy);
        width = std::max(width, r.hi - r.lo + 1);
    }
    Index levels = 1;  // windows of 1, 2, 4, ... < 2 * width pixels: pow2 level j is 2^j wide
    while ((Index(1) << levels) <= width) ++levels;
    const Index pw = cols + 2 * ext;  // a padded row: ext identity pixels on each side
    const Index span = dy_max - dy_min + 1;
    const auto nr = static_cast<Index>(runs.size());
    s.pow2.assign(static_cast<size_t>(levels * pw), identity);
    s.ring.resize(static_cast<size_t>(span * nr * cols));
    s.zero.assign(static_cast<size_t>(span), 0);
    bool skip_zero = true;  // every run holds the anchor column: all-0 rows need no reduction
    for (const auto& [lo, hi] : runs) skip_zero = skip_zero && lo <= 0 && hi >= 0;
    // the runs of source row sy into ring slot sy mod span
    auto reduce_row = [&](Index sy) {
        const bool zero = skip_zero && detail::all_zero(src + sy * src_stride, cols);
        s.zero[static_cast<size_t>(sy % span)] = zero ? 1 : 0;
        if (zero) return;  // every run of it is 0 (see above): the slot is never read
        std::uint8_t* p0 = s.pow2.data();
        std::memcpy(p0 + ext, src + sy * src_stride, static_cast<size_t>(cols));
        for (Index j = 1; j < levels; ++j) {  // level j: extremum of pixels [i, i + 2^j)
            const Index half = Index(1) << (j - 1);
            const std::uint8_t* prev = p0 + (j - 1) * pw;
            detail::extremum_row(dil, prev, prev + half, p0 + j * pw, pw - half);
        }
        std::uint8_t* slot = s.ring.data() + (sy % span) * nr * cols;
        for (Index p = 0; p < nr; ++p) {
            const auto [lo, hi] = runs[static_cast<size_t>(p)];
            const Index w = hi - lo + 1;
            Index j = 0;
            while ((Index(2) << j) <= w) ++j;  // 2^j <= w < 2^(j + 1)
            const std::uint8_t* level = p0 + j * pw + ext + lo;  // window [x + lo, x + lo + 2^j)
            const Index rest = w - (Index(1) << j);  // the second window starts `rest` further
            if (rest == 0)
                std::memcpy(slot + p * cols, level, static_cast<size_t>(cols));
            else
                detail::extremum_row(dil, level, level + rest, slot + p * cols, cols);
        }
    };
    Index reduced = 0;  // source rows [0, reduced) are reduced; the ring holds the last `span`
    for (Index y = 0; y < rows; ++y) {
        for (const Index need = std::min(y + dy_max + 1, rows); reduced < need; ++reduced)
            reduce_row(reduced);
        std::uint8_t* out = dst + y * cols;
        if (!dil) {  // an erosion's row is 0 where an all-0 row contributes
            bool zero = false;
            for (size_t r = 0; r < el.size() && !zero; ++r) {
                const Index sy = y + el[r].dy;
                zero = sy >= 0 && sy < rows && s.zero[static_cast<size_t>(sy % span)] != 0;
            }
            if (zero) {
                std::memset(out, 0, static_cast<size_t>(cols));
                continue;
            }
        }
        bool first = true;
        for (size_t r = 0; r < el.size(); ++r) {
            const Index sy = y + el[r].dy;
            if (sy < 0 || sy >= rows) continue;
            if (s.zero[static_cast<size_t>(sy % span)] != 0) continue;  // dilation: max with 0
            const std::uint8_t* in = s.ring.data() + ((sy % span) * nr + run_of[r]) * cols;
            if (first)
                std::memcpy(out, in, static_cast<size_t>(cols));
            else
                detail::extremum_into(dil, in, out, cols);
            first = false;
        }
        if (first) std::memset(out, identity, static_cast<size_t>(cols));
    }
}

// ---------------------------------------------------------------------------------------------
// The packed path: a mask of at most two non-zero levels (0/255, 0/1, 0/127/255: the detectors'
// masks with or without shadows) as bit planes, 64 pixels a word. Flat erosion and dilation
// commute with every threshold, so the cleaned mask is 255 where the cleaned plane of
// (x == 255) is set, m where only the plane of (x != 0) is, 0 elsewhere: the byte path's values
// exactly. Erosion is an AND, dilation an OR, of shifted words.
//
// Layout: the planes' rows one after another, each row S words (its cols bits, then at least
// `ext` bits of padding), R band rows above, between and below the planes (R = the largest
// |dy|), and G guard words at each end. Padding, bands and guards hold the identity of the next
// pass (all ones before an erosion, zeros before a dilation): pixels outside the image never
// win, as in the byte path. So every pass is a few long loops over the whole buffer, with no
// per-row work: at 480 x 360 a row is 8 words, and per-row calls would cost more than the words.

namespace detail {

/// The 8 bytes at p as a little-endian word (bit i of byte j is bit 8 j + i).
inline std::uint64_t load_word(const std::uint8_t* p) {
    std::uint64_t v;
    std::memcpy(&v, p, sizeof v);
    return v;
}

/// out[k] = extremum over i < ns of the 64 bits starting s_i bits after word k of `src`
/// (s_i = 8 q_i + r_i, 0 <= r_i < 8; bits before/after come from the neighbouring words), for
/// k < n. The bit stream read at a bit offset is two unaligned words: (lo >> r) | (hi << (8 - r)),
/// hi being lo's stream one byte later, so the bits the two hold in common are the same bits.
PFTRACK_VECTOR_CLONES static void shifted_extremum(bool dilate, const std::uint8_t* src,
                                                   std::uint64_t* __restrict out, Index n,
                                                   const Index* q, const int* r, int ns) {
    for (int i = 0; i < ns; ++i) {
        const std::uint8_t* p = src + q[i];
        const int a = r[i], b = 8 - r[i];
        if (i == 0)
            for (Index k = 0; k < n; ++k)
                out[k] = (load_word(p + 8 * k) >> a) | (load_word(p + 8 * k + 1) << b);
        else if (dilate)
            for (Index k = 0; k < n; ++k)
                out[k] |= (load_word(p + 8 * k) >> a) | (load_word(p + 8 * k + 1) << b);
        else
            for (Index k = 0; k < n; ++k)
                out[k] &= (load_word(p + 8 * k) >> a) | (load_word(p + 8 * k + 1) << b);
    }
}

#if defined(__x86_64__) && defined(__GNUC__)
#define PFTRACK_MORPH_AVX2 1
/// `shifted_extremum` 4 words a step (AVX2) for NS shifts (NS > 0), or ns of them (NS == 0),
/// all in registers: the same words.
template <int NS, bool Dilate>
__attribute__((target("avx2"))) inline void shifted_avx2(const std::uint8_t* src,
                                                         std::uint64_t* out, Index n,
                                                         const Index* q, const int* r, int ns) {
    constexpr int kMax = 8;  // callers pass at most 8 shifts (runs up to 8 wide; doubling's 2)
    const int cnt = NS > 0 ? NS : ns;
    const Index n4 = n / 4 * 4;
    __m128i ca[kMax], cb[kMax];
    const std::uint8_t* p[kMax];
    for (int i = 0; i < cnt; ++i) {
        ca[i] = _mm_cvtsi32_si128(r[i]);
        cb[i] = _mm_cvtsi32_si128(8 - r[i]);
        p[i] = src + q[i];
    }
    for (Index k = 0; k < n4; k += 4) {
        __m256i acc = _mm256_setzero_si256();
        for (int i = 0; i < cnt; ++i) {
            const __m256i lo = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p[i] + 8 * k));
            const __m256i hi =
                _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p[i] + 8 * k + 1));
            const __m256i v =
                _mm256_or_si256(_mm256_srl_epi64(lo, ca[i]), _mm256_sll_epi64(hi, cb[i]));
            acc = i == 0 ? v : Dilate ? _mm256_or_si256(acc, v) : _mm256_and_si256(acc, v);
        }
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + k), acc);
    }
    for (Index k = n4; k < n; ++k)
        for (int i = 0; i < cnt; ++i) {
            const std::uint64_t v =
                (load_word(p[i] + 8 * k) >> r[i]) | (load_word(p[i] + 8 * k + 1) << (8 - r[i]));
            out[k] = i == 0 ? v : Dilate ? out[k] | v : out[k] & v;
        }
}

template <bool Dilate>
inline void shifted_avx2_any(const std::uint8_t* src, std::uint64_t* out, Index n,
                             const Index* q, const int* r, int ns) {
    switch (ns) {  // the shift counts the elements in use have, unrolled
        case 1: return shifted_avx2<1, Dilate>(src, out, n, q, r, ns);
        case 2: return shifted_avx2<2, Dilate>(src, out, n, q, r, ns);
        case 3: return shifted_avx2<3, Dilate>(src, out, n, q, r, ns);
        case 4: return shifted_avx2<4, Dilate>(src, out, n, q, r, ns);
        case 5: return shifted_avx2<5, Dilate>(src, out, n, q, r, ns);
        case 6: return shifted_avx2<6, Dilate>(src, out, n, q, r, ns);
        case 7: return shifted_avx2<7, Dilate>(src, out, n, q, r, ns);
        default: return shifted_avx2<0, Dilate>(src, out, n, q, r, ns);
    }
}

/// `shifted_extremum` by AVX2 (at most 8 shifts: the runs of up to 8 pixels, the doubling's 2).
inline void shifted_extremum_avx2(bool dilate, const std::uint8_t* src, std::uint64_t* out,
                                  Index n, const Index* q, const int* r, int ns) {
    if (dilate)
        shifted_avx2_any<true>(src, out, n, q, r, ns);
    else
        shifted_avx2_any<false>(src, out, n, q, r, ns);
}

/// o[k] = the extremum of in[e][k] over e < NE (or ne), then the bits outside `valid` set to
/// `fill` (AVX2, 4 words a step).
template <int NE, bool Dilate>
__attribute__((target("avx2"))) inline void vertical_avx2_n(const std::uint64_t* const* in,
                                                            int ne, const std::uint64_t* valid,
                                                            std::uint64_t fill, std::uint64_t* o,
                                                            Index n) {
    const int cnt = NE > 0 ? NE : ne;
    const Index n4 = n / 4 * 4;
    const __m256i f = _mm256_set1_epi64x(static_cast<long long>(fill));
    for (Index k = 0; k < n4; k += 4) {
        __m256i acc = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(in[0] + k));
        for (int e = 1; e < cnt; ++e) {
            const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(in[e] + k));
            acc = Dilate ? _mm256_or_si256(acc, v) : _mm256_and_si256(acc, v);
        }
        const __m256i m = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(valid + k));
        acc = _mm256_or_si256(_mm256_and_si256(acc, m), _mm256_andnot_si256(m, f));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(o + k), acc);
    }
    for (Index k = n4; k < n; ++k) {
        std::uint64_t acc = in[0][k];
        for (int e = 1; e < cnt; ++e) acc = Dilate ? acc | in[e][k] : acc & in[e][k];
        o[k] = (acc & valid[k]) | (fill & ~valid[k]);
    }
}

template <bool Dilate>
inline void vertical_avx2_any(const std::uint64_t* const* in, int ne, const std::uint64_t* valid,
                              std::uint64_t fill, std::uint64_t* o, Index n) {
    switch (ne) {  // the element heights in use (3 to 31: odd), unrolled up to 11
        case 1: return vertical_avx2_n<1, Dilate>(in, ne, valid, fill, o, n);
        case 3: return vertical_avx2_n<3, Dilate>(in, ne, valid, fill, o, n);
        case 5: return vertical_avx2_n<5, Dilate>(in, ne, valid, fill, o, n);
        case 7: return vertical_avx2_n<7, Dilate>(in, ne, valid, fill, o, n);
        case 9: return vertical_avx2_n<9, Dilate>(in, ne, valid, fill, o, n);
        case 11: return vertical_avx2_n<11, Dilate>(in, ne, valid, fill, o, n);
        default: return vertical_avx2_n<0, Dilate>(in, ne, valid, fill, o, n);
    }
}

inline void vertical_avx2(bool dilate, const std::uint64_t* const* in, int ne,
                          const std::uint64_t* valid, std::uint64_t fill, std::uint64_t* o,
                          Index n) {
    if (dilate)
        vertical_avx2_any<true>(in, ne, valid, fill, o, n);
    else
        vertical_avx2_any<false>(in, ne, valid, fill, o, n);
}

/// The planes' bits of each row's first cols / 32 * 32 bytes (AVX2): a = (x != 0) into
/// `pa + y * S` words, b = (x == 255) into `pb + y * S`; false when a byte is neither 0, 255 nor
/// *m (set from the first such byte). any_mid / any_b: whether a byte is *m / 255.
__attribute__((target("avx2"))) inline bool pack_rows_avx2(const std::uint8_t* src,
                                                           Index stride, Index rows, Index cols,
                                                           std::uint64_t* pa, std::uint64_t* pb,
                                                           Index S, int& m, bool& any_mid,
                                                           bool& any_b) {
    const Index c32 = cols / 32 * 32;
    const __m256i zero = _mm256_setzero_si256(), ones = _mm256_set1_epi8(-1);
    std::uint32_t bs = 0, mids = 0;
    for (Index y = 0; y < rows; ++y) {
        const std::uint8_t* row = src + y * stride;
        auto* a = reinterpret_cast<std::uint8_t*>(pa + y * S);
        auto* b = reinterpret_cast<std::uint8_t*>(pb + y * S);
        for (Index x = 0; x < c32; x += 32) {
            const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row + x));
            const auto wa = ~static_cast<std::uint32_t>(
                _mm256_movemask_epi8(_mm256_cmpeq_epi8(v, zero)));
            const auto wb =
                static_cast<std::uint32_t>(_mm256_movemask_epi8(_mm256_cmpeq_epi8(v, ones)));
            const std::uint32_t mid = wa & ~wb;
            if (mid != 0) {  // the rare chunk with a level under 255: one value only
                if (m < 0) m = row[x + __builtin_ctz(mid)];
                const auto e = static_cast<std::uint32_t>(_mm256_movemask_epi8(
                    _mm256_cmpeq_epi8(v, _mm256_set1_epi8(static_cast<char>(m)))));
                if ((mid & ~e) != 0) return false;
                mids |= mid;
            }
            bs |= wb;
            std::memcpy(a + x / 8, &wa, 4);
            std::memcpy(b + x / 8, &wb, 4);
        }
    }
    any_mid = any_mid || mids != 0;
    any_b = any_b || bs != 0;
    return true;
}

/// 32 bytes, 0xff where bit j of w is set (byte j).
__attribute__((target("avx2"), always_inline)) inline __m256i expand32_avx2(std::uint32_t w) {
    const __m256i spread = _mm256_setr_epi8(0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1, 2, 2,
                                            2, 2, 2, 2, 2, 2, 3, 3, 3, 3, 3, 3, 3, 3);
    const __m256i bit = _mm256_set1_epi64x(static_cast<long long>(0x8040201008040201ULL));
    const __m256i v = _mm256_shuffle_epi8(_mm256_set1_epi32(static_cast<int>(w)), spread);
    return _mm256_cmpeq_epi8(_mm256_and_si256(v, bit), bit);
}

/// `zero_bytes` by 32-byte stores, the last n % 32 bytes by one overlapping store (n >= 32)
/// or memset.
__attribute__((target("avx2"))) inline void zero_bytes_avx2(std::uint8_t* p, Index n) {
    __m256i z = _mm256_setzero_si256();
    // opaque to the optimiser, which would otherwise make the loop a call of memset
    __asm__("" : "+x"(z));
    Index i = 0;
    for (; i + 32 <= n; i += 32) _mm256_storeu_si256(reinterpret_cast<__m256i*>(p + i), z);
    if (i == n) return;
    if (n >= 32)
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(p + n - 32), z);
    else
        std::memset(p + i, 0, static_cast<size_t>(n - i));
}

/// Each row's first cols / 32 * 32 bytes from the planes (AVX2): 255 where b is set (with
/// `two`), ma where only a is, 0 elsewhere.
__attribute__((target("avx2"))) inline void unpack_rows_avx2(const std::uint64_t* pa,
                                                             const std::uint64_t* pb, Index S,
                                                             bool two, std::uint8_t ma,
                                                             std::uint8_t* dst, Index rows,
                                                             Index cols) {
    const Index c32 = cols / 32 * 32;
    const __m256i level = _mm256_set1_epi8(static_cast<char>(ma));
    for (Index y = 0; y < rows; ++y) {
        const auto* a = reinterpret_cast<const std::uint8_t*>(pa + y * S);
        const auto* b = reinterpret_cast<const std::uint8_t*>(pb + y * S);
        std::uint8_t* out = dst + y * cols;
        for (Index x = 0; x < c32; x += 32) {
            std::uint32_t wa, wb;
            std::memcpy(&wa, a + x / 8, 4);
            __m256i v = _mm256_and_si256(expand32_avx2(wa), level);
            if (two) {
                std::memcpy(&wb, b + x / 8, 4);
                v = _mm256_or_si256(v, expand32_avx2(wb));
            }
            _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + x), v);
        }
    }
}
#endif

/// o[k] = extremum of a[k] and b[k], k < n.
PFTRACK_VECTOR_CLONES static void word_extremum2(bool dilate, const std::uint64_t* __restrict a,
                                                 const std::uint64_t* __restrict b,
                                                 std::uint64_t* __restrict o, Index n) {
    if (dilate)
        for (Index k = 0; k < n; ++k) o[k] = a[k] | b[k];
    else
        for (Index k = 0; k < n; ++k) o[k] = a[k] & b[k];
}

/// o[k] = extremum of o[k] and a[k], k < n.
PFTRACK_VECTOR_CLONES static void word_extremum(bool dilate, const std::uint64_t* __restrict a,
                                                std::uint64_t* __restrict o, Index n) {
    if (dilate)
        for (Index k = 0; k < n; ++k) o[k] |= a[k];
    else
        for (Index k = 0; k < n; ++k) o[k] &= a[k];
}

/// o[k] = extremum of o[k] and a[k], then the bits outside `valid` set to `fill` (all ones or
/// zeros: the next pass's identity), k < n.
PFTRACK_VECTOR_CLONES static void word_extremum_fill(bool dilate, const std::uint64_t* __restrict a,
                                                     const std::uint64_t* __restrict valid,
                                                     std::uint64_t fill,
                                                     std::uint64_t* __restrict o, Index n) {
    if (dilate)
        for (Index k = 0; k < n; ++k) o[k] = ((o[k] | a[k]) & valid[k]) | (fill & ~valid[k]);
    else
        for (Index k = 0; k < n; ++k) o[k] = ((o[k] & a[k]) & valid[k]) | (fill & ~valid[k]);
}

/// n zero bytes at p: 32-byte stores where `avx2`, else memset. (glibc's memset takes `rep
/// stosb` for a few kilobytes, which callgrind counts as one instruction a byte: the rows
/// `clean_packed_blocks` leaves out would have counted as much as packing them.)
inline void zero_bytes(std::uint8_t* p, Index n, bool avx2) {
#ifdef PFTRACK_MORPH_AVX2
    if (avx2) return zero_bytes_avx2(p, n);
#endif
    (void)avx2;
    std::memset(p, 0, static_cast<size_t>(n));
}

/// The bits of 8 bytes that are not 0 (bit j: byte j), without SIMD.
inline std::uint64_t nonzero_bits8(std::uint64_t x) {
    constexpr std::uint64_t lo7 = 0x7f7f7f7f7f7f7f7fULL, hi = 0x8080808080808080ULL;
    const std::uint64_t t = (((x & lo7) + lo7) | x) & hi;  // byte j's top bit: byte j != 0
    return ((t >> 7) * 0x0102040810204080ULL) >> 56;  // gather the 8 flags into one byte
}

}  // namespace detail

/// Scratch of `clean_packed`, reused from call to call.
struct PackedScratch {
    std::vector<std::uint64_t> x, out, valid;
    std::vector<std::vector<std::uint64_t>> runs;  // one per distinct run, and the levels
    std::vector<std::uint64_t> level;
    std::vector<std::uint64_t> expand;  // 256 entries: byte -> 8 bytes 0x00 / 0xff
    std::vector<std::pair<Index, Index>> groups;  // clean_packed_blocks' rows: first, last
};

/// One pass of `clean_packed`: an element and an operation.
struct PackedPass {
    const std::vector<ElementRow>* element;
    MorphOp op;
};

/// Over the elements of `passes`: their widest horizontal extent `ext`, their largest vertical
/// reach `reach`, and `summed`, each pass's reach added up (how far a foreground row can act,
/// all passes together). False when an element lacks its anchor: its window may then hold no
/// pixel of the image, where an erosion gives 255, a level the planes need not have (a 0/m
/// mask).
inline bool pass_reaches(const std::vector<PackedPass>& passes, Index& ext, Index& reach,
                         Index& summed) {
    ext = reach = summed = 0;
    for (const PackedPass& p : passes) {
        Index own = 0;
        bool anchor = false;
        for (const ElementRow& r : *p.element) {
            ext = std::max({ext, -r.lo, r.hi});
            own = std::max({own, -r.dy, r.dy});
            anchor = anchor || (r.dy == 0 && r.lo <= 0 && r.hi >= 0);
        }
        if (!anchor) return false;
        reach = std::max(reach, own);
        summed += own;
    }
    return true;
}

/// dst (rows x cols, packed) = the passes applied in order to src (rows x cols, `src_stride`
/// bytes a row), each as `morphology`, when src holds at most two non-zero values one of which,
/// if two, is 255 (0 and 255; 0 and m; 0, m and 255): the same bytes as the byte path. Returns
/// false, writing nothing, for any other mask or an element without its anchor pixel (the caller
/// then takes the byte path). With `simd`, on a CPU with AVX2, bytes are packed and unpacked 32 at
/// a time and the passes take 4 words a step (`*_avx2`); else the portable loops (bytes 8 at a
/// time in 64-bit words, a table per 8 pixels): the same bits. `dst` must not alias `src`.
inline bool clean_packed(const std::uint8_t* src, Index src_stride, std::uint8_t* dst, Index rows,
                         Index cols, const std::vector<PackedPass>& passes, bool simd,
                         PackedScratch& s) {
#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
    (void)src, (void)src_stride, (void)dst, (void)rows, (void)cols, (void)passes, (void)simd,
        (void)s;
    return false;  // the word layout assumes little-endian loads
#else
    using u64 = std::uint64_t;
    Index ext, reach, summed;
    if (!pass_reaches(passes, ext, reach, summed)) return false;
    const Index data_words = (cols + 63) / 64;
    const Index S = (cols + ext + 63) / 64;  // a row: cols bits and >= ext bits of padding
    const Index G = ext / 64 + 2;             // guard words: a shifted read's reach, and a byte
    // ---- pack: plane A = (x != 0) at plane 0, plane B = (x == 255) at plane 1
    // at least one band row: the levels of a doubling are computed over the whole buffer but
    // their guard words are only set to the identity, so no data row may start right after them
    const Index R = std::max<Index>(reach, 1);
    const Index plane_rows = rows + R;  // a plane and the band after it
    const Index T2 = R + 2 * plane_rows;
    const Index total = G + T2 * S + G;
    s.x.assign(static_cast<size_t>(total), 0);
    u64* X = s.x.data() + G;
    u64* A0 = X + R * S;
    u64* B0 = X + (R + plane_rows) * S;
    int m = -1;  // the one value other than 0 and 255, once seen
    bool any_b = false, any_mid = false;
#ifdef PFTRACK_MORPH_AVX2
    const bool avx2 = simd && __builtin_cpu_supports("avx2");
#else
    const bool avx2 = false;
    (void)simd;
#endif
#ifdef PFTRACK_MORPH_AVX2
    if (avx2 && !detail::pack_rows_avx2(src, src_stride, rows, cols, A0, B0, S, m, any_mid, any_b))
        return false;  // a third non-zero value
#endif
    for (Index y = 0; y < rows; ++y) {
        const std::uint8_t* row = src + y * src_stride;
        u64* a = A0 + y * S;
        u64* b = B0 + y * S;
        Index x = avx2 ? cols / 32 * 32 : 0;  // the AVX2 pass packed those
        for (; x + 8 <= cols; x += 8) {
            u64 na, nb, ne = 0;
            const u64 v = detail::load_word(row + x);
            na = detail::nonzero_bits8(v);
            nb = ~detail::nonzero_bits8(~v) & 0xffu;
            const u64 mid = na & ~nb;
            if (mid != 0) {
                if (m < 0) m = row[x + __builtin_ctzll(mid)];
                ne = ~detail::nonzero_bits8(v ^ (0x0101010101010101ULL * static_cast<u64>(m))) &
                     0xffu;
                if ((mid & ~ne) != 0) return false;
                any_mid = true;
            }
            any_b = any_b || nb != 0;
            a[x / 64] |= na << (x % 64);
            b[x / 64] |= nb << (x % 64);
        }
        for (; x < cols; ++x) {
            const std::uint8_t v = row[x];
            if (v == 0) continue;
            if (v != 255) {
                if (m < 0) m = v;
                if (v != m) return false;
                any_mid = true;
            } else {
                any_b = true;
            }
            a[x / 64] |= u64(1) << (x % 64);
            if (v == 255) b[x / 64] |= u64(1) << (x % 64);
        }
    }
    // one plane when B adds nothing (0/255: A == B) or is empty (0/m); else both
    const int planes = any_mid && any_b ? 2 : 1;
    const std::uint8_t level_a = any_mid ? static_cast<std::uint8_t>(m) : 255;
    const Index T = planes == 2 ? T2 : R + plane_rows;  // rows of bands and planes processed
    const Index n = T * S;
    // ---- valid bits: the data bits of each plane row, 0 in padding and bands
    s.valid.assign(static_cast<size_t>(n), 0);
    for (int p = 0; p < planes; ++p)
        for (Index y = 0; y < rows; ++y) {
            u64* v = s.valid.data() + (R + p * plane_rows + y) * S;
            for (Index w = 0; w < data_words; ++w) v[w] = ~u64(0);
            if (cols % 64 != 0) v[data_words - 1] = (u64(1) << (cols % 64)) - 1;
        }
    s.out.assign(static_cast<size_t>(total), 0);
    auto set_identity = [&](std::vector<u64>& buf, u64 id) {  // guards and outer bands
        u64* b = buf.data();
        std::fill(b, b + G + R * S, id);
        std::fill(b + G + (T - R) * S, b + total, id);
    };
    const u64 first_id = passes.empty() || passes[0].op == MorphOp::dilate ? 0 : ~u64(0);
    {  // the first pass's identity in padding and bands
        u64* x = s.x.data() + G;
        const u64* v = s.valid.data();
        for (Index k = 0; k < n; ++k) x[k] = (x[k] & v[k]) | (first_id & ~v[k]);
        set_identity(s.x, first_id);
    }
    // ---- the passes
    auto shifted = [avx2](bool dil, const std::uint8_t* src, u64* out, Index nw, const Index* qs,
                          const int* rs, int ns) {
#ifdef PFTRACK_MORPH_AVX2
        if (avx2) return detail::shifted_extremum_avx2(dil, src, out, nw, qs, rs, ns);
#endif
        detail::shifted_extremum(dil, src, out, nw, qs, rs, ns);
    };
    std::vector<Index> q;
    std::vector<int> r;
    auto shifts = [&](std::initializer_list<Index> bits) {
        q.clear(), r.clear();
        for (Index b : bits) {
            q.push_back(b >> 3);  // floor(b / 8)
            r.push_back(static_cast<int>(b & 7));
        }
    };
    for (size_t pi = 0; pi < passes.size(); ++pi) {
        const std::vector<ElementRow>& el = *passes[pi].element;
        const bool dil = passes[pi].op == MorphOp::dilate;
        const u64 id = dil ? 0 : ~u64(0);
        const u64 next_id =
            pi + 1 < passes.size() && passes[pi + 1].op == MorphOp::erode ? ~u64(0) : 0;
        const auto* xb = reinterpret_cast<const std::uint8_t*>(s.x.data() + G);
        // the distinct runs, each reduced over the whole buffer
        std::vector<std::pair<Index, Index>> runs;
        for (const ElementRow& e : el) {
            const std::pair<Index, Index> key{e.lo, e.hi};
            auto it = std::find(runs.begin(), runs.end(), key);
            if (it == runs.end()) {
                runs.push_back(key);
                it = runs.end() - 1;
            }
            (void)it;
        }
        if (s.runs.size() < runs.size()) s.runs.resize(runs.size());
        std::vector<const u64*> run_data(runs.size());
        for (size_t p = 0; p < runs.size(); ++p) {
            const auto [lo, hi] = runs[p];
            if (lo == 0 && hi == 0) {
                run_data[p] = s.x.data() + G;  // the plane itself
                continue;
            }
            std::vector<u64>& h = s.runs[p];
            h.resize(static_cast<size_t>(total));
            const Index w = hi - lo + 1;
            if (w <= 8) {  // the run's w shifted reads directly
                q.clear(), r.clear();
                for (Index b = lo; b <= hi; ++b) {
                    q.push_back(b >> 3);
                    r.push_back(static_cast<int>(b & 7));
                }
                shifted(dil, xb, h.data() + G, n, q.data(), r.data(), static_cast<int>(q.size()));
            } else {  // by doubling: level j is the extremum of bits [i, i + 2^j)
                s.level.assign(static_cast<size_t>(total), id);
                std::vector<u64> cur(s.x.begin(), s.x.end());
                Index width = 1;
                while (2 * width <= w) {
                    shifts({0, width});
                    shifted(dil, reinterpret_cast<const std::uint8_t*>(cur.data() + G),
                            s.level.data() + G, n, q.data(), r.data(), 2);
                    std::swap(cur, s.level);
                    std::fill(cur.begin(), cur.begin() + G, id);
                    std::fill(cur.end() - G, cur.end(), id);
                    width *= 2;
                }
                const Index rest = w - width;
                if (rest == 0)
                    shifts({lo});
                else
                    shifts({lo, lo + rest});
                shifted(dil, reinterpret_cast<const std::uint8_t*>(cur.data() + G), h.data() + G, n,
                        q.data(), r.data(), static_cast<int>(q.size()));
            }
            run_data[p] = h.data() + G;
        }
        // each output row: the extremum of the element rows' runs, R rows of band around
        u64* o = s.out.data() + G;
        const Index k0 = R * S, len = (T - 2 * R) * S;
        std::vector<const u64*> in(el.size());
        for (size_t e = 0; e < el.size(); ++e) {
            const auto key = std::make_pair(el[e].lo, el[e].hi);
            const size_t p =
                static_cast<size_t>(std::find(runs.begin(), runs.end(), key) - runs.begin());
            in[e] = run_data[p] + k0 + el[e].dy * S;
        }
#ifdef PFTRACK_MORPH_AVX2
        if (avx2) {
            detail::vertical_avx2(dil, in.data(), static_cast<int>(in.size()),
                                  s.valid.data() + k0, next_id, o + k0, len);
        } else
#endif
        {  // the first two rows into the output, the others into it, the last with the fill
            size_t e = 1;
            if (el.size() >= 3) {
                detail::word_extremum2(dil, in[0], in[1], o + k0, len);
                for (e = 2; e + 1 < el.size(); ++e) detail::word_extremum(dil, in[e], o + k0, len);
            } else {
                std::memcpy(o + k0, in[0], static_cast<size_t>(len) * sizeof(u64));
            }
            detail::word_extremum_fill(dil, in[el.size() == 1 ? 0 : e], s.valid.data() + k0,
                                       next_id, o + k0, len);
        }
        set_identity(s.out, next_id);
        std::swap(s.x, s.out);
    }
    // ---- unpack: 8 pixels a table look-up
    if (s.expand.empty()) {
        s.expand.resize(256);
        for (unsigned v = 0; v < 256; ++v) {
            u64 e = 0;
            for (unsigned j = 0; j < 8; ++j)
                if (v >> j & 1u) e |= u64(0xff) << (8 * j);
            s.expand[v] = e;
        }
    }
    const u64* E = s.expand.data();
    const u64 ma = 0x0101010101010101ULL * level_a;
    const u64* PA = s.x.data() + G + R * S;
    const u64* PB = s.x.data() + G + (R + plane_rows) * S;
#ifdef PFTRACK_MORPH_AVX2
    if (avx2) detail::unpack_rows_avx2(PA, PB, S, planes == 2, level_a, dst, rows, cols);
#endif
    for (Index y = 0; y < rows; ++y) {
        const auto* a = reinterpret_cast<const std::uint8_t*>(PA + y * S);
        const auto* b = reinterpret_cast<const std::uint8_t*>(PB + y * S);
        std::uint8_t* out = dst + y * cols;
        Index x = avx2 ? cols / 32 * 32 : 0;  // the AVX2 pass unpacked those
        for (; x + 8 <= cols; x += 8) {
            u64 v = E[a[x / 8]] & ma;
            if (planes == 2) v |= E[b[x / 8]];  // B within A after cleaning: 255 | m = 255
            std::memcpy(out + x, &v, 8);
        }
        for (; x < cols; ++x) {
            const bool in_a = a[x / 8] >> (x % 8) & 1u;
            const bool in_b = planes == 2 && (b[x / 8] >> (x % 8) & 1u);
            out[x] = in_b ? 255 : in_a ? level_a : 0;
        }
    }
    return true;
#endif
}

/// `clean_packed` of the blocks of rows that hold a non-zero byte, each taken with `margin`
/// rows above and below (the sum of the passes' vertical reaches) as an image of its own; every
/// other row of dst is 0. The same bytes as `clean_packed` of the whole mask: with the anchor in
/// every element an erosion never grows the foreground and each dilation grows it by its reach,
/// so after every pass the rows of a block within its remaining margin of the block's edge are
/// still 0, in the whole mask as in the block (an erosion there sees its own 0 pixel; a dilation
/// gets 0 from an outside row as from a left-out one), and rows more than `margin` from a
/// non-zero row stay 0. Groups of non-zero rows closer than 2 margin + 1 empty rows share a
/// block. A foreground mask is mostly empty rows (PETS09's raw masks: 141 of 360 rows hold a
/// pixel, in one band), which the packed planes would otherwise pack, pass and unpack. Returns
/// false, dst undefined, where `clean_packed` of a block does (a third level in it, or an
/// element without its anchor): the caller then takes the byte path for the whole mask.
inline bool clean_packed_blocks(const std::uint8_t* src, Index src_stride, std::uint8_t* dst,
                                Index rows, Index cols, const std::vector<PackedPass>& passes,
                                bool simd, PackedScratch& s) {
    Index ext, reach, margin;  // margin: the passes' summed reach
    if (!pass_reaches(passes, ext, reach, margin)) return false;  // the argument above needs it
#ifdef PFTRACK_MORPH_AVX2
    const bool avx2 = simd && __builtin_cpu_supports("avx2");
#else
    const bool avx2 = false;
#endif
    s.groups.clear();
    for (Index y = 0; y < rows; ++y) {
        if (detail::all_zero(src + y * src_stride, cols)) continue;  // the byte path's test
        if (!s.groups.empty() && y - s.groups.back().second - 1 <= 2 * margin)
            s.groups.back().second = y;
        else
            s.groups.emplace_back(y, y);
    }
    Index done = 0;  // rows of dst written
    const auto zero_rows = [&](Index to) {
        detail::zero_bytes(dst + done * cols, (to - done) * cols, avx2);
    };
    for (const auto& [first, last] : s.groups) {
        const Index a = std::max<Index>(first - margin, 0);
        const Index b = std::min<Index>(last + 1 + margin, rows);
        zero_rows(a);
        if (!clean_packed(src + a * src_stride, src_stride, dst + a * cols, b - a, cols, passes,
                          simd, s))
            return false;
        done = b;
    }
    zero_rows(rows);
    return true;
}

}  // namespace pftrack
