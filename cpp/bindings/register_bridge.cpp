// Bindings of bridge.hpp: the goal-directed state equation and the segment Kalman filter.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <string>
#include <type_traits>
#include <vector>

#include "pftrack/bridge.hpp"
#include "pftrack/gap_mixture.hpp"
#include "pftrack/gdt_noise.hpp"

namespace py = pybind11;
using namespace pftrack;

namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

GdtForm parse_form(const std::string& name, const char* fn) {
    if (name == "general") return GdtForm::general;
    if (name == "invertible") return GdtForm::invertible;
    if (name == "pseudo_inverse" || name == "pinv") return GdtForm::pseudo_inverse;
    fail(fn, "form is '" + name + "', expected 'general', 'invertible' or 'pseudo_inverse'");
}

/// (n, n) -> one matrix; (k, n, n) -> k matrices.
std::vector<MatrixXd> matrix_stack(const Array& a, const char* fn, const char* what) {
    std::vector<MatrixXd> out;
    if (a.ndim() == 2) {
        out.emplace_back(Eigen::Map<const RowMatrixXd>(a.data(), a.shape(0), a.shape(1)));
    } else if (a.ndim() == 3) {
        require(a.shape(0) > 0, fn, std::string(what) + " stack is empty");
        // C-contiguous (Array is c_style): matrix k starts k * rows * cols values in, which is
        // also right when a side is 0 (a.data(k, 0, 0) would raise IndexError there)
        const auto* base = static_cast<const double*>(a.data());
        const py::ssize_t step = a.shape(1) * a.shape(2);
        for (py::ssize_t k = 0; k < a.shape(0); ++k)
            out.emplace_back(Eigen::Map<const RowMatrixXd>(base + k * step, a.shape(1), a.shape(2)));
    } else {
        fail(fn, std::string(what) + " must be (n, n) or (T, n, n), got ndim " +
                     std::to_string(a.ndim()));
    }
    return out;
}

MatrixXd matrix2(const Array& a, const char* fn, const char* what) {
    require(a.ndim() == 2, fn, (std::string(what) + " ndim").c_str(), a.ndim(), 2);
    return Eigen::Map<const RowMatrixXd>(a.data(), a.shape(0), a.shape(1));
}

VectorXd vector1(const Array& a, const char* fn, const char* what) {
    require(a.ndim() == 1, fn, (std::string(what) + " ndim").c_str(), a.ndim(), 1);
    return Eigen::Map<const VectorXd>(a.data(), a.shape(0));
}

GdtProblem make_problem(const Array& A, const Array& Q, const Array& H, const Array& Pi_T,
                        const Array& m0, const Array& Pi_0, const Array& y, int T, const char* fn) {
    GdtProblem p;
    p.A = matrix_stack(A, fn, "A");
    p.Q = matrix_stack(Q, fn, "Q");
    p.H = matrix2(H, fn, "H");
    p.Pi_T = matrix2(Pi_T, fn, "Pi_T");
    p.m0 = vector1(m0, fn, "m0");
    p.Pi_0 = matrix2(Pi_0, fn, "Pi_0");
    p.y = vector1(y, fn, "y");
    p.T = T;
    const double n = static_cast<double>(p.m0.size());
    // eps and cov hold (T + 1) n x n matrices each
    require_size((static_cast<double>(T) + 1.0) * n * std::max(n, 1.0), fn, "T steps of the path");
    return p;
}

/// A path that is not finite comes from a model that blows up over the gap: refuse it.
template <class M>
void require_finite_result(const M& path, const char* fn) {
    require(path.allFinite(), fn,
            "the result is not finite: A is unstable over T steps, or the covariances are "
            "singular (check A's eigenvalues, Q and Pi_0)");
}

/// Problem k of a batch as C++ arrays; a wrong type becomes a TypeError, not RuntimeError.
GdtProblem batch_problem(const py::handle& h, std::size_t k) {
    const char* fn = "gdt_solve_batch";
    if (!py::isinstance<py::tuple>(h) || py::len(h) != 8)
        fail(fn, "problem " + std::to_string(k) +
                     " must be a tuple (A, Q, H, Pi_T, m0, Pi_0, y, T)");
    const py::tuple t = py::reinterpret_borrow<py::tuple>(h);
    if (!py::isinstance<py::int_>(t[7]) || py::isinstance<py::bool_>(t[7]))
        throw py::type_error(std::string(fn) + ": problem " + std::to_string(k) +
                             ": T must be an int, got " +
                             std::string(py::str(py::type::of(t[7]).attr("__name__"))));
    std::vector<Array> a;
    for (int i = 0; i < 7; ++i) {
        const py::object item = t[static_cast<std::size_t>(i)];
        const py::array probe = py::array::ensure(item);
        if (PyComplex_Check(item.ptr()) || (probe && probe.dtype().kind() == 'c'))
            throw py::type_error(std::string(fn) + ": problem " + std::to_string(k) + ": item " +
                                 std::to_string(i) + " is complex, expected real numbers");
        try {
            a.push_back(item.cast<Array>());
        } catch (const py::cast_error&) {
            throw py::type_error(std::string(fn) + ": problem " + std::to_string(k) + ": item " +
                                 std::to_string(i) + " is not an array of numbers");
        }
    }
    int T = 0;
    try {
        T = t[7].cast<int>();
    } catch (const py::cast_error&) {
        fail(fn, "problem " + std::to_string(k) + ": T does not fit in an int");
    }
    return make_problem(a[0], a[1], a[2], a[3], a[4], a[5], a[6], T, fn);
}

