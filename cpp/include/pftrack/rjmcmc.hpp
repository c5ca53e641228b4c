// Reversible-jump MCMC joint multi-object tracker (Smith, Gatica-Perez & Odobez, CVPR 2005; the
// first paper's algorithm 1, the method it compares against).
//
// One Markov chain per frame over the JOINT configuration X = {(i, x_i)} of a varying number of
// objects: i is an identity ("slot" of the frame's identity table: the identities kept from the
// previous frame, then one newborn slot per birth candidate), x_i = (cx, cy, s) its state, box
// (cx, cy, s w0_i, s h0_i). The chain targets
//
//   log pi(X) = sum_{i in X} [ -lambda D^2(q*_i, q(x_i))              colour likelihood (eq. 9-10)
//                              + log P_i(x_i)                         predictive prior of i
//                              + log omega_i                          prior odds that i is present
//                              + kappa cov(b_i)                       foreground coverage
//                              + delta max_k IoU(b_i, d_k) ]          detection support
//             + sum_{i<j}  [ -gamma IoU(b_i, b_j)                     pairwise interaction prior
//                            - kappa cov(b_i & b_j) ]                 (inclusion-exclusion)
//
//   cov(b) = [ fg(b) - eta (|b| - fg(b)) ] / F
//
// where fg(b) counts foreground pixels of box b (integral image of the mask), |b| its pixels,
// F the frame's foreground pixels: the coverage term is kappa [C - eta (A - C)] / F with C the
// covered foreground and A the covered area of the union of the boxes (recall of the foreground
// minus eta times the background covered), exact while no three boxes overlap.
// P_i is, for an identity of the previous frame, the mixture of its AR2 predictions from the
// previous kept samples that contain it,  P_i(x) = 1/N_i sum_n N(x; A x_n + B x'_n, C^2)
// (Khan et al. 2005's factored predictive prior), and for a newborn of candidate k,
// P_k(x) = N(x; (cx_k, cy_k, 1), diag(tau_xy^2, tau_xy^2, tau_s^2)). Outside s in [s_min, s_max]
// the target is 0. d_k are all the frame's candidate (detector) boxes: the detections support the
// identities they overlap (a unary term: the ratios below keep their form). omega_i =
// e_i / (1 - e_i) with e_i = p_survive x (fraction of the previous kept samples containing i),
// clipped to [1e-3, 1 - 1e-3]; omega_k = beta for a newborn.
//
// Identity table and birth gate: a candidate whose box overlaps the mean prediction of an identity
// with existence >= 1/2 by IoU >= birth_gate gets NO newborn slot (it is that identity's
// detection). Without the gate a newborn slot sits on every detected person: its reference is the
// histogram of this very box and its prior a tight Gaussian on it, so it out-scores the kept
// identity (older reference, broad AR2 prior), and death + birth hand every person a new id
// every ~4 frames. The gate only decides which slots exist in this frame; the chain and its
// ratios below are unchanged (the detailed-balance test covers them).
//
// Moves, chosen with probabilities p_b, p_d, p_u, p_s (a move that is impossible in X, e.g. a
// death in the empty configuration, leaves X unchanged):
//   birth  X -> X u {(o, x)}: o among the slots absent from X with probability
//            q_b(o|X) = w_o(X) / sum_{o' not in X} w_o'(X),
//            w_o(X) = eps + fgfrac(a_o) prod_{j in X} (1 - |a_o & b_j| / |a_o|)
//            (a_o: the slot's anchor box: candidate box, or the identity's mean prediction; the
//            weight is the share of the anchor's foreground not yet explained by X), x ~ P_o.
//            The new dimensions are drawn directly (x = u), so the Jacobian is 1:
//     r_birth = pi(X') p_d (1/|X'|) / [ pi(X) p_b q_b(o|X) P_o(x) ]
//   death  X -> X \ {o}, o uniform among X:
//     r_death = pi(X') p_b q_b(o|X') P_o(x_o) / [ pi(X) p_d (1/|X|) ]          (= 1 / r_birth)
//   update X -> X with x_o replaced by x* ~ P_o (a previous sample n uniform, then the AR2
//            dynamics from it; for a newborn, around the candidate), o uniform among X:
//     r_update = pi(X') p_u (1/|X|) P_o(x_o) / [ pi(X) p_u (1/|X|) P_o(x*) ]
//   swap   X -> X with the states (and motion histories) of two identities i != j exchanged,
//            {i, j} uniform among the |X|(|X|-1)/2 pairs; symmetric:
//     r_swap = pi(X') [p_s / C(|X|, 2)] / ( pi(X) [p_s / C(|X|, 2)] )
// accepted when u < r. The P_o factors cancel numerically in birth/death/update (the proposals
// are the priors) but are computed as written. B burn-in iterations, then N kept samples (the
// chain's state after each iteration, repeats included).
//
// Estimates: for each identity present in any kept sample, its existence probability (share of
// kept samples containing it) and mean state over those samples; and the MAP sample (highest
// log pi among the kept samples). Newborn slots present in any kept sample become identities
// with fresh ids, base size and reference histogram of their candidate.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "histogram.hpp"
#include "integral_histogram.hpp"
#include "likelihood.hpp"
#include "propagate.hpp"
#include "rng.hpp"

