// Colour histograms of image boxes, from a precomputed bin image (hsv_bins).
//
// A box is (cx, cy, w, h) in pixels, pixel centres at integer coordinates. It covers columns
// x0 = floor(cx - w/2 + 1/2) .. x1 = floor(cx + w/2 + 1/2) (half open) and likewise rows, clipped
// to the image. Pixels with a negative bin (background) are never counted. Each histogram is
// normalised to sum 1; a box with nothing to count (outside the image, or no foreground) gets the
// all-zero histogram, whose Bhattacharyya coefficient with any reference is 0 (distance 1).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "check.hpp"
#include "likelihood.hpp"
#include "types.hpp"

namespace pftrack {

enum class Kernel { kUniform = 0, kEpanechnikov = 1 };

struct PixelRange {
    Index x0, x1, y0, y1;  // half open, clipped; empty when x0 >= x1 or y0 >= y1
    bool empty() const { return x0 >= x1 || y0 >= y1; }
};

inline Index round_half_up(double v) { return static_cast<Index>(std::floor(v + 0.5)); }

/// floor(v + 1/2) for v + 1/2 clamped to [-2, hi]: the same after clipping to [0, hi - 2], and
/// without a call to floor (a library call without SSE4.1). NaN lands on -2.
inline Index round_half_up_clamped(double v, double hi) {
    const double c = std::min(std::max(v + 0.5, -2.0), hi);
    const auto i = static_cast<Index>(c);                    // truncation towards zero
    return i - (static_cast<double>(i) > c ? 1 : 0);         // floor for negative c
}

inline PixelRange box_pixels(double cx, double cy, double w, double h, Index rows, Index cols) {
    const double xh = static_cast<double>(cols) + 2.0, yh = static_cast<double>(rows) + 2.0;
    PixelRange r;
    r.x0 = std::max<Index>(0, round_half_up_clamped(cx - 0.5 * w, xh));
    r.x1 = std::min<Index>(cols, round_half_up_clamped(cx + 0.5 * w, xh));
    r.y0 = std::max<Index>(0, round_half_up_clamped(cy - 0.5 * h, yh));
    r.y1 = std::min<Index>(rows, round_half_up_clamped(cy + 0.5 * h, yh));
    return r;
}

/// The lattice of every `step`-th pixel: the points (x, y) with x and y multiples of `step`.
/// `lattice_points` gives the lattice points of a pixel range in lattice units (the point
/// (i, j) is the pixel (i step, j step)); step 1 gives the range itself.
inline PixelRange lattice_points(const PixelRange& r, Index step) {
    if (r.empty() || step == 1) return r;
    const auto up = [step](Index v) { return (v + step - 1) / step; };  // ceil, v >= 0
    return {up(r.x0), up(r.x1), up(r.y0), up(r.y1)};
}

/// Largest lattice step kept by `lattice_step`.
constexpr Index kMaxLatticeStep = 64;

/// The step of the lattice on which a box of `w` x `h` pixels is counted so that it keeps at
/// least `min_samples` points: floor(sqrt(w h / min_samples)), at least 1 (every pixel) and at
/// most kMaxLatticeStep, nor more than half the box's shorter side (a few samples across it
/// at least: a small `min_samples` on a narrow box kept 0-2 of its pixels). `min_samples` 0 (or
/// a box of fewer than 4 min_samples pixels, or non-finite sizes) gives 1.
inline Index lattice_step(double w, double h, double min_samples) {
    const double area = w * h;
    if (!(min_samples > 0.0) || !(area >= 4.0 * min_samples) || !std::isfinite(area)) return 1;
    const double k = std::min(std::floor(std::sqrt(area / min_samples)),
                              std::max(1.0, std::floor(0.5 * std::min(w, h))));
    return std::min<Index>(kMaxLatticeStep, static_cast<Index>(k));
}

inline bool box_is_sane(double cx, double cy, double w, double h) {
    // Far outside any image is fine (empty histogram); only non-finite or negative sizes are not.
    return std::isfinite(cx) && std::isfinite(cy) && std::isfinite(w) && std::isfinite(h) &&
           w >= 0.0 && h >= 0.0 && std::abs(cx) < 1e9 && std::abs(cy) < 1e9 && w < 1e9 && h < 1e9;
}

/// The partial sum (0-3) to which HistogramScratch::coefficient_of_counts adds bin k's term:
/// k mod 4, but 0 for the bins after the last whole group of 4 (the loop's tail).
inline int partial_sum_of(int k, int n_bins) { return k < (n_bins & ~3) ? (k & 3) : 0; }

/// Bins split by partial_sum_of: bins[q][0 .. n[q]) go to partial sum q, in increasing order.
/// An integral histogram's box (for_each_range_count<true>) also gives its counts in compact
/// form: counts[l] for the compact index l of each bin present, local[q][j] that of bins[q][j],
/// bin_of_local[l] the bin of l (-1: background), n_local of them; counts is null otherwise.
struct BinLanes {
    const std::int16_t* bins[4];
    int n[4];
    const std::int16_t* local[4] = {nullptr, nullptr, nullptr, nullptr};
    const std::uint16_t* counts = nullptr;
    const std::int16_t* bin_of_local = nullptr;
    int n_local = 0;
};

/// Scratch space for one histogram. Slot 0 collects background (bin -1) so the inner loop never
/// branches; kCopies interleaved copies break the store-to-load dependency of runs of equal bins.
class HistogramScratch {
public:
    // Interleaved copies of the counts: neighbouring pixels often share a bin (59% of pixels in
    // 20x50 PETS boxes equal the one 4 to the left), and ++c[b] on one copy waits for the
    // previous increment's store. 8 copies measured 5-15% faster than 4 on PETS frames.
    static constexpr int kCopies = 8;
    explicit HistogramScratch(int n_bins)
        : n_bins_(n_bins), stride_(n_bins + 1), stride16_((n_bins + 1 + 7) & ~7),
          counts_(kCopies * static_cast<size_t>(stride_)),
          counts16_(kCopies * static_cast<size_t>(stride16_)),
          weights_(4 * static_cast<size_t>(stride_)), hist_(static_cast<size_t>(n_bins)) {}

