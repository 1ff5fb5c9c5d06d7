// Stage 2 of Gawthrop & Wang (2005); see include/ctid/estimate/fsf/physical.hpp.
#include "ctid/estimate/fsf/physical.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <span>

#include "ctid/core/check.hpp"
#include "ctid/model/state_space.hpp"
#include "ctid/simulate/lsim.hpp"
#include "ctid/simulate/simulate.hpp"
#include "ctid/validate/metrics.hpp"
#include "internal/least_squares.hpp"
#include "estimate/search.hpp"
#include "internal/levenberg_marquardt.hpp"

namespace ctid {

template <>
const OptionTable<PhysicalFitOptions>& option_table<PhysicalFitOptions>() {
  using O = PhysicalFitOptions;
  static const OptionTable<O> t =
      OptionTable<O>("physical")
          .integer("max_iterations", &O::max_iterations, "", at_least(1), "Levenberg-Marquardt iterations")
          .real("tolerance", &O::tolerance, "", above(0), "relative cost decrease that stops the search")
          .integer("step_points", &O::step_points, "", at_least(2),
                   "samples of the compressed step response on [0, T] (route via fsf)")
          .flag("estimate_initial_state", &O::estimate_initial_state,
                "raw route: estimate each record's initial state (its free response) instead of starting from rest; "
                "diagnostics x0 per record")
          .named_reals("fixed", &O::fixed, "parameters held at a value, by name (fixed.k=2)")
          .named_bounds("bounds", &O::bounds, "parameter bounds by name (bounds.k=0,inf)");
  return t;
}

void PhysicalFitOptions::validate() const { option_table<PhysicalFitOptions>().check(*this); }

namespace {

// Residuals r(Theta) and their Jacobian from the shifted model and its sensitivities (to the free parameters
// `free`, the indices into Theta).
using ResidualFn = std::function<void(const Eigen::VectorXd& theta, const std::vector<int>& free, const TransferFunction& g,
                                      const std::vector<TransferFunction>* sens, Eigen::VectorXd& r, Eigen::MatrixXd* J)>;

// target: the data the residuals are measured against (for the fit report); nuisance_at (when given): called once with
// the starting Theta, the number of further quantities the residual function estimates itself (the raw route's
// initial states), counted in the degrees of freedom. sequences (when given): the residuals' layout in time order, for
// a covariance that allows for coloured residuals (search::set_covariance); otherwise sigma^2 (J^T J)^-1 with a
// warning that it is indicative.
Result<TransferFunction> fit(const PhysicalModel& model, const std::vector<PhysicalParameter>& params, double a,
                             const PhysicalFitOptions& opt, const ResidualFn& residual, const Eigen::VectorXd& target,
                             const char* route, const std::function<int(const Eigen::VectorXd&)>& nuisance_at = {},
                             const std::vector<internal::ResidualSequence>& sequences = {}) {
  const int n_data = static_cast<int>(target.size());
  const auto start = std::chrono::steady_clock::now();
  opt.validate();
  const int P = model.n_parameters();
  Eigen::VectorXd full(P);
  std::vector<bool> given(P, false);
  // The declarations' fixed/lower/upper, then the options' fixed.NAME and bounds.NAME on top, in one vocabulary.
  FixedValues fixed_values;
  ParameterBounds bounds;
  for (const auto& p : params) {
    int idx = -1;
    for (int i = 0; i < P; ++i)
      if (model.parameter_names()[i] == p.name) idx = i;
    if (idx < 0) {
      std::string list;
      for (const auto& nm : model.parameter_names()) list += (list.empty() ? "" : ", ") + nm;
      throw InvalidOptions(detail::format("physical: '{}' is not a parameter of \"{}\" (parameters: {})", p.name,
                                          model.expression(), list));
    }
    CTID_REQUIRE_OPTION(std::isfinite(p.initial), "physical: parameter '{}' has no (finite) initial value", p.name);
    CTID_REQUIRE_OPTION(!(p.lower > p.upper), "physical: bounds of '{}' are empty ([{}, {}])", p.name, p.lower, p.upper);
    full(idx) = std::min(std::max(p.initial, p.lower), p.upper);
    given[idx] = true;
    if (p.fixed) fixed_values[p.name] = full(idx);
    else if (p.lower > -INFINITY || p.upper < INFINITY) bounds[p.name] = {p.lower, p.upper};
  }
  overlay_constraints(fixed_values, bounds, opt.fixed, opt.bounds);
  const ParameterConstraints c = resolve_constraints(fixed_values, bounds, model.parameter_names(), "physical",
                                                     "a parameter of \"" + model.expression() + "\"");
  const std::vector<bool>& fixed = c.held;
  Eigen::VectorXd lo_full = c.lower, hi_full = c.upper;
  for (int i = 0; i < P; ++i) {
    if (fixed[i]) {
      full(i) = lo_full(i) = hi_full(i) = c.value(i);
      given[i] = true;
    } else if (given[i]) {
      full(i) = std::min(std::max(full(i), lo_full(i)), hi_full(i));
    }
  }
  for (int i = 0; i < P; ++i)
    CTID_REQUIRE_OPTION(given[i], "physical: parameter '{}' of \"{}\" needs an initial value", model.parameter_names()[i],
                        model.expression());
  const std::vector<int> free = c.free();
  CTID_REQUIRE_OPTION(!free.empty(), "physical: every parameter is fixed; nothing to estimate");
  const int p = static_cast<int>(free.size());
  CTID_REQUIRE(n_data > p, "physical: {} residuals cannot determine {} parameters", n_data, p);
  Eigen::VectorXd x0(p), lo(p), hi(p);
  for (int j = 0; j < p; ++j) {
    x0(j) = full(free[j]);
    lo(j) = lo_full(free[j]);
    hi(j) = hi_full(free[j]);
  }
  const int nuisance = nuisance_at ? nuisance_at(full) : 0;
  auto theta_of = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd t = full;
    for (int j = 0; j < p; ++j) t(free[j]) = x(j);
    return t;
  };
  std::vector<double> history;
  auto evaluate = [&](const Eigen::VectorXd& x, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
    const Eigen::VectorXd th = theta_of(x);
    TransferFunction g;
    try {
      g = model.shifted(th, a);
    } catch (const InvalidArgument&) {
      return false;  // e.g. the denominator vanishes at this point
    }
    if (J) {
      const std::vector<TransferFunction> all = model.sensitivities(th, a);
      std::vector<TransferFunction> sens;
      for (int j = 0; j < p; ++j) sens.push_back(all[free[j]]);
      residual(th, free, g, &sens, r, J);
    } else {
      residual(th, free, g, nullptr, r, nullptr);
    }
    if (!r.allFinite() || (J && !J->allFinite())) return false;
    if (J) history.push_back(0.5 * r.squaredNorm());
    return true;
  };
  internal::LmOptions lmo;
  lmo.max_iterations = opt.max_iterations;
  lmo.ftol = lmo.xtol = opt.tolerance;
  lmo.keep_jacobian = !sequences.empty();
  const internal::LmResult lm = internal::levenberg_marquardt(evaluate, x0, lo, hi, lmo);

