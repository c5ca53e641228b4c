#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "pftrack/blobs.hpp"
#include "arrays.hpp"

namespace py = pybind11;
using namespace pftrack;

namespace {

std::vector<BlobRect> to_rects(const Eigen::Ref<const RowMatrixXd>& boxes, const char* fn) {
    require(boxes.cols() == 4, fn, "boxes cols", boxes.cols(), "4 (left, top, w, h)");
    require_finite(boxes, fn, "boxes");
    std::vector<BlobRect> out(static_cast<std::size_t>(boxes.rows()));
    for (Index i = 0; i < boxes.rows(); ++i)
        out[static_cast<std::size_t>(i)] = {boxes(i, 0), boxes(i, 1), boxes(i, 2), boxes(i, 3)};
    return out;
}

SizeLines to_lines(const Eigen::Ref<const RowMatrixXd>& coef, const char* fn) {
    require(coef.rows() == 2 && coef.cols() == 2, fn,
            "coefficients must have shape (2, 2) [[h_slope, h_intercept], [w_slope, w_intercept]]");
    require_finite(coef, fn, "coefficients");
    return {coef(0, 0), coef(0, 1), coef(1, 0), coef(1, 1)};
}

void require_positive(double v, const char* fn, const char* what) {
    require(std::isfinite(v) && v > 0.0, fn, what, v, "a finite value > 0");
}

}  // namespace