namespace pftrack {

enum class RjMove { kBirth = 0, kDeath = 1, kUpdate = 2, kSwap = 3 };

constexpr double kNegInf = -std::numeric_limits<double>::infinity();

struct RjParams {
    int burn_in = 50;
    int n_samples = 200;
    double p_birth = 0.1, p_death = 0.1, p_update = 0.7, p_swap = 0.1;
    Ar2Model model;             // AR2 dynamics (use_means is ignored: each sample has its own past)
    double lambda = 10.0;       // colour likelihood exp(-lambda D^2)
    Kernel kernel = Kernel::kUniform;
    double interaction = 10.0;  // gamma: log Psi = -gamma sum_{i<j} IoU
    double coverage = 20.0;     // kappa
    double background_penalty = 0.25;  // eta
    double birth_prior = 2.0;   // beta: prior odds of a newborn
    double survival = 0.95;     // p_survive
    double birth_sigma_xy = 3.0, birth_sigma_s = 0.05;  // spread of P_k around a candidate
    double birth_eps = 0.02;    // eps of the birth weights
    double detection = 20.0;    // delta: log D_i = delta max_k IoU(b_i, d_k) over the candidates
    double birth_gate = 0.1;    // no newborn slot for a candidate with IoU >= this with a kept
                                // identity's predicted box (> 1: every candidate gets a slot)
    double min_samples = 0.0;   // large boxes counted on a lattice keeping >= this many points,
                                // as sis_step counts them (lattice_step); 0: every pixel

    void validate(const char* fn) const {
        require(burn_in >= 0, fn, "burn_in", burn_in, ">= 0");
        require(n_samples >= 1, fn, "n_samples", n_samples, ">= 1");
        // the chain counts its B + N iterations in an int: the sum must not overflow
        require(n_samples <= std::numeric_limits<int>::max() - burn_in, fn,
                "burn_in + n_samples", static_cast<std::int64_t>(burn_in) + n_samples,
                "<= 2147483647");
        const double p[4] = {p_birth, p_death, p_update, p_swap};
        for (double v : p) require(std::isfinite(v) && v >= 0.0, fn, "move probabilities must be >= 0");
        require(p_birth + p_death + p_update + p_swap > 0.0, fn, "move probabilities sum to 0");
        require((p_birth > 0.0) == (p_death > 0.0), fn,
                "p_birth and p_death must both be > 0 or both 0 (reversibility)");
        model.validate(fn);
        require((model.sigma > 0.0).all(), fn, "sigma must be > 0 for the RJ-MCMC prior densities");
        check_lambda(lambda, fn);
        require(std::isfinite(interaction) && interaction >= 0.0, fn, "interaction", interaction, ">= 0");
        require(std::isfinite(coverage) && coverage >= 0.0, fn, "coverage", coverage, ">= 0");
        require(std::isfinite(background_penalty) && background_penalty >= 0.0, fn,
                "background_penalty", background_penalty, ">= 0");
        require(std::isfinite(birth_prior) && birth_prior > 0.0, fn, "birth_prior", birth_prior, "> 0");
        require(std::isfinite(survival) && survival > 0.0 && survival <= 1.0, fn, "survival",
                survival, "in (0, 1]");
        require(std::isfinite(birth_sigma_xy) && birth_sigma_xy > 0.0 && std::isfinite(birth_sigma_s) &&
                    birth_sigma_s > 0.0,
                fn, "birth_sigma_xy and birth_sigma_s must be > 0");
        require(std::isfinite(birth_eps) && birth_eps > 0.0, fn, "birth_eps", birth_eps, "> 0");
        require(std::isfinite(birth_gate) && birth_gate > 0.0, fn, "birth_gate", birth_gate, "> 0");
        require(std::isfinite(min_samples) && min_samples >= 0.0, fn, "min_samples", min_samples,
                ">= 0");
        require(std::isfinite(detection) && detection >= 0.0, fn, "detection", detection, ">= 0");
    }
    double move_total() const { return p_birth + p_death + p_update + p_swap; }
    double move_prob(RjMove m) const {
        const double p[4] = {p_birth, p_death, p_update, p_swap};
        return p[static_cast<int>(m)] / move_total();
    }
};

/// An identity of the frame's table ("slot").
struct RjIdentity {
    std::int64_t id = -1;  // global id; -1 for a newborn slot
    int candidate = -1;    // >= 0: newborn of this birth candidate
    double w0 = 1.0, h0 = 1.0;
    Eigen::VectorXd ref;       // reference histogram (normalised)
    Eigen::VectorXd sqrt_ref;  // its square root
    double log_omega = 0.0;    // log prior odds of presence
    RowMatrixXd parents;       // (N_i, 6) previous kept states of this identity (x, x')
    RowMatrixXd mu;            // (N_i, 3) AR2 predictions A x + B x'
    std::vector<Index> runs;   // lengths of the runs of equal consecutive rows of mu (sum N_i)
    double anchor[4] = {0, 0, 0, 0};  // box for the birth weight
    Index lattice = 1;  // every box of this slot is counted on the lattice of this step
};

/// One object of a configuration; `unary` caches its single-object log-target term and
/// `log_prior` the log P_slot(x) inside it (the proposal density of the move ratios).
struct RjObject {
    int slot = 0;
    double x[3] = {0, 0, 1};
    double prev[3] = {0, 0, 1};
    double unary = 0.0;
    double log_prior = 0.0;
};

/// Lengths of the runs of equal consecutive rows of `mu` (bit for bit). The kept samples repeat
/// an identity's state until a move changes it (a rejected move, a move of another object), so
/// an identity's N_i predictions hold far fewer distinct rows than N_i.
inline std::vector<Index> equal_row_runs(const RowMatrixXd& mu) {
    std::vector<Index> runs;
    const auto bytes = static_cast<size_t>(mu.cols()) * sizeof(double);
    for (Index n = 0; n < mu.rows(); ++n) {
        if (n > 0 && std::memcmp(mu.row(n).data(), mu.row(n - 1).data(), bytes) == 0)
            ++runs.back();
        else
            runs.push_back(1);
    }
    return runs;
}
using RjConfig = std::vector<RjObject>;  // sorted by slot, at most one object per slot

/// Integral image of a foreground mask: S(y, x) = #fg pixels in rows < y, columns < x.
struct FgIntegral {
    std::vector<std::int64_t> s;
    Index rows = 0, cols = 0;
    double total = 0.0;

