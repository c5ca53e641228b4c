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
#include <string>
#include <utility>
#include <vector>

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

/// c[i] = c[i] where inside[i] is 0xFF, else value (inside[i] is 0 or 0xFF), i < n.
PFTRACK_VECTOR_CLONES static void keep_inside(std::uint8_t* __restrict c,
                                              const std::uint8_t* __restrict inside,
                                              std::uint8_t value, Index n) {
    for (Index i = 0; i < n; ++i)
        c[i] = static_cast<std::uint8_t>((c[i] & inside[i]) | (value & ~inside[i]));
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

/// The closing (a dilation, then an erosion) of `src` (rows x cols, `src_stride` bytes a row)
/// by `el` into `dst` (rows x cols, packed), as cv2.morphologyEx(MORPH_CLOSE). `tmp` is scratch
/// of rows x cols bytes; no two of src, dst, tmp may alias.
inline void close_mask(const std::uint8_t* src, Index src_stride, std::uint8_t* dst,
                       std::uint8_t* tmp, Index rows, Index cols,
                       const std::vector<ElementRow>& el, MorphScratch& s) {
    morphology(src, src_stride, tmp, rows, cols, el, MorphOp::dilate, s);
    morphology(tmp, cols, dst, rows, cols, el, MorphOp::erode, s);
}

/// The opening (an erosion, then a dilation) of `src` by `el` into `dst`, as
/// cv2.morphologyEx(MORPH_OPEN); the arguments as `close_mask`'s.
inline void open_mask(const std::uint8_t* src, Index src_stride, std::uint8_t* dst,
                      std::uint8_t* tmp, Index rows, Index cols,
                      const std::vector<ElementRow>& el, MorphScratch& s) {
    morphology(src, src_stride, tmp, rows, cols, el, MorphOp::erode, s);
    morphology(tmp, cols, dst, rows, cols, el, MorphOp::dilate, s);
}

/// How far (columns, rows) from a pixel the element `el` reads, on the farther side.
inline std::pair<Index, Index> element_reach(const std::vector<ElementRow>& el) {
    Index rx = 0, ry = 0;
    for (const ElementRow& r : el) {
        rx = std::max({rx, -r.lo, r.hi});
        ry = std::max({ry, -r.dy, r.dy});
    }
    return {rx, ry};
}

/// A pixel rectangle [x0, x1) x [y0, y1).
struct PixelRect {
    Index x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

/// The cleaning of a mask (the opening by `open_el`, then the closing by `close_el`) at the
/// pixels of `regions` only: dst (rows x cols, packed) holds open_mask-then-close_mask's values
/// inside every region (clipped to the image) and 0 elsewhere. Returns false, with dst the whole
/// cleaning, when that costs no more (the estimate below).
///
/// Each region is cleaned on a crop of `src` grown by the four passes' reach (twice each
/// element's, per axis). A pass computes every pixel of the crop, but a pixel within an
/// element's reach of a crop edge that is not the image's own edge misses source pixels
/// outside the crop, so the exact part shrinks by that reach at each pass; at an image edge the
/// crop edge is the image edge, where both leave the outside pixels out alike. After the four
/// passes the region itself is exact: the values of the whole-mask passes, bit for bit.
///
/// A pass costs about the same per row at any width up to a frame's (a row's fixed work:
/// calls, loop tails), so the crops are not passed one by one: they are laid side by side, top
/// aligned, on one canvas as tall as the tallest, `sep` columns apart, and each pass runs once
/// on the canvas. Before each pass the canvas outside the crops (the columns between them, the
/// rows under the shorter ones) is set to the pass's identity (255 for an erosion, 0 for a
/// dilation), which never wins a minimum or maximum: each crop's values are then those of the
/// crop passed alone, as an image of its own (`sep` is at least every element's column reach,
/// so no crop reads another's pixels). `a` and `b` are scratch, resized here; none of src, dst,
/// a, b may alias.
inline bool clean_regions(const std::uint8_t* src, Index src_stride, std::uint8_t* dst,
                          Index rows, Index cols, const std::vector<ElementRow>& open_el,
                          const std::vector<ElementRow>& close_el,
                          const std::vector<PixelRect>& regions, MorphScratch& s,
                          std::vector<std::uint8_t>& a, std::vector<std::uint8_t>& b) {
    const auto [ox, oy] = element_reach(open_el);
    const auto [cx, cy] = element_reach(close_el);
    const Index gx = 2 * (ox + cx), gy = 2 * (oy + cy), sep = std::max<Index>(ox, cx);
    std::vector<std::pair<PixelRect, PixelRect>> work;  // (region, its crop), both clipped
    Index height = 0, width = sep;  // the canvas
    for (const PixelRect& r : regions) {
        const PixelRect in{std::max<Index>(r.x0, 0), std::max<Index>(r.y0, 0),
                           std::min(r.x1, cols), std::min(r.y1, rows)};
        if (in.x0 >= in.x1 || in.y0 >= in.y1) continue;
        const PixelRect crop{std::max<Index>(in.x0 - gx, 0), std::max<Index>(in.y0 - gy, 0),
                             std::min(in.x1 + gx, cols), std::min(in.y1 + gy, rows)};
        height = std::max(height, crop.y1 - crop.y0);
        width += crop.x1 - crop.x0 + sep;
        work.emplace_back(in, crop);
    }
    // a row's fixed work, counted as this many bytes of its vector work (callgrind, 480x360)
    constexpr Index kRowCost = 256;
    if (height * (width + kRowCost) >= rows * (cols + kRowCost)) {  // the whole costs no more
        a.resize(static_cast<size_t>(rows * cols));
        b.resize(static_cast<size_t>(rows * cols));
        open_mask(src, src_stride, b.data(), a.data(), rows, cols, open_el, s);
        close_mask(b.data(), cols, dst, a.data(), rows, cols, close_el, s);
        return false;
    }
    std::memset(dst, 0, static_cast<size_t>(rows * cols));
    if (work.empty()) return true;
    a.resize(static_cast<size_t>(height * width));
    b.resize(static_cast<size_t>(height * width));
    // 0xFF on the crops, 0 outside them; the canvas outside set to `value` (before each pass:
    // the pass's identity) by one vector blend, not a memset per row and crop
    std::vector<std::uint8_t> inside(static_cast<size_t>(height * width), 0);
    {
        Index x = sep;
        for (const auto& [in, crop] : work) {
            const Index w = crop.x1 - crop.x0;
            for (Index y = 0; y < crop.y1 - crop.y0; ++y)
                std::memset(inside.data() + y * width + x, 0xFF, size_t(w));
            x += w + sep;
        }
    }
    auto outside = [&](std::uint8_t* c, std::uint8_t value) {
        detail::keep_inside(c, inside.data(), value, height * width);
    };
    Index x = sep;
    for (const auto& [in, crop] : work) {
        const Index w = crop.x1 - crop.x0;
        for (Index y = crop.y0; y < crop.y1; ++y)
            std::memcpy(a.data() + (y - crop.y0) * width + x, src + y * src_stride + crop.x0,
                        size_t(w));
        x += w + sep;
    }
    outside(a.data(), 255);
    morphology(a.data(), width, b.data(), height, width, open_el, MorphOp::erode, s);
    outside(b.data(), 0);
    morphology(b.data(), width, a.data(), height, width, open_el, MorphOp::dilate, s);
    outside(a.data(), 0);
    morphology(a.data(), width, b.data(), height, width, close_el, MorphOp::dilate, s);
    outside(b.data(), 255);
    morphology(b.data(), width, a.data(), height, width, close_el, MorphOp::erode, s);
    x = sep;
    for (const auto& [in, crop] : work) {
        for (Index y = in.y0; y < in.y1; ++y)
            std::memcpy(dst + y * cols + in.x0,
                        a.data() + (y - crop.y0) * width + x + (in.x0 - crop.x0),
                        static_cast<size_t>(in.x1 - in.x0));
        x += crop.x1 - crop.x0 + sep;
    }
    return true;
}

}  // namespace pftrack
