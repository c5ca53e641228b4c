// The detectors' blob pass: a cleaned foreground mask -> filtered, merged and split boxes
// (python/pftrack/detection/base.py documents the rules; tests/reference/blobs.py is the
// reference, OpenCV contours plus NumPy, which this matches exactly), and the person-size
// model's Theil-Sen line (python/pftrack/detection/size_model.py).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <vector>

#include "check.hpp"
#include "mask_scan.hpp"
#include "types.hpp"

namespace pftrack {

/// A box: left, top, width, height, in pixels.
struct BlobRect {
    double x, y, w, h;
};

/// The person-size model's lines in the foot row: expected h and w = slope * y + intercept.
struct SizeLines {
    double h_slope, h_intercept, w_slope, w_intercept;
};

/// Blob filters, thresholds as in BlobConfig (fractions of the frame's area).
struct BlobLimits {
    double min_area, max_area, min_aspect, max_aspect, min_fill;
};

/// Median as numpy.median gives it: the middle value, or the mean of the two middle ones.
inline double median_of(std::vector<double>& v) {
    const std::size_t m = v.size(), k = m / 2;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
    const double hi = v[k];
    if (m % 2 == 1) return hi;
    const double lo = *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k));
    return (lo + hi) / 2.0;
}

/// Theil-Sen line through (x, y): the median of the slopes over every pair with distinct x,
/// intercept median(y - slope x). Throws std::invalid_argument when no two x differ.
inline std::pair<double, double> theil_sen(const double* x, const double* y, Index n) {
    // 0.5 n (n - 1) in double: the count cannot overflow before it is checked
    require_size(0.5 * static_cast<double>(n) * static_cast<double>(n - 1), "theil_sen",
                 "the pairwise slopes of " + std::to_string(n) + " points");
    std::vector<double> s;
    s.reserve(static_cast<std::size_t>(n > 1 ? n * (n - 1) / 2 : 0));
    for (Index i = 0; i < n; ++i)
        for (Index j = i + 1; j < n; ++j) {
            const double dx = x[j] - x[i];
            if (dx != 0.0) s.push_back((y[j] - y[i]) / dx);
        }
    if (s.empty()) fail("theil_sen", "x has no two distinct values, expected at least two");
    const double slope = median_of(s);
    if (!std::isfinite(slope)) fail("theil_sen", "the slope overflows (values too large)");
    std::vector<double> r(static_cast<std::size_t>(n));
    for (Index i = 0; i < n; ++i) {
        const double sx = slope * x[i];  // two roundings, as NumPy's y - slope * x
        r[static_cast<std::size_t>(i)] = y[i] - sx;
    }
    const double intercept = median_of(r);
    if (!std::isfinite(intercept)) fail("theil_sen", "the intercept overflows (values too large)");
    return {slope, intercept};
}

/// Theil-Sen line refitted once on the points within 3 robust sigmas (1.4826 MAD, at least 1)
/// of the first line, when at least 3 points with distinct x remain (PersonSizeModel's fit).
inline std::pair<double, double> robust_line(const std::vector<double>& x,
                                             const std::vector<double>& y) {
    const Index n = static_cast<Index>(x.size());
    auto [slope, intercept] = theil_sen(x.data(), y.data(), n);
    std::vector<double> r(x.size()), dev(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
        const double sx = slope * x[i];
        const double fit = sx + intercept;
        r[i] = y[i] - fit;
    }
    std::vector<double> tmp = r;
    const double mid = median_of(tmp);
    for (std::size_t i = 0; i < x.size(); ++i) dev[i] = std::abs(r[i] - mid);
    const double sigma = 1.4826 * median_of(dev);
    const double bound = 3.0 * std::max(sigma, 1.0);
    std::vector<double> kx, ky;
    for (std::size_t i = 0; i < x.size(); ++i)
        if (std::abs(r[i]) <= bound) {
            kx.push_back(x[i]);
            ky.push_back(y[i]);
        }
    if (kx.size() >= 3 &&
        *std::max_element(kx.begin(), kx.end()) - *std::min_element(kx.begin(), kx.end()) > 0.0)
        return theil_sen(kx.data(), ky.data(), static_cast<Index>(kx.size()));
    return {slope, intercept};
}

