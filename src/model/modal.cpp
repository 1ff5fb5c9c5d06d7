// El-Shafey (1987) ch. 2 and Theorems 4.1-4.2: see include/ctid/model/modal.hpp.
#include "ctid/model/modal.hpp"

#include <cmath>

#include <unsupported/Eigen/MatrixFunctions>

#include "ctid/core/check.hpp"
#include "internal/least_squares.hpp"

namespace ctid {

namespace {
bool all_finite(const Eigen::MatrixXd& M) { return M.allFinite(); }
}  // namespace

InputGenerator::InputGenerator(Eigen::MatrixXd A, Eigen::VectorXd c, Eigen::VectorXd x0)
    : A_(std::move(A)), c_(std::move(c)), x0_(std::move(x0)) {
  CTID_REQUIRE(A_.rows() == A_.cols() && A_.rows() >= 1, "InputGenerator: A must be square and non-empty (got {}x{})",
               A_.rows(), A_.cols());
  CTID_REQUIRE(c_.size() == A_.rows() && x0_.size() == A_.rows(),
               "InputGenerator: c ({}) and x0 ({}) must have the order of A ({})", c_.size(), x0_.size(), A_.rows());
  CTID_REQUIRE(all_finite(A_) && all_finite(c_) && all_finite(x0_), "InputGenerator: non-finite entries");
}

InputGenerator InputGenerator::constant(double level) {
  return InputGenerator(Eigen::MatrixXd::Zero(1, 1), Eigen::VectorXd::Constant(1, level), Eigen::VectorXd::Ones(1));
}

InputGenerator InputGenerator::exponential(double sigma, double amplitude) {
  return InputGenerator(Eigen::MatrixXd::Constant(1, 1, sigma), Eigen::VectorXd::Constant(1, amplitude),
                        Eigen::VectorXd::Ones(1));
}

InputGenerator InputGenerator::sinusoid(double w, double a_sin, double a_cos, double sigma) {
  CTID_REQUIRE(std::isfinite(w) && w > 0, "InputGenerator::sinusoid: the frequency must be > 0 rad/s (got {})", w);
  Eigen::MatrixXd A(2, 2);
  A << sigma, w, -w, sigma;
  return InputGenerator(A, Eigen::Vector2d(a_sin, a_cos), Eigen::Vector2d(0.0, 1.0));
}

InputGenerator InputGenerator::operator+(const InputGenerator& o) const {
  if (order() == 0) return o;
  if (o.order() == 0) return *this;
  const int n1 = order(), n2 = o.order();
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n1 + n2, n1 + n2);
  A.topLeftCorner(n1, n1) = A_;
  A.bottomRightCorner(n2, n2) = o.A_;
  Eigen::VectorXd c(n1 + n2), x0(n1 + n2);
  c << c_, o.c_;
  x0 << x0_, o.x0_;
  return InputGenerator(A, c, x0);
}

Eigen::VectorXcd InputGenerator::modes() const { return Eigen::EigenSolver<Eigen::MatrixXd>(A_, false).eigenvalues(); }

Polynomial InputGenerator::characteristic_polynomial() const {
  return StateSpace(A_, Eigen::MatrixXd::Zero(order(), 1), Eigen::MatrixXd::Zero(1, order()), Eigen::MatrixXd::Zero(1, 1))
      .to_transfer_function()
      .den();
}

Eigen::MatrixXd InputGenerator::basis(const Eigen::VectorXd& t) const {
  CTID_REQUIRE(order() >= 1, "InputGenerator: empty generator");
  CTID_REQUIRE(t.allFinite(), "InputGenerator::basis: non-finite time");
  Eigen::MatrixXd X(t.size(), order());
  // Uniform grids: steps by Phi = e^{A h}, re-anchored by an exact exponential every 1024 samples so
  // that round-off cannot accumulate; other grids: one exponential per time.
  const Eigen::Index N = t.size();
  const double h = N > 1 ? t(1) - t(0) : 0.0;
  bool uniform = N > 2 && h > 0;
  for (Eigen::Index i = 2; uniform && i < N; ++i) uniform = std::abs(t(i) - t(i - 1) - h) <= 1e-12 * std::max(1.0, std::abs(t(i)));
  const Eigen::MatrixXd Phi = uniform ? Eigen::MatrixXd(Eigen::MatrixXd(A_ * h).exp()) : Eigen::MatrixXd();
  Eigen::VectorXd x;
  for (Eigen::Index i = 0; i < N; ++i) {
    if (!uniform || i % 1024 == 0) x = Eigen::MatrixXd(A_ * t(i)).exp() * x0_;
    else x = Phi * x;
    X.row(i) = x.transpose();
  }
  return X;
}