    FgIntegral() = default;
    FgIntegral(const std::uint8_t* mask, Index rows_, Index cols_, Index stride) : rows(rows_), cols(cols_) {
        s.assign(static_cast<size_t>((rows + 1) * (cols + 1)), 0);
        for (Index y = 0; y < rows; ++y) {
            std::int64_t run = 0;
            const std::uint8_t* m = mask + y * stride;
            for (Index x = 0; x < cols; ++x) {
                run += m[x] != 0 ? 1 : 0;
                at(y + 1, x + 1) = at(y, x + 1) + run;
            }
        }
        total = static_cast<double>(at(rows, cols));
    }
    std::int64_t& at(Index y, Index x) { return s[static_cast<size_t>(y * (cols + 1) + x)]; }
    std::int64_t get(Index y, Index x) const { return s[static_cast<size_t>(y * (cols + 1) + x)]; }
    double count(const PixelRange& r) const {
        if (r.empty()) return 0.0;
        return static_cast<double>(get(r.y1, r.x1) - get(r.y0, r.x1) - get(r.y1, r.x0) + get(r.y0, r.x0));
    }
};

inline double range_area(const PixelRange& r) {
    return r.empty() ? 0.0 : static_cast<double>((r.x1 - r.x0) * (r.y1 - r.y0));
}
inline PixelRange range_intersection(const PixelRange& a, const PixelRange& b) {
    return PixelRange{std::max(a.x0, b.x0), std::min(a.x1, b.x1), std::max(a.y0, b.y0),
                      std::min(a.y1, b.y1)};
}

/// IoU of two (cx, cy, w, h) boxes (continuous coordinates).
inline double iou_cxcywh(const double* a, const double* b) {
    const double iw = std::min(a[0] + a[2] / 2, b[0] + b[2] / 2) - std::max(a[0] - a[2] / 2, b[0] - b[2] / 2);
    const double ih = std::min(a[1] + a[3] / 2, b[1] + b[3] / 2) - std::max(a[1] - a[3] / 2, b[1] - b[3] / 2);
    if (iw <= 0.0 || ih <= 0.0) return 0.0;
    const double inter = iw * ih;
    return inter / (a[2] * a[3] + b[2] * b[3] - inter);
}

/// One frame's model: image, foreground integral, identity table and parameters. Every log-target,
/// proposal and acceptance term of the chain is computed here.
class RjFrame {
public:
    RjFrame(const BinImage& img, FgIntegral fg, std::vector<RjIdentity> ids, const RjParams& prm,
            std::vector<std::array<double, 4>> detections = {})
        : img_(img), fg_(std::move(fg)), ids_(std::move(ids)), prm_(prm),
          dets_(std::move(detections)), scratch_(img.n_bins), hist_(static_cast<size_t>(img.n_bins)) {}

    const std::vector<RjIdentity>& identities() const { return ids_; }
    const RjParams& params() const { return prm_; }
    int n_slots() const { return static_cast<int>(ids_.size()); }

    PixelRange box(int slot, const double* x) const {
        const RjIdentity& id = ids_[static_cast<size_t>(slot)];
        return box_pixels(x[0], x[1], x[2] * id.w0, x[2] * id.h0, img_.rows, img_.cols);
    }

    /// log P_slot(x), normalised density (the proposal of births and updates).
    double log_prior_pos(int slot, const double* x) const {
        const Ar2Model& m = prm_.model;
        if (!(x[2] >= m.s_min && x[2] <= m.s_max)) return kNegInf;
        const RjIdentity& id = ids_[static_cast<size_t>(slot)];
        constexpr double kLog2Pi = 1.8378770664093453;
        if (id.candidate >= 0) {
            const double sd[3] = {prm_.birth_sigma_xy, prm_.birth_sigma_xy, prm_.birth_sigma_s};
            const double c[3] = {id.anchor[0], id.anchor[1], 1.0};
            double lp = 0.0;
            for (int d = 0; d < 3; ++d) {
                const double z = (x[d] - c[d]) / sd[d];
                lp += -0.5 * z * z - std::log(sd[d]) - 0.5 * kLog2Pi;
            }
            return lp;
        }
        // log (1/N_i) sum_n N(x; mu_n, C^2), by log-sum-exp. Equal rows give equal terms: each
        // run of them is evaluated once (its exp added once per row, in the same order, so the
        // sum is the same double as row by row). An evaluation costs O(distinct rows) exps and
        // O(N_i) additions.
        const double norm = -std::log(m.sigma[0] * m.sigma[1] * m.sigma[2]) - 1.5 * kLog2Pi -
                            std::log(static_cast<double>(id.mu.rows()));
        double mx = kNegInf;
        lse_.resize(id.runs.size());
        Index n = 0;
        for (size_t r = 0; r < id.runs.size(); ++r) {
            double q = 0.0;
            for (int d = 0; d < 3; ++d) {
                const double z = (x[d] - id.mu(n, d)) / m.sigma[d];
                q -= 0.5 * z * z;
            }
            lse_[r] = q;
            mx = std::max(mx, q);
            n += id.runs[r];
        }
        double sum = 0.0;
        for (size_t r = 0; r < id.runs.size(); ++r) {
            const double e = std::exp(lse_[r] - mx);
            for (Index j = 0; j < id.runs[r]; ++j) sum += e;
        }
        return norm + mx + std::log(sum);
    }