    /// Writes the normalised histogram of one box to `out` (n_bins values).
    /// Returns the total counted weight (0 for an empty box).
    double compute(const BinImage& img, double cx, double cy, double w, double h, Kernel kernel,
                   double* out) {
        const PixelRange r = box_pixels(cx, cy, w, h, img.rows, img.cols);
        std::fill(out, out + n_bins_, 0.0);
        if (r.empty()) return 0.0;
        return kernel == Kernel::kUniform ? uniform(img, r, out) : epanechnikov(img, r, cx, cy, w, h, out);
    }

private:
    double uniform(const BinImage& img, const PixelRange& r, double* out) {
        const std::int64_t total = count(img, r);
        if (total == 0) return 0.0;
        const double inv = 1.0 / static_cast<double>(total);
        const std::int32_t* c = counts_.data() + 1;
        for (int k = 0; k < n_bins_; ++k) out[k] = static_cast<double>(c[k]) * inv;
        return static_cast<double>(total);
    }

public:
    /// Counts the box's pixels per bin (uniform kernel) into counts(); returns the total counted.
    std::int64_t count_box(const BinImage& img, double cx, double cy, double w, double h) {
        const PixelRange r = box_pixels(cx, cy, w, h, img.rows, img.cols);
        if (r.empty()) return 0;
        return count(img, r);
    }
    /// Per-bin counts of the last count_box (n_bins values).
    const std::int32_t* counts() const { return counts_.data() + 1; }

