// Output-error refinement of an NDE model (see include/ctid/estimate/nde_oe.hpp; Ljung 1999 ch. 7).
#include "ctid/estimate/nde_oe.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "ctid/core/check.hpp"
#include "ctid/validate/metrics.hpp"
#include "data/record_refs.hpp"
#include "internal/least_squares.hpp"
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
          .real("rtol", &O::rtol, "", between(1e-13, 1e-6), "relative tolerance of the simulations (the Jacobian needs accuracy)");
  return t;
}

void NdeOeOptions::validate() const { option_table<NdeOeOptions>().check(*this); }

namespace {
// nde_oe of one record or of several, without copying them.
Result<NdeModel> nde_oe_records(const internal::RecordRefs& records, const NdeModel& initial, const NdeOeOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  opt.validate();
  CTID_REQUIRE(!records.empty(), "nde_oe: no records");
  const int E = static_cast<int>(records.size());
  for (int e = 0; e < E; ++e) {
    const std::string who = E > 1 ? "nde_oe (record " + std::to_string(e + 1) + ")" : "nde_oe";
    require_io_data(records[static_cast<size_t>(e)], who.c_str());
  }
  const auto& terms = initial.terms();
  const int m = static_cast<int>(terms.size());
  // Order of the model (number of states) and the reference term.
  int L = 0;
  for (const auto& term : terms)
    for (const auto& f : term.factors)
      if (!f.input) L = std::max(L, f.derivative);
  int ref = -1, top = -1;
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
  const ParameterConstraints cons =
      resolve_constraints(opt.fixed, opt.bounds, names, "nde_oe", "a term of " + initial.to_string(), held);
  const std::vector<bool>& fixed = cons.held;
  Eigen::VectorXd c_init = initial.coefficients() / initial.coefficients()(ref);
  for (int i = 0; i < m; ++i)
    if (std::isfinite(cons.value(i))) c_init(i) = cons.value(i);
  const std::vector<int> free = cons.free();
  const int pc = static_cast<int>(free.size());
  Eigen::VectorXd lo_c(pc), hi_c(pc);
  for (int j = 0; j < pc; ++j) {
    lo_c(j) = cons.lower(free[j]);
    hi_c(j) = cons.upper(free[j]);
  }
  // Parameters x = [free coefficients (pc), initial state of record 1 (nx), of record 2, ...]: every record
  // has its own initial state (several experiments of one system).
  const int nx = opt.estimate_initial_state ? L : 0;
  const int p = pc + E * nx;
  // Records concatenated: record e's samples are rows [start[e], start[e] + size) of the residual vector.
  std::vector<Eigen::VectorXd> us(E), ys(E), ts(E);
  std::vector<Intersample> holds(E);
  std::vector<Eigen::Index> starts(E);
  int N = 0;
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
  Eigen::VectorXd y(N);
  for (int e = 0; e < E; ++e) y.segment(starts[e], ys[e].size()) = ys[e];
  auto x0_of = [&](const Eigen::VectorXd& x, int e) {
    return nx ? Eigen::VectorXd(x.segment(pc + e * nx, nx)) : Eigen::VectorXd();
  };

  auto coefficients = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd c = c_init;
    for (int j = 0; j < pc; ++j) c(free[static_cast<size_t>(j)]) = x(j);
    return c;
  };
  auto simulate = [&](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
    const NdeModel model(terms, coefficients(x));
    out.resize(N);
    for (int e = 0; e < E; ++e) {
      const NdeSimulation s = model.simulate(us[e], ts[e], holds[e], x0_of(x, e), opt.rtol);
      out.segment(starts[e], ys[e].size()) = s.y;
      if (!s.ok()) return false;
    }
    return true;
  };

  // Start: the given coefficients, each record's y(0) measured and its derivatives 0 (differences of noisy
  // samples are worse); when that simulation escapes, the free nonlinear coefficients are halved until it does not.
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(p);
  for (int e = 0; e < E && nx; ++e) x0(pc + e * nx) = ys[e](0);
  double start_scale = 1.0;
  Eigen::VectorXd ystart;
  for (int shrink = 0;; ++shrink) {
    start_scale = shrink > 30 ? 0.0 : std::ldexp(1.0, -shrink);
    for (int j = 0; j < pc; ++j) {
      const int i = free[static_cast<size_t>(j)];
      x0(j) = c_init(i) * (terms[static_cast<size_t>(i)].degree() >= 2 ? start_scale : 1.0);
    }
    if (simulate(x0, ystart) || start_scale == 0.0) break;
  }