  Result<TransferFunction> res;
  const Eigen::VectorXd th = theta_of(lm.x);
  res.model = model.transfer_function(th);
  res.parameters.names = model.parameter_names();
  res.parameters.values = th;
  res.parameters.fixed = fixed;
  const double sigma2 = 2.0 * lm.cost / std::max(1, n_data - p - nuisance);
  const search::CovarianceVerdict verdict =
      search::set_covariance(res.parameters, res.diagnostics, lm, free, sigma2, {lo, hi}, sequences);
  {
    Eigen::VectorXd r;
    if (std::isfinite(lm.cost) && evaluate(lm.x, r, nullptr)) res.fit = fit_report_or_inf(target, target + r, p + nuisance);
    else res.fit = fit_report_or_inf(target, Eigen::VectorXd::Constant(n_data, NAN), p + nuisance);
  }
  res.diagnostics.set(diagnostic::shift_a, a);
  res.diagnostics.set(diagnostic::cost, lm.cost);
  res.diagnostics.set(diagnostic::cost_history, Eigen::Map<Eigen::VectorXd>(history.data(), static_cast<Eigen::Index>(history.size())));
  if (!res.diagnostics.has(diagnostic::residual_ar_order))
    res.diagnostics.warnings.push_back(detail::format(
        "{} route: parameter standard deviations assume independent residuals; they are indicative", route));
  // The window must make G(s + a) stable: a > max Re(poles) of the fitted plant (GW-A2 step 1).
  const Eigen::VectorXcd poles = res.model.poles();
  double slowest = -INFINITY;
  for (Eigen::Index i = 0; i < poles.size(); ++i) slowest = std::max(slowest, poles(i).real());
  res.diagnostics.set(diagnostic::max_pole_real_part, slowest);
  if (poles.size() > 0 && !(a > slowest))
    res.diagnostics.warnings.push_back(detail::format(
        "the window a = {} does not exceed the largest real part of the fitted plant's poles ({}): G(s + a) is not "
        "stable and {}; increase a",
        a, slowest,
        std::string(route) == "raw"
            ? "the windowed simulation e^(-a t) y(t) the fit compares grows over the record, so the record's end "
              "dominates the fit"
            : "the compressed response is not meaningful"));
  internal::set_termination(res.summary, lm, "the model cannot be evaluated at the initial parameters",
                            verdict.unidentifiable, verdict.at_bound);
  res.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return res;
}

}  // namespace