/// The person-size model's lines from its samples (n rows of foot y, h, w, `stride` doubles a
/// row): [[h_slope, h_intercept], [w_slope, w_intercept]]. Every foot on one row (spread under
/// 1 px): slopes 0 and the median sizes; otherwise `robust_line` of h and of w against foot y.
inline SizeLines size_fit(const double* samples, Index n, Index stride) {
    if (n < 1) fail("size_fit", "samples is empty, expected at least one row");
    std::vector<double> y(static_cast<std::size_t>(n)), h(y.size()), w(y.size());
    for (Index i = 0; i < n; ++i) {
        const auto k = static_cast<std::size_t>(i);
        y[k] = samples[i * stride];
        h[k] = samples[i * stride + 1];
        w[k] = samples[i * stride + 2];
    }
    if (*std::max_element(y.begin(), y.end()) - *std::min_element(y.begin(), y.end()) < 1.0)
        return {0.0, median_of(h), 0.0, median_of(w)};
    const auto [hs, hi] = robust_line(y, h);
    const auto [ws, wi] = robust_line(y, w);
    return {hs, hi, ws, wi};
}

/// round(v) half to even (numpy.round), as an integer count, clamped to [0, 2^53].
inline std::int64_t to_count(double v) {
    return static_cast<std::int64_t>(std::nearbyint(std::clamp(v, 0.0, 9007199254740992.0)));
}

/// Expected (h, w) at foot row `foot_y`, at least 1 px (PersonSizeModel.expected).
inline void expected_size(const SizeLines& s, double foot_y, double& h, double& w) {
    const double hy = s.h_slope * foot_y, wy = s.w_slope * foot_y;  // no fused multiply-add
    h = std::max(hy + s.h_intercept, 1.0);
    w = std::max(wy + s.w_intercept, 1.0);
}

/// How many people each box holds side by side (PersonSizeModel.split_count).
inline std::vector<std::int64_t> split_count(const std::vector<BlobRect>& b, const SizeLines& s,
                                             double split_ratio, double split_max_height) {
    std::vector<std::int64_t> n(b.size(), 1);
    for (std::size_t i = 0; i < b.size(); ++i) {
        double h_exp, w_exp;
        expected_size(s, b[i].y + b[i].h, h_exp, w_exp);
        const bool wide = b[i].w > split_ratio * w_exp && b[i].h <= split_max_height * h_exp;
        // at most 2^53 (any box of a real frame is far below): the cast stays defined
        if (wide) n[i] = std::max<std::int64_t>(to_count(b[i].w / w_exp), 1);
    }
    return n;
}

namespace detail {

/// The union `u` of boxes `a` and `c` when they may be one person's fragments: they overlap in
/// columns by half the narrower box, and the union fits `merge_slack` expected sizes.
inline bool fragment_union(const BlobRect& a, const BlobRect& c, const SizeLines& s,
                           double merge_slack, BlobRect& u) {
    const double ov = std::min(a.x + a.w, c.x + c.w) - std::max(a.x, c.x);
    if (ov < 0.5 * std::min(a.w, c.w)) return false;
    const double x0 = std::min(a.x, c.x), y0 = std::min(a.y, c.y);
    const double x1 = std::max(a.x + a.w, c.x + c.w);
    const double y1 = std::max(a.y + a.h, c.y + c.h);
    double h_exp, w_exp;
    expected_size(s, y1, h_exp, w_exp);
    if (y1 - y0 > merge_slack * h_exp || x1 - x0 > merge_slack * w_exp) return false;
    u = {x0, y0, x1 - x0, y1 - y0};
    return true;
}

}  // namespace detail

