// The stretches of observed runs that square regions leave unobserved
// (python/pftrack/recovery/calibrate.py::_region_blocks): per square, the points in its band of
// x (as searched in the points sorted by x), those in its band of y, those within half a side on
// both axes once the distances are rounded as np.round rounds them, and the stretches of
// consecutive points of a run they make. The same tests on the same doubles as the NumPy loop it
// replaced (tests/reference/regions.py), so the same stretches bit for bit; only the way to the
// candidate points differs (a grid of cells, which holds every point of the bands).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <utility>
#include <vector>

namespace pftrack {

/// One entry per (square, stretch), squares in turn: the run, the stretch's first point in the
/// run, its number of points.
struct RegionStretches {
    std::vector<std::int64_t> run, start, length;
};

namespace detail {

/// 10^d for d = 0..22, each exact in double (NumPy's power_of_ten gives the same values).
inline constexpr double kRegionPow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                            1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                            1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/// np.round(v, d) of a float64: v * 10^d, rint (ties to even), / 10^d; d == 0 is rint alone.
inline double round_decimals(double v, int d) {
    if (d == 0) return std::nearbyint(v);
    return std::nearbyint(v * kRegionPow10[d]) / kRegionPow10[d];
}

/// The largest double v >= 0 with round_decimals(v, d) <= `limit` (>= 0, finite): a binary
/// search on the bits of v, which are ordered as the doubles >= 0 (+inf fails: its rounding is
/// +inf).
inline double last_within(double limit, int d) {
    const auto value = [](std::uint64_t b) {
        double v;
        std::memcpy(&v, &b, sizeof v);
        return v;
    };
    std::uint64_t ok = 0, bad = 0x7FF0000000000000;  // 0.0 passes, +inf fails
    while (bad - ok > 1) {
        const std::uint64_t mid = ok + (bad - ok) / 2;
        (round_decimals(value(mid), d) <= limit ? ok : bad) = mid;
    }
    return value(ok);
}

/// The bits of a double, ordered as the doubles (-0.0 as 0.0, which compare equal; not NaN).
inline std::uint64_t order_key(double v) {
    v += 0.0;  // -0.0 + 0.0 is 0.0
    std::uint64_t b;
    std::memcpy(&b, &v, sizeof b);
    return (b >> 63) ? ~b : b | (std::uint64_t(1) << 63);
}

/// `key` sorted (an LSD radix sort, four passes of 16 bits); `swap` is scratch of its size.
inline void radix_sort(std::vector<std::uint64_t>& key, std::vector<std::uint64_t>& swap) {
    const std::size_t n = key.size();
    if (n == 0) return;
    std::vector<std::size_t> count(65537);
    for (int shift = 0; shift < 64; shift += 16) {
        std::fill(count.begin(), count.end(), 0);
        for (std::size_t k = 0; k < n; ++k) ++count[((key[k] >> shift) & 0xFFFF) + 1];
        if (count[((key[0] >> shift) & 0xFFFF) + 1] == n) continue;  // one digit: no move
        for (std::size_t d = 0; d < 65536; ++d) count[d + 1] += count[d];
        for (std::size_t k = 0; k < n; ++k) swap[count[(key[k] >> shift) & 0xFFFF]++] = key[k];
        key.swap(swap);
    }
}

/// Cells of one axis: floor((v - v0) / w) clamped to 0..cells - 1, which only grows with v (so
/// the cells of the ends of a range hold every value in it); one cell when w is not finite.
struct RegionAxis {
    double v0 = 0.0, inv = 0.0;
    std::int64_t cells = 1;
    std::int64_t of(double v) const {
        const double c = (v - v0) * inv;
        if (!(c >= 1.0)) return 0;  // below the first cell's end, or NaN (one cell)
        return c < static_cast<double>(cells - 1) ? static_cast<std::int64_t>(c) : cells - 1;
    }
};

}  // namespace detail

/// `squares` squares of `side` px (> 0) centred on `centres` (squares, 2), laid over the `n`
/// points `xy` (n, 2) of runs of `sizes` (runs, summing to n), each row-major and finite: the
/// squares in turn while the points in their bands of x, summed, stay within `work` (the first
/// square always), and in each the stretches of consecutive points of a run whose distances to
/// the centre, rounded to `decimals` (0..22), are within half a side on both axes, with a point
/// of the run before and after them.
inline RegionStretches region_blocks(const double* xy, std::int64_t n, const std::int64_t* sizes,
                                     std::int64_t runs, const double* centres,
                                     std::int64_t squares, double side, std::int64_t work,
                                     int decimals) {
    RegionStretches out;
    if (n == 0 || squares == 0) return out;
    const auto un = static_cast<std::size_t>(n);
    std::vector<std::int64_t> run_of(un), pos(un);
    std::vector<char> first(un), last(un);
    for (std::int64_t r = 0, at = 0; r < runs; ++r)
        for (std::int64_t k = 0; k < sizes[r]; ++k, ++at) {
            run_of[at] = r;
            pos[at] = k;
            first[at] = k == 0;
            last[at] = k == sizes[r] - 1;
        }
    const double half = 0.5 * side;
    // 10.0**-d as Python computes it (pow, correctly rounded) is 1 / 10^d, correctly rounded.
    // 0.5 * side + eps contracted to an FMA would differ only for a subnormal side, where both
    // give eps.
    const double reach = half + 1.0 / detail::kRegionPow10[decimals];

    // round_decimals(v) <= half for v >= 0 holds for v up to `near` and beyond it never: the
    // rounding only grows with v (a product, rint and a quotient, each monotone), so one
    // comparison with the largest passing double (a binary search on the bits of doubles >= 0,
    // ordered as the doubles) is the rounded test of every distance.
    const double near = detail::last_within(half, decimals);

    // The bands of x of every square: np.searchsorted(xs, cx -+ reach, "left" / "right") on the
    // sorted x, here on their order keys (the same order, equal where the doubles are equal).
    // The squares kept: those before the first whose cumulative band passes `work`, at least one.
    std::vector<std::uint64_t> xs(un), scratch(un);
    for (std::int64_t i = 0; i < n; ++i) xs[i] = detail::order_key(xy[2 * i]);
    detail::radix_sort(xs, scratch);
    std::int64_t kept = squares, total = 0;
    for (std::int64_t k = 0; k < squares; ++k) {
        const double cx = centres[2 * k];
        const auto lo = std::lower_bound(xs.begin(), xs.end(), detail::order_key(cx - reach));
        const auto hi = std::upper_bound(xs.begin(), xs.end(), detail::order_key(cx + reach));
        total += hi - lo;
        if (total > work) {
            kept = std::max<std::int64_t>(1, k);
            break;
        }
    }

    // A grid of cells of side `reach` at least (so a square's bands cross at most four cells
    // each way), at most about 4 n cells, the points listed cell by cell.
    double x0 = xy[0], x1 = xy[0], y0 = xy[1], y1 = xy[1];
    for (std::int64_t i = 1; i < n; ++i) {
        x0 = std::min(x0, xy[2 * i]), x1 = std::max(x1, xy[2 * i]);
        y0 = std::min(y0, xy[2 * i + 1]), y1 = std::max(y1, xy[2 * i + 1]);
    }
    detail::RegionAxis ax, ay;
    const double ex = x1 - x0, ey = y1 - y0;
    if (std::isfinite(ex) && std::isfinite(ey)) {
        const double most = 4.0 * static_cast<double>(n) + 16.0;
        double w = reach;
        const auto cells = [&](double e) { return std::min(std::floor(e / w) + 1.0, most); };
        while (cells(ex) * cells(ey) > most) w *= 2.0;
        ax = {x0, 1.0 / w, static_cast<std::int64_t>(cells(ex))};
        ay = {y0, 1.0 / w, static_cast<std::int64_t>(cells(ey))};
    }
    const auto uc = static_cast<std::size_t>(ax.cells * ay.cells);
    std::vector<std::int64_t> cell_start(uc + 1, 0), cell_of(un);
    for (std::int64_t i = 0; i < n; ++i) {
        cell_of[i] = ax.of(xy[2 * i]) * ay.cells + ay.of(xy[2 * i + 1]);
        ++cell_start[cell_of[i] + 1];
    }
    for (std::size_t c = 0; c < uc; ++c) cell_start[c + 1] += cell_start[c];
    struct Point {
        double x, y;
        std::int64_t i;
    };
    std::vector<Point> grid(un);
    {
        std::vector<std::int64_t> fill(cell_start.begin(), cell_start.end() - 1);
        for (std::int64_t i = 0; i < n; ++i) grid[fill[cell_of[i]]++] = {xy[2 * i], xy[2 * i + 1], i};
    }

    std::vector<std::int64_t> inside;
    std::vector<std::pair<std::int64_t, std::int64_t>> stretches;  // first and last point
    std::vector<std::int64_t> mark(un, -1);                         // the square it is inside
    for (std::int64_t k = 0; k < kept; ++k) {
        const double cx = centres[2 * k], cy = centres[2 * k + 1];
        const double left = cx - reach, right = cx + reach;
        // |y - cy| <= reach in double holds y within reach (1 + 2^-52) of cy: the cells of the
        // band of y widened by more than that and the round-off of cy -+ reach
        const double slack = (std::fabs(cy) + reach) * 1e-14;
        const std::int64_t gx0 = ax.of(left), gx1 = ax.of(right);
        const std::int64_t gy0 = ay.of(cy - reach - slack), gy1 = ay.of(cy + reach + slack);
        inside.clear();
        for (std::int64_t gx = gx0; gx <= gx1; ++gx)
            for (std::int64_t c = gx * ay.cells + gy0, e = gx * ay.cells + gy1; c <= e; ++c)
                for (std::int64_t j = cell_start[c]; j < cell_start[c + 1]; ++j) {
                    const Point& p = grid[j];
                    // the band of x (xs >= cx - reach, xs <= cx + reach), the band of y, and
                    // the distances rounded as np.round(np.abs(xy - centre), decimals) <= half
                    // (the last two as |d| <= near: the same test)
                    const double dy = std::fabs(p.y - cy);
                    if (p.x >= left && p.x <= right && dy <= reach && dy <= near &&
                        std::fabs(p.x - cx) <= near)
                        inside.push_back(p.i);
                }
        // A stretch breaks where the next point inside is not the next point of the same run:
        // each point inside with no point inside just before it in its run starts one, which
        // runs on while the next point is inside. The stretches in order of their first point,
        // as the points inside sorted give them (sorting the few stretches, not the points).
        for (const std::int64_t i : inside) mark[i] = k;
        stretches.clear();
        for (const std::int64_t s : inside) {
            if (!first[s] && mark[s - 1] == k) continue;  // not a stretch's first point
            std::int64_t e = s;
            while (e + 1 < n && mark[e + 1] == k && !first[e + 1]) ++e;
            stretches.emplace_back(s, e);
        }
        std::sort(stretches.begin(), stretches.end());
        for (const auto& [s, e] : stretches)
            if (!first[s] && !last[e]) {  // observed on both sides
                out.run.push_back(run_of[s]);
                out.start.push_back(pos[s]);
                out.length.push_back(e - s + 1);
            }
    }
    return out;
}

}  // namespace pftrack
