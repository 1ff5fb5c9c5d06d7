// Johansson (1986) RJ 7-23: filter bank for z = 1/(1 + p tau) and the exact transform
// theta_tau <-> (a, b). See include/ctid/signal/svf.hpp.
#include "ctid/signal/svf.hpp"

#include <cmath>

#include "ctid/core/check.hpp"
#include "ctid/model/state_space.hpp"
#include "ctid/simulate/lsim.hpp"

namespace ctid {

namespace {
double binom(int n, int k) {
  if (k < 0 || k > n) return 0.0;
  double r = 1.0;
  for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
  return r;
}
void check_n_tau(int n, double tau, const char* what) {
  CTID_REQUIRE(n >= 1, "{}: the model order must be >= 1 (got {})", what, n);
  CTID_REQUIRE(std::isfinite(tau) && tau > 0, "{}: the filter time constant tau must be > 0 (got {})", what, tau);
}
}  // namespace

Eigen::MatrixXd svf_m_tau(int n, double tau) {
  check_n_tau(n, tau, "svf_m_tau");
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n, n);
  for (int i = 1; i <= n; ++i)
    for (int j = 1; j <= i; ++j) M(i - 1, j - 1) = (((i - j) % 2) ? -1.0 : 1.0) * binom(n - j, i - j) * std::pow(tau, j);
  return M;
}

Eigen::MatrixXd svf_m_tau_inverse(int n, double tau) {
  check_n_tau(n, tau, "svf_m_tau_inverse");
  Eigen::MatrixXd Mi = Eigen::MatrixXd::Zero(n, n);
  for (int k = 1; k <= n; ++k)
    for (int i = 1; i <= k; ++i) Mi(k - 1, i - 1) = binom(n - i, k - i) * std::pow(tau, -k);
  return Mi;
}

Eigen::VectorXd svf_g_tau(int n) {
  CTID_REQUIRE(n >= 1, "svf_g_tau: the model order must be >= 1 (got {})", n);
  Eigen::VectorXd g(n);
  for (int i = 1; i <= n; ++i) g(i - 1) = ((i + 1) % 2 ? -1.0 : 1.0) * binom(n, i);
  return g;
}

Eigen::VectorXd theta_tau_from_ab(const Eigen::VectorXd& a, const Eigen::VectorXd& b, double tau) {
  const int n = static_cast<int>(a.size());
  CTID_REQUIRE(b.size() == n, "theta_tau_from_ab: a has {} and b has {} coefficients (both need n)", a.size(), b.size());
  const Eigen::MatrixXd M = svf_m_tau(n, tau);
  Eigen::VectorXd th(2 * n);
  th.head(n) = M * (-a) + svf_g_tau(n);
  th.tail(n) = M * b;
  return th;
}

void ab_from_theta_tau(const Eigen::VectorXd& th, double tau, Eigen::VectorXd& a, Eigen::VectorXd& b) {
  CTID_REQUIRE(th.size() >= 2 && th.size() % 2 == 0, "ab_from_theta_tau: theta_tau needs 2n entries (got {})", th.size());
  const int n = static_cast<int>(th.size() / 2);
  const Eigen::MatrixXd Mi = svf_m_tau_inverse(n, tau);
  a = -(Mi * (th.head(n) - svf_g_tau(n)));
  b = Mi * th.tail(n);
}

