// Recursive LSSVF (Johansson 1986, RJ 52-53, sampled RJ 59-60, continuous-time RJ 56-58) and the
// single-coefficient tracker (RJ 74-79; RJ 56-61, RJ 74-79). See include/ctid/estimate/svf/rls_svf.hpp.
#include "ctid/estimate/svf/rls_svf.hpp"

#include <chrono>
#include <cmath>
#include <limits>

#include "ctid/core/check.hpp"
#include "ctid/estimate/svf/lssvf.hpp"
#include "ctid/validate/metrics.hpp"
#include "estimate/svf/svf_common.hpp"
#include "estimate/transfer_function/tf_common.hpp"

namespace ctid {

template <>
const OptionTable<RlsSvfOptions>& option_table<RlsSvfOptions>() {
  using O = RlsSvfOptions;
  static const OptionTable<O> t =
      OptionTable<O>("rls_svf")
          .real("tau", &O::tau, "s", above(0), "filter time constant of z = 1/(1 + p tau)")
          .real("p0", &O::p0, "", above(0), "initial covariance P(0) = p0 I")
          .real("forgetting", &O::forgetting, "", above_at_most(0, 1), "forgetting factor lambda per regression update")
          .real("alpha", &O::alpha, "1/s", at_least(0), "exponential weighting rate: lambda times e^{-2 alpha dt}")
          .real("regression_interval", &O::regression_interval, "s", at_least(0),
                "time between regression updates; 0: every sample")
          .choice("recursion", &O::recursion, {{"sampled", RlsRecursion::Sampled}, {"continuous", RlsRecursion::Continuous}},
                  "sampled sum (RJ 59-60) or continuous-time recursion integrated exactly between updates (RJ 56-57)")
          .choice("input_intersample", &O::input_intersample,
                  {{"zoh", Intersample::Zoh}, {"foh", Intersample::Foh}, {"bl", Intersample::BandLimited}},
                  "intersample behaviour of the input in the filters (a fit to a record takes the record's)")
          .named_reals("fixed", &O::fixed, "known coefficients held fixed, by parameter name (fixed.a2=4)")
          .reals("theta0", &O::theta0, "", OptionRange{},
                 "initial parameters [a1..an, b0..]; none: 0");
  return t;
}

void RlsSvfOptions::validate() const {
  option_table<RlsSvfOptions>().check(*this);
  CTID_REQUIRE_OPTION(recursion == RlsRecursion::Sampled || forgetting == 1.0,
                      "rls_svf: forgetting is a factor per sampled update; with recursion=continuous weight the past "
                      "by alpha (1/s) instead (got forgetting {})",
                      forgetting);
}

RlsSvf::RlsSvf(const TfOrders& orders, const RlsSvfOptions& options)
    : orders_((orders.validate(), orders)),
      opt_((options.validate(), options)),
      stream_(orders.nf, options.tau, options.input_intersample, options.regression_interval, "rls_svf") {
  CTID_REQUIRE_OPTION(orders_.nk == 0, "rls_svf: nk must be 0 for the recursive estimator (got {}); delay the input yourself",
                      orders_.nk);
  const svf_detail::SvfLayout L = svf_detail::make_layout(orders_, opt_.tau, opt_.fixed, "rls_svf");
  M_ = L.M;
  g_ = L.g;
  fixed_ = L.fixed;
  theta_fixed_ = L.theta_fixed;
  free_ = L.free;
  const int n = orders_.nf;
  theta_tau_mode_ = opt_.fixed.empty() && orders_.nb == n;
  const int p = theta_tau_mode_ ? 2 * n : static_cast<int>(free_.size());
  if (opt_.theta0.size() > 0)
    CTID_REQUIRE_OPTION(opt_.theta0.size() == orders_.n_parameters(), "rls_svf: theta0 needs {} values [a1.., b0..] (got {})",
                        orders_.n_parameters(), opt_.theta0.size());
  theta_.resize(p);
  P_.resize(p, p);
  Pphi_.resize(p);
  row_.resize(p);
  row_prev_.resize(p);
  scratch_.resize(p);
  psi_.resize(2 * n);
  reset();
}

void RlsSvf::reset() {
  const int n = orders_.nf;
  stream_.reset();
  P_.setIdentity();
  P_ *= opt_.p0;
  theta_.setZero();
  if (opt_.theta0.size() > 0) {
    Eigen::VectorXd th = theta_fixed_;
    svf_detail::SvfLayout L;
    L.n = n;
    L.nb = orders_.nb;
    for (int i = 0; i < orders_.n_parameters(); ++i) {
      const int t = L.theta_index(i);
      if (!fixed_[t]) th(t) = (i < n ? -1.0 : 1.0) * opt_.theta0(i);
    }
    if (theta_tau_mode_) {
      theta_.head(n) = M_ * th.head(n) + g_;
      theta_.tail(n) = M_ * th.tail(n);
    } else {
      for (std::size_t j = 0; j < free_.size(); ++j) theta_(static_cast<Eigen::Index>(j)) = th(free_[j]);
    }
  }
  n_updates_ = 0;
  have_prev_ = false;
}

void RlsSvf::start_record() {
  stream_.reset();
  have_prev_ = false;  // the continuous criterion's integral does not bridge two records
}

// One rank-one step of the weighted information update P^{-1} <- P^{-1} + w phi phi^T, P^{-1} theta <- P^{-1} theta +
// w phi target (Sherman-Morrison): K = w P phi / (1 + w phi^T P phi).
void RlsSvf::weighted_update(const Eigen::VectorXd& phi, double target, double w) {
  const int p = static_cast<int>(theta_.size());
  double den = 1.0, err = target;
  for (int i = 0; i < p; ++i) {
    double s = 0;
    for (int j = 0; j < p; ++j) s += P_(i, j) * phi(j);
    Pphi_(i) = s;
    den += w * phi(i) * s;
    err -= theta_(i) * phi(i);
  }
  for (int i = 0; i < p; ++i) theta_(i) += w * Pphi_(i) / den * err;
  for (int j = 0; j < p; ++j)
    for (int i = 0; i < p; ++i) P_(i, j) -= w * Pphi_(i) * Pphi_(j) / den;
}

void RlsSvf::update(double t, double u, double y) {
  if (!stream_.push(t, u, y)) return;
  const double dt = stream_.regression_step();
  const int n = orders_.nf;
  const int p = static_cast<int>(theta_.size());
  const double* phy = stream_.bank().chain(0);
  const double* phu = stream_.bank().chain(1);
  double target;
  if (theta_tau_mode_) {
    for (int i = 0; i < n; ++i) {
      row_(i) = phy[i];
      row_(n + i) = phu[i];
    }
    target = stream_.bank().filtered(0);
  } else {
    svf_detail::physical_regressor(M_, phy, phu, psi_.data());
    target = stream_.bank().filtered(0);
    for (int i = 0; i < n; ++i) target -= g_(i) * phy[i];
    for (int k = 0; k < 2 * n; ++k)
      if (fixed_[k]) target -= theta_fixed_(k) * psi_(k);
    for (int j = 0; j < p; ++j) row_(j) = psi_(free_[j]);
  }
  if (opt_.recursion == RlsRecursion::Continuous) {
    if (have_prev_) {
      continuous_step(dt, target);
      ++n_updates_;
    }
    row_prev_ = row_;
    target_prev_ = target;
    have_prev_ = true;
    return;
  }
  const double lambda = opt_.forgetting * (opt_.alpha > 0 ? std::exp(-2.0 * opt_.alpha * dt) : 1.0);
  // RLS (RJ 59-60) with forgetting: K = P phi / (lambda + phi' P phi), P = (P - K phi' P) / lambda.
  if (lambda != 1.0) P_ *= 1.0 / lambda;
  weighted_update(row_, target, 1.0);
  ++n_updates_;
}

// RJ 56-57 over one step h from the last regression instant, exact for a regressor and target linear in between (the
// header's formula): P <- e^{2 alpha h} P, then one weighted update along each eigenvector e of W, with regressor
// e_0 phi_k + e_1 phi_k+1 and target e_0 y_k + e_1 y_k+1.
void RlsSvf::continuous_step(double h, double target) {
  // W / h = int_0^1 e^{-x u} [u^2, u (1 - u), (1 - u)^2] du with x = 2 alpha h and u the fraction of the step before its
  // end (the older sample weighs u, the newer 1 - u): a power series below x = 1 (terms to 1e-19), closed form above.
  const double x = 2.0 * opt_.alpha * h;
  double w00 = 0, w01 = 0, w11 = 0;
  if (x < 1.0) {
    double term = 1.0;  // (-x)^m / m!
    for (int m = 0; m < 22; ++m) {
      const double k1 = 1.0 / (m + 1), k2 = 1.0 / (m + 2), k3 = 1.0 / (m + 3);
      w00 += term * k3;
      w01 += term * (k2 - k3);
      w11 += term * (k1 - 2 * k2 + k3);
      term *= -x / (m + 1);
    }
  } else {
    const double E = std::exp(-x), x2 = x * x, x3 = x2 * x;
    w00 = 2 * (1 - E) / x3 - 2 * E / x2 - E / x;
    w01 = (1 + E) / x2 - 2 * (1 - E) / x3;
    w11 = 1 / x - 2 / x2 + 2 * (1 - E) / x3;
  }
  if (x > 0) P_ *= std::exp(x);  // the information decays by e^{-2 alpha h} over the step
  // The eigenvectors (c, s) and (-s, c) of [[w00, w01], [w01, w11]], eigenvalues m +- r (both > 0).
  const double m = 0.5 * (w00 + w11), r = std::hypot(0.5 * (w00 - w11), w01);
  const double angle = 0.5 * std::atan2(2 * w01, w00 - w11), c = std::cos(angle), s = std::sin(angle);
  scratch_ = c * row_prev_ + s * row_;
  weighted_update(scratch_, c * target_prev_ + s * target, h * (m + r));
  scratch_ = -s * row_prev_ + c * row_;
  weighted_update(scratch_, -s * target_prev_ + c * target, h * (m - r));
}

Eigen::VectorXd RlsSvf::theta_tau() const {
  const int n = orders_.nf;
  if (theta_tau_mode_) return theta_;
  Eigen::VectorXd th = theta_fixed_;
  for (std::size_t j = 0; j < free_.size(); ++j) th(free_[j]) = theta_(static_cast<Eigen::Index>(j));
  Eigen::VectorXd tt(2 * n);
  tt.head(n) = M_ * th.head(n) + g_;
  tt.tail(n) = M_ * th.tail(n);
  return tt;
}

Eigen::VectorXd RlsSvf::parameters() const {
  const int n = orders_.nf, nb = orders_.nb;
  Eigen::VectorXd a, b;
  ab_from_theta_tau(theta_tau(), opt_.tau, a, b);
  Eigen::VectorXd out(n + nb);
  out.head(n) = a;
  out.tail(nb) = b.tail(nb);
  return out;
}

TransferFunction RlsSvf::model() const {
  const Eigen::VectorXd p = parameters();
  const int n = orders_.nf, nb = orders_.nb;
  Eigen::VectorXd den(n + 1);
  den(0) = 1.0;
  den.tail(n) = p.head(n);
  return TransferFunction(Eigen::VectorXd(p.tail(nb)), den);
}

// ---------------------------------------------------------------------------------------
void CoefficientTrackerOptions::validate() const {
  CTID_REQUIRE_OPTION(std::isfinite(tau) && tau > 0, "coefficient_tracker: tau must be > 0 (got {})", tau);
  CTID_REQUIRE_OPTION(std::isfinite(threshold) && threshold > 0, "coefficient_tracker: threshold must be > 0 (got {})",
                      threshold);
  CTID_REQUIRE_OPTION(std::isfinite(regression_interval) && regression_interval >= 0,
                      "coefficient_tracker: regression_interval must be >= 0 (got {})", regression_interval);
}

CoefficientTracker::CoefficientTracker(const TransferFunction& known, const std::string& unknown,
                                       const CoefficientTrackerOptions& o)
    : stream_((o.validate(), std::max(1, known.order())), o.tau, o.input_intersample, o.regression_interval,
              "coefficient_tracker"),
      threshold_(o.threshold) {
  n_ = known.order();
  CTID_REQUIRE(n_ >= 1, "coefficient_tracker: the known model must have order >= 1");
  CTID_REQUIRE(known.num().degree() < n_ || known.num().is_zero(),
               "coefficient_tracker: the known model must be strictly proper (numerator degree {}, order {})",
               known.num().degree(), n_);
  const int idx = svf_detail::parameter_index(TfOrders{n_, n_, 0}, unknown, "coefficient_tracker");
  M_ = svf_m_tau(n_, o.tau);
  g_ = svf_g_tau(n_);
  theta_.resize(2 * n_);
  for (int i = 0; i < n_; ++i) {
    theta_(i) = -known.den().coefficients()(i + 1);
    theta_(n_ + i) = known.num().coefficient_of_power(n_ - 1 - i);
  }
  j_ = idx;  // parameter index equals theta index when nb = n
  sign_ = idx < n_ ? -1.0 : 1.0;
  estimate_ = sign_ * theta_(j_);
  psi_.resize(2 * n_);
}

void CoefficientTracker::update(double t, double u, double y) {
  updated_ = false;
  if (!stream_.push(t, u, y)) return;
  const double* phy = stream_.bank().chain(0);
  const double* phu = stream_.bank().chain(1);
  svf_detail::physical_regressor(M_, phy, phu, psi_.data());
  double lhs = stream_.bank().filtered(0);
  for (int i = 0; i < n_; ++i) lhs -= g_(i) * phy[i];
  for (int k = 0; k < 2 * n_; ++k)
    if (k != j_) lhs -= theta_(k) * psi_(k);
  last_psi_ = psi_(j_);
  if (std::abs(last_psi_) >= threshold_) {
    theta_(j_) = lhs / last_psi_;
    estimate_ = sign_ * theta_(j_);
    updated_ = true;
  }
}

namespace {
// rls_svf of one record or of several, without copying them.
Result<TransferFunction> rls_svf_records(const internal::RecordRefs& ds, const TfOrders& orders, const RlsSvfOptions& options) {
  CTID_REQUIRE(!ds.empty(), "rls_svf: no records");
  for (std::size_t e = 0; e < ds.size(); ++e) {
    const std::string who = ds.size() > 1 ? "rls_svf (record " + std::to_string(e + 1) + ")" : "rls_svf";
    require_io_data(ds[e], who.c_str());
    CTID_REQUIRE(ds[e].intersample(0) == ds[0].intersample(0), "{}: input intersample {}; record 1's is {}", who,
                 to_string(ds[e].intersample(0)), to_string(ds[0].intersample(0)));
  }
  CTID_REQUIRE(orders.nk == 0, "rls_svf: nk must be 0 (got {}; delay the input column instead)", orders.nk);
  const auto start = std::chrono::steady_clock::now();
  RlsSvfOptions o = options;
  o.input_intersample = ds[0].intersample(0);
  RlsSvf rls(orders, o);
  for (std::size_t e = 0; e < ds.size(); ++e) {
    const IdData& d = ds[e];
    if (e > 0) rls.start_record();
    for (int k = 0; k < d.size(); ++k) rls.update(d.time(k), d.u()(k, 0), d.y()(k, 0));
  }
  Result<TransferFunction> r;
  r.model = rls.model();
  r.parameters.names = tf_parameter_names(orders);
  r.parameters.values = rls.parameters();
  r.parameters.std = Eigen::VectorXd::Constant(orders.n_parameters(), std::numeric_limits<double>::quiet_NaN());
  r.parameters.fixed.assign(orders.n_parameters(), false);
  for (int i = 0; i < orders.n_parameters(); ++i) r.parameters.fixed[i] = options.fixed.count(r.parameters.names[i]) > 0;
  r.diagnostics.set(diagnostic::tau, options.tau);
  if (ds.size() > 1) r.diagnostics.set(diagnostic::experiments, static_cast<double>(ds.size()));
  r.summary.iterations = static_cast<int>(rls.n_updates());
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // The simulation fit over all records (each from rest), as one concatenated output.
  const auto [y, yhat] = tf_detail::pooled_outputs(r.model, ds, 0.0);
  r.fit = fit_report_or_inf(y, yhat, orders.n_parameters() - static_cast<int>(options.fixed.size()));
  if (!r.model.is_stable()) r.diagnostics.warnings.push_back("the estimated model is unstable");
  return r;
}
}  // namespace

Result<TransferFunction> rls_svf(const IdData& d, const TfOrders& orders, const RlsSvfOptions& options) {
  return rls_svf_records(d, orders, options);
}

Result<TransferFunction> rls_svf(const std::vector<IdData>& ds, const TfOrders& orders, const RlsSvfOptions& options) {
  return rls_svf_records(ds, orders, options);
}

}  // namespace ctid
