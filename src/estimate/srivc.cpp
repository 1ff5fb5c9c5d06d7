// SRIVC — Young & Jakeman (1980); Garnier & Wang (2008) ch. 4. See include/ctid/estimate/srivc.hpp.
#include "ctid/estimate/srivc.hpp"

#include <chrono>
#include <cmath>
#include <limits>

#include "ctid/core/check.hpp"
#include "ctid/estimate/lssvf.hpp"
#include "ctid/signal/prefilter.hpp"
#include "ctid/simulate/lsim.hpp"
#include "ctid/validate/metrics.hpp"
#include "estimate/svf_common.hpp"
#include "estimate/tf_common.hpp"
#include "internal/least_squares.hpp"

namespace ctid {

void SrivcOptions::validate() const {
  CTID_REQUIRE_OPTION(max_iterations >= 1, "srivc: max_iterations must be >= 1 (got {})", max_iterations);
  CTID_REQUIRE_OPTION(tolerance > 0 && std::isfinite(tolerance), "srivc: tolerance must be > 0 (got {})", tolerance);
  CTID_REQUIRE_OPTION(std::isfinite(delay) && delay >= 0, "srivc: delay must be >= 0 (got {} s)", delay);
  CTID_REQUIRE_OPTION(std::isfinite(delay_min) && delay_min >= 0, "srivc: delay_min must be >= 0 (got {} s)", delay_min);
  CTID_REQUIRE_OPTION(std::isfinite(delay_max), "srivc: delay_max must be finite (got {})", delay_max);
  CTID_REQUIRE_OPTION(delay_max < 0 || delay_max >= delay_min, "srivc: the delay range [{}, {}] s is empty", delay_min,
                      delay_max);
  CTID_REQUIRE_OPTION(delay_grid >= 0, "srivc: delay_grid must be >= 0 (got {})", delay_grid);
}


using namespace tf_detail;

namespace {

struct SrivcRun {
  Eigen::VectorXd theta;        // [a1..an, b0..bm]
  internal::LinearSolution sol; // of the last IV step
  Eigen::MatrixXd zz;           // sum zeta zeta^T of the last step
  int iterations = 0;
  bool converged = false;
  bool rank_deficient = false;
};

// SRIVC iterations at a fixed total delay.
SrivcRun srivc_fixed_delay(const IdData& d, const TfOrders& o, double delay, Eigen::VectorXd theta, const SrivcOptions& opt,
                           int max_iterations) {
  const int n = o.nf, m = o.nb - 1, p = o.nf + o.nb;
  const Eigen::VectorXd t = d.times();
  const Eigen::VectorXd y = d.y().col(0), u = d.u().col(0);
  const Intersample uis = d.intersample(0);
  SrivcRun run;
  run.theta = theta;
  for (int it = 1; it <= max_iterations; ++it) {
    run.iterations = it;
    const TransferFunction model = stabilized(tf_of(run.theta, o, 0.0));
    const Polynomial& A = model.den();
    const TransferFunction F(Polynomial{1.0}, A);                   // prefilter 1/A
    const TransferFunction Fx(model.num(), A * A);                  // auxiliary model, prefiltered: B/A^2
    const Eigen::MatrixXd yf = filtered_derivatives(F, n, y, t, Intersample::Foh);
    const Eigen::MatrixXd uf = filtered_derivatives(F, m, u, t, uis, delay);
    const Eigen::MatrixXd xf = filtered_derivatives(Fx, n - 1, u, t, uis, delay);
    internal::InstrumentalVariables iv(p, /*with_rss=*/false);
    std::vector<double> phi(p), zeta(p);
    for (Eigen::Index k = 0; k < t.size(); ++k) {
      for (int i = 1; i <= n; ++i) {
        phi[i - 1] = -yf(k, n - i);
        zeta[i - 1] = -xf(k, n - i);
      }
      for (int j = 0; j <= m; ++j) phi[n + j] = zeta[n + j] = uf(k, m - j);
      iv.add(zeta.data(), phi.data(), yf(k, n), 1.0);
    }
    run.sol = iv.solve();
    run.zz = iv.zz();
    if (run.sol.rank_deficient || !run.sol.theta.allFinite()) {
      run.rank_deficient = true;
      return run;
    }
    double change = 0;
    for (int i = 0; i < p; ++i)
      change = std::max(change, std::abs(run.sol.theta(i) - run.theta(i)) / std::max(std::abs(run.sol.theta(i)), 1e-8));
    run.theta = run.sol.theta;
    if (change < opt.tolerance) {
      run.converged = true;
      return run;
    }
  }
  return run;
}

Eigen::VectorXd initial_theta(const IdData& d, const TfOrders& o, double delay, const SrivcOptions& opt) {
  if (opt.initial) {
    CTID_REQUIRE_OPTION(opt.initial->order() == o.nf, "srivc: the initial model has order {} but nf = {}", opt.initial->order(),
                        o.nf);
    return params_of(*opt.initial, o);
  }
  // LSSVF with an automatic filter on the delay-shifted input (nk = 0, strictly proper).
  IdData shifted = d;
  if (delay > 0) {
    const Eigen::VectorXd ud = filtered_derivatives(TransferFunction(Polynomial{1.0}, Polynomial{1.0}), 0, d.u().col(0),
                                                    d.times(), d.intersample(0), delay);
    Eigen::MatrixXd u = ud;
    shifted = d.is_uniform() ? IdData(u, d.y(), d.ts(), d.t0()) : IdData(u, d.y(), d.times());
    shifted.set_intersample(0, d.intersample(0));
  }
  const TfOrders lo{std::min(o.nb, o.nf), o.nf, 0};
  LssvfOptions lso;
  lso.tau_grid_size = 3;  // a rough start is enough: SRIVC's own iterations do the rest
  const Result<TransferFunction> ls = lssvf(shifted, lo, lso);
  Eigen::VectorXd th = Eigen::VectorXd::Zero(o.nf + o.nb);
  th.head(o.nf) = ls.parameters.values.head(o.nf);
  th.tail(lo.nb) = ls.parameters.values.tail(lo.nb);
  return th;
}

}  // namespace

Result<TransferFunction> srivc(const IdData& data, const TfOrders& orders, const SrivcOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  orders.validate(/*allow_biproper=*/true);
  options.validate();
  CTID_REQUIRE(data.nu() == 1 && data.ny() == 1, "srivc: needs one input and one output (data has {} inputs, {} outputs)",
               data.nu(), data.ny());
  CTID_REQUIRE(orders.nk == 0 || data.is_uniform(), "srivc: nk = {} needs uniformly sampled data", orders.nk);
  const int p = orders.nf + orders.nb;
  CTID_REQUIRE(data.size() > p, "srivc: {} samples cannot determine {} parameters", data.size(), p);
  const double base_delay = options.delay + (orders.nk > 0 ? orders.nk * data.ts() : 0.0);

  double delay = base_delay;
  Eigen::VectorXd theta;
  Eigen::VectorXd grid, grid_cost;
  if (options.estimate_delay) {
    const double dmax = options.delay_max >= 0 ? options.delay_max : 0.1 * data.duration();
    const double h = data.is_uniform() ? data.ts() : data.duration() / std::max(1, data.size() - 1);
    int G = options.delay_grid > 0 ? options.delay_grid
                                   : std::min(200, static_cast<int>(std::floor((dmax - options.delay_min) / h)) + 1);
    G = std::max(G, 2);
    grid.resize(G);
    grid_cost.resize(G);
    double best = std::numeric_limits<double>::infinity();
    Eigen::VectorXd warm;
    for (int i = 0; i < G; ++i) {
      const double dl = options.delay_min + (dmax - options.delay_min) * i / double(G - 1);
      grid(i) = dl;
      // The first grid point starts from the user's model or LSSVF; the others from their
      // neighbour's estimate (the dynamics change little between neighbouring delays).
      const Eigen::VectorXd th0 = i == 0 ? initial_theta(data, orders, dl, options) : warm;
      const SrivcRun r = srivc_fixed_delay(data, orders, dl, th0, options, 3);
      warm = r.rank_deficient || !r.theta.allFinite() ? th0 : r.theta;
      grid_cost(i) = r.rank_deficient ? INFINITY : output_error_mse(tf_of(r.theta, orders, dl), data);
      if (grid_cost(i) < best) {
        best = grid_cost(i);
        delay = dl;
        theta = r.theta;
      }
    }
    // Refinement: alternate SRIVC at the current delay with a golden-section search of the
    // output-error cost over one grid step on either side.
    const double step = (dmax - options.delay_min) / double(G - 1);
    double lo = std::max(options.delay_min, delay - step), hi = std::min(dmax, delay + step);
    for (int outer = 0; outer < 40; ++outer) {
      theta = srivc_fixed_delay(data, orders, delay, theta, options, options.max_iterations).theta;
      auto cost = [&](double dl) { return output_error_mse(tf_of(theta, orders, dl), data); };
      const double gr = 0.5 * (std::sqrt(5.0) - 1.0);
      double a = lo, b = hi, c = b - gr * (b - a), e = a + gr * (b - a), fc = cost(c), fe = cost(e);
      while (b - a > 1e-6 * std::max(h, 1e-12)) {
        if (fc < fe) { b = e; e = c; fe = fc; c = b - gr * (b - a); fc = cost(c); }
        else { a = c; c = e; fc = fe; e = a + gr * (b - a); fe = cost(e); }
      }
      const double next = 0.5 * (a + b);
      const double moved = std::abs(next - delay);
      const bool done = moved < 1e-7 * h;
      delay = next;
      // The alternation converges linearly; shrink the bracket around the current delay.
      const double half = std::max(4.0 * moved, 1e-3 * h);
      lo = std::max(options.delay_min, delay - std::min(half, step));
      hi = std::min(dmax, delay + std::min(half, step));
      if (done) break;
    }
  } else {
    theta = initial_theta(data, orders, delay, options);
  }

  const SrivcRun run = srivc_fixed_delay(data, orders, delay, theta, options, options.max_iterations);
  Result<TransferFunction> r;
  r.model = tf_of(run.theta, orders, delay);
  r.parameters.names = tf_parameter_names(orders);
  r.parameters.values = run.theta;
  r.parameters.fixed.assign(p, false);
  r.fit = fit_report_or_inf(data.y().col(0), lsim(r.model, data, 0), p + (options.estimate_delay ? 1 : 0));
  // Covariance sigma^2 (sum zeta zeta^T)^{-1}, sigma^2 from the output error.
  const double sigma2 = r.fit.mse * data.size() / std::max(1, data.size() - p);
  if (!run.rank_deficient && std::isfinite(sigma2)) {
    r.parameters.covariance = sigma2 * run.zz.ldlt().solve(Eigen::MatrixXd::Identity(p, p));
    r.parameters.std = r.parameters.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  } else {
    r.parameters.covariance = Eigen::MatrixXd::Constant(p, p, NAN);
    r.parameters.std = Eigen::VectorXd::Constant(p, NAN);
  }
  r.diagnostics.condition_number = run.sol.condition;
  r.diagnostics.scalars["delay"] = delay;
  r.diagnostics.scalars["noise_variance"] = sigma2;
  if (grid.size() > 0) {
    r.diagnostics.vectors["delay_grid"] = grid;
    r.diagnostics.vectors["delay_grid_mse"] = grid_cost;
  }
  r.summary.iterations = run.iterations;
  if (run.rank_deficient) {
    r.summary.termination = Termination::RankDeficient;
    r.summary.message = detail::format("the instrumental-variable matrix is singular (condition {}); the input does not "
                                       "excite {} parameters",
                                       run.sol.condition, p);
  } else if (!run.converged) {
    r.summary.termination = Termination::MaxIterations;
    r.summary.message = detail::format("no convergence to a relative change of {} in {} iterations", options.tolerance,
                                       options.max_iterations);
  } else {
    r.summary.termination = Termination::Converged;
  }
  if (r.summary.succeeded() && !r.model.is_stable()) {
    r.summary.termination = Termination::Unstable;
    r.summary.message = "SRIVC converged to an unstable model (the prefilter was stabilised during the iterations)";
  }
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

}  // namespace ctid