    /// Colour log-likelihood -lambda D^2 of slot at x.
    double log_colour(int slot, const double* x) {
        const RjIdentity& id = ids_[static_cast<size_t>(slot)];
        double counted = 0.0;  // the slot's lattice (min_samples), or every pixel
        const double rho = state_coefficient(img_, x[0], x[1], x[2] * id.w0, x[2] * id.h0,
                                             id.sqrt_ref.data(), prm_.kernel, id.lattice, scratch_,
                                             hist_, counted);
        const double d = bhattacharyya_distance_from_rho(rho);
        return -prm_.lambda * d * d;
    }

    double coverage_of(const PixelRange& r) const {
        const double f = std::max(fg_.total, 1.0);
        const double c = fg_.count(r);
        // cov(b) = [fg(b) - eta (|b| - fg(b))] / F
        return prm_.coverage * (c - prm_.background_penalty * (range_area(r) - c)) / f;
    }

    /// Detection term delta max_k IoU(b, d_k) of slot at x (0 without candidates).
    double detection_of(int slot, const double* x) const {
        if (prm_.detection <= 0.0 || dets_.empty()) return 0.0;
        const RjIdentity& id = ids_[static_cast<size_t>(slot)];
        const double b[4] = {x[0], x[1], x[2] * id.w0, x[2] * id.h0};
        double best = 0.0;
        for (const auto& d : dets_) best = std::max(best, iou_cxcywh(b, d.data()));
        return prm_.detection * best;
    }

    /// The single-object term of log pi (-inf outside the scale bounds), given lp = log P_slot(x).
    double unary(int slot, const double* x, double lp) {
        if (!std::isfinite(lp)) return kNegInf;
        return log_colour(slot, x) + lp + ids_[static_cast<size_t>(slot)].log_omega +
               coverage_of(box(slot, x)) + detection_of(slot, x);
    }

    /// Fills o's cached terms (unary and log_prior) for its slot and state.
    void score(RjObject& o) {
        o.log_prior = log_prior_pos(o.slot, o.x);
        o.unary = unary(o.slot, o.x, o.log_prior);
    }

    /// The pairwise term of log pi for two objects.
    double pair(const RjObject& a, const RjObject& b) const {
        const PixelRange ra = box(a.slot, a.x), rb = box(b.slot, b.x);
        const PixelRange ri = range_intersection(ra, rb);
        const double inter = range_area(ri);
        if (inter <= 0.0) return 0.0;
        const double uni = range_area(ra) + range_area(rb) - inter;
        return -prm_.interaction * inter / uni - coverage_of(ri);
    }

    void fill_unary(RjConfig& c) {
        for (RjObject& o : c) score(o);
    }

    /// log pi(X) from the cached unary terms.
    double log_target(const RjConfig& c) const {
        double t = 0.0;
        for (size_t i = 0; i < c.size(); ++i) {
            t += c[i].unary;
            for (size_t j = i + 1; j < c.size(); ++j) t += pair(c[i], c[j]);
        }
        return t;
    }

    double birth_weight(int slot, const RjConfig& c) const {
        const RjIdentity& id = ids_[static_cast<size_t>(slot)];
        const PixelRange a = box_pixels(id.anchor[0], id.anchor[1], id.anchor[2], id.anchor[3],
                                        img_.rows, img_.cols);
        const double area = range_area(a);
        if (area <= 0.0) return prm_.birth_eps;
        double share = fg_.count(a) / area;
        for (const RjObject& o : c) share *= 1.0 - range_area(range_intersection(a, box(o.slot, o.x))) / area;
        return prm_.birth_eps + share;
    }

    static bool present(const RjConfig& c, int slot) {
        for (const RjObject& o : c)
            if (o.slot == slot) return true;
        return false;
    }

    /// log q_b(o | X).
    double log_birth_choice(int slot, const RjConfig& c) const {
        double total = 0.0;
        for (int s = 0; s < n_slots(); ++s)
            if (!present(c, s)) total += birth_weight(s, c);
        return std::log(birth_weight(slot, c)) - std::log(total);
    }