namespace {
// Exact response of g (already shifted to G(s + a)) to the windowed held input
// u_a(t) = e^{-a t} u_k on [t_k, t_{k+1}): the input's generator v' = -a v is appended to the
// state and reset to e^{-a (t_k - t_0)} u_k at every sample (uniform sampling).
Eigen::VectorXd windowed_zoh_response(const TransferFunction& g, const Eigen::VectorXd& u, double h, double a) {
  const StateSpace ss = g.to_state_space();
  const int n = ss.nx();
  Eigen::MatrixXd Aa = Eigen::MatrixXd::Zero(n + 1, n + 1);
  Aa.topLeftCorner(n, n) = ss.A();
  Aa.topRightCorner(n, 1) = ss.B();
  Aa(n, n) = -a;
  const Eigen::MatrixXd Phi = expm(Aa * h);
  Eigen::VectorXd y(u.size()), z = Eigen::VectorXd::Zero(n + 1), zn(n + 1);
  for (Eigen::Index k = 0; k < u.size(); ++k) {
    const double v = std::exp(-a * h * double(k)) * u(k);
    y(k) = (ss.C() * z.head(n))(0) + ss.D()(0, 0) * v;
    z(n) = v;
    zn.noalias() = Phi * z;
    z = zn;
  }
  return y;
}

// Records (experiments of one system) as the raw route measures them: the outputs stacked, windowed by e^{-at} from
// each record's start when a > 0, and a model G(s + a) simulated from rest on each record's (windowed) input.
struct WindowedRecords {
  std::span<const IdData> records;
  double a;
  Eigen::VectorXd y;

