// Shared array types. Row-major so that a NumPy (N, D) C-contiguous array maps without a copy.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

// The vectorisable per-row loops (background.hpp, morphology.hpp), compiled twice on x86-64
// Linux with GCC (AVX2 and baseline), the CPU picking one at load time. None uses FMA, so both
// give the same values.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define PFTRACK_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define PFTRACK_VECTOR_CLONES
#endif

namespace pftrack {

using RowMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using RowMatrixXi = Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using Index = Eigen::Index;

/// The source of a lazily binned image: its bins are computed tile by tile, the first time a
/// reader asks for a range of pixels (`ensure`), by `fill` (which writes the bins of one
/// rectangle of pixels into the image's buffer). Thread-safe: readers run with the GIL
/// released, possibly several on one image. A tile's bins are written once, under the mutex,
/// before its flag is set (release); a reader that sees every flag of its range set (acquire)
/// reads bins that are complete and never written again.
class LazyBins {
public:
    /// Writes the bins of pixels [y0, y1) x [x0, x1) into the image buffer.
    using Fill = std::function<void(Index y0, Index y1, Index x0, Index x1)>;
    static constexpr Index kTileRows = 16;
    static constexpr Index kTileCols = 32;

    LazyBins(Index rows, Index cols, Fill fill)
        : rows_(rows), cols_(cols), tiles_y_((rows + kTileRows - 1) / kTileRows),
          tiles_x_((cols + kTileCols - 1) / kTileCols),
          done_(new std::atomic<std::uint8_t>[static_cast<size_t>(tiles_y_ * tiles_x_)]),
          missing_(tiles_y_ * tiles_x_), fill_(std::move(fill)) {
        for (Index t = 0; t < missing_; ++t) done_[static_cast<size_t>(t)].store(0, std::memory_order_relaxed);
        complete_.store(missing_ == 0, std::memory_order_release);
    }

    /// Bins every pixel of [x0, x1) x [y0, y1) (clipped to the image) not binned yet.
    void ensure(Index x0, Index x1, Index y0, Index y1) {
        if (complete_.load(std::memory_order_acquire)) return;
        x0 = std::max<Index>(x0, 0);
        y0 = std::max<Index>(y0, 0);
        x1 = std::min(x1, cols_);
        y1 = std::min(y1, rows_);
        if (x0 >= x1 || y0 >= y1) return;
        const Index tx0 = x0 / kTileCols, tx1 = (x1 - 1) / kTileCols + 1;
        const Index ty0 = y0 / kTileRows, ty1 = (y1 - 1) / kTileRows + 1;
        if (all_done(tx0, tx1, ty0, ty1)) return;
        const std::lock_guard<std::mutex> lock(mu_);
        for (Index ty = ty0; ty < ty1; ++ty) {
            // each run of missing tiles of this tile row: one rectangle (longer rows to bin)
            Index tx = tx0;
            while (tx < tx1) {
                if (flag(ty, tx).load(std::memory_order_relaxed)) {
                    ++tx;
                    continue;
                }
                Index end = tx + 1;
                while (end < tx1 && !flag(ty, end).load(std::memory_order_relaxed)) ++end;
                fill_(ty * kTileRows, std::min((ty + 1) * kTileRows, rows_), tx * kTileCols,
                      std::min(end * kTileCols, cols_));
                missing_ -= end - tx;
                for (; tx < end; ++tx) flag(ty, tx).store(1, std::memory_order_release);
            }
        }
        if (missing_ == 0) {
            fill_ = nullptr;  // the source (a copy of the frame) is no longer needed
            complete_.store(true, std::memory_order_release);
        }
    }

    /// Bins every pixel not binned yet.
    void ensure_all() { ensure(0, cols_, 0, rows_); }

    /// Tiles not binned yet.
    Index pending() {
        const std::lock_guard<std::mutex> lock(mu_);
        return missing_;
    }

private:
    std::atomic<std::uint8_t>& flag(Index ty, Index tx) {
        return done_[static_cast<size_t>(ty * tiles_x_ + tx)];
    }
    bool all_done(Index tx0, Index tx1, Index ty0, Index ty1) {
        for (Index ty = ty0; ty < ty1; ++ty)
            for (Index tx = tx0; tx < tx1; ++tx)
                if (!flag(ty, tx).load(std::memory_order_acquire)) return false;
        return true;
    }