    /// log r of the move X -> Xp (before min(1, .)); `slot` is the object born / killed / updated,
    /// unused for a swap. Both configurations must have their cached terms filled (score): the
    /// P_o terms are the objects' log_prior, computed once per proposed state.
    double log_acceptance_ratio(RjMove m, const RjConfig& x, const RjConfig& xp, int slot) const {
        const double lt = log_target(x), ltp = log_target(xp);
        if (!std::isfinite(ltp)) return kNegInf;
        const double lpb = std::log(prm_.move_prob(RjMove::kBirth));
        const double lpd = std::log(prm_.move_prob(RjMove::kDeath));
        switch (m) {
            case RjMove::kBirth: {
                // r_birth = pi(X') p_d (1/|X'|) / [pi(X) p_b q_b(o|X) P_o(x)]
                const double lpo = find(xp, slot).log_prior;
                return ltp - lt + lpd - std::log(static_cast<double>(xp.size())) -
                       (lpb + log_birth_choice(slot, x) + lpo);
            }
            case RjMove::kDeath: {
                // r_death = pi(X') p_b q_b(o|X') P_o(x_o) / [pi(X) p_d (1/|X|)]
                const double lpo = find(x, slot).log_prior;
                return ltp - lt + lpb + log_birth_choice(slot, xp) + lpo -
                       (lpd - std::log(static_cast<double>(x.size())));
            }
            case RjMove::kUpdate: {
                // r_update = pi(X') p_u (1/|X|) P_o(x_o) / [pi(X) p_u (1/|X|) P_o(x*)]
                const double lq_rev = find(x, slot).log_prior;
                const double lq_fwd = find(xp, slot).log_prior;
                return ltp - lt + lq_rev - lq_fwd;
            }
            case RjMove::kSwap:
                // r_swap = pi(X') / pi(X): both directions pick the pair with p_s / C(|X|, 2)
                return ltp - lt;
        }
        return kNegInf;
    }

    static const RjObject& find(const RjConfig& c, int slot) {
        for (const RjObject& o : c)
            if (o.slot == slot) return o;
        fail("rjmcmc", "slot " + std::to_string(slot) + " is not in the configuration");
    }

    /// Draws x ~ P_slot and the motion history that goes with it; u0 picks the previous sample,
    /// w are three standard normals.
    void draw_state(int slot, double u0, const double* w, double* x, double* prev) const {
        const RjIdentity& id = ids_[static_cast<size_t>(slot)];
        if (id.candidate >= 0) {
            x[0] = id.anchor[0] + prm_.birth_sigma_xy * w[0];
            x[1] = id.anchor[1] + prm_.birth_sigma_xy * w[1];
            x[2] = 1.0 + prm_.birth_sigma_s * w[2];
            for (int d = 0; d < 3; ++d) prev[d] = x[d];  // zero velocity at birth
            return;
        }
        const Index nn = id.mu.rows();
        const Index n = std::min<Index>(nn - 1, static_cast<Index>(u0 * static_cast<double>(nn)));
        for (int d = 0; d < 3; ++d) {
            x[d] = id.mu(n, d) + prm_.model.sigma[d] * w[d];
            prev[d] = id.parents(n, d);
        }
    }

    /// Proposes a move from `c` with the draws of chain iteration k. Returns the proposed
    /// configuration in `out` (unary terms filled) and the slot concerned; false when the move is
    /// impossible in `c` (then `out` is untouched).
    bool propose(RjMove m, const RjConfig& c, const CounterRng& ur, const CounterRng& nr,
                 std::uint64_t k, RjConfig& out, int& slot) {
        const double u1 = ur.uniform(8 * k + 1), u2 = ur.uniform(8 * k + 2);
        const double w[3] = {nr.normal(4 * k), nr.normal(4 * k + 1), nr.normal(4 * k + 2)};
        const size_t n = c.size();
        switch (m) {
            case RjMove::kBirth: {
                std::vector<double> cum;
                std::vector<int> opts;
                double total = 0.0;
                for (int s = 0; s < n_slots(); ++s)
                    if (!present(c, s)) {
                        total += birth_weight(s, c);
                        cum.push_back(total);
                        opts.push_back(s);
                    }
                if (opts.empty()) return false;
                size_t j = 0;
                while (j + 1 < opts.size() && u1 * total >= cum[j]) ++j;
                slot = opts[j];
                RjObject o;
                o.slot = slot;
                draw_state(slot, u2, w, o.x, o.prev);
                score(o);
                out = c;
                out.insert(std::upper_bound(out.begin(), out.end(), o,
                                            [](const RjObject& a, const RjObject& b) { return a.slot < b.slot; }),
                           o);
                return true;
            }
            case RjMove::kDeath: {
                if (n == 0) return false;
                const size_t j = std::min(n - 1, static_cast<size_t>(u1 * static_cast<double>(n)));
                slot = c[j].slot;
                out = c;
                out.erase(out.begin() + static_cast<std::ptrdiff_t>(j));
                return true;
            }
            case RjMove::kUpdate: {
                if (n == 0) return false;
                const size_t j = std::min(n - 1, static_cast<size_t>(u1 * static_cast<double>(n)));
                slot = c[j].slot;
                out = c;
                draw_state(slot, u2, w, out[j].x, out[j].prev);
                score(out[j]);
                return true;
            }
            case RjMove::kSwap: {
                if (n < 2) return false;
                const size_t pairs = n * (n - 1) / 2;
                size_t p = std::min(pairs - 1, static_cast<size_t>(u1 * static_cast<double>(pairs)));
                size_t a = 0;
                while (p >= n - 1 - a) {
                    p -= n - 1 - a;
                    ++a;
                }
                const size_t b = a + 1 + p;
                out = c;
                for (int d = 0; d < 3; ++d) {
                    std::swap(out[a].x[d], out[b].x[d]);
                    std::swap(out[a].prev[d], out[b].prev[d]);
                }
                score(out[a]);
                score(out[b]);
                slot = out[a].slot;
                return true;
            }
        }
        return false;
    }