/// Groups of boxes that are one person's fragments (PersonSizeModel.merge_fragments): greedily
/// the pair with the smallest union among those overlapping in columns by half the narrower
/// box and fitting `merge_slack` expected sizes, until no pair fits. Ties go to the first pair.
///
/// The pairs are not all scanned again after each merge (O(n^3) for n boxes: 0.5-0.8 s for
/// 1000 fragments): each box keeps its best later partner (the smallest union, the first on a
/// tie), and a merge rescans only the rows whose best it touched. A merged box keeps the
/// first box's place and the second's is left out, so the order of the boxes left, and with it
/// "the first pair", is the same as erasing the second box; the groups and their order are
/// those of the full scan (tests/reference/blobs.py).
inline std::vector<std::vector<Index>> merge_fragments(const std::vector<BlobRect>& b,
                                                       const SizeLines& s, double merge_slack) {
    const std::size_t n = b.size();
    constexpr std::size_t kNone = static_cast<std::size_t>(-1);
    std::vector<std::vector<Index>> groups(n);
    for (std::size_t i = 0; i < n; ++i) groups[i] = {static_cast<Index>(i)};
    std::vector<BlobRect> cur = b;
    std::vector<char> alive(n, 1);
    std::vector<std::size_t> partner(n, kNone);  // the best j > i, kNone without one
    std::vector<double> best(n, 0.0);             // the area of (i, partner[i])'s union
    const auto scan = [&](std::size_t i) {
        partner[i] = kNone;
        for (std::size_t j = i + 1; j < n; ++j) {
            BlobRect u;
            if (!alive[j] || !detail::fragment_union(cur[i], cur[j], s, merge_slack, u)) continue;
            const double area = u.w * u.h;
            if (partner[i] == kNone || area < best[i]) {
                partner[i] = j;
                best[i] = area;
            }
        }
    };
    for (std::size_t i = 0; i < n; ++i) scan(i);
    while (true) {
        std::size_t bi = kNone;
        for (std::size_t i = 0; i < n; ++i)
            if (alive[i] && partner[i] != kNone && (bi == kNone || best[i] < best[bi])) bi = i;
        if (bi == kNone) break;
        const std::size_t bj = partner[bi];
        BlobRect merged;
        detail::fragment_union(cur[bi], cur[bj], s, merge_slack, merged);
        cur[bi] = merged;
        groups[bi].insert(groups[bi].end(), groups[bj].begin(), groups[bj].end());
        groups[bj].clear();
        alive[bj] = 0;
        // rows after bj pair only with boxes after it: unchanged. Rows whose best was bi (now
        // another box) or bj (gone) are rescanned; a row before bi may now pair best with bi.
        for (std::size_t i = 0; i < bj; ++i) {
            if (!alive[i]) continue;
            if (i == bi || partner[i] == bi || partner[i] == bj) {
                scan(i);
            } else if (i < bi) {
                BlobRect u;
                if (!detail::fragment_union(cur[i], cur[bi], s, merge_slack, u)) continue;
                const double area = u.w * u.h;
                if (partner[i] == kNone || area < best[i] || (area == best[i] && bi < partner[i])) {
                    partner[i] = bi;
                    best[i] = area;
                }
            }
        }
    }
    std::vector<std::vector<Index>> out;
    for (std::size_t i = 0; i < n; ++i)
        if (alive[i]) out.push_back(std::move(groups[i]));
    return out;
}

