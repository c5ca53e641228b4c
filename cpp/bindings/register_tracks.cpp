// The tracker's per-frame centre filters, one call for every track (pftrack.tracking.track's
// predict_tracks and follow_tracks_motion): each live track's state is read from and written to
// its Python objects (LiveTrack, its CentreKalman), so the tracker keeps them as it did; the
// arithmetic is centre_filter.hpp's, the same floats as the Python loops it replaces
// (tests/tracking/test_centre_batch.py). Was a Python loop over the tracks on plain floats,
// about 3 us a track a frame.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "pftrack/centre_filter.hpp"
#include "arrays.hpp"

namespace py = pybind11;
using namespace pftrack;

// the blends and boxes below are the loops' floats too: no fused multiply-add (as in
// centre_filter.hpp; GCC contracts in C++ wherever the target has FMA, e.g. PFTRACK_NATIVE)
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off")
#endif

namespace {

/// The attribute names, interned once (made on the first call, the GIL held; never freed: the
/// interpreter may be gone when static destructors run).
struct Names {
    py::str motion, size, p, v, cov, accel, flat, measured, rho, age, box;
};

const Names& names() {
    static const Names* n = new Names{
        py::str("motion"), py::str("size"),  py::str("p"),        py::str("v"),
        py::str("cov"),    py::str("accel"), py::str("flat"),     py::str("measured"),
        py::str("rho"),    py::str("age"),   py::str("box")};
    return *n;
}

std::string item(const char* what, size_t k, const char* name) {
    return std::string(what) + "[" + std::to_string(k) + "]." + name;
}

/// The 2 floats of `obj`, a (2,) array (any real dtype; read as float64, as .tolist() then
/// Python's arithmetic takes them). TypeError for another object, ValueError for another shape.
void read_pair(const py::handle& obj, const char* fn, const std::string& what, double* out) {
    if (!py::isinstance<py::array>(obj))
        throw py::type_error(std::string(fn) + ": " + what + " is " +
                             bind::type_name(obj) +
                             ", expected a (2,) float64 array");
    auto a = py::reinterpret_borrow<py::array>(obj);
    if (!bind::is_dtype<double>(a.dtype())) {
        if (!bind::real_kind(a.dtype().kind()))
            throw py::type_error(std::string(fn) + ": " + what + " dtype is " +
                                 bind::dtype_name(a) + ", expected float64");
        a = py::array_t<double, py::array::forcecast>::ensure(a);
        if (!a) throw py::error_already_set();
    }
    if (!(a.ndim() == 1 && a.shape(0) == 2))
        fail(fn, what + " must have shape (2,)");
    const auto* base = static_cast<const char*>(a.data());
    std::memcpy(out, base, sizeof(double));
    std::memcpy(out + 1, base + a.strides(0), sizeof(double));
}

/// A Python number as a double (a float, an int, a NumPy scalar), or TypeError naming `what`.
double number(const py::handle& obj, const char* fn, const std::string& what) {
    const double x = PyFloat_AsDouble(obj.ptr());
    if (x == -1.0 && PyErr_Occurred()) {
        PyErr_Clear();
        throw py::type_error(std::string(fn) + ": " + what + " is " +
                             bind::type_name(obj) +
                             ", expected a float");
    }
    return x;
}

/// A track's centre filter: p, v and cov (three numbers) of its `motion`; `size` (w, h).
struct Read {
    py::object motion;
    CentreState s;
    double w, h;
};

Read read_track(const py::handle& t, const char* fn, size_t k) {
    const Names& n = names();
    Read r{t.attr(n.motion), {}, 0.0, 0.0};
    double pair[2];
    read_pair(t.attr(n.size), fn, item("tracks", k, "size"), pair);
    r.w = pair[0];
    r.h = pair[1];
    read_pair(r.motion.attr(n.p), fn, item("tracks", k, "motion.p"), pair);
    r.s.px = pair[0];
    r.s.py = pair[1];
    read_pair(r.motion.attr(n.v), fn, item("tracks", k, "motion.v"), pair);
    r.s.vx = pair[0];
    r.s.vy = pair[1];
    const py::object cov = r.motion.attr(n.cov);
    const std::string what = item("tracks", k, "motion.cov");
    if (!PyTuple_Check(cov.ptr()) || PyTuple_GET_SIZE(cov.ptr()) != 3)
        throw py::type_error(std::string(fn) + ": " + what + " must be a tuple of 3 floats");
    r.s.p00 = number(PyTuple_GET_ITEM(cov.ptr(), 0), fn, what);
    r.s.p01 = number(PyTuple_GET_ITEM(cov.ptr(), 1), fn, what);
    r.s.p11 = number(PyTuple_GET_ITEM(cov.ptr(), 2), fn, what);
    return r;
}

[[noreturn]] void zero_variance(const char* fn, size_t k) {
    // the Python loop's division by it raised ZeroDivisionError
    fail(fn, "tracks[" + std::to_string(k) +
                 "]: the centre's innovation variance p00 + sd^2 is 0 (no covariance and no "
                 "measurement noise)");
}

/// A (len,) view of row `k` of `rows` (K, cols), from column `at`: what indexing a row of a
/// (K, cols) array gives (its base is `rows`).
py::array row_view(const py::array& rows, py::ssize_t k, py::ssize_t at, py::ssize_t len) {
    auto* data = static_cast<double*>(const_cast<void*>(rows.data())) + k * rows.shape(1) + at;
    return py::array(py::dtype::of<double>(), {len}, {static_cast<py::ssize_t>(sizeof(double))},
                     data, rows);
}

/// ValueError unless track `k`'s new state (its `cols` numbers in `row`, and the covariance) is
/// finite: a NaN or an overflow in a track's filter, its measurement or its size would spread
/// to the association's costs (nothing is changed on any track).
void require_finite_state(const char* fn, size_t k, const double* row, int cols,
                          const CentreState& s) {
    bool ok = std::isfinite(s.p00) && std::isfinite(s.p01) && std::isfinite(s.p11);
    for (int c = 0; c < cols; ++c) ok = ok && std::isfinite(row[c]);
    if (!ok)
        fail(fn, "tracks[" + std::to_string(k) +
                     "]: its new centre, velocity, covariance or box is not finite (a NaN or an "
                     "overflow in its state, size, measurement or gain)");
}

py::list track_list(const py::handle& tracks, const char* fn) {
    if (!PyList_Check(tracks.ptr()))
        throw py::type_error(std::string(fn) + ": tracks is " +
                             bind::type_name(tracks) +
                             ", expected a list of LiveTrack");
    return py::reinterpret_borrow<py::list>(tracks);
}

/// (K, cols) float64 rows of `obj` (forcecast), checked against `k` tracks.
py::array_t<double, py::array::c_style | py::array::forcecast> rows_of(
    const py::handle& obj, const char* fn, const char* what, size_t k, py::ssize_t cols) {
    bind::check_real(obj, fn, what);
    auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
    if (!a) {
        PyErr_Clear();
        throw py::type_error(std::string(fn) + ": " + what + " is not an array of numbers");
    }
    if (!(a.ndim() == 2 && a.shape(0) == static_cast<py::ssize_t>(k) && a.shape(1) == cols))
        fail(fn, std::string(what) + " must have shape (" + std::to_string(k) + ", " +
                     std::to_string(cols) + "), one row per track");
    return a;
}

}  // namespace