// ---------------------------------------------------------------------------------------
SvfFilterBank::SvfFilterBank(int n, double tau, std::vector<Intersample> is, const std::optional<TransferFunction>& F)
    : n_(n), tau_(tau), is_(std::move(is)) {
  check_n_tau(n, tau, "SvfFilterBank");
  CTID_REQUIRE(!is_.empty(), "SvfFilterBank: at least one signal is needed");
  const std::size_t S = is_.size();
  chain_out_.assign(S * n_, 0.0);
  filt_out_.assign(S, 0.0);
  coef_.e.assign(n_, 0.0);  // sized once: step() never allocates
  coef_.g0.assign(n_, 0.0);
  coef_.g1.assign(n_, 0.0);
  if (F) {
    CTID_REQUIRE(F->is_stable(), "SvfFilterBank: the extra data filter must be stable (poles of {})", F->to_string());
    CTID_REQUIRE(F->io_delay() == 0.0, "SvfFilterBank: the extra data filter must have no delay");
    generic_ = true;
    const StateSpace fs = F->to_state_space();
    nf_ = fs.nx();
    const int nb = nf_ + n_;
    Ab_ = Eigen::MatrixXd::Zero(nb, nb);
    Bb_ = Eigen::MatrixXd::Zero(nb, 1);
    Ab_.topLeftCorner(nf_, nf_) = fs.A();
    Bb_.topRows(nf_) = fs.B();
    // Chain driven by w = C_F x_F + D_F s.
    Ab_.block(nf_, 0, 1, nf_) = fs.C() / tau;
    Bb_(nf_, 0) = fs.D()(0, 0) / tau;
    for (int k = 0; k < n_; ++k) {
      Ab_(nf_ + k, nf_ + k) = -1.0 / tau;
      if (k > 0) Ab_(nf_ + k, nf_ + k - 1) = 1.0 / tau;
    }
    Cf_ = fs.C();
    Df_ = fs.D()(0, 0);
    xs_ = Eigen::MatrixXd::Zero(nb, static_cast<Eigen::Index>(S));
    tmp_ = Eigen::VectorXd::Zero(nb);
  }
}

void SvfFilterBank::reset() {
  std::fill(chain_out_.begin(), chain_out_.end(), 0.0);
  std::fill(filt_out_.begin(), filt_out_.end(), 0.0);
  if (generic_) xs_.setZero();
}

void SvfFilterBank::set_current(const double* v) {
  for (std::size_t i = 0; i < is_.size(); ++i) {
    if (generic_) filt_out_[i] = (Cf_.row(0).dot(xs_.col(i).head(nf_))) + Df_ * v[i];
    else filt_out_[i] = v[i];
  }
}

void SvfFilterBank::update_coefficients(double h) {
  h_ = h;
  if (generic_) {
    const Discretization d = discretize(Ab_, Bb_, h);
    Phi_ = d.Phi;
    G0_ = d.Gamma0.col(0);
    G1_ = d.Gamma1.col(0);
    return;
  }
  coef_.compute(n_, h, tau_);
}

void SvfChainCoefficients::compute(int n, double h, double tau) {
  e.resize(n);
  g0.resize(n);
  g1.resize(n);
  const double x = h / tau;
  // e_j = e^{-x} x^j / j!
  double ej = std::exp(-x);
  for (int j = 0; j < n; ++j) {
    e[j] = ej;
    ej *= x / (j + 1);
  }
  for (int k = 1; k <= n; ++k) {
    if (x <= 30.0) {
      // Series from j = k: no cancellation for small x.
      double term = std::exp(-x + k * std::log(x) - std::lgamma(k + 1.0));
      double p = 0, q = 0;
      for (int j = k; j < k + 400; ++j) {
        p += term;
        q += term * double(j + 1 - k) / double(j + 1);
        if (term < 1e-18 * p) break;
        term *= x / (j + 1);
      }
      g0[k - 1] = p;
      g1[k - 1] = q;
    } else {
      // Complements: P(k, x) = 1 - e^{-x} sum_{j<k} x^j/j!.
      auto P = [&](int kk) {
        double s = 0, t = std::exp(-x);
        for (int j = 0; j < kk; ++j) { s += t; t *= x / (j + 1); }
        return 1.0 - s;
      };
      g0[k - 1] = P(k);
      g1[k - 1] = P(k) - (double(k) / x) * P(k + 1);
    }
  }
}

