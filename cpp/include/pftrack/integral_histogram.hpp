// Uniform-kernel box counts for many overlapping boxes (the particles of one object) from one
// integral histogram per group of boxes: T[y][x][k] = pixels of bin k above row y and left of
// column x in the group's region, so a box's counts are four table rows, T[y1][x1] - T[y0][x1]
// - T[y1][x0] + T[y0][x0], whatever its size (Porikli 2005). Counts are exact integers, equal to
// the direct count, so the coefficients built from them are bit-identical. Only the rows and
// columns the group's boxes start or end at are built (stop 70): no box reads any other.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "histogram.hpp"

namespace pftrack {

/// How box_coefficients counts uniform-kernel boxes: per group by a cost model, always pixel by
/// pixel, or from an integral histogram wherever one is allowed (tests force each path).
enum class BoxPath { kAuto = 0, kDirect = 1, kIntegral = 2 };

inline Index pixel_count(const PixelRange& r) { return r.empty() ? 0 : (r.x1 - r.x0) * (r.y1 - r.y0); }

inline PixelRange bounding_union(const PixelRange& a, const PixelRange& b) {
    return {std::min(a.x0, b.x0), std::max(a.x1, b.x1), std::min(a.y0, b.y0), std::max(a.y1, b.y1)};
}

/// Integral histogram of one rectangular region of a bin image, over the bins present in the
/// region only (numbered compactly: fewer table entries to build and to read per box), at the
/// corners of the boxes it is built for only.
/// Entries are uint16 and wrap around; differences of four of them are still exact for any box
/// of fewer than 65536 pixels (its counts are < 2^16), however large the region.
class IntegralHistogram {
public:
    static constexpr int kLanes = 8;  // uint16 lanes of a 128-bit vector
    /// Largest box (pixels) whose counts are exact in uint16.
    static constexpr Index kMaxBoxPixels = 65535;
    /// Table entries a grown buffer rounds up to at most (for_each_range_count's cap).
    static constexpr size_t kMaxTableEntries = size_t(1) << 22;

    explicit IntegralHistogram(int n_bins)
        : n_bins_(n_bins), local_of_(static_cast<size_t>(n_bins) + 1),
          seen_(static_cast<size_t>(n_bins) + 1) {}

    int n_bins() const { return n_bins_; }
    /// The bins (>= 0) present in the prepared region, split by partial_sum_of.
    BinLanes present() const {
        BinLanes l;
        for (int q = 0; q < 4; ++q) {
            l.bins[q] = lanes_.data() + lane_start_[q];
            l.local[q] = lanes_local_.data() + lane_start_[q];
            l.n[q] = lane_start_[q + 1] - lane_start_[q];
        }
        l.counts = local_.data();  // box_counts' compact counts (after build)
        l.bin_of_local = bin_of_local_.data();
        l.n_local = n_local_;
        return l;
    }

    /// Numbers the bins present in `region` (background, bin -1, included when present).
    /// Returns the table's entries per pixel: a multiple of kLanes. A lazy image bins the
    /// region here, for build() too (which reads the prepared region only). Call build() next.
    int prepare(const BinImage& img, const PixelRange& region) {
        img.ensure(region.x0, region.x1, region.y0, region.y1);
        region_ = region;
        std::fill(seen_.begin(), seen_.end(), std::uint8_t(0));
        std::uint8_t* seen = seen_.data() + 1;  // seen[-1]: background
        for (Index y = region.y0; y < region.y1; ++y) {
            const std::int16_t* b = img.row(y);
            for (Index x = region.x0; x < region.x1; ++x) seen[b[x]] = 1;
        }
        bin_of_local_.clear();
        for (int b = -1; b < n_bins_; ++b) {
            local_of_[static_cast<size_t>(b + 1)] = static_cast<std::int16_t>(bin_of_local_.size());
            if (seen[b]) bin_of_local_.push_back(b);
        }
        n_local_ = static_cast<int>(bin_of_local_.size());
        lanes_.resize(bin_of_local_.size());  // present(): bins >= 0 by partial sum, in order
        lanes_local_.resize(bin_of_local_.size());  // ... and their compact indices
        int at = 0;
        for (int q = 0; q < 4; ++q) {
            lane_start_[q] = at;
            for (int l = 0; l < n_local_; ++l) {
                const std::int16_t b = bin_of_local_[static_cast<size_t>(l)];
                if (b >= 0 && partial_sum_of(b, n_bins_) == q) {
                    lanes_[static_cast<size_t>(at)] = b;
                    lanes_local_[static_cast<size_t>(at++)] = static_cast<std::int16_t>(l);
                }
            }
        }
        lane_start_[4] = at;
        stride_ = (n_local_ + kLanes - 1) / kLanes * kLanes;
        return stride_;
    }