void register_blobs(py::module_& m) {
    m.def(
        "blob_boxes",
        [](const py::object& mask_in, double min_area, double max_area, double min_aspect,
           double max_aspect, double min_fill, double person_aspect,
           std::optional<Eigen::Ref<const RowMatrixXd>> size_lines, double split_ratio,
           double split_max_height, double merge_slack, double split_valley) {
            const char* fn = "blob_boxes";
            const py::array mask = bind::mask_array(mask_in, fn);
            require(mask.ndim() == 2, fn, "mask must be a (H, W) array");
            bind::check_mask(mask, mask.shape(0), mask.shape(1), fn);  // uint8 or bool, packed
            require(std::isfinite(min_area) && std::isfinite(max_area) && 0.0 <= min_area &&
                        min_area <= max_area && max_area <= 1.0,
                    fn, "min_area, max_area must satisfy 0 <= min_area <= max_area <= 1");
            require(std::isfinite(max_aspect) && min_aspect > 0.0 && min_aspect <= max_aspect, fn,
                    "min_aspect, max_aspect must satisfy 0 < min_aspect <= max_aspect");
            require(min_fill >= 0.0 && min_fill <= 1.0, fn, "min_fill", min_fill, "in [0, 1]");
            require(std::isfinite(person_aspect) && person_aspect >= 0.0, fn, "person_aspect",
                    person_aspect, "a finite value >= 0");
            require(std::isfinite(split_valley) && split_valley >= 0.0, fn, "split_valley",
                    split_valley, "a finite value >= 0");
            std::optional<SizeLines> lines;
            if (size_lines) {
                lines = to_lines(*size_lines, fn);
                require_positive(split_ratio, fn, "split_ratio");
                require_positive(split_max_height, fn, "split_max_height");
                require_positive(merge_slack, fn, "merge_slack");
            }
            const auto* data = static_cast<const std::uint8_t*>(mask.data());
            const Index rows = mask.shape(0), cols = mask.shape(1), stride = mask.strides(0);
            std::vector<BlobRect> rects;
            std::vector<double> fill;
            {
                py::gil_scoped_release nogil;  // safe: plain buffers, `mask` kept alive by the caller
                blob_boxes(data, rows, cols, stride,
                           {min_area, max_area, min_aspect, max_aspect, min_fill}, person_aspect,
                           lines ? &*lines : nullptr, split_ratio, split_max_height, merge_slack,
                           rects, fill, split_valley);
            }
            RowMatrixXd out(static_cast<Index>(rects.size()), 4);
            Eigen::VectorXd f(static_cast<Index>(fill.size()));
            for (std::size_t i = 0; i < rects.size(); ++i) {
                const auto k = static_cast<Index>(i);
                out.row(k) << rects[i].x, rects[i].y, rects[i].w, rects[i].h;
                f(k) = fill[i];
            }
            return py::make_tuple(out, f);
        },
        py::arg("mask"), py::arg("min_area"), py::arg("max_area"), py::arg("min_aspect"),
        py::arg("max_aspect"), py::arg("min_fill"), py::arg("person_aspect"),
        py::arg("size_lines"), py::arg("split_ratio"), py::arg("split_max_height"),
        py::arg("merge_slack"), py::arg("split_valley") = 1.0,
        "Boxes (K, 4) and fills (K,) of the blobs of mask (H, W) uint8, unsorted; a group is "
        "cut only where its column profile falls to split_valley times its sides' peaks "
        "(>= 1: at every minimum).");

    m.def(
        "split_count",
        [](Eigen::Ref<const RowMatrixXd> boxes, Eigen::Ref<const RowMatrixXd> size_lines,
           double split_ratio, double split_max_height) {
            const char* fn = "split_count";
            const std::vector<BlobRect> b = to_rects(boxes, fn);
            const SizeLines s = to_lines(size_lines, fn);
            const std::vector<std::int64_t> n = split_count(b, s, split_ratio, split_max_height);
            return py::array_t<std::int64_t>(static_cast<py::ssize_t>(n.size()), n.data());
        },
        py::arg("boxes"), py::arg("size_lines"), py::arg("split_ratio"),
        py::arg("split_max_height"), "People side by side in each box (K, 4): (K,) int64.");

    m.def(
        "merge_fragments",
        [](Eigen::Ref<const RowMatrixXd> boxes, Eigen::Ref<const RowMatrixXd> size_lines,
           double merge_slack) {
            const char* fn = "merge_fragments";
            const std::vector<BlobRect> b = to_rects(boxes, fn);
            const SizeLines s = to_lines(size_lines, fn);
            return merge_fragments(b, s, merge_slack);
        },
        py::arg("boxes"), py::arg("size_lines"), py::arg("merge_slack"),
        "Groups (list of lists of indices) of the boxes (K, 4) that are one person's fragments.");

    m.def(
        "extend_legs",
        [](const py::object& mask_in, Eigen::Ref<const RowMatrixXd> boxes,
           Eigen::Ref<const RowMatrixXd> size_lines, double min_height, double row_fill) {
            const char* fn = "extend_legs";
            const py::array mask = bind::mask_array(mask_in, fn);
            require(mask.ndim() == 2, fn, "mask must be a (H, W) array");
            bind::check_mask(mask, mask.shape(0), mask.shape(1), fn);  // uint8 or bool, packed
            std::vector<BlobRect> b = to_rects(boxes, fn);
            const SizeLines s = to_lines(size_lines, fn);
            require(std::isfinite(min_height) && min_height >= 0.0, fn, "min_height", min_height,
                    "a finite value >= 0");
            require(row_fill >= 0.0 && row_fill <= 1.0, fn, "row_fill", row_fill, "in [0, 1]");
            const auto* data = static_cast<const std::uint8_t*>(mask.data());
            const Index rows = mask.shape(0), cols = mask.shape(1), stride = mask.strides(0);
            {
                py::gil_scoped_release nogil;  // safe: plain buffers, `mask` kept alive by the caller
                extend_legs(data, rows, cols, stride, b, s, min_height, row_fill);
            }
            RowMatrixXd out(static_cast<Index>(b.size()), 4);
            for (std::size_t i = 0; i < b.size(); ++i)
                out.row(static_cast<Index>(i)) << b[i].x, b[i].y, b[i].w, b[i].h;
            return out;
        },
        py::arg("mask"), py::arg("boxes"), py::arg("size_lines"), py::arg("min_height"),
        py::arg("row_fill"),
        "Boxes (K, 4) of short people extended down through mask (H, W) rows (lost legs).");

    m.def(
        "size_fit",
        [](Eigen::Ref<const RowMatrixXd> samples) {
            const char* fn = "size_fit";
            require(samples.cols() == 3, fn, "samples cols", samples.cols(), "3 (foot y, h, w)");
            require_finite(samples, fn, "samples");
            SizeLines s;
            {
                py::gil_scoped_release nogil;  // safe: `samples` kept alive by the caller
                s = size_fit(samples.data(), samples.rows(), samples.outerStride());
            }
            RowMatrixXd out(2, 2);
            out << s.h_slope, s.h_intercept, s.w_slope, s.w_intercept;
            return out;
        },
        py::arg("samples"),
        "Size lines (2, 2) [[h_slope, h_intercept], [w_slope, w_intercept]] from samples (n, 3).");

    m.def(
        "theil_sen",
        [](Eigen::Ref<const Eigen::VectorXd> x, Eigen::Ref<const Eigen::VectorXd> y) {
            const char* fn = "theil_sen";
            require(x.size() == y.size(), fn, "y size", y.size(), "x's size");
            require_finite(x, fn, "x");
            require_finite(y, fn, "y");
            std::pair<double, double> r;
            {
                py::gil_scoped_release nogil;  // safe: x and y kept alive by the caller
                r = theil_sen(x.data(), y.data(), x.size());
            }
            return r;
        },
        py::arg("x"), py::arg("y"), "Theil-Sen (slope, intercept) of y against x, both (n,).");
}
