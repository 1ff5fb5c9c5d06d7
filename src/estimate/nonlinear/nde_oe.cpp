// Output-error refinement of an NDE model (see include/ctid/estimate/nonlinear/nde_oe.hpp; Ljung 1999 ch. 7): the problem
// with its exact forward sensitivities, searched by the multi-start driver of estimate/search.hpp.
#include "ctid/estimate/nonlinear/nde_oe.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "ctid/core/check.hpp"
#include "ctid/validate/metrics.hpp"
#include "data/record_refs.hpp"
#include "estimate/search.hpp"
#include "internal/levenberg_marquardt.hpp"
#include "internal/ode.hpp"

namespace ctid {

template <>
const OptionTable<NdeOeOptions>& option_table<NdeOeOptions>() {
  using O = NdeOeOptions;
  static const OptionTable<O> t =
      OptionTable<O>("nde_oe")
          .integer("max_iterations", &O::max_iterations, "", at_least(1), "Levenberg-Marquardt iterations")
          .real("tolerance", &O::tolerance, "", OptionRange{0, 1, true, true, {}, {}},
                "relative cost decrease or parameter change that stops the search")
          .flag("estimate_initial_state", &O::estimate_initial_state,
                "estimate [y, Dy, ..] at the first sample; 0: start from rest")
          .named_reals("fixed", &O::fixed,
                       "coefficients held at a value, by term name (fixed.u=-1.1; the reference term's coefficient is 1)")
          .named_bounds("bounds", &O::bounds, "bounds on free coefficients by term name (bounds.y^2=0,inf)")
          .real("rtol", &O::rtol, "", between(1e-13, 1e-6), "relative tolerance of the simulations (the Jacobian needs accuracy)")
          .integer("starts", &O::starts, "", at_least(1),
                   "multi-start: the starting model plus starts-1 drawn coefficient sets (within finite bounds, else "
                   "within a decade of the start's value; the lowest cost wins)")
          .integer("seed", &O::seed, "", at_least(0), "seed of the drawn starts");
  return t;
}

void NdeOeOptions::validate() const { option_table<NdeOeOptions>().check(*this); }

namespace {
// The output-error problem of an NDE model over a record set: the search vector
//     x = [free coefficients (pc) | initial state of record 1 (nx) | of record 2 | ..]
// (every record has its own initial state: several experiments of one system), the records concatenated (record
// e's samples are rows [start[e], start[e] + size) of the residual), the residuals y - yhat and their Jacobian from
// the forward sensitivities.
struct Problem {
  const std::vector<NdeTerm>& terms;
  const NdeOeOptions& opt;
  int m = 0, L = 0, ref = -1, top = -1;
  ParameterConstraints cons;
  Eigen::VectorXd c_init;   // the starting coefficients in the reference term's scale, held ones at their values
  std::vector<int> free;
  int pc = 0, nx = 0, p = 0, E = 0, N = 0;
  Eigen::VectorXd lo, hi;
  std::vector<Eigen::VectorXd> us, ys, ts;
  std::vector<Intersample> holds;
  std::vector<Eigen::Index> starts;
  Eigen::VectorXd y;