    /// Fills the table of the prepared region at the corners of the boxes `ranges[*m]`, m in
    /// [m0, m1) (each inside the region) only: T[y][x] for the rows y and columns x some box
    /// starts or ends at, numbered in order (row_of_, col_of_). Counts are kept from the first
    /// corner row and column on: the pixels above or left of them are in all four of a box's
    /// entries or in none, so every box's counts are the full table's. Each pixel adds 1 to its
    /// column band's running count (between two corner columns), and only the corner rows'
    /// entries are summed and written: the full table wrote (w + 1) x stride entries a row.
    void build(const BinImage& img, const std::vector<PixelRange>& ranges, const Index* m0,
               const Index* m1) {
        const Index w = region_.x1 - region_.x0, h = region_.y1 - region_.y0;
        corners(ranges, m0, m1, w, h);
        const Index nx = static_cast<Index>(xs_.size()), ny = static_cast<Index>(ys_.size());
        const int s = stride_;
        row_len_ = nx * s;
        reserve_table(static_cast<size_t>(ny * row_len_));
        local_.resize(static_cast<size_t>(s));
        bands_.resize(static_cast<size_t>(row_len_));
        std::uint16_t* t = table_.get();
        std::fill(t, t + row_len_, std::uint16_t(0));
        if (nx == 0) return;
        // band_of[x]: where pixel column x0 + x counts, band j (columns xs[j-1] .. xs[j]) at j s
        // (Index: the sum with a bin's compact index needs no widening a pixel)
        band_of_.resize(static_cast<size_t>(xs_.back() - xs_.front()));
        for (Index j = 1; j < nx; ++j)
            for (Index x = xs_[static_cast<size_t>(j - 1)]; x < xs_[static_cast<size_t>(j)]; ++x)
                band_of_[static_cast<size_t>(x - xs_.front())] = j * s;
        const std::int16_t* local_of = local_of_.data() + 1;
        const Index* band_of = band_of_.data();
        const Index cx0 = region_.x0 + xs_.front(), cw = xs_.back() - xs_.front();
        std::uint16_t* band = bands_.data();
        std::fill(band, band + row_len_, std::uint16_t(0));  // sum_bands zeroes what it read
        for (Index i = 1; i < ny; ++i) {
            for (Index y = ys_[static_cast<size_t>(i - 1)]; y < ys_[static_cast<size_t>(i)]; ++y) {
                const std::int16_t* b = img.row(region_.y0 + y) + cx0;
                Index x = 0;
                for (; x + 4 <= cw; x += 4) {  // four a turn: the loop's own count and jump
                    const Index l0 = band_of[x] + local_of[b[x]];
                    const Index l1 = band_of[x + 1] + local_of[b[x + 1]];
                    const Index l2 = band_of[x + 2] + local_of[b[x + 2]];
                    const Index l3 = band_of[x + 3] + local_of[b[x + 3]];
                    ++band[l0];  // mod 2^16, as every entry
                    ++band[l1];
                    ++band[l2];
                    ++band[l3];
                }
                for (; x < cw; ++x) ++band[band_of[x] + local_of[b[x]]];
            }
            // T[i][j] = T[i-1][j] + the bands 1 .. j of the rows between the two corner rows
            sum_bands(t + (i - 1) * row_len_, t + i * row_len_, nx);
        }
    }

    /// Counts of the box `r` (one of those build() was given, at most kMaxBoxPixels pixels) written to c[bin]
    /// for each bin present in the region, c[-1] for background; other entries are left alone.
    void box_counts(const PixelRange& r, std::int32_t* c) {
        box_counts_compact(r);
        const std::uint16_t* out = local_.data();
        const std::int16_t* bin = bin_of_local_.data();
        for (int k = 0; k < n_local_; ++k) c[bin[k]] = out[k];
    }