py::dict result_dict(GdtResult&& r, bool paths_only) {
    py::dict d;
    d["path"] = std::move(r.path);
    if (!paths_only) {
        const Index n = r.x0_mean.size();
        RowMatrixXd eps = std::move(r.eps);
        RowMatrixXd cov = std::move(r.cov);
        py::array_t<double> e = py::cast(std::move(eps));
        py::array_t<double> c = py::cast(std::move(cov));
        d["eps"] = e.reshape({e.shape(0), static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(n)});
        d["cov"] = c.reshape({c.shape(0), static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(n)});
        d["x0_mean"] = std::move(r.x0_mean);
        d["x0_cov"] = std::move(r.x0_cov);
    }
    return d;
}

}  // namespace

void register_bridge(py::module_& m) {
    m.def(
        "gdt_solve",
        [](const Array& A, const Array& Q, const Array& H, const Array& Pi_T, const Array& m0,
           const Array& Pi_0, const Array& y, int T, const std::string& form,
           bool start_conditioned) {
            const GdtForm f = parse_form(form, "gdt_solve");
            GdtProblem p = make_problem(A, Q, H, Pi_T, m0, Pi_0, y, T, "gdt_solve");
            GdtResult r;
            {
                py::gil_scoped_release nogil;  // safe: C++ copies of the inputs only
                r = gdt_solve(p, f, start_conditioned);
            }
            require_finite_result(r.path, "gdt_solve");
            require_finite_result(r.cov, "gdt_solve");
            return result_dict(std::move(r), false);
        },
        py::arg("A"), py::arg("Q"), py::arg("H"), py::arg("Pi_T"), py::arg("m0"), py::arg("Pi_0"),
        py::arg("y"), py::arg("T"), py::arg("form") = "general",
        py::arg("start_conditioned") = true,
        "Goal-directed path: dict path (T+1, n), eps (T, n, n), cov (T+1, n, n), x0_mean, x0_cov.");
    m.def(
        "gdt_sample",
        [](const Array& A, const Array& Q, const Array& H, const Array& Pi_T, const Array& m0,
           const Array& Pi_0, const Array& y, int T, int n_samples, std::uint64_t seed,
           const std::string& form, bool start_conditioned) {
            const GdtForm f = parse_form(form, "gdt_sample");
            GdtProblem p = make_problem(A, Q, H, Pi_T, m0, Pi_0, y, T, "gdt_sample");
            require(n_samples >= 0, "gdt_sample", "n_samples", n_samples, ">= 0");
            require_size(static_cast<double>(n_samples) * (static_cast<double>(T) + 1.0) *
                             static_cast<double>(p.m0.size()),
                         "gdt_sample", "n_samples paths of T steps");
            RowMatrixXd out;
            {
                py::gil_scoped_release nogil;  // safe: C++ copies of the inputs only
                out = gdt_sample(p, f, start_conditioned, n_samples, seed);
            }
            require_finite_result(out, "gdt_sample");
            const py::ssize_t n = static_cast<py::ssize_t>(p.m0.size());
            py::array_t<double> a = py::cast(std::move(out));
            return a.reshape({static_cast<py::ssize_t>(n_samples), static_cast<py::ssize_t>(T + 1), n});
        },
        py::arg("A"), py::arg("Q"), py::arg("H"), py::arg("Pi_T"), py::arg("m0"), py::arg("Pi_0"),
        py::arg("y"), py::arg("T"), py::arg("n_samples"), py::arg("seed"),
        py::arg("form") = "general", py::arg("start_conditioned") = true,
        "Sampled goal-directed paths (n_samples, T+1, n), eps_t noise from a counter-based seed.");
    m.def(
        "gdt_solve_batch",
        [](const py::list& problems, const std::string& form, bool start_conditioned,
           bool paths_only) {
            const GdtForm f = parse_form(form, "gdt_solve_batch");
            std::vector<GdtProblem> ps;
            ps.reserve(problems.size());
            for (const py::handle& h : problems) ps.push_back(batch_problem(h, ps.size()));
            std::vector<GdtResult> rs(ps.size());
            {
                py::gil_scoped_release nogil;  // safe: C++ copies of the inputs only
                for (size_t i = 0; i < ps.size(); ++i) rs[i] = gdt_solve(ps[i], f, start_conditioned);
            }
            py::list out;
            for (auto& r : rs) {
                require_finite_result(r.path, "gdt_solve_batch");
                if (!paths_only) require_finite_result(r.cov, "gdt_solve_batch");
                out.append(result_dict(std::move(r), paths_only));
            }
            return out;
        },
        py::arg("problems"), py::arg("form") = "general", py::arg("start_conditioned") = true,
        py::arg("paths_only") = false,
        "Many problems (tuples A, Q, H, Pi_T, m0, Pi_0, y, T) in one call, GIL released.");
    m.def(
        "kalman_filter",
        [](const Array& z, const Array& A, const Array& Q, const Array& H, const Array& R,
           const Array& m_init, const Array& P_init) {
            const char* fn = "kalman_filter";
            const RowMatrixXd zz = matrix2(z, fn, "z");
            const MatrixXd a = matrix2(A, fn, "A"), q = matrix2(Q, fn, "Q"), h = matrix2(H, fn, "H"),
                           r = matrix2(R, fn, "R"), p0 = matrix2(P_init, fn, "P_init");
            const VectorXd m0 = vector1(m_init, fn, "m_init");
            require_finite(zz, fn, "z");
            require_finite(m0, fn, "m_init");
            require_finite(p0, fn, "P_init");
            KalmanEstimate e;
            {
                py::gil_scoped_release nogil;  // safe: C++ copies of the inputs only
                e = kalman_filter(zz, a, q, h, r, m0, p0);
            }
            require_finite_result(e.m, fn);
            require_finite_result(e.P, fn);
            return py::make_tuple(e.m, e.P);
        },
        py::arg("z"), py::arg("A"), py::arg("Q"), py::arg("H"), py::arg("R"), py::arg("m_init"),
        py::arg("P_init"), "Filtered (m (n,), P (n, n)) after the last of z (K, m).");
    m.def(
        "gdt_recover_batch",
        [](Eigen::Ref<const RowMatrixXd> seg_a, Eigen::Ref<const Eigen::VectorXi> a_len,
           Eigen::Ref<const RowMatrixXd> seg_b, Eigen::Ref<const Eigen::VectorXi> b_len,
           const Array& A, const Array& Q, const Array& H, const Array& R, double p_init_velocity,
           const std::string& goal, int history, bool start_conditioned) {
            const char* fn = "gdt_recover_batch";
            SegmentModel model{matrix2(A, fn, "A"), matrix2(Q, fn, "Q"), matrix2(H, fn, "H"),
                               matrix2(R, fn, "R"), p_init_velocity};
            GoalKind kind;
            if (goal == "first_point") kind = GoalKind::first_point;
            else if (goal == "backward_state") kind = GoalKind::backward_state;
            else fail(fn, "goal is '" + goal + "', expected 'first_point' or 'backward_state'");
            py::gil_scoped_release nogil;  // safe: Eigen views and C++ copies only
            return gdt_recover_batch(seg_a, a_len, seg_b, b_len, model, kind, history,
                                     start_conditioned);
        },
        py::arg("seg_a"), py::arg("a_len"), py::arg("seg_b"), py::arg("b_len"), py::arg("A"),
        py::arg("Q"), py::arg("H"), py::arg("R"), py::arg("p_init_velocity"), py::arg("goal"),
        py::arg("history"), py::arg("start_conditioned"),
        "Interior positions (sum(T_g - 1), m) of every gap; segments stacked (frame, pos...).");
    m.def(
        "noise_loglik_grid",
        [](Eigen::Ref<const Eigen::VectorXd> z, Eigen::Ref<const Eigen::VectorXi> lengths,
           Eigen::Ref<const Eigen::VectorXd> q, Eigen::Ref<const Eigen::VectorXd> r) {
            py::gil_scoped_release nogil;  // safe: Eigen views only
            return noise_loglik_grid(z, lengths, q, r);
        },
        py::arg("z"), py::arg("lengths"), py::arg("q"), py::arg("r"),
        "Log-likelihood (G,) of runs z (stacked, lengths) under each (q, r) pair.");
    m.def(
        "gap_mixture",
        [](Eigen::Ref<const Eigen::VectorXd> z, Index fa, Index fb, Eigen::Ref<const RowMatrixXd> F,
           Eigen::Ref<const RowMatrixXd> Q, double r, Eigen::Ref<const Eigen::VectorXd> p0,
           Eigen::Ref<const Eigen::VectorXi> t1, Eigen::Ref<const Eigen::VectorXi> t2, double v2) {
            GapMixtureResult res;
            {
                py::gil_scoped_release nogil;  // safe: Eigen views and C++ copies only
                res = gap_mixture(z, fa, fb, F, Q, r, p0, t1, t2, v2);
            }
            return py::make_tuple(std::move(res.paths), std::move(res.loglik));
        },
        py::arg("z"), py::arg("fa"), py::arg("fb"), py::arg("F"), py::arg("Q"), py::arg("r"),
        py::arg("p0"), py::arg("t1"), py::arg("t2"), py::arg("v2"),
        "Smoothed gap positions (H, T-1) and window log-likelihoods (H,) per stand hypothesis.");
    m.def(
        "gap_mixture_many",
        [](const py::sequence& jobs, const py::sequence& F, const py::sequence& Q,
           const std::vector<double>& r, const py::sequence& p0, const std::vector<double>& v2,
           int threads) {
            const char* fn = "gap_mixture_many";
            // everything is copied into C++ objects while the GIL is held
            auto as = [&](const py::handle& item, const std::string& what, auto* out) {
                using T = std::remove_pointer_t<decltype(out)>;
                try {
                    *out = item.cast<T>();
                } catch (const py::cast_error&) {
                    throw py::type_error(std::string(fn) + ": " + what + " is " +
                                         std::string(py::str(py::type::of(item).attr("__name__"))) +
                                         ", expected an array of numbers of the right shape");
                }
            };
            GapMixtureModels models;
            models.r = r;
            models.v2 = v2;
            const auto K = r.size();
            require(py::len(F) == K && py::len(Q) == K && py::len(p0) == K && v2.size() == K, fn,
                    "F, Q, r, p0 and v2 must have one entry per model");
            models.F.resize(K);
            models.Q.resize(K);
            models.p0.resize(K);
            for (std::size_t k = 0; k < K; ++k) {
                const std::string at = "[" + std::to_string(k) + "]";
                as(F[k], "F" + at, &models.F[k]);
                as(Q[k], "Q" + at, &models.Q[k]);
                as(p0[k], "p0" + at, &models.p0[k]);
            }
            std::vector<GapMixtureJob> batch(py::len(jobs));
            for (std::size_t j = 0; j < batch.size(); ++j) {
                const std::string what = "jobs[" + std::to_string(j) + "]";
                const py::object item = jobs[j];
                require(py::isinstance<py::tuple>(item) && py::len(item) == 6, fn,
                        what + " must be a tuple (z, fa, fb, model, t1, t2)");
                const auto t = item.cast<py::tuple>();
                GapMixtureJob& g = batch[j];
                as(t[0], what + ".z", &g.z);
                as(t[1], what + ".fa", &g.fa);
                as(t[2], what + ".fb", &g.fb);
                as(t[3], what + ".model", &g.model);
                as(t[4], what + ".t1", &g.t1s);
                as(t[5], what + ".t2", &g.t2s);
            }
            std::vector<GapMixtureResult> res;
            {
                py::gil_scoped_release nogil;  // safe: C++ copies only
                res = gap_mixture_many(batch, models, threads);
            }
            py::list out;
            for (auto& g : res) out.append(py::make_tuple(std::move(g.paths), std::move(g.loglik)));
            return out;
        },
        py::arg("jobs"), py::arg("F"), py::arg("Q"), py::arg("r"), py::arg("p0"), py::arg("v2"),
        py::arg("threads"),
        "gap_mixture of every job (z, fa, fb, model, t1, t2) on up to `threads` threads: a list "
        "of (paths, loglik), the same as one gap_mixture call per job.");
    m.def(
        "state_loglik_batch",
        [](Eigen::Ref<const Eigen::VectorXd> z, Eigen::Ref<const Eigen::VectorXi> lengths,
           Eigen::Ref<const RowMatrixXd> F, Eigen::Ref<const RowMatrixXd> Q,
           Eigen::Ref<const Eigen::VectorXd> r, double big, int threads) {
            py::gil_scoped_release nogil;  // safe: Eigen views only
            return state_loglik_batch(z, lengths, F, Q, r, big, threads);
        },
        py::arg("z"), py::arg("lengths"), py::arg("F"), py::arg("Q"), py::arg("r"), py::arg("big"),
        py::arg("threads") = 1,
        "Kalman log-likelihood (K,) of runs z (stacked, lengths) under K models (F, Q stacked), "
        "on up to `threads` threads (the same values with any number).");
}
