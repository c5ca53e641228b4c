// pftrack._core: the compiled kernels. Each register_<concept>.cpp binds one header of
// cpp/include/pftrack; this file only calls them in order.
#include <pybind11/pybind11.h>

namespace py = pybind11;

void register_histogram(py::module_& m);
void register_likelihood(py::module_& m);
void register_resample(py::module_& m);
void register_filter(py::module_& m);
void register_detection(py::module_& m);
void register_mcmc(py::module_& m);
void register_bridge(py::module_& m);
void register_assignment(py::module_& m);
void register_smoothing(py::module_& m);
void register_refine(py::module_& m);
void register_blobs(py::module_& m);
void register_text(py::module_& m);
void register_regions(py::module_& m);
void register_tracks(py::module_& m);
void register_overlap(py::module_& m);
void register_camera(py::module_& m);

PYBIND11_MODULE(_core, m) {
    m.doc() = "pftrack's C++ kernels (private: use the pftrack package)";
    register_histogram(m);
    register_likelihood(m);
    register_resample(m);
    register_filter(m);
    register_detection(m);
    register_mcmc(m);
    register_bridge(m);
    register_assignment(m);
    register_smoothing(m);
    register_refine(m);
    register_blobs(m);
    register_text(m);
    register_regions(m);
    register_tracks(m);
    register_overlap(m);
    register_camera(m);
}