    /// Counts of the box `r` (as box_counts) in compact form only, into present().counts;
    /// returns its background pixels (bin -1).
    std::int64_t box_counts_compact(const PixelRange& r) {
        // frame column and row -> table column and row (corners of the boxes built for)
        const Index x0 = col_of_[static_cast<size_t>(r.x0 - region_.x0)];
        const Index x1 = col_of_[static_cast<size_t>(r.x1 - region_.x0)];
        const Index y0 = row_of_[static_cast<size_t>(r.y0 - region_.y0)];
        const Index y1 = row_of_[static_cast<size_t>(r.y1 - region_.y0)];
        const std::uint16_t* t = table_.get();
        const std::uint16_t* a = t + y0 * row_len_ + x0 * stride_;
        const std::uint16_t* b = t + y0 * row_len_ + x1 * stride_;
        const std::uint16_t* d = t + y1 * row_len_ + x0 * stride_;
        const std::uint16_t* e = t + y1 * row_len_ + x1 * stride_;
        std::uint16_t* out = local_.data();
#if defined(__SSE2__)
        for (int k = 0; k < stride_; k += kLanes) {
            const __m128i v = _mm_add_epi16(
                _mm_sub_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(e + k)),
                              _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + k))),
                _mm_sub_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(a + k)),
                              _mm_loadu_si128(reinterpret_cast<const __m128i*>(d + k))));
            _mm_storeu_si128(reinterpret_cast<__m128i*>(out + k), v);
        }
#else
        for (int k = 0; k < stride_; ++k)
            out[k] = static_cast<std::uint16_t>(e[k] - b[k] - d[k] + a[k]);  // mod 2^16: exact
#endif
        return n_local_ > 0 && bin_of_local_[0] < 0 ? out[0] : 0;  // background: compact 0
    }

private:
    /// Room for `entries` table entries, left as they are: build() writes every entry it
    /// reads (a std::vector's resize zeroed each growth, and copied the old table over, for
    /// each object's region on every frame).
    void reserve_table(size_t entries) {
        if (entries <= table_capacity_) return;
        table_capacity_ = std::max(entries, std::min(2 * table_capacity_, kMaxTableEntries));
        table_.reset(new std::uint16_t[table_capacity_]);  // default-initialised: not zeroed
    }

    /// One corner row of the table: cur[j] = above[j] + (bands_ 1 .. j summed), cur[0] = 0;
    /// bands_ is left zero for the next corner row (in the same pass: a memset call a corner
    /// row cost more than the stores).
    void sum_bands(const std::uint16_t* above, std::uint16_t* cur, Index nx) {
        const int s = stride_;
#if defined(__SSE2__)
        switch (s / kLanes) {  // the running sum in registers: up to 16 vectors
            case 1: return sum_bands_in<1>(above, cur, nx);
            case 2: return sum_bands_in<2>(above, cur, nx);
            case 3: return sum_bands_in<3>(above, cur, nx);
            case 4: return sum_bands_in<4>(above, cur, nx);
            case 5: return sum_bands_in<5>(above, cur, nx);
            case 6: return sum_bands_in<6>(above, cur, nx);
            case 7: return sum_bands_in<7>(above, cur, nx);
            case 8: return sum_bands_in<8>(above, cur, nx);
            case 9: return sum_bands_in<9>(above, cur, nx);
            case 10: return sum_bands_in<10>(above, cur, nx);
            case 11: return sum_bands_in<11>(above, cur, nx);
            case 12: return sum_bands_in<12>(above, cur, nx);
            case 13: return sum_bands_in<13>(above, cur, nx);
            case 14: return sum_bands_in<14>(above, cur, nx);
            case 15: return sum_bands_in<15>(above, cur, nx);
            case 16: return sum_bands_in<16>(above, cur, nx);
            default: break;
        }
#endif
        std::fill(cur, cur + s, std::uint16_t(0));
        std::uint16_t* run = local_.data();
        std::fill(run, run + s, std::uint16_t(0));
        std::uint16_t* band = bands_.data();
        for (Index o = s; o < nx * s; o += s)
            for (int k = 0; k < s; ++k) {
                run[k] = static_cast<std::uint16_t>(run[k] + band[o + k]);
                band[o + k] = 0;
                cur[o + k] = static_cast<std::uint16_t>(above[o + k] + run[k]);
            }
    }

