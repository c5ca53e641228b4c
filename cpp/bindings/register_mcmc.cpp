// Bindings of the comparison samplers: the per-object Metropolis-Hastings step (mh.hpp) and the
// RJ-MCMC joint tracker (rjmcmc.hpp), with the RJ-MCMC test hooks (log target, log acceptance
// ratio and proposals of single moves on a prepared frame).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <memory>
#include <optional>
#include <string>

#include "arrays.hpp"
#include "pickling.hpp"
#include "pftrack/mh.hpp"
#include "pftrack/rjmcmc.hpp"
#include "step_args.hpp"

namespace py = pybind11;
using namespace pftrack;


namespace {

RjMove parse_move(const std::string& name, const char* fn) {
    if (name == "birth") return RjMove::kBirth;
    if (name == "death") return RjMove::kDeath;
    if (name == "update") return RjMove::kUpdate;
    if (name == "swap") return RjMove::kSwap;
    fail(fn, "move is '" + name + "', expected 'birth', 'death', 'update' or 'swap'");
}

const char* kMoveNames[4] = {"birth", "death", "update", "swap"};

/// The foreground integral of `mask_in` (its array is held by the caller, FgIntegral points
/// into it: a py::object parameter of the binding).
FgIntegral make_fg(const py::object& mask_in, const BinnedImage& image, const char* fn) {
    const py::array mask = bind::mask_array(mask_in, fn);
    bind::check_mask(mask, image.rows, image.cols, fn);
    return FgIntegral(static_cast<const std::uint8_t*>(mask.data()), image.rows, image.cols,
                      mask.strides(0));
}

RowMatrixXd optional_hists(const std::optional<RowMatrixXd>& h, const char* fn) {
    if (!h) return RowMatrixXd(0, 0);
    require_finite(*h, fn, "candidate_hists");
    return *h;
}

/// The Python-side tracker: the C++ tracker plus, for the test hooks, one prepared frame.
struct PyRjTracker {
    RJMCMCTracker tracker;
    std::shared_ptr<BinnedImage> image;  // keeps the prepared frame's bins alive
    std::unique_ptr<RjFrame> frame;

    RjFrame& prepared(const char* fn) {
        require(frame != nullptr, fn, "no prepared frame: call prepare(image, mask, candidates) first");
        return *frame;
    }

    RjConfig config(RjFrame& f, const Eigen::Ref<const Eigen::VectorXi>& slots,
                    const Eigen::Ref<const RowMatrixXd>& states, const char* fn) {
        require(states.rows() == slots.size(), fn, "states rows", states.rows(), slots.size());
        require(states.cols() == 6 || slots.size() == 0, fn, "states cols", states.cols(),
                "6 (cx, cy, s, previous cx, cy, s)");
        require_finite(states, fn, "states");
        RjConfig c;
        for (Index i = 0; i < slots.size(); ++i) {
            require(slots(i) >= 0 && slots(i) < f.n_slots(), fn, "slot", slots(i),
                    "in [0, number of slots)");
            require(!RjFrame::present(c, slots(i)), fn, "slots must be distinct");
            RjObject o;
            o.slot = slots(i);
            for (int d = 0; d < 3; ++d) {
                o.x[d] = states(i, d);
                o.prev[d] = states(i, 3 + d);
            }
            c.push_back(o);
        }
        std::sort(c.begin(), c.end(), [](const RjObject& a, const RjObject& b) { return a.slot < b.slot; });
        f.fill_unary(c);
        return c;
    }
};

py::tuple config_arrays(const RjConfig& c) {
    Eigen::VectorXi slots(static_cast<Index>(c.size()));
    RowMatrixXd states(static_cast<Index>(c.size()), 6);
    for (size_t j = 0; j < c.size(); ++j) {
        slots(static_cast<Index>(j)) = c[j].slot;
        for (int d = 0; d < 3; ++d) {
            states(static_cast<Index>(j), d) = c[j].x[d];
            states(static_cast<Index>(j), 3 + d) = c[j].prev[d];
        }
    }
    return py::make_tuple(slots, states);
}

}  // namespace

