// El-Shafey (1987) ch. 6: minimum-time observer and b~ (ES 6.1-6.43; ES 6.1-6.36, ES 6.37-6.43).
// See include/ctid/estimate/modal/modal_observer.hpp.
#include "ctid/estimate/modal/modal_observer.hpp"

#include <cmath>
#include <limits>

#include <unsupported/Eigen/MatrixFunctions>

#include "ctid/core/check.hpp"

namespace ctid {

namespace {
int whole(double a, double b, const char* what) {
  const double r = a / b;
  CTID_REQUIRE(std::isfinite(r) && r >= 1 - 1e-9 && r <= 1e9 && std::abs(r - std::round(r)) <= 1e-9 * r,
               "DeadbeatObserver: {} ({} s / {} s = {}) must be a whole number >= 1", what, a, b, r);
  return static_cast<int>(std::lround(r));
}

// Delta: (n+1) x (n+1) lower bidiagonal, 1 on the diagonal, -1 below.
Eigen::MatrixXd delta(int n) {
  Eigen::MatrixXd D = Eigen::MatrixXd::Identity(n + 1, n + 1);
  for (int i = 1; i <= n; ++i) D(i, i - 1) = -1.0;
  return D;
}

// Gamma_j = blockdiag(1, H_j), (H_j)_{l+1, m} = p_{j, l+m} for l + m <= n (Hankel, ES 6.19).
Eigen::MatrixXd gamma(const Eigen::RowVectorXd& pj) {
  const int n = static_cast<int>(pj.size());
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n + 1, n + 1);
  G(0, 0) = 1.0;
  for (int l = 0; l < n; ++l)
    for (int m = 1; m + l <= n; ++m) G(1 + l, m) = pj(l + m - 1);
  return G;
}
}  // namespace

void DeadbeatObserver::assemble(const std::vector<Eigen::VectorXd>& r) {
  const int n = order();
  r_ = r;
  qt0_ = P_ * r[0];
  const Eigen::MatrixXd Dt = delta(n).transpose();
  Qbar_.assign(r.size(), Eigen::MatrixXd(n, n + 1));
  for (int j = 0; j < n; ++j) {
    const Eigen::MatrixXd DG = Dt * gamma(P_.row(j));
    for (size_t o = 0; o < r.size(); ++o) {
      Eigen::VectorXd v(n + 1);
      v << qt0_(j), r[o];
      Qbar_[o].row(j) = (DG * v).transpose();  // ES 6.23
    }
  }
}

DeadbeatObserver DeadbeatObserver::from_model(const TransferFunction& tf, double T, double Ts) {
  CTID_REQUIRE(std::isfinite(Ts) && Ts > 0, "DeadbeatObserver: Ts must be > 0 (got {})", Ts);
  const int m = whole(T, Ts, "the level period T over the sampling period");
  const StateSpace pv = phase_variable_form(tf);
  const int n = pv.nx();
  Eigen::VectorXd shifts(n);
  for (int i = 0; i < n; ++i) shifts(i) = (i + 1) * T;
  DeadbeatObserver o;
  o.T_ = T;
  o.Ts_ = Ts;
  o.P_ = modal_parameters(pv, shifts, n - 1).P;
  // r_m(s) = int_0^{s - mT} c^T e^{A sigma} b d sigma [RECONSTRUCTED sign], from the exponential of [[A, b], [0, 0]].
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + 1, n + 1);
  M.topLeftCorner(n, n) = pv.A();
  M.topRightCorner(n, 1) = pv.B();
  std::vector<Eigen::VectorXd> r(m, Eigen::VectorXd(n));
  for (int off = 0; off < m; ++off)
    for (int k = 1; k <= n; ++k) {
      const Eigen::MatrixXd E = Eigen::MatrixXd(M * (off * Ts - k * T)).exp();
      r[off](k - 1) = (pv.C() * E.topRightCorner(n, 1))(0, 0);
    }
  o.assemble(r);
  return o;
}

DeadbeatObserver DeadbeatObserver::from_step_response(const ModalModel& model, const TimeResponse& step, double T) {
  const int n = model.order();
  CTID_REQUIRE(model.max_order() >= n - 1, "DeadbeatObserver: needs p_0 .. p_{} (the model has up to p_{})", n - 1,
               model.max_order());
  for (int i = 0; i < n; ++i)
    CTID_REQUIRE(std::abs(model.shifts()(i) - (i + 1) * T) <= 1e-9 * T, "DeadbeatObserver: shift T_{} = {} s must be {} s "
                 "(i T)", i + 1, model.shifts()(i), (i + 1) * T);
  CTID_REQUIRE(step.t.size() >= 2 && step.t(0) == 0.0, "DeadbeatObserver: the step response must start at t = 0");
  const double Ts = step.t(1) - step.t(0);
  const int m = whole(T, Ts, "the level period T over the step response spacing");
  CTID_REQUIRE(step.value.size() >= (n + 1) * m, "DeadbeatObserver: the step response must cover [0, {} s) ({} samples, "
               "has {})", (n + 1) * T, (n + 1) * m, step.value.size());
  DeadbeatObserver o;
  o.T_ = T;
  o.Ts_ = Ts;
  o.P_ = model.P().topRows(n);
  const Eigen::RowVectorXd p0 = o.P_.row(0);
  const Eigen::MatrixXd DL = modal_delta_l(p0);
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(delta(n).transpose() * gamma(p0));
  std::vector<Eigen::VectorXd> r(m);
  for (int off = 0; off < m; ++off) {
    Eigen::VectorXd g(n + 1);
    for (int i = 0; i <= n; ++i) g(i) = step.value(off + i * m);
    const Eigen::VectorXd v = lu.solve(DL * g);  // [q~_00; r(s)] (ES 6.27, 6.29)
    r[off] = v.tail(n);
  }
  o.assemble(r);
  return o;
}