#if defined(__SSE2__)
    template <int V>
    void sum_bands_in(const std::uint16_t* above, std::uint16_t* cur, Index nx) {
        const __m128i zero = _mm_setzero_si128();
        __m128i run[V];
        for (int j = 0; j < V; ++j) {
            run[j] = zero;
            _mm_storeu_si128(reinterpret_cast<__m128i*>(cur + j * kLanes), zero);
        }
        std::uint16_t* band = bands_.data();
        for (Index o = V * kLanes; o < nx * V * kLanes; o += V * kLanes)
            for (int j = 0; j < V; ++j) {
                const Index k = o + j * kLanes;
                auto* bk = reinterpret_cast<__m128i*>(band + k);
                run[j] = _mm_add_epi16(run[j], _mm_loadu_si128(bk));
                _mm_storeu_si128(bk, zero);
                _mm_storeu_si128(reinterpret_cast<__m128i*>(cur + k),
                                 _mm_add_epi16(run[j], _mm_loadu_si128(reinterpret_cast<const __m128i*>(above + k))));
            }
    }
#endif

    /// xs_, ys_: the sorted distinct columns and rows (region-relative) the boxes start or end
    /// at; col_of_, row_of_: a corner's table column and row (other entries are not read).
    void corners(const std::vector<PixelRange>& ranges, const Index* m0, const Index* m1, Index w,
                 Index h) {
        col_of_.assign(static_cast<size_t>(w + 1), -1);
        row_of_.assign(static_cast<size_t>(h + 1), -1);
        for (const Index* m = m0; m != m1; ++m) {
            const PixelRange& r = ranges[static_cast<size_t>(*m)];
            col_of_[static_cast<size_t>(r.x0 - region_.x0)] = 0;
            col_of_[static_cast<size_t>(r.x1 - region_.x0)] = 0;
            row_of_[static_cast<size_t>(r.y0 - region_.y0)] = 0;
            row_of_[static_cast<size_t>(r.y1 - region_.y0)] = 0;
        }
        number(col_of_, xs_);
        number(row_of_, ys_);
    }

    /// Numbers the marked (0) entries of `of` in order, and lists them in `at`.
    static void number(std::vector<Index>& of, std::vector<Index>& at) {
        at.clear();
        for (size_t v = 0; v < of.size(); ++v)
            if (of[v] == 0) {
                of[v] = static_cast<Index>(at.size());
                at.push_back(static_cast<Index>(v));
            }
    }

    int n_bins_;
    int n_local_ = 0;
    int lane_start_[5] = {0, 0, 0, 0, 0};  // lanes_[lane_start_[q] ..): partial sum q's bins
    int stride_ = 0;
    Index row_len_ = 0;
    PixelRange region_{0, 0, 0, 0};
    std::vector<std::int16_t> local_of_;     // bin + 1 -> compact index (for bins present)
    std::vector<std::uint8_t> seen_;         // bin + 1 -> present in the region
    std::vector<std::int16_t> bin_of_local_;  // compact index -> bin (-1: background)
    std::vector<std::int16_t> lanes_;        // the bins >= 0 present, by partial sum (present())
    std::vector<std::int16_t> lanes_local_;  // their compact indices
    std::unique_ptr<std::uint16_t[]> table_;  // corner rows x corner columns x stride_ (of a larger buffer)
    std::vector<Index> xs_, ys_;             // the corner columns and rows (region-relative)
    std::vector<Index> col_of_, row_of_;     // region column / row -> table column / row
    std::vector<Index> band_of_;             // column (from xs_[0]) -> its band's first entry
    std::vector<std::uint16_t> bands_;       // one corner row band's counts, by column band
    size_t table_capacity_ = 0;
    std::vector<std::uint16_t> local_;       // one box's (or one row's running) compact counts
};

// The compact coefficients (for_each_range_count<true>) look every square root up: no box
// counted from a table reaches the table's end.
static_assert(IntegralHistogram::kMaxBoxPixels < HistogramScratch::kSqrtTableMax,
              "coefficient_of_compact needs every table-counted box under kSqrtTableMax pixels");

/// Cost model of one group, in ns on the development machine (a least-squares fit over boxes of
/// 4x4 to 60x150 pixels, 1 to 256 boxes, PETS and noise frames; docs/kernels.md). Both include
/// the coefficient. direct: per box pixel and per box; integral: per region pixel (scan, table
/// build) and per region pixel and vector of 8 bins, per box and per box and vector of bins.
struct BoxCostModel {
    double direct_pixel = 0.31, direct_box = 76.0;
    double region_pixel = 1.74, region_vector = 0.54;
    double box_fixed = 61.0, box_vector = 3.5;

    double direct(Index box_pixels, Index n_boxes) const {
        return direct_pixel * static_cast<double>(box_pixels) + direct_box * static_cast<double>(n_boxes);
    }
    double integral(Index region_pixels, Index n_boxes, int vectors) const {
        const double a = static_cast<double>(region_pixels), v = static_cast<double>(vectors);
        return a * (region_pixel + region_vector * v) +
               static_cast<double>(n_boxes) * (box_fixed + box_vector * v);
    }
};