  WindowedRecords(std::span<const IdData> ds, double window) : records(ds), a(window) {
    Eigen::Index n = 0;
    for (std::size_t e = 0; e < records.size(); ++e) {
      const IdData& d = records[e];
      const std::string who = records.size() > 1 ? "physical (record " + std::to_string(e + 1) + ")" : "physical";
      require_io_data(d, who.c_str());
      CTID_REQUIRE(a == 0.0 || (d.is_uniform() && d.intersample(0) == Intersample::Zoh),
                   "{}: the windowed raw route (a > 0) needs uniformly sampled data with a held (ZOH) input", who);
      n += d.size();
    }
    y.resize(n);
    for (Eigen::Index e = 0, at = 0; e < static_cast<Eigen::Index>(records.size()); at += records[e].size(), ++e) {
      const IdData& d = records[e];
      const Eigen::VectorXd t = d.times();
      y.segment(at, d.size()) = d.y().col(0);
      if (a > 0) y.segment(at, d.size()).array() *= (-a * (t.array() - t(0))).exp();  // y_a = e^{-at} y
    }
  }
  // Model output for the (windowed) input: exact for the held input in both cases.
  Eigen::VectorXd simulate(const TransferFunction& shifted) const {
    Eigen::VectorXd out(y.size());
    for (Eigen::Index e = 0, at = 0; e < static_cast<Eigen::Index>(records.size()); at += records[e].size(), ++e) {
      const IdData& d = records[e];
      out.segment(at, d.size()) = a > 0 ? windowed_zoh_response(shifted, d.u().col(0), d.ts(), a) : lsim(shifted, d, 0);
    }
    return out;
  }
};

// An FSF route's result: its fit to the compressed response becomes diagnostics compressed_fit_percent; fit is the
// simulation fit on the record (as the raw route measures it) when the record is given, else not computed.
Result<TransferFunction> with_simulation_fit(Result<TransferFunction> r, const PhysicalModel& model, double a,
                                             const IdData* data) {
  r.diagnostics.set(diagnostic::compressed_fit_percent, r.fit.fit_percent);
  const int p = r.fit.n_parameters;
  r.fit = FitReport{};
  r.fit.n_parameters = p;
  if (!data) return r;
  const WindowedRecords w(std::span<const IdData>(data, 1), a);
  r.fit = fit_report_or_inf(w.y, w.simulate(model.shifted(r.parameters.values, a)), p);
  return r;
}
}  // namespace


Result<TransferFunction> fit_physical_step(const PhysicalModel& model, const std::vector<PhysicalParameter>& params,
                                           const FsfModel& fsf, const PhysicalFitOptions& opt, const IdData* data) {
  opt.validate();
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(opt.step_points, 0.0, fsf.T());
  const Eigen::VectorXd target = fsf.step_response(t);
  CTID_REQUIRE_OPTION(!opt.estimate_initial_state, "physical: estimate_initial_state applies to the raw route (--via "
                      "raw); the FSF routes compress the record from rest");
  ResidualFn res = [&](const Eigen::VectorXd&, const std::vector<int>&, const TransferFunction& g,
                       const std::vector<TransferFunction>* sens, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
    r = step_response(g, t) - target;  // e = y_model - y_s (GW 22)
    if (J) {
      J->resize(t.size(), static_cast<Eigen::Index>(sens->size()));
      for (std::size_t j = 0; j < sens->size(); ++j) J->col(static_cast<Eigen::Index>(j)) = step_response((*sens)[j], t);
    }
  };
  return with_simulation_fit(fit(model, params, fsf.shift(), opt, res, target, "step"), model, fsf.shift(), data);
}