/// Legs lost to the shadow test, recovered within the person-size model (PaperConfig.leg_height):
/// a box shorter than `min_height` times the height of a person whose head is at its top row
/// (h_e solves h = h_intercept + h_slope (top + h), so h_e = (h_intercept + h_slope top) /
/// (1 - h_slope); h_slope > 1 is a camera below head height, where nearer heads are higher;
/// no such person when h_slope = 1 or h_e <= 0) is extended down, row by row,
/// through the rows below it where at least `row_fill` of the box's columns (and at least one)
/// are non-zero in `mask` (foreground 255 or shadow 127), never past the expected foot row
/// top + h_e. Columns [round(x), round(x + w)) and the first row round(y + h) are clipped to
/// the mask. Boxes are changed in place; only heights change.
inline void extend_legs(const std::uint8_t* mask, Index rows, Index cols, Index stride,
                        std::vector<BlobRect>& boxes, const SizeLines& s, double min_height,
                        double row_fill) {
    const double denom = 1.0 - s.h_slope;
    if (denom == 0.0) return;
    const auto clip = [](double v, Index hi) {
        return static_cast<Index>(std::nearbyint(std::clamp(v, 0.0, double(hi))));
    };
    for (BlobRect& b : boxes) {
        const double hy = s.h_slope * b.y;  // no fused multiply-add (NumPy's rounding)
        const double h_exp = (s.h_intercept + hy) / denom;
        if (!(h_exp > 0.0) || !(b.h < min_height * h_exp)) continue;
        const double foot = b.y + h_exp;
        const Index x0 = clip(b.x, cols), x1 = clip(b.x + b.w, cols);
        if (x1 <= x0) continue;
        const double need = row_fill * double(x1 - x0);
        Index r = clip(b.y + b.h, rows);
        const Index start = r;
        // row r joins when the new bottom r + 1 stays at or above the expected foot row
        while (r < rows && double(r + 1) <= foot) {
            const std::uint8_t* m = mask + r * stride;
            Index n = 0;
            for (Index x = x0; x < x1; ++x) n += m[x] != 0;
            if (n == 0 || double(n) < need) break;
            ++r;
        }
        if (r > start) b.h = double(r) - b.y;
    }
}

namespace detail {

struct Runs {  // runs of equal pixels, row by row, in raster order
    std::vector<Index> a, b;       // [a, b) columns
    std::vector<Index> row_start;  // runs of row r: row_start[r] .. row_start[r + 1]
};

inline Index find_root(std::vector<Index>& parent, Index i) {
    while (parent[static_cast<std::size_t>(i)] != i) {
        const Index p = parent[static_cast<std::size_t>(i)];
        parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(p)];
        i = p;
    }
    return i;
}

inline void unite(std::vector<Index>& parent, Index i, Index j) {
    i = find_root(parent, i);
    j = find_root(parent, j);
    if (i == j) return;
    if (i < j) std::swap(i, j);
    parent[static_cast<std::size_t>(i)] = j;  // the root is the run met first
}

/// Joins runs of consecutive rows: 8-connected (diagonal contact counts) or 4-connected.
inline void join_rows(const Runs& r, Index rows, bool eight, std::vector<Index>& parent) {
    const Index d = eight ? 1 : 0;
    for (Index y = 1; y < rows; ++y) {
        Index i = r.row_start[static_cast<std::size_t>(y - 1)];
        const Index i_end = r.row_start[static_cast<std::size_t>(y)];
        Index j = i_end;
        const Index j_end = r.row_start[static_cast<std::size_t>(y + 1)];
        while (i < i_end && j < j_end) {
            const auto ui = static_cast<std::size_t>(i), uj = static_cast<std::size_t>(j);
            if (r.a[ui] < r.b[uj] + d && r.a[uj] < r.b[ui] + d) unite(parent, i, j);
            if (r.b[ui] < r.b[uj]) ++i;
            else ++j;
        }
    }
}

inline std::int64_t count_nonzero(const std::uint8_t* mask, Index stride, Index x0, Index y0,
                                  Index x1, Index y1) {
    std::int64_t n = 0;
    for (Index y = y0; y < y1; ++y) {
        const std::uint8_t* p = mask + y * stride;
        for (Index x = x0; x < x1; ++x) n += p[x] != 0;
    }
    return n;
}

}  // namespace detail