    Index rows_, cols_, tiles_y_, tiles_x_;
    std::unique_ptr<std::atomic<std::uint8_t>[]> done_;  // per tile, row-major: binned
    Index missing_;                                      // tiles not binned (under mu_)
    std::atomic<bool> complete_{false};
    std::mutex mu_;
    Fill fill_;
};

/// A read-only view of a 2-D image of bin indices (one per pixel), as made by `hsv_bins`.
/// A negative bin marks a pixel that is never counted (background, or masked out).
/// With `lazy` set, only the pixels of ranges passed to `ensure` may be read (the readers of
/// histogram.hpp and integral_histogram.hpp ensure each range before they read it).
struct BinImage {
    const std::int16_t* data = nullptr;
    Index rows = 0;
    Index cols = 0;
    Index row_stride = 0;  // in elements
    int n_bins = 0;
    LazyBins* lazy = nullptr;  // null: every bin is computed

    const std::int16_t* row(Index y) const { return data + y * row_stride; }
    /// Makes the bins of pixels [x0, x1) x [y0, y1) readable (a no-op unless lazy).
    void ensure(Index x0, Index x1, Index y0, Index y1) const {
        if (lazy != nullptr) lazy->ensure(x0, x1, y0, y1);
    }
};

/// An allocator whose value-initialisation leaves trivial elements uninitialised: a vector of
/// n of them is only allocated, not zeroed. For buffers that their maker fills in full.
template <class T>
struct DefaultInitAllocator : std::allocator<T> {
    template <class U>
    struct rebind {
        using other = DefaultInitAllocator<U>;
    };
    DefaultInitAllocator() = default;
    template <class U>
    DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}
    template <class U>
    void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
        ::new (static_cast<void*>(p)) U;  // default-, not value-initialised
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

/// An owned bin image. Made by `hsv_bins` (trusted) or from a user's array, checked once on
/// construction (every bin in [-1, n_bins)), so the per-particle loops never need to check.
/// The constructor leaves the bins uninitialised: every maker (the background pass,
/// `mask_bins`, `hsv_bins`, the checked copy of a user's array) writes all of them, and a frame's
/// worth of zeros written first cost as much as a third of `mask_bins`.
/// A lazy image (`lazy` set, see `make_lazy`) computes its bins on demand: `view()` and copies
/// compute every bin still missing, `lazy_view()` leaves that to the readers that ensure their
/// ranges. `data` is complete only after `view()`.
struct BinnedImage {
    std::vector<std::int16_t, DefaultInitAllocator<std::int16_t>> data;
    Index rows = 0;
    Index cols = 0;
    int n_bins = 0;
    std::unique_ptr<LazyBins> lazy;  // null: every bin is computed

    BinnedImage() = default;
    BinnedImage(Index rows_, Index cols_, int n_bins_)
        : data(static_cast<size_t>(rows_ * cols_)), rows(rows_), cols(cols_), n_bins(n_bins_) {}
    /// A copy has every bin computed (and no lazy source).
    BinnedImage(const BinnedImage& other) : rows(other.rows), cols(other.cols), n_bins(other.n_bins) {
        other.complete();
        data = other.data;
    }
    BinnedImage& operator=(const BinnedImage& other) {
        if (this != &other) {
            other.complete();
            data = other.data;
            rows = other.rows;
            cols = other.cols;
            n_bins = other.n_bins;
            lazy.reset();
        }
        return *this;
    }
    // moves keep the buffer (and so the lazy source's pointers into it) in place
    BinnedImage(BinnedImage&&) noexcept = default;
    BinnedImage& operator=(BinnedImage&&) noexcept = default;
    ~BinnedImage() = default;

    /// Makes the image lazy: `fill(y0, y1, x0, x1)` writes the bins of that rectangle into
    /// `data` (row stride `cols`) when first asked for.
    void make_lazy(LazyBins::Fill fill) { lazy = std::make_unique<LazyBins>(rows, cols, std::move(fill)); }
    /// Computes every bin still missing.
    void complete() const {
        if (lazy) lazy->ensure_all();
    }
    /// A view of every bin (all computed first).
    BinImage view() const {
        complete();
        return BinImage{data.data(), rows, cols, cols, n_bins, nullptr};
    }
    /// A view whose readers compute the bins of the ranges they read (`BinImage::ensure`).
    BinImage lazy_view() const { return BinImage{data.data(), rows, cols, cols, n_bins, lazy.get()}; }
};

}  // namespace pftrack
