#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "pickling.hpp"
#include "pftrack/background.hpp"
#include "pftrack/ghost.hpp"
#include "pftrack/morphology.hpp"
#include "pftrack/parallel.hpp"

namespace py = pybind11;
using namespace pftrack;

namespace {

std::string shape_str(const py::array& a) {
    std::string s = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
    return s + (a.ndim() == 1 ? ",)" : ")");
}

py::array_t<std::uint8_t> new_mask(Index rows, Index cols) {
    return py::array_t<std::uint8_t>({static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(cols)});
}

/// The frame (H, W, 3) uint8 of the size of the model's (initialised) background.
py::array model_frame(const BackgroundModel& self, const py::object& frame_in, const char* fn) {
    py::array frame = bind::bgr_image(frame_in, fn, "frame");
    require(self.initialized(), fn, "the model has no background yet");
    require(frame.shape(0) == self.rows() && frame.shape(1) == self.cols(), fn,
            "frame shape is " + shape_str(frame) + ", expected (" + std::to_string(self.rows()) +
                ", " + std::to_string(self.cols()) + ", 3)");
    return frame;
}

/// A frame and a mask of the size of the model's (initialised) background.
void check_frame_and_mask(const BackgroundModel& self, const py::array& frame,
                          const py::array& mask, const char* fn) {
    require(self.initialized(), fn, "the model has no background yet");
    bind::check_bgr_image(frame, fn, "frame");
    require(frame.shape(0) == self.rows() && frame.shape(1) == self.cols(), fn,
            "frame shape is " + shape_str(frame) + ", expected (" + std::to_string(self.rows()) +
                ", " + std::to_string(self.cols()) + ", 3)");
    bind::check_mask(mask, self.rows(), self.cols(), fn);
}

/// A structuring element: (kh, kw) uint8 or bool, C-contiguous, each row one run.
std::vector<ElementRow> to_element(const py::array& k, const char* fn) {
    bind::check_mask_dtype(k, fn);
    if (!(k.ndim() == 2 && k.shape(0) >= 1 && k.shape(1) >= 1))
        fail(fn, "element must have shape (kh, kw) with kh, kw >= 1");
    if (!(k.strides(1) == 1 && k.strides(0) == k.shape(1)))
        fail(fn, "element must be C-contiguous");
    return element_rows(static_cast<const std::uint8_t*>(k.data()), k.shape(0), k.shape(1), fn);
}

/// `passes` of a (H, W) uint8/bool mask, checked, into a new mask: the packed path
/// (morphology.hpp `clean_packed_blocks`: `clean_packed` of the blocks of non-empty rows) for a
/// mask of two levels or three with 255, else the byte path (`morphology`, pass after pass
/// through a scratch mask).
py::array_t<std::uint8_t> mask_passes(const py::object& mask_in,
                                      const std::vector<std::pair<py::object, MorphOp>>& given,
                                      const char* fn) {
    const py::array mask = bind::mask_array(mask_in, fn);
    std::vector<std::vector<ElementRow>> elements;
    for (const auto& [element_in, op] : given) {
        const py::array element = bind::mask_array(element_in, fn, "element", "(kh, kw)");
        elements.push_back(to_element(element, fn));
    }
    if (!(mask.ndim() == 2 && mask.shape(0) > 0 && mask.shape(1) > 0))
        fail(fn, "mask must be a non-empty (H, W) array");
    bind::check_mask(mask, mask.shape(0), mask.shape(1), fn);
    std::vector<PackedPass> passes;
    for (size_t i = 0; i < given.size(); ++i) passes.push_back({&elements[i], given[i].second});
    const Index rows = mask.shape(0), cols = mask.shape(1);
    auto out = new_mask(rows, cols);
    std::uint8_t* optr = out.mutable_data();
    const auto* mptr = static_cast<const std::uint8_t*>(mask.data());
    const Index mstride = mask.strides(0);
    const bool simd = detail::avx2_allowed().load(std::memory_order_relaxed);
    {
        py::gil_scoped_release nogil;  // safe: raw buffers held by the caller / owned here
        // scratch kept per thread from frame to frame (each detector runs on one thread)
        thread_local PackedScratch packed;
        if (clean_packed_blocks(mptr, mstride, optr, rows, cols, passes, simd, packed)) return out;
        thread_local std::vector<std::uint8_t> a, b;
        thread_local MorphScratch scratch;
        a.resize(static_cast<size_t>(rows * cols));
        b.resize(static_cast<size_t>(rows * cols));
        const std::uint8_t* in = mptr;
        Index in_stride = mstride;
        for (size_t i = 0; i < passes.size(); ++i) {
            // the last pass into the result, the others through the two scratch masks
            std::uint8_t* to = i + 1 == passes.size() ? optr : (i % 2 == 0 ? a.data() : b.data());
            morphology(in, in_stride, to, rows, cols, *passes[i].element, passes[i].op, scratch);
            in = to;
            in_stride = cols;
        }
    }
    return out;
}

}  // namespace