Result<TransferFunction> fit_physical_frequency(const PhysicalModel& model, const std::vector<PhysicalParameter>& params,
                                                const FsfModel& fsf, const PhysicalFitOptions& opt, const IdData* data) {
  const int m = fsf.m();
  Eigen::VectorXd w(m + 1);
  Eigen::VectorXcd target(m + 1);
  for (int k = 0; k <= m; ++k) {
    w(k) = k * fsf.omega();
    target(k) = fsf.theta_k(k);
  }
  CTID_REQUIRE_OPTION(!opt.estimate_initial_state, "physical: estimate_initial_state applies to the raw route (--via "
                      "raw); the FSF routes compress the record from rest");
  ResidualFn res = [&](const Eigen::VectorXd&, const std::vector<int>&, const TransferFunction& g,
                       const std::vector<TransferFunction>* sens, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
    const Eigen::VectorXcd e = g.frequency_response(w) - target;  // E(jw) of GW 30, real and imaginary parts
    r.resize(2 * (m + 1));
    r << e.real(), e.imag();
    if (J) {
      J->resize(2 * (m + 1), static_cast<Eigen::Index>(sens->size()));
      for (std::size_t j = 0; j < sens->size(); ++j) {
        const Eigen::VectorXcd d = (*sens)[j].frequency_response(w);
        J->col(static_cast<Eigen::Index>(j)) << d.real(), d.imag();
      }
    }
  };
  Eigen::VectorXd stacked(2 * (m + 1));
  stacked << target.real(), target.imag();
  return with_simulation_fit(fit(model, params, fsf.shift(), opt, res, stacked, "frequency"), model, fsf.shift(),
                             data);
}