    RjMove choose_move(double u) const {
        double acc = 0.0;
        for (int m = 0; m < 3; ++m) {
            acc += prm_.move_prob(static_cast<RjMove>(m));
            if (u < acc) return static_cast<RjMove>(m);
        }
        return RjMove::kSwap;
    }

private:
    BinImage img_;
    FgIntegral fg_;
    std::vector<RjIdentity> ids_;
    RjParams prm_;
    std::vector<std::array<double, 4>> dets_;  // every candidate box (cx, cy, w, h)
    HistogramScratch scratch_;
    std::vector<double> hist_;
    mutable std::vector<double> lse_;
};

struct RjChainResult {
    std::vector<RjConfig> samples;  // the N kept configurations
    std::vector<double> log_targets;
    std::int64_t proposed[4] = {0, 0, 0, 0};
    std::int64_t accepted[4] = {0, 0, 0, 0};
};

/// Runs B + N iterations of the chain from `start`; draws from CounterRng(seed, step).
inline RjChainResult rjmcmc_chain(RjFrame& frame, RjConfig start, std::uint64_t seed,
                                  std::uint64_t step) {
    const RjParams& prm = frame.params();
    const CounterRng ur(seed, step);
    const CounterRng nr(mix64(seed ^ 0xD1B54A32D192ED03ULL), step);
    RjChainResult res;
    RjConfig cur = std::move(start);
    frame.fill_unary(cur);
    double cur_lt = frame.log_target(cur);
    RjConfig prop;
    const auto total = static_cast<std::uint64_t>(prm.burn_in + prm.n_samples);
    res.samples.reserve(static_cast<size_t>(prm.n_samples));
    for (std::uint64_t k = 0; k < total; ++k) {
        const RjMove m = frame.choose_move(ur.uniform(8 * k));
        int slot = -1;
        const bool kept = k >= static_cast<std::uint64_t>(prm.burn_in);
        if (frame.propose(m, cur, ur, nr, k, prop, slot)) {
            if (kept) ++res.proposed[static_cast<int>(m)];
            const double lr = frame.log_acceptance_ratio(m, cur, prop, slot);
            const double u = ur.uniform(8 * k + 3);
            if (lr >= 0.0 || u < std::exp(lr)) {
                std::swap(cur, prop);
                cur_lt = frame.log_target(cur);
                if (kept) ++res.accepted[static_cast<int>(m)];
            }
        }
        if (kept) {
            res.samples.push_back(cur);
            res.log_targets.push_back(cur_lt);
        }
    }
    return res;
}

struct RjStepResult {
    RowMatrixXd estimates;  // (M, 6): id, cx, cy, w, h, existence probability
    RowMatrixXd map;        // (Q, 5): id, cx, cy, w, h of the MAP sample
    std::int64_t proposed[4] = {0, 0, 0, 0};
    std::int64_t accepted[4] = {0, 0, 0, 0};
    double mean_objects = 0.0;  // mean number of objects per kept sample
    double map_log_target = 0.0;
};

/// The tracker's memory between frames: the identities and their kept samples.
class RJMCMCTracker {
public:
    struct Track {
        std::int64_t id;
        double w0, h0;
        Eigen::VectorXd ref;
        RowMatrixXd parents;  // (N_i, 6): (x, x') of the kept samples containing it
        double existence;     // share of the kept samples containing it
    };

    explicit RJMCMCTracker(const RjParams& prm) : prm_(prm) { prm_.validate("RJMCMCTracker"); }

    const RjParams& params() const { return prm_; }
    const std::vector<Track>& tracks() const { return tracks_; }
    std::int64_t next_id() const { return next_id_; }

    /// Replaces the kept identities and the next fresh id with a saved state (`tracks()` and
    /// `next_id()` of a tracker with the same parameters): a checkpoint's resume. Checked
    /// whole before anything changes: ids distinct in [0, next_id), base sizes finite > 0,
    /// references of one length with finite values >= 0 and a positive sum, kept samples
    /// (N_i >= 1, 6) finite, existence in (0, 1].
    void restore(std::vector<Track> tracks, std::int64_t next_id) {
        const char* fn = "RJMCMCTracker.restore";
        require(next_id >= 0, fn, "next_id", next_id, ">= 0");
        std::vector<std::int64_t> seen;
        for (size_t k = 0; k < tracks.size(); ++k) {
            const Track& t = tracks[k];
            const std::string at = "tracks[" + std::to_string(k) + "]";
            require(t.id >= 0 && t.id < next_id, fn, (at + ".id").c_str(), t.id,
                    "in [0, next_id)");
            require(std::find(seen.begin(), seen.end(), t.id) == seen.end(), fn,
                    at + ".id " + std::to_string(t.id) + " is given twice");
            seen.push_back(t.id);
            require(std::isfinite(t.w0) && t.w0 > 0.0 && std::isfinite(t.h0) && t.h0 > 0.0, fn,
                    at + ": w0 and h0 must be finite and > 0");
            require(t.ref.size() > 0 && t.ref.size() == tracks[0].ref.size() &&
                        t.ref.allFinite() && (t.ref.array() >= 0.0).all() && t.ref.sum() > 0.0,
                    fn, at + ".ref must hold finite values >= 0 with a positive sum, as long as "
                              "tracks[0].ref");
            require(t.parents.rows() >= 1 && t.parents.cols() == 6 && t.parents.allFinite(), fn,
                    at + ".parents must be a finite (N, 6) array with N >= 1");
            require(t.existence > 0.0 && t.existence <= 1.0, fn, (at + ".existence").c_str(),
                    t.existence, "in (0, 1]");
        }
        tracks_ = std::move(tracks);
        next_id_ = next_id;
    }

