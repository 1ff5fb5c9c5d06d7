// Output-error refinement of an NDE model (see include/ctid/estimate/nde_oe.hpp; Ljung 1999 ch. 7).
#include "ctid/estimate/nde_oe.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "ctid/core/check.hpp"
#include "ctid/validate/metrics.hpp"
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
          .names("fixed", &O::fixed, "term names whose coefficients are held (the reference term always is)")
          .real("rtol", &O::rtol, "", between(1e-13, 1e-6), "relative tolerance of the simulations (the Jacobian needs accuracy)");
  return t;
}

void NdeOeOptions::validate() const { option_table<NdeOeOptions>().check(*this); }

Result<NdeModel> nde_oe(const IdData& data, const NdeModel& initial, const NdeOeOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  opt.validate();
  require_io_data(data, "nde_oe");
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
  std::vector<bool> fixed(static_cast<size_t>(m), false);
  fixed[static_cast<size_t>(ref)] = true;
  for (const auto& name : opt.fixed) {
    int hit = -1;
    for (int i = 0; i < m; ++i)
      if (terms[static_cast<size_t>(i)].name() == name) hit = i;
    CTID_REQUIRE(hit >= 0, "nde_oe: fixed term '{}' is not a term of {}", name, initial.to_string());
    fixed[static_cast<size_t>(hit)] = true;
  }
  const Eigen::VectorXd c_init = initial.coefficients() / initial.coefficients()(ref);
  std::vector<int> free;
  for (int i = 0; i < m; ++i)
    if (!fixed[static_cast<size_t>(i)]) free.push_back(i);
  const int pc = static_cast<int>(free.size());
  const int nx = opt.estimate_initial_state ? L : 0;
  const int p = pc + nx;
  const int N = data.size();
  CTID_REQUIRE(N > p, "nde_oe: {} samples for {} free parameters", N, p);

  const Eigen::VectorXd u = data.u().col(0), y = data.y().col(0);
  Eigen::VectorXd t(N);
  for (int k = 0; k < N; ++k) t(k) = data.time(k) - data.t0();
  const Intersample hold = data.intersample(0) == Intersample::Zoh ? Intersample::Zoh : Intersample::Foh;

  auto coefficients = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd c = c_init;
    for (int j = 0; j < pc; ++j) c(free[static_cast<size_t>(j)]) = x(j);
    return c;
  };
  auto simulate = [&](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
    const NdeModel model(terms, coefficients(x));
    const NdeSimulation s = model.simulate(u, t, hold, nx ? Eigen::VectorXd(x.tail(nx)) : Eigen::VectorXd(), opt.rtol);
    out = s.y;
    return s.ok();
  };

  // Start: the given coefficients, y(0) measured and its derivatives 0 (differences of noisy samples are
  // worse); when that simulation escapes, the free nonlinear coefficients are halved until it does not.
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(p);
  if (nx) x0(pc) = y(0);
  double start_scale = 1.0;
  Eigen::VectorXd ys;
  for (int shrink = 0;; ++shrink) {
    start_scale = shrink > 30 ? 0.0 : std::ldexp(1.0, -shrink);
    for (int j = 0; j < pc; ++j) {
      const int i = free[static_cast<size_t>(j)];
      x0(j) = c_init(i) * (terms[static_cast<size_t>(i)].degree() >= 2 ? start_scale : 1.0);
    }
    if (simulate(x0, ys) || start_scale == 0.0) break;
  }

  // Forward sensitivities (DESIGN.md §6: analytic, not differences). With x = [y, Dy, .., D^{L-1}y] and the
  // explicit form D^L y = f_L(x, u) = -(1/c_top) sum_{i != top} c_i phi_i(x, u), the sensitivity S_j = dx/dtheta_j
  // obeys S_j' = [S_j(1..L-1); grad_x f_L . S_j + df_L/dtheta_j], with df_L/dc_i = -phi_i/c_top (i != top),
  // df_L/dc_top = -f_L/c_top, 0 for the initial state, and S_j(0) = e_k for theta_j = D^k y(0).
  const Eigen::Index nz = L + static_cast<Eigen::Index>(L) * p;
  Eigen::VectorXd phi(m), grad(L);
  auto sensitivities = [&](const Eigen::VectorXd& x, Eigen::VectorXd& yhat, Eigen::MatrixXd& S) {
    const Eigen::VectorXd c = coefficients(x);
    const double ctop = c(top);
    internal::OdeRhs rhs = [&](const Eigen::VectorXd& z, double uu, Eigen::VectorXd& dz) {
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
      for (int j = 0; j < p; ++j) {
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
    if (nx) z0.head(L) = x.tail(nx);
    for (int k = 0; k < nx; ++k) z0(L + static_cast<Eigen::Index>(L) * (pc + k) + k) = 1.0;
    yhat.resize(N);
    S.resize(N, p);
    return internal::dopri45(rhs, z0, u, t, hold == Intersample::Zoh, opt.rtol, 1e-12, L,
                             [&](Eigen::Index k, const Eigen::VectorXd& z) {
                               yhat(k) = z(0);
                               for (int j = 0; j < p; ++j) S(k, j) = z(L + static_cast<Eigen::Index>(L) * j);
                             })
        .ok;
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
  const Eigen::VectorXd lo = Eigen::VectorXd::Constant(p, -INFINITY), hi = Eigen::VectorXd::Constant(p, INFINITY);
  const internal::LmResult lm = internal::levenberg_marquardt(evaluate, x0, lo, hi, lmo);

  Result<NdeModel> r;
  const Eigen::VectorXd c = coefficients(lm.x);
  r.model = NdeModel(terms, c);
  const int np = m + nx;
  r.parameters.names.resize(static_cast<size_t>(np));
  r.parameters.values.resize(np);
  r.parameters.fixed.assign(static_cast<size_t>(np), false);
  for (int i = 0; i < m; ++i) {
    r.parameters.names[static_cast<size_t>(i)] = terms[static_cast<size_t>(i)].name();
    r.parameters.values(i) = c(i);
    r.parameters.fixed[static_cast<size_t>(i)] = fixed[static_cast<size_t>(i)];
  }
  for (int k = 0; k < nx; ++k) {
    r.parameters.names[static_cast<size_t>(m + k)] =
        k == 0 ? "y(0)" : (k == 1 ? "Dy(0)" : "D^" + std::to_string(k) + "y(0)");
    r.parameters.values(m + k) = lm.x(pc + k);
  }
  std::vector<int> slot(free);
  for (int k = 0; k < nx; ++k) slot.push_back(m + k);
  const double sigma2 = 2.0 * lm.cost / std::max(1, N - p);
  r.parameters.covariance = Eigen::MatrixXd::Zero(np, np);
  r.parameters.std = Eigen::VectorXd::Zero(np);
  if (lm.jtj.rows() == p && std::isfinite(sigma2)) {
    const Eigen::MatrixXd C = sigma2 * lm.jtj.ldlt().solve(Eigen::MatrixXd::Identity(p, p));
    for (int i = 0; i < p; ++i)
      for (int j = 0; j < p; ++j)
        r.parameters.covariance(slot[static_cast<size_t>(i)], slot[static_cast<size_t>(j)]) = C(i, j);
    r.parameters.std = r.parameters.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
    const Eigen::VectorXd dg = lm.jtj.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
    const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(
                                   dg.asDiagonal() * lm.jtj * dg.asDiagonal(), Eigen::EigenvaluesOnly)
                                   .eigenvalues();
    r.diagnostics.condition_number = ev(0) > 0 ? std::sqrt(ev(p - 1) / ev(0)) : INFINITY;
  }
  r.diagnostics.vectors["x0"] = nx ? Eigen::VectorXd(lm.x.tail(nx)) : Eigen::VectorXd::Zero(L);
  r.diagnostics.scalars["noise_variance"] = sigma2;
  r.diagnostics.scalars["start_scale"] = start_scale;
  if (start_scale < 1.0)
    r.diagnostics.warnings.push_back(detail::format(
        "the starting model escapes on these data; the search started with its nonlinear coefficients times {}",
        start_scale));
  r.summary.iterations = lm.iterations;
  Eigen::VectorXd yfit;
  if (!std::isfinite(lm.cost) || !simulate(lm.x, yfit)) {
    r.summary.termination = Termination::NumericalFailure;
    r.summary.message = "the model cannot be simulated on these data, even with its nonlinear terms removed";
    yfit = Eigen::VectorXd::Constant(N, NAN);
  } else {
    internal::set_termination(r.summary, lm);
  }
  r.fit = fit_report_or_inf(y, yfit, p);
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace ctid
