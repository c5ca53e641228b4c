// Linear sum assignment (the rectangular assignment problem) by shortest augmenting paths:
// D. F. Crouse, "On implementing 2D rectangular assignment algorithms", IEEE TAES 52(4), 2016,
// in the same order of operations as scipy.optimize.linear_sum_assignment, so that the two break
// ties alike and a tracker gives the same identities whichever one it calls.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
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
/// column can be reached at finite cost. `row_of(i)` gives row i of the nr x nc cost matrix
/// (nr <= nc) as a pointer to its nc entries, valid until the next call: a dense matrix's row,
/// or a row made when the search reads it (padded_assignment, overlap.hpp).
template <class RowOf>
inline Eigen::Index augmenting_path(Eigen::Index nc, RowOf&& row_of, const std::vector<double>& u,
                                    const std::vector<double>& v,
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
        const double* row = row_of(i);
        for (Eigen::Index it = 0; it < num_remaining; ++it) {
            const Eigen::Index j = remaining[it];
            const double r = min_val + row[j] - u[i] - v[j];
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

/// After the search from free row `cur` reached column `sink` at `min_val`: Crouse's dual
/// update of u (the rows in the tree) and v (the columns in it), then the augmentation along
/// `path` (row4col and col4row swapped back to `cur`). With `vmax`, *vmax is raised to every
/// v it changes (padded_assignment's bound on the entries it skips).
inline void augment(Eigen::Index cur, Eigen::Index sink, double min_val, std::vector<double>& u,
                    std::vector<double>& v, const std::vector<double>& shortest,
                    const std::vector<Eigen::Index>& path, const std::vector<char>& SR,
                    const std::vector<char>& SC, std::vector<Eigen::Index>& row4col,
                    std::vector<Eigen::Index>& col4row, double* vmax = nullptr) {
    const auto nr = static_cast<Eigen::Index>(SR.size()), nc = static_cast<Eigen::Index>(SC.size());
    u[cur] += min_val;
    for (Eigen::Index i = 0; i < nr; ++i)
        if (SR[i] && i != cur) u[i] += min_val - shortest[col4row[i]];
    for (Eigen::Index j = 0; j < nc; ++j)
        if (SC[j]) {
            v[j] -= min_val - shortest[j];
            if (vmax != nullptr) *vmax = std::max(*vmax, v[j]);
        }
    Eigen::Index j = sink;
    while (true) {
        const Eigen::Index i = path[j];
        row4col[j] = i;
        std::swap(col4row[i], j);
        if (i == cur) break;
    }
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
        const Eigen::Index sink = detail::augmenting_path(
            nc, [&](Eigen::Index i) { return c.data() + i * nc; }, u, v, path, row4col,
            shortest, cur, SR, SC, remaining, min_val);
        require(sink >= 0, fn, "cost matrix is infeasible (no assignment at finite cost)");
        detail::augment(cur, sink, min_val, u, v, shortest, path, SR, SC, row4col, col4row);
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

using IndexVector = Eigen::Matrix<std::int64_t, Eigen::Dynamic, 1>;

/// The least-cost assignment of ends to starts over the given pairs only (sparse): pair k joins
/// end `r[k]` to start `c[k]` at `cost[k]`, and every end also has a start of its own at
/// `unjoined` (left unjoined), so the most joins are made, then the least cost: what a dense
/// (n_ends, n_starts) matrix with `unjoined` outside the pairs gives. Shortest augmenting
/// paths by Dijkstra on reduced costs (Crouse's dual update, as linear_sum_assignment's), over
/// the pairs a path visits: time and memory follow them, not n_ends * n_starts. The same
/// operations in the same order as pftrack.recovery.linking's NumPy reference (a heap ordered
/// by path cost, then column), so the two give the same joins, ties and all. Returns (ends,
/// starts) of the joins, ends ascending.
inline std::pair<IndexVector, IndexVector> sparse_assignment(const Eigen::Ref<const IndexVector>& r,
                                                             const Eigen::Ref<const IndexVector>& c,
                                                             const Eigen::Ref<const Eigen::VectorXd>& cost,
                                                             std::int64_t n_ends, std::int64_t n_starts,
                                                             double unjoined) {
    constexpr const char* fn = "sparse_assignment";
    constexpr double inf = std::numeric_limits<double>::infinity();
    const Eigen::Index n = r.size();
    require(c.size() == n && cost.size() == n, fn,
            "r, c and cost must have one length, got " + std::to_string(n) + ", " +
                std::to_string(c.size()) + ", " + std::to_string(cost.size()));
    // 2^24 each: a component of 16 million fragments is past any tracks file (a cap, so that
    // a wrong count is refused, not a MemoryError of gigabytes)
    constexpr std::int64_t most = std::int64_t{1} << 24;
    require(n_ends >= 0 && n_starts >= 0 && n_ends <= most && n_starts <= most, fn,
            "n_ends and n_starts must be in 0..2^24");
    require(std::isfinite(unjoined), fn, "unjoined", unjoined, "finite");
    for (Eigen::Index k = 0; k < n; ++k) {
        require(r[k] >= 0 && r[k] < n_ends, fn,
                "r[" + std::to_string(k) + "] is " + std::to_string(r[k]) + ", expected 0.." +
                    std::to_string(n_ends - 1));
        require(c[k] >= 0 && c[k] < n_starts, fn,
                "c[" + std::to_string(k) + "] is " + std::to_string(c[k]) + ", expected 0.." +
                    std::to_string(n_starts - 1));
        require(std::isfinite(cost[k]), fn, "cost[" + std::to_string(k) + "] is not finite");
    }
    const auto ne = static_cast<std::size_t>(n_ends);
    const std::size_t n_cols = static_cast<std::size_t>(n_starts) + ne;
    // each end's pairs in the order given, then its own stand-in start
    std::vector<std::size_t> first(ne + 1, 0);
    for (Eigen::Index k = 0; k < n; ++k) ++first[static_cast<std::size_t>(r[k]) + 1];
    for (std::size_t a = 0; a < ne; ++a) first[a + 1] += first[a] + 1;
    std::vector<std::int64_t> col(first[ne]);
    std::vector<double> weight(first[ne]);
    {
        std::vector<std::size_t> at(first.begin(), first.end() - 1);
        for (Eigen::Index k = 0; k < n; ++k) {
            const auto a = static_cast<std::size_t>(r[k]);
            col[at[a]] = c[k];
            weight[at[a]++] = cost[k];
        }
        for (std::size_t a = 0; a < ne; ++a) {
            col[at[a]] = n_starts + static_cast<std::int64_t>(a);
            weight[at[a]] = unjoined;
        }
    }
    std::vector<double> u(ne, 0.0), v(n_cols, 0.0), dist(n_cols, inf);
    std::vector<std::int64_t> row4col(n_cols, -1), col4row(ne, -1), pred(n_cols, -1);
    std::vector<char> done(n_cols, 0);
    std::vector<std::int64_t> done_order, touched;
    using Entry = std::pair<double, std::int64_t>;
    std::vector<Entry> heap;
    const auto later = std::greater<Entry>();
    for (std::int64_t cur = 0; cur < n_ends; ++cur) {
        heap.clear();
        std::int64_t i = cur, j = -1;
        double base = 0.0;
        while (true) {
            const auto ui = static_cast<std::size_t>(i);
            for (std::size_t e = first[ui]; e < first[ui + 1]; ++e) {
                const std::int64_t jj = col[e];
                const auto sj = static_cast<std::size_t>(jj);
                const double d = base + weight[e] - u[ui] - v[sj];
                if (!done[sj] && d < dist[sj]) {
                    if (dist[sj] == inf) touched.push_back(jj);
                    dist[sj] = d;
                    pred[sj] = i;
                    heap.emplace_back(d, jj);
                    std::push_heap(heap.begin(), heap.end(), later);
                }
            }
            while (true) {
                require(!heap.empty(), fn, "no augmenting path (internal error)");
                std::pop_heap(heap.begin(), heap.end(), later);
                const Entry top = heap.back();
                heap.pop_back();
                base = top.first;
                j = top.second;
                const auto sj = static_cast<std::size_t>(j);
                if (!done[sj] && base == dist[sj]) break;
            }
            done[static_cast<std::size_t>(j)] = 1;
            done_order.push_back(j);
            if (row4col[static_cast<std::size_t>(j)] == -1) break;  // a free start: the path ends
            i = row4col[static_cast<std::size_t>(j)];
        }
        const std::int64_t sink = j;
        for (const std::int64_t jj : done_order) {  // the dual update: reduced costs stay >= 0
            const auto sj = static_cast<std::size_t>(jj);
            if (jj != sink) u[static_cast<std::size_t>(row4col[sj])] += base - dist[sj];
            v[sj] -= base - dist[sj];
        }
        u[static_cast<std::size_t>(cur)] += base;
        j = sink;
        while (true) {  // augment along the path
            const std::int64_t ii = pred[static_cast<std::size_t>(j)];
            row4col[static_cast<std::size_t>(j)] = ii;
            std::swap(col4row[static_cast<std::size_t>(ii)], j);
            if (ii == cur) break;
        }
        for (const std::int64_t jj : touched) {
            dist[static_cast<std::size_t>(jj)] = inf;
            done[static_cast<std::size_t>(jj)] = 0;
        }
        touched.clear();
        done_order.clear();
    }
    std::vector<std::int64_t> rows;
    for (std::int64_t a = 0; a < n_ends; ++a)
        if (col4row[static_cast<std::size_t>(a)] < n_starts) rows.push_back(a);
    IndexVector ends(static_cast<Eigen::Index>(rows.size())), starts(ends.size());
    for (std::size_t k = 0; k < rows.size(); ++k) {
        ends[static_cast<Eigen::Index>(k)] = rows[k];
        starts[static_cast<Eigen::Index>(k)] = col4row[static_cast<std::size_t>(rows[k])];
    }
    return {ends, starts};
}

}  // namespace pftrack
