// Johansson (1986) in the frequency domain: the least-squares criterion on frequency-response data (RJ 45, with the
// data filter of RJ 42) and the information matrix of an input spectrum (RJ 47-50: P^-1 = int Phi(-i w) Phi^T(i w) dw,
// Phi_tau = Gamma_tau U). Johansson 1986, the LS criterion (RJ 44-50). See include/ctid/estimate/svf/lssvf.hpp.
#include <chrono>
#include <cmath>
#include <complex>
#include <limits>

#include "ctid/core/check.hpp"
#include "ctid/estimate/svf/lssvf.hpp"
#include "estimate/svf/svf_common.hpp"
#include "estimate/transfer_function/tf_common.hpp"
#include "internal/least_squares.hpp"

namespace ctid {

using svf_detail::SvfLayout;
using cd = std::complex<double>;

namespace {
// [z G, .., z^n G, z, .., z^n] at w with z = 1 / (1 + i w tau): Gamma_tau of RJ 50 for G the model's response, the
// frequency-domain regressor of RJ 45 for G a measured one.
Eigen::VectorXcd filtered_regressor(cd G, double w, double tau, int n) {
  const cd z = 1.0 / cd(1.0, w * tau);
  Eigen::VectorXcd gamma(2 * n);
  cd zk = 1.0;
  for (int k = 0; k < n; ++k) {
    zk *= z;
    gamma(k) = zk * G;
    gamma(n + k) = zk;
  }
  return gamma;
}
}  // namespace

Eigen::VectorXcd svf_gamma(const TransferFunction& g0, double tau, double w) {
  const int n = g0.order();
  CTID_REQUIRE(n >= 1, "svf_gamma: the model must have order >= 1 (got a static gain)");
  CTID_REQUIRE(std::isfinite(tau) && tau > 0, "svf_gamma: tau must be > 0 (got {} s)", tau);
  CTID_REQUIRE(std::isfinite(w) && w >= 0, "svf_gamma: the frequency must be >= 0 (got {} rad/s)", w);
  return filtered_regressor(g0.frequency_response(Eigen::VectorXd::Constant(1, w))(0), w, tau, n);
}

SvfInformation svf_information(const TransferFunction& g0, double tau, const Eigen::VectorXd& w,
                               const Eigen::VectorXd& power) {
  CTID_REQUIRE(w.size() >= 1 && w.size() == power.size(),
               "svf_information: {} frequencies and {} powers (need the same number, at least one)", w.size(),
               power.size());
  CTID_REQUIRE(g0.is_stable(), "svf_information: the model is not stable, so an input has no stationary response "
               "(RJ 55's first condition); poles: {}", g0.to_string(6));
  const int n = g0.order();
  SvfInformation info;
  info.matrix = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  for (Eigen::Index k = 0; k < w.size(); ++k) {
    CTID_REQUIRE(k == 0 || w(k) > w(k - 1), "svf_information: frequencies must increase (w[{}] = {} after {} rad/s)",
                 k, w(k), w(k - 1));
    CTID_REQUIRE(std::isfinite(power(k)) && power(k) >= 0, "svf_information: power[{}] = {} (must be >= 0)", k,
                 power(k));
    const Eigen::VectorXcd g = svf_gamma(g0, tau, w(k));
    info.matrix += power(k) * (g * g.adjoint()).real();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(info.matrix);
  info.eigenvalues = es.eigenvalues();
  info.directions = es.eigenvectors();
  const double top = info.eigenvalues.maxCoeff();
  for (Eigen::Index i = 0; i < info.eigenvalues.size(); ++i) info.rank += info.eigenvalues(i) > 1e-10 * top ? 1 : 0;
  info.condition = info.rank == 2 * n && top > 0 ? top / info.eigenvalues(0) : std::numeric_limits<double>::infinity();
  return info;
}

namespace {

// Least squares of RJ 45 at one tau: rows Re and Im of the filtered equation error through the layout's map.
internal::LinearSolution solve_frequency(const FrequencyData& d, const SvfLayout& L, const Eigen::VectorXd& weight) {
  const svf_detail::RowMap map(L);
  const int n = L.n;
  internal::StreamingLeastSquares ls(map.p);
  std::vector<double> row(map.p);
  const Eigen::VectorXcd& G = d.response();
  for (int k = 0; k < d.size(); ++k) {
    const Eigen::VectorXcd phi = filtered_regressor(G(k), d.w()(k), L.tau, n);
    const Eigen::VectorXd re = phi.real(), im = phi.imag();  // [z^i G; z^i]: map.apply reads the halves
    double lhs = map.apply(re.data(), re.data() + n, G(k).real(), row.data());
    ls.add(row.data(), lhs, weight(k));
    lhs = map.apply(im.data(), im.data() + n, G(k).imag(), row.data());
    ls.add(row.data(), lhs, weight(k));
  }
  return ls.solve();
}

// Weighted relative misfit of a model's response: sum w |G - Gm|^2 / sum w |G|^2.
double misfit(const FrequencyData& d, const TransferFunction& m, const Eigen::VectorXd& weight) {
  const Eigen::VectorXcd Gm = m.frequency_response(d.w());
  double num = 0, den = 0;
  for (int k = 0; k < d.size(); ++k) {
    num += weight(k) * std::norm(d.response()(k) - Gm(k));
    den += weight(k) * std::norm(d.response()(k));
  }
  return den > 0 ? num / den : std::numeric_limits<double>::infinity();
}

}  // namespace

Result<TransferFunction> lssvf(const FrequencyData& data, const TfOrders& orders, const LssvfOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  orders.validate();
  options.validate();
  CTID_REQUIRE(data.outputs() == 1 && data.inputs() == 1,
               "lssvf: frequency data with {} outputs and {} inputs; the frequency-domain LSSVF takes one of each",
               data.outputs(), data.inputs());
  CTID_REQUIRE_OPTION(orders.nk == 0, "lssvf: nk must be 0 with frequency data (got {})", orders.nk);
  CTID_REQUIRE_OPTION(options.alpha == 0.0 && options.transient_time == 0.0 && options.weights == SvfWeights::Riemann,
                      "lssvf: alpha ({} 1/s), transient_time ({} s) and trapezoidal weights weight samples in time; "
                      "they have no meaning for frequency data",
                      options.alpha, options.transient_time);
  const int K = data.size();
  Eigen::VectorXd weight = Eigen::VectorXd::Ones(K);
  if (!data.variance().empty())
    for (int k = 0; k < K; ++k) weight(k) = 1.0 / data.variance()[static_cast<std::size_t>(k)](0, 0);
  if (options.data_filter) {
    const Eigen::VectorXcd F = options.data_filter->frequency_response(data.w());
    for (int k = 0; k < K; ++k) weight(k) *= std::norm(F(k));
  }
  const SvfLayout probe = svf_detail::make_layout(orders, 1.0, options.fixed, "lssvf");
  CTID_REQUIRE(2 * K > static_cast<int>(probe.free.size()),
               "lssvf: {} frequencies give {} real equations for {} free parameters", K, 2 * K, probe.free.size());

  double tau = options.tau;
  Eigen::VectorXd grid, fits;
  if (tau == 0.0) {
    const double lo = 0.1 / data.w().maxCoeff(), hi = std::max(4 * lo, 10.0 / data.w().minCoeff());
    const int G = options.tau_grid_size;
    grid.resize(G);
    fits.resize(G);
    double best = std::numeric_limits<double>::infinity();
    tau = std::sqrt(lo * hi);
    for (int i = 0; i < G; ++i) {
      grid(i) = lo * std::pow(hi / lo, double(i) / (G - 1));
      const SvfLayout L = svf_detail::make_layout(orders, grid(i), options.fixed, "lssvf");
      const internal::LinearSolution s = solve_frequency(data, L, weight);
      fits(i) = -std::numeric_limits<double>::infinity();
      if (s.rank_deficient || !s.theta.allFinite()) continue;
      const double m = misfit(data, svf_detail::tf_from_theta(L, svf_detail::full_theta(L, s.theta), 0.0), weight);
      fits(i) = 100.0 * (1.0 - std::sqrt(m));
      if (m < best) {
        best = m;
        tau = grid(i);
      }
    }
  }
  const SvfLayout L = svf_detail::make_layout(orders, tau, options.fixed, "lssvf");
  const internal::LinearSolution sol = solve_frequency(data, L, weight);
  Result<TransferFunction> r = svf_detail::make_model_result(orders, L, sol, 0.0, 0.0);
  if (grid.size() > 0) {
    r.diagnostics.set(diagnostic::tau_grid, grid);
    r.diagnostics.set(diagnostic::tau_grid_fit_percent, fits);
  }
  r.fit = tf_detail::frequency_fit(r.model, data.w(), data.response(), static_cast<int>(L.free.size()));
  r.summary.iterations = 1;
  tf_detail::check_cancellation(r);
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

}  // namespace ctid
