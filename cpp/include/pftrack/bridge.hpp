// Goal-directed state equation (Oh & Jung 2015, after Srinivasan et al. 2006): the mean path,
// the per-step noise covariances and the state covariances of a linear-Gaussian process
//   x_t = A_t x_{t-1} + w_t,  w_t ~ N(0, Q_t)                                        (eq. 1)
// conditioned on one goal measurement y_T = H_T x_T + v_T, v_T ~ N(0, Pi_T)          (eq. 4)
// and on the initial state x_0 ~ N(m_0, Pi_0). Three forms: general H_T (eqs. 7-10),
// invertible H_T (11-15) and pseudo-inverse (16-18). All sums
//   S_t = sum_{i=t..T} Phi(T,i) Q_i Phi(T,i)^T
// come from one backward recursion, S_t = Phi(T,t) Q_t Phi(T,t)^T + S_{t+1}, with
// Phi(T,t) = Phi(T,t+1) A_{t+1}: O(T) per gap, no matrix powers.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>

#include "pftrack/check.hpp"
#include "pftrack/rng.hpp"
#include "pftrack/types.hpp"

namespace pftrack {

using MatrixXd = Eigen::MatrixXd;
using VectorXd = Eigen::VectorXd;

enum class GdtForm { general, invertible, pseudo_inverse };

/// One goal-directed problem. `A` and `Q` hold either one matrix (constant model) or one per
/// step t = 1..T (A[t-1] = A_t).
struct GdtProblem {
    std::vector<MatrixXd> A;
    std::vector<MatrixXd> Q;
    MatrixXd H;      // H_T (m, n)
    MatrixXd Pi_T;   // (m, m) goal covariance
    VectorXd m0;     // (n) initial mean
    MatrixXd Pi_0;   // (n, n) initial covariance
    VectorXd y;      // (m) goal measurement
    int T = 0;       // number of steps: x_T is the goal's state
};

struct GdtResult {
    RowMatrixXd path;  // (T + 1, n): x_0 .. x_T
    RowMatrixXd eps;   // (T, n * n): eps_1 .. eps_T, each n x n row-major
    RowMatrixXd cov;   // (T + 1, n * n): cov of x_0 .. x_T along the path
    VectorXd x0_mean;  // E[x_0 | y_T]
    MatrixXd x0_cov;   // cov(x_0 | y_T)
};

namespace detail {

inline const MatrixXd& step_matrix(const std::vector<MatrixXd>& v, int t) {
    // t = 1..T; a single matrix stands for every step
    return v.size() == 1 ? v[0] : v[static_cast<size_t>(t - 1)];
}

inline std::string shape_of(const MatrixXd& a) {
    return "(" + std::to_string(a.rows()) + ", " + std::to_string(a.cols()) + ")";
}

inline void require_square(const MatrixXd& a, Index n, const char* fn, const std::string& what) {
    require(a.rows() == n && a.cols() == n, fn, what.c_str(), shape_of(a),
            "(" + std::to_string(n) + ", " + std::to_string(n) + ")");
}

/// Symmetric, finite, positive semi-definite (positive definite when `definite`).
inline void require_covariance(const MatrixXd& c, const char* fn, const std::string& what,
                               bool definite) {
    require_finite(c, fn, what.c_str());
    const double scale = c.cwiseAbs().maxCoeff();
    require((c - c.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * (scale > 0 ? scale : 1.0), fn,
            what + " is not symmetric");
    Eigen::LDLT<MatrixXd> ldlt(c);
    const VectorXd d = ldlt.vectorD();
    const double tol = 1e-10 * static_cast<double>(c.rows()) * (scale > 0 ? scale : 1.0);
    bool ok = ldlt.info() == Eigen::Success;
    for (Index i = 0; ok && i < d.size(); ++i) ok = definite ? d(i) > tol : d(i) >= -tol;
    require(ok, fn,
            what + (definite ? " is not positive definite (singular or indefinite)"
                             : " is not positive semi-definite"));
}

inline MatrixXd sym(const MatrixXd& a) { return 0.5 * (a + a.transpose()); }

/// Inverse of a symmetric positive definite matrix, with a message naming it when it is not.
inline MatrixXd spd_inverse(const MatrixXd& a, const char* fn, const char* what) {
    Eigen::LLT<MatrixXd> llt(a);
    require(llt.info() == Eigen::Success, fn,
            std::string(what) + " is singular or not positive definite");
    return llt.solve(MatrixXd::Identity(a.rows(), a.cols()));
}

}  // namespace detail

/// Throws std::invalid_argument naming the problem: T <= 0, mismatched dimensions, non-finite
/// values, non-symmetric / non-PSD Q, non-PD Pi_0 or Pi_T, singular A (needed by the
/// invertible and pseudo-inverse forms) or H unfit for the chosen form.
inline void gdt_check(const GdtProblem& p, GdtForm form, const char* fn = "gdt_solve") {
    using namespace detail;
    require(p.T > 0, fn, "T", p.T, "> 0 (steps from the initial state to the goal)");
    const Index n = p.m0.size();
    require(n > 0, fn, "m0 is empty");
    require(!p.A.empty() && (p.A.size() == 1 || p.A.size() == static_cast<size_t>(p.T)), fn,
            "number of A matrices", p.A.size(), "1 or T = " + std::to_string(p.T));
    require(!p.Q.empty() && (p.Q.size() == 1 || p.Q.size() == static_cast<size_t>(p.T)), fn,
            "number of Q matrices", p.Q.size(), "1 or T = " + std::to_string(p.T));
    for (size_t i = 0; i < p.A.size(); ++i) {
        require_square(p.A[i], n, fn, "A[" + std::to_string(i) + "] shape");
        require_finite(p.A[i], fn, "A");
    }
    for (size_t i = 0; i < p.Q.size(); ++i) {
        require_square(p.Q[i], n, fn, "Q[" + std::to_string(i) + "] shape");
        require_covariance(p.Q[i], fn, "Q[" + std::to_string(i) + "]", false);
    }
    require_finite(p.m0, fn, "m0");
    require_square(p.Pi_0, n, fn, "Pi_0 shape");
    require_covariance(p.Pi_0, fn, "Pi_0", true);
    const Index m = p.y.size();
    require(m > 0, fn, "y is empty");
    require_finite(p.y, fn, "y");
    require(p.H.rows() == m && p.H.cols() == n, fn, "H shape", shape_of(p.H),
            "(" + std::to_string(m) + ", " + std::to_string(n) + ") = (len(y), len(m0))");
    require_finite(p.H, fn, "H");
    require_square(p.Pi_T, m, fn, "Pi_T shape");
    require_covariance(p.Pi_T, fn, "Pi_T", true);
    if (form == GdtForm::invertible) {
        require(m == n, fn, "H must be square for the invertible form (use form='general')");
        Eigen::FullPivLU<MatrixXd> lu(p.H);
        require(lu.isInvertible(), fn, "H is singular (use form='general')");
    }
    if (form == GdtForm::pseudo_inverse) {
        Eigen::FullPivLU<MatrixXd> lu(p.H.transpose() * p.H);
        require(lu.isInvertible(), fn,
                "H^T H is singular: the pseudo-inverse form needs H of full column rank "
                "(use form='general')");
    }
    if (form != GdtForm::general)
        for (size_t i = 0; i < p.A.size(); ++i) {
            Eigen::FullPivLU<MatrixXd> lu(p.A[i]);
            require(lu.isInvertible(), fn, "A[" + std::to_string(i) + "] is singular");
        }
}

/// Per-step quantities of the goal-directed equation, written so that every form reduces to
///   x_t = A_t x_{t-1} + K_t (y_T - G_t x_{t-1}),  eps_t = covariance of step t,
/// with G_t = H_T Phi(T, t-1). The forms differ only in how K_t and eps_t are computed.
struct GdtSteps {
    std::vector<MatrixXd> K;    // (n, m) drift gains, t = 1..T
    std::vector<MatrixXd> G;    // (m, n)
    std::vector<MatrixXd> eps;  // (n, n)
    VectorXd x0_mean;
    MatrixXd x0_cov;
};

/// Build the per-step gains. Preconditions: gdt_check(p, form) passed.
inline GdtSteps gdt_steps(const GdtProblem& p, GdtForm form) {
    using namespace detail;
    const char* fn = "gdt_solve";
    const Index n = p.m0.size();
    const int T = p.T;
    GdtSteps s;
    s.K.resize(static_cast<size_t>(T));
    s.G.resize(static_cast<size_t>(T));
    s.eps.resize(static_cast<size_t>(T));
    const MatrixXd Pi0_inv = spd_inverse(p.Pi_0, fn, "Pi_0");

    if (form == GdtForm::general) {
        // Backward: Phi = Phi(T, t), S = S_t = sum_{i=t..T} Phi(T,i) Q_i Phi(T,i)^T.
        MatrixXd Phi = MatrixXd::Identity(n, n);
        MatrixXd S = MatrixXd::Zero(n, n);
        MatrixXd Minv;
        for (int t = T; t >= 1; --t) {
            const MatrixXd& Qt = step_matrix(p.Q, t);
            // S_t = Phi(T,t) Q_t Phi(T,t)^T + S_{t+1}
            S.noalias() += Phi * Qt * Phi.transpose();
            // M_t = Pi_T + H S_t H^T
            const MatrixXd M = p.Pi_T + p.H * S * p.H.transpose();
            Minv = spd_inverse(sym(M), fn, "Pi_T + H S H^T");
            const MatrixXd HPhi = p.H * Phi;  // H Phi(T, t)
            // u_t = Q_t Phi^T(T,t) H^T M_t^{-1} (y - H Phi(T,t-1) x_{t-1})   (eq. 7)
            s.K[static_cast<size_t>(t - 1)] = Qt * HPhi.transpose() * Minv;
            // eps_t = Q_t - Q_t Phi^T H^T M_t^{-1} H Phi Q_t^T                (eq. 8)
            s.eps[static_cast<size_t>(t - 1)] =
                sym(Qt - s.K[static_cast<size_t>(t - 1)] * HPhi * Qt.transpose());
            Phi = Phi * step_matrix(p.A, t);  // Phi(T, t-1)
            s.G[static_cast<size_t>(t - 1)] = p.H * Phi;
        }
        // After the loop Phi = Phi(T, 0) and Minv = M_1^{-1}.
        const MatrixXd F = p.H * Phi;  // H Phi(T, 0)
        // cov(x0|yT) = (Pi_0^{-1} + Phi^T(T,0) H^T M_1^{-1} H Phi(T,0))^{-1}   (eq. 9)
        s.x0_cov = sym(spd_inverse(sym(Pi0_inv + F.transpose() * Minv * F), fn, "cov(x0|yT)^-1"));
        // E[x0|yT] = m0 + cov Phi^T H^T M_1^{-1} (y - H Phi(T,0) m0)         (eq. 10)
        s.x0_mean = p.m0 + s.x0_cov * F.transpose() * Minv * (p.y - F * p.m0);
        return s;
    }

    // Invertible / pseudo-inverse forms: goal mapped to state space,
    //   x_T = H^+ y,  cov = H^+ Pi_T H^+T   (H^+ = H^-1, or (H^T H)^-1 H^T)   (eqs. 13, 17)
    MatrixXd Hp;
    if (form == GdtForm::invertible) {
        Hp = p.H.fullPivLu().inverse();
    } else {
        const MatrixXd HtH = p.H.transpose() * p.H;
        Hp = HtH.fullPivLu().solve(p.H.transpose());
    }
    const MatrixXd goal_cov = sym(Hp * p.Pi_T * Hp.transpose());
    const VectorXd goal_state = Hp * p.y;
    // Backward: Psi = Phi(t, T) = A_{t+1}^{-1} Phi(t+1, T),
    //           W_t = sum_{i=t..T} Phi(t,i) Q_i Phi(t,i)^T = Q_t + A_{t+1}^{-1} W_{t+1} A_{t+1}^{-T}.
    MatrixXd Psi = MatrixXd::Identity(n, n);
    MatrixXd W = MatrixXd::Zero(n, n);
    MatrixXd PiInv;
    MatrixXd Ainv_const;
    if (p.A.size() == 1) Ainv_const = p.A[0].fullPivLu().inverse();
    MatrixXd PhiT = MatrixXd::Identity(n, n);  // Phi(T, t), for G_t
    for (int t = T; t >= 1; --t) {
        const MatrixXd& Qt = step_matrix(p.Q, t);
        if (t < T) {
            const MatrixXd Ainv =
                p.A.size() == 1 ? Ainv_const : step_matrix(p.A, t + 1).fullPivLu().inverse();
            Psi = Ainv * Psi;
            W = Ainv * W * Ainv.transpose();
        }
        W += Qt;
        // Pi(t, T) = Phi(t,T) H^+ Pi_T H^+T Phi^T(t,T) + W_t               (eq. 13 / 17)
        const MatrixXd Pi = sym(Psi * goal_cov * Psi.transpose() + W);
        PiInv = spd_inverse(Pi, fn, "Pi(t, T)");
        // u_t = Q_t Pi^{-1}(t,T) Phi(t,T) H^+ (y - H Phi(T,t-1) x_{t-1})    (eq. 11 / 16)
        s.K[static_cast<size_t>(t - 1)] = Qt * PiInv * Psi * Hp;
        // eps_t = Q_t - Q_t Pi^{-1}(t,T) Q_t^T                              (eq. 12)
        s.eps[static_cast<size_t>(t - 1)] = sym(Qt - Qt * PiInv * Qt.transpose());
        PhiT = PhiT * step_matrix(p.A, t);
        s.G[static_cast<size_t>(t - 1)] = p.H * PhiT;
    }
    // Pi(0, T) = A_1^{-1} (Pi(1, T)) A_1^{-T}: one more backward step, without Q_0.
    const MatrixXd A1inv = p.A.size() == 1 ? Ainv_const : p.A[0].fullPivLu().inverse();
    const MatrixXd Psi0 = A1inv * Psi;
    const MatrixXd W0 = A1inv * W * A1inv.transpose();
    const MatrixXd Pi0T = sym(Psi0 * goal_cov * Psi0.transpose() + W0);
    const MatrixXd Pi0T_inv = spd_inverse(Pi0T, fn, "Pi(0, T)");
    // cov(x0|yT) = (Pi_0^{-1} + Pi^{-1}(0,T))^{-1}                           (eq. 14)
    s.x0_cov = sym(spd_inverse(sym(Pi0_inv + Pi0T_inv), fn, "cov(x0|yT)^-1"));
    // E[x0|yT] = cov (Pi_0^{-1} m0 + Pi^{-1}(0,T) Phi(0,T) H^+ y)           (eq. 15 / 18)
    s.x0_mean = s.x0_cov * (Pi0_inv * p.m0 + Pi0T_inv * Psi0 * goal_state);
    return s;
}

namespace detail {

/// General form (eqs. 7-10) with fixed-size matrices (state N, goal MG): no heap allocation
/// inside the loops. Same maths, step for step, as gdt_steps + gdt_solve.
template <int N, int MG>
GdtResult gdt_solve_general_fixed(const GdtProblem& p, bool start_conditioned) {
    using MatN = Eigen::Matrix<double, N, N>;
    using MatG = Eigen::Matrix<double, MG, MG>;
    using VecN = Eigen::Matrix<double, N, 1>;
    const char* fn = "gdt_solve";
    const int T = p.T;
    std::vector<MatN> A(p.A.begin(), p.A.end()), Q(p.Q.begin(), p.Q.end());
    auto At = [&](int t) -> const MatN& { return A.size() == 1 ? A[0] : A[static_cast<size_t>(t - 1)]; };
    auto Qt = [&](int t) -> const MatN& { return Q.size() == 1 ? Q[0] : Q[static_cast<size_t>(t - 1)]; };
    const Eigen::Matrix<double, MG, N> H = p.H;
    const MatG PiT = p.Pi_T;
    const Eigen::Matrix<double, MG, 1> y = p.y;
    std::vector<Eigen::Matrix<double, N, MG>> K(static_cast<size_t>(T));
    std::vector<Eigen::Matrix<double, MG, N>> G(static_cast<size_t>(T));
    std::vector<MatN> eps(static_cast<size_t>(T));
    MatN Phi = MatN::Identity();
    MatN S = MatN::Zero();
    MatG Minv;
    for (int t = T; t >= 1; --t) {
        const size_t k = static_cast<size_t>(t - 1);
        // S_t = Phi(T,t) Q_t Phi(T,t)^T + S_{t+1}
        S.noalias() += Phi * Qt(t) * Phi.transpose();
        // M_t = Pi_T + H S_t H^T
        const MatG M = PiT + H * S * H.transpose();
        Eigen::LLT<MatG> llt(0.5 * (M + M.transpose()));
        require(llt.info() == Eigen::Success, fn, "Pi_T + H S H^T is singular or not positive definite");
        Minv = llt.solve(MatG::Identity());
        const Eigen::Matrix<double, MG, N> HPhi = H * Phi;
        K[k] = Qt(t) * HPhi.transpose() * Minv;                        // eq. 7
        const MatN e = Qt(t) - K[k] * HPhi * Qt(t).transpose();        // eq. 8
        eps[k] = 0.5 * (e + e.transpose());
        Phi = Phi * At(t);  // Phi(T, t-1)
        G[k] = H * Phi;
    }
    const Eigen::Matrix<double, MG, N> F = H * Phi;  // H Phi(T, 0)
    Eigen::LLT<MatN> l0(p.Pi_0);
    require(l0.info() == Eigen::Success, fn, "Pi_0 is singular or not positive definite");
    const MatN info = l0.solve(MatN::Identity()) + F.transpose() * Minv * F;
    Eigen::LLT<MatN> l1(0.5 * (info + info.transpose()));
    require(l1.info() == Eigen::Success, fn, "cov(x0|yT)^-1 is singular or not positive definite");
    MatN C0 = l1.solve(MatN::Identity());  // eq. 9
    C0 = (0.5 * (C0 + C0.transpose())).eval();
    const VecN m0 = p.m0;
    const VecN x0m = m0 + C0 * F.transpose() * Minv * (y - F * m0);  // eq. 10
    GdtResult r;
    r.x0_mean = x0m;
    r.x0_cov = C0;
    r.path.resize(T + 1, N);
    r.eps.resize(T, N * N);
    r.cov.resize(T + 1, N * N);
    VecN x = start_conditioned ? x0m : m0;
    MatN P = start_conditioned ? C0 : MatN(p.Pi_0);
    r.path.row(0) = x.transpose();
    Eigen::Map<Eigen::Matrix<double, N, N, Eigen::RowMajor>>(r.cov.row(0).data()) = P;
    for (int t = 1; t <= T; ++t) {
        const size_t k = static_cast<size_t>(t - 1);
        x = At(t) * x + K[k] * (y - G[k] * x);  // x_t = A_t x_{t-1} + u_t   (eq. 3, mean)
        const MatN B = At(t) - K[k] * G[k];
        P = B * P * B.transpose() + eps[k];
        P = (0.5 * (P + P.transpose())).eval();
        r.path.row(t) = x.transpose();
        Eigen::Map<Eigen::Matrix<double, N, N, Eigen::RowMajor>>(r.eps.row(t - 1).data()) = eps[k];
        Eigen::Map<Eigen::Matrix<double, N, N, Eigen::RowMajor>>(r.cov.row(t).data()) = P;
    }
    return r;
}

}  // namespace detail

/// Solve one problem: mean path x_0..x_T (x_t = A_t x_{t-1} + u_t), eps_t, the state
/// covariances along the path and the conditioned initial state. The path starts at
/// E[x_0|y_T] (`start_conditioned`, giving E[x_t|y_T]) or at m_0 (the paper's framework: x_0 is
/// the Kalman estimate at the end of the first segment).
inline GdtResult gdt_solve(const GdtProblem& p, GdtForm form, bool start_conditioned) {
    gdt_check(p, form);
    if (form == GdtForm::general && p.m0.size() == 4) {  // image states: fixed-size kernels
        if (p.y.size() == 2) return detail::gdt_solve_general_fixed<4, 2>(p, start_conditioned);
        if (p.y.size() == 4) return detail::gdt_solve_general_fixed<4, 4>(p, start_conditioned);
    }
    const GdtSteps s = gdt_steps(p, form);
    const Index n = p.m0.size();
    const int T = p.T;
    GdtResult r;
    r.x0_mean = s.x0_mean;
    r.x0_cov = s.x0_cov;
    r.path.resize(T + 1, n);
    r.eps.resize(T, n * n);
    r.cov.resize(T + 1, n * n);
    VectorXd x = start_conditioned ? s.x0_mean : p.m0;
    MatrixXd P = start_conditioned ? s.x0_cov : p.Pi_0;
    r.path.row(0) = x.transpose();
    Eigen::Map<RowMatrixXd>(r.cov.row(0).data(), n, n) = P;
    for (int t = 1; t <= T; ++t) {
        const size_t k = static_cast<size_t>(t - 1);
        const MatrixXd& At = detail::step_matrix(p.A, t);
        // x_t = A_t x_{t-1} + u_t,  u_t = K_t (y - G_t x_{t-1})           (eq. 3, mean)
        x = At * x + s.K[k] * (p.y - s.G[k] * x);
        // cov: x_t is linear in x_{t-1} with matrix (A_t - K_t G_t), plus eps_t
        const MatrixXd B = At - s.K[k] * s.G[k];
        P = detail::sym(B * P * B.transpose() + s.eps[k]);
        r.path.row(t) = x.transpose();
        Eigen::Map<RowMatrixXd>(r.eps.row(t - 1).data(), n, n) = s.eps[k];
        Eigen::Map<RowMatrixXd>(r.cov.row(t).data(), n, n) = P;
    }
    return r;
}

/// Lower Cholesky-like factor of a PSD matrix (LDLT, negative round-off pivots clamped to 0).
inline MatrixXd psd_factor(const MatrixXd& c) {
    Eigen::LDLT<MatrixXd> ldlt(c);
    const VectorXd d = ldlt.vectorD().cwiseMax(0.0).cwiseSqrt();
    MatrixXd L = ldlt.matrixL();
    MatrixXd F = ldlt.transpositionsP().transpose() * (L * d.asDiagonal());
    return F;
}

/// `n_samples` random paths of the goal-directed process x_t = A_t x_{t-1} + u_t + eps_t noise,
/// x_0 ~ N(E[x0|yT], cov(x0|yT)), or x_0 ~ N(m_0, Pi_0) when not `start_conditioned`: the
/// distribution whose mean and covariances gdt_solve gives for the same flag (path, cov).
/// Returns (n_samples * (T + 1), n): sample s occupies rows s (T+1) .. s (T+1) + T. Draw k of
/// sample s is CounterRng(seed, s).normal(k), so results do not depend on threads or order.
inline RowMatrixXd gdt_sample(const GdtProblem& p, GdtForm form, bool start_conditioned,
                              int n_samples, std::uint64_t seed) {
    gdt_check(p, form, "gdt_sample");
    require(n_samples > 0, "gdt_sample", "n_samples", n_samples, "> 0");
    const GdtSteps s = gdt_steps(p, form);
    const Index n = p.m0.size();
    const int T = p.T;
    std::vector<MatrixXd> F(static_cast<size_t>(T));
    for (int t = 0; t < T; ++t) F[static_cast<size_t>(t)] = psd_factor(s.eps[static_cast<size_t>(t)]);
    // x_0's distribution: the conditioned one, or the prior N(m_0, Pi_0) (was x_0 = m_0, whose
    // paths had covariance 0 at t = 0 where gdt_solve's cov[0] is Pi_0)
    const MatrixXd F0 = psd_factor(start_conditioned ? s.x0_cov : p.Pi_0);
    const VectorXd& x0 = start_conditioned ? s.x0_mean : p.m0;
    RowMatrixXd out(static_cast<Index>(n_samples) * (T + 1), n);
    VectorXd z(n);
    for (int smp = 0; smp < n_samples; ++smp) {
        const CounterRng rng(seed, static_cast<std::uint64_t>(smp));
        std::uint64_t k = 0;
        for (Index j = 0; j < n; ++j) z(j) = rng.normal(k++);
        VectorXd x = x0 + F0 * z;
        const Index base = static_cast<Index>(smp) * (T + 1);
        out.row(base) = x.transpose();
        for (int t = 1; t <= T; ++t) {
            const size_t i = static_cast<size_t>(t - 1);
            for (Index j = 0; j < n; ++j) z(j) = rng.normal(k++);
            // x_t = A_t x_{t-1} + u_t + eps_t                                 (eq. 3)
            x = detail::step_matrix(p.A, t) * x + s.K[i] * (p.y - s.G[i] * x) + F[i] * z;
            out.row(base + t) = x.transpose();
        }
    }
    return out;
}

// ---------------------------------------------------------------------------------------------
// Kalman filtering of a segment (for the initial state of a gap, and the goal state from the
// other side when run backwards).

struct KalmanEstimate {
    VectorXd m;
    MatrixXd P;
};

/// Kalman filter over measurements z (K, m) with constant A, Q, H, R; the first state is
/// m_init, P_init. Returns the filtered state after the last measurement.
inline KalmanEstimate kalman_filter(const Eigen::Ref<const RowMatrixXd>& z, const MatrixXd& A,
                                    const MatrixXd& Q, const MatrixXd& H, const MatrixXd& R,
                                    const VectorXd& m_init, const MatrixXd& P_init) {
    const char* fn = "kalman_filter";
    const Index n = A.rows();
    require(z.rows() > 0, fn, "z (the segment) is empty");
    require(z.cols() == H.rows(), fn, "z cols", z.cols(), H.rows());
    require_finite(z, fn, "z");
    detail::require_square(A, n, fn, "A shape");
    detail::require_square(Q, n, fn, "Q shape");
    detail::require_square(R, H.rows(), fn, "R shape");
    require(H.cols() == n, fn, "H cols", H.cols(), n);
    require(m_init.size() == n, fn, "m_init size", m_init.size(), n);
    detail::require_square(P_init, n, fn, "P_init shape");
    detail::require_covariance(R, fn, "R", true);
    detail::require_covariance(Q, fn, "Q", false);
    KalmanEstimate e{m_init, P_init};
    const MatrixXd I = MatrixXd::Identity(n, n);
    for (Index k = 0; k < z.rows(); ++k) {
        if (k > 0) {
            e.m = A * e.m;
            e.P = detail::sym(A * e.P * A.transpose() + Q);
        }
        const MatrixXd S = H * e.P * H.transpose() + R;
        const MatrixXd K = e.P * H.transpose() * detail::spd_inverse(detail::sym(S), fn, "S");
        e.m += K * (z.row(k).transpose() - H * e.m);
        const MatrixXd IKH = I - K * H;  // Joseph form keeps P symmetric PSD
        e.P = detail::sym(IKH * e.P * IKH.transpose() + K * R * K.transpose());
    }
    return e;
}

// ---------------------------------------------------------------------------------------------
// Many gaps in one call: segment filtering + goal-directed path, for a (position, velocity) state.

/// Model of the segments: state (p_1..p_m, v_1..v_m) (n = 2m), measurement = position.
struct SegmentModel {
    MatrixXd A;  // (n, n)
    MatrixXd Q;  // (n, n)
    MatrixXd H;  // (m, n)
    MatrixXd R;  // (m, m)
    double p_init_velocity = 1e2;
};

/// Goal of each gap: the first point of segment B (the paper), or the full state estimated by a
/// Kalman filter run backwards over segment B, with its covariance as Pi_T.
enum class GoalKind { first_point, backward_state };

namespace detail {

/// Rows [begin, end) of `seg` (frame, p...) restricted to the run of consecutive frames that
/// touches the gap (the last run of A, the first run of B), at most `history` rows.
inline void gap_run(const Eigen::Ref<const RowMatrixXd>& seg, Index begin, Index end, bool tail,
                    int history, Index& run_begin, Index& run_end) {
    if (tail) {
        run_end = end;
        run_begin = end - 1;
        while (run_begin > begin && seg(run_begin, 0) - seg(run_begin - 1, 0) == 1.0 &&
               run_end - run_begin < history)
            --run_begin;
    } else {
        run_begin = begin;
        run_end = begin + 1;
        while (run_end < end && seg(run_end, 0) - seg(run_end - 1, 0) == 1.0 &&
               run_end - run_begin < history)
            ++run_end;
    }
}

inline KalmanEstimate filter_run(const RowMatrixXd& z, const SegmentModel& model) {
    const Index m = model.H.rows();
    const Index n = model.A.rows();
    VectorXd m_init = VectorXd::Zero(n);
    m_init.head(m) = z.row(0).transpose();
    if (z.rows() > 1) m_init.segment(m, m) = (z.row(1) - z.row(0)).transpose();
    MatrixXd P_init = MatrixXd::Zero(n, n);
    P_init.topLeftCorner(m, m) = model.R;
    P_init.block(m, m, m, m) = MatrixXd::Identity(m, m) * model.p_init_velocity;
    return kalman_filter(z, model.A, model.Q, model.H, model.R, m_init, P_init);
}

}  // namespace detail

namespace detail {

/// Gains of the fixed-size Kalman filter of a segment run (initialised like filter_run). The
/// covariances do not depend on the measurements and every run starts from the same one, so
/// step k's gain and filtered covariance are computed once per call for all runs (forward over
/// A, backward over B), with the operations of the per-run filter: the same bits.
template <int N, int M>
struct KalmanGainsFixed {
    using MatN = Eigen::Matrix<double, N, N>;
    MatN A, Q;
    Eigen::Matrix<double, M, N> H;
    Eigen::Matrix<double, M, M> R;
    MatN P_init;
    std::vector<Eigen::Matrix<double, N, M>> K;  // gain of step k
    std::vector<MatN> P;                         // filtered covariance after step k