/// Outer boxes of the 8-connected foreground regions of `mask` (`rows` x `cols` bytes, `stride`
/// bytes a row, non-zero = foreground) that are not inside a hole of another region: the
/// bounding rectangles of cv2.findContours(RETR_EXTERNAL), in its order (the reverse raster
/// order of each region's first pixel). A region is outer when its leftmost pixel touches the
/// image's edge or the background left of it reaches the edge (4-connected background).
inline std::vector<BlobRect> outer_regions(const std::uint8_t* mask, Index rows, Index cols,
                                           Index stride) {
    detail::Runs fg, bg;
    std::vector<Index> left_bg;  // per foreground run: the background run just left, or -1
    fg.row_start.assign(static_cast<std::size_t>(rows + 1), 0);
    bg.row_start.assign(static_cast<std::size_t>(rows + 1), 0);
    const bool avx2 = detail::avx2_usable();
    for (Index y = 0; y < rows; ++y) {
        fg.row_start[static_cast<std::size_t>(y)] = static_cast<Index>(fg.a.size());
        bg.row_start[static_cast<std::size_t>(y)] = static_cast<Index>(bg.a.size());
        const std::uint8_t* p = mask + y * stride;
        Index x = 0;
        while (x < cols) {
            const Index s = x;
            x = detail::skip_zero_words(p, x, cols, avx2);  // background is most of a mask
            while (x < cols && p[x] == 0) ++x;
            if (x > s) {
                bg.a.push_back(s);
                bg.b.push_back(x);
            }
            if (x == cols) break;
            const Index f = x;
            while (x < cols && p[x] != 0) ++x;
            fg.a.push_back(f);
            fg.b.push_back(x);
            left_bg.push_back(f > 0 ? static_cast<Index>(bg.a.size()) - 1 : -1);
        }
    }
    fg.row_start[static_cast<std::size_t>(rows)] = static_cast<Index>(fg.a.size());
    bg.row_start[static_cast<std::size_t>(rows)] = static_cast<Index>(bg.a.size());

    std::vector<Index> fp(fg.a.size()), bp(bg.a.size());
    std::iota(fp.begin(), fp.end(), Index{0});
    std::iota(bp.begin(), bp.end(), Index{0});
    detail::join_rows(fg, rows, true, fp);
    detail::join_rows(bg, rows, false, bp);
    std::vector<char> outer(bg.a.size(), 0);  // per background root: reaches the image's edge
    for (Index y = 0; y < rows; ++y)
        for (Index k = bg.row_start[static_cast<std::size_t>(y)];
             k < bg.row_start[static_cast<std::size_t>(y + 1)]; ++k) {
            const auto uk = static_cast<std::size_t>(k);
            if (y == 0 || y == rows - 1 || bg.a[uk] == 0 || bg.b[uk] == cols)
                outer[static_cast<std::size_t>(detail::find_root(bp, k))] = 1;
        }

    struct Region {
        Index x0, y0, x1, y1, left_run;  // inclusive bounds; the run at the leftmost column
    };
    std::vector<Index> slot(fg.a.size(), -1);  // per root: its region
    std::vector<Region> regions;
    for (Index y = 0; y < rows; ++y)
        for (Index k = fg.row_start[static_cast<std::size_t>(y)];
             k < fg.row_start[static_cast<std::size_t>(y + 1)]; ++k) {
            const auto uk = static_cast<std::size_t>(k);
            const auto root = static_cast<std::size_t>(detail::find_root(fp, k));
            if (slot[root] < 0) {
                slot[root] = static_cast<Index>(regions.size());
                regions.push_back({fg.a[uk], y, fg.b[uk] - 1, y, k});
                continue;
            }
            Region& g = regions[static_cast<std::size_t>(slot[root])];
            if (fg.a[uk] < g.x0) {
                g.x0 = fg.a[uk];
                g.left_run = k;
            }
            g.x1 = std::max(g.x1, fg.b[uk] - 1);
            g.y1 = y;
        }
    std::vector<BlobRect> out;
    for (auto it = regions.rbegin(); it != regions.rend(); ++it) {
        const Index lb = left_bg[static_cast<std::size_t>(it->left_run)];
        if (lb >= 0 && !outer[static_cast<std::size_t>(detail::find_root(bp, lb))]) continue;
        out.push_back({double(it->x0), double(it->y0), double(it->x1 - it->x0 + 1),
                       double(it->y1 - it->y0 + 1)});
    }
    return out;
}

