#include "ctid/model/state_space.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "ctid/core/check.hpp"

namespace ctid {

StateSpace::StateSpace(Eigen::MatrixXd A, Eigen::MatrixXd B, Eigen::MatrixXd C, Eigen::MatrixXd D)
    : A_(std::move(A)), B_(std::move(B)), C_(std::move(C)), D_(std::move(D)) {
  CTID_REQUIRE(A_.rows() == A_.cols(), "StateSpace: A must be square (got {}x{})", A_.rows(), A_.cols());
  CTID_REQUIRE(B_.rows() == A_.rows(), "StateSpace: B needs {} rows like A (got {})", A_.rows(), B_.rows());
  CTID_REQUIRE(C_.cols() == A_.rows(), "StateSpace: C needs {} columns like A (got {})", A_.rows(), C_.cols());
  CTID_REQUIRE(D_.rows() == C_.rows() && D_.cols() == B_.cols(), "StateSpace: D must be {}x{} (got {}x{})", C_.rows(),
               B_.cols(), D_.rows(), D_.cols());
  CTID_REQUIRE(A_.allFinite() && B_.allFinite() && C_.allFinite() && D_.allFinite(),
               "StateSpace: the matrices contain NaN or Inf");
}

StateSpace::StateSpace(Eigen::MatrixXd A, Eigen::MatrixXd B, Eigen::MatrixXd C, Eigen::MatrixXd D, Eigen::MatrixXd K)
    : StateSpace(std::move(A), std::move(B), std::move(C), std::move(D)) {
  if (K.size() == 0) return;
  CTID_REQUIRE(K.rows() == A_.rows() && K.cols() == C_.rows(), "StateSpace: K must be {}x{} (nx x ny; got {}x{})",
               A_.rows(), C_.rows(), K.rows(), K.cols());
  CTID_REQUIRE(K.allFinite(), "StateSpace: K contains NaN or Inf");
  K_ = std::move(K);
}

StateSpace StateSpace::controllable_canonical(const TransferFunction& tf) {
  const int n = tf.order();
  const Eigen::VectorXd& a = tf.den().coefficients();  // monic, length n+1
  Eigen::VectorXd b = Eigen::VectorXd::Zero(n + 1);
  b.tail(tf.num().coefficients().size()) = tf.num().coefficients();
  const double d = b(0);  // direct term (b has the same length as a, a(0) = 1)
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n), B = Eigen::MatrixXd::Zero(n, 1), C(1, n), D(1, 1);
  for (int j = 0; j < n; ++j) {
    A(0, j) = -a(j + 1);
    C(0, j) = b(j + 1) - d * a(j + 1);
  }
  for (int i = 1; i < n; ++i) A(i, i - 1) = 1.0;
  if (n > 0) B(0, 0) = 1.0;
  D(0, 0) = d;
  return StateSpace(A, B, C, D);
}

StateSpace StateSpace::observable_canonical(const TransferFunction& tf) {
  const StateSpace c = controllable_canonical(tf);
  return StateSpace(c.A().transpose(), c.C().transpose(), c.B().transpose(), c.D());
}

Eigen::VectorXcd StateSpace::poles() const {
  if (nx() == 0) return Eigen::VectorXcd(0);
  return Eigen::EigenSolver<Eigen::MatrixXd>(A_, false).eigenvalues();
}

std::vector<Mode> StateSpace::modes() const {
  std::vector<Mode> out;
  if (nx() == 0) return out;
  const Eigen::EigenSolver<Eigen::MatrixXd> es(A_, true);
  for (Eigen::Index i = 0; i < nx(); ++i) {
    const std::complex<double> p = es.eigenvalues()(i);
    if (p.imag() < 0) continue;
    Mode m;
    m.pole = p;
    m.wn = std::abs(p);
    m.zeta = m.wn > 0 ? -p.real() / m.wn : 1.0;
    m.shape = C_.cast<std::complex<double>>() * es.eigenvectors().col(i);
    Eigen::Index big = 0;
    if (m.shape.size() > 0) m.shape.cwiseAbs().maxCoeff(&big);
    const double norm = m.shape.norm();
    if (norm > 0) m.shape *= std::conj(m.shape(big)) / (std::abs(m.shape(big)) * norm);
    out.push_back(std::move(m));
  }
  std::sort(out.begin(), out.end(), [](const Mode& a, const Mode& b) { return a.wn < b.wn; });
  return out;
}

