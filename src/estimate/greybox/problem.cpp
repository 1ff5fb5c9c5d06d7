// ctid — the grey-box output-error problem over a record set (see problem.hpp; Ljung 1999 §7.3).
#include "estimate/greybox/problem.hpp"

#include <algorithm>
#include <cmath>

#include "ctid/core/check.hpp"

namespace ctid::greybox_detail {

namespace {
// The model's declared constraints with the options on top, resolved against its parameter names.
ParameterConstraints constraints_of(const GreyboxModel& model, const GreyboxOptions& opt) {
  FixedValues fixed_values;
  ParameterBounds bounds;
  for (const auto& p : model.spec().parameters) {
    if (p.fixed) fixed_values[p.name] = p.value;
    else if (p.lower > -INFINITY || p.upper < INFINITY) bounds[p.name] = {p.lower, p.upper};
  }
  overlay_constraints(fixed_values, bounds, opt.fixed, opt.bounds);
  return resolve_constraints(fixed_values, bounds, model.parameter_names(), "greybox", "a parameter of the model");
}
}  // namespace

Problem::Problem(const internal::RecordRefs& records, const GreyboxModel& m, const GreyboxOptions& options)
    : model(m), opt(options), integrator_(options.integrator) {
  CTID_REQUIRE(!records.empty(), "greybox: no records");
  E = static_cast<int>(records.size());
  ny = model.ny();
  np = model.np();
  nx = model.nx();
  // Constraints: the model's declarations, the options on top (a held option replaces a declared bound).
  cons = constraints_of(model, opt);
  theta0 = model.parameter_values();
  for (int i = 0; i < np; ++i)
    if (cons.held[i]) theta0(i) = cons.value(i);
  free = cons.free();
  pf = static_cast<int>(free.size());
  if (opt.estimate_initial_state)
    for (int i = 0; i < nx; ++i)
      if (model.spec().initial[i].estimate) free_x0.push_back(i);
  nx0 = static_cast<int>(free_x0.size());
  p = pf + E * nx0;

  rec.resize(static_cast<size_t>(E));
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
    r.hold = greybox_intersample(d);
    r.start = static_cast<Eigen::Index>(N) * ny;
    N += d.size();
  }
  CTID_REQUIRE(static_cast<long>(N) * ny > p, "greybox: {} samples for {} free quantities ({} parameters, {} initial states)",
               N * ny, p, pf, E * nx0);
  // Output weights: 1 for one output; 1/RMS deviation of each output with several (outputs in different units).
  w = Eigen::VectorXd::Ones(ny);
  y.resize(static_cast<Eigen::Index>(N) * ny);
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
  wy = y;
  for (const Record& r : rec)
    for (int j = 0; j < ny; ++j) wy.segment(r.start + static_cast<Eigen::Index>(j) * r.n, r.n) *= w(j);

  guess_.resize(static_cast<size_t>(E));
  for (int e = 0; e < E; ++e) guess_[static_cast<size_t>(e)] = model.initial_state_guess(records[static_cast<size_t>(e)]);
  lo = Eigen::VectorXd::Constant(p, -INFINITY);
  hi = Eigen::VectorXd::Constant(p, INFINITY);
  v0.resize(p);
  for (int j = 0; j < pf; ++j) {
    const int i = free[static_cast<size_t>(j)];
    lo(j) = cons.lower(i);
    hi(j) = cons.upper(i);
    v0(j) = std::clamp(theta0(i), lo(j), hi(j));
  }
  for (int e = 0; e < E; ++e)
    for (int k = 0; k < nx0; ++k) v0(pf + e * nx0 + k) = guess_[static_cast<size_t>(e)](free_x0[static_cast<size_t>(k)]);
}

GreyboxModel Problem::model_at(const Eigen::VectorXd& v) const {
  Eigen::VectorXd th = theta0;
  for (int j = 0; j < pf; ++j) th(free[static_cast<size_t>(j)]) = v(j);
  return model.with_parameters(th);
}

Eigen::VectorXd Problem::x0_of(const GreyboxModel& m, const Eigen::VectorXd& v, int e) const {
  Eigen::VectorXd x = m.initial_state();
  for (int i = 0; i < nx; ++i)
    if (std::isnan(x(i)) || model.spec().initial[i].estimate) x(i) = guess_[static_cast<size_t>(e)](i);
  for (int k = 0; k < nx0; ++k) x(free_x0[static_cast<size_t>(k)]) = v(pf + e * nx0 + k);
  return x;
}

GreyboxSimulation Problem::simulate(const GreyboxModel& m, const Record& d, const Eigen::MatrixXd& u,
                                    const Eigen::VectorXd& t, const Eigen::VectorXd& x0) {
  GreyboxSimulation s = m.simulate(u, t, d.hold, x0, opt.rtol, integrator_);
  if (s.integrator == GreyboxIntegrator::Bdf) integrator_ = GreyboxIntegrator::Bdf;
  return s;
}

GreyboxSensitivities Problem::sensitivities(const GreyboxModel& m, const Record& d, const Eigen::MatrixXd& u,
                                            const Eigen::VectorXd& t, const Eigen::VectorXd& x0,
                                            const std::vector<int>& states, bool x0_from_parameters) {
  GreyboxSensitivities s = m.sensitivities(u, t, d.hold, x0, free, states, opt.rtol, x0_from_parameters, integrator_);
  if (s.integrator == GreyboxIntegrator::Bdf) integrator_ = GreyboxIntegrator::Bdf;
  return s;
}

bool Problem::evaluate(const Eigen::VectorXd& v, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
  const GreyboxModel m = model_at(v);
  r.resize(y.size());
  if (J) *J = Eigen::MatrixXd::Zero(y.size(), p);
  for (int e = 0; e < E; ++e) {
    const Record& d = rec[static_cast<size_t>(e)];
    const Eigen::VectorXd x0 = x0_of(m, v, e);
    if (!J) {
      const GreyboxSimulation s = simulate(m, d, d.u, d.t, x0);
      if (!s.ok()) return escape = s.message, false;
      for (int j = 0; j < ny; ++j) r.segment(d.start + static_cast<Eigen::Index>(j) * d.n, d.n) = w(j) * s.y.col(j);
      continue;
    }
    const GreyboxSensitivities s = sensitivities(m, d, d.u, d.t, x0, free_x0, true);
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
}

internal::LmOptions Problem::lm_options() const {
  internal::LmOptions o;
  o.max_iterations = opt.max_iterations;
  o.ftol = opt.tolerance;
  o.xtol = opt.tolerance;
  o.keep_jacobian = true;  // the covariance allows for coloured residuals (search::set_covariance)
  return o;
}

internal::LmResult Problem::search(const Eigen::VectorXd& v) {
  const internal::LmEvaluate f = [this](const Eigen::VectorXd& x, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
    return evaluate(x, r, J);
  };
  return internal::levenberg_marquardt(f, v, lo, hi, lm_options());
}

}  // namespace ctid::greybox_detail