    KalmanGainsFixed(const MatN& A_, const MatN& Q_, const Eigen::Matrix<double, M, N>& H_,
                     const Eigen::Matrix<double, M, M>& R_, double p_vel)
        : A(A_), Q(Q_), H(H_), R(R_) {
        P_init.setZero();
        P_init.template topLeftCorner<M, M>() = R;
        P_init.template bottomRightCorner<N - M, N - M>().diagonal().setConstant(p_vel);
    }

    /// Steps 0 .. len - 1 available.
    void extend(Index len) {
        const MatN I = MatN::Identity();
        while (static_cast<Index>(K.size()) < len) {
            MatN Pk = K.empty() ? P_init : P.back();
            if (!K.empty()) Pk = A * Pk * A.transpose() + Q;
            const Eigen::Matrix<double, M, M> S = H * Pk * H.transpose() + R;
            Eigen::LLT<Eigen::Matrix<double, M, M>> llt(S);
            require(llt.info() == Eigen::Success, "gdt_recover_batch",
                    "innovation covariance is not positive definite");
            const Eigen::Matrix<double, N, M> Kk =
                (llt.solve((Pk * H.transpose()).transpose())).transpose();
            const MatN IKH = I - Kk * H;
            Pk = IKH * Pk * IKH.transpose() + Kk * R * Kk.transpose();
            Pk = 0.5 * (Pk + Pk.transpose()).eval();
            K.push_back(Kk);
            P.push_back(Pk);
        }
    }
};

/// Fixed-size Kalman filter over rows [r0, r1) of `seg` (columns 1..M), optionally in reverse
/// order, initialised like filter_run, with the shared gains `g`. Same maths as kalman_filter,
/// without heap allocations.
template <int N, int M>
void kalman_run_fixed(const Eigen::Ref<const RowMatrixXd>& seg, Index r0, Index r1, bool reverse,
                      KalmanGainsFixed<N, M>& g, Eigen::Matrix<double, N, 1>& m,
                      Eigen::Matrix<double, N, N>& P) {
    using VecM = Eigen::Matrix<double, M, 1>;
    const Index len = r1 - r0;
    auto z = [&](Index k) -> VecM {
        const Index r = reverse ? r1 - 1 - k : r0 + k;
        return seg.block(r, 1, 1, M).transpose();
    };
    g.extend(len);
    m.setZero();
    m.template head<M>() = z(0);
    if (len > 1) m.template tail<N - M>() = z(1) - z(0);
    for (Index k = 0; k < len; ++k) {
        if (k > 0) m = g.A * m;
        m += g.K[static_cast<size_t>(k)] * (z(k) - g.H * m);
    }
    P = g.P[static_cast<size_t>(len - 1)];
}

/// Gains of the fixed-size goal-directed mean path (general form, eqs. 7 and 10) for one goal
/// covariance Pi_T. They depend on the number of steps s = T - t to the goal only, not on T:
/// computed once, for the longest gap, and shared by every gap with this Pi_T (the loop of the
/// per-gap computation, run once: the same bits). Also the M^-1 of each s (eq. 9 at s = T - 1).
template <int N, int MG>
struct GoalGainsFixed {
    using MatN = Eigen::Matrix<double, N, N>;
    using MatG = Eigen::Matrix<double, MG, MG>;
    MatN A, Q;
    Eigen::Matrix<double, MG, N> H;
    MatG PiT;
    MatN Phi = MatN::Identity();  // Phi(T, T - s) for the next s
    MatN S = MatN::Zero();
    std::vector<Eigen::Matrix<double, N, MG>> K;  // K_t, t = T - s
    std::vector<Eigen::Matrix<double, MG, N>> G;  // H Phi(T, t - 1)
    std::vector<MatG> Minv;