    /// Moves the kept identities into the next frame's pixels by a similarity transform
    /// `affine` (2 x 3, previous frame's pixels to this frame's): the kept samples' current and
    /// previous centres are mapped, base sizes times z = sqrt|det| (the scales stay), as
    /// warp_tracks moves the per-object filters. For camera-motion compensation.
    void warp(const Eigen::Ref<const RowMatrixXd>& affine) {
        const char* fn = "RJMCMCTracker.warp";
        require(affine.rows() == 2 && affine.cols() == 3, fn, "affine must have shape (2, 3)");
        require_finite(affine, fn, "affine");
        const double z =
            std::sqrt(std::abs(affine(0, 0) * affine(1, 1) - affine(0, 1) * affine(1, 0)));
        require(z > 0.0, fn, "affine is singular (determinant 0), expected a similarity");
        std::vector<Track> moved = tracks_;  // kept as they were if the result is not finite
        for (Track& t : moved) {
            for (Index n = 0; n < t.parents.rows(); ++n)
                for (int c : {0, 3}) {
                    const double x = t.parents(n, c), y = t.parents(n, c + 1);
                    t.parents(n, c) = affine(0, 0) * x + affine(0, 1) * y + affine(0, 2);
                    t.parents(n, c + 1) = affine(1, 0) * x + affine(1, 1) * y + affine(1, 2);
                }
            t.w0 *= z;
            t.h0 *= z;
            require(t.parents.allFinite() && std::isfinite(t.w0) && std::isfinite(t.h0), fn,
                    "affine moves an identity out of the finite numbers");
        }
        tracks_ = std::move(moved);
    }

    /// Builds one frame's model: previous identities first (in track order), then one newborn slot
    /// per candidate whose box holds foreground colour (an all-zero histogram cannot be a reference).
    RjFrame make_frame(const BinImage& img, FgIntegral fg, const Eigen::Ref<const RowMatrixXd>& cands,
                       const RowMatrixXd& cand_hists) const {
        const char* fn = "rjmcmc_step";
        check_bin_image(img, fn);
        check_boxes(cands, fn, "candidates");
        RowMatrixXd hists = cand_hists;
        if (hists.rows() == 0 && cands.rows() > 0) hists = box_histograms(img, cands, prm_.kernel);
        require(hists.rows() == cands.rows(), fn, "candidate_hists rows", hists.rows(), cands.rows());
        require(hists.cols() == img.n_bins || cands.rows() == 0, fn, "candidate_hists cols",
                hists.cols(), img.n_bins);
        const Ar2Model& m = prm_.model;
        std::vector<RjIdentity> ids;
        for (const Track& t : tracks_) {
            require(t.ref.size() == img.n_bins, fn, "track reference bins", t.ref.size(), img.n_bins);
            RjIdentity id;
            id.id = t.id;
            id.w0 = t.w0;
            id.h0 = t.h0;
            id.ref = t.ref;
            id.sqrt_ref = sqrt_reference(t.ref, img.n_bins, fn);
            const double e = std::clamp(prm_.survival * t.existence, 1e-3, 1.0 - 1e-3);
            id.log_omega = std::log(e / (1.0 - e));
            id.parents = t.parents;
            id.mu.resize(t.parents.rows(), 3);
            Eigen::Vector3d mean = Eigen::Vector3d::Zero();
            for (Index n = 0; n < t.parents.rows(); ++n)
                for (int d = 0; d < 3; ++d) {
                    // mu_n = A x_n + B x'_n   (eq. 7)
                    id.mu(n, d) = m.a[d] * t.parents(n, d) + m.b[d] * t.parents(n, 3 + d);
                    mean[d] += id.mu(n, d);
                }
            id.runs = equal_row_runs(id.mu);
            mean /= static_cast<double>(std::max<Index>(1, t.parents.rows()));
            const double s = std::clamp(mean[2], m.s_min, m.s_max);
            id.anchor[0] = mean[0];
            id.anchor[1] = mean[1];
            id.anchor[2] = s * t.w0;
            id.anchor[3] = s * t.h0;
            // one lattice for the frame, from the mean prediction's box (as mh_step)
            id.lattice = lattice_step(id.anchor[2], id.anchor[3], prm_.min_samples);
            ids.push_back(std::move(id));
        }
        const size_t n_kept = ids.size();
        for (Index k = 0; k < cands.rows(); ++k) {
            const double sum = hists.row(k).sum();
            if (!(sum > 0.0) || !(cands(k, 2) > 0.0) || !(cands(k, 3) > 0.0)) continue;
            // Birth gate: a candidate that a confident identity's prediction already covers is
            // that identity's detection, not a new object. Without the gate its newborn slot
            // (reference histogram from this very box, tight prior on it) out-scores the kept
            // identity, and death + birth hand the object a new id every few frames.
            const double cbox[4] = {cands(k, 0), cands(k, 1), cands(k, 2), cands(k, 3)};
            bool explained = false;
            for (size_t s = 0; s < n_kept && !explained; ++s)
                explained = tracks_[s].existence >= 0.5 && iou_cxcywh(cbox, ids[s].anchor) >= prm_.birth_gate;
            if (explained) continue;
            require_weights(hists.row(k), fn, "candidate_hists row");
            RjIdentity id;
            id.candidate = static_cast<int>(k);
            id.w0 = cands(k, 2);
            id.h0 = cands(k, 3);
            id.ref = hists.row(k).transpose() / sum;
            id.sqrt_ref = id.ref.array().sqrt().matrix();
            id.log_omega = std::log(prm_.birth_prior);
            for (int d = 0; d < 4; ++d) id.anchor[d] = cands(k, d);
            id.lattice = lattice_step(id.w0, id.h0, prm_.min_samples);
            ids.push_back(std::move(id));
        }
        std::vector<std::array<double, 4>> dets;
        for (Index k = 0; k < cands.rows(); ++k)
            dets.push_back({cands(k, 0), cands(k, 1), cands(k, 2), cands(k, 3)});
        return RjFrame(img, std::move(fg), std::move(ids), prm_, std::move(dets));
    }

