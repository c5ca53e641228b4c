#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "arrays.hpp"
#include "pftrack/background.hpp"
#include "pftrack/histogram.hpp"
#include "pftrack/integral_histogram.hpp"
#include "pftrack/hsv.hpp"
#include "pftrack/likelihood.hpp"

namespace py = pybind11;
using namespace pftrack;

namespace {

/// The HsvLut of the last binning asked for (tables of ~450 KB, built once per binning): the
/// same bins as hsv_bin_of for every colour (tests/core check it), several times faster.
std::shared_ptr<const HsvLut> cached_lut(const HsvBinning& p) {
    static std::mutex mu;
    static std::shared_ptr<const HsvLut> lut;
    static HsvBinning key;
    const std::lock_guard<std::mutex> lock(mu);
    if (!lut || key.n_h != p.n_h || key.n_s != p.n_s || key.n_v != p.n_v ||
        key.s_min != p.s_min || key.v_min != p.v_min) {
        lut = std::make_shared<const HsvLut>(p);
        key = p;
    }
    return lut;
}

}  // namespace

Kernel parse_kernel(const std::string& name, const char* fn) {
    if (name == "uniform") return Kernel::kUniform;
    if (name == "epanechnikov") return Kernel::kEpanechnikov;
    fail(fn, "kernel is '" + name + "', expected 'uniform' or 'epanechnikov'");
}

BoxPath parse_method(const std::string& name, const char* fn) {
    if (name == "auto") return BoxPath::kAuto;
    if (name == "direct") return BoxPath::kDirect;
    if (name == "integral") return BoxPath::kIntegral;
    fail(fn, "method is '" + name + "', expected 'auto', 'direct' or 'integral'");
}