  Problem(const internal::RecordRefs& records, const NdeModel& initial, const NdeOeOptions& options);
  Eigen::VectorXd x0_of(const Eigen::VectorXd& x, int e) const {
    return nx ? Eigen::VectorXd(x.segment(pc + e * nx, nx)) : Eigen::VectorXd();
  }
  Eigen::VectorXd coefficients(const Eigen::VectorXd& x) const {
    Eigen::VectorXd c = c_init;
    for (int j = 0; j < pc; ++j) c(free[static_cast<size_t>(j)]) = x(j);
    return c;
  }
  bool simulate(const Eigen::VectorXd& x, Eigen::VectorXd& out) const;
  bool record_sensitivities(const Eigen::VectorXd& x, int e, Eigen::VectorXd& yhat, Eigen::MatrixXd& S) const;
  bool evaluate(const Eigen::VectorXd& x, Eigen::VectorXd& r, Eigen::MatrixXd* J) const;
  Eigen::VectorXd start(double& start_scale) const;
};

Problem::Problem(const internal::RecordRefs& records, const NdeModel& initial, const NdeOeOptions& options)
    : terms(initial.terms()), opt(options), m(static_cast<int>(initial.terms().size())), E(static_cast<int>(records.size())) {
  for (int e = 0; e < E; ++e) {
    const std::string who = E > 1 ? "nde_oe (record " + std::to_string(e + 1) + ")" : "nde_oe";
    require_io_data(records[static_cast<size_t>(e)], who.c_str());
  }
  // Order of the model (number of states) and the reference term.
  for (const auto& term : terms)
    for (const auto& f : term.factors)
      if (!f.input) L = std::max(L, f.derivative);
  for (int i = 0; i < m; ++i) {
    const auto& f = terms[static_cast<size_t>(i)].factors;
    if (f.size() == 1 && !f[0].input && f[0].derivative == 0) ref = i;
    if (f.size() == 1 && !f[0].input && f[0].derivative == L) top = i;
  }
  if (ref < 0) ref = top;
  CTID_REQUIRE(ref >= 0, "nde_oe: the model {} has neither y nor a linear highest derivative of y", initial.to_string());
  // Constraints by term name (fixed.NAME, bounds.NAME), in the scale where the reference coefficient is 1.
  std::vector<std::string> names;
  for (const auto& t : terms) names.push_back(t.name());
  if (const auto f = opt.fixed.find(names[static_cast<size_t>(ref)]); f != opt.fixed.end())
    CTID_REQUIRE_OPTION(f->second == 1.0, "nde_oe: fixed.{}: the reference term's coefficient is 1 (got {})", f->first,
                        f->second);
  std::vector<bool> held(static_cast<size_t>(m), false);
  held[static_cast<size_t>(ref)] = true;
  cons = resolve_constraints(opt.fixed, opt.bounds, names, "nde_oe", "a term of " + initial.to_string(), held);
  c_init = initial.coefficients() / initial.coefficients()(ref);
  for (int i = 0; i < m; ++i)
    if (std::isfinite(cons.value(i))) c_init(i) = cons.value(i);
  free = cons.free();
  pc = static_cast<int>(free.size());
  nx = opt.estimate_initial_state ? L : 0;
  p = pc + E * nx;
  lo = Eigen::VectorXd::Constant(p, -INFINITY);
  hi = Eigen::VectorXd::Constant(p, INFINITY);
  for (int j = 0; j < pc; ++j) {
    lo(j) = cons.lower(free[j]);
    hi(j) = cons.upper(free[j]);
  }
  us.resize(E);
  ys.resize(E);
  ts.resize(E);
  holds.resize(E);
  starts.resize(E);
  for (int e = 0; e < E; ++e) {
    const IdData& d = records[static_cast<size_t>(e)];
    starts[e] = N;
    N += d.size();
    us[e] = d.u().col(0);
    ys[e] = d.y().col(0);
    ts[e].resize(d.size());
    for (int k = 0; k < d.size(); ++k) ts[e](k) = d.time(k) - d.t0();
    holds[e] = d.intersample(0) == Intersample::Zoh ? Intersample::Zoh : Intersample::Foh;
  }
  CTID_REQUIRE(N > p, "nde_oe: {} samples for {} free parameters", N, p);
  y.resize(N);
  for (int e = 0; e < E; ++e) y.segment(starts[e], ys[e].size()) = ys[e];
}

bool Problem::simulate(const Eigen::VectorXd& x, Eigen::VectorXd& out) const {
  const NdeModel model(terms, coefficients(x));
  out.resize(N);
  for (int e = 0; e < E; ++e) {
    const NdeSimulation s = model.simulate(us[e], ts[e], holds[e], x0_of(x, e), opt.rtol);
    out.segment(starts[e], ys[e].size()) = s.y;
    if (!s.ok()) return false;
  }
  return true;
}

// Start: the given coefficients, each record's y(0) measured and its derivatives 0 (differences of noisy samples
// are worse); when that simulation escapes, the free nonlinear coefficients are halved until it does not.
Eigen::VectorXd Problem::start(double& start_scale) const {
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(p);
  for (int e = 0; e < E && nx; ++e) x0(pc + e * nx) = ys[e](0);
  Eigen::VectorXd ystart;
  for (int shrink = 0;; ++shrink) {
    start_scale = shrink > 30 ? 0.0 : std::ldexp(1.0, -shrink);
    for (int j = 0; j < pc; ++j) {
      const int i = free[static_cast<size_t>(j)];
      x0(j) = c_init(i) * (terms[static_cast<size_t>(i)].degree() >= 2 ? start_scale : 1.0);
    }
    if (simulate(x0, ystart) || start_scale == 0.0) break;
  }
  return x0;
}

// Forward sensitivities (analytic, not differences). With x = [y, Dy, .., D^{L-1}y] and the explicit form
// D^L y = f_L(x, u) = -(1/c_top) sum_{i != top} c_i phi_i(x, u), the sensitivity S_j = dx/dtheta_j obeys
// S_j' = [S_j(1..L-1); grad_x f_L . S_j + df_L/dtheta_j], with df_L/dc_i = -phi_i/c_top (i != top),
// df_L/dc_top = -f_L/c_top, 0 for the initial state, and S_j(0) = e_k for theta_j = D^k y(0).
// Per record the sensitivities of its pc coefficients and its own nx initial states (q columns); the other
// records' initial states do not move its output.
bool Problem::record_sensitivities(const Eigen::VectorXd& x, int e, Eigen::VectorXd& yhat, Eigen::MatrixXd& S) const {
  const int q = pc + nx;
  const Eigen::Index nz = L + static_cast<Eigen::Index>(L) * q;
  Eigen::VectorXd phi(m), grad(L);
  const Eigen::VectorXd c = coefficients(x);
  const double ctop = c(top);
  internal::OdeRhs rhs = [&](double, const Eigen::VectorXd& z, const double* ui, Eigen::VectorXd& dz) {
    const double uu = ui[0];
    grad.setZero();
    double sum = 0;
    for (int i = 0; i < m; ++i) {
      if (i == top) continue;
      const auto& fs = terms[static_cast<size_t>(i)].factors;
      double v = 1;
      for (const auto& fa : fs) v *= fa.input ? uu : z(fa.derivative);
      phi(i) = v;
      sum += c(i) * v;
      for (size_t k = 0; k < fs.size(); ++k) {  // d phi_i / d x_k by the product rule
        if (fs[k].input) continue;
        double others = c(i);
        for (size_t r2 = 0; r2 < fs.size(); ++r2)
          if (r2 != k) others *= fs[r2].input ? uu : z(fs[r2].derivative);
        grad(fs[k].derivative) += others;
      }
    }
    const double fl = -sum / ctop;
    grad /= -ctop;
    dz.head(L - 1) = z.segment(1, L - 1);
    dz(L - 1) = fl;
    for (int j = 0; j < q; ++j) {
      const Eigen::Index o = L + static_cast<Eigen::Index>(L) * j;
      dz.segment(o, L - 1) = z.segment(o + 1, L - 1);
      double b = 0;
      if (j < pc) {
        const int i = free[static_cast<size_t>(j)];
        b = i == top ? -fl / ctop : -phi(i) / ctop;
      }
      dz(o + L - 1) = grad.dot(z.segment(o, L)) + b;
    }
  };
  Eigen::VectorXd z0 = Eigen::VectorXd::Zero(nz);
  if (nx) z0.head(L) = x0_of(x, e);
  for (int k = 0; k < nx; ++k) z0(L + static_cast<Eigen::Index>(L) * (pc + k) + k) = 1.0;
  const Eigen::Index n = ys[e].size();
  yhat.resize(n);
  S.resize(n, q);
  return internal::dopri45(rhs, z0, us[e], ts[e],
                           holds[e] == Intersample::Zoh ? internal::Between::Hold : internal::Between::Linear, opt.rtol,
                           1e-12, L,
                           [&](Eigen::Index k, const Eigen::VectorXd& z) {
                             yhat(k) = z(0);
                             for (int j = 0; j < q; ++j) S(k, j) = z(L + static_cast<Eigen::Index>(L) * j);
                           })
      .ok;
}

// The residuals and the stacked Jacobian (coefficients shared; record e's initial state only in its rows).
bool Problem::evaluate(const Eigen::VectorXd& x, Eigen::VectorXd& r, Eigen::MatrixXd* J) const {
  Eigen::VectorXd yx;
  if (!J) {
    if (!simulate(x, yx)) return false;
    r = y - yx;
    return true;
  }
  yx.resize(N);
  J->setZero(N, p);
  Eigen::VectorXd ye;
  Eigen::MatrixXd Se;
  for (int e = 0; e < E; ++e) {
    if (!record_sensitivities(x, e, ye, Se)) return false;
    const Eigen::Index n = ys[e].size();
    yx.segment(starts[e], n) = ye;
    J->block(starts[e], 0, n, pc) = -Se.leftCols(pc);
    if (nx) J->block(starts[e], pc + e * nx, n, nx) = -Se.rightCols(nx);
  }
  r = y - yx;
  return true;
}

// The result of the search: the model, every coefficient and initial state, the covariance, the fit.
Result<NdeModel> result_of(const Problem& P, const search::MultiStartResult& run, double start_scale) {
  const internal::LmResult& lm = run.best;
  const int m = P.m, nx = P.nx, E = P.E;
  Result<NdeModel> r;
  const Eigen::VectorXd c = P.coefficients(lm.x);
  r.model = NdeModel(P.terms, c);
  const int np = m + E * nx;
  r.parameters.names.resize(static_cast<size_t>(np));
  r.parameters.values.resize(np);
  r.parameters.fixed.assign(static_cast<size_t>(np), false);
  for (int i = 0; i < m; ++i) {
    r.parameters.names[static_cast<size_t>(i)] = P.terms[static_cast<size_t>(i)].name();
    r.parameters.values(i) = c(i);
    r.parameters.fixed[static_cast<size_t>(i)] = P.cons.held[static_cast<size_t>(i)];
  }
  // Initial states: "y(0)", "Dy(0)", ..; with several records "r<e>.y(0)", ...
  for (int e = 0; e < E; ++e)
    for (int k = 0; k < nx; ++k) {
      const std::string state = k == 0 ? "y(0)" : (k == 1 ? "Dy(0)" : "D^" + std::to_string(k) + "y(0)");
      r.parameters.names[static_cast<size_t>(m + e * nx + k)] = E > 1 ? "r" + std::to_string(e + 1) + "." + state : state;
      r.parameters.values(m + e * nx + k) = lm.x(P.pc + e * nx + k);
    }
  std::vector<int> slot(P.free);
  for (int k = 0; k < E * nx; ++k) slot.push_back(m + k);
  const double sigma2 = 2.0 * lm.cost / std::max(1, P.N - P.p);
  std::vector<internal::ResidualSequence> sequences;  // each record, in time order
  for (int e = 0; e < E; ++e)
    sequences.push_back({P.starts[static_cast<size_t>(e)], P.ys[static_cast<size_t>(e)].size(), 0});
  const search::CovarianceVerdict verdict =
      search::set_covariance(r.parameters, r.diagnostics, lm, slot, sigma2, {P.lo, P.hi}, sequences);
  // The first record's initial state is "x0" (what simulate()'s estimated initial condition takes); further
  // records' are "x0_2", "x0_3", ...
  for (int e = 0; e < E; ++e)
    r.diagnostics.set(diagnostic::x0, nx ? P.x0_of(lm.x, e) : Eigen::VectorXd::Zero(P.L), e);
  if (E > 1) r.diagnostics.set(diagnostic::experiments, E);
  r.diagnostics.set(diagnostic::noise_variance, sigma2);
  r.diagnostics.set(diagnostic::start_scale, start_scale);
  if (P.opt.starts > 1) r.diagnostics.set(diagnostic::starts_cost, run.costs);
  if (start_scale < 1.0)
    r.diagnostics.warnings.push_back(detail::format(
        "the starting model escapes on these data; the search started with its nonlinear coefficients times {}",
        start_scale));
  const std::string failure = "the model cannot be simulated on these data, even with its nonlinear terms removed";
  internal::set_termination(r.summary, lm, failure, verdict.unidentifiable, verdict.at_bound);
  Eigen::VectorXd yfit;
  if (!std::isfinite(lm.cost) || !P.simulate(lm.x, yfit)) {
    r.summary.termination = Termination::NumericalFailure;
    r.summary.message = failure;
    yfit = Eigen::VectorXd::Constant(P.N, NAN);
  }
  r.fit = fit_report_or_inf(P.y, yfit, P.p);
  return r;
}

// nde_oe of one record or of several, without copying them.
Result<NdeModel> nde_oe_records(const internal::RecordRefs& records, const NdeModel& initial, const NdeOeOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  opt.validate();
  CTID_REQUIRE(!records.empty(), "nde_oe: no records");
  const Problem P(records, initial, opt);
  double start_scale = 1.0;
  const Eigen::VectorXd x0 = P.start(start_scale);
  internal::LmOptions lmo;
  lmo.max_iterations = opt.max_iterations;
  lmo.ftol = opt.tolerance;
  lmo.xtol = opt.tolerance;
  lmo.keep_jacobian = true;  // the covariance allows for coloured residuals (search::set_covariance)
  const internal::LmEvaluate evaluate = [&P](const Eigen::VectorXd& x, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
    return P.evaluate(x, r, J);
  };
  const search::MultiStartResult run = search::multi_start(
      [&](const Eigen::VectorXd& v) { return internal::levenberg_marquardt(evaluate, v, P.lo, P.hi, lmo); }, x0, P.lo,
      P.hi, {opt.starts, static_cast<std::uint64_t>(opt.seed), P.pc});
  Result<NdeModel> r = result_of(P, run, start_scale);
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}
}  // namespace

Result<NdeModel> nde_oe(const IdData& data, const NdeModel& initial, const NdeOeOptions& opt) {
  return nde_oe_records(data, initial, opt);
}

Result<NdeModel> nde_oe(const std::vector<IdData>& records, const NdeModel& initial, const NdeOeOptions& opt) {
  return nde_oe_records(records, initial, opt);
}

}  // namespace ctid
