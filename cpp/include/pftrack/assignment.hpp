// Linear sum assignment (the rectangular assignment problem) by shortest augmenting paths:
// D. F. Crouse, "On implementing 2D rectangular assignment algorithms", IEEE TAES 52(4), 2016,
// in the same order of operations as scipy.optimize.linear_sum_assignment, so that the two break
// ties alike and a tracker gives the same identities whichever one it calls.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "pftrack/check.hpp"
#include "pftrack/types.hpp"

namespace pftrack {

namespace detail {

/// One shortest augmenting path from free row `i`; returns the sink column, or -1 when no
/// column can be reached at finite cost. `cost` is row-major nr x nc with nr <= nc.
inline Eigen::Index augmenting_path(Eigen::Index nc, const std::vector<double>& cost,
                                    std::vector<double>& u, std::vector<double>& v,
                                    std::vector<Eigen::Index>& path,
                                    const std::vector<Eigen::Index>& row4col,
                                    std::vector<double>& shortest, Eigen::Index i,
                                    std::vector<char>& SR, std::vector<char>& SC,
                                    std::vector<Eigen::Index>& remaining, double& min_val) {
    constexpr double inf = std::numeric_limits<double>::infinity();
    min_val = 0.0;
    // columns not yet in the tree, visited from the last one: the order scipy uses
    Eigen::Index num_remaining = nc;
    for (Eigen::Index it = 0; it < nc; ++it) remaining[it] = nc - it - 1;
    std::fill(SR.begin(), SR.end(), 0);
    std::fill(SC.begin(), SC.end(), 0);
    std::fill(shortest.begin(), shortest.end(), inf);
    Eigen::Index sink = -1;
    while (sink == -1) {
        Eigen::Index index = -1;
        double lowest = inf;
        SR[i] = 1;
        for (Eigen::Index it = 0; it < num_remaining; ++it) {
            const Eigen::Index j = remaining[it];
            const double r = min_val + cost[i * nc + j] - u[i] - v[j];
            if (r < shortest[j]) {
                path[j] = i;
                shortest[j] = r;
            }
            // ties go to a free column, which ends the search soonest
            if (shortest[j] < lowest || (shortest[j] == lowest && row4col[j] == -1)) {
                lowest = shortest[j];
                index = it;
            }
        }
        min_val = lowest;
        if (min_val == inf) return -1;
        const Eigen::Index j = remaining[index];
        if (row4col[j] == -1)
            sink = j;
        else
            i = row4col[j];
        SC[j] = 1;
        remaining[index] = remaining[--num_remaining];
    }
    return sink;
}

}  // namespace detail

/// Minimum-cost assignment of rows to columns of `cost` (R, C): min(R, C) pairs, each row and
/// column used at most once. Returns (rows, cols), rows ascending, as SciPy does. Entries may be
/// +inf (a forbidden pair); NaN and -inf are refused, and so is a matrix with no full assignment.
inline std::pair<Eigen::VectorXi, Eigen::VectorXi> linear_sum_assignment(
    const Eigen::Ref<const RowMatrixXd>& cost) {
    constexpr const char* fn = "linear_sum_assignment";
    const Eigen::Index R = cost.rows(), C = cost.cols();
    for (Eigen::Index i = 0; i < R; ++i)
        for (Eigen::Index j = 0; j < C; ++j) {
            const double c = cost(i, j);
            require(!std::isnan(c) && c != -std::numeric_limits<double>::infinity(), fn,
                    "cost has a NaN or -inf entry");
        }
    const bool transpose = C < R;
    const Eigen::Index nr = transpose ? C : R, nc = transpose ? R : C;
    Eigen::VectorXi rows(nr), cols(nr);
    if (nr == 0) return {rows, cols};
    std::vector<double> c(static_cast<std::size_t>(nr * nc));
    for (Eigen::Index i = 0; i < nr; ++i)
        for (Eigen::Index j = 0; j < nc; ++j) c[i * nc + j] = transpose ? cost(j, i) : cost(i, j);

    std::vector<double> u(nr, 0.0), v(nc, 0.0), shortest(nc);
    std::vector<Eigen::Index> path(nc, -1), col4row(nr, -1), row4col(nc, -1), remaining(nc);
    std::vector<char> SR(nr), SC(nc);
    for (Eigen::Index cur = 0; cur < nr; ++cur) {
        double min_val = 0.0;
        const Eigen::Index sink = detail::augmenting_path(nc, c, u, v, path, row4col, shortest,
                                                          cur, SR, SC, remaining, min_val);
        require(sink >= 0, fn, "cost matrix is infeasible (no assignment at finite cost)");
        u[cur] += min_val;
        for (Eigen::Index i = 0; i < nr; ++i)
            if (SR[i] && i != cur) u[i] += min_val - shortest[col4row[i]];
        for (Eigen::Index j = 0; j < nc; ++j)
            if (SC[j]) v[j] -= min_val - shortest[j];
        Eigen::Index j = sink;
        while (true) {
            const Eigen::Index i = path[j];
            row4col[j] = i;
            std::swap(col4row[i], j);
            if (i == cur) break;
        }
    }
    if (transpose) {
        // rows ascending in the caller's orientation: order the pairs by the column they got
        std::vector<Eigen::Index> order(nr);
        std::iota(order.begin(), order.end(), 0);
        std::sort(order.begin(), order.end(),
                  [&](Eigen::Index a, Eigen::Index b) { return col4row[a] < col4row[b]; });
        for (Eigen::Index k = 0; k < nr; ++k) {
            rows[k] = static_cast<int>(col4row[order[k]]);
            cols[k] = static_cast<int>(order[k]);
        }
    } else {
        for (Eigen::Index k = 0; k < nr; ++k) {
            rows[k] = static_cast<int>(k);
            cols[k] = static_cast<int>(col4row[k]);
        }
    }
    return {rows, cols};
}

}  // namespace pftrack