const Eigen::MatrixXd& DeadbeatObserver::Qbar(int r) const {
  CTID_REQUIRE(r >= 0 && r < offsets(), "DeadbeatObserver: offset {} outside [0, {})", r, offsets());
  return Qbar_[r];
}

const Eigen::VectorXd& DeadbeatObserver::r(int offset) const {
  CTID_REQUIRE(offset >= 0 && offset < offsets(), "DeadbeatObserver: offset {} outside [0, {})", offset, offsets());
  return r_[offset];
}

Eigen::MatrixXd DeadbeatObserver::reconstruct(const IdData& data) const {
  CTID_REQUIRE(order() > 0, "DeadbeatObserver: not designed");
  CTID_REQUIRE(data.nu() == 1 && data.ny() == 1 && data.is_uniform(), "DeadbeatObserver: needs uniformly sampled SISO "
               "data");
  CTID_REQUIRE(std::abs(data.ts() - Ts_) <= 1e-9 * Ts_, "DeadbeatObserver: designed for Ts = {} s, the record has {} s",
               Ts_, data.ts());
  const int n = order(), m = offsets(), N = data.size();
  const Eigen::VectorXd u = data.u().col(0), y = data.y().col(0);
  for (int i = 0; i < N; ++i)
    CTID_REQUIRE(u(i) == u(i - i % m), "DeadbeatObserver: the input changes inside a level period (t = {} s)",
                 i * Ts_);
  Eigen::MatrixXd X = Eigen::MatrixXd::Constant(N, n, std::numeric_limits<double>::quiet_NaN());
  Eigen::VectorXd yv(n), uv(n + 1);
  for (int i = n * m; i < N; ++i) {
    const int k = i / m, off = i % m;
    for (int l = 1; l <= n; ++l) yv(l - 1) = y(i - l * m);
    for (int l = 0; l <= n; ++l) uv(l) = u((k - l) * m);
    X.row(i) = (-P_ * yv + Qbar_[off] * uv).transpose();
  }
  return X;
}

Eigen::VectorXd DeadbeatObserver::markov_parameters(const Eigen::RowVectorXd& p_n) const {
  const int n = order();
  CTID_REQUIRE(n > 0, "DeadbeatObserver: not designed");
  CTID_REQUIRE(p_n.size() == n, "DeadbeatObserver: p_n has {} entries for order {}", p_n.size(), n);
  // The step response's constant part g_c = H(0): p_0 leaves q_00 = g_c (1 + sum_i p_0i) = q~_00 (b~_0 = 0 for a
  // strictly proper model). 1 + sum_i p_0i is the scalar form 1 + sum_i p_0i e^{-s T_i} at s = 0 (ES 2.24): zero
  // exactly when s = 0 is a pole.
  const double one_plus = 1.0 + P_.row(0).sum();
  CTID_REQUIRE(std::abs(one_plus) > 1e-9 * (1.0 + P_.row(0).cwiseAbs().sum()),
               "DeadbeatObserver: the system has a pole at s = 0 (1 + sum p_0i = {}): an integrating plant's step "
               "response has no constant part, so b~ cannot be separated this way (use a transfer-function fit)",
               one_plus);
  const double g_c = qt0_(0) / one_plus;
  Eigen::MatrixXd Pall(n + 1, n);
  Pall << P_, p_n;
  Eigen::VectorXd shifts(n);
  for (int i = 0; i < n; ++i) shifts(i) = (i + 1) * T_;
  const Polynomial a = ModalModel(shifts, Pall, Eigen::MatrixXd()).characteristic_polynomial();  // Theorem 4.1
  Eigen::VectorXd bt(n);
  for (int j = 1; j < n; ++j) bt(j - 1) = g_c * P_.row(j).sum() - qt0_(j);
  double bn = g_c * p_n.sum();
  for (int j = 0; j < n; ++j) bn += a.coefficient_of_power(j) * qt0_(j);
  bt(n - 1) = bn;
  return bt;
}

}  // namespace ctid
