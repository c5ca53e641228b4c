// The paper's detector, per-pixel part: an adaptive background (running average, updated
// selectively where there is no foreground), the difference of each frame to it and to the previous
// frame, a noise-adaptive threshold, fused with the HSV binning of the same frame so that every
// frame is read once. Morphology and connected components follow in Python (OpenCV).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "check.hpp"
#include "hsv.hpp"
#include "types.hpp"

namespace pftrack {

/// `hsv_bin_of` as table look-ups, without branches: identical results (tests check all 2^24
/// colours), several times faster. The colour/grey decision and the saturation bin depend on
/// (max, min) only, the value bin on max only, the hue bin on (sector, numerator, max - min) only.
class HsvLut {
public:
    explicit HsvLut(const HsvBinning& p) : n_s_(p.n_s) {
        p.validate("HsvLut");
        sat_.assign(256 * 256, -1);
        grey_.assign(256, 0);
        for (int mx = 0; mx < 256; ++mx) {
            // Same expressions as hsv_bin_of, so the same doubles and the same truncations.
            const double v = mx / 255.0;
            grey_[mx] = static_cast<std::int16_t>(p.n_h * p.n_s +
                                                  std::min(static_cast<int>(v * p.n_v), p.n_v - 1));
            for (int mn = 0; mn <= mx; ++mn) {
                const double s = mx > 0 ? static_cast<double>(mx - mn) / mx : 0.0;
                if (s > p.s_min && v > p.v_min)
                    sat_[mx * 256 + mn] =
                        static_cast<std::int8_t>(std::min(static_cast<int>(s * p.n_s), p.n_s - 1));
            }
        }
        hue_.assign(3 * kHueStride, 0);
        for (int sector = 0; sector < 3; ++sector)
            for (int d = 1; d < 256; ++d)
                for (int num = -d; num <= d; ++num) {
                    double h;
                    if (sector == 0) {  // max is r: num = g - b
                        h = 60.0 * num / d;
                        if (h < 0.0) h += 360.0;
                    } else if (sector == 1) {  // max is g: num = b - r
                        h = 60.0 * num / d + 120.0;
                    } else {  // max is b: num = r - g
                        h = 60.0 * num / d + 240.0;
                    }
                    hue_[sector * kHueStride + d * 511 + num + 255] =
                        static_cast<std::uint8_t>(std::min(static_cast<int>(h * p.n_h / 360.0), p.n_h - 1));
                }
    }

    int bin(int b, int g, int r) const {
        const int mx = std::max(r, std::max(g, b));
        const int mn = std::min(r, std::min(g, b));
        // hsv_bin_of's order of tests: r first, then g, then b (ties go to the earlier one).
        const int sector = (mx == r) ? 0 : ((mx == g) ? 1 : 2);
        const int num = (mx == r) ? g - b : ((mx == g) ? b - r : r - g);
        const int sb = sat_[mx * 256 + mn];
        const int hb = hue_[sector * kHueStride + (mx - mn) * 511 + num + 255];
        return sb >= 0 ? hb * n_s_ + sb : grey_[mx];
    }

private:
    static constexpr int kHueStride = 256 * 511;
    int n_s_;
    std::vector<std::int8_t> sat_;    // [max * 256 + min] -> saturation bin, -1 for grey pixels
    std::vector<std::int16_t> grey_;  // [max] -> grey bin
    std::vector<std::uint8_t> hue_;   // [sector][max - min][num + 255] -> hue bin
};

/// Settings of `BackgroundModel`. Thresholds are on the max-over-channels absolute difference,
/// in grey levels.
struct BackgroundConfig {
    double alpha = 0.05;      // running-average rate where the pixel is background (selective update)
    double alpha_fg = 0.005;  // slow rate where it is foreground (absorbs stopped objects; 0 = off)
    double k_noise = 4.0;     // threshold = k_noise * median background difference of the last frame
    double t_min = 25.0;      // ... clamped to [t_min, t_max]
    double t_max = 60.0;
    double low_ratio = 0.5;   // a pixel that also moved (frame difference > threshold) is
                              // foreground from low_ratio * threshold on (hysteresis)
    double shadow_lo = 0.5;   // a pixel darker than the background, with brightness ratio
                              // sum(I) / sum(B) in [shadow_lo, 1) ...
    double shadow_chroma = 0.03;  // ... and chromaticity |I_c / sum(I) - B_c / sum(B)| <=
                                  // shadow_chroma for every c, is a shadow: background, not
                                  // learnt (rate alpha_fg). shadow_lo = 1 turns this off.

