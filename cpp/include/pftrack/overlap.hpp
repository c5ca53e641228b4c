// Many boxes in one frame (python/pftrack/boxes.py, tracking/association.py): the pairs of boxes
// that overlap, found by sort-and-sweep instead of a dense (n, m) IoU matrix, and the
// association's padded assignment without its dense (T + D)^2 matrix.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "pftrack/assignment.hpp"
#include "pftrack/check.hpp"
#include "pftrack/types.hpp"

namespace pftrack {

using PairIndex = Eigen::Matrix<std::int64_t, Eigen::Dynamic, 1>;

/// Every pair (i, j) of a box a[i] and a box b[j] (left, top, w, h) whose interiors meet:
/// left_a < right_b and left_b < right_a, and the same in y, with right = left + w and bottom =
/// top + h computed as NumPy computes them (pftrack.boxes._intersection). These are all the
/// pairs whose intersection area iw * ih can be > 0, so all whose IoU can be > 0; the caller
/// computes the IoU of these pairs only. Sort-and-sweep on x (Baraff 1992): boxes sorted by their
/// left edge, each tested in y against the boxes of the other set whose x-span is still open.
/// Time O((n + m) log(n + m) + tests + pairs), memory O(n + m + pairs); the tests are the pairs
/// that meet in x, e.g. every pair when all boxes share one column. Returns (i, j), int64, in
/// increasing (i, j) order.
inline std::pair<PairIndex, PairIndex> overlap_pairs(const Eigen::Ref<const RowMatrixXd>& a,
                                                     const Eigen::Ref<const RowMatrixXd>& b) {
    constexpr const char* fn = "overlap_pairs";
    require(a.cols() == 4, fn, "a cols", a.cols(), "4 (left, top, w, h)");
    require(b.cols() == 4, fn, "b cols", b.cols(), "4 (left, top, w, h)");
    require_bounded(a, 1e9, fn, "a");
    require_bounded(b, 1e9, fn, "b");
    require((a.rightCols(2).array() >= 0.0).all() && (b.rightCols(2).array() >= 0.0).all(), fn,
            "boxes must have w, h >= 0");
    struct Span {
        double x0, x1, y0, y1;
        std::int64_t index;
        int set;  // 0: a, 1: b
    };
    std::vector<Span> spans;
    spans.reserve(static_cast<std::size_t>(a.rows() + b.rows()));
    auto add = [&](const Eigen::Ref<const RowMatrixXd>& m, int set) {
        for (Index k = 0; k < m.rows(); ++k) {
            const double x0 = m(k, 0), y0 = m(k, 1);
            const double x1 = x0 + m(k, 2), y1 = y0 + m(k, 3);
            // an empty span (a zero width, or one lost to rounding at a large coordinate)
            // meets nothing: its intersection width is <= 0 with every box
            if (x1 > x0 && y1 > y0) spans.push_back({x0, x1, y0, y1, k, set});
        }
    };
    add(a, 0);
    add(b, 1);
    std::sort(spans.begin(), spans.end(), [](const Span& p, const Span& q) {
        if (p.x0 != q.x0) return p.x0 < q.x0;
        if (p.set != q.set) return p.set < q.set;
        return p.index < q.index;
    });
    std::vector<std::pair<std::int64_t, std::int64_t>> pairs;
    std::vector<const Span*> open[2];
    for (const Span& s : spans) {
        // the other set's boxes that started at or before s.x0: still open while right > s.x0
        // (their left <= s.x0 < s.x1 holds already); closed ones are dropped here
        std::vector<const Span*>& other = open[1 - s.set];
        std::size_t kept = 0;
        for (const Span* o : other) {
            if (!(o->x1 > s.x0)) continue;
            other[kept++] = o;
            if (std::max(s.y0, o->y0) < std::min(s.y1, o->y1)) {
                if (s.set == 0)
                    pairs.emplace_back(s.index, o->index);
                else
                    pairs.emplace_back(o->index, s.index);
            }
        }
        other.resize(kept);
        open[s.set].push_back(&s);
    }
    std::sort(pairs.begin(), pairs.end());
    PairIndex i(static_cast<Index>(pairs.size())), j(static_cast<Index>(pairs.size()));
    for (std::size_t k = 0; k < pairs.size(); ++k) {
        i[static_cast<Index>(k)] = pairs[k].first;
        j[static_cast<Index>(k)] = pairs[k].second;
    }
    return {i, j};
}

/// linear_sum_assignment (assignment.hpp) of the association's padded matrix
///   [[cost, tau on the diagonal, forbidden elsewhere], [tau on the diagonal, forbidden elsewhere; 0]]
/// of shape (T + D, D + T) (pftrack.tracking.association._padding), without making it: each row
/// is written into one buffer when the search scans it. The same operations in the same order
/// as linear_sum_assignment on the dense matrix, so the same pairs, ties and all, in O(T + D)
/// memory beside `cost` instead of two (T + D)^2 copies. Returns (rows, cols) int32.
inline std::pair<Eigen::VectorXi, Eigen::VectorXi> padded_assignment(
    const Eigen::Ref<const RowMatrixXd>& cost, double tau, double forbidden) {
    constexpr const char* fn = "padded_assignment";
    constexpr double inf = std::numeric_limits<double>::infinity();
    require(std::isfinite(tau) && std::isfinite(forbidden), fn,
            "tau and forbidden must be finite");
    require_finite(cost, fn, "cost");
    const Index nt = cost.rows(), nd = cost.cols(), n = nt + nd;
    Eigen::VectorXi rows(n), cols(n);
    if (n == 0) return {rows, cols};
    // two rows, each with one entry of tau that moves: a track's (its costs, then forbidden
    // but tau at nd + i) and a padding row's (forbidden but tau at i - nt, then zeros); a
    // padding row is then made in O(1), a track's in one copy of its costs
    std::vector<double> track_row(static_cast<std::size_t>(n), forbidden);
    std::vector<double> pad_row(static_cast<std::size_t>(n), forbidden);
    std::fill(pad_row.begin() + nd, pad_row.end(), 0.0);
    Index track_tau = -1, pad_tau = -1;  // where tau is now
    const double* row = nullptr;
    auto fill = [&](Index i) {
        if (i < nt) {
            for (Index j = 0; j < nd; ++j) track_row[j] = cost(i, j);
            if (track_tau >= 0) track_row[track_tau] = forbidden;
            track_tau = nd + i;
            track_row[track_tau] = tau;
            row = track_row.data();
        } else {
            if (pad_tau >= 0) pad_row[pad_tau] = forbidden;
            pad_tau = i - nt;
            pad_row[pad_tau] = tau;
            row = pad_row.data();
        }
    };
    // from here: linear_sum_assignment's state and steps (assignment.hpp), a row of the padded
    // matrix read as row[j] after fill(i)
    const Index nc = n;
    std::vector<double> u(n, 0.0), v(nc, 0.0), shortest(nc);
    std::vector<Index> path(nc, -1), col4row(n, -1), row4col(nc, -1), remaining(nc);
    std::vector<char> SR(n), SC(nc);
    // The search, skipping the entries equal to `forbidden` (most of them): each scanned row
    // updates only its other entries (a track's gated pairs and its own padding column; a
    // padding row's detection and the T padding columns), and the lowest column is sought
    // among the columns so updated, in the order of `remaining` (its position `pos`), by the
    // rule of the full scan. A skipped entry's value min_val + forbidden - u[i] - v[j] is at
    // least bound = (min_val + forbidden - u[i]) - vmax (rounding is monotone; vmax >= every
    // v[j]); while every column taken is below the least such bound, the full scan would have
    // taken the same columns with the same values and paths (a skipped entry is never the
    // lowest nor tied with it), so the result is the same. Otherwise that search is made again
    // by the full scan: the sparse one changed nothing that outlives a search.
    std::vector<Index> first(static_cast<std::size_t>(nt) + 1, 0), gated;
    std::vector<double> gated_cost;
    for (Index i = 0; i < nt; ++i) {
        for (Index j = 0; j < nd; ++j)
            if (cost(i, j) != forbidden) {
                gated.push_back(j);
                gated_cost.push_back(cost(i, j));
            }
        gated.push_back(nd + i);
        gated_cost.push_back(tau);
        first[static_cast<std::size_t>(i) + 1] = static_cast<Index>(gated.size());
    }
    std::vector<Index> pos(nc), touched;
    std::vector<char> is_touched(nc, 0);
    double vmax = 0.0;  // >= every v[j] (v starts at 0)
    double min_val = 0.0;
    Index sink = -1;
    auto start = [&](Index& num_remaining) {
        num_remaining = nc;
        for (Index it = 0; it < nc; ++it) {
            remaining[it] = nc - it - 1;
            pos[nc - it - 1] = it;
        }
        std::fill(SR.begin(), SR.end(), 0);
        std::fill(SC.begin(), SC.end(), 0);
        std::fill(shortest.begin(), shortest.end(), inf);
        min_val = 0.0;
        sink = -1;
    };
    auto full_search = [&](Index cur) {
        // assignment.hpp's search itself, each row made as it reads it
        sink = detail::augmenting_path(
            nc, [&](Index i) { fill(i); return row; }, u, v, path, row4col, shortest, cur, SR,
            SC, remaining, min_val);
        require(sink >= 0, fn, "cost matrix is infeasible (no assignment at finite cost)");
    };
    auto sparse_search = [&](Index cur) -> bool {
        Index i = cur, num_remaining = 0;
        start(num_remaining);
        for (Index j : touched) is_touched[j] = 0;
        touched.clear();
        double bound = inf, top = -inf;
        auto update = [&](Index j, double c) {
            if (SC[j]) return;  // no longer in `remaining`
            const double r = min_val + c - u[i] - v[j];
            if (r < shortest[j]) {
                path[j] = i;
                shortest[j] = r;
            }
            if (!is_touched[j]) {
                is_touched[j] = 1;
                touched.push_back(j);
            }
        };
        while (sink == -1) {
            SR[i] = 1;
            bound = std::min(bound, min_val + forbidden - u[i] - vmax);
            if (i < nt) {
                for (Index k = first[i]; k < first[i + 1]; ++k) update(gated[k], gated_cost[k]);
            } else {
                update(i - nt, tau);
                for (Index j = nd; j < nc; ++j) update(j, 0.0);
            }
            // the lowest value; among its columns the last free one in `remaining`, else the
            // first one (the full scan's rule)
            double lowest = inf;
            Index at = -1, free_at = -1, t_at = -1;
            for (std::size_t t = 0; t < touched.size(); ++t) {
                const Index j = touched[t];
                const double s_j = shortest[j];
                if (s_j < lowest) {
                    lowest = s_j;
                    at = pos[j];
                    free_at = row4col[j] == -1 ? pos[j] : -1;
                } else if (s_j == lowest) {
                    at = std::min(at, pos[j]);
                    if (row4col[j] == -1) free_at = std::max(free_at, pos[j]);
                }
            }
            if (at < 0) return false;  // nothing but skipped entries
            const Index index = free_at >= 0 ? free_at : at;
            min_val = lowest;
            top = std::max(top, lowest);
            if (!(top < bound)) return false;  // a skipped entry might be the lowest
            const Index j = remaining[index];
            for (t_at = 0; touched[static_cast<std::size_t>(t_at)] != j; ++t_at) {
            }
            touched[static_cast<std::size_t>(t_at)] = touched.back();
            touched.pop_back();
            is_touched[j] = 0;
            if (row4col[j] == -1)
                sink = j;
            else
                i = row4col[j];
            SC[j] = 1;
            const Index moved = remaining[--num_remaining];
            remaining[index] = moved;
            pos[moved] = index;
        }
        return true;
    };
    for (Index cur = 0; cur < n; ++cur) {
        if (!sparse_search(cur)) full_search(cur);
        detail::augment(cur, sink, min_val, u, v, shortest, path, SR, SC, row4col, col4row,
                        &vmax);
    }
    for (Index k = 0; k < n; ++k) {
        rows[k] = static_cast<int>(k);
        cols[k] = static_cast<int>(col4row[k]);
    }
    return {rows, cols};
}

}  // namespace pftrack