namespace {
// fit_physical_raw of one record or of several, without copying them (one record: a span of one).
Result<TransferFunction> fit_physical_raw_records(const PhysicalModel& model, const std::vector<PhysicalParameter>& params,
                                                  std::span<const IdData> records, double a, const PhysicalFitOptions& opt) {
  CTID_REQUIRE(!records.empty(), "physical: no records");
  CTID_REQUIRE(std::isfinite(a) && a >= 0, "physical: the window a must be >= 0 (got {})", a);
  // Several records (experiments of one system): their residuals stacked, each record simulated from rest and
  // windowed from its own start.
  const WindowedRecords w(records, a);
  const Eigen::Index n = w.y.size();
  int nx = 0;  // the realisation's order (at the starting values; fixed by the model's structure), 0: from rest
  std::vector<Eigen::VectorXd> since_start;  // each record's times from its first sample
  for (const IdData& d : records) since_start.push_back(d.times().array() - d.times()(0));
  // Initial states (estimate_initial_state): record e adds the free response C e^{(A - aI)(t - t_0)} x0_e of the
  // model's realisation (PhysicalModel::realisation; windowed like the record). x0_e enters linearly and is eliminated
  // by variable projection (Golub & Pereyra 1973; Kaufman 1975): at given parameters it is the least-squares fit of
  // the record's output error, the residual is that error's projection P r_e, and the Jacobian P (S_e + d(Phi_e
  // x0_e)/dTheta) (the free response's derivative through the sensitivity equations) — whose Gram is the parameters'
  // information with the initial states eliminated, so the covariance accounts for them.
  ResidualFn res = [&](const Eigen::VectorXd& theta, const std::vector<int>& free, const TransferFunction& g,
                       const std::vector<TransferFunction>* sens, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
    r = w.simulate(g) - w.y;
    if (J) {
      J->resize(n, static_cast<Eigen::Index>(sens->size()));
      for (std::size_t j = 0; j < sens->size(); ++j) J->col(static_cast<Eigen::Index>(j)) = w.simulate((*sens)[j]);
    }
    if (nx == 0) return;
    const StateSpaceWithGradient m = model.realisation(theta, a);
    if (m.model.nx() != nx) {  // the expression's degree dropped at these values (a leading coefficient vanished)
      r.setConstant(NAN);      // rejected by the search
      return;
    }
    const Eigen::MatrixXd zero_b = Eigen::MatrixXd::Zero(nx, 1), zero_d = Eigen::MatrixXd::Zero(1, 1);
    const StateSpace free_system(m.model.A(), zero_b, m.model.C(), zero_d);
    for (Eigen::Index e = 0, at = 0; e < static_cast<Eigen::Index>(records.size()); at += records[e].size(), ++e) {
      const Eigen::VectorXd& tt = since_start[static_cast<size_t>(e)];
      const Eigen::MatrixXd u0 = Eigen::MatrixXd::Zero(tt.size(), 1);
      auto free_response = [&](const StateSpace& sys, const Eigen::VectorXd& x0) {
        LsimOptions lo;
        lo.x0 = x0;
        return Eigen::VectorXd(lsim(sys, u0, tt, {Intersample::Zoh}, lo).col(0));
      };
      Eigen::MatrixXd Phi(tt.size(), nx);
      for (int i = 0; i < nx; ++i) Phi.col(i) = free_response(free_system, Eigen::VectorXd::Unit(nx, i));
      const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> qr(Phi);
      const Eigen::VectorXd x0 = qr.solve(Eigen::VectorXd(-r.segment(at, tt.size())));
      r.segment(at, tt.size()) += Phi * x0;
      if (!J) continue;
      Eigen::MatrixXd Je = J->middleRows(at, tt.size());
      for (std::size_t j = 0; j < free.size(); ++j) {
        // d/dTheta_j of C e^{At} x0: the sensitivity system [x; dx]' = [A 0; dA A][x; dx], y = [dC C][x; dx].
        const StateSpace& d = m.derivatives[static_cast<size_t>(free[j])];
        Eigen::MatrixXd A2 = Eigen::MatrixXd::Zero(2 * nx, 2 * nx), C2(1, 2 * nx);
        A2.topLeftCorner(nx, nx) = m.model.A();
        A2.bottomLeftCorner(nx, nx) = d.A();
        A2.bottomRightCorner(nx, nx) = m.model.A();
        C2 << d.C(), m.model.C();
        Eigen::VectorXd z0 = Eigen::VectorXd::Zero(2 * nx);
        z0.head(nx) = x0;
        Je.col(static_cast<Eigen::Index>(j)) +=
            free_response(StateSpace(A2, Eigen::MatrixXd::Zero(2 * nx, 1), C2, zero_d), z0);
      }
      J->middleRows(at, tt.size()) = Je - Phi * qr.solve(Je);  // the projection onto the complement of Phi
    }
  };
  auto initial_states = [&](const Eigen::VectorXd& theta0) {
    nx = opt.estimate_initial_state ? model.realisation(theta0, a).model.nx() : 0;
    return nx * static_cast<int>(records.size());
  };
  // Unwindowed residuals are stationary: their colour enters the covariance (each record a sequence).
  std::vector<internal::ResidualSequence> sequences;
  if (a == 0.0)
    for (Eigen::Index e = 0, at = 0; e < static_cast<Eigen::Index>(records.size()); at += records[e].size(), ++e)
      sequences.push_back({at, records[e].size(), 0});
  Result<TransferFunction> r = fit(model, params, a, opt, res, w.y, "raw", initial_states, sequences);
  if (records.size() > 1) r.diagnostics.set(diagnostic::experiments, static_cast<double>(records.size()));
  if (nx > 0 && r.model.den().coefficients().allFinite()) {
    // Each record's initial state in the fitted transfer function's realisation (what simulate and validate start
    // from): the least-squares state of simulate(Estimated) on the record.
    SimulateOptions so;
    so.initial = InitialCondition::Estimated;
    for (std::size_t e = 0; e < records.size(); ++e)
      r.diagnostics.set(diagnostic::x0, simulate(AnyModel(r.model), records[e], so).x0, static_cast<int>(e));
  }
  return r;
}
}  // namespace

Result<TransferFunction> fit_physical_raw(const PhysicalModel& model, const std::vector<PhysicalParameter>& params,
                                          const IdData& data, double a, const PhysicalFitOptions& opt) {
  return fit_physical_raw_records(model, params, std::span<const IdData>(&data, 1), a, opt);
}

Result<TransferFunction> fit_physical_raw(const PhysicalModel& model, const std::vector<PhysicalParameter>& params,
                                          const std::vector<IdData>& records, double a, const PhysicalFitOptions& opt) {
  return fit_physical_raw_records(model, params, records, a, opt);
}

}  // namespace ctid