bool StateSpace::is_stable() const {
  const Eigen::VectorXcd p = poles();
  for (Eigen::Index i = 0; i < p.size(); ++i)
    if (!(p(i).real() < 0)) return false;
  return true;
}

namespace {
// det(sI - M) from the eigenvalues. Defective (repeated) eigenvalues come back perturbed by
// O(sqrt(eps)) and not always as exact conjugate pairs; the coefficients are continuous in the
// roots, so the real part of the expanded product is accurate and the imaginary residue is dropped
// (Polynomial::from_roots rejects it, rightly, for user-given roots).
Polynomial char_poly(const Eigen::MatrixXd& M) {
  if (M.rows() == 0) return Polynomial{1.0};
  const Eigen::VectorXcd r = Eigen::EigenSolver<Eigen::MatrixXd>(M, false).eigenvalues();
  Eigen::VectorXcd c = Eigen::VectorXcd::Zero(r.size() + 1);
  c(0) = 1.0;
  for (Eigen::Index k = 0; k < r.size(); ++k)
    for (Eigen::Index i = k + 1; i >= 1; --i) c(i) -= r(k) * c(i - 1);
  return Polynomial(Eigen::VectorXd(c.real()));
}
}  // namespace

TransferFunction StateSpace::to_transfer_function(int out, int in) const {
  CTID_REQUIRE(out >= 0 && out < ny() && in >= 0 && in < nu(), "StateSpace: channel ({}, {}) out of range ({} outputs, {} inputs)",
               out, in, ny(), nu());
  const Polynomial den = char_poly(A_);
  const Eigen::MatrixXd ABC = A_ - B_.col(in) * C_.row(out);
  Polynomial strictly = char_poly(ABC) - den;
  // The s^n terms cancel exactly; drop a numerically-zero leading remainder.
  Eigen::VectorXd c = strictly.coefficients();
  const double scale = std::max(1.0, den.coefficients().cwiseAbs().maxCoeff());
  const double cmax = c.cwiseAbs().maxCoeff();
  Eigen::Index first = 0;
  while (first < c.size() - 1 && std::abs(c(first)) < 1e-12 * std::max(cmax, 1e-300 * scale)) ++first;
  strictly = Polynomial(Eigen::VectorXd(c.tail(c.size() - first)));
  return TransferFunction(strictly + den * D_(out, in), den);
}

Eigen::VectorXcd StateSpace::frequency_response(const Eigen::VectorXd& w, int out, int in) const {
  CTID_REQUIRE(out >= 0 && out < ny() && in >= 0 && in < nu(), "StateSpace: channel ({}, {}) out of range", out, in);
  Eigen::VectorXcd g(w.size());
  const Eigen::MatrixXcd Ac = A_.cast<std::complex<double>>();
  const Eigen::VectorXcd b = B_.col(in).cast<std::complex<double>>();
  const Eigen::RowVectorXcd c = C_.row(out).cast<std::complex<double>>();
  for (Eigen::Index i = 0; i < w.size(); ++i) {
    if (nx() == 0) { g(i) = D_(out, in); continue; }
    Eigen::MatrixXcd M = -Ac;
    M.diagonal().array() += std::complex<double>(0.0, w(i));
    g(i) = (c * M.partialPivLu().solve(b))(0) + D_(out, in);
  }
  return g;
}

}  // namespace ctid
