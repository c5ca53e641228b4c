// The detector's ghost test in one pass per blob: the share of a blob's boundary edges that the
// current frame holds, against the background's. A real object has its silhouette's edges in the
// frame; a ghost (uncovered background the model still pictures as an object) has them only in
// the background. Same quantity as the OpenCV version in python/pftrack/detection/ghost.py:
// Gaussian blur 5x5 (sigma 1.5), Sobel 3x3, largest gradient magnitude over the channels, summed
// over the boundary band of the mask inside the blob's box (4 px margin), borders reflected
// (OpenCV's BORDER_REFLECT_101) at the edges of that box.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <new>
#include <utility>
#include <vector>

#include "types.hpp"

namespace pftrack {

namespace detail {

/// OpenCV's BORDER_REFLECT_101 (gfedcb|abcdefgh|gfedcba) for an axis of n >= 1 samples.
inline Index reflect101(Index p, Index n) {
    if (n == 1) return 0;
    while (p < 0 || p >= n) p = p < 0 ? -p : 2 * (n - 1) - p;
    return p;
}

/// cv::getGaussianKernel(5, 1.5): exp(-x^2 / (2 sigma^2)), x = -2 .. 2, normalised to sum 1.
inline std::array<double, 5> gaussian5_sigma15() {
    std::array<double, 5> g{};
    double s = 0.0;
    for (int i = 0; i < 5; ++i) {
        const double x = i - 2;
        g[static_cast<size_t>(i)] = std::exp(-x * x / (2.0 * 1.5 * 1.5));
        s += g[static_cast<size_t>(i)];
    }
    for (double& v : g) v /= s;
    return g;
}

/// std::allocator whose `resize` leaves new elements uninitialised: the scratch below is
/// written in full before it is read, and value-initialising it on every growth was 7 % of
/// `edge_support`'s instructions (memset).
template <class T>
struct UninitAllocator : std::allocator<T> {
    template <class U>
    struct rebind {
        using other = UninitAllocator<U>;
    };
    UninitAllocator() = default;
    template <class U>
    UninitAllocator(const UninitAllocator<U>&) noexcept {}
    template <class U>
    void construct(U* p) noexcept {
        ::new (static_cast<void*>(p)) U;  // default-, not value-initialised
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};
template <class T>
using ScratchVector = std::vector<T, UninitAllocator<T>>;

/// Scratch of `edge_magnitudes`, reused from blob to blob.
struct EdgeScratch {
    ScratchVector<float> pad, tmp, blur;  // padded channel, row-filtered, blurred (3 planes)
    ScratchVector<float> best;            // largest squared magnitude over the channels
    std::vector<Index> rx, ry, xm, xp;    // reflected indices
};

/// `edge_magnitudes`' row pass of the 5x5 Gaussian, over the n = ph pw floats of pad (ph rows
/// of pw = w + 4: a channel's w pixels and 2 reflected ones on each side) as one sequence:
/// tmp[i] = g0 p[i] + g1 p[i+1] + g2 p[i+2] + g1 p[i+3] + g0 p[i+4] in float32, in this order
/// (no FMA: the AVX2 clone gives the baseline's floats). tmp keeps pad's row stride pw: columns
/// 0 .. w-1 of each row are the blur, the 4 after them mix two rows and are never used. One loop
/// instead of a loop of w per row, each with its own vector remainder (regions 20-40 px wide).
PFTRACK_VECTOR_CLONES static void blur_rows5(const float* __restrict pad, float* __restrict tmp,
                                             Index n, float g0, float g1, float g2) {
    for (Index i = 0; i < n - 4; ++i)
        tmp[i] = g0 * pad[i] + g1 * pad[i + 1] + g2 * pad[i + 2] + g1 * pad[i + 3] +
                 g0 * pad[i + 4];
    for (Index i = std::max(n - 4, Index(0)); i < n; ++i) tmp[i] = 0.0f;  // unused, but defined
}

/// `edge_magnitudes`' column pass: blur (h rows of stride pw) from tmp (h + 4 rows of stride
/// pw), the same taps, as one loop over the h pw outputs (unused columns included).
PFTRACK_VECTOR_CLONES static void blur_cols5(const float* __restrict tmp, float* __restrict blur,
                                             Index h, Index pw, float g0, float g1, float g2) {
    const Index n = h * pw;
    for (Index i = 0; i < n; ++i)
        blur[i] = g0 * tmp[i] + g1 * tmp[i + pw] + g2 * tmp[i + 2 * pw] + g1 * tmp[i + 3 * pw] +
                  g0 * tmp[i + 4 * pw];
}

/// `edge_magnitudes`' Sobel away from the region's border: best[i] = max(0, max_c gx_c^2 +
/// gy_c^2) for the flat indices i in [pw + 1, (h - 1) pw - 1) of the three planes of `blur`
/// (h rows of stride pw each), the same float operations in the same order as the per-pixel
/// code (so the same values), as one loop over the rows' concatenation: at columns 0 and
/// w - 1 .. pw - 1, i +- 1 reaches another row or an unused column, values the caller never
/// reads (it computes the border pixels itself).
PFTRACK_VECTOR_CLONES static void sobel_best(const float* __restrict blur, Index h, Index pw,
                                             float* __restrict best) {
    const Index n = h * pw;
    const float* __restrict b0 = blur;
    const float* __restrict b1 = blur + n;
    const float* __restrict b2 = blur + 2 * n;
    for (Index i = pw + 1; i < n - pw - 1; ++i) {
        float m = 0.0f;
        for (const float* __restrict b : {b0, b1, b2}) {
            const float* r0 = b - pw;
            const float* r2 = b + pw;
            const float gx =
                (r0[i + 1] - r0[i - 1]) + 2.0f * (b[i + 1] - b[i - 1]) + (r2[i + 1] - r2[i - 1]);
            const float gy =
                (r2[i - 1] - r0[i - 1]) + 2.0f * (r2[i] - r0[i]) + (r2[i + 1] - r0[i + 1]);
            m = std::max(m, gx * gx + gy * gy);
        }
        best[i] = m;
    }
}

/// The squared edge magnitude at each band pixel (`band`, h x w, row-major, non-zero = in) into
/// `s.best` (h rows of stride w + 4; other pixels undefined): max_c (gx_c^2 + gy_c^2), gx, gy
/// the 3x3 Sobel derivatives of the 5x5 Gaussian blur (float32, as OpenCV's) of channel c of the
/// h x w image whose row y of channel c `fill_row(y, c, out)` writes to out[0 .. w).
template <class FillRow>
void edge_magnitudes(FillRow fill_row, Index h, Index w, const ScratchVector<std::uint8_t>& band,
                     EdgeScratch& s) {
    static const std::array<double, 5> gd = gaussian5_sigma15();
    const float g0 = static_cast<float>(gd[0]), g1 = static_cast<float>(gd[1]),
                g2 = static_cast<float>(gd[2]);  // symmetric: g3 = g1, g4 = g0
    // every plane below has rows of stride pw: the padded width
    const Index pw = w + 4, ph = h + 4, plane = h * pw;
    s.rx.resize(static_cast<size_t>(pw));
    s.ry.resize(static_cast<size_t>(ph));
    for (Index j = 0; j < pw; ++j) s.rx[static_cast<size_t>(j)] = reflect101(j - 2, w);
    for (Index j = 0; j < ph; ++j) s.ry[static_cast<size_t>(j)] = reflect101(j - 2, h);
    s.xm.resize(static_cast<size_t>(w));
    s.xp.resize(static_cast<size_t>(w));
    for (Index x = 0; x < w; ++x) {
        s.xm[static_cast<size_t>(x)] = reflect101(x - 1, w);
        s.xp[static_cast<size_t>(x)] = reflect101(x + 1, w);
    }
    s.pad.resize(static_cast<size_t>(pw * ph));
    s.tmp.resize(static_cast<size_t>(pw * ph));
    s.blur.resize(static_cast<size_t>(3 * plane));
    for (int c = 0; c < 3; ++c) {
        // the channel with 2 reflected pixels on every side: each row read once, its 2 + 2
        // margin pixels copied from inside it
        for (Index yy = 0; yy < ph; ++yy) {
            float* row = s.pad.data() + yy * pw;
            fill_row(s.ry[static_cast<size_t>(yy)], c, row + 2);
            for (const Index xx : {Index(0), Index(1), w + 2, w + 3})
                row[xx] = row[2 + s.rx[static_cast<size_t>(xx)]];
        }
        // rows first, then columns (OpenCV's separable order)
        // (AVX2 or baseline clones: blur_rows5, blur_cols5)
        blur_rows5(s.pad.data(), s.tmp.data(), pw * ph, g0, g1, g2);
        blur_cols5(s.tmp.data(), s.blur.data() + c * plane, h, pw, g0, g1, g2);
    }
    // the interior in one vectorised pass (AVX2 or baseline clones: sobel_best); the border
    // pixels (reflected neighbours) per pixel below
    s.best.resize(static_cast<size_t>(plane));
    sobel_best(s.blur.data(), h, pw, s.best.data());
    // the border pixels of the band: reflected neighbours, per pixel
    for (Index y = 0; y < h; ++y) {
        const Index ym = reflect101(y - 1, h), yp = reflect101(y + 1, h);
        const std::uint8_t* in = band.data() + y * w;
        const bool border_row = y == 0 || y == h - 1;
        const Index step = border_row ? 1 : w - 1;  // every column, or the first and last
        for (Index x = 0; x < w; x += step) {
            if (!in[x]) continue;
            const Index xm = s.xm[static_cast<size_t>(x)], xp = s.xp[static_cast<size_t>(x)];
            float best = 0.0f;
            for (int c = 0; c < 3; ++c) {
                const float* b = s.blur.data() + c * plane;
                const float* r0 = b + ym * pw;
                const float* r1 = b + y * pw;
                const float* r2 = b + yp * pw;
                // Sobel: [-1 0 1] along the axis, [1 2 1] across it
                const float gx = (r0[xp] - r0[xm]) + 2.0f * (r1[xp] - r1[xm]) + (r2[xp] - r2[xm]);
                const float gy = (r2[xm] - r0[xm]) + 2.0f * (r2[x] - r0[x]) + (r2[xp] - r0[xp]);
                best = std::max(best, gx * gx + gy * gy);
            }
            s.best[static_cast<size_t>(y * pw + x)] = best;
        }
    }
}

/// `edge_support`'s boundary band of an h x w region (h, w >= 3) of a mask (row y at
/// mask + y * mask_stride): band = (3x3 dilation of mask != 0) and not (3x3 erosion of it), as
/// 0/1, both taken inside the region only (outside neighbours do not count), as row maxima /
/// minima of the 0/1 mask (`on`, `hmax`, `hmin`: h x w scratch), then column ones. Whether any
/// pixel is in the band.
PFTRACK_VECTOR_CLONES static bool band_rows(const std::uint8_t* mask, Index mask_stride,
                                            Index h, Index w, std::uint8_t* __restrict on,
                                            std::uint8_t* __restrict hmax,
                                            std::uint8_t* __restrict hmin,
                                            std::uint8_t* __restrict band) {
    for (Index y = 0; y < h; ++y) {
        const std::uint8_t* __restrict m = mask + y * mask_stride;
        std::uint8_t* __restrict o = on + y * w;
        for (Index x = 0; x < w; ++x) o[x] = m[x] != 0 ? 1 : 0;
        std::uint8_t* __restrict mx = hmax + y * w;
        std::uint8_t* __restrict mn = hmin + y * w;
        mx[0] = std::max(o[0], o[1]);
        mn[0] = std::min(o[0], o[1]);
        for (Index x = 1; x < w - 1; ++x) {  // of 0/1: max is or, min is and
            mx[x] = static_cast<std::uint8_t>(o[x - 1] | o[x] | o[x + 1]);
            mn[x] = static_cast<std::uint8_t>(o[x - 1] & o[x] & o[x + 1]);
        }
        mx[w - 1] = std::max(o[w - 2], o[w - 1]);
        mn[w - 1] = std::min(o[w - 2], o[w - 1]);
    }
    std::uint8_t any = 0;
    for (Index y = 0; y < h; ++y) {
        const Index a = std::max(y - 1, Index(0)), z = std::min(y + 1, h - 1);
        const std::uint8_t* __restrict xa = hmax + a * w;
        const std::uint8_t* __restrict xy = hmax + y * w;
        const std::uint8_t* __restrict xz = hmax + z * w;
        const std::uint8_t* __restrict na = hmin + a * w;
        const std::uint8_t* __restrict ny = hmin + y * w;
        const std::uint8_t* __restrict nz = hmin + z * w;
        std::uint8_t* __restrict bd = band + y * w;
        for (Index x = 0; x < w; ++x) {
            const int dil = xa[x] | xy[x] | xz[x], ero = na[x] & ny[x] & nz[x];
            bd[x] = static_cast<std::uint8_t>(dil & (ero ^ 1));
            any |= bd[x];
        }
    }
    return any != 0;
}

/// Channel c's bytes of n interleaved BGR pixels as floats: out[x] = p[3 x] (p at channel c).
PFTRACK_VECTOR_CLONES static void channel_floats(const std::uint8_t* __restrict p,
                                                 float* __restrict out, Index n) {
    for (Index x = 0; x < n; ++x) out[x] = static_cast<float>(p[3 * x]);
}

}  // namespace detail

/// The ghost test's statistic over a blob's boundary band.
enum class GhostStatistic {
    ratio,  // E_frame / (E_frame + E_background): the summed edge magnitudes
    vote,   // the share of band pixels whose frame edge is stronger than the background's
};

/// Share of each blob's boundary edges that the current frame holds (the ghost test).
///
/// For box k (`boxes` K x 4 doubles, left, top, w, h, row-major): the region
/// [int(left) - 4, int(left + w) + 4) x [int(top) - 4, int(top + h) + 4), clipped to the frame;
/// its band = (3x3 dilation of the mask != 0) and not (3x3 erosion of it), both taken inside the
/// region only; out[k] = E_frame / (E_frame + E_background), the `detail::edge_sum` of the frame
/// (`bgr`, interleaved, `row_stride` bytes a row) and of the background (`background`: float
/// rows of `bg_row_stride` floats, channel c of pixel x at [c * bg_plane_stride + x * bg_pixel
/// _stride]). 0.5 when the region is under 3 px on a side, its band is empty, or both sums are 0.
/// With `GhostStatistic::vote`, out[k] is instead the share of band pixels whose frame magnitude
/// is strictly larger than the background's: a ghost that its owner has just left keeps the
/// owner's strong edge on one side of its boundary, which outweighs the rest in the sums but is
/// one side in the vote (0.5 when the band is empty or the region too small).
inline void edge_support(const std::uint8_t* bgr, Index row_stride, const float* background,
                         Index bg_row_stride, Index bg_plane_stride, Index bg_pixel_stride,
                         Index rows, Index cols, const std::uint8_t* mask, Index mask_stride,
                         const double* boxes, Index k, double* out,
                         GhostStatistic statistic = GhostStatistic::ratio) {
    detail::EdgeScratch scratch;
    detail::ScratchVector<float> best_f;  // the frame's squared magnitudes (scratch.best's)
    detail::ScratchVector<std::uint8_t> on, band, hmax, hmin;  // written in full by band_rows
    for (Index i = 0; i < k; ++i) {
        out[i] = 0.5;
        const double* b = boxes + 4 * i;
        // Python's int(): truncation toward zero
        const Index x0 = std::max(static_cast<Index>(b[0]) - 4, Index(0));
        const Index y0 = std::max(static_cast<Index>(b[1]) - 4, Index(0));
        const Index x1 = std::min(static_cast<Index>(b[0] + b[2]) + 4, cols);
        const Index y1 = std::min(static_cast<Index>(b[1] + b[3]) + 4, rows);
        if (x1 - x0 < 3 || y1 - y0 < 3) continue;
        const Index w = x1 - x0, h = y1 - y0;
        const auto n = static_cast<size_t>(w * h);
        band.resize(n);
        on.resize(n);
        hmax.resize(n);
        hmin.resize(n);
        // (AVX2 or baseline clones: detail::band_rows)
        if (!detail::band_rows(mask + y0 * mask_stride + x0, mask_stride, h, w, on.data(),
                               hmax.data(), hmin.data(), band.data()))
            continue;
        detail::edge_magnitudes(
            [&](Index y, int c, float* __restrict out) {
                // (AVX2 or baseline clones: detail::channel_floats)
                detail::channel_floats(bgr + (y0 + y) * row_stride + 3 * x0 + c, out, w);
            },
            h, w, band, scratch);
        std::swap(best_f, scratch.best);  // O(1): the background's go into the other buffer
        detail::edge_magnitudes(
            [&](Index y, int c, float* __restrict out) {
                const float* __restrict p = background + (y0 + y) * bg_row_stride +
                                            c * bg_plane_stride + x0 * bg_pixel_stride;
                if (bg_pixel_stride == 1)
                    std::copy(p, p + w, out);
                else
                    for (Index x = 0; x < w; ++x) out[x] = p[x * bg_pixel_stride];
            },
            h, w, band, scratch);
        // one pass over the band for both pictures, in row-major order (planes of stride w + 4)
        const float* bf = best_f.data();
        const float* bb = scratch.best.data();
        const Index pw = w + 4;
        if (statistic == GhostStatistic::vote) {
            // sqrt is increasing: comparing the squares gives the magnitudes' comparison
            Index stronger = 0, count = 0;
            for (Index y = 0; y < h; ++y)
                for (Index x = 0; x < w; ++x)
                    if (band[static_cast<size_t>(y * w + x)]) {
                        stronger += bf[y * pw + x] > bb[y * pw + x] ? 1 : 0;
                        ++count;
                    }
            out[i] = static_cast<double>(stronger) / static_cast<double>(count);
            continue;
        }
        double e_f = 0.0, e_b = 0.0;  // each summed in the band's row-major order
        for (Index y = 0; y < h; ++y)
            for (Index x = 0; x < w; ++x)
                if (band[static_cast<size_t>(y * w + x)]) {
                    e_f += std::sqrt(static_cast<double>(bf[y * pw + x]));
                    e_b += std::sqrt(static_cast<double>(bb[y * pw + x]));
                }
        if (e_f + e_b > 0.0) out[i] = e_f / (e_f + e_b);
    }
}

}  // namespace pftrack