    /// Bhattacharyya coefficient of one box's normalised histogram with the reference whose
    /// square roots are `sqrt_ref`, without writing the histogram out. For the uniform kernel
    /// straight from the integer counts: rho = sum_k sqrt(c_k) sqrt(q_k) / sqrt(n). `counted`
    /// gets the counted weight (pixels, for the uniform kernel); an empty box has rho = 0.
    double coefficient(const BinImage& img, double cx, double cy, double w, double h, Kernel kernel,
                       const double* sqrt_ref, double& counted) {
        if (kernel == Kernel::kUniform) {
            const std::int64_t total = count_box(img, cx, cy, w, h);
            counted = static_cast<double>(total);
            return coefficient_of_counts(counts(), total, sqrt_ref);
        }
        counted = compute(img, cx, cy, w, h, kernel, hist_.data());
        return bhattacharyya_coefficient_row(hist_.data(), sqrt_ref, n_bins_);
    }

    /// Epanechnikov-kernel coefficient of the pixels of `r` (already clipped) for the box
    /// (cx, cy, w, h) in the same pixels; `counted` gets the counted weight.
    double epanechnikov_coefficient(const BinImage& img, const PixelRange& r, double cx, double cy,
                                    double w, double h, const double* sqrt_ref, double& counted) {
        std::fill(hist_.begin(), hist_.end(), 0.0);
        counted = r.empty() ? 0.0 : epanechnikov(img, r, cx, cy, w, h, hist_.data());
        return bhattacharyya_coefficient_row(hist_.data(), sqrt_ref, n_bins_);
    }

    /// Uniform-kernel coefficient of the pixels of `r` (already clipped, as box_pixels gives).
    double coefficient_of_range(const BinImage& img, const PixelRange& r, const double* sqrt_ref,
                                double& counted) {
        const std::int64_t total = r.empty() ? 0 : count(img, r);
        counted = static_cast<double>(total);
        return coefficient_of_counts(counts(), total, sqrt_ref);
    }

    /// rho = sum_k sqrt(c_k) sqrt(q_k) / sqrt(total) of integer counts c (n_bins values summing
    /// to `total`); 0 when total is 0. Every path that counts a box (directly, or from an
    /// integral histogram) ends here, so equal counts give bit-identical coefficients.
    double coefficient_of_counts(const std::int32_t* c, std::int64_t total, const double* sqrt_ref) {
        if (total == 0) return 0.0;
        const double norm = std::sqrt(static_cast<double>(total));
        if (total >= kSqrtTableMax) return sqrt_count_dot(c, sqrt_ref, n_bins_) / norm;
        // every count is <= total: look the square roots up (same values as std::sqrt)
        const double* tab = sqrt_table(static_cast<size_t>(total));
        double r0 = 0.0, r1 = 0.0, r2 = 0.0, r3 = 0.0;
        int k = 0;
        for (; k + 4 <= n_bins_; k += 4) {
            r0 += tab[c[k]] * sqrt_ref[k];
            r1 += tab[c[k + 1]] * sqrt_ref[k + 1];
            r2 += tab[c[k + 2]] * sqrt_ref[k + 2];
            r3 += tab[c[k + 3]] * sqrt_ref[k + 3];
        }
        for (; k < n_bins_; ++k) r0 += tab[c[k]] * sqrt_ref[k];
        return ((r0 + r1) + (r2 + r3)) / norm;
    }

    /// coefficient_of_counts of counts that are 0 outside the bins `present` (split by
    /// partial_sum_of): the same sums, bit for bit, over those bins only. Each term goes to the
    /// partial sum the full loop adds it to, in the same order; the terms skipped are
    /// 0 * sqrt_ref[k] = +0, and adding +0 leaves a partial sum (>= +0) unchanged. The four
    /// sums advance together, in registers.
    double coefficient_of_counts(const std::int32_t* c, std::int64_t total, const double* sqrt_ref,
                                 const BinLanes& present) {
        if (total == 0) return 0.0;
        if (total >= kSqrtTableMax) return coefficient_of_counts(c, total, sqrt_ref);
        const double norm = std::sqrt(static_cast<double>(total));
        const double* tab = sqrt_table(static_cast<size_t>(total));
        const auto term = [&](int k) { return tab[c[k]] * sqrt_ref[k]; };
        return lane_sums(present.bins, present.n, term) / norm;
    }

