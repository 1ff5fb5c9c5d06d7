// ctid — nonlinear grey-box identification by output error with exact forward sensitivities (see
// include/ctid/estimate/greybox/greybox.hpp; Ljung 1999 §7.3; Bohlin 2006): the problem (problem.hpp), multiple shooting
// where the plant does not run free (multiple_shooting.hpp; Bock & Plitt 1984), the multi-start search
// (estimate/search.hpp).
#include "ctid/estimate/greybox/greybox.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include "ctid/core/check.hpp"
#include "ctid/validate/metrics.hpp"
#include "estimate/greybox/multiple_shooting.hpp"
#include "estimate/greybox/problem.hpp"
#include "estimate/search.hpp"

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
          .choice("integrator", &O::integrator,
                  {{"auto", GreyboxIntegrator::Auto}, {"explicit", GreyboxIntegrator::Explicit}, {"bdf", GreyboxIntegrator::Bdf}},
                  "explicit: Dormand-Prince 5(4); bdf: CVODES's BDF with the exact Jacobian (stiff models); auto: "
                  "Dormand-Prince, BDF where it needs more than 200 steps per sample")
          .integer("segments", &O::segments, "", at_least(0),
                   "multiple shooting: each record split into this many segments, each from a free state tied to the "
                   "previous segment's end; 1: single shooting; 0: automatic (multiple shooting when the free run from the "
                   "start escapes or drifts, fit below -900 %: segments of 100 samples, halved down to 4 until each "
                   "simulates from the start)")
          .flag("estimate_initial_state", &O::estimate_initial_state,
                "estimate the initial states the model marks \"estimate\" (one per record); 0: hold them at their start")
          .named_reals("fixed", &O::fixed, "parameters held at a value by name (fixed.k1=0.05), on top of the model's")
          .named_bounds("bounds", &O::bounds, "bounds on parameters by name (bounds.k1=0,inf), replacing the model's");
  return t;
}

void GreyboxOptions::validate() const { option_table<GreyboxOptions>().check(*this); }

namespace {
using greybox_detail::Problem;

// The result of a fit from its best search (x: the problem's v).
Result<GreyboxModel> result_of(Problem& P, const internal::LmResult& best, const search::MultiStartResult& run,
                               const greybox_detail::MultipleShooting* shooting, const Eigen::VectorXd& segment_fit) {
  const GreyboxModel& model = P.model;
  const int E = P.E, np = P.np, nx0 = P.nx0, pf = P.pf;
  Result<GreyboxModel> r;
  const GreyboxModel fitted = P.model_at(best.x);
  r.model = fitted.with_estimated_initial(P.x0_of(fitted, best.x, 0));
  const int total = np + E * nx0;
  r.parameters.names = model.parameter_names();
  r.parameters.values.resize(total);
  r.parameters.values.head(np) = fitted.parameter_values();
  r.parameters.fixed.assign(static_cast<size_t>(total), false);
  for (int i = 0; i < np; ++i) r.parameters.fixed[static_cast<size_t>(i)] = P.cons.held[i];
  for (int e = 0; e < E; ++e)
    for (int k = 0; k < nx0; ++k) {
      const std::string st = model.spec().states[static_cast<size_t>(P.free_x0[static_cast<size_t>(k)])] + "(0)";
      r.parameters.names.push_back(E > 1 ? detail::format("r{}.{}", e + 1, st) : st);
      r.parameters.values(np + e * nx0 + k) = best.x(pf + e * nx0 + k);
    }
  std::vector<int> slot(P.free);
  for (int k = 0; k < E * nx0; ++k) slot.push_back(np + k);
  const double sigma2 = 2.0 * best.cost / std::max<double>(1.0, static_cast<double>(P.N) * P.ny - P.p);
  std::vector<internal::ResidualSequence> sequences;  // each output of each record, in time order
  for (const auto& d : P.rec)
    for (int j = 0; j < P.ny; ++j) sequences.push_back({d.start + static_cast<Eigen::Index>(j) * d.n, d.n, j});
  const search::CovarianceVerdict verdict =
      search::set_covariance(r.parameters, r.diagnostics, best, slot, sigma2, {P.lo, P.hi}, sequences);
  for (int e = 0; e < E; ++e) r.diagnostics.set(diagnostic::x0, P.x0_of(fitted, best.x, e), e);
  if (E > 1) r.diagnostics.set(diagnostic::experiments, E);
  r.diagnostics.set(diagnostic::noise_variance, P.ny == 1 ? sigma2 : NAN);
  if (P.opt.starts > 1) r.diagnostics.set(diagnostic::starts_cost, run.costs);
  if (shooting) {
    r.diagnostics.set(diagnostic::segments, shooting->segments());
    r.diagnostics.set(diagnostic::continuity_defect, shooting->defect());
  }
  const std::string failure = "the model cannot be simulated on these data from its start" +
                              std::string(P.opt.starts > 1 ? "s" : "") + (P.escape.empty() ? "" : ": " + P.escape);
  internal::set_termination(r.summary, best, failure, verdict.unidentifiable, verdict.at_bound);
  // The fit: all outputs of all records stacked, each weighted (one output: the output itself).
  Eigen::VectorXd rr;
  Eigen::VectorXd yfit = Eigen::VectorXd::Constant(P.y.size(), NAN);
  if (segment_fit.size()) yfit = segment_fit;
  else if (std::isfinite(best.cost) && P.evaluate(best.x, rr, nullptr)) yfit = P.wy - rr;
  else if (r.summary.succeeded()) {
    r.summary.termination = Termination::NumericalFailure;
    r.summary.message = failure;
  }
  r.fit = fit_report_or_inf(P.wy, yfit, P.p);
  return r;
}

// greybox of one record or of several, without copying them: the problem, multiple shooting where it is needed,
// the multi-start search, the result.
Result<GreyboxModel> greybox_records(const internal::RecordRefs& records, const GreyboxModel& model, const GreyboxOptions& opt) {
  const auto clock0 = std::chrono::steady_clock::now();
  opt.validate();
  Problem P(records, model, opt);
  std::optional<greybox_detail::MultipleShooting> shooting;
  if (greybox_detail::wants_multiple_shooting(P)) shooting.emplace(P, opt.segments);
  const search::MultiStartResult run = search::multi_start(
      [&](const Eigen::VectorXd& v) { return shooting ? shooting->search(v) : P.search(v); }, P.v0, P.lo, P.hi,
      {opt.starts, static_cast<std::uint64_t>(opt.seed), P.pf});
  internal::LmResult best = run.best;
  std::vector<std::string> warnings;
  Eigen::VectorXd segment_fit;  // the segments' weighted outputs when the multiple-shooting estimate stands
  if (shooting) shooting->settle(best, segment_fit, warnings);
  Result<GreyboxModel> r = result_of(P, best, run, shooting ? &*shooting : nullptr, segment_fit);
  r.diagnostics.warnings.insert(r.diagnostics.warnings.begin(), warnings.begin(), warnings.end());
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock0).count();
  return r;
}
}  // namespace

Result<GreyboxModel> greybox(const IdData& data, const GreyboxModel& model, const GreyboxOptions& opt) {
  return greybox_records(data, model, opt);
}

Result<GreyboxModel> greybox(const std::vector<IdData>& records, const GreyboxModel& model, const GreyboxOptions& opt) {
  return greybox_records(records, model, opt);
}

}  // namespace ctid
