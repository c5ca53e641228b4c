// What sis_step and mh_step share in the binding layer: their common arguments become SisParams,
// and their results one dict (mh_step adds "acceptance").
#pragma once

#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include <string>

#include "pftrack/sis.hpp"

pftrack::Kernel parse_kernel(const std::string& name, const char* fn);  // register_histogram.cpp

namespace pftrack::bind {

namespace py = pybind11;

inline Ar2Model make_model(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                           const Eigen::Vector3d& sigma, double s_min, double s_max,
                           bool use_means) {
    Ar2Model m;
    m.a = a.array();
    m.b = b.array();
    m.sigma = sigma.array();
    m.s_min = s_min;
    m.s_max = s_max;
    m.use_means = use_means;
    return m;
}

inline SisParams make_step_params(double w0, double h0, const Eigen::Vector3d& a,
                                  const Eigen::Vector3d& b, const Eigen::Vector3d& sigma,
                                  double s_min, double s_max, bool use_means, double lam,
                                  const std::string& kernel, bool resample, const char* fn) {
    SisParams prm;
    prm.model = make_model(a, b, sigma, s_min, s_max, use_means);
    prm.lambda = lam;
    prm.kernel = parse_kernel(kernel, fn);
    prm.w0 = w0;
    prm.h0 = h0;
    prm.resample = resample;
    return prm;
}

inline py::dict step_result_dict(const SisResult& r) {
    py::dict out;
    out["mean"] = Eigen::Vector3d(r.estimate.mean);
    out["map"] = Eigen::Vector3d(r.estimate.map);
    out["map_index"] = r.estimate.map_index;
    out["ess"] = r.ess;
    out["rho_max"] = r.rho_max;
    out["rho_mean"] = r.rho_mean;
    out["fg_mean"] = r.fg_mean;
    return out;
}

}  // namespace pftrack::bind
