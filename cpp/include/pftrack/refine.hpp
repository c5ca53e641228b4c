// Box refinement: shrink loose detection boxes to the extent of their foreground
// (python/pftrack/detection/refine.py documents the rule; tests/reference/refine.py is its
// NumPy reference, which this matches exactly).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "check.hpp"
#include "types.hpp"

namespace pftrack {

/// Refines each row (left, top, width, height) of `boxes` in place against the mask (`rows` x
/// `cols` bytes, `stride` bytes a row; non-zero = foreground). A box is clipped to whole pixels
/// [floor(x), ceil(x + w)) x [floor(y), ceil(y + h)) inside the image; one under 3 pixels a side,
/// or whose foreground share is below `min_cover`, is left as it is. Otherwise the rows and
/// columns whose foreground share exceeds `fraction` times the densest one's are kept and the
/// box spans the first to the last kept one. Shares are count / length in double, as NumPy's
/// mean of a boolean patch gives them, so the comparisons are the reference's to the bit.
///
/// With `leg_fill` in [0, 1] the mask has shadows (255 foreground, 127 shadow, 0 background):
/// only 255 is foreground for the steps above, and a refined box then grows down, row by row
/// below its last row and down to the clipped box's last row, while the row's share of
/// foreground or shadow pixels between its first and last column is at least `leg_fill`:
/// legs that the shadow test took for shadow (dark trousers on a grey path), which a cast
/// shadow beside the feet, outside those columns, does not extend. A negative `leg_fill`: no
/// growing, and every non-zero pixel is foreground.
///
/// A refined box whose height (after the growing) is under `min_height` times the clipped
/// box's keeps the box's own top and height: only its columns are refined. 0: no such test.
inline void refine_boxes(Eigen::Ref<RowMatrixXd> boxes, const std::uint8_t* mask, Index rows,
                         Index cols, Index stride, double fraction, double min_cover,
                         double leg_fill = -1.0, double min_height = 0.0) {
    const bool legs = leg_fill >= 0.0;
    const std::uint8_t level = legs ? 127 : 0;  // foreground: mask > level
    std::vector<std::int32_t> col_count, row_count;
    for (Index k = 0; k < boxes.rows(); ++k) {
        const double x = boxes(k, 0), y = boxes(k, 1), w = boxes(k, 2), h = boxes(k, 3);
        const double fx0 = std::max(0.0, std::floor(x)), fx1 = std::min(double(cols), std::ceil(x + w));
        const double fy0 = std::max(0.0, std::floor(y)), fy1 = std::min(double(rows), std::ceil(y + h));
        if (!(fx1 - fx0 >= 3.0 && fy1 - fy0 >= 3.0)) continue;  // also NaN
        const auto x0 = static_cast<Index>(fx0), x1 = static_cast<Index>(fx1);
        const auto y0 = static_cast<Index>(fy0), y1 = static_cast<Index>(fy1);
        const Index pw = x1 - x0, ph = y1 - y0;
        col_count.assign(static_cast<size_t>(pw), 0);
        row_count.assign(static_cast<size_t>(ph), 0);
        std::int64_t total = 0;
        for (Index r = 0; r < ph; ++r) {
            const std::uint8_t* m = mask + (y0 + r) * stride + x0;
            std::int32_t n = 0;
            for (Index c = 0; c < pw; ++c) {
                const std::int32_t on = m[c] > level;
                n += on;
                col_count[static_cast<size_t>(c)] += on;
            }
            row_count[static_cast<size_t>(r)] = n;
            total += n;
        }
        if (static_cast<double>(total) / static_cast<double>(pw * ph) < min_cover) continue;
        // share of a column: count / rows of the patch; of a row: count / its columns
        const double dh = static_cast<double>(ph), dw = static_cast<double>(pw);
        const double col_max = *std::max_element(col_count.begin(), col_count.end()) / dh;
        const double row_max = *std::max_element(row_count.begin(), row_count.end()) / dw;
        Index c0 = -1, c1 = -1, r0 = -1, r1 = -1;
        for (Index c = 0; c < pw; ++c)
            if (col_count[static_cast<size_t>(c)] / dh > fraction * col_max) {
                if (c0 < 0) c0 = c;
                c1 = c;
            }
        for (Index r = 0; r < ph; ++r)
            if (row_count[static_cast<size_t>(r)] / dw > fraction * row_max) {
                if (r0 < 0) r0 = r;
                r1 = r;
            }
        if (c0 < 0 || r0 < 0) continue;  // fraction >= 1: nothing exceeds the densest
        if (legs) {
            const double span = static_cast<double>(c1 + 1 - c0);
            while (r1 + 1 < ph) {
                const std::uint8_t* m = mask + (y0 + r1 + 1) * stride + x0;
                std::int32_t n = 0;
                for (Index c = c0; c <= c1; ++c) n += m[c] != 0;
                if (static_cast<double>(n) / span < leg_fill) break;
                ++r1;
            }
        }
        boxes(k, 0) = static_cast<double>(x0 + c0);
        boxes(k, 2) = static_cast<double>(c1 + 1 - c0);
        if (static_cast<double>(r1 + 1 - r0) < min_height * dh) continue;  // rows: the box's own
        boxes(k, 1) = static_cast<double>(y0 + r0);
        boxes(k, 3) = static_cast<double>(r1 + 1 - r0);
    }
}

}  // namespace pftrack