  // Forward sensitivities (analytic, not differences). With x = [y, Dy, .., D^{L-1}y] and the
  // explicit form D^L y = f_L(x, u) = -(1/c_top) sum_{i != top} c_i phi_i(x, u), the sensitivity S_j = dx/dtheta_j
  // obeys S_j' = [S_j(1..L-1); grad_x f_L . S_j + df_L/dtheta_j], with df_L/dc_i = -phi_i/c_top (i != top),
  // df_L/dc_top = -f_L/c_top, 0 for the initial state, and S_j(0) = e_k for theta_j = D^k y(0).
  // Per record the sensitivities of its pc coefficients and its own nx initial states (q columns); the other
  // records' initial states do not move its output.
  const int q = pc + nx;
  const Eigen::Index nz = L + static_cast<Eigen::Index>(L) * q;
  Eigen::VectorXd phi(m), grad(L);
  auto record_sensitivities = [&](const Eigen::VectorXd& x, int e, Eigen::VectorXd& yhat, Eigen::MatrixXd& S) {
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
        for (size_t q = 0; q < fs.size(); ++q) {  // d phi_i / d x_k by the product rule
          if (fs[q].input) continue;
          double others = c(i);
          for (size_t r2 = 0; r2 < fs.size(); ++r2)
            if (r2 != q) others *= fs[r2].input ? uu : z(fs[r2].derivative);
          grad(fs[q].derivative) += others;
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
                             holds[e] == Intersample::Zoh ? internal::Between::Hold : internal::Between::Linear, opt.rtol, 1e-12, L,
                             [&](Eigen::Index k, const Eigen::VectorXd& z) {
                               yhat(k) = z(0);
                               for (int j = 0; j < q; ++j) S(k, j) = z(L + static_cast<Eigen::Index>(L) * j);
                             })
        .ok;
  };
  // The stacked output and Jacobian (coefficients shared; record e's initial state only in its rows).
  auto sensitivities = [&](const Eigen::VectorXd& x, Eigen::VectorXd& yhat, Eigen::MatrixXd& S) {
    yhat.resize(N);
    S = Eigen::MatrixXd::Zero(N, p);
    Eigen::VectorXd ye;
    Eigen::MatrixXd Se;
    for (int e = 0; e < E; ++e) {
      if (!record_sensitivities(x, e, ye, Se)) return false;
      const Eigen::Index n = ys[e].size();
      yhat.segment(starts[e], n) = ye;
      S.block(starts[e], 0, n, pc) = Se.leftCols(pc);
      if (nx) S.block(starts[e], pc + e * nx, n, nx) = Se.rightCols(nx);
    }
    return true;
  };
  auto evaluate = [&](const Eigen::VectorXd& x, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
    Eigen::VectorXd yx;
    if (!J) {
      if (!simulate(x, yx)) return false;
      r = y - yx;
      return true;
    }
    if (!sensitivities(x, yx, *J)) return false;
    r = y - yx;
    *J = -*J;
    return true;
  };
  internal::LmOptions lmo;
  lmo.max_iterations = opt.max_iterations;
  lmo.ftol = opt.tolerance;
  lmo.xtol = opt.tolerance;
  Eigen::VectorXd lo = Eigen::VectorXd::Constant(p, -INFINITY), hi = Eigen::VectorXd::Constant(p, INFINITY);
  lo.head(pc) = lo_c;
  hi.head(pc) = hi_c;
  const internal::LmResult lm = internal::levenberg_marquardt(evaluate, x0, lo, hi, lmo);

  Result<NdeModel> r;
  const Eigen::VectorXd c = coefficients(lm.x);
  r.model = NdeModel(terms, c);
  const int np = m + E * nx;
  r.parameters.names.resize(static_cast<size_t>(np));
  r.parameters.values.resize(np);
  r.parameters.fixed.assign(static_cast<size_t>(np), false);
  for (int i = 0; i < m; ++i) {
    r.parameters.names[static_cast<size_t>(i)] = terms[static_cast<size_t>(i)].name();
    r.parameters.values(i) = c(i);
    r.parameters.fixed[static_cast<size_t>(i)] = fixed[static_cast<size_t>(i)];
  }
  // Initial states: "y(0)", "Dy(0)", ..; with several records "r<e>.y(0)", ...
  for (int e = 0; e < E; ++e)
    for (int k = 0; k < nx; ++k) {
      const std::string state = k == 0 ? "y(0)" : (k == 1 ? "Dy(0)" : "D^" + std::to_string(k) + "y(0)");
      r.parameters.names[static_cast<size_t>(m + e * nx + k)] = E > 1 ? "r" + std::to_string(e + 1) + "." + state : state;
      r.parameters.values(m + e * nx + k) = lm.x(pc + e * nx + k);
    }
  std::vector<int> slot(free);
  for (int k = 0; k < E * nx; ++k) slot.push_back(m + k);
  const double sigma2 = 2.0 * lm.cost / std::max(1, N - p);
  std::vector<std::string> free_names;
  for (int j : slot) free_names.push_back(r.parameters.names[static_cast<size_t>(j)]);
  const std::string unidentifiable = internal::unidentifiable(lm.jtj, lm.x, free_names);
  r.parameters.set_covariance(unidentifiable.empty() ? internal::covariance(lm.jtj, sigma2) : Eigen::MatrixXd(), slot);
  r.diagnostics.condition_number = internal::gram_condition(lm.jtj);
  // The first record's initial state is "x0" (what simulate()'s estimated initial condition takes); further
  // records' are "x0_2", "x0_3", ...
  for (int e = 0; e < E; ++e)
    r.diagnostics.set(diagnostic::x0, nx ? x0_of(lm.x, e) : Eigen::VectorXd::Zero(L), e);
  if (E > 1) r.diagnostics.set(diagnostic::experiments, E);
  r.diagnostics.set(diagnostic::noise_variance, sigma2);
  r.diagnostics.set(diagnostic::start_scale, start_scale);
  if (start_scale < 1.0)
    r.diagnostics.warnings.push_back(detail::format(
        "the starting model escapes on these data; the search started with its nonlinear coefficients times {}",
        start_scale));
  const std::string failure = "the model cannot be simulated on these data, even with its nonlinear terms removed";
  internal::set_termination(r.summary, lm, failure, unidentifiable);
  Eigen::VectorXd yfit;
  if (!std::isfinite(lm.cost) || !simulate(lm.x, yfit)) {
    r.summary.termination = Termination::NumericalFailure;
    r.summary.message = failure;
    yfit = Eigen::VectorXd::Constant(N, NAN);
  }
  r.fit = fit_report_or_inf(y, yfit, p);
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