void register_detection(py::module_& m) {
    py::class_<BackgroundModel>(
        m, "BackgroundModel",
        "Adaptive background + frame difference + threshold, fused with HSV binning (one pass).")
        .def(py::init([](double alpha, double alpha_fg, int n_learn, double k_noise, double t_min, double t_max,
                         double low_ratio, double shadow_lo, double shadow_chroma, int n_h, int n_s, int n_v, double s_min, double v_min) {
                 return BackgroundModel(
                     BackgroundConfig{alpha, alpha_fg, n_learn, k_noise, t_min, t_max, low_ratio, shadow_lo, shadow_chroma},
                     HsvBinning{n_h, n_s, n_v, s_min, v_min});
             }),
             py::arg("alpha") = 0.05, py::arg("alpha_fg") = 0.005, py::arg("n_learn") = 30,
             py::arg("k_noise") = 4.0,
             py::arg("t_min") = 25.0, py::arg("t_max") = 60.0, py::arg("low_ratio") = 0.5,
             py::arg("shadow_lo") = 0.5, py::arg("shadow_chroma") = 0.03,
             py::arg("n_h") = 10, py::arg("n_s") = 10, py::arg("n_v") = 10, py::arg("s_min") = 0.1,
             py::arg("v_min") = 0.2)
        .def(
            "apply",
            [](BackgroundModel& self, const py::object& frame_in, bool bins,
               std::optional<py::array> hold) {
                const char* fn = "BackgroundModel.apply";
                const bind::InUse busy(&self, fn);
                const py::array frame = bind::bgr_image(frame_in, fn, "frame");
                const Index rows = frame.shape(0), cols = frame.shape(1);
                if (self.initialized())
                    require(rows == self.rows() && cols == self.cols(), fn,
                            "frame shape is " + shape_str(frame) + ", expected (" +
                                std::to_string(self.rows()) + ", " + std::to_string(self.cols()) +
                                ", 3) as the earlier frames (call reset() before a new video)");
                const std::uint8_t* hptr = nullptr;
                Index hstride = 0;
                if (hold) {
                    bind::check_mask(*hold, rows, cols, fn);
                    hptr = static_cast<const std::uint8_t*>(hold->data());
                    hstride = hold->strides(0);
                }
                std::shared_ptr<BinnedImage> img;
                if (bins) img = std::make_shared<BinnedImage>(rows, cols, self.binning().n_bins());
                auto mask = new_mask(rows, cols);
                const auto* src = static_cast<const std::uint8_t*>(frame.data());
                const Index stride = frame.strides(0);
                std::uint8_t* mptr = mask.mutable_data();
                std::int16_t* bptr = img ? img->data.data() : nullptr;
                {
                    // safe: raw buffers kept alive by the caller / owned here; the model is not
                    // shared between threads by pftrack (one model per video)
                    py::gil_scoped_release nogil;
                    self.apply(src, rows, cols, stride, bptr, mptr, hptr, hstride);
                }
                return py::make_tuple(bins ? py::cast(img) : py::none(), mask);
            },
            py::arg("frame"), py::arg("bins") = true, py::arg("hold") = py::none(),
            "frame (H, W, 3) uint8 BGR -> (BinnedImage of all pixels, or None without bins; raw "
            "mask (H, W) uint8: 255 foreground, 127 shadow, 0 background). hold (H, W) uint8/bool: "
            "candidates where != 0 are not learnt.")
        .def(
            "blend",
            [](BackgroundModel& self, const py::object& frame_in, const py::object& mask_in,
               double rate) {
                const char* fn = "BackgroundModel.blend";
                const bind::InUse busy(&self, fn);
                const py::array frame = bind::bgr_image(frame_in, fn, "frame");
                const py::array mask = bind::mask_array(mask_in, fn);
                check_frame_and_mask(self, frame, mask, fn);
                const auto* src = static_cast<const std::uint8_t*>(frame.data());
                const auto* mptr = static_cast<const std::uint8_t*>(mask.data());
                const Index stride = frame.strides(0), mstride = mask.strides(0);
                {
                    py::gil_scoped_release nogil;  // safe: raw buffers held by the caller
                    self.blend(src, stride, mptr, mstride, rate);
                }
            },
            py::arg("frame"), py::arg("mask"), py::arg("rate"),
            "background += rate (frame - background) where mask (H, W) uint8/bool != 0.")
        .def(
            "global_gain",
            [](BackgroundModel& self, const py::object& frame_in, Index step, double min_sum) {
                const char* fn = "BackgroundModel.global_gain";
                const bind::InUse busy(&self, fn);
                const py::array frame = model_frame(self, frame_in, fn);
                const auto* src = static_cast<const std::uint8_t*>(frame.data());
                const Index stride = frame.strides(0);
                py::gil_scoped_release nogil;  // safe: raw buffer held by the caller
                return self.global_gain(src, stride, step, min_sum);
            },
            py::arg("frame"), py::arg("step") = 4, py::arg("min_sum") = 30.0,
            "Median of sum(frame) / sum(background) over every step-th row and column (pixels "
            "whose background sum is >= min_sum): the frame's global gain.")
        .def(
            "mean_and_gain",
            [](BackgroundModel& self, const py::object& frame_in, Index step, double min_sum) {
                const char* fn = "BackgroundModel.mean_and_gain";
                const bind::InUse busy(&self, fn);
                const py::array frame = model_frame(self, frame_in, fn);
                require(step >= 1, fn, "step", static_cast<double>(step), ">= 1");
                const auto* src = static_cast<const std::uint8_t*>(frame.data());
                const Index stride = frame.strides(0);
                double mean = 0.0, gain = 0.0;
                {
                    py::gil_scoped_release nogil;  // safe: raw buffer held by the caller
                    gain = self.global_gain(src, stride, step, min_sum, &mean);
                }
                return py::make_tuple(mean, gain);
            },
            py::arg("frame"), py::arg("step") = 4, py::arg("min_sum") = 30.0,
            "(sampled_mean(frame, step), global_gain(frame, step, min_sum)) in one read of the "
            "sampled pixels.")
        .def(
            "scale",
            [](BackgroundModel& self, double gain) {
                const bind::InUse busy(&self, "BackgroundModel.scale");
                self.scale(gain);
            },
            py::arg("gain"),
            "background *= gain (float32, clipped to 255): follow a global illumination change.")
        .def(
            "edge_support",
            [](const BackgroundModel& self, const py::object& frame_in, const py::object& mask_in,
               py::array_t<double, py::array::c_style | py::array::forcecast> boxes,
               const std::string& statistic) {
                const char* fn = "BackgroundModel.edge_support";
                const bind::InUse busy(&self, fn, true);  // reads only
                const py::array frame = bind::bgr_image(frame_in, fn, "frame");
                const py::array mask = bind::mask_array(mask_in, fn);
                require(statistic == "ratio" || statistic == "vote", fn,
                        "statistic is '" + statistic + "', expected 'ratio' or 'vote'");
                const auto stat =
                    statistic == "vote" ? GhostStatistic::vote : GhostStatistic::ratio;
                check_frame_and_mask(self, frame, mask, fn);
                require(boxes.ndim() == 2 && boxes.shape(1) == 4, fn,
                        "boxes must have shape (K, 4), got " + shape_str(boxes));
                const Index k = boxes.shape(0);
                const double* bp = boxes.data();
                for (Index i = 0; i < 4 * k; ++i)
                    require(std::isfinite(bp[i]) && std::abs(bp[i]) <= 1e9, fn, "box value",
                            bp[i], "finite, within +-1e9");
                py::array_t<double> out(static_cast<py::ssize_t>(k));
                const auto* src = static_cast<const std::uint8_t*>(frame.data());
                const auto* mptr = static_cast<const std::uint8_t*>(mask.data());
                const Index stride = frame.strides(0), mstride = mask.strides(0);
                double* optr = out.mutable_data();
                {
                    // safe: raw buffers held by the caller / owned here; the model is only read
                    py::gil_scoped_release nogil;
                    const Index cols = self.cols();
                    edge_support(src, stride, self.background_planar(), 3 * cols, cols, 1,
                                 self.rows(), cols, mptr, mstride, bp, k, optr, stat);
                }
                return out;
            },
            py::arg("frame"), py::arg("mask"), py::arg("boxes"), py::arg("statistic") = "ratio",
            "Ghost test: share (K,) of each box's (K, 4) mask-boundary edges held by the frame "
            "('ratio': of the summed magnitudes; 'vote': of the band pixels).")
        .def(
            "set_background",
            [](BackgroundModel& self, py::array_t<float, py::array::c_style | py::array::forcecast> bg) {
                const char* fn = "BackgroundModel.set_background";
                const bind::InUse busy(&self, fn);
                require(bg.ndim() == 3 && bg.shape(2) == 3, fn,
                        "background must have shape (H, W, 3), got " + shape_str(bg));
                require(bg.shape(0) > 0 && bg.shape(1) > 0, fn, "background is empty");
                const float* p = bg.data();
                for (py::ssize_t i = 0; i < bg.size(); ++i)
                    require(p[i] >= 0.0f && p[i] <= 255.0f, fn, "background value", p[i],
                            "in [0, 255]");
                self.set_background(p, bg.shape(0), bg.shape(1));
            },
            py::arg("background"),
            "Initialise from a (H, W, 3) BGR image (e.g. a median of frames) instead of the first frame.")
        .def(py::pickle(
            [](const BackgroundModel& self) {  // settings, then what the model has learnt
                const bind::InUse busy(&self, "BackgroundModel.__getstate__", true);
                const BackgroundConfig& c = self.config();
                const HsvBinning& h = self.binning();
                const BackgroundModel::State s = self.state();
                const auto bytes = [](const void* p, size_t n) {
                    return py::bytes(static_cast<const char*>(p), n);
                };
                return py::make_tuple(
                    py::make_tuple(c.alpha, c.alpha_fg, c.n_learn, c.k_noise, c.t_min, c.t_max,
                                   c.low_ratio, c.shadow_lo, c.shadow_chroma),
                    py::make_tuple(h.n_h, h.n_s, h.n_v, h.s_min, h.v_min),
                    py::make_tuple(s.rows, s.cols, s.frame_count, s.learning, s.threshold,
                                   s.threshold_scale),
                    bytes(s.background.data(), s.background.size() * sizeof(float)),
                    bytes(s.previous.data(), s.previous.size()),
                    bytes(s.hist.data(), s.hist.size() * sizeof(std::int64_t)));
            },
            [](const py::tuple& t) {
                const char* fn = "BackgroundModel.__setstate__";
                require(t.size() == 6, fn, "state size", t.size(), 6);
                const auto c = t[0].cast<py::tuple>(), h = t[1].cast<py::tuple>(),
                           k = t[2].cast<py::tuple>();
                require(c.size() == 9 && h.size() == 5 && k.size() == 6, fn,
                        "the state is not a pickled BackgroundModel's");
                BackgroundConfig config{c[0].cast<double>(), c[1].cast<double>(),
                                        c[2].cast<int>(),    c[3].cast<double>(),
                                        c[4].cast<double>(), c[5].cast<double>(),
                                        c[6].cast<double>(), c[7].cast<double>(),
                                        c[8].cast<double>()};
                HsvBinning binning{h[0].cast<int>(), h[1].cast<int>(), h[2].cast<int>(),
                                   h[3].cast<double>(), h[4].cast<double>()};
                BackgroundModel model(config, binning);  // checks the settings
                BackgroundModel::State s;
                s.rows = k[0].cast<Index>();
                s.cols = k[1].cast<Index>();
                s.frame_count = k[2].cast<long>();
                s.learning = k[3].cast<bool>();
                s.threshold = k[4].cast<double>();
                s.threshold_scale = k[5].cast<double>();
                const std::string bg = t[3].cast<std::string>(), prev = t[4].cast<std::string>(),
                                  hist = t[5].cast<std::string>();
                require(bg.size() % sizeof(float) == 0 &&
                            hist.size() == s.hist.size() * sizeof(std::int64_t),
                        fn, "the state is not a pickled BackgroundModel's");
                s.background.resize(bg.size() / sizeof(float));
                std::memcpy(s.background.data(), bg.data(), bg.size());
                s.previous.assign(prev.begin(), prev.end());
                std::memcpy(s.hist.data(), hist.data(), hist.size());
                model.restore(std::move(s));
                return model;
            }))
        .def("__reduce__", &bind::reduce_by_state,
             "Pickled at every protocol as BackgroundModel.__new__ + __setstate__ (pickling.hpp).")
        .def(
            "__copy__",
            [](const BackgroundModel& self) {
                const bind::InUse busy(&self, "BackgroundModel.__copy__", true);
                return BackgroundModel(self);
            },
            "An independent copy (copy.copy and copy.deepcopy: a checkpoint of the model).")
        .def(
            "__deepcopy__",
            [](const BackgroundModel& self, const py::dict&) {
                const bind::InUse busy(&self, "BackgroundModel.__deepcopy__", true);
                return BackgroundModel(self);
            },
            py::arg("memo"))
        .def(
            "reset",
            [](BackgroundModel& self) {
                const bind::InUse busy(&self, "BackgroundModel.reset");
                self.reset();
            },
            "Forget the background: the next frame initialises it.")
        .def_property_readonly("initialized", &BackgroundModel::initialized)
        .def_property_readonly("frame_count", &BackgroundModel::frame_count)
        .def_property_readonly("threshold", &BackgroundModel::threshold,
                               "Threshold the next frame will use (grey levels).")
        .def(
            "set_threshold_scale",
            [](BackgroundModel& self, double s) {
                const bind::InUse busy(&self, "BackgroundModel.set_threshold_scale");
                self.set_threshold_scale(s);
            },
            py::arg("s"),
             "Threshold bounds become [s t_min, s t_max] (at most 255); the current threshold is "
             "scaled by s / the previous s and clamped to them. reset() sets 1.")
        .def_property_readonly("threshold_scale", &BackgroundModel::threshold_scale,
                               "The scale of the threshold's bounds (set_threshold_scale).")
        .def_property_readonly("n_bins", [](const BackgroundModel& s) { return s.binning().n_bins(); })
        .def_property_readonly("shape",
                               [](const BackgroundModel& s) -> py::object {
                                   if (!s.initialized()) return py::none();
                                   return py::make_tuple(s.rows(), s.cols());
                               })
        .def_property_readonly(
            "background",
            [](const BackgroundModel& s) -> py::object {
                const bind::InUse busy(&s, "BackgroundModel.background", true);
                if (!s.initialized()) return py::none();
                py::array_t<float> a({static_cast<py::ssize_t>(s.rows()),
                                      static_cast<py::ssize_t>(s.cols()), py::ssize_t(3)});
                s.background_bgr(a.mutable_data());
                return a;
            },
            "Copy of the background (H, W, 3) float32 BGR, or None before the first frame.")
        .def_property_readonly(
            "difference_histogram",
            [](const BackgroundModel& s) {
                py::array_t<std::int64_t> a(256);
                std::copy(s.difference_histogram().begin(), s.difference_histogram().end(),
                          a.mutable_data());
                return a;
            },
            "(256,) int64 counts of floor(max-channel |frame - background|) of the last frame.")
        .def_property_readonly("alpha", [](const BackgroundModel& s) { return s.config().alpha; })
        .def_property_readonly("alpha_fg", [](const BackgroundModel& s) { return s.config().alpha_fg; })
        .def_property_readonly("n_learn", [](const BackgroundModel& s) { return s.config().n_learn; })
        .def_property_readonly("k_noise", [](const BackgroundModel& s) { return s.config().k_noise; })
        .def_property_readonly("t_min", [](const BackgroundModel& s) { return s.config().t_min; })
        .def_property_readonly("t_max", [](const BackgroundModel& s) { return s.config().t_max; })
        .def_property_readonly("low_ratio", [](const BackgroundModel& s) { return s.config().low_ratio; })
        .def_property_readonly("shadow_lo", [](const BackgroundModel& s) { return s.config().shadow_lo; })
        .def_property_readonly("shadow_chroma",
                               [](const BackgroundModel& s) { return s.config().shadow_chroma; });

    m.def(
        "median_frames",
        [](const py::sequence& frames, int threads) {
            const char* fn = "median_frames";
            require(threads >= 1, fn, "threads", threads, ">= 1");
            const auto m = static_cast<Index>(py::len(frames));
            require(m >= 1, fn, "frames is empty, expected at least one frame");
            require(m <= 65535, fn, "frames holds", m, "at most 65535 frames");
            std::vector<py::array> keep;  // holds every frame while the GIL is released
            keep.reserve(static_cast<size_t>(m));
            for (Index f = 0; f < m; ++f) {
                const std::string what = "frames[" + std::to_string(f) + "]";
                keep.push_back(bind::bgr_image(frames[static_cast<size_t>(f)], fn, what.c_str()));
                require(keep.back().shape(0) == keep[0].shape(0) &&
                            keep.back().shape(1) == keep[0].shape(1),
                        fn,
                        what + " shape is " + shape_str(keep.back()) + ", expected " +
                            shape_str(keep[0]) + " as frames[0]");
            }
            const Index rows = keep[0].shape(0), cols = keep[0].shape(1), n = 3 * cols;
            py::array_t<float> out({static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(cols),
                                    py::ssize_t(3)});
            std::vector<const std::uint8_t*> base(static_cast<size_t>(m));
            std::vector<Index> stride(static_cast<size_t>(m));
            for (Index f = 0; f < m; ++f) {
                base[static_cast<size_t>(f)] = static_cast<const std::uint8_t*>(keep[static_cast<size_t>(f)].data());
                stride[static_cast<size_t>(f)] = keep[static_cast<size_t>(f)].strides(0);
            }
            float* optr = out.mutable_data();
            {
                // safe: the frames are held in `keep`, the output is owned here
                py::gil_scoped_release nogil;
                // chunks of a row small enough that the m frames' pieces stay in L1 over the
                // 8 passes of the selection (9 for an even m)
                const Index chunk = std::max(Index(64), Index(16384) / m);
                // bands of rows on up to `threads` threads, each with its own scratch: every
                // pixel's median is its own, so the values do not depend on the split
                const Index bands = std::min<Index>(rows, 4 * Index(threads));
                parallel_for(bands, threads, [&](Index b) {
                    std::vector<std::uint8_t> lo(static_cast<size_t>(n)),
                        hi(static_cast<size_t>(n)), cand(static_cast<size_t>(n));
                    std::vector<std::uint16_t> count(static_cast<size_t>(n));
                    std::vector<const std::uint8_t*> at(static_cast<size_t>(m));
                    for (Index y = rows * b / bands; y < rows * (b + 1) / bands; ++y)
                        for (Index x0 = 0; x0 < n; x0 += chunk) {
                            const Index len = std::min(chunk, n - x0);
                            for (size_t f = 0; f < base.size(); ++f)
                                at[f] = base[f] + y * stride[f] + x0;
                            median_u8(at.data(), m, len, optr + y * n + x0, lo.data(), hi.data(),
                                      cand.data(), count.data());
                        }
                });
            }
            return out;
        },
        py::arg("frames"), py::arg("threads") = 1,
        "Per-pixel median (H, W, 3) float32 of a sequence of (H, W, 3) uint8 frames, on up to "
        "`threads` threads (the same values with any number).");

    m.def(
        "mask_bins",
        [](const BinnedImage& binned, const py::object& mask_in) {
            const char* fn = "mask_bins";
            const py::array mask = bind::mask_array(mask_in, fn);
            bind::check_mask(mask, binned.rows, binned.cols, fn);
            auto out = std::make_shared<BinnedImage>(binned.rows, binned.cols, binned.n_bins);
            const auto* mptr = static_cast<const std::uint8_t*>(mask.data());
            const Index mstride = mask.strides(0);
            {
                py::gil_scoped_release nogil;  // safe: raw buffers held by the caller / owned here
                mask_bins(binned.view().data, binned.rows, binned.cols, mptr, mstride,
                          out->data.data());
            }
            return out;
        },
        py::arg("binned"), py::arg("mask"),
        "New BinnedImage with bins -1 where mask (H, W) uint8/bool is 0 (background).");

    m.def(
        "sampled_mean",
        [](const py::object& frame_in, Index step) {
            const char* fn = "sampled_mean";
            const py::array frame =
                bind::ndarray(frame_in, fn, "frame", "(H, W, 3) uint8 (BGR, as cv2 reads it)");
            if (!bind::is_u8(frame.dtype()))
                throw py::type_error(std::string(fn) + ": frame dtype is " +
                                     bind::dtype_name(frame) + ", expected uint8");
            if (!(frame.ndim() == 3 && frame.shape(2) == 3))
                fail(fn, "frame must have shape (H, W, 3), got " + shape_str(frame));
            if (!(frame.shape(0) > 0 && frame.shape(1) > 0)) fail(fn, "frame is empty");
            require(step >= 1, fn, "step", static_cast<double>(step), ">= 1");
            // any strides (a view such as frame[:, :, ::-1] too); the GIL kept: a few
            // microseconds, and the caller's array cannot change under it
            return sampled_mean(static_cast<const std::uint8_t*>(frame.data()), frame.shape(0),
                                frame.shape(1), frame.strides(0), frame.strides(1),
                                frame.strides(2), step);
        },
        py::arg("frame"), py::arg("step"),
        "Mean level of every step-th pixel of every step-th row of a (H, W, 3) uint8 frame "
        "(numpy's frame[::step, ::step].mean(), the same double).");

    m.def(
        "_set_avx2",
        [](bool allowed) { return detail::avx2_allowed().exchange(allowed); },
        py::arg("allowed"),
        "Testing hook: whether background.hpp's hand-written AVX2 passes may run (BackgroundModel."
        "apply's row pass and difference histogram, hsv_bins' rows; morphology.hpp's packed "
        "masks: clean_mask, open_mask, close_mask; mask_scan.hpp's 64-byte skip of a mask's "
        "empty bytes: blob_boxes, masked hsv_bins; where the CPU has AVX2; the portable loops "
        "otherwise, the same results). Returns the previous setting; process-wide.");

    m.def(
        "close_mask",
        [](const py::object& mask, const py::object& element) {
            return mask_passes(mask, {{element, MorphOp::dilate}, {element, MorphOp::erode}},
                               "close_mask");
        },
        py::arg("mask"), py::arg("element"),
        "Closing (H, W) uint8 of a (H, W) uint8/bool mask by a (kh, kw) element whose rows are "
        "single runs: cv2.morphologyEx(mask, MORPH_CLOSE, element)'s values.");

    m.def(
        "open_mask",
        [](const py::object& mask, const py::object& element) {
            return mask_passes(mask, {{element, MorphOp::erode}, {element, MorphOp::dilate}},
                               "open_mask");
        },
        py::arg("mask"), py::arg("element"),
        "Opening (H, W) uint8 of a (H, W) uint8/bool mask by a (kh, kw) element whose rows are "
        "single runs: cv2.morphologyEx(mask, MORPH_OPEN, element)'s values.");

    m.def(
        "clean_mask",
        [](const py::object& mask, const py::object& open_element,
           const py::object& close_element) {
            return mask_passes(mask,
                               {{open_element, MorphOp::erode},
                                {open_element, MorphOp::dilate},
                                {close_element, MorphOp::dilate},
                                {close_element, MorphOp::erode}},
                               "clean_mask");
        },
        py::arg("mask"), py::arg("open_element"), py::arg("close_element"),
        "Opening by open_element, then closing by close_element, of a (H, W) uint8/bool mask in "
        "one call: (H, W) uint8, cv2.morphologyEx's values; a mask of 0 and one or two levels "
        "(255 the upper) as bit planes, others byte by byte.");
}