/// Uniform-kernel counts of K boxes (rows (cx, cy, w, h)), reusing work across overlapping
/// boxes. Boxes are grouped greedily in the given order (up to kOpenGroups groups stay open, so
/// interleaved objects still group): a box joins the most recently joined open group whose
/// clipped union grows by at most twice the box's area (two particles of one object offset by
/// half a box still join; two objects a box apart do not). Each group is then counted directly or
/// from an integral histogram of its union, whichever the cost model finds cheaper.
/// Calls `from_counts(i, c, total, present)` with box i's counts c[0 .. n_bins) (c[-1]:
/// background; 0 but for the bins `present`, BinLanes) and counted pixels for boxes
/// counted from a table, and `direct(i, r)` with the clipped pixel
/// range of every other box (empty ones included). With kCompact, `from_counts(i, total,
/// present, first)` instead, the counts in compact form only (present.counts; `first` for the
/// first box of each table, whose bins present then change). Scratch is local to the call, but for the
/// table: `shared_table`, the caller's to reuse (for img.n_bins bins), else a local one.
/// for_each_box_count of boxes given as clipped pixel ranges of `img` (as box_pixels gives).
template <bool kCompact = false, class FromCounts, class Direct>
inline void for_each_range_count(const BinImage& img, const std::vector<PixelRange>& ranges,
                                 BoxPath path, FromCounts&& from_counts, Direct&& direct,
                                 IntegralHistogram* shared_table = nullptr) {
    const Index n = static_cast<Index>(ranges.size());
    if (path == BoxPath::kDirect) {
        for (Index i = 0; i < n; ++i) direct(i, ranges[static_cast<size_t>(i)]);
        return;
    }
    // Table size cap (uint16 entries: 8 MB); regions of more pixels than the cap allows at the
    // worst case (every bin present) are not grown.
    constexpr Index kMaxTableEntries = Index(1) << 22;
    constexpr size_t kOpenGroups = 8;
    constexpr Index kMinGroupedPixels = 64;
    const Index max_vectors = (img.n_bins + 1 + IntegralHistogram::kLanes - 1) / IntegralHistogram::kLanes;
    const Index max_region = std::max<Index>(4096, kMaxTableEntries / (max_vectors * IntegralHistogram::kLanes));

    struct Group {
        PixelRange u;
        Index box_pixels, n_boxes;
    };
    std::vector<Group> groups;
    std::vector<size_t> open;  // indices into groups, most recently joined first
    std::vector<std::int32_t> group_of(static_cast<size_t>(n), -1);
    for (Index i = 0; i < n; ++i) {
        const PixelRange r = ranges[static_cast<size_t>(i)];
        const Index a = pixel_count(r);
        // Direct: empty boxes, boxes whose uint16 counts could wrap, and (unless forced) boxes so
        // small that a table lookup saves less than the grouping costs.
        if (a == 0 || a > IntegralHistogram::kMaxBoxPixels ||
            (path == BoxPath::kAuto && a < kMinGroupedPixels)) {
            direct(i, r);
            continue;
        }
        size_t slot = open.size();
        for (size_t j = 0; j < open.size(); ++j) {
            const Group& g = groups[open[j]];
            const Index ua = pixel_count(bounding_union(g.u, r));
            if (ua <= pixel_count(g.u) + 2 * a && ua <= max_region) {
                slot = j;
                break;
            }
        }
        size_t gi;
        if (slot == open.size()) {
            gi = groups.size();
            groups.push_back({r, a, 1});
            open.insert(open.begin(), gi);
            if (open.size() > kOpenGroups) open.pop_back();
        } else {
            gi = open[slot];
            Group& g = groups[gi];
            g.u = bounding_union(g.u, r);
            g.box_pixels += a;
            ++g.n_boxes;
            std::rotate(open.begin(), open.begin() + static_cast<std::ptrdiff_t>(slot),
                        open.begin() + static_cast<std::ptrdiff_t>(slot) + 1);
        }
        group_of[static_cast<size_t>(i)] = static_cast<std::int32_t>(gi);
    }
    if (groups.empty()) return;

    // Members of each group, in box order (counting sort).
    std::vector<Index> start(groups.size() + 1, 0), members(static_cast<size_t>(n));
    for (Index i = 0; i < n; ++i)
        if (group_of[static_cast<size_t>(i)] >= 0) ++start[static_cast<size_t>(group_of[static_cast<size_t>(i)]) + 1];
    for (size_t g = 0; g < groups.size(); ++g) start[g + 1] += start[g];
    {
        std::vector<Index> fill(start.begin(), start.end() - 1);
        for (Index i = 0; i < n; ++i) {
            const std::int32_t g = group_of[static_cast<size_t>(i)];
            if (g >= 0) members[static_cast<size_t>(fill[static_cast<size_t>(g)]++)] = i;
        }
    }

    const BoxCostModel cost;
    // a table kept by the caller keeps its memory: a new one per object and frame allocated,
    // and zeroed, up to megabytes before build() wrote over them
    std::optional<IntegralHistogram> own_table;
    if (shared_table == nullptr || shared_table->n_bins() != img.n_bins) own_table.emplace(img.n_bins);
    IntegralHistogram& table = own_table ? *own_table : *shared_table;
    std::vector<std::int32_t> counts(static_cast<size_t>(img.n_bins) + 1);
    std::int32_t* c = counts.data() + 1;  // c[-1]: background
    BinLanes present{};
    for (size_t g = 0; g < groups.size(); ++g) {
        const Group& grp = groups[g];
        const Index* m0 = members.data() + start[g];
        const Index* m1 = members.data() + start[g + 1];
        const Index region = pixel_count(grp.u);
        const double direct_cost = cost.direct(grp.box_pixels, grp.n_boxes);
        bool integral = path == BoxPath::kIntegral ||
                        cost.integral(region, grp.n_boxes, 1) < direct_cost;  // best case first
        if (integral) {
            const int stride = table.prepare(img, grp.u);
            integral = region * stride <= kMaxTableEntries &&
                       (path == BoxPath::kIntegral ||
                        cost.integral(region, grp.n_boxes, stride / IntegralHistogram::kLanes) < direct_cost);
        }
        if (!integral) {
            for (const Index* m = m0; m != m1; ++m) direct(*m, ranges[static_cast<size_t>(*m)]);
            continue;
        }
        table.build(img, ranges, m0, m1);
        present = table.present();
        if constexpr (kCompact) {
            // no copy over every bin: from_counts(i, total, present, first box of the region)
            for (const Index* m = m0; m != m1; ++m) {
                const PixelRange& r = ranges[static_cast<size_t>(*m)];
                const std::int64_t background = table.box_counts_compact(r);
                from_counts(*m, pixel_count(r) - background, present, m == m0);
            }
        } else {
            std::fill(counts.begin(), counts.end(), 0);  // bins absent from the region stay 0
            for (const Index* m = m0; m != m1; ++m) {
                const PixelRange& r = ranges[static_cast<size_t>(*m)];
                table.box_counts(r, c);
                from_counts(*m, static_cast<const std::int32_t*>(c), pixel_count(r) - c[-1],
                            present);
            }
        }
    }
}