Eigen::VectorXd InputGenerator::operator()(const Eigen::VectorXd& t) const { return basis(t) * c_; }

ModalParameters modal_parameters(const StateSpace& sys, const Eigen::VectorXd& shifts, int max_order) {
  CTID_REQUIRE(sys.nu() == 1 && sys.ny() == 1, "modal_parameters: needs a SISO model (got {} inputs, {} outputs)",
               sys.nu(), sys.ny());
  const int n = sys.nx();
  CTID_REQUIRE(n >= 1, "modal_parameters: the model has no states");
  CTID_REQUIRE(shifts.size() == n, "modal_parameters: {} shifts given for a model of order {} (one per state)",
               shifts.size(), n);
  CTID_REQUIRE(max_order >= 0, "modal_parameters: max_order must be >= 0 (got {})", max_order);
  for (int i = 0; i < n; ++i) {
    CTID_REQUIRE(std::isfinite(shifts(i)) && shifts(i) != 0, "modal_parameters: shift {} must be finite and non-zero "
                 "(got {})", i + 1, shifts(i));
    for (int k = 0; k < i; ++k)
      CTID_REQUIRE(shifts(i) != shifts(k), "modal_parameters: shifts {} and {} are equal ({} s)", k + 1, i + 1, shifts(i));
  }
  ModalParameters r;
  r.psi.resize(n, n);
  const Eigen::RowVectorXd c = sys.C().row(0);
  for (int i = 0; i < n; ++i) r.psi.row(i) = c * Eigen::MatrixXd(-sys.A() * shifts(i)).exp();
  r.condition = internal::condition_number(r.psi);
  CTID_REQUIRE(r.condition < 1e13, "modal_parameters: psi is singular (condition {}): the model is unobservable or the "
               "shifts make two modes indistinguishable; move the shifts", r.condition);
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(r.psi.transpose());
  r.P.resize(max_order + 1, n);
  Eigen::RowVectorXd cAj = c;
  for (int j = 0; j <= max_order; ++j) {
    r.P.row(j) = -lu.solve(cAj.transpose()).transpose();
    cAj = cAj * sys.A();
  }
  return r;
}

ModalParameters modal_parameters(const TransferFunction& tf, const Eigen::VectorXd& shifts, int max_order) {
  return modal_parameters(phase_variable_form(tf), shifts, max_order);
}

ShiftChoice choose_modal_shifts(const TransferFunction& prior, double Ts, double max_shift) {
  const StateSpace pv = phase_variable_form(prior);
  const int n = pv.nx();
  CTID_REQUIRE(std::isfinite(Ts) && Ts > 0, "choose_modal_shifts: Ts must be > 0 (got {})", Ts);
  CTID_REQUIRE(std::isfinite(max_shift) && max_shift / (n * Ts) <= 1e5,
               "choose_modal_shifts: max_shift = {} s must be finite and at most 1e5 n Ts = {} s", max_shift,
               1e5 * n * Ts);
  const int kmax = static_cast<int>(std::floor(max_shift / (n * Ts) + 1e-9));
  CTID_REQUIRE(kmax >= 1, "choose_modal_shifts: max_shift = {} s is shorter than n Ts = {} s", max_shift, n * Ts);
  ShiftChoice c;
  c.spacings.resize(kmax);
  c.conditions.resize(kmax);
  const Eigen::RowVectorXd cr = pv.C().row(0);
  Eigen::MatrixXd psi(n, n);
  int best = -1;
  for (int k = 1; k <= kmax; ++k) {
    const double d = k * Ts;
    const Eigen::MatrixXd E = Eigen::MatrixXd(-pv.A() * d).exp();  // e^{-A i d} = E^i
    Eigen::RowVectorXd row = cr;
    for (int i = 0; i < n; ++i) psi.row(i) = row = row * E;
    c.spacings(k - 1) = d;
    c.conditions(k - 1) = internal::condition_number(psi);
    if (std::isfinite(c.conditions(k - 1)) && (best < 0 || c.conditions(k - 1) < c.conditions(best))) best = k - 1;
  }
  CTID_REQUIRE(best >= 0, "choose_modal_shifts: psi is singular for every spacing up to {} s", max_shift / n);
  c.condition = c.conditions(best);
  c.shifts = Eigen::VectorXd::LinSpaced(n, 1, n) * c.spacings(best);
  return c;
}