/// Cuts each box into counts[i] people at the minima of its column profile; parts with fewer
/// than `min_pixels` foreground pixels are dropped, each kept part gets its tight box.
/// With `valley` < 1 a cut is made only where the profile falls to at most `valley` times the
/// lower of the two sides' peaks (the columns from the last cut made to it, and from it to the
/// next minimum): one wide person's profile has no such valley.
inline void split_groups(const std::uint8_t* mask, Index stride, std::vector<BlobRect>& rects,
                         std::vector<double>& fill, const std::vector<std::int64_t>& counts,
                         double min_pixels, double valley = 1.0) {
    std::vector<BlobRect> out_r;
    std::vector<double> out_f;
    std::vector<std::int64_t> profile;
    std::vector<Index> cuts, kept;
    for (std::size_t i = 0; i < rects.size(); ++i) {
        const auto x = static_cast<Index>(rects[i].x), y = static_cast<Index>(rects[i].y);
        const auto w = static_cast<Index>(rects[i].w), h = static_cast<Index>(rects[i].h);
        // at most 2^20 parts (bounds the work; a real frame's counts are far below)
        const std::int64_t n = std::min<std::int64_t>(counts[i], std::int64_t{1} << 20);
        if (n < 2) {
            out_r.push_back(rects[i]);
            out_f.push_back(fill[i]);
            continue;
        }
        profile.assign(static_cast<std::size_t>(w), 0);
        for (Index r = 0; r < h; ++r) {
            const std::uint8_t* p = mask + (y + r) * stride + x;
            for (Index c = 0; c < w; ++c) profile[static_cast<std::size_t>(c)] += p[c] != 0;
        }
        cuts.assign(1, 0);
        const Index half = std::max<Index>(1, w / (4 * n));
        for (std::int64_t k = 1; k < n; ++k) {
            const auto c = static_cast<Index>(std::nearbyint(double(k * w) / double(n)));
            const Index lo = std::max(cuts.back() + 1, c - half), hi = std::min(w - 1, c + half + 1);
            if (hi > lo) {
                const auto first = profile.begin() + lo;
                cuts.push_back(lo + (std::min_element(first, profile.begin() + hi) - first));
            } else {
                cuts.push_back(c);
            }
        }
        cuts.push_back(w);
        if (valley < 1.0) {
            kept.assign(1, 0);
            for (std::size_t k = 1; k + 1 < cuts.size(); ++k) {
                // a cut with no column on one side (a narrow box cut into many) is no valley;
                // every cut lies in [0, w]
                if (!(kept.back() < cuts[k] && cuts[k] < cuts[k + 1])) continue;
                const auto at = [&](Index j) { return profile[static_cast<std::size_t>(j)]; };
                std::int64_t left = 0, right = 0;
                for (Index j = kept.back(); j < cuts[k]; ++j) left = std::max(left, at(j));
                for (Index j = cuts[k]; j < cuts[k + 1]; ++j) right = std::max(right, at(j));
                if (double(at(cuts[k])) <= valley * double(std::min(left, right)))
                    kept.push_back(cuts[k]);
            }
            kept.push_back(w);
            cuts.swap(kept);
        }
        for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
            const Index a = std::max<Index>(cuts[k], 0), b = std::min(cuts[k + 1], w);
            if (b <= a) continue;
            Index r0 = h, r1 = -1, c0 = b, c1 = -1;
            std::int64_t sum = 0;
            for (Index r = 0; r < h; ++r) {
                const std::uint8_t* p = mask + (y + r) * stride + x;
                for (Index c = a; c < b; ++c)
                    if (p[c] != 0) {
                        ++sum;
                        r0 = std::min(r0, r);
                        r1 = r;
                        c0 = std::min(c0, c);
                        c1 = std::max(c1, c);
                    }
            }
            if (r1 < 0 || double(sum) < min_pixels) continue;
            const Index pw = c1 - c0 + 1, ph = r1 - r0 + 1;
            out_r.push_back({double(x + c0), double(y + r0), double(pw), double(ph)});
            out_f.push_back(double(sum) / double(pw * ph));
        }
    }
    rects.swap(out_r);
    fill.swap(out_f);
}

