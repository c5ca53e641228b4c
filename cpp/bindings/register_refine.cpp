#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <optional>

#include "pftrack/refine.hpp"
#include "arrays.hpp"

namespace py = pybind11;
using namespace pftrack;

void register_refine(py::module_& m) {
    m.def(
        "refine_boxes",
        [](Eigen::Ref<const RowMatrixXd> boxes, const py::object& mask_in, double fraction,
           double min_cover, std::optional<double> leg_fill, double min_height) {
            const char* fn = "refine_boxes";
            const py::array mask = bind::mask_array(mask_in, fn);
            require(boxes.cols() == 4, fn, "boxes cols", boxes.cols(), "4 (left, top, w, h)");
            require_finite(boxes, fn, "boxes");
            bind::check_mask_dtype(mask, fn);  // any (H, W): not check_mask's frame size
            require(mask.ndim() == 2, fn, "mask must be a (H, W) array");
            require(mask.strides(1) == 1 && mask.strides(0) > 0, fn,
                    "mask must be packed along rows (use numpy.ascontiguousarray)");
            require(std::isfinite(fraction) && fraction >= 0.0 && fraction < 1.0, fn, "fraction",
                    fraction, "in [0, 1)");
            require(std::isfinite(min_cover) && min_cover >= 0.0 && min_cover <= 1.0, fn,
                    "min_cover", min_cover, "in [0, 1]");
            if (leg_fill)
                require(std::isfinite(*leg_fill) && *leg_fill >= 0.0 && *leg_fill <= 1.0, fn,
                        "leg_fill", *leg_fill, "None or in [0, 1]");
            require(std::isfinite(min_height) && min_height >= 0.0 && min_height <= 1.0, fn,
                    "min_height", min_height, "in [0, 1]");
            const double fill = leg_fill.value_or(-1.0);  // the core's "off"

            RowMatrixXd out = boxes;
            const auto* data = static_cast<const std::uint8_t*>(mask.data());
            const Index rows = mask.shape(0), cols = mask.shape(1), stride = mask.strides(0);
            {
                py::gil_scoped_release nogil;  // safe: `out` is ours, `mask` kept alive by the caller
                refine_boxes(out, data, rows, cols, stride, fraction, min_cover, fill, min_height);
            }
            return out;
        },
        py::arg("boxes"), py::arg("mask"), py::arg("fraction"), py::arg("min_cover"),
        py::arg("leg_fill") = py::none(), py::arg("min_height") = 0.0,
        "Boxes (K, 4) left, top, w, h shrunk to the foreground of mask (H, W) uint8 or bool; "
        "with leg_fill in [0, 1], mask 255/127/0 and boxes grown down through shadowed legs; "
        "a box refined to under min_height of its height keeps its top and height.");
}