void register_histogram(py::module_& m) {
    py::class_<BinnedImage, std::shared_ptr<BinnedImage>>(
        m, "BinnedImage", "A frame's colour-bin index per pixel (-1: never counted).")
        .def(py::init([](const py::object& bins_in, const py::object& n_in) {
                 const char* fn = "BinnedImage";
                 // n_bins: any integer (not a bool), checked here rather than by pybind11's
                 // conversion to int, whose refusal of 2**31 lists every signature instead
                 if (py::isinstance<py::bool_>(n_in) || !PyIndex_Check(n_in.ptr()))
                     throw py::type_error(std::string(fn) + ": n_bins must be an int, got " +
                                          bind::type_name(n_in));
                 const auto index = py::reinterpret_steal<py::object>(PyNumber_Index(n_in.ptr()));
                 if (!index) {  // an array of floats, or of several values: was NumPy's "only
                     PyErr_Clear();  // integer scalar arrays can be converted ...", no name
                     const py::array a = py::array::ensure(n_in);
                     throw py::type_error(
                         std::string(fn) + ": n_bins must be an int, got " +
                         bind::type_name(n_in) +
                         (a ? " of " + bind::dtype_name(a) : ""));
                 }
                 int overflow = 0;
                 const long long wide = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
                 if (overflow != 0 || wide < 1 || wide > 32767)
                     throw py::value_error(std::string(fn) + ": n_bins is " +
                                           py::str(index).cast<std::string>() +
                                           ", expected an integer in [1, 32767]");
                 const int n_bins = static_cast<int>(wide);
                 // bins: an array, or what NumPy makes one of (a list of rows)
                 const py::array given = py::array::ensure(bins_in);
                 if (!given)
                     throw py::value_error(std::string(fn) + ": bins must be an (H, W) array of "
                                           "bin indices, got a " +
                                           bind::type_name(bins_in) +
                                           " NumPy cannot make one of");
                 const char kind = given.dtype().kind();
                 if (kind != 'b' && kind != 'i' && kind != 'u' && kind != 'f')
                     throw py::type_error(std::string(fn) + ": bins must hold bin indices "
                                          "(integers), got " + bind::dtype_name(given));
                 require(given.ndim() == 2, fn, "bins ndim", given.ndim(), 2);
                 require(given.shape(0) > 0 && given.shape(1) > 0, fn, "bins is empty");
                 require(n_bins >= 1 && n_bins <= 32767, fn, "n_bins", n_bins, "in [1, 32767]");
                 auto img = std::make_shared<BinnedImage>(given.shape(0), given.shape(1), n_bins);
                 // int16 as it comes; any other array checked as given before it becomes int16
                 // (a cast first would wrap 70000 to 4464 and read 1.5 as 1)
                 const auto copy = [&](const auto& bins) {
                     const auto* src = bins.data();
                     for (size_t i = 0; i < img->data.size(); ++i) {
                         const auto v = src[i];
                         // 1.5 said "expected in [-1, n_bins)", which 1.5 is: say it is no index
                         if (!(v == std::floor(v)))
                             require(false, fn, "bins value", v,
                                     "an integer: bins must be an integer array of bin indices "
                                     "in [-1, n_bins)");
                         require(v >= -1 && v < n_bins, fn, "bins value", v, "in [-1, n_bins)");
                         img->data[i] = static_cast<std::int16_t>(v);
                     }
                 };
                 if (given.dtype().is(py::dtype::of<std::int16_t>()))
                     copy(py::array_t<std::int16_t, py::array::c_style | py::array::forcecast>::ensure(given));
                 else
                     copy(py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(given));
                 return img;
             }),
             py::arg("bins"), py::arg("n_bins"))
        .def(
            "__copy__", [](const BinnedImage& b) { return std::make_shared<BinnedImage>(b); },
            "A copy with every bin computed (copy.copy and copy.deepcopy).")
        .def(
            "__deepcopy__",
            [](const BinnedImage& b, const py::dict&) { return std::make_shared<BinnedImage>(b); },
            py::arg("memo"))
        .def(
            "__reduce__",
            [](const py::object& self) {  // pickled as BinnedImage(bins, n_bins)
                return py::make_tuple(py::type::of(self),
                                      py::make_tuple(self.attr("bins"), self.attr("n_bins")));
            })
        .def_property_readonly("n_bins", [](const BinnedImage& b) { return b.n_bins; })
        .def_property_readonly("shape", [](const BinnedImage& b) { return py::make_tuple(b.rows, b.cols); })
        .def_property_readonly(
            "tiles_pending", [](const BinnedImage& b) { return b.lazy ? b.lazy->pending() : Index(0); },
            "Tiles (16 x 32 pixels) a lazy image has not binned yet (0: every bin computed)")
        .def_property_readonly(
            "bins",
            [](py::object self) {
                const auto& b = self.cast<const BinnedImage&>();
                {
                    py::gil_scoped_release nogil;  // safe: the C++ image only, kept by `self`
                    b.complete();  // a lazy image bins what no reader has asked for yet
                }
                py::array_t<std::int16_t> a({b.rows, b.cols},
                                            {static_cast<py::ssize_t>(b.cols * 2), py::ssize_t(2)},
                                            b.data.data(), self);
                py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
                return a;
            },
            "(H, W) int16 read-only view of the bins");

    m.def(
        "hsv_bins",
        [](const py::object& frame_in, std::optional<py::array> mask, int n_h, int n_s, int n_v,
           double s_min, double v_min, bool lazy) {
            const char* fn = "hsv_bins";
            const py::array frame = bind::bgr_image(frame_in, fn, "frame");
            const HsvBinning p{n_h, n_s, n_v, s_min, v_min};
            p.validate(fn);
            const auto rows = frame.shape(0), cols = frame.shape(1);
            const std::uint8_t* mptr = nullptr;
            py::ssize_t mstride = 0;
            if (mask) {
                bind::check_mask(*mask, rows, cols, fn);
                mptr = static_cast<const std::uint8_t*>(mask->data());
                mstride = mask->strides(0);
            }
            auto img = std::make_shared<BinnedImage>(rows, cols, p.n_bins());
            const auto* src = static_cast<const std::uint8_t*>(frame.data());
            const auto stride = frame.strides(0);
            const std::shared_ptr<const HsvLut> lut = cached_lut(p);
            if (lazy) {
                // Its own packed copies of the frame (and mask): the caller may change or drop
                // them before a reader bins a tile.
                // (not zeroed first: every byte is copied below)
                using Bytes = std::vector<std::uint8_t, DefaultInitAllocator<std::uint8_t>>;
                auto bgr = std::make_shared<Bytes>(static_cast<size_t>(rows * cols * 3));
                auto m = std::make_shared<Bytes>(mptr ? static_cast<size_t>(rows * cols) : size_t(0));
                {
                    py::gil_scoped_release nogil;  // safe: raw buffers, held alive by the caller
                    for (py::ssize_t y = 0; y < rows; ++y) {
                        std::memcpy(bgr->data() + y * cols * 3, src + y * stride,
                                    static_cast<size_t>(cols * 3));
                        if (mptr)
                            std::memcpy(m->data() + y * cols, mptr + y * mstride,
                                        static_cast<size_t>(cols));
                    }
                }
                std::int16_t* out = img->data.data();
                const Index c = cols;
                img->make_lazy([bgr, m, lut, out, c](Index y0, Index y1, Index x0, Index x1) {
                    const std::uint8_t* mk = m->empty() ? nullptr : m->data() + y0 * c + x0;
                    hsv_bins_image(*lut, bgr->data() + (y0 * c + x0) * 3, y1 - y0, x1 - x0, c * 3,
                                   mk, c, out + y0 * c + x0, c);
                });
                return img;
            }
            {
                py::gil_scoped_release nogil;  // safe: raw buffers only, held alive by the caller
                hsv_bins_image(*lut, src, rows, cols, stride, mptr, mstride, img->data.data());
            }
            return img;
        },
        py::arg("frame"), py::arg("mask") = py::none(), py::arg("n_h") = 10, py::arg("n_s") = 10,
        py::arg("n_v") = 10, py::arg("s_min") = 0.1, py::arg("v_min") = 0.2,
        py::arg("lazy") = false,
        "Bin index per pixel of a BGR uint8 frame (H, W, 3); mask (H, W) zero = background. "
        "lazy: each tile binned when first read (same bins).");

    m.def(
        "box_histograms",
        [](const BinnedImage& image, Eigen::Ref<const RowMatrixXd> boxes, const std::string& kernel,
           const std::string& method) {
            const char* fn = "box_histograms";
            check_boxes(boxes, fn, "boxes");
            require_size(static_cast<double>(boxes.rows()) * image.n_bins, fn,
                         "the (K, B) histograms of " + std::to_string(boxes.rows()) + " boxes");
            const Kernel k = parse_kernel(kernel, fn);
            const BoxPath path = parse_method(method, fn);
            py::gil_scoped_release nogil;  // safe: Eigen views and the C++ image only
            return box_histograms(image.lazy_view(), boxes, k, path);
        },
        py::arg("image"), py::arg("boxes"), py::arg("kernel") = "uniform",
        py::arg("method") = "auto",
        "Normalised histograms (K, B) of boxes (K, 4) = (cx, cy, w, h); empty box -> zero row. "
        "method: as box_weights.");

    m.def(
        "box_weights",
        [](const BinnedImage& image, Eigen::Ref<const RowMatrixXd> boxes,
           Eigen::Ref<const Eigen::VectorXd> ref, double lam, const std::string& kernel,
           const std::string& method, Index step) {
            const char* fn = "box_weights";
            check_boxes(boxes, fn, "boxes");
            check_lambda(lam, fn);
            const Kernel k = parse_kernel(kernel, fn);
            const BoxPath path = parse_method(method, fn);
            require(step >= 1 && step <= kMaxLatticeStep, fn, "step", step, "in [1, 64]");
            py::gil_scoped_release nogil;  // safe: Eigen views and the C++ image only
            require(boxes.rows() > 0, fn, "boxes rows", boxes.rows(), ">= 1");
            const Eigen::VectorXd sq = sqrt_reference(ref, image.n_bins, fn);
            Eigen::VectorXd rho(boxes.rows()), counted(boxes.rows());
            box_coefficients(image.lazy_view(), boxes, sq.data(), k, path, rho.data(),
                             counted.data(), step);
            return weights_from_rho(rho, lam, fn);
        },
        py::arg("image"), py::arg("boxes"), py::arg("ref"), py::arg("lam") = 20.0,
        py::arg("kernel") = "uniform", py::arg("method") = "auto", py::arg("step") = 1,
        "Weights (K,) ~ exp(-lam D^2) of boxes (K, 4) against ref (B,): box_histograms + "
        "bhattacharyya_weights fused, no (K, B) matrix. method: 'auto', 'direct' or 'integral' "
        "(uniform-kernel counts from integral histograms of groups of overlapping boxes; same "
        "result). step > 1: only the pixels whose column and row are multiples of step count "
        "(each box directly; method is then ignored).");
}