    /// Takes the reference's square roots of the bins of `present` (an integral histogram's
    /// region, compact form) for coefficient_of_compact: once per region, not per box.
    void gather_reference(const double* sqrt_ref, const BinLanes& present) {
        sref_local_.resize(static_cast<size_t>(present.n_local));
        for (int l = 0; l < present.n_local; ++l) {
            const int b = present.bin_of_local[l];
            sref_local_[static_cast<size_t>(l)] = b >= 0 ? sqrt_ref[b] : 0.0;
        }
    }

    /// coefficient_of_counts(c, total, sqrt_ref, present) of a box given in compact form
    /// (present.counts, after gather_reference of the same region and reference), total <
    /// kSqrtTableMax: the same terms tab[c_k] sqrt_ref[k], into the same partial sums in the
    /// same order, so bit for bit the same value, read from the compact counts in place of a
    /// copy of them scattered over every bin.
    double coefficient_of_compact(std::int64_t total, const BinLanes& present) const {
        if (total == 0) return 0.0;
        const double norm = std::sqrt(static_cast<double>(total));
        const double* tab = sqrt_table(static_cast<size_t>(total));
        const std::uint16_t* cnt = present.counts;
        const double* sref = sref_local_.data();
        const auto term = [&](int l) { return tab[cnt[l]] * sref[l]; };
        return lane_sums(present.local, present.n, term) / norm;
    }

    // Boxes of fewer pixels look sqrt(count) up in a table (110 square roots per box cost as
    // much as counting a 20x50 box's pixels); larger boxes compute them.
    static constexpr std::int64_t kSqrtTableMax = std::int64_t(1) << 16;

private:
    /// ((r0 + r1) + (r2 + r3)) where r_q adds term(index[q][j]) for j = 0 .. n[q] in order,
    /// the four sums advancing together, in registers (coefficient_of_counts of `present`'s
    /// bins, coefficient_of_compact of their compact indices: one order, so bit for bit the
    /// same sums).
    template <class Term>
    static double lane_sums(const std::int16_t* const (&index)[4], const int (&n)[4], Term term) {
        const std::int16_t *i0 = index[0], *i1 = index[1], *i2 = index[2], *i3 = index[3];
        const int n0 = n[0], n1 = n[1], n2 = n[2], n3 = n[3];
        const int m = std::min(std::min(n0, n1), std::min(n2, n3));
        double r0 = 0.0, r1 = 0.0, r2 = 0.0, r3 = 0.0;
        for (int j = 0; j < m; ++j) {
            r0 += term(i0[j]);
            r1 += term(i1[j]);
            r2 += term(i2[j]);
            r3 += term(i3[j]);
        }
        for (int j = m; j < n0; ++j) r0 += term(i0[j]);
        for (int j = m; j < n1; ++j) r1 += term(i1[j]);
        for (int j = m; j < n2; ++j) r2 += term(i2[j]);
        for (int j = m; j < n3; ++j) r3 += term(i3[j]);
        return (r0 + r1) + (r2 + r3);
    }

    /// sqrt(0 .. at_least), grown on demand (each entry exactly std::sqrt of its index). One
    /// table per thread, kept from call to call: a scratch made per object and frame filled
    /// its own anew (a quarter of the coefficients' time on the tracker's frames).
    static const double* sqrt_table(size_t at_least) {
        thread_local std::vector<double> table;
        if (table.size() <= at_least) {
            const size_t old = table.size();
            table.resize(std::max(at_least + 1, 2 * old));
            for (size_t i = old; i < table.size(); ++i) table[i] = std::sqrt(static_cast<double>(i));
        }
        return table.data();
    }