/// Uniform-kernel counts of K boxes (rows (cx, cy, w, h)): for_each_range_count of their
/// clipped pixel ranges.
template <bool kCompact = false, class Derived, class FromCounts, class Direct>
inline void for_each_box_count(const BinImage& img, const Eigen::MatrixBase<Derived>& boxes,
                               BoxPath path, FromCounts&& from_counts, Direct&& direct,
                               IntegralHistogram* shared_table = nullptr) {
    std::vector<PixelRange> ranges(static_cast<size_t>(boxes.rows()));
    for (Index i = 0; i < boxes.rows(); ++i)
        ranges[static_cast<size_t>(i)] =
            box_pixels(boxes(i, 0), boxes(i, 1), boxes(i, 2), boxes(i, 3), img.rows, img.cols);
    for_each_range_count<kCompact>(img, ranges, path, std::forward<FromCounts>(from_counts),
                         std::forward<Direct>(direct), shared_table);
}

/// The points of the lattice of step `step` (the pixels whose column and row are multiples of
/// it) under a set of boxes, gathered into an image of their own: point (i, j) of the image is
/// the pixel ((x0 + i) step, (y0 + j) step) of the frame, (x0, y0) the first point of the
/// boxes' union. Boxes become ranges of points (lattice_points, shifted), so every counting
/// path (direct, or an integral histogram of a group) works on the lattice unchanged.
class LatticeImage {
public:
    /// Gathers the points under the rows of `boxes` (cx, cy, w, h) of `img`; `ranges` gets each
    /// box's points in this image's pixels (empty for a box without a point).
    template <class Derived>
    LatticeImage(const BinImage& img, const Eigen::MatrixBase<Derived>& boxes, Index step,
                 std::vector<PixelRange>& ranges)
        : step_(step) {
        ranges.resize(static_cast<size_t>(boxes.rows()));
        PixelRange u{0, 0, 0, 0};
        bool any = false;
        for (Index i = 0; i < boxes.rows(); ++i) {
            const PixelRange p = lattice_points(
                box_pixels(boxes(i, 0), boxes(i, 1), boxes(i, 2), boxes(i, 3), img.rows, img.cols), step);
            ranges[static_cast<size_t>(i)] = p;
            if (p.empty()) continue;
            u = any ? bounding_union(u, p) : p;
            any = true;
        }
        x0_ = u.x0;
        y0_ = u.y0;
        const Index cols = u.x1 - u.x0, rows = u.y1 - u.y0;
        view_ = BinImage{nullptr, rows, cols, cols, img.n_bins, nullptr};
        if (!any) return;
        img.ensure(u.x0 * step, (u.x1 - 1) * step + 1, u.y0 * step, (u.y1 - 1) * step + 1);
        bins_.resize(static_cast<size_t>(rows * cols));
        for (Index j = 0; j < rows; ++j) {
            const std::int16_t* src = img.row((u.y0 + j) * step) + u.x0 * step;
            std::int16_t* dst = bins_.data() + j * cols;
            for (Index i = 0; i < cols; ++i) dst[i] = src[i * step];
        }
        view_.data = bins_.data();
        for (PixelRange& p : ranges)
            p = p.empty() ? PixelRange{0, 0, 0, 0}
                          : PixelRange{p.x0 - u.x0, p.x1 - u.x0, p.y0 - u.y0, p.y1 - u.y0};
    }

