// Checks on NumPy arrays that only the binding layer can make (dtype, ndim, strides), with
// messages in the core's style: "hsv_bins: frame dtype is float64, expected uint8".
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <mutex>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "pftrack/check.hpp"
#include "pftrack/types.hpp"

namespace pftrack::bind {

namespace py = pybind11;

inline std::string dtype_name(const py::array& a) { return py::str(a.dtype()).cast<std::string>(); }

/// The name of `obj`'s type ("list", "NoneType", "ndarray"), for one-line TypeErrors.
inline std::string type_name(const py::handle& obj) {
    return py::str(py::type::of(obj).attr("__name__")).cast<std::string>();
}

/// Whether dtype `d` is T's: the same descriptor object (the usual case, no call), or an
/// equivalent one (PyArray_EquivTypes: an array that went through pickle has an equal but
/// distinct descriptor; a byte-swapped one is not equivalent).
template <typename T>
inline bool is_dtype(const py::dtype& d) {
    const py::dtype want = py::dtype::of<T>();
    return d.is(want) || d.equal(want);
}
inline bool is_u8(const py::dtype& d) { return is_dtype<std::uint8_t>(d); }
inline bool is_bool(const py::dtype& d) { return is_dtype<bool>(d); }

/// A (H, W, 3) uint8 image whose pixels are packed (3 bytes a pixel, 1 a channel); rows may be
/// strided (views of a larger image are fine). A wrong dtype is a TypeError, a wrong shape or
/// layout a ValueError, as the Python layer's frame checks (pftrack._check.bgr_array) raise
/// them: a float32 or uint16 frame was ValueError from the core and TypeError from Python.
inline void check_bgr_image(const py::array& a, const char* fn, const char* what) {
    // Every message is built only on failure: these checks run on every frame, and naming the
    // dtype (a str() through Python) or concatenating strings up front cost a call each time.
    if (!is_u8(a.dtype())) {
        const bool deep = is_dtype<std::uint16_t>(a.dtype());
        throw py::type_error(std::string(fn) + ": " + what + " dtype is " + dtype_name(a) +
                             ", expected uint8 (BGR, as cv2 reads it)" +
                             (deep ? "; a 16-bit frame? (frame >> 8).astype(np.uint8) keeps its "
                                     "top 8 bits"
                                   : ""));
    }
    if (!(a.ndim() == 3 && a.shape(2) == 3))
        fail(fn, std::string(what) + " must have shape (H, W, 3)");
    if (!(a.shape(0) > 0 && a.shape(1) > 0)) fail(fn, std::string(what) + " is empty");
    if (!(a.strides(2) == 1 && a.strides(1) == 3 && a.strides(0) > 0))
        fail(fn, std::string(what) + " pixels must be packed (use numpy.ascontiguousarray)");
}

/// `obj` as a NumPy array, or a one-line TypeError naming `what` and what it is (`expected`:
/// the array it should be, after "expected a numpy.ndarray ").
inline py::array ndarray(const py::handle& obj, const char* fn, const char* what,
                         const std::string& expected) {
    if (!py::isinstance<py::array>(obj))
        throw py::type_error(std::string(fn) + ": " + what + " is " +
                             type_name(obj) +
                             ", expected a numpy.ndarray " + expected);
    return py::reinterpret_borrow<py::array>(obj);
}

/// `obj` as a NumPy array checked by check_bgr_image; anything else (a list, None, a PIL
/// image) is a one-line TypeError naming `what`, where a `py::array` parameter gave pybind11's
/// list of signatures.
inline py::array bgr_image(const py::handle& obj, const char* fn, const char* what) {
    py::array a = ndarray(obj, fn, what, "(H, W, 3) uint8 (BGR, as cv2 reads it)");
    check_bgr_image(a, fn, what);
    return a;
}

/// `obj` as a NumPy array for the mask-like argument `what` of shape `shape` (a mask "(H, W)",
/// a structuring element "(kh, kw)"); anything else (a list, None) is a one-line TypeError
/// naming `what`, where a `py::array` parameter gave pybind11's list of signatures. Its dtype,
/// shape and layout are the caller's to check (check_mask, check_mask_dtype).
inline py::array mask_array(const py::handle& obj, const char* fn, const char* what = "mask",
                            const char* shape = "(H, W)") {
    return ndarray(obj, fn, what, std::string(shape) + " uint8 or bool");
}

/// A mask's dtype: uint8 or bool (named in the message only on failure). A wrong dtype is a
/// TypeError, as the Python layer's checks (hsv_bins, RJMCMCFilter.step) raise it: the same
/// fault was ValueError from the core and TypeError from Python.
inline void check_mask_dtype(const py::array& m, const char* fn) {
    const py::dtype d = m.dtype();
    if (!is_u8(d) && !is_bool(d))
        throw py::type_error(std::string(fn) + ": mask dtype is " + dtype_name(m) +
                             ", expected uint8 or bool");
}

/// A (H, W) mask of uint8 or bool, matching the image's size, packed along rows (messages built
/// only on failure, as above).
inline void check_mask(const py::array& m, py::ssize_t rows, py::ssize_t cols, const char* fn) {
    check_mask_dtype(m, fn);
    if (!(m.ndim() == 2 && m.shape(0) == rows && m.shape(1) == cols))
        fail(fn, "mask must have the frame's (H, W) shape");
    if (!(m.strides(1) == 1 && m.strides(0) > 0))
        fail(fn, "mask must be packed along rows (use numpy.ascontiguousarray)");
}

/// `obj` as the float64 array `what` that `fn` updates in place (never copied: a copy would take
/// the result and be lost), of `ndim` dimensions, C-contiguous and writeable. Anything else is
/// one line naming `what`, as pftrack.particle_filter.propagate's checks give it: not an array
/// or another dtype (float32, a long double, a big-endian >f8) a TypeError naming the dtype,
/// a layout or number of dimensions it cannot be written through a ValueError. Was pybind11's
/// "incompatible function arguments" with the whole signature (an Eigen::Ref .noconvert()).
inline py::array inplace_f64(const py::handle& obj, const char* fn, const char* what, int ndim) {
    const std::string want = "a C-contiguous, writeable float64 array (updated in place, never "
                             "copied)";
    if (!py::isinstance<py::array>(obj))
        throw py::type_error(std::string(fn) + ": " + what + " must be " + want + ", got " +
                             type_name(obj));
    const auto a = py::reinterpret_borrow<py::array>(obj);
    if (!is_dtype<double>(a.dtype())) {
        const bool swapped = a.dtype().kind() == 'f' && a.dtype().itemsize() == 8;
        throw py::type_error(std::string(fn) + ": " + what + " must be " + want + ", got dtype " +
                             dtype_name(a) +
                             (swapped ? " (not this machine's byte order; pass a copy in its "
                                        "order, .astype(np.float64), and read the result from it)"
                                      : ""));
    }
    if (!((a.flags() & py::array::c_style) != 0 && a.writeable()))
        fail(fn, std::string(what) + " must be " + want + ", got " +
                     (a.writeable() ? "one not C-contiguous" : "a read-only one"));
    if (a.ndim() != ndim)
        fail(fn, std::string(what) + " must have " + std::to_string(ndim) + " dimension" +
                     (ndim == 1 ? "" : "s") + ", got " + std::to_string(a.ndim()));
    return a;
}

/// The (rows, cols) matrix of a 2-D array inplace_f64 checked, written through.
inline Eigen::Map<RowMatrixXd> inplace_matrix(const py::handle& obj, const char* fn,
                                              const char* what) {
    py::array a = inplace_f64(obj, fn, what, 2);
    return {static_cast<double*>(a.mutable_data()), a.shape(0), a.shape(1)};
}

/// The (n,) vector of a 1-D array inplace_f64 checked, written through.
inline Eigen::Map<Eigen::VectorXd> inplace_vector(const py::handle& obj, const char* fn,
                                                  const char* what) {
    py::array a = inplace_f64(obj, fn, what, 1);
    return {static_cast<double*>(a.mutable_data()), a.shape(0)};
}

/// One object in one thread at a time: a method that releases the GIL, or that could run while
/// another thread is inside such a method of the same object (and would see its buffers being
/// reallocated), holds this for its whole call; methods that only read (`shared`) may run
/// together. A thread that would overlap a writer raises RuntimeError instead of corrupting
/// the object or crashing the process (a Tracker shared by two threads).
class InUse {
public:
    InUse(const void* object, const char* fn, bool shared = false) : object_(object) {
        std::lock_guard<std::mutex> lock(mutex());
        auto [it, fresh] = held().try_emplace(object, 0);
        // count: readers inside (> 0), or a writer (-1)
        if (shared ? it->second < 0 : !fresh)
            throw std::runtime_error(std::string(fn) +
                                     ": the object is in use by another thread (use one per "
                                     "thread, or a lock around it)");
        it->second = shared ? it->second + 1 : -1;
    }
    ~InUse() {
        std::lock_guard<std::mutex> lock(mutex());
        auto it = held().find(object_);
        if (it->second > 1)
            --it->second;
        else
            held().erase(it);
    }
    InUse(const InUse&) = delete;
    InUse& operator=(const InUse&) = delete;

private:
    const void* object_;
    static std::mutex& mutex() {
        static std::mutex m;
        return m;
    }
    static std::unordered_map<const void*, int>& held() {
        static std::unordered_map<const void*, int> objects;
        return objects;
    }
};

/// A numeric array's kinds: booleans, integers, floats (complex numbers, objects, text, bytes,
/// datetimes and records are not).
inline bool real_kind(char kind) {
    return kind == 'b' || kind == 'i' || kind == 'u' || kind == 'f';
}

/// TypeError when `h` (argument `what` of `fn`) is an array, or a list or buffer NumPy reads as
/// one, of a kind that is not real numbers (NumPy's cast took a complex array's real part with
/// only a ComplexWarning, and parsed text as numbers). A valid ndarray costs one kind read.
inline void check_real(py::handle h, const std::string& fn, const std::string& what) {
    if (py::isinstance<py::array>(h)) {
        const py::dtype d = py::reinterpret_borrow<py::array>(h).dtype();
        if (real_kind(d.kind())) return;
        throw py::type_error(fn + ": " + what + " must hold real numbers, got dtype " +
                             py::str(d).cast<std::string>());
    }
    if (!(PyList_Check(h.ptr()) || PyTuple_Check(h.ptr()) || PyObject_CheckBuffer(h.ptr())))
        return;
    py::object a;
    try {
        a = py::module_::import("numpy").attr("asarray")(h);
    } catch (const py::error_already_set&) {
        return;  // ragged or unreadable: the conversion that follows fails and says so
    }
    check_real(a, fn, what);
}

}  // namespace pftrack::bind