StateSpace phase_variable_form(const TransferFunction& tf) {
  const int n = tf.order();
  CTID_REQUIRE(n >= 1, "phase_variable_form: the transfer function has no poles");
  CTID_REQUIRE(tf.num().degree() < n || tf.num().is_zero(),
               "phase_variable_form: needs a strictly proper transfer function (numerator degree {} >= {})",
               tf.num().degree(), n);
  const double lead = tf.den().leading();
  // a_k (k = 0..n, a_n = 1) and b_j (j = 0..n-1), ascending powers.
  Eigen::VectorXd a(n + 1), b = Eigen::VectorXd::Zero(n);
  for (int k = 0; k <= n; ++k) a(k) = tf.den().coefficient_of_power(k) / lead;
  for (int j = 0; j < n; ++j) b(j) = tf.num().coefficient_of_power(j) / lead;
  // ES 2.12: b_j = sum_{k=j+1}^{n} a_k b~_{k-j}, solved from j = n-1 down.
  Eigen::VectorXd bt(n + 1);
  bt(0) = 0;
  for (int m = 1; m <= n; ++m) {
    double s = b(n - m);
    for (int k = n - m + 1; k <= n - 1; ++k) s -= a(k) * bt(k - n + m);
    bt(m) = s;
  }
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i + 1 < n; ++i) A(i, i + 1) = 1.0;
  for (int k = 0; k < n; ++k) A(n - 1, k) = -a(k);
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(1, n);
  C(0, 0) = 1.0;
  return StateSpace(A, bt.tail(n), C, Eigen::MatrixXd::Zero(1, 1));
}

ModalModel::ModalModel(Eigen::VectorXd shifts, Eigen::MatrixXd P, Eigen::MatrixXd Q)
    : shifts_(std::move(shifts)), P_(std::move(P)), Q_(std::move(Q)) {
  CTID_REQUIRE(shifts_.size() >= 1, "ModalModel: needs at least one shift");
  CTID_REQUIRE(P_.cols() == shifts_.size() && P_.rows() >= 1,
               "ModalModel: P must have one column per shift ({} columns, {} shifts)", P_.cols(), shifts_.size());
  CTID_REQUIRE(Q_.rows() == P_.rows() || Q_.size() == 0, "ModalModel: Q has {} rows, P has {}", Q_.rows(), P_.rows());
  if (Q_.size() == 0) Q_.resize(P_.rows(), 0);
}

Polynomial ModalModel::characteristic_polynomial() const {
  const int n = order();
  CTID_REQUIRE(max_order() >= n, "ModalModel: Theorem 4.1 needs p_0 .. p_{} (have up to p_{})", n, max_order());
  const Eigen::MatrixXd Pn = P_.topRows(n);
  const Eigen::VectorXd a = Pn.transpose().colPivHouseholderQr().solve(-P_.row(n).transpose());
  Eigen::VectorXd c(n + 1);
  c(0) = 1.0;
  for (int k = 0; k < n; ++k) c(k + 1) = a(n - 1 - k);
  return Polynomial(c);
}

TransferFunction ModalModel::transfer_function(const InputGenerator& g) const { return modal_theorems_tf({{*this, g}}); }

namespace {
// Descending monic polynomial from ascending a_0..a_{n-1}; numerator from ascending b.
TransferFunction tf_from_ab(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const Eigen::Index n = a.size();
  Eigen::VectorXd den(n + 1), num(n);
  den(0) = 1.0;
  for (Eigen::Index k = 0; k < n; ++k) {
    den(k + 1) = a(n - 1 - k);
    num(k) = b(n - 1 - k);
  }
  return TransferFunction(Polynomial(num), Polynomial(den));
}

int common_order(const std::vector<ModalExperiment>& ex, const char* who) {
  CTID_REQUIRE(!ex.empty(), "{}: no experiments", who);
  const int n = ex[0].model.order();
  for (size_t e = 0; e < ex.size(); ++e) {
    CTID_REQUIRE(ex[e].model.order() == n, "{}: experiment {} has order {}, experiment 1 has {}", who, e + 1,
                 ex[e].model.order(), n);
    CTID_REQUIRE(ex[e].model.Q().cols() == ex[e].input.order(), "{}: experiment {} has {} q columns but its input "
                 "generator has order {}", who, e + 1, ex[e].model.Q().cols(), ex[e].input.order());
  }
  return n;
}

// [v, A^T v, ..., (A^T)^{n-1} v] (n_c x n).
Eigen::MatrixXd krylov(const Eigen::MatrixXd& A, Eigen::VectorXd v, int n) {
  Eigen::MatrixXd K(v.size(), n);
  for (int j = 0; j < n; ++j) {
    K.col(j) = v;
    v = A.transpose() * v;
  }
  return K;
}
}  // namespace

