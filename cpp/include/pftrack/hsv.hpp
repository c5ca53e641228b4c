// HSV colour binning after Perez, Hue, Vermaak & Gangnet (ECCV 2002): Nh x Ns colour bins for
// pixels that are saturated and bright enough, Nv grey bins (by value) for the rest.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>

#include "check.hpp"
#include "types.hpp"

namespace pftrack {

struct HsvBinning {
    int n_h = 10;
    int n_s = 10;
    int n_v = 10;
    double s_min = 0.1;  // colour bins need saturation > s_min (on [0, 1])
    double v_min = 0.2;  // ... and value > v_min (on [0, 1])

    int n_bins() const { return n_h * n_s + n_v; }

    void validate(const char* fn) const {
        require(n_h >= 1 && n_h <= 64, fn, "n_h", n_h, "in [1, 64]");
        require(n_s >= 1 && n_s <= 64, fn, "n_s", n_s, "in [1, 64]");
        require(n_v >= 1 && n_v <= 64, fn, "n_v", n_v, "in [1, 64]");
        require(s_min >= 0.0 && s_min <= 1.0, fn, "s_min", s_min, "in [0, 1]");
        require(v_min >= 0.0 && v_min <= 1.0, fn, "v_min", v_min, "in [0, 1]");
        require(n_bins() <= std::numeric_limits<std::int16_t>::max(), fn, "n_bins", n_bins(),
                "at most 32767");
    }
};

/// Bin of one pixel. H in degrees [0, 360), S = (max-min)/max, V = max/255, all in double so
/// that the NumPy reference (tests/reference.py) reproduces every bin exactly.
inline int hsv_bin_of(int b, int g, int r, const HsvBinning& p) {
    const int mx = std::max(r, std::max(g, b));
    const int mn = std::min(r, std::min(g, b));
    const double v = mx / 255.0;
    const double s = mx > 0 ? static_cast<double>(mx - mn) / mx : 0.0;
    if (s > p.s_min && v > p.v_min) {
        const double d = static_cast<double>(mx - mn);
        double h;
        if (mx == r) {
            h = 60.0 * (g - b) / d;
            if (h < 0.0) h += 360.0;
        } else if (mx == g) {
            h = 60.0 * (b - r) / d + 120.0;
        } else {
            h = 60.0 * (r - g) / d + 240.0;
        }
        const int hb = std::min(static_cast<int>(h * p.n_h / 360.0), p.n_h - 1);
        const int sb = std::min(static_cast<int>(s * p.n_s), p.n_s - 1);
        return hb * p.n_s + sb;
    }
    const int vb = std::min(static_cast<int>(v * p.n_v), p.n_v - 1);
    return p.n_h * p.n_s + vb;
}

/// Bin every pixel of a BGR uint8 image (rows x cols, `row_stride` bytes between rows, 3 bytes a
/// pixel). Where `mask` is given (one byte a pixel, `mask_stride` bytes a row), zero marks a
/// background pixel whose bin is -1 so that no histogram ever counts it.
inline void hsv_bins(const std::uint8_t* bgr, Index rows, Index cols, Index row_stride,
                     const std::uint8_t* mask, Index mask_stride, const HsvBinning& p,
                     std::int16_t* out) {
    for (Index y = 0; y < rows; ++y) {
        const std::uint8_t* px = bgr + y * row_stride;
        const std::uint8_t* m = mask ? mask + y * mask_stride : nullptr;
        std::int16_t* o = out + y * cols;
        for (Index x = 0; x < cols; ++x) {
            const int bin = hsv_bin_of(px[3 * x], px[3 * x + 1], px[3 * x + 2], p);
            o[x] = (m && m[x] == 0) ? std::int16_t(-1) : static_cast<std::int16_t>(bin);
        }
    }
}

}  // namespace pftrack