/// The whole blob pass of one cleaned mask (BlobExtractor.boxes without the size model's
/// update and the final sort): outer regions, area / aspect / fill filters, then, with `size`,
/// fragments merged and groups split by the person-size model, else, with `person_aspect` > 0,
/// groups split by that aspect; a cut only at a valley of the column profile (`split_valley`,
/// split_groups). Returns boxes and fills in the reference's (unsorted) order.
inline void blob_boxes(const std::uint8_t* mask, Index rows, Index cols, Index stride,
                       const BlobLimits& lim, double person_aspect, const SizeLines* size,
                       double split_ratio, double split_max_height, double merge_slack,
                       std::vector<BlobRect>& rects, std::vector<double>& fill,
                       double split_valley = 1.0) {
    const std::vector<BlobRect> all = outer_regions(mask, rows, cols, stride);
    const double frame_area = double(rows * cols);
    const double lo_area = lim.min_area * frame_area, hi_area = lim.max_area * frame_area;
    rects.clear();
    fill.clear();
    for (const BlobRect& r : all) {
        const double aspect = r.h / r.w;
        if (!(r.w * r.h >= lo_area && aspect >= lim.min_aspect && aspect <= lim.max_aspect))
            continue;
        const auto x = static_cast<Index>(r.x), y = static_cast<Index>(r.y);
        const double area = double(detail::count_nonzero(mask, stride, x, y,
                                                         x + static_cast<Index>(r.w),
                                                         y + static_cast<Index>(r.h)));
        const double f = area / (r.w * r.h);
        if (area >= lo_area && area <= hi_area && f >= lim.min_fill) {
            rects.push_back(r);
            fill.push_back(f);
        }
    }
    if (rects.empty()) return;
    // min_area * H * W, multiplied left to right as in Python
    const double min_pixels = lim.min_area * double(rows) * double(cols);
    if (size != nullptr) {
        const std::vector<std::vector<Index>> groups = merge_fragments(rects, *size, merge_slack);
        if (groups.size() != rects.size()) {
            std::vector<BlobRect> mr;
            std::vector<double> mf;
            for (const auto& g : groups) {
                double x0 = rects[static_cast<std::size_t>(g[0])].x, y0 = rects[static_cast<std::size_t>(g[0])].y;
                double x1 = x0 + rects[static_cast<std::size_t>(g[0])].w;
                double y1 = y0 + rects[static_cast<std::size_t>(g[0])].h;
                for (Index k : g) {
                    const BlobRect& r = rects[static_cast<std::size_t>(k)];
                    x0 = std::min(x0, r.x);
                    y0 = std::min(y0, r.y);
                    x1 = std::max(x1, r.x + r.w);
                    y1 = std::max(y1, r.y + r.h);
                }
                mr.push_back({x0, y0, x1 - x0, y1 - y0});
                if (g.size() > 1) {
                    const auto ix0 = static_cast<Index>(x0), iy0 = static_cast<Index>(y0);
                    const auto ix1 = static_cast<Index>(x1), iy1 = static_cast<Index>(y1);
                    const double n = double(detail::count_nonzero(mask, stride, ix0, iy0, ix1, iy1));
                    mf.push_back(n / double(std::max<Index>((ix1 - ix0) * (iy1 - iy0), 1)));
                } else {
                    mf.push_back(fill[static_cast<std::size_t>(g[0])]);
                }
            }
            rects.swap(mr);
            fill.swap(mf);
        }
        split_groups(mask, stride, rects, fill,
                     split_count(rects, *size, split_ratio, split_max_height), min_pixels,
                     split_valley);
    } else if (person_aspect > 0.0) {
        std::vector<std::int64_t> n(rects.size());
        for (std::size_t i = 0; i < rects.size(); ++i) {
            const double objects = rects[i].w * person_aspect / rects[i].h;
            n[i] = objects < 1.5 ? 1 : to_count(objects);
        }
        split_groups(mask, stride, rects, fill, n, min_pixels, split_valley);
    }
}

}  // namespace pftrack