    void validate(const char* fn) const {
        require(alpha > 0.0 && alpha <= 1.0, fn, "alpha", alpha, "in (0, 1]");
        require(alpha_fg >= 0.0 && alpha_fg <= 1.0, fn, "alpha_fg", alpha_fg, "in [0, 1]");
        require(k_noise >= 0.0 && k_noise <= 1e6, fn, "k_noise", k_noise, "in [0, 1e6]");
        require(t_min >= 0.0 && t_min <= 255.0, fn, "t_min", t_min, "in [0, 255]");
        require(t_max >= t_min && t_max <= 255.0, fn, "t_max", t_max, "in [t_min, 255]");
        require(low_ratio >= 0.0 && low_ratio <= 1.0, fn, "low_ratio", low_ratio, "in [0, 1]");
        require(shadow_lo >= 0.0 && shadow_lo <= 1.0, fn, "shadow_lo", shadow_lo, "in [0, 1]");
        require(shadow_chroma >= 0.0 && shadow_chroma <= 1.0, fn, "shadow_chroma", shadow_chroma,
                "in [0, 1]");
    }
};

/// Adaptive background with the paper's selective update. The first frame (or `set_background`)
/// initialises it; every later frame goes through `apply`, which in one read of the frame
///   (a) bins each pixel (`hsv_bin_of`'s bins, via HsvLut),
///   (b) d_bg = max_c |frame_c - background_c|, d_prev = max_c |frame_c - previous_c|,
///   (c) candidate = d_bg > T or (d_prev > T and d_bg > low_ratio * T); a candidate that is a
///       shadow (see BackgroundConfig) is not foreground; mask 255/0,
///   (d) background_c += a (frame_c - background_c), a = alpha where neither foreground nor
///       shadow, alpha_fg where either (float32 arithmetic, in this order, so a NumPy reference
///       matches bit for bit),
///   (e) stores the frame as the previous one, and counts floor(d_bg) in a 256-bin histogram.
/// T for the next frame = clamp(k_noise * median(d_bg), t_min, t_max), the median read from that
/// histogram with linear interpolation inside its bin: a robust noise level, since most pixels
/// are background. The first frame's threshold is t_min.
class BackgroundModel {
public:
    BackgroundModel(const BackgroundConfig& config, const HsvBinning& binning)
        : config_(config), binning_(binning), lut_((binning.validate("BackgroundModel"), binning)) {
        config_.validate("BackgroundModel");
        threshold_ = config_.t_min;
    }

    const BackgroundConfig& config() const { return config_; }
    const HsvBinning& binning() const { return binning_; }
    bool initialized() const { return rows_ > 0; }
    Index rows() const { return rows_; }
    Index cols() const { return cols_; }
    long frame_count() const { return frame_count_; }
    double threshold() const { return threshold_; }
    const std::vector<float>& background() const { return background_; }
    const std::array<std::int64_t, 256>& difference_histogram() const { return hist_; }

    void reset() {
        rows_ = cols_ = 0;
        frame_count_ = 0;
        background_.clear();
        previous_.clear();
        threshold_ = config_.t_min;
        hist_.fill(0);
    }

    /// Set the background (rows x cols x 3 floats, BGR); the previous frame becomes its rounding.
    void set_background(const float* bgr, Index rows, Index cols) {
        rows_ = rows;
        cols_ = cols;
        const size_t n = static_cast<size_t>(rows * cols * 3);
        background_.assign(bgr, bgr + n);
        previous_.resize(n);
        for (size_t i = 0; i < n; ++i) {
            const float v = std::min(std::max(background_[i], 0.0f), 255.0f);
            previous_[i] = static_cast<std::uint8_t>(v + 0.5f);
        }
        threshold_ = config_.t_min;
        hist_.fill(0);
    }

