// Sanathanan-Koerner + output-error refinement on frequency data; see frequency.hpp.
#include "ctid/estimate/transfer_function/frequency.hpp"

#include <algorithm>
#include <chrono>
#include <vector>
#include <cmath>
#include <complex>

#include "ctid/core/check.hpp"
#include "ctid/estimate/svf/lssvf.hpp"
#include "estimate/transfer_function/tf_common.hpp"
#include "internal/least_squares.hpp"
#include "internal/levenberg_marquardt.hpp"

namespace ctid {

template <>
const OptionTable<FrequencyFitOptions>& option_table<FrequencyFitOptions>() {
  using O = FrequencyFitOptions;
  static const OptionTable<O> t =
      OptionTable<O>("tf_from_frequency")
          .integer("sk_iterations", &O::sk_iterations, "", at_least(1), "Sanathanan-Koerner iterations")
          .flag("refine", &O::refine, "output-error refinement after Sanathanan-Koerner")
          .integer("max_iterations", &O::max_iterations, "", at_least(1), "Levenberg-Marquardt iterations of the refinement")
          .real("tolerance", &O::tolerance, "", above(0), "relative cost decrease that stops the refinement")
          .flag("estimate_delay", &O::estimate_delay, "add an input delay (s) to the refinement (parameter delay)")
          .real("delay", &O::delay, "s", at_least(0), "fixed or initial input delay")
          .flag("require_stable", &O::require_stable, "keep the refinement among stable models");
  return t;
}

void FrequencyFitOptions::validate() const { option_table<FrequencyFitOptions>().check(*this); }

namespace {
using cd = std::complex<double>;

// Evaluate the scaled model at s' = j w / w0: parameters [a'(n), b'(nb)], delay T (unscaled).
struct ScaledModel {
  int n, nb;
  Eigen::VectorXd ws;  // scaled frequencies
  Eigen::VectorXd w;   // unscaled (for the delay)
  cd A(int k, const Eigen::VectorXd& p) const {
    const cd s(0, ws(k));
    cd v = 1.0;
    for (int i = 0; i < n; ++i) v = v * s + p(i);
    return v;
  }
  cd B(int k, const Eigen::VectorXd& p) const {
    const cd s(0, ws(k));
    cd v = 0.0;
    for (int j = 0; j < nb; ++j) v = v * s + p(n + j);
    return v;
  }
};

// The starts of the output-error refinement from Sanathanan-Koerner iterations on Gd (G with the given delay removed)
// for the scaled model sc; `sk_done` receives the number of SK iterations run.
std::vector<Eigen::VectorXd> sk_starts(const ScaledModel& sc, const Eigen::VectorXcd& Gd, int p,
                                       const FrequencyFitOptions& opt, int& sk_done) {
  const int n = sc.n, nb = sc.nb, K = static_cast<int>(Gd.size());
  // 1. Sanathanan-Koerner: B(jw) - Gd A(jw) = 0 weighted by 1/|A_prev|; real unknowns [a', b'].
  // Every SK iterate (denominator stabilised) is a candidate start for the refinement; the
  // iterations are run twice: with unit base weights, and with base weights |G| that favour
  // the points with the best signal-to-noise ratio (noisy high-frequency data can make SK
  // lock on a spurious resonance, and the output-error cost has local minima).
  auto oe_cost = [&](const Eigen::VectorXd& t) {
    double c = 0;
    for (int k = 0; k < K; ++k) c += std::norm(Gd(k) - sc.B(k, t) / sc.A(k, t));
    return c;
  };
  auto stabilise = [&](const Eigen::VectorXd& t) {
    Eigen::VectorXd den(n + 1);
    den(0) = 1.0;
    den.tail(n) = t.head(n);
    const Polynomial As = tf_detail::stabilized(TransferFunction(Polynomial{1.0}, Polynomial(den))).den();
    Eigen::VectorXd out = t;
    for (int i = 1; i <= n; ++i) out(i - 1) = As.coefficient_of_power(n - i);
    return out;
  };
  std::vector<std::pair<double, Eigen::VectorXd>> starts;  // (cost, stabilised SK iterate)
  Eigen::VectorXd th = Eigen::VectorXd::Zero(n + nb);
  sk_done = 0;
  auto run_sk = [&](const Eigen::VectorXd& base) {
    Eigen::VectorXd wgt = base;
    for (int it = 0; it < opt.sk_iterations; ++it) {
      Eigen::MatrixXd M(2 * K, n + nb);
      Eigen::VectorXd rhs(2 * K);
      for (int k = 0; k < K; ++k) {
        const cd s(0, sc.ws(k));
        // G A = G (s^n + sum a_i s^{n-i}): unknown terms G a_i s^{n-i} - b_j s^{nb-1-j} = -G s^n
        for (int i = 1; i <= n; ++i) {
          const cd c = Gd(k) * std::pow(s, n - i) * wgt(k);
          M(2 * k, i - 1) = c.real();
          M(2 * k + 1, i - 1) = c.imag();
        }
        for (int j = 0; j < nb; ++j) {
          const cd c = -std::pow(s, nb - 1 - j) * wgt(k);
          M(2 * k, n + j) = c.real();
          M(2 * k + 1, n + j) = c.imag();
        }
        const cd r = -Gd(k) * std::pow(s, n) * wgt(k);
        rhs(2 * k) = r.real();
        rhs(2 * k + 1) = r.imag();
      }
      const Eigen::VectorXd next = M.colPivHouseholderQr().solve(rhs);
      ++sk_done;
      if (!next.allFinite()) break;
      const Eigen::VectorXd cand = stabilise(next);
      starts.emplace_back(oe_cost(cand), cand);
      const double change = (next - th).norm() / std::max(next.norm(), 1e-300);
      th = next;
      for (int k = 0; k < K; ++k) wgt(k) = base(k) / std::max(std::abs(sc.A(k, th)), 1e-300);
      if (change < 1e-12) break;
    }
  };
  run_sk(Eigen::VectorXd::Ones(K));
  if (opt.refine) run_sk(Gd.cwiseAbs());

  // Candidate starts: the cheapest SK iterates and Levy's unweighted first iterate.
  std::vector<Eigen::VectorXd> x0s;
  auto add_start = [&](const Eigen::VectorXd& t) {
    Eigen::VectorXd x0(p);
    x0.head(n + nb) = t;
    if (opt.estimate_delay) x0(n + nb) = opt.delay;
    for (const auto& e : x0s)
      if ((e - x0).norm() <= 1e-9 * x0.norm()) return;
    x0s.push_back(x0);
  };
  if (!starts.empty()) {
    std::vector<std::pair<double, Eigen::VectorXd>> sorted = starts;
    std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    add_start(sorted.front().second);  // the cheapest first (the only one when refine = false)
    add_start(starts.front().second);  // Levy
    for (std::size_t i = 1; i < std::min<std::size_t>(4, sorted.size()); ++i) add_start(sorted[i].second);
  } else {
    add_start(th);
  }
  return x0s;
}
}  // namespace

Result<TransferFunction> tf_from_frequency(const FrequencyData& data, const TfOrders& orders, const FrequencyFitOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  orders.validate(/*allow_biproper=*/true);
  opt.validate();
  CTID_REQUIRE_OPTION(orders.nk == 0, "tf_from_frequency: nk must be 0 (use delay / estimate_delay), got {}", orders.nk);
  const int n = orders.nf, nb = orders.nb, p = n + nb + (opt.estimate_delay ? 1 : 0);
  const int K = data.size();
  CTID_REQUIRE(2 * K > p, "tf_from_frequency: {} frequencies give {} real equations for {} parameters", K, 2 * K, p);
  CTID_REQUIRE(data.outputs() == 1 && data.inputs() == 1,
               "tf_from_frequency: a transfer function has one input and one output; the data have {} and {} (ssest "
               "fits a state-space model to an FRF matrix)", data.inputs(), data.outputs());
  const Eigen::VectorXcd& G = data.response();
  const double w0 = std::exp(data.w().array().log().mean());
  ScaledModel sc{n, nb, data.w() / w0, data.w()};
  // G with the fixed/initial delay removed for the linear SK stage.
  Eigen::VectorXcd Gd(K);
  for (int k = 0; k < K; ++k) Gd(k) = G(k) * std::exp(cd(0, data.w()(k) * opt.delay));

  int sk_done = 0;
  const std::vector<Eigen::VectorXd> x0s = sk_starts(sc, Gd, p, opt, sk_done);
  Eigen::VectorXd x0 = x0s.front();
  if (opt.estimate_delay) x0(n + nb) = opt.delay;
  Eigen::VectorXd lo = Eigen::VectorXd::Constant(p, -INFINITY), hi = Eigen::VectorXd::Constant(p, INFINITY);
  if (opt.estimate_delay) lo(n + nb) = 0.0;
  auto evaluate = [&](const Eigen::VectorXd& x, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
    if (opt.require_stable && n > 0) {
      Eigen::VectorXd den(n + 1);
      den(0) = 1.0;
      den.tail(n) = x.head(n);
      const Eigen::VectorXcd poles = Polynomial(den).roots();
      for (Eigen::Index i = 0; i < poles.size(); ++i)
        if (!(poles(i).real() < 0)) return false;
    }
    const double T = opt.estimate_delay ? x(n + nb) : opt.delay;
    r.resize(2 * K);
    if (J) J->resize(2 * K, p);
    for (int k = 0; k < K; ++k) {
      const cd s(0, sc.ws(k));
      const cd A = sc.A(k, x), B = sc.B(k, x), e = std::exp(cd(0, -data.w()(k) * T));
      const cd Gm = B / A * e;
      const cd res = G(k) - Gm;
      r(2 * k) = res.real();
      r(2 * k + 1) = res.imag();
      if (J) {
        for (int i = 1; i <= n; ++i) {
          const cd d = Gm * std::pow(s, n - i) / A;  // d res / d a'_i = + Gm s^{n-i} / A
          (*J)(2 * k, i - 1) = d.real();
          (*J)(2 * k + 1, i - 1) = d.imag();
        }
        for (int j = 0; j < nb; ++j) {
          const cd d = -std::pow(s, nb - 1 - j) / A * e;
          (*J)(2 * k, n + j) = d.real();
          (*J)(2 * k + 1, n + j) = d.imag();
        }
        if (opt.estimate_delay) {
          const cd d = cd(0, data.w()(k)) * Gm;  // d res / dT = + j w Gm
          (*J)(2 * k, n + nb) = d.real();
          (*J)(2 * k + 1, n + nb) = d.imag();
        }
      }
    }
    return r.allFinite();
  };
  internal::LmResult lm;
  lm.x = x0;
  if (opt.refine) {
    internal::LmOptions lmo;
    lmo.max_iterations = opt.max_iterations;
    lmo.ftol = lmo.xtol = opt.tolerance;
    lm.cost = INFINITY;
    for (const auto& start_x : x0s) {
      internal::LmResult cand = internal::levenberg_marquardt(evaluate, start_x, lo, hi, lmo);
      if (cand.cost < lm.cost) lm = cand;
    }
  } else {
    Eigen::VectorXd r;
    Eigen::MatrixXd J;
    evaluate(x0, r, &J);
    lm.cost = 0.5 * r.squaredNorm();
    lm.jtj = J.transpose() * J;
    lm.converged = true;
  }

  // Unscale: a_i = a'_i w0^i, b_j = b'_j w0^{n - nb + 1 + j}.
  Eigen::VectorXd scale(p);
  for (int i = 1; i <= n; ++i) scale(i - 1) = std::pow(w0, i);
  for (int j = 0; j < nb; ++j) scale(n + j) = std::pow(w0, n - nb + 1 + j);
  if (opt.estimate_delay) scale(n + nb) = 1.0;
  const Eigen::VectorXd x = lm.x.cwiseProduct(scale);
  Result<TransferFunction> r;
  const double T = opt.estimate_delay ? x(n + nb) : opt.delay;
  r.model = tf_detail::tf_of(x.head(n + nb), orders, T);
  r.parameters.names = tf_parameter_names(orders);
  if (opt.estimate_delay) r.parameters.names.push_back("delay");
  r.parameters.values = x;
  r.parameters.fixed.assign(p, false);
  const double sigma2 = 2.0 * lm.cost / std::max(1, 2 * K - p);  // per real/imaginary part
  const Eigen::MatrixXd Cs = internal::covariance(lm.jtj, sigma2);
  r.parameters.set_covariance(Cs.size() ? Eigen::MatrixXd(scale.asDiagonal() * Cs * scale.asDiagonal()) : Cs);
  r.fit = tf_detail::frequency_fit(r.model, data.w(), G, p);
  r.diagnostics.set(diagnostic::noise_variance, sigma2);
  r.diagnostics.set(diagnostic::frequency_scale, w0);
  r.diagnostics.set(diagnostic::sk_iterations, sk_done);
  internal::set_termination(r.summary, lm);
  if (r.summary.succeeded() && !r.model.is_stable())
    r.diagnostics.warnings.push_back("the fitted model is unstable (frequency data do not constrain stability)");
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

}  // namespace ctid