    /// The chain's start: every identity with existence >= 1/2 at its mean prediction.
    RjConfig start_config(const RjFrame& frame) const {
        RjConfig c;
        const auto& ids = frame.identities();
        for (size_t s = 0; s < tracks_.size(); ++s) {
            if (tracks_[s].existence < 0.5) continue;
            RjObject o;
            o.slot = static_cast<int>(s);
            o.x[0] = ids[s].anchor[0];
            o.x[1] = ids[s].anchor[1];
            o.x[2] = std::clamp(ids[s].anchor[2] / tracks_[s].w0, prm_.model.s_min, prm_.model.s_max);
            const RowMatrixXd& p = tracks_[s].parents;
            for (int d = 0; d < 3; ++d) o.prev[d] = p.col(d).mean();
            c.push_back(o);
        }
        return c;
    }

    /// One frame: build the model, run the chain, summarise, and keep the samples for the next
    /// frame. Draws from CounterRng(seed, step).
    RjStepResult step(const BinImage& img, FgIntegral fg, const Eigen::Ref<const RowMatrixXd>& cands,
                      const RowMatrixXd& cand_hists, std::uint64_t seed, std::uint64_t step) {
        RjFrame frame = make_frame(img, std::move(fg), cands, cand_hists);
        RjChainResult chain = rjmcmc_chain(frame, start_config(frame), seed, step);
        return summarise(frame, chain);
    }

    RjStepResult summarise(const RjFrame& frame, const RjChainResult& chain) {
        const auto& ids = frame.identities();
        const size_t n_slots = ids.size();
        const double n = static_cast<double>(chain.samples.size());
        std::vector<std::vector<Index>> rows(n_slots);  // (sample, object) per slot
        std::vector<Eigen::Vector3d> sums(n_slots, Eigen::Vector3d::Zero());
        std::vector<RowMatrixXd> parents(n_slots);
        std::vector<Index> counts(n_slots, 0);
        double n_obj = 0.0;
        for (const RjConfig& c : chain.samples) {
            n_obj += static_cast<double>(c.size());
            for (const RjObject& o : c) ++counts[static_cast<size_t>(o.slot)];
        }
        for (size_t s = 0; s < n_slots; ++s) parents[s].resize(counts[s], 6);
        std::vector<Index> fill(n_slots, 0);
        for (const RjConfig& c : chain.samples)
            for (const RjObject& o : c) {
                const auto s = static_cast<size_t>(o.slot);
                for (int d = 0; d < 3; ++d) {
                    parents[s](fill[s], d) = o.x[d];
                    parents[s](fill[s], 3 + d) = o.prev[d];
                    sums[s][d] += o.x[d];
                }
                ++fill[s];
            }
        // identities of this frame's newborn slots
        std::vector<std::int64_t> gid(n_slots, -1);
        for (size_t s = 0; s < n_slots; ++s)
            gid[s] = ids[s].candidate >= 0 ? (counts[s] > 0 ? next_id_++ : -1) : ids[s].id;

        RjStepResult r;
        Index m = 0;
        for (size_t s = 0; s < n_slots; ++s) m += counts[s] > 0 ? 1 : 0;
        r.estimates.resize(m, 6);
        std::vector<Track> next;
        Index row = 0;
        for (size_t s = 0; s < n_slots; ++s) {
            if (counts[s] == 0) continue;
            const Eigen::Vector3d mean = sums[s] / static_cast<double>(counts[s]);
            const double ex = static_cast<double>(counts[s]) / n;
            r.estimates.row(row++) << static_cast<double>(gid[s]), mean[0], mean[1],
                mean[2] * ids[s].w0, mean[2] * ids[s].h0, ex;
            next.push_back(Track{gid[s], ids[s].w0, ids[s].h0, ids[s].ref, parents[s], ex});
        }
        const auto best = static_cast<size_t>(
            std::max_element(chain.log_targets.begin(), chain.log_targets.end()) - chain.log_targets.begin());
        const RjConfig& mc = chain.samples[best];
        r.map.resize(static_cast<Index>(mc.size()), 5);
        for (size_t j = 0; j < mc.size(); ++j) {
            const RjIdentity& id = ids[static_cast<size_t>(mc[j].slot)];
            r.map.row(static_cast<Index>(j)) << static_cast<double>(gid[static_cast<size_t>(mc[j].slot)]),
                mc[j].x[0], mc[j].x[1], mc[j].x[2] * id.w0, mc[j].x[2] * id.h0;
        }
        r.map_log_target = chain.log_targets[best];
        for (int k = 0; k < 4; ++k) {
            r.proposed[k] = chain.proposed[k];
            r.accepted[k] = chain.accepted[k];
        }
        r.mean_objects = n_obj / n;
        tracks_ = std::move(next);
        return r;
    }

private:
    RjParams prm_;
    std::vector<Track> tracks_;
    std::int64_t next_id_ = 0;
};

}  // namespace pftrack