void register_mcmc(py::module_& m) {
    m.def(
        "mh_step",
        [](const py::object& particles_in, const py::object& weights_in,
           const py::object& means_in, const BinnedImage& image,
           Eigen::Ref<const Eigen::VectorXd> ref, double w0, double h0, const Eigen::Vector3d& a,
           const Eigen::Vector3d& b, const Eigen::Vector3d& sigma, double s_min, double s_max,
           bool use_means, double lam, const std::string& kernel, bool resample, std::uint64_t seed,
           std::uint64_t step, int n_iter, int burn_in, const std::string& proposal,
           const Eigen::Vector3d& rw_sigma, double min_samples) {
            const char* fn = "mh_step";
            // written in place: checked here, one line (was pybind11's list of signatures)
            Eigen::Map<RowMatrixXd> particles = bind::inplace_matrix(particles_in, fn, "particles");
            Eigen::Map<Eigen::VectorXd> weights = bind::inplace_vector(weights_in, fn, "weights");
            Eigen::Map<RowMatrixXd> means = bind::inplace_matrix(means_in, fn, "means");
            MhParams prm;
            prm.base = bind::make_step_params(w0, h0, a, b, sigma, s_min, s_max, use_means, lam,
                                              kernel, resample, fn);
            prm.n_iter = n_iter;
            prm.burn_in = burn_in;
            if (proposal == "dynamics")
                prm.proposal = MhProposal::kDynamics;
            else if (proposal == "random_walk")
                prm.proposal = MhProposal::kRandomWalk;
            else
                fail(fn, "proposal is '" + proposal + "', expected 'dynamics' or 'random_walk'");
            prm.rw_sigma = rw_sigma.array();
            prm.base.min_samples = min_samples;  // checked by mh_step, as sis_step checks it
            MhResult r;
            {
                py::gil_scoped_release nogil;  // safe: Eigen views and the C++ image only
                r = mh_step(particles, weights, means, image.lazy_view(), ref, prm, seed, step);
            }
            py::dict out = bind::step_result_dict(r);
            out["acceptance"] = r.acceptance;
            return out;
        },
        py::arg("particles"), py::arg("weights"), py::arg("means"), py::arg("image"), py::arg("ref"), py::arg("w0"),
        py::arg("h0"), py::arg("a"), py::arg("b"), py::arg("sigma"), py::arg("s_min"),
        py::arg("s_max"), py::arg("use_means"), py::arg("lam"), py::arg("kernel"),
        py::arg("resample"), py::arg("seed"), py::arg("step"), py::arg("n_iter") = 1,
        py::arg("burn_in") = 0, py::arg("proposal") = "dynamics",
        py::arg("rw_sigma") = Eigen::Vector3d(2.0, 2.0, 0.01), py::arg("min_samples") = 0.0,
        "Resample, then n_iter Metropolis-Hastings iterations per particle (eq. 5); particles "
        "(N, 6), weights (N,), means (2, 3) updated in place; returns sis_step's dict + acceptance. "
        "min_samples as sis_step's: boxes counted on the lattice sis_step would use (the step of "
        "the previous mean state's box), 0 every pixel.");

    py::class_<PyRjTracker>(m, "RJMCMCTracker",
                            "Reversible-jump MCMC joint tracker (birth, death, update, swap).")
        .def(py::init([](int burn_in, int n_samples, double p_birth, double p_death,
                         double p_update, double p_swap, const Eigen::Vector3d& a,
                         const Eigen::Vector3d& b, const Eigen::Vector3d& sigma, double s_min,
                         double s_max, double lam, const std::string& kernel, double interaction,
                         double coverage, double background_penalty, double birth_prior, double survival,
                         double birth_sigma_xy, double birth_sigma_s, double birth_eps,
                         double birth_gate, double detection, double min_samples) {
                 RjParams p;
                 p.burn_in = burn_in;
                 p.n_samples = n_samples;
                 p.p_birth = p_birth;
                 p.p_death = p_death;
                 p.p_update = p_update;
                 p.p_swap = p_swap;
                 p.model.a = a.array();
                 p.model.b = b.array();
                 p.model.sigma = sigma.array();
                 p.model.s_min = s_min;
                 p.model.s_max = s_max;
                 p.lambda = lam;
                 p.kernel = parse_kernel(kernel, "RJMCMCTracker");
                 p.interaction = interaction;
                 p.coverage = coverage;
                 p.background_penalty = background_penalty;
                 p.birth_prior = birth_prior;
                 p.survival = survival;
                 p.birth_sigma_xy = birth_sigma_xy;
                 p.birth_sigma_s = birth_sigma_s;
                 p.birth_eps = birth_eps;
                 p.birth_gate = birth_gate;
                 p.detection = detection;
                 p.min_samples = min_samples;
                 return PyRjTracker{RJMCMCTracker(p), nullptr, nullptr};
             }),
             py::arg("burn_in") = 50, py::arg("n_samples") = 200, py::arg("p_birth") = 0.1,
             py::arg("p_death") = 0.1, py::arg("p_update") = 0.7, py::arg("p_swap") = 0.1,
             py::arg("a") = Eigen::Vector3d(2.0, 2.0, 2.0),
             py::arg("b") = Eigen::Vector3d(-1.0, -1.0, -1.0),
             py::arg("sigma") = Eigen::Vector3d(4.0, 4.0, 0.02), py::arg("s_min") = 0.2,
             py::arg("s_max") = 5.0, py::arg("lam") = 10.0, py::arg("kernel") = "uniform",
             py::arg("interaction") = 10.0, py::arg("coverage") = 20.0, py::arg("background_penalty") = 0.25,
             py::arg("birth_prior") = 2.0, py::arg("survival") = 0.95,
             py::arg("birth_sigma_xy") = 3.0, py::arg("birth_sigma_s") = 0.05,
             py::arg("birth_eps") = 0.02, py::arg("birth_gate") = 0.1,
             py::arg("detection") = 20.0, py::arg("min_samples") = 0.0)
        .def("__reduce__",
             bind::refuse_pickle("RJMCMCTracker", "its chain has no pickled form of its own "
                                                  "(pickle the RJMCMCFilter, whose state is "
                                                  ".tracks and .next_id, given back by "
                                                  ".restore)"))
        .def(
            "step",
            [](PyRjTracker& self, const BinnedImage& image, const py::object& mask,
               Eigen::Ref<const RowMatrixXd> candidates, std::optional<RowMatrixXd> candidate_hists,
               std::uint64_t seed, std::uint64_t step) {
                const char* fn = "rjmcmc_step";
                const bind::InUse busy(&self, fn);
                FgIntegral fg = make_fg(mask, image, fn);
                const RowMatrixXd hists = optional_hists(candidate_hists, fn);
                RjStepResult r;
                {
                    py::gil_scoped_release nogil;  // safe: C++ objects and Eigen views only
                    r = self.tracker.step(image.view(), std::move(fg), candidates, hists, seed, step);
                }
                py::dict out, acc;
                out["estimates"] = r.estimates;
                out["map"] = r.map;
                for (int k = 0; k < 4; ++k)
                    acc[kMoveNames[k]] = py::make_tuple(r.accepted[k], r.proposed[k]);
                out["acceptance"] = acc;
                out["mean_objects"] = r.mean_objects;
                out["map_log_target"] = r.map_log_target;
                return out;
            },
            py::arg("image"), py::arg("mask"), py::arg("candidates"),
            py::arg("candidate_hists") = py::none(), py::arg("seed"), py::arg("step"),
            "One frame. mask (H, W) uint8/bool, candidates (K, 4) cx, cy, w, h, candidate_hists "
            "(K, B) or None (computed from the image). Returns dict(estimates (M, 6) id, cx, cy, "
            "w, h, existence; map (Q, 5); acceptance {move: (accepted, proposed)}; ...).")
        .def_property_readonly(
            "tracks",
            [](const PyRjTracker& self) {
                const bind::InUse busy(&self, "RJMCMCTracker.tracks", true);
                py::list out;
                for (const auto& t : self.tracker.tracks()) {
                    py::dict d;
                    d["id"] = t.id;
                    d["w0"] = t.w0;
                    d["h0"] = t.h0;
                    d["ref"] = t.ref;
                    d["parents"] = t.parents;
                    d["existence"] = t.existence;
                    out.append(d);
                }
                return out;
            },
            "The identities kept for the next frame (id, w0, h0, ref, parents (N_i, 6), existence).")
        .def(
            "warp",
            [](PyRjTracker& self, Eigen::Ref<const RowMatrixXd> affine) {
                const bind::InUse busy(&self, "RJMCMCTracker.warp");
                self.tracker.warp(affine);
            },
            py::arg("affine"),
            "Move the kept identities by a similarity transform affine (2, 3), previous frame's "
            "pixels to this frame's (camera-motion compensation).")
        .def_property_readonly(
            "next_id",
            [](const PyRjTracker& self) {
                const bind::InUse busy(&self, "RJMCMCTracker.next_id", true);
                return self.tracker.next_id();
            },
            "The id the next newborn identity gets.")
        .def(
            "restore",
            [](PyRjTracker& self, const py::list& tracks, std::int64_t next_id) {
                const char* fn = "RJMCMCTracker.restore";
                std::vector<RJMCMCTracker::Track> ts;
                for (const py::handle& h : tracks) {
                    require(py::isinstance<py::dict>(h), fn,
                            "tracks must be dicts as RJMCMCTracker.tracks gives them");
                    const auto d = py::reinterpret_borrow<py::dict>(h);
                    for (const char* key : {"id", "w0", "h0", "ref", "parents", "existence"})
                        require(d.contains(key), fn, std::string("a track has no '") + key + "'");
                    try {
                        ts.push_back({d["id"].cast<std::int64_t>(), d["w0"].cast<double>(),
                                      d["h0"].cast<double>(), d["ref"].cast<Eigen::VectorXd>(),
                                      d["parents"].cast<RowMatrixXd>(),
                                      d["existence"].cast<double>()});
                    } catch (const py::cast_error&) {
                        throw py::type_error(std::string(fn) + ": a track's id is not an int, or "
                                             "w0, h0, existence not numbers, or ref, parents "
                                             "not float arrays");
                    }
                }
                const bind::InUse busy(&self, fn);
                self.tracker.restore(std::move(ts), next_id);
            },
            py::arg("tracks"), py::arg("next_id"),
            "Replace the kept identities (dicts as .tracks gives them) and the next fresh id: "
            "a checkpoint's resume.")
        // ---- test hooks: single moves on a prepared frame ----
        .def(
            "prepare",
            [](PyRjTracker& self, const BinnedImage& image, const py::object& mask,
               Eigen::Ref<const RowMatrixXd> candidates, std::optional<RowMatrixXd> candidate_hists) {
                const bind::InUse busy(&self, "RJMCMCTracker.prepare");
                const char* fn = "prepare";
                FgIntegral fg = make_fg(mask, image, fn);
                self.image = std::make_shared<BinnedImage>(image);
                self.frame = std::make_unique<RjFrame>(self.tracker.make_frame(
                    self.image->view(), std::move(fg), candidates, optional_hists(candidate_hists, fn)));
            },
            py::arg("image"), py::arg("mask"), py::arg("candidates"),
            py::arg("candidate_hists") = py::none(),
            "Build (without running) the frame model used by the hooks below.")
        .def(
            "slots",
            [](PyRjTracker& self) {
                const bind::InUse busy(&self, "RJMCMCTracker.slots");
                py::list out;
                for (const RjIdentity& id : self.prepared("slots").identities()) {
                    py::dict d;
                    d["id"] = id.id;
                    d["candidate"] = id.candidate;
                    d["w0"] = id.w0;
                    d["h0"] = id.h0;
                    d["ref"] = id.ref;
                    d["log_omega"] = id.log_omega;
                    d["parents"] = id.parents;
                    d["anchor"] = Eigen::Vector4d(id.anchor[0], id.anchor[1], id.anchor[2], id.anchor[3]);
                    out.append(d);
                }
                return out;
            },
            "The prepared frame's identity table.")
        .def(
            "log_target",
            [](PyRjTracker& self, Eigen::Ref<const Eigen::VectorXi> slots,
               Eigen::Ref<const RowMatrixXd> states) {
                const bind::InUse busy(&self, "RJMCMCTracker.log_target");
                RjFrame& f = self.prepared("log_target");
                return f.log_target(self.config(f, slots, states, "log_target"));
            },
            py::arg("slots"), py::arg("states"), "log pi(X) of a configuration on the prepared frame.")
        .def(
            "log_acceptance",
            [](PyRjTracker& self, const std::string& move, Eigen::Ref<const Eigen::VectorXi> slots,
               Eigen::Ref<const RowMatrixXd> states, Eigen::Ref<const Eigen::VectorXi> to_slots,
               Eigen::Ref<const RowMatrixXd> to_states, int slot) {
                const bind::InUse busy(&self, "RJMCMCTracker.log_acceptance");
                const char* fn = "log_acceptance";
                RjFrame& f = self.prepared(fn);
                const RjMove mv = parse_move(move, fn);
                const RjConfig x = self.config(f, slots, states, fn);
                const RjConfig xp = self.config(f, to_slots, to_states, fn);
                return f.log_acceptance_ratio(mv, x, xp, slot);
            },
            py::arg("move"), py::arg("slots"), py::arg("states"), py::arg("to_slots"),
            py::arg("to_states"), py::arg("slot") = -1,
            "log r of one move X -> X' (the chain accepts with min(1, r)).")
        .def(
            "propose",
            [](PyRjTracker& self, const std::string& move, Eigen::Ref<const Eigen::VectorXi> slots,
               Eigen::Ref<const RowMatrixXd> states, std::uint64_t seed, std::uint64_t step,
               std::uint64_t k) -> py::object {
                const bind::InUse busy(&self, "RJMCMCTracker.propose");
                const char* fn = "propose";
                RjFrame& f = self.prepared(fn);
                const RjMove mv = parse_move(move, fn);
                const RjConfig x = self.config(f, slots, states, fn);
                const CounterRng ur(seed, step);
                const CounterRng nr(mix64(seed ^ 0xD1B54A32D192ED03ULL), step);
                RjConfig out;
                int slot = -1;
                if (!f.propose(mv, x, ur, nr, k, out, slot)) return py::none();
                py::tuple arrays = config_arrays(out);
                return py::make_tuple(arrays[0], arrays[1], slot);
            },
            py::arg("move"), py::arg("slots"), py::arg("states"), py::arg("seed"), py::arg("step"),
            py::arg("k"),
            "The proposal of one move with the draws of chain iteration k: (slots, states, slot) "
            "or None when the move is impossible.");
}