    /// Counts the range's pixels per bin into counts_ (slot 0: background); returns the total.
    std::int64_t count(const BinImage& img, const PixelRange& r) {
        img.ensure(r.x0, r.x1, r.y0, r.y1);  // a lazy image bins the range first
        const Index area = (r.x1 - r.x0) * (r.y1 - r.y0);
        return area < 65536 ? count_copies(img, r, 1, counts16_.data(), stride16_)
                            : count_copies(img, r, 1, counts_.data(), stride_);
    }

public:
    /// Uniform-kernel coefficient of the lattice points `points` (lattice_points of a clipped
    /// range: the point (i, j) is the pixel (i step, j step)), read in place: the same counts,
    /// so the same coefficient, as gathering them first (LatticeImage) and counting that.
    /// `counted` gets the points counted times step^2.
    double coefficient_of_lattice(const BinImage& img, const PixelRange& points, Index step,
                                  const double* sqrt_ref, double& counted) {
        std::int64_t total = 0;
        if (!points.empty()) {
            img.ensure(points.x0 * step, (points.x1 - 1) * step + 1, points.y0 * step,
                       (points.y1 - 1) * step + 1);
            const Index area = (points.x1 - points.x0) * (points.y1 - points.y0);
            total = area < 65536 ? count_copies(img, points, step, counts16_.data(), stride16_)
                                 : count_copies(img, points, step, counts_.data(), stride_);
        }
        counted = static_cast<double>(total * step * step);
        return coefficient_of_counts(counts(), total, sqrt_ref);
    }

private:
    /// kCopies interleaved copies of type T (uint16 when no count can reach 65536: half the
    /// bytes to clear and add up per box), summed into counts_. `step` > 1 counts the lattice
    /// points `r` (in lattice units) of the image, in place.
    template <class T>
    std::int64_t count_copies(const BinImage& img, const PixelRange& r, Index step, T* base,
                              int stride) {
        std::fill(base, base + kCopies * static_cast<size_t>(stride), T(0));
        T* c[kCopies];
        for (int q = 0; q < kCopies; ++q) c[q] = base + 1 + q * stride;  // +1: bin -1 in slot 0
        const Index w = r.x1 - r.x0;
        if (step == 1) {
            for (Index y = r.y0; y < r.y1; ++y) {
                const std::int16_t* b = img.row(y) + r.x0;
                Index x = 0;
                for (; x + kCopies <= w; x += kCopies)
                    for (int q = 0; q < kCopies; ++q) ++c[q][b[x + q]];
                for (int q = 0; x < w; ++x, ++q) ++c[q][b[x]];
            }
        } else {
            for (Index y = r.y0; y < r.y1; ++y) {
                const std::int16_t* b = img.row(y * step) + r.x0 * step;
                Index x = 0;
                for (; x + kCopies <= w; x += kCopies)
                    for (int q = 0; q < kCopies; ++q) ++c[q][b[(x + q) * step]];
                for (int q = 0; x < w; ++x, ++q) ++c[q][b[x * step]];
            }
        }
        std::int32_t* out = counts_.data() + 1;
        const int nb = n_bins_;  // a local: stores through `out` (int32) could alias n_bins_
        for (int k = 0; k < nb; ++k) {
            T s = c[0][k];
            for (int q = 1; q < kCopies; ++q) s = static_cast<T>(s + c[q][k]);  // <= area: no wrap
            out[k] = static_cast<std::int32_t>(s);
        }
        std::int64_t background = 0;  // slot -1
        for (int q = 0; q < kCopies; ++q) background += c[q][-1];
        return (r.x1 - r.x0) * (r.y1 - r.y0) - background;
    }