void SvfFilterBank::step(double h, const double* prev, const double* next) {
  if (h != h_) update_coefficients(h);
  const std::size_t S = is_.size();
  for (std::size_t i = 0; i < S; ++i) {
    const double s0 = prev[i];
    const double ds = (is_[i] == Intersample::Zoh) ? 0.0 : next[i] - prev[i];
    if (generic_) {
      tmp_.noalias() = Phi_ * xs_.col(static_cast<Eigen::Index>(i));
      tmp_ += G0_ * s0 + G1_ * ds;
      xs_.col(static_cast<Eigen::Index>(i)) = tmp_;
      for (int k = 0; k < n_; ++k) chain_out_[i * n_ + k] = tmp_(nf_ + k);
      filt_out_[i] = Cf_.row(0).dot(tmp_.head(nf_)) + Df_ * next[i];
      continue;
    }
    double* x = &chain_out_[i * n_];
    // x_new[k] = sum_{m <= k} e_{k-m} x[m] + g0_k s0 + g1_k ds (lower-triangular Toeplitz):
    // updating from the last state down uses only old values.
    for (int k = n_ - 1; k >= 0; --k) {
      double acc = coef_.g0[k] * s0 + coef_.g1[k] * ds;
      for (int m = 0; m <= k; ++m) acc += coef_.e[k - m] * x[m];
      x[k] = acc;
    }
    filt_out_[i] = next[i];
  }
}

SvfStream::SvfStream(int n, double tau, Intersample input, double interval, const char* who)
    : bank_(n, tau, {Intersample::Foh, input}), interval_(interval), who_(who) {
  CTID_REQUIRE(std::isfinite(interval) && interval >= 0, "{}: the regression interval must be >= 0 (got {})", who, interval);
}

void SvfStream::reset() {
  bank_.reset();
  started_ = false;
}

bool SvfStream::push(double t, double u, double y) {
  CTID_REQUIRE(std::isfinite(t) && std::isfinite(u) && std::isfinite(y), "{}: non-finite sample (t = {}, u = {}, y = {})",
               who_, t, u, y);
  const double next[2] = {y, u};
  if (!started_) {
    bank_.set_current(next);
    started_ = true;
    t_ = t_reg_ = t;
    y_prev_ = y;
    u_prev_ = u;
    return false;
  }
  CTID_REQUIRE(t > t_, "{}: sample times must increase (t = {} after {})", who_, t, t_);
  const double prev[2] = {y_prev_, u_prev_};
  bank_.step(t - t_, prev, next);
  t_ = t;
  y_prev_ = y;
  u_prev_ = u;
  if (interval_ > 0 && t - t_reg_ < interval_ * (1.0 - 1e-9)) return false;
  reg_step_ = t - t_reg_;
  t_reg_ = t;
  return true;
}

Eigen::MatrixXd svf_filter(const IdData& data, int n, double tau, int input, int output,
                           const std::optional<TransferFunction>& F) {
  CTID_REQUIRE(output < data.ny(), "svf_filter: output index {} out of range ({} outputs)", output, data.ny());
  CTID_REQUIRE(output >= 0 || (input >= 0 && input < data.nu()), "svf_filter: input index {} out of range ({} inputs)",
               input, data.nu());
  const Intersample is = output >= 0 ? Intersample::Foh : data.intersample(input);
  SvfFilterBank bank(n, tau, {is}, F);
  const int N = data.size();
  Eigen::MatrixXd out(N, n);
  auto sample = [&](int k) { return output >= 0 ? data.y()(k, output) : data.u()(k, input); };
  double prev = sample(0);
  bank.set_current(&prev);
  for (int k = 0; k < N; ++k) {
    if (k > 0) {
      const double next = sample(k);
      bank.step(data.is_uniform() ? data.ts() : data.time(k) - data.time(k - 1), &prev, &next);
      prev = next;
    }
    for (int j = 0; j < n; ++j) out(k, j) = bank.chain(0)[j];
  }
  return out;
}

}  // namespace ctid
