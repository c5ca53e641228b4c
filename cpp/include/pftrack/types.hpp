// Shared array types. Row-major so that a NumPy (N, D) C-contiguous array maps without a copy.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
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

/// A read-only view of a 2-D image of bin indices (one per pixel), as made by `hsv_bins`.
/// A negative bin marks a pixel that is never counted (background, or masked out).
struct BinImage {
    const std::int16_t* data = nullptr;
    Index rows = 0;
    Index cols = 0;
    Index row_stride = 0;  // in elements
    int n_bins = 0;

    const std::int16_t* row(Index y) const { return data + y * row_stride; }
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
struct BinnedImage {
    std::vector<std::int16_t, DefaultInitAllocator<std::int16_t>> data;
    Index rows = 0;
    Index cols = 0;
    int n_bins = 0;

    BinnedImage() = default;
    BinnedImage(Index rows_, Index cols_, int n_bins_)
        : data(static_cast<size_t>(rows_ * cols_)), rows(rows_), cols(cols_), n_bins(n_bins_) {}

    BinImage view() const { return BinImage{data.data(), rows, cols, cols, n_bins}; }
};

}  // namespace pftrack