void register_tracks(py::module_& m) {
    m.def(
        "centre_predict_tracks",
        [](const py::object& tracks_in, const py::object& summary_in, const py::object& gains_in,
           double colour_noise, double flat_rho) {
            const char* fn = "centre_predict_tracks";
            const Names& n = names();
            const py::list tracks = track_list(tracks_in, fn);
            const size_t k = tracks.size();
            const auto summary = rows_of(summary_in, fn, "summary", k, 4);
            const double* z = summary.data();
            if (!(PyList_Check(gains_in.ptr()) || PyTuple_Check(gains_in.ptr())))
                throw py::type_error(
                    std::string(fn) + ": gains is " +
                    bind::type_name(gains_in) +
                    ", expected a list of floats, one per track");
            const auto gain_seq = py::reinterpret_borrow<py::sequence>(gains_in);
            if (gain_seq.size() != k)
                fail(fn, "gains has " + std::to_string(gain_seq.size()) + " values for " +
                             std::to_string(k) + " tracks");
            std::vector<double> g(k);
            for (size_t i = 0; i < k; ++i)
                g[i] = number(gain_seq[i], fn, "gains[" + std::to_string(i) + "]");
            std::vector<Read> read;
            std::vector<double> accel(k);
            std::vector<py::object> ages(k);
            const py::int_ one(1);
            read.reserve(k);
            for (size_t i = 0; i < k; ++i) {
                read.push_back(read_track(tracks[i], fn, i));
                accel[i] = number(read[i].motion.attr(n.accel), fn,
                                  item("tracks", i, "motion.accel"));
                const py::object age = tracks[i].attr(n.age);
                ages[i] = py::reinterpret_steal<py::object>(PyNumber_Add(age.ptr(), one.ptr()));
                if (!ages[i]) throw py::error_already_set();
            }
            // every track computed before any changes: a refused one leaves them all as they were
            py::array_t<double> out({static_cast<py::ssize_t>(k), py::ssize_t{8}});
            double* o = out.mutable_data();
            std::vector<char> flat(k);
            for (size_t i = 0; i < k; ++i) {
                Read& r = read[i];
                const double zx = z[4 * i], zy = z[4 * i + 1], rho = z[4 * i + 2];
                const double rho_max = z[4 * i + 3];
                double q = (g[i] != 1.0 ? accel[i] * g[i] : accel[i]) * r.h;
                q = q * q;  // (accel h)^2
                centre_predict(r.s, q);
                flat[i] = !(rho_max - rho > flat_rho);  // no colour evidence (NaN: none)
                if (!flat[i]) {
                    const double sd = colour_noise * r.h;
                    if (!centre_update(r.s, zx, zy, sd * sd)) zero_variance(fn, i);
                }
                double* row = o + 8 * i;
                row[0] = r.s.px;
                row[1] = r.s.py;
                row[2] = r.s.vx;
                row[3] = r.s.vy;
                row[4] = r.s.px - r.w / 2.0;
                row[5] = r.s.py - r.h / 2.0;
                row[6] = r.w;
                row[7] = r.h;
                require_finite_state(fn, i, row, 8, r.s);
            }
            // the attributes in the Python loop's order
            for (size_t i = 0; i < k; ++i) {
                const Read& r = read[i];
                const py::handle t = tracks[i];
                r.motion.attr(n.cov) = py::make_tuple(r.s.p00, r.s.p01, r.s.p11);
                t.attr(n.flat) = py::bool_(flat[i] != 0);
                t.attr(n.measured) = py::none();
                t.attr(n.rho) = py::float_(z[4 * i + 2]);
                t.attr(n.age) = ages[i];
            }
            for (size_t i = 0; i < k; ++i) {
                const auto at = static_cast<py::ssize_t>(i);
                read[i].motion.attr(n.p) = row_view(out, at, 0, 2);
                read[i].motion.attr(n.v) = row_view(out, at, 2, 2);
                tracks[i].attr(n.box) = row_view(out, at, 4, 4);
            }
            return out;
        },
        py::arg("tracks"), py::arg("summary"), py::arg("gains"), py::arg("colour_noise"),
        py::arg("flat_rho"),
        "Predict every track's centre filter one frame and update it with its colour filter's "
        "centre (summary (K, 4): cx, cy, rho, rho_max) where rho_max - rho > flat_rho; gains "
        "(a list of K floats) multiply each motion.accel. Sets motion.p, v, cov and the track's flat, "
        "measured, rho, age, box (views of the returned (K, 8) rows: p, v, box).");
    m.def(
        "centre_follow_tracks",
        [](const py::object& tracks_in, const py::object& boxes_in, double detection_noise,
           bool smooth) {
            const char* fn = "centre_follow_tracks";
            const Names& n = names();
            const py::list tracks = track_list(tracks_in, fn);
            const size_t k = tracks.size();
            const auto boxes = rows_of(boxes_in, fn, "boxes", k, 4);
            const double* b = boxes.data();
            std::vector<Read> read;
            read.reserve(k);
            for (size_t i = 0; i < k; ++i) read.push_back(read_track(tracks[i], fn, i));
            py::array_t<double> out({static_cast<py::ssize_t>(k), py::ssize_t{14}});
            double* o = out.mutable_data();
            for (size_t i = 0; i < k; ++i) {
                Read& r = read[i];
                const double bx = b[4 * i], by = b[4 * i + 1], bw = b[4 * i + 2];
                const double bh = b[4 * i + 3];
                const double sd = detection_noise * r.h;
                if (!centre_update(r.s, bx + bw / 2.0, by + bh / 2.0, sd * sd))
                    zero_variance(fn, i);
                const double w = 0.7 * r.w + 0.3 * bw, h = 0.7 * r.h + 0.3 * bh;
                double* row = o + 14 * i;
                row[0] = r.s.px;
                row[1] = r.s.py;
                row[2] = r.s.vx;
                row[3] = r.s.vy;
                row[4] = w;
                row[5] = h;
                row[6] = smooth ? r.s.px - w / 2.0 : bx;
                row[7] = smooth ? r.s.py - h / 2.0 : by;
                row[8] = smooth ? w : bw;
                row[9] = smooth ? h : bh;
                row[10] = bx;
                row[11] = by;
                row[12] = bw;
                row[13] = bh;
                require_finite_state(fn, i, row, 14, r.s);
            }
            for (size_t i = 0; i < k; ++i)
                read[i].motion.attr(n.cov) =
                    py::make_tuple(read[i].s.p00, read[i].s.p01, read[i].s.p11);
            for (size_t i = 0; i < k; ++i) {
                const auto at = static_cast<py::ssize_t>(i);
                const py::handle t = tracks[i];
                read[i].motion.attr(n.p) = row_view(out, at, 0, 2);
                read[i].motion.attr(n.v) = row_view(out, at, 2, 2);
                t.attr(n.size) = row_view(out, at, 4, 2);
                t.attr(n.box) = row_view(out, at, 6, 4);
                t.attr(n.measured) = row_view(out, at, 10, 4);
            }
            return out;
        },
        py::arg("tracks"), py::arg("boxes"), py::arg("detection_noise"), py::arg("smooth"),
        "Update every track's centre filter with its detection's centre (boxes (K, 4) left, "
        "top, w, h; sd detection_noise heights), blend the size 0.7 / 0.3 and set the box (the "
        "filtered one when smooth, else the detection's). Sets motion.p, v, cov and the track's "
        "size, box, measured (views of the returned (K, 14) rows).");
}