    GoalGainsFixed(const MatN& A_, const MatN& Q_, const Eigen::Matrix<double, MG, N>& H_,
                   const MatG& PiT_)
        : A(A_), Q(Q_), H(H_), PiT(PiT_) {}

    /// s = 0 .. T - 1 available.
    void extend(int T) {
        const char* fn = "gdt_recover_batch";
        while (static_cast<int>(K.size()) < T) {
            // S_t = Phi(T,t) Q Phi(T,t)^T + S_{t+1};  M_t = Pi_T + H S_t H^T
            S.noalias() += Phi * Q * Phi.transpose();
            const MatG M = PiT + H * S * H.transpose();
            Eigen::LLT<MatG> llt(0.5 * (M + M.transpose()));
            require(llt.info() == Eigen::Success, fn, "Pi_T + H S H^T is not positive definite");
            MatG Mi;
            Mi = llt.solve(MatG::Identity());
            const Eigen::Matrix<double, MG, N> HPhi = H * Phi;
            Eigen::Matrix<double, N, MG> Kt;
            Kt = Q * HPhi.transpose() * Mi;  // eq. 7
            Phi = Phi * A;                   // Phi(T, t-1)
            Eigen::Matrix<double, MG, N> Gt;
            Gt = H * Phi;
            K.push_back(Kt);
            G.push_back(Gt);
            Minv.push_back(Mi);
        }
    }
};

/// Fixed-size goal-directed mean path of one gap of T steps with the gains `g` of its Pi_T;
/// writes the positions of x_1 .. x_{T-1} into out rows [row, row + T - 1).
template <int N, int MG>
void gdt_path_fixed(GoalGainsFixed<N, MG>& g, const Eigen::Matrix<double, N, 1>& m0,
                    const Eigen::Matrix<double, N, N>& P0, const Eigen::Matrix<double, MG, 1>& y,
                    int T, bool start_conditioned, RowMatrixXd& out, Index row) {
    using MatN = Eigen::Matrix<double, N, N>;
    const char* fn = "gdt_recover_batch";
    g.extend(T);
    const auto last = static_cast<size_t>(T - 1);
    Eigen::Matrix<double, N, 1> x = m0;
    if (start_conditioned) {
        const Eigen::Matrix<double, MG, N>& F = g.G[last];  // H Phi(T, 0)
        const Eigen::Matrix<double, MG, MG>& Minv = g.Minv[last];
        Eigen::LLT<MatN> l0(P0);
        require(l0.info() == Eigen::Success, fn, "Pi_0 is not positive definite");
        const MatN info = l0.solve(MatN::Identity()) + F.transpose() * Minv * F;  // eq. 9
        Eigen::LLT<MatN> l1(0.5 * (info + info.transpose()));
        require(l1.info() == Eigen::Success, fn, "cov(x0|yT) is singular");
        x = m0 + l1.solve(F.transpose() * Minv * (y - F * m0));  // eq. 10
    }
    for (int t = 1; t < T; ++t) {
        const auto s = static_cast<size_t>(T - t);
        x = g.A * x + g.K[s] * (y - g.G[s] * x);  // eq. 3 (mean)
        out.row(row++) = x.template head<N / 2>().transpose();
    }
}

template <int M>
RowMatrixXd gdt_recover_batch_fixed(const Eigen::Ref<const RowMatrixXd>& seg_a,
                                    const Eigen::Ref<const Eigen::VectorXi>& a_len,
                                    const Eigen::Ref<const RowMatrixXd>& seg_b,
                                    const Eigen::Ref<const Eigen::VectorXi>& b_len,
                                    const SegmentModel& model, GoalKind goal, int history,
                                    bool start_conditioned, const std::vector<int>& Ts,
                                    Index total) {
    constexpr int N = 2 * M;
    using MatN = Eigen::Matrix<double, N, N>;
    const MatN A = model.A, Q = model.Q;
    const Eigen::Matrix<double, M, N> H = model.H;
    const Eigen::Matrix<double, M, M> R = model.R;
    MatN J = MatN::Identity();
    J.template bottomRightCorner<M, M>() *= -1.0;  // time reversal flips velocities
    RowMatrixXd out(total, M);
    // Gains shared by the gaps: the segments' filter, the goal's path (one Pi_T for the first
    // point of B; one per length of B's filtered run for its backward state).
    KalmanGainsFixed<N, M> filt(A, Q, H, R, model.p_init_velocity);
    GoalGainsFixed<N, M> to_point(A, Q, H, R);
    std::map<Index, GoalGainsFixed<N, N>> to_state;
    constexpr Index kMaxCachedSteps = Index(1) << 17;  // steps of to_state kept (~50 MB at most)
    Index cached = 0;
    Index ia = 0, ib = 0, row = 0;
    for (Index g = 0; g < a_len.size(); ++g) {
        const int T = Ts[static_cast<size_t>(g)];
        Index r0, r1;
        gap_run(seg_a, ia, ia + a_len(g), true, history, r0, r1);
        Eigen::Matrix<double, N, 1> m0;
        MatN P0;
        kalman_run_fixed<N, M>(seg_a, r0, r1, false, filt, m0, P0);
        if (goal == GoalKind::first_point) {
            const Eigen::Matrix<double, M, 1> y = seg_b.block(ib, 1, 1, M).transpose();
            gdt_path_fixed<N, M>(to_point, m0, P0, y, T, start_conditioned, out, row);
        } else {
            gap_run(seg_b, ib, ib + b_len(g), false, history, r0, r1);
            Eigen::Matrix<double, N, 1> mb;
            MatN Pb;
            kalman_run_fixed<N, M>(seg_b, r0, r1, true, filt, mb, Pb);
            auto it = to_state.find(r1 - r0);  // Pb depends on the run's length only
            const Index more = it == to_state.end()
                                   ? T
                                   : std::max<Index>(T - static_cast<Index>(it->second.K.size()), 0);
            if (cached + more > kMaxCachedSteps) {  // bounded memory: start again (same bits)
                to_state.clear();
                cached = 0;
                it = to_state.end();
            }
            if (it == to_state.end()) {
                const MatN PiT = J * Pb * J;
                it = to_state
                         .emplace(r1 - r0, GoalGainsFixed<N, N>(A, Q, MatN::Identity(),
                                                                0.5 * (PiT + PiT.transpose())))
                         .first;
            }
            cached += std::max<Index>(T - static_cast<Index>(it->second.K.size()), 0);
            gdt_path_fixed<N, N>(it->second, m0, P0, J * mb, T, start_conditioned, out, row);
        }
        row += T - 1;
        ia += a_len(g);
        ib += b_len(g);
    }
    return out;
}

}  // namespace detail

/// Recover every gap between consecutive pairs of segments. `seg_a` stacks the A segments
/// (rows frame, p_1..p_m; `a_len[g]` rows each), `seg_b` the B segments likewise. Returns the
/// mean positions of every gap's interior frames (T_g - 1 rows per gap, gaps in order).
inline RowMatrixXd gdt_recover_batch(const Eigen::Ref<const RowMatrixXd>& seg_a,
                                     const Eigen::Ref<const Eigen::VectorXi>& a_len,
                                     const Eigen::Ref<const RowMatrixXd>& seg_b,
                                     const Eigen::Ref<const Eigen::VectorXi>& b_len,
                                     const SegmentModel& model, GoalKind goal, int history,
                                     bool start_conditioned) {
    const char* fn = "gdt_recover_batch";
    const Index m = model.H.rows();
    const Index n = model.A.rows();
    require(m > 0 && n == 2 * m, fn, "A rows", n, "2 x measurement size (position, velocity)");
    require(model.A.cols() == n && model.Q.rows() == n && model.Q.cols() == n &&
                model.H.cols() == n && model.R.rows() == m && model.R.cols() == m,
            fn, "model matrices have mismatched shapes");
    require_finite(model.A, fn, "A");
    require_finite(model.H, fn, "H");
    detail::require_covariance(model.Q, fn, "Q", false);
    detail::require_covariance(model.R, fn, "R", true);
    require(model.p_init_velocity > 0 && std::isfinite(model.p_init_velocity), fn,
            "p_init_velocity", model.p_init_velocity, "> 0");
    require(seg_a.cols() == m + 1 && seg_b.cols() == m + 1, fn,
            "segments must have columns (frame, position...)");
    require(a_len.size() == b_len.size(), fn, "len(b_len)", b_len.size(), a_len.size());
    require_lengths(a_len, seg_a.rows(), fn, "a_len");
    require_lengths(b_len, seg_b.rows(), fn, "b_len");
    require(history >= 1, fn, "history", history, ">= 1");
    require_finite(seg_a, fn, "seg_a");
    require_finite(seg_b, fn, "seg_b");
    const Index G = a_len.size();
    std::vector<int> Ts(static_cast<size_t>(G));
    Index ia = 0, ib = 0, total = 0;
    for (Index g = 0; g < G; ++g) {
        const Index na = a_len(g), nb = b_len(g);
        require(na > 0 && nb > 0, fn, "segment of gap " + std::to_string(g) + " is empty");
        for (Index k = ia + 1; k < ia + na; ++k)
            require(seg_a(k, 0) > seg_a(k - 1, 0), fn,
                    "frames of segment_a of gap " + std::to_string(g) + " do not increase");
        for (Index k = ib + 1; k < ib + nb; ++k)
            require(seg_b(k, 0) > seg_b(k - 1, 0), fn,
                    "frames of segment_b of gap " + std::to_string(g) + " do not increase");
        const double fa = seg_a(ia + na - 1, 0), fb = seg_b(ib, 0);
        require(fb > fa, fn, "segment_b of gap " + std::to_string(g) + " starts at frame " +
                                 std::to_string(fb) + ", not after segment_a's end " +
                                 std::to_string(fa));
        Ts[static_cast<size_t>(g)] = static_cast<int>(fb - fa);
        total += Ts[static_cast<size_t>(g)] - 1;
        ia += na;
        ib += nb;
    }
    if (m == 2)  // image positions: allocation-free fixed-size kernels
        return detail::gdt_recover_batch_fixed<2>(seg_a, a_len, seg_b, b_len, model, goal, history,
                                                  start_conditioned, Ts, total);
    MatrixXd J = MatrixXd::Identity(n, n);
    J.bottomRightCorner(m, m) *= -1.0;  // time reversal flips velocities
    RowMatrixXd out(total, m);
    Index row = 0;
    ia = ib = 0;
    for (Index g = 0; g < G; ++g) {
        GdtProblem p;
        p.T = Ts[static_cast<size_t>(g)];
        p.A = {model.A};
        p.Q = {model.Q};
        Index r0, r1;
        detail::gap_run(seg_a, ia, ia + a_len(g), true, history, r0, r1);
        const KalmanEstimate ea = detail::filter_run(seg_a.block(r0, 1, r1 - r0, m), model);
        p.m0 = ea.m;
        p.Pi_0 = ea.P;
        if (goal == GoalKind::first_point) {
            p.H = model.H;
            p.Pi_T = model.R;
            p.y = seg_b.block(ib, 1, 1, m).transpose();
        } else {
            detail::gap_run(seg_b, ib, ib + b_len(g), false, history, r0, r1);
            const RowMatrixXd zb = seg_b.block(r0, 1, r1 - r0, m).colwise().reverse();
            const KalmanEstimate eb = detail::filter_run(zb, model);
            p.H = MatrixXd::Identity(n, n);
            p.Pi_T = detail::sym(J * eb.P * J);
            p.y = J * eb.m;
        }
        const GdtSteps s = gdt_steps(p, GdtForm::general);
        VectorXd x = start_conditioned ? s.x0_mean : p.m0;
        for (int t = 1; t < p.T; ++t) {
            const size_t k = static_cast<size_t>(t - 1);
            // x_t = A x_{t-1} + K_t (y - G_t x_{t-1})                        (eqs. 3, 7)
            x = p.A[0] * x + s.K[k] * (p.y - s.G[k] * x);
            out.row(row++) = x.head(m).transpose();
        }
        ia += a_len(g);
        ib += b_len(g);
    }
    return out;
}

}  // namespace pftrack
