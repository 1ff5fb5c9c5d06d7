// FSF model — Gawthrop & Wang (2005) eqs (1)-(13); see include/ctid/model/fsf.hpp.
#include "ctid/model/fsf.hpp"

#include <cmath>
#include <numbers>

#include "ctid/core/check.hpp"

namespace ctid {

using cd = std::complex<double>;

FsfModel::FsfModel(double delta, int N, int n, Eigen::VectorXd theta, Eigen::MatrixXd cov, double shift)
    : delta_(delta), shift_(shift), N_(N), n_(n), theta_(std::move(theta)), cov_(std::move(cov)) {
  CTID_REQUIRE(std::isfinite(delta) && delta > 0, "FsfModel: the sample interval must be > 0 (got {})", delta);
  CTID_REQUIRE(N >= 1, "FsfModel: N = T/Delta must be >= 1 (got {})", N);
  CTID_REQUIRE(n >= 1 && n % 2 == 1, "FsfModel: the number of filters n must be odd and >= 1 (got {})", n);
  CTID_REQUIRE(n <= N, "FsfModel: n = {} filters exceed N = {} samples per window", n, N);
  CTID_REQUIRE(theta_.size() == n, "FsfModel: theta needs n = {} real parameters (got {})", n, theta_.size());
  CTID_REQUIRE(cov_.size() == 0 || (cov_.rows() == n && cov_.cols() == n), "FsfModel: covariance must be {}x{}", n, n);
  CTID_REQUIRE(std::isfinite(shift) && shift >= 0, "FsfModel: the window shift must be >= 0 (got {})", shift);
}

double FsfModel::omega() const { return 2.0 * std::numbers::pi / T(); }

cd FsfModel::theta_k(int k) const {
  const int mm = m();
  CTID_REQUIRE(k >= -mm && k <= mm, "FsfModel: k = {} outside [-{}, {}]", k, mm, mm);
  if (k == 0) return theta_(0);
  const cd t(theta_(2 * std::abs(k) - 1), theta_(2 * std::abs(k)));
  return k > 0 ? t : std::conj(t);
}

cd FsfModel::filter_response(int k, double w) const {
  const cd zinv = std::exp(cd(0, -w * delta_));
  const cd pole = std::exp(cd(0, 2.0 * std::numbers::pi * k / N_));
  const cd den = 1.0 - pole * zinv;
  if (std::abs(den) < 1e-12) return 1.0;  // w = k Omega: Hbar_k = 1 (removable singularity)
  return (1.0 - std::pow(zinv, N_)) / (double(N_) * den);
}

Eigen::VectorXcd FsfModel::frequency_response(const Eigen::VectorXd& w) const {
  Eigen::VectorXcd g = Eigen::VectorXcd::Zero(w.size());
  for (Eigen::Index i = 0; i < w.size(); ++i)
    for (int k = -m(); k <= m(); ++k) g(i) += theta_k(k) * filter_response(k, w(i));
  return g;
}

Eigen::RowVectorXd FsfModel::step_basis(double t) const {
  Eigen::RowVectorXd r = Eigen::RowVectorXd::Zero(n_);
  const double tt = std::clamp(t, 0.0, T());
  const double W = omega();
  r(0) = tt / T();
  for (int k = 1; k <= m(); ++k) {
    // 2 Re[theta_k (e^{jkWt} - 1)/(jkWT)] = 2 [Re theta_k sin(kWt) + Im theta_k (cos(kWt) - 1)] / (kWT)
    const double x = k * W * tt, d = k * W * T();
    r(2 * k - 1) = 2.0 * std::sin(x) / d;
    r(2 * k) = 2.0 * (std::cos(x) - 1.0) / d;
  }
  return r;
}

Eigen::VectorXd FsfModel::step_response(const Eigen::VectorXd& t) const {
  Eigen::VectorXd y(t.size());
  for (Eigen::Index i = 0; i < t.size(); ++i) y(i) = step_basis(t(i)).dot(theta_);
  return y;
}

Eigen::VectorXd FsfModel::step_response_std(const Eigen::VectorXd& t) const {
  Eigen::VectorXd s = Eigen::VectorXd::Constant(t.size(), NAN);
  if (cov_.size() == 0) return s;
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const Eigen::RowVectorXd r = step_basis(t(i));
    s(i) = std::sqrt(std::max(0.0, (r * cov_ * r.transpose())(0, 0)));
  }
  return s;
}

