// Shared array types. Row-major so that a NumPy (N, D) C-contiguous array maps without a copy.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <utility>
#include <vector>

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

/// An owned bin image. Made by `hsv_bins` (trusted) or from a user's array, checked once on
/// construction (every bin in [-1, n_bins)), so the per-particle loops never need to check.
struct BinnedImage {
    std::vector<std::int16_t> data;
    Index rows = 0;
    Index cols = 0;
    int n_bins = 0;

    BinnedImage() = default;
    BinnedImage(Index rows_, Index cols_, int n_bins_)
        : data(static_cast<size_t>(rows_ * cols_)), rows(rows_), cols(cols_), n_bins(n_bins_) {}

    BinImage view() const { return BinImage{data.data(), rows, cols, cols, n_bins}; }
};

}  // namespace pftrack
