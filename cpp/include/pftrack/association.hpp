// The cost of pairing tracks with detections (python/pftrack/tracking/association.py), in one
// pass over the pairs: what the NumPy of `associate` computed in about 40 calls on small arrays.
#pragma once

#include <algorithm>
#include <cmath>

#include "check.hpp"
#include "types.hpp"

namespace pftrack {

/// Cost (T, D) of every (track, detection) pair, `forbidden` where the gate forbids it.
///
/// Boxes are (left, top, w, h). A pair costs
///   (1 - IoU) + colour_weight (1 - rho) + min(dist / radius, 2),
/// dist the distance of the boxes' centres, radius = match_distance height (1 + 0.25 min(coasted,
/// 8)) the track's; it is gated in when IoU >= match_iou or dist <= radius. `rho` (T, D) holds
/// the colour coefficients. The floats of the NumPy reference (tests/reference/kernels.py:
/// association_cost), in its order of operations; an empty union has IoU 0.
inline RowMatrixXd association_cost(const Eigen::Ref<const RowMatrixXd>& track_boxes,
                                    const Eigen::Ref<const Eigen::VectorXd>& heights,
                                    const Eigen::Ref<const Eigen::VectorXd>& coasted,
                                    const Eigen::Ref<const RowMatrixXd>& rho,
                                    const Eigen::Ref<const RowMatrixXd>& boxes,
                                    double match_distance, double colour_weight, double match_iou,
                                    double forbidden) {
    const char* fn = "association_cost";
    const Index nt = track_boxes.rows(), nd = boxes.rows();
    require(track_boxes.cols() == 4, fn, "track_boxes cols", track_boxes.cols(), "4 (x, y, w, h)");
    require(boxes.cols() == 4, fn, "boxes cols", boxes.cols(), "4 (x, y, w, h)");
    require(heights.size() == nt, fn, "heights size", heights.size(), "one per track");
    require(coasted.size() == nt, fn, "coasted size", coasted.size(), "one per track");
    require(rho.rows() == nt && rho.cols() == nd, fn,
            "rho must have shape (T, D): one coefficient per track and detection");
    require_bounded(track_boxes, 1e9, fn, "track_boxes");
    require_bounded(boxes, 1e9, fn, "boxes");
    require((track_boxes.rightCols(2).array() >= 0.0).all() &&
                (boxes.rightCols(2).array() >= 0.0).all(),
            fn, "boxes must have w, h >= 0");
    require_finite(rho, fn, "rho");
    require_finite(coasted, fn, "coasted");
    require((coasted.array() >= 0.0).all(), fn, "coasted must be >= 0");
    require(std::isfinite(colour_weight) && std::isfinite(match_iou) && std::isfinite(forbidden),
            fn, "colour_weight, match_iou and forbidden must be finite");
    Eigen::VectorXd radius(nt);
    for (Index i = 0; i < nt; ++i) {
        radius(i) = match_distance * heights(i) * (1.0 + 0.25 * std::min(coasted(i), 8.0));
        require(std::isfinite(radius(i)) && radius(i) > 0.0, fn,
                "match_distance * heights must be finite and > 0 (the distance gate's radius)");
    }
    RowMatrixXd cost(nt, nd);
    for (Index i = 0; i < nt; ++i) {
        const double ax0 = track_boxes(i, 0), ay0 = track_boxes(i, 1);
        const double aw = track_boxes(i, 2), ah = track_boxes(i, 3);
        const double ax1 = ax0 + aw, ay1 = ay0 + ah, area = aw * ah;
        const double tx = ax0 + aw / 2, ty = ay0 + ah / 2;
        for (Index j = 0; j < nd; ++j) {
            const double bx0 = boxes(j, 0), by0 = boxes(j, 1), bw = boxes(j, 2), bh = boxes(j, 3);
            // min and max as NumPy's (a signed zero aside, which changes no cost)
            const double iw = std::max(std::min(ax1, bx0 + bw) - std::max(ax0, bx0), 0.0);
            const double ih = std::max(std::min(ay1, by0 + bh) - std::max(ay0, by0), 0.0);
            const double inter = iw * ih;
            const double uni = area + bw * bh - inter;
            const double iou = uni > 0.0 ? inter / uni : 0.0;
            const double dx = tx - (bx0 + bw / 2), dy = ty - (by0 + bh / 2);
            const double dist = std::sqrt(dx * dx + dy * dy);
            const double c = (1.0 - iou) + colour_weight * (1.0 - rho(i, j)) +
                             std::min(dist / radius(i), 2.0);
            cost(i, j) = (iou >= match_iou || dist <= radius(i)) ? c : forbidden;
        }
    }
    return cost;
}

}  // namespace pftrack