    const BinImage& view() const { return view_; }
    /// A frame coordinate in this image's pixels (the point of lattice column/row `v` / step).
    double x(double frame_x) const { return frame_x / static_cast<double>(step_) - static_cast<double>(x0_); }
    double y(double frame_y) const { return frame_y / static_cast<double>(step_) - static_cast<double>(y0_); }

private:
    Index step_;
    Index x0_ = 0, y0_ = 0;
    std::vector<std::int16_t> bins_;
    BinImage view_;
};

/// Coefficients rho (K,) and counted pixels (K,) of K boxes (rows (cx, cy, w, h)) against
/// `sqrt_ref`. Uniform kernel: for_each_box_count (bit-identical to counting each box);
/// Epanechnikov: each box directly. With `step` > 1 only the points of the lattice of that step
/// are counted (LatticeImage; `counted` is then the points counted times step^2).
/// `shared`: scratch space of the caller's to reuse (for img.n_bins bins), else a local one;
/// `shared_table` likewise for the integral histograms (for_each_range_count).
template <class Derived>
inline void box_coefficients(const BinImage& img, const Eigen::MatrixBase<Derived>& boxes,
                             const double* sqrt_ref, Kernel kernel, BoxPath path, double* rho,
                             double* counted, Index step = 1, HistogramScratch* shared = nullptr,
                             IntegralHistogram* shared_table = nullptr) {
    std::optional<HistogramScratch> own;
    if (shared == nullptr) own.emplace(img.n_bins);
    HistogramScratch& scratch = shared != nullptr ? *shared : *own;
    if (step > 1) {
        std::vector<PixelRange> ranges;
        const LatticeImage lattice(img, boxes, step, ranges);
        const BinImage& points = lattice.view();
        const double area = static_cast<double>(step * step);
        if (kernel != Kernel::kUniform) {
            for (Index i = 0; i < boxes.rows(); ++i) {
                rho[i] = scratch.epanechnikov_coefficient(
                    points, ranges[static_cast<size_t>(i)], lattice.x(boxes(i, 0)),
                    lattice.y(boxes(i, 1)), boxes(i, 2) / static_cast<double>(step),
                    boxes(i, 3) / static_cast<double>(step), sqrt_ref, counted[i]);
                counted[i] *= area;
            }
            return;
        }
        for_each_range_count<true>(
            points, ranges, path,
            [&](Index i, std::int64_t total, const BinLanes& present, bool first) {
                if (first) scratch.gather_reference(sqrt_ref, present);
                counted[i] = static_cast<double>(total) * area;
                rho[i] = scratch.coefficient_of_compact(total, present);
            },
            [&](Index i, const PixelRange& r) {
                rho[i] = scratch.coefficient_of_range(points, r, sqrt_ref, counted[i]);
                counted[i] *= area;
            },
            shared_table);
        return;
    }
    if (kernel != Kernel::kUniform) {
        for (Index i = 0; i < boxes.rows(); ++i)
            rho[i] = scratch.coefficient(img, boxes(i, 0), boxes(i, 1), boxes(i, 2), boxes(i, 3),
                                         kernel, sqrt_ref, counted[i]);
        return;
    }
    for_each_box_count<true>(
        img, boxes, path,
        [&](Index i, std::int64_t total, const BinLanes& present, bool first) {
            if (first) scratch.gather_reference(sqrt_ref, present);
            counted[i] = static_cast<double>(total);
            rho[i] = scratch.coefficient_of_compact(total, present);
        },
        [&](Index i, const PixelRange& r) {
            rho[i] = scratch.coefficient_of_range(img, r, sqrt_ref, counted[i]);
        },
        shared_table);
}