Eigen::RowVectorXd FsfModel::impulse_basis(double t) const {
  Eigen::RowVectorXd b = Eigen::RowVectorXd::Zero(n_);
  if (t < 0 || t >= T()) return b;
  const double W = omega();
  b(0) = 1.0 / T();
  for (int k = 1; k <= m(); ++k) {  // 2 Re[theta_k e^{jkWt}] / T
    b(2 * k - 1) = 2.0 * std::cos(k * W * t) / T();
    b(2 * k) = -2.0 * std::sin(k * W * t) / T();
  }
  return b;
}

Eigen::VectorXd FsfModel::impulse_response(const Eigen::VectorXd& t) const {
  Eigen::VectorXd g(t.size());
  for (Eigen::Index i = 0; i < t.size(); ++i) g(i) = impulse_basis(t(i)).dot(theta_);
  return g;
}

Eigen::VectorXd FsfModel::impulse_response_std(const Eigen::VectorXd& t) const {
  Eigen::VectorXd s = Eigen::VectorXd::Constant(t.size(), NAN);
  if (cov_.size() == 0) return s;
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const Eigen::RowVectorXd b = impulse_basis(t(i));
    s(i) = std::sqrt(std::max(0.0, (b * cov_ * b.transpose())(0, 0)));
  }
  return s;
}

Eigen::VectorXcd FsfModel::frequency_response_std(const Eigen::VectorXd& w) const {
  Eigen::VectorXcd s = Eigen::VectorXcd::Constant(w.size(), cd(NAN, NAN));
  if (cov_.size() == 0) return s;
  for (Eigen::Index i = 0; i < w.size(); ++i) {
    // G = theta_0 H_0 + sum_k (Re theta_k (H_k + H_-k) + Im theta_k j (H_k - H_-k)): linear in theta.
    Eigen::RowVectorXd re(n_), im(n_);
    const cd h0 = filter_response(0, w(i));
    re(0) = h0.real();
    im(0) = h0.imag();
    for (int k = 1; k <= m(); ++k) {
      const cd hp = filter_response(k, w(i)), hm = filter_response(-k, w(i));
      const cd a = hp + hm, b = cd(0, 1) * (hp - hm);
      re(2 * k - 1) = a.real();
      im(2 * k - 1) = a.imag();
      re(2 * k) = b.real();
      im(2 * k) = b.imag();
    }
    s(i) = cd(std::sqrt(std::max(0.0, (re * cov_ * re.transpose())(0, 0))),
              std::sqrt(std::max(0.0, (im * cov_ * im.transpose())(0, 0))));
  }
  return s;
}

Eigen::VectorXd FsfModel::discrete_impulse_response() const {
  Eigen::VectorXd g(N_);
  for (int i = 0; i < N_; ++i) {
    double v = theta_(0);
    for (int k = 1; k <= m(); ++k) {
      const double x = 2.0 * std::numbers::pi * k * i / N_;
      v += 2.0 * (theta_(2 * k - 1) * std::cos(x) - theta_(2 * k) * std::sin(x));
    }
    g(i) = v / N_;
  }
  return g;
}

Eigen::VectorXd FsfModel::simulate(const Eigen::VectorXd& u) const {
  const Eigen::VectorXd g = discrete_impulse_response();
  Eigen::VectorXd y = Eigen::VectorXd::Zero(u.size());
  for (Eigen::Index i = 0; i < u.size(); ++i)
    for (int l = 0; l < N_ && l <= i; ++l) y(i) += g(l) * u(i - l);
  return y;
}

}  // namespace ctid