TransferFunction modal_theorems_tf(const std::vector<ModalExperiment>& ex) {
  const int n = common_order(ex, "modal_theorems_tf");
  int rows_a = 0, rows_b = 0;
  for (size_t e = 0; e < ex.size(); ++e) {
    CTID_REQUIRE(ex[e].model.max_order() >= n, "modal_theorems_tf: Theorem 4.1 needs p_0 .. p_{} (experiment {} has up "
                 "to p_{})", n, e + 1, ex[e].model.max_order());
    rows_a += n;
    rows_b += ex[e].input.order();
  }
  CTID_REQUIRE(rows_b >= n, "modal_theorems_tf: Theorem 4.2 needs at least n = {} input modes in total (have {})", n,
               rows_b);
  // Theorem 4.1: P^T a = -p_n for every experiment.
  Eigen::MatrixXd Aa(rows_a, n);
  Eigen::VectorXd ba(rows_a);
  int r = 0;
  for (const auto& x : ex) {
    Aa.middleRows(r, n) = x.model.P().topRows(n).transpose();
    ba.segment(r, n) = -x.model.P().row(n).transpose();
    r += n;
  }
  const Eigen::VectorXd a = Aa.colPivHouseholderQr().solve(ba);
  // Theorem 4.2: q_n + sum a_j q_j = R_b b.
  Eigen::MatrixXd Ab(rows_b, n);
  Eigen::VectorXd bb(rows_b);
  r = 0;
  for (const auto& x : ex) {
    const int nc = x.input.order();
    Eigen::VectorXd qt = x.model.Q().row(n).transpose();
    for (int j = 0; j < n; ++j) qt += a(j) * x.model.Q().row(j).transpose();
    Ab.middleRows(r, nc) = krylov(x.input.A(), x.input.c(), n);
    bb.segment(r, nc) = qt;
    r += nc;
  }
  return tf_from_ab(a, Ab.colPivHouseholderQr().solve(bb));
}

TransferFunction modal_output_function_tf(const std::vector<ModalExperiment>& ex) {
  const int n = common_order(ex, "modal_output_function_tf");
  int rows = 0;
  for (const auto& x : ex) rows += x.input.order();
  CTID_REQUIRE(rows >= 2 * n, "modal_output_function_tf: needs at least 2n = {} input modes in total (have {})", 2 * n,
               rows);
  Eigen::MatrixXd R(rows, 2 * n);
  Eigen::VectorXd rhs(rows);
  int r = 0;
  for (const auto& x : ex) {
    const int nc = x.input.order();
    const Eigen::VectorXd q0 = x.model.Q().row(0).transpose();
    // nu = (I + sum_i p_0i e^{-A^T T_i}) c: the input filtered by the output modal parameters (ES 4.5).
    Eigen::VectorXd nu = x.input.c();
    for (int i = 0; i < n; ++i)
      nu += x.model.P()(0, i) * (Eigen::MatrixXd(-x.input.A().transpose() * x.model.shifts()(i)).exp() * x.input.c());
    R.block(r, 0, nc, n) = krylov(x.input.A(), q0, n);
    R.block(r, n, nc, n) = -krylov(x.input.A(), nu, n);
    Eigen::VectorXd v = q0;
    for (int j = 0; j < n; ++j) v = x.input.A().transpose() * v;
    rhs.segment(r, nc) = -v;
    r += nc;
  }
  const Eigen::VectorXd theta = R.colPivHouseholderQr().solve(rhs);
  return tf_from_ab(theta.head(n), theta.tail(n));
}

}  // namespace ctid