/// Coefficient rho of one box (cx, cy, w, h) against `sqrt_ref`, as the MCMC samplers evaluate
/// a state; `counted` gets its counted weight. With `step` > 1 on the lattice of that step, the
/// points and coefficient box_coefficients gives the box (the uniform kernel's points read in
/// place, not gathered first); step 1: every pixel, the normalised histogram into `hist`
/// (img.n_bins values) and its Bhattacharyya coefficient.
inline double state_coefficient(const BinImage& img, double cx, double cy, double w, double h,
                                const double* sqrt_ref, Kernel kernel, Index step,
                                HistogramScratch& scratch, std::vector<double>& hist,
                                double& counted) {
    double rho = 0.0;
    if (step > 1 && kernel == Kernel::kUniform) {
        const PixelRange points = lattice_points(box_pixels(cx, cy, w, h, img.rows, img.cols), step);
        rho = scratch.coefficient_of_lattice(img, points, step, sqrt_ref, counted);
    } else if (step > 1) {
        const Eigen::Matrix<double, 1, 4> box(cx, cy, w, h);
        box_coefficients(img, box, sqrt_ref, kernel, BoxPath::kDirect, &rho, &counted, step,
                         &scratch);
    } else {
        counted = scratch.compute(img, cx, cy, w, h, kernel, hist.data());
        rho = bhattacharyya_coefficient_row(hist.data(), sqrt_ref, img.n_bins);
    }
    return rho;
}

/// Histograms (K, n_bins) of K boxes, as box_histograms(img, boxes, kernel), with the uniform
/// kernel's counts from for_each_box_count (the same values: c_k / total, or a zero row).
template <class Derived>
inline RowMatrixXd box_histograms(const BinImage& img, const Eigen::MatrixBase<Derived>& boxes,
                                  Kernel kernel, BoxPath path) {
    if (kernel != Kernel::kUniform) return box_histograms(img, boxes, kernel);
    RowMatrixXd out(boxes.rows(), img.n_bins);
    HistogramScratch scratch(img.n_bins);
    const int nb = img.n_bins;
    for_each_box_count(
        img, boxes, path,
        [&](Index i, const std::int32_t* c, std::int64_t total, const BinLanes&) {
            double* row = out.row(i).data();
            if (total == 0) {
                std::fill(row, row + nb, 0.0);
                return;
            }
            const double inv = 1.0 / static_cast<double>(total);
            for (int k = 0; k < nb; ++k) row[k] = static_cast<double>(c[k]) * inv;
        },
        [&](Index i, const PixelRange&) {
            scratch.compute(img, boxes(i, 0), boxes(i, 1), boxes(i, 2), boxes(i, 3), kernel,
                            out.row(i).data());
        });
    return out;
}

/// Bhattacharyya coefficients (K,) of K boxes' histograms against a reference, fused: no
/// (K, B) histogram matrix is made. `sqrt_ref` = sqrt(ref / sum(ref)) (sqrt_reference).
template <class Derived>
inline Eigen::VectorXd box_coefficients(const BinImage& img, const Eigen::MatrixBase<Derived>& boxes,
                                        const Eigen::VectorXd& sqrt_ref, Kernel kernel,
                                        BoxPath path = BoxPath::kAuto) {
    Eigen::VectorXd rho(boxes.rows()), counted(boxes.rows());
    box_coefficients(img, boxes, sqrt_ref.data(), kernel, path, rho.data(), counted.data());
    return rho;
}

}  // namespace pftrack
