// ctid — nonlinear grey-box identification by output error with exact forward sensitivities (see
// include/ctid/estimate/greybox.hpp; Ljung 1999 §7.3; Bohlin 2006).
#include "ctid/estimate/greybox.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include "ctid/core/check.hpp"
#include "ctid/validate/metrics.hpp"
#include "internal/least_squares.hpp"
#include "internal/levenberg_marquardt.hpp"

namespace ctid {

template <>
const OptionTable<GreyboxOptions>& option_table<GreyboxOptions>() {
  using O = GreyboxOptions;
  static const OptionTable<O> t =
      OptionTable<O>("greybox")
          .integer("max_iterations", &O::max_iterations, "", at_least(1), "Levenberg-Marquardt iterations per start")
          .real("tolerance", &O::tolerance, "", OptionRange{0, 1, true, true, {}, {}},
                "relative cost decrease or parameter change that stops a search")
          .integer("starts", &O::starts, "", at_least(1),
                   "multi-start: the model's values plus starts-1 points drawn within the bounds (the lowest cost wins)")
          .integer("seed", &O::seed, "", at_least(0), "seed of the drawn starts")
          .real("rtol", &O::rtol, "", between(1e-13, 1e-4), "relative tolerance of the simulations (absolute: 1e-3 rtol)")
          .flag("estimate_initial_state", &O::estimate_initial_state,
                "estimate the initial states the model marks \"estimate\" (one per record); 0: hold them at their start")
          .named_reals("fixed", &O::fixed, "parameters held at a value by name (fixed.k1=0.05), on top of the model's")
          .named_bounds("bounds", &O::bounds, "bounds on parameters by name (bounds.k1=0,inf), replacing the model's");
  return t;
}

void GreyboxOptions::validate() const { option_table<GreyboxOptions>().check(*this); }

Result<GreyboxModel> greybox(const IdData& data, const GreyboxModel& model, const GreyboxOptions& opt) {
  return greybox(std::vector<IdData>{data}, model, opt);
}

namespace {
// One record as the search sees it.
struct Record {
  Eigen::MatrixXd u;
  Eigen::VectorXd t, y;  // y: the outputs stacked column by column (N ny)
  Intersample hold = Intersample::Zoh;
  Eigen::Index start = 0;  // first row in the stacked residual
  int n = 0;
};
}  // namespace

Result<GreyboxModel> greybox(const std::vector<IdData>& records, const GreyboxModel& model, const GreyboxOptions& opt) {
  const auto clock0 = std::chrono::steady_clock::now();
  opt.validate();
  CTID_REQUIRE(!records.empty(), "greybox: no records");
  const int E = static_cast<int>(records.size()), ny = model.ny(), np = model.np(), nx = model.nx();
  // Constraints: the model's declarations, the options on top (a held option replaces a declared bound).
  FixedValues fixed_values;
  ParameterBounds bounds;
  for (const auto& p : model.spec().parameters) {
    if (p.fixed) fixed_values[p.name] = p.value;
    else if (p.lower > -INFINITY || p.upper < INFINITY) bounds[p.name] = {p.lower, p.upper};
  }
  overlay_constraints(fixed_values, bounds, opt.fixed, opt.bounds);
  const ParameterConstraints cons =
      resolve_constraints(fixed_values, bounds, model.parameter_names(), "greybox", "a parameter of the model");
  Eigen::VectorXd theta0 = model.parameter_values();
  for (int i = 0; i < np; ++i)
    if (cons.held[i]) theta0(i) = cons.value(i);
  const std::vector<int> free = cons.free();
  const int pf = static_cast<int>(free.size());
  std::vector<int> free_x0;
  if (opt.estimate_initial_state)
    for (int i = 0; i < nx; ++i)
      if (model.spec().initial[i].estimate) free_x0.push_back(i);
  const int nx0 = static_cast<int>(free_x0.size());
  const int p = pf + E * nx0;

  std::vector<Record> rec(static_cast<size_t>(E));
  int N = 0;
  for (int e = 0; e < E; ++e) {
    const IdData& d = records[static_cast<size_t>(e)];
    const std::string who = E > 1 ? detail::format("greybox (record {})", e + 1) : std::string("greybox");
    CTID_REQUIRE(d.nu() == model.nu() && d.ny() == ny, "{}: the data have {} inputs and {} outputs, the model {} ({}) and {} ({})",
                 who, d.nu(), d.ny(), model.nu(), options_detail::format_names(model.spec().inputs), ny,
                 options_detail::format_names(model.output_names()));
    CTID_REQUIRE(d.size() >= 2, "{}: {} samples", who, d.size());
    Record& r = rec[static_cast<size_t>(e)];
    r.u = d.u();
    r.t = d.times();
    r.y = Eigen::Map<const Eigen::VectorXd>(d.y().data(), d.y().size());
    r.n = d.size();
    bool zoh = true;
    for (int i = 0; i < d.nu(); ++i) zoh = zoh && d.intersample(i) == Intersample::Zoh;
    r.hold = zoh ? Intersample::Zoh : Intersample::Foh;
    r.start = static_cast<Eigen::Index>(N) * ny;
    N += d.size();
  }
  CTID_REQUIRE(static_cast<long>(N) * ny > p, "greybox: {} samples for {} free quantities ({} parameters, {} initial states)",
               N * ny, p, pf, E * nx0);
  // Output weights: 1 for one output; 1/RMS deviation of each output with several (outputs in different units).
  Eigen::VectorXd w = Eigen::VectorXd::Ones(ny);
  Eigen::VectorXd y(static_cast<Eigen::Index>(N) * ny);
  for (const Record& r : rec)
    for (int j = 0; j < ny; ++j) y.segment(r.start + static_cast<Eigen::Index>(j) * r.n, r.n) = r.y.segment(static_cast<Eigen::Index>(j) * r.n, r.n);
  if (ny > 1)
    for (int j = 0; j < ny; ++j) {
      double s = 0, s2 = 0;
      for (const Record& r : rec) {
        s += r.y.segment(static_cast<Eigen::Index>(j) * r.n, r.n).sum();
        s2 += r.y.segment(static_cast<Eigen::Index>(j) * r.n, r.n).squaredNorm();
      }
      const double var = s2 / N - (s / N) * (s / N);
      CTID_REQUIRE(var > 0, "greybox: output {} is constant in every record", model.output_names()[j]);
      w(j) = 1.0 / std::sqrt(var);
    }
  Eigen::VectorXd wy = y;
  for (const Record& r : rec)
    for (int j = 0; j < ny; ++j) wy.segment(r.start + static_cast<Eigen::Index>(j) * r.n, r.n) *= w(j);

  // The search's vector v = [free parameters (pf), estimated initial states of record 1 (nx0), of record 2, ..].
  auto model_at = [&](const Eigen::VectorXd& v) {
    Eigen::VectorXd th = theta0;
    for (int j = 0; j < pf; ++j) th(free[static_cast<size_t>(j)]) = v(j);
    return model.with_parameters(th);
  };
  std::vector<Eigen::VectorXd> guess(static_cast<size_t>(E));
  for (int e = 0; e < E; ++e) guess[static_cast<size_t>(e)] = model.initial_state_guess(records[static_cast<size_t>(e)]);
  auto x0_of = [&](const GreyboxModel& m, const Eigen::VectorXd& v, int e) {
    // Initial-state expressions of parameters move with them; estimated states come from v.
    Eigen::VectorXd x = m.initial_state();
    for (int i = 0; i < nx; ++i)
      if (std::isnan(x(i)) || model.spec().initial[i].estimate) x(i) = guess[static_cast<size_t>(e)](i);
    for (int k = 0; k < nx0; ++k) x(free_x0[static_cast<size_t>(k)]) = v(pf + e * nx0 + k);
    return x;
  };
  std::string escape;  // the last escape's message
  const internal::LmEvaluate evaluate = [&](const Eigen::VectorXd& v, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
    const GreyboxModel m = model_at(v);
    r.resize(y.size());
    if (J) *J = Eigen::MatrixXd::Zero(y.size(), p);
    for (int e = 0; e < E; ++e) {
      const Record& d = rec[static_cast<size_t>(e)];
      const Eigen::VectorXd x0 = x0_of(m, v, e);
      if (!J) {
        const GreyboxSimulation s = m.simulate(d.u, d.t, d.hold, x0, opt.rtol);
        if (!s.ok()) return escape = s.message, false;
        for (int j = 0; j < ny; ++j)
          r.segment(d.start + static_cast<Eigen::Index>(j) * d.n, d.n) = w(j) * s.y.col(j);
        continue;
      }
      const GreyboxSensitivities s = m.sensitivities(d.u, d.t, d.hold, x0, free, free_x0, opt.rtol);
      if (!s.ok) return escape = s.message, false;
      for (int j = 0; j < ny; ++j) {
        const Eigen::Index row = d.start + static_cast<Eigen::Index>(j) * d.n;
        r.segment(row, d.n) = w(j) * s.y.col(j);
        const Eigen::MatrixXd& dy = s.dy[static_cast<size_t>(j)];
        J->block(row, 0, d.n, pf) = -w(j) * dy.leftCols(pf);
        if (nx0) J->block(row, pf + e * nx0, d.n, nx0) = -w(j) * dy.rightCols(nx0);
      }
    }
    r = wy - r;
    return true;
  };

  Eigen::VectorXd lo = Eigen::VectorXd::Constant(p, -INFINITY), hi = Eigen::VectorXd::Constant(p, INFINITY);
  Eigen::VectorXd v0(p);
  for (int j = 0; j < pf; ++j) {
    const int i = free[static_cast<size_t>(j)];
    lo(j) = cons.lower(i);
    hi(j) = cons.upper(i);
    v0(j) = std::clamp(theta0(i), lo(j), hi(j));
  }
  for (int e = 0; e < E; ++e)
    for (int k = 0; k < nx0; ++k) v0(pf + e * nx0 + k) = guess[static_cast<size_t>(e)](free_x0[static_cast<size_t>(k)]);
  internal::LmOptions lmo;
  lmo.max_iterations = opt.max_iterations;
  lmo.ftol = opt.tolerance;
  lmo.xtol = opt.tolerance;
  // Multi-start: start 0 is the model's values; the others draw each free parameter within its bounds.
  std::mt19937_64 rng(static_cast<std::uint64_t>(opt.seed));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  internal::LmResult best;
  best.cost = INFINITY;
  Eigen::VectorXd start_costs(opt.starts);
  for (int s = 0; s < opt.starts; ++s) {
    Eigen::VectorXd v = v0;
    if (s > 0)
      for (int j = 0; j < pf; ++j) {
        if (std::isfinite(lo(j)) && std::isfinite(hi(j))) v(j) = lo(j) + (hi(j) - lo(j)) * unit(rng);
        else {
          const double mag = v0(j) != 0.0 ? std::abs(v0(j)) : 1.0;
          const double sign = v0(j) < 0 ? -1.0 : 1.0;
          v(j) = std::clamp(sign * mag * std::pow(10.0, 2.0 * unit(rng) - 1.0), lo(j), hi(j));
        }
      }
    const internal::LmResult lm = internal::levenberg_marquardt(evaluate, v, lo, hi, lmo);
    start_costs(s) = lm.cost;
    if (s == 0 || lm.cost < best.cost) best = lm;
    if (lm.interrupted) {
      best.interrupted = true;
      best.message = lm.message;
      break;
    }
  }

  Result<GreyboxModel> r;
  const GreyboxModel fitted = model_at(best.x);
  Eigen::VectorXd x0_first = x0_of(fitted, best.x, 0);
  r.model = fitted.with_estimated_initial(x0_first);
  const std::vector<std::string> pnames = model.parameter_names();
  const int total = np + E * nx0;
  r.parameters.names = pnames;
  r.parameters.values.resize(total);
  r.parameters.values.head(np) = fitted.parameter_values();
  r.parameters.fixed.assign(static_cast<size_t>(total), false);
  for (int i = 0; i < np; ++i) r.parameters.fixed[static_cast<size_t>(i)] = cons.held[i];
  for (int e = 0; e < E; ++e)
    for (int k = 0; k < nx0; ++k) {
      const std::string st = model.spec().states[static_cast<size_t>(free_x0[static_cast<size_t>(k)])] + "(0)";
      r.parameters.names.push_back(E > 1 ? detail::format("r{}.{}", e + 1, st) : st);
      r.parameters.values(np + e * nx0 + k) = best.x(pf + e * nx0 + k);
    }
  std::vector<int> slot(free);
  for (int k = 0; k < E * nx0; ++k) slot.push_back(np + k);
  const double sigma2 = 2.0 * best.cost / std::max<double>(1.0, static_cast<double>(N) * ny - p);
  std::vector<std::string> free_names;
  for (int j : slot) free_names.push_back(r.parameters.names[static_cast<size_t>(j)]);
  const std::string unidentifiable =
      std::isfinite(best.cost) ? internal::unidentifiable(best.jtj, best.x, free_names) : std::string();
  if (std::isfinite(best.cost) && unidentifiable.empty())
    r.parameters.set_covariance(internal::covariance(best.jtj, sigma2), slot);
  else r.parameters.set_covariance({}, slot);
  r.diagnostics.condition_number = std::isfinite(best.cost) ? internal::gram_condition(best.jtj) : NAN;
  for (int e = 0; e < E; ++e) r.diagnostics.set(diagnostic::x0, x0_of(fitted, best.x, e), e);
  if (E > 1) r.diagnostics.set(diagnostic::experiments, E);
  r.diagnostics.set(diagnostic::noise_variance, ny == 1 ? sigma2 : NAN);
  if (opt.starts > 1) r.diagnostics.set(diagnostic::starts_cost, start_costs);
  const std::string failure = "the model cannot be simulated on these data from its start" +
                              std::string(opt.starts > 1 ? "s" : "") + (escape.empty() ? "" : ": " + escape);
  internal::set_termination(r.summary, best, failure, unidentifiable);
  // The fit: all outputs of all records stacked, each weighted (one output: the output itself).
  Eigen::VectorXd rr;
  Eigen::VectorXd yfit = Eigen::VectorXd::Constant(y.size(), NAN);
  if (std::isfinite(best.cost) && evaluate(best.x, rr, nullptr)) yfit = wy - rr;
  else if (r.summary.succeeded()) {
    r.summary.termination = Termination::NumericalFailure;
    r.summary.message = failure;
  }
  r.fit = fit_report_or_inf(wy, yfit, p);
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock0).count();
  return r;
}

}  // namespace ctid