    /// One frame (rows x cols BGR, `row_stride` bytes a row). Writes `bins` (rows x cols) and
    /// `mask` (rows x cols, 255 = foreground), both packed.
    void apply(const std::uint8_t* bgr, Index rows, Index cols, Index row_stride, std::int16_t* bins,
               std::uint8_t* mask) {
        if (!initialized()) {
            first_frame(bgr, rows, cols, row_stride, bins, mask);
            return;
        }
        require(rows == rows_ && cols == cols_, "BackgroundModel.apply",
                "frame shape changed from (" + std::to_string(rows_) + ", " + std::to_string(cols_) +
                    ", 3) to (" + std::to_string(rows) + ", " + std::to_string(cols) +
                    ", 3); call reset() before a new video");
        const float t = static_cast<float>(threshold_);
        const float t_low = static_cast<float>(config_.low_ratio * threshold_);
        const float a_bg = static_cast<float>(config_.alpha);
        const float a_fg = static_cast<float>(config_.alpha_fg);
        const float s_lo = static_cast<float>(config_.shadow_lo);
        const float s_chroma = static_cast<float>(config_.shadow_chroma);
        hist_.fill(0);
        std::int64_t* hist = hist_.data();
        for (Index y = 0; y < rows; ++y) {
            const std::uint8_t* px = bgr + y * row_stride;
            float* bg = background_.data() + y * cols * 3;
            std::uint8_t* prev = previous_.data() + y * cols * 3;
            std::int16_t* o = bins + y * cols;
            std::uint8_t* m = mask + y * cols;
            for (Index x = 0; x < cols; ++x) {
                const int b = px[3 * x], g = px[3 * x + 1], r = px[3 * x + 2];
                o[x] = static_cast<std::int16_t>(lut_.bin(b, g, r));
                const float fb = static_cast<float>(b), fg = static_cast<float>(g),
                            fr = static_cast<float>(r);
                float* q = bg + 3 * x;
                const float eb = fb - q[0], eg = fg - q[1], er = fr - q[2];
                const float d_bg = std::max(std::abs(eb), std::max(std::abs(eg), std::abs(er)));
                std::uint8_t* p = prev + 3 * x;
                const int d_prev = std::max(std::abs(b - p[0]),
                                            std::max(std::abs(g - p[1]), std::abs(r - p[2])));
                const bool cand = d_bg > t || (static_cast<float>(d_prev) > t && d_bg > t_low);
                bool shadow = false;
                if (cand) {
                    // darker by a bounded ratio, same chromaticity: |I_c sB - B_c sI| <= k sI sB
                    const float s_i = fb + fg + fr, s_b = q[0] + q[1] + q[2];
                    if (s_i < s_b && s_i >= s_lo * s_b && s_i > 0.0f) {
                        const float tol = s_chroma * s_i * s_b;
                        shadow = std::abs(fb * s_b - q[0] * s_i) <= tol &&
                                 std::abs(fg * s_b - q[1] * s_i) <= tol &&
                                 std::abs(fr * s_b - q[2] * s_i) <= tol;
                    }
                }
                const bool fore = cand && !shadow;
                m[x] = fore ? 255 : 0;
                ++hist[std::min(static_cast<int>(d_bg), 255)];
                // background_c += a (frame_c - background_c)   (selective running average)
                const float a = cand ? a_fg : a_bg;
                q[0] = q[0] + a * eb;
                q[1] = q[1] + a * eg;
                q[2] = q[2] + a * er;
                p[0] = static_cast<std::uint8_t>(b);
                p[1] = static_cast<std::uint8_t>(g);
                p[2] = static_cast<std::uint8_t>(r);
            }
        }
        threshold_ = next_threshold();
        ++frame_count_;
    }

private:
    void first_frame(const std::uint8_t* bgr, Index rows, Index cols, Index row_stride,
                     std::int16_t* bins, std::uint8_t* mask) {
        rows_ = rows;
        cols_ = cols;
        background_.resize(static_cast<size_t>(rows * cols * 3));
        previous_.resize(static_cast<size_t>(rows * cols * 3));
        for (Index y = 0; y < rows; ++y) {
            const std::uint8_t* px = bgr + y * row_stride;
            for (Index x = 0; x < cols * 3; ++x) {
                background_[static_cast<size_t>(y * cols * 3 + x)] = static_cast<float>(px[x]);
                previous_[static_cast<size_t>(y * cols * 3 + x)] = px[x];
            }
            for (Index x = 0; x < cols; ++x)
                bins[y * cols + x] =
                    static_cast<std::int16_t>(lut_.bin(px[3 * x], px[3 * x + 1], px[3 * x + 2]));
        }
        std::fill(mask, mask + rows * cols, std::uint8_t(0));
        threshold_ = config_.t_min;
        hist_.fill(0);
        ++frame_count_;
    }

    double next_threshold() const {
        const double half = 0.5 * static_cast<double>(rows_ * cols_);
        double cum = 0.0, median = 255.0;
        for (int i = 0; i < 256; ++i) {
            const double c = static_cast<double>(hist_[static_cast<size_t>(i)]);
            if (cum + c >= half) {
                median = i + (half - cum) / c;
                break;
            }
            cum += c;
        }
        return std::min(std::max(config_.k_noise * median, config_.t_min), config_.t_max);
    }

    BackgroundConfig config_;
    HsvBinning binning_;
    HsvLut lut_;
    Index rows_ = 0, cols_ = 0;
    long frame_count_ = 0;
    double threshold_ = 0.0;
    std::vector<float> background_;
    std::vector<std::uint8_t> previous_;
    std::array<std::int64_t, 256> hist_{};
};

/// Bins with background set to -1: out = mask == 0 ? -1 : bins.
inline void mask_bins(const std::int16_t* bins, Index rows, Index cols, const std::uint8_t* mask,
                      Index mask_stride, std::int16_t* out) {
    for (Index y = 0; y < rows; ++y) {
        const std::int16_t* src = bins + y * cols;
        const std::uint8_t* m = mask + y * mask_stride;
        std::int16_t* o = out + y * cols;
        for (Index x = 0; x < cols; ++x) o[x] = m[x] ? src[x] : std::int16_t(-1);
    }
}

}  // namespace pftrack