    // Epanechnikov profile k(r^2) = max(0, 1 - r^2), r^2 = ((x-cx)/(w/2))^2 + ((y-cy)/(h/2))^2.
    double epanechnikov(const BinImage& img, const PixelRange& r, double cx, double cy, double w,
                        double h, double* out) {
        img.ensure(r.x0, r.x1, r.y0, r.y1);  // a lazy image bins the range first
        std::fill(weights_.begin(), weights_.end(), 0.0);
        double* a0 = weights_.data() + 1;
        double* a1 = a0 + stride_;
        const double ix = w > 0.0 ? 2.0 / w : 0.0;
        const double iy = h > 0.0 ? 2.0 / h : 0.0;
        rowk_.resize(static_cast<size_t>(r.x1 - r.x0));
        for (Index x = r.x0; x < r.x1; ++x) {
            const double dx = (static_cast<double>(x) - cx) * ix;
            rowk_[static_cast<size_t>(x - r.x0)] = dx * dx;
        }
        for (Index y = r.y0; y < r.y1; ++y) {
            const double dy = (static_cast<double>(y) - cy) * iy;
            const double base = 1.0 - dy * dy;
            if (base <= 0.0) continue;
            const std::int16_t* b = img.row(y);
            Index x = r.x0;
            for (; x + 2 <= r.x1; x += 2) {
                a0[b[x]] += std::max(0.0, base - rowk_[static_cast<size_t>(x - r.x0)]);
                a1[b[x + 1]] += std::max(0.0, base - rowk_[static_cast<size_t>(x + 1 - r.x0)]);
            }
            for (; x < r.x1; ++x) a0[b[x]] += std::max(0.0, base - rowk_[static_cast<size_t>(x - r.x0)]);
        }
        double total = 0.0;
        for (int k = 0; k < n_bins_; ++k) {
            out[k] = a0[k] + a1[k];
            total += out[k];
        }
        if (!(total > 0.0)) {
            std::fill(out, out + n_bins_, 0.0);
            return 0.0;
        }
        const double inv = 1.0 / total;
        for (int k = 0; k < n_bins_; ++k) out[k] *= inv;
        return total;
    }

    int n_bins_;
    int stride_;
    int stride16_;
    std::vector<std::int32_t> counts_;    // kCopies x stride_; copy 0 holds the summed counts
    std::vector<std::uint16_t> counts16_;  // kCopies x stride16_, for boxes under 65536 pixels
    std::vector<double> weights_;
    std::vector<double> rowk_;
    std::vector<double> hist_;
    std::vector<double> sref_local_;  // gather_reference: sqrt_ref of each compact bin
};

inline void check_bin_image(const BinImage& img, const char* fn) {
    require(img.rows > 0 && img.cols > 0, fn, "bins must be a non-empty 2-D image");
    require(img.n_bins >= 1 && img.n_bins <= 32767, fn, "n_bins", img.n_bins, "in [1, 32767]");
}

/// Checks a (K, 4) box array: finite, w and h >= 0. The message names the first bad row.
template <class Derived>
inline void check_boxes(const Eigen::MatrixBase<Derived>& boxes, const char* fn, const char* what) {
    require(boxes.cols() == 4, fn, (std::string(what) + " cols").c_str(), boxes.cols(),
            "4 (cx, cy, w, h)");
    for (Index i = 0; i < boxes.rows(); ++i)
        if (!box_is_sane(boxes(i, 0), boxes(i, 1), boxes(i, 2), boxes(i, 3))) {
            std::ostringstream s;
            s << what << "[" << i << "] is (" << boxes(i, 0) << ", " << boxes(i, 1) << ", "
              << boxes(i, 2) << ", " << boxes(i, 3)
              << "), expected finite (cx, cy, w, h) with w, h >= 0, each value within ±1e+09 px";
            fail(fn, s.str());
        }
}

/// Histograms of K boxes: (K, n_bins), each row sums to 1 (or is all zero for an empty box).
template <class Derived>
inline RowMatrixXd box_histograms(const BinImage& img, const Eigen::MatrixBase<Derived>& boxes,
                                  Kernel kernel) {
    RowMatrixXd out(boxes.rows(), img.n_bins);
    HistogramScratch scratch(img.n_bins);
    for (Index i = 0; i < boxes.rows(); ++i)
        scratch.compute(img, boxes(i, 0), boxes(i, 1), boxes(i, 2), boxes(i, 3), kernel,
                        out.row(i).data());
    return out;
}

}  // namespace pftrack
