// LSSVF / IVSVF — Johansson (1986) RJ 11-25, 44, 52-55, 59-61 (RJ 7-17..A5).
// See include/ctid/estimate/svf/lssvf.hpp.
#include "ctid/estimate/svf/lssvf.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "ctid/core/check.hpp"
#include "ctid/core/progress.hpp"
#include "ctid/signal/svf.hpp"
#include "ctid/simulate/lsim.hpp"
#include "ctid/validate/metrics.hpp"
#include "estimate/svf/svf_common.hpp"
#include "estimate/transfer_function/tf_common.hpp"
#include "internal/least_squares.hpp"

namespace ctid {

template <>
const OptionTable<LssvfOptions>& option_table<LssvfOptions>() {
  using O = LssvfOptions;
  static const OptionTable<O> t =
      OptionTable<O>("lssvf")
          .real("tau", &O::tau, "s", or_special(above(0), 0, "automatic"),
                "filter time constant of z = 1/(1 + p tau); 0: best simulation fit over a grid from 2 Ts to duration/20")
          .choice("weights", &O::weights, {{"riemann", SvfWeights::Riemann}, {"trapezoidal", SvfWeights::Trapezoidal}},
                  "sample weights of the criterion int e^2 dt (RJ 44, 59-61)")
          .real("alpha", &O::alpha, "1/s", at_least(0), "exponential weighting rate: criterion weight e^{2 alpha t}")
          .real("transient_time", &O::transient_time, "s", at_least(0),
                "seconds at the start left out of the criterion (filter and system transients)")
          .named_reals("fixed", &O::fixed, "known coefficients held fixed, by parameter name (fixed.a2=4)")
          .model("data_filter", &O::data_filter, "extra filter F(s) applied to input and output (stable, proper, no delay)")
          .integer("tau_grid_size", &O::tau_grid_size, "", between(2, O::kMaxTauGrid),
                   "number of tau candidates of the automatic choice");
  return t;
}

template <>
const OptionTable<IvsvfOptions>& option_table<IvsvfOptions>() {
  using O = IvsvfOptions;
  static const OptionTable<O> t = OptionTable<O>("ivsvf")
                                      .include(&O::svf, option_table<LssvfOptions>())
                                      .integer("max_iterations", &O::max_iterations, "", at_least(1),
                                               "instrument/estimate refinements after the LS start")
                                      .real("tolerance", &O::tolerance, "", above(0),
                                            "stop when the relative parameter change is below");
  return t;
}

void LssvfOptions::validate() const {
  option_table<LssvfOptions>().check(*this);
  if (data_filter) {
    CTID_REQUIRE_OPTION(data_filter->is_stable(), "lssvf: data_filter must be stable (got {})", data_filter->to_string());
    CTID_REQUIRE_OPTION(data_filter->io_delay() == 0.0, "lssvf: data_filter must have no delay (got {} s)",
                        data_filter->io_delay());
  }
}

void IvsvfOptions::validate() const {
  svf.validate();
  option_table<IvsvfOptions>().check(*this);
}

std::vector<std::string> tf_parameter_names(const TfOrders& o) {
  std::vector<std::string> names;
  for (int i = 1; i <= o.nf; ++i) names.push_back("a" + std::to_string(i));
  for (int j = 0; j < o.nb; ++j) names.push_back("b" + std::to_string(j));
  return names;
}

namespace svf_detail {

int parameter_index(const TfOrders& o, const std::string& name, const char* who) {
  const auto names = tf_parameter_names(o);
  for (std::size_t k = 0; k < names.size(); ++k)
    if (names[k] == name) return static_cast<int>(k);
  std::string known;
  for (const auto& nm : names) known += (known.empty() ? "" : ", ") + nm;
  throw InvalidOptions(detail::format("{}: '{}' is not a coefficient of this structure ({})", who, name, known));
}

SvfLayout make_layout(const TfOrders& o, double tau, const FixedValues& fixed, const char* who) {
  SvfLayout L;
  L.n = o.nf;
  L.nb = o.nb;
  L.tau = tau;
  L.M = svf_m_tau(L.n, tau);
  L.g = svf_g_tau(L.n);
  L.fixed.assign(2 * L.n, false);
  L.theta_fixed = Eigen::VectorXd::Zero(2 * L.n);
  for (int i = 0; i < L.n - L.nb; ++i) L.fixed[L.n + i] = true;  // leading b's are zero
  const std::vector<std::string> names = tf_parameter_names(o);
  const ParameterConstraints c = resolve_constraints(fixed, {}, names, who, "a coefficient of this structure (" +
                                                     options_detail::format_names(names) + ")");
  for (int idx = 0; idx < static_cast<int>(names.size()); ++idx) {
    if (!c.held[static_cast<std::size_t>(idx)]) continue;
    const int t = L.theta_index(idx);
    L.fixed[t] = true;
    L.theta_fixed(t) = idx < L.n ? -c.value(idx) : c.value(idx);
  }
  for (int t = 0; t < 2 * L.n; ++t)
    if (!L.fixed[t]) L.free.push_back(t);
  CTID_REQUIRE_OPTION(!L.free.empty(), "{}: every coefficient is fixed; nothing to estimate", who);
  return L;
}

PreparedData prepare(const IdData& data, const TfOrders& o, double transient_time, double alpha, SvfWeights weights,
                     const char* who) {
  require_io_data(data, who);
  CTID_REQUIRE(o.nk == 0 || data.is_uniform(), "{}: nk = {} needs uniformly sampled data (these are irregular)", who, o.nk);
  CTID_REQUIRE(o.nk < data.size(), "{}: nk = {} is not shorter than the record ({} samples)", who, o.nk, data.size());
  PreparedData P;
  const int N = data.size();
  P.data = &data;
  P.ys = data.y().col(0).data();
  P.us = data.u().col(0).data();
  P.nk = o.nk;
  P.uniform = data.is_uniform();
  P.h = P.uniform ? data.ts() : data.duration() / std::max(1, N - 1);
  P.u_intersample = data.intersample(0);
  P.alpha = alpha;
  P.weights = weights;
  P.t_end = data.time(N - 1);
  const int first = static_cast<int>(tf_detail::first_after(data, transient_time));
  CTID_REQUIRE(first < N, "{}: transient_time = {} s leaves no samples (record lasts {} s)", who, transient_time,
               data.duration());
  P.first = first;
  P.n_used = N - first;
  return P;
}

internal::LinearSolution solve_ls(const std::vector<PreparedData>& Ps, const SvfLayout& L,
                                  const std::optional<TransferFunction>& filt) {
  // Fast pass with the Gram matrix; a second pass with blocked QR when the problem is
  // ill-conditioned enough for the normal equations to lose accuracy.
  const int p = static_cast<int>(L.free.size());
  internal::GramLeastSquares gram(p);
  for (const PreparedData& P : Ps)
    svf_pass(P, L, filt, nullptr, [&](const double* row, double lhs, const double*, double w) { gram.add(row, lhs, w); });
  internal::LinearSolution s = gram.solve();
  if (s.condition < internal::kGramConditionLimit && s.theta.allFinite()) return s;
  internal::StreamingLeastSquares ls(p);
  for (const PreparedData& P : Ps)
    svf_pass(P, L, filt, nullptr, [&](const double* row, double lhs, const double*, double w) { ls.add(row, lhs, w); });
  return ls.solve();
}

internal::LinearSolution solve_iv(const std::vector<PreparedData>& Ps, const SvfLayout& L,
                                  const std::optional<TransferFunction>& filt, const std::vector<Eigen::VectorXd>& aux) {
  const int p = static_cast<int>(L.free.size());
  internal::InstrumentalVariables iv(p);
  for (std::size_t e = 0; e < Ps.size(); ++e)
    svf_pass(Ps[e], L, filt, &aux[e],
             [&](const double* row, double lhs, const double* zrow, double w) { iv.add(zrow, row, lhs, w); });
  return iv.solve();
}

Eigen::VectorXd full_theta(const SvfLayout& L, const Eigen::VectorXd& theta_free) {
  Eigen::VectorXd th = L.theta_fixed;
  for (std::size_t j = 0; j < L.free.size(); ++j) th(L.free[j]) = theta_free(static_cast<Eigen::Index>(j));
  return th;
}

TransferFunction tf_from_theta(const SvfLayout& L, const Eigen::VectorXd& th, double delay) {
  Eigen::VectorXd den(L.n + 1), num(L.nb);
  den(0) = 1.0;
  den.tail(L.n) = -th.head(L.n);
  num = th.tail(L.nb);
  return TransferFunction(num, den, delay);
}

Result<TransferFunction> make_result(const internal::RecordRefs& data, const TfOrders& o, const SvfLayout& L,
                                     const internal::LinearSolution& sol, double alpha) {
  Result<TransferFunction> r = make_model_result(o, L, sol, alpha, o.nk > 0 ? o.nk * data.front().ts() : 0.0);
  // Output-error fit of the model on the estimation data.
  r.fit = simulation_fit(r.model, data, static_cast<int>(L.free.size()));
  if (data.size() > 1) r.diagnostics.set(diagnostic::experiments, static_cast<double>(data.size()));
  return r;
}

Result<TransferFunction> make_model_result(const TfOrders& o, const SvfLayout& L, const internal::LinearSolution& sol,
                                           double alpha, double delay) {
  Result<TransferFunction> r;
  const Eigen::VectorXd th = full_theta(L, sol.theta);
  const int np = o.nf + o.nb;
  r.parameters.names = tf_parameter_names(o);
  r.parameters.values.resize(np);
  r.parameters.fixed.assign(np, false);
  // Map between the parameter vector [a1..an, b0..b(nb-1)] and theta = [-a, b_1..b_n].
  Eigen::VectorXd sign(np);
  std::vector<int> tidx(np);
  for (int i = 0; i < np; ++i) {
    tidx[i] = L.theta_index(i);
    sign(i) = i < L.n ? -1.0 : 1.0;
    r.parameters.values(i) = sign(i) * th(tidx[i]);
    r.parameters.fixed[i] = L.fixed[tidx[i]];
  }
  // The free entries of theta are parameters slots[k], with sign flips.
  std::vector<int> slots;
  Eigen::VectorXd flip(static_cast<Eigen::Index>(L.free.size()));
  for (std::size_t k = 0; k < L.free.size(); ++k) {
    const int i = static_cast<int>(std::find(tidx.begin(), tidx.end(), L.free[k]) - tidx.begin());
    CTID_ASSERT(i < np);
    slots.push_back(i);
    flip(static_cast<Eigen::Index>(k)) = sign(i);
  }
  r.parameters.set_covariance(flip.asDiagonal() * sol.covariance * flip.asDiagonal(), slots);

  r.model = tf_from_theta(L, th, delay);
  r.diagnostics.condition_number = sol.condition;
  r.diagnostics.set(diagnostic::tau, L.tau);
  r.diagnostics.set(diagnostic::equation_error_variance, sol.sigma2);
  r.diagnostics.set(diagnostic::theta_tau, svf_transform(L, th));
  if (sol.rank_deficient) {
    r.summary.termination = Termination::RankDeficient;
    r.summary.message = detail::format(
        "the filtered regressor is rank deficient (scaled condition number {}); the input does not excite all {} "
        "parameters, or tau = {} s is far from the system's time scale",
        sol.condition, L.free.size(), L.tau);
  }
  // Diagnostics of RJ-A4 and RJ-A5.
  const double s0 = -1.0 / L.tau;
  double bscale = 0;
  for (int i = 0; i < L.nb; ++i) bscale += std::abs(th(L.n + L.n - L.nb + i)) * std::pow(std::abs(s0), L.nb - 1 - i);
  const double b_at = r.model.num()(s0);
  r.diagnostics.set(diagnostic::B_at_minus_1_over_tau, b_at);
  if (bscale > 0 && std::abs(b_at) < 1e-2 * bscale)
    r.diagnostics.warnings.push_back(detail::format(
        "B(-1/tau) = {} is nearly zero: a zero of the model is close to -1/tau = {}; the regressor is nearly singular "
        "in that direction (RJ identifiability condition); choose another tau",
        b_at, s0));
  if (!r.model.is_stable()) r.diagnostics.warnings.push_back("the estimated model is unstable");
  if (alpha > 0) {
    if (L.tau >= 1.0 / alpha)
      r.diagnostics.warnings.push_back(detail::format(
          "tau = {} s is not below 1/alpha = {} s: exponential weighting needs z(s - alpha) stable (RJ 55)", L.tau,
          1.0 / alpha));
    const Eigen::VectorXcd poles = r.model.poles();
    for (Eigen::Index i = 0; i < poles.size(); ++i)
      if (poles(i).real() >= -alpha) {
        r.diagnostics.warnings.push_back(detail::format(
            "pole {} + {}j has real part >= -alpha = {}: G(s - alpha) is not stable (RJ 55)", poles(i).real(),
            poles(i).imag(), -alpha));
        break;
      }
  }
  return r;
}

Eigen::VectorXd svf_transform(const SvfLayout& L, const Eigen::VectorXd& th) {
  Eigen::VectorXd tt(2 * L.n);
  tt.head(L.n) = L.M * th.head(L.n) + L.g;
  tt.tail(L.n) = L.M * th.tail(L.n);
  return tt;
}

double choose_tau(const internal::RecordRefs& data, const TfOrders& o, const LssvfOptions& opt, Eigen::VectorXd* grid_out,
                  Eigen::VectorXd* fit_out) {
  std::vector<PreparedData> P;
  double h = 0, shortest = std::numeric_limits<double>::infinity();
  for (const IdData& d : data) {
    P.push_back(prepare(d, o, opt.transient_time, opt.alpha, opt.weights, "lssvf"));
    h = std::max(h, P.back().h);
    shortest = std::min(shortest, d.duration());
  }
  const double lo = 2.0 * h;
  const double hi = std::max(lo * 4.0, shortest / 20.0);
  const int G = opt.tau_grid_size;
  Eigen::VectorXd grid(G), fits(G);
  double best_tau = lo, best_fit = -std::numeric_limits<double>::infinity();
  bool have = false;
  for (int i = 0; i < G; ++i) {
    if (!report_progress("tau_grid", i + 1, best_fit)) break;  // interrupted: the best tau so far
    const double tau = lo * std::pow(hi / lo, double(i) / (G - 1));
    grid(i) = tau;
    fits(i) = -std::numeric_limits<double>::infinity();
    const SvfLayout L = make_layout(o, tau, opt.fixed, "lssvf");
    const internal::LinearSolution s = solve_ls(P, L, opt.data_filter);
    if (s.rank_deficient || !s.theta.allFinite()) continue;
    const TransferFunction tf = tf_from_theta(L, full_theta(L, s.theta), o.nk > 0 ? o.nk * data.front().ts() : 0.0);
    if (!tf.is_stable()) continue;
    const double f = simulation_fit(tf, data, 0).fit_percent;
    if (!std::isfinite(f)) continue;
    fits(i) = f;
    if (f > best_fit) { best_fit = f; best_tau = tau; have = true; }
  }
  if (grid_out) *grid_out = grid;
  if (fit_out) *fit_out = fits;
  return have ? best_tau : std::sqrt(lo * hi);
}

}  // namespace svf_detail

using namespace svf_detail;

namespace {
// The records prepared for the SVF regressions; `who` names the record when there are several.
std::vector<PreparedData> prepare_all(const internal::RecordRefs& data, const TfOrders& o, const LssvfOptions& opt,
                                      const char* who) {
  CTID_REQUIRE(!data.empty(), "{}: no records given", who);
  std::vector<PreparedData> P;
  for (std::size_t e = 0; e < data.size(); ++e) {
    const std::string name = data.size() == 1 ? std::string(who) : detail::format("{} (record {})", who, e + 1);
    P.push_back(prepare(data[e], o, opt.transient_time, opt.alpha, opt.weights, name.c_str()));
    CTID_REQUIRE(e == 0 || o.nk == 0 || std::abs(data[e].ts() - data[0].ts()) <= 1e-9 * data[0].ts(),
                 "{}: nk counts samples, so the records need one sampling period ({} s and {} s)", name, data[0].ts(),
                 data[e].ts());
  }
  return P;
}
// lssvf and ivsvf of one record or of several, without copying them.
Result<TransferFunction> lssvf_records(const internal::RecordRefs& data, const TfOrders& orders,
                                       const LssvfOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  orders.validate();
  options.validate();
  const std::vector<PreparedData> P = prepare_all(data, orders, options, "lssvf");
  Eigen::VectorXd grid, fits;
  double tau = options.tau, longest = 0;
  for (const IdData& d : data) longest = std::max(longest, d.duration());
  CTID_REQUIRE(tau <= 1e3 * longest, "lssvf: tau = {} s is more than 1000 times the record ({} s): the filtered "
               "signals would not move", tau, longest);
  if (tau == 0.0) tau = choose_tau(data, orders, options, &grid, &fits);
  const SvfLayout L = make_layout(orders, tau, options.fixed, "lssvf");
  int n_used = 0;
  for (const PreparedData& p : P) n_used += p.n_used;
  CTID_REQUIRE(n_used > static_cast<int>(L.free.size()),
               "lssvf: {} samples in the criterion cannot determine {} free parameters", n_used, L.free.size());
  const internal::LinearSolution sol = solve_ls(P, L, options.data_filter);
  Result<TransferFunction> r = make_result(data, orders, L, sol, options.alpha);
  if (grid.size() > 0) {
    r.diagnostics.set(diagnostic::tau_grid, grid);
    r.diagnostics.set(diagnostic::tau_grid_fit_percent, fits);
  }
  r.summary.iterations = 1;
  tf_detail::check_cancellation(r);
  tf_detail::warn_poles_beyond_bandwidth(r, data.front());
  if (interrupt_requested()) {
    r.summary.termination = Termination::Interrupted;
    r.summary.message = "interrupted during the choice of tau";
  }
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

Result<TransferFunction> ivsvf_records(const internal::RecordRefs& data, const TfOrders& orders,
                                       const IvsvfOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  orders.validate();
  options.validate();
  Result<TransferFunction> r = lssvf_records(data, orders, options.svf);
  if (!r.usable()) return r;
  const double tau = r.diagnostics.get(diagnostic::tau);
  const std::vector<PreparedData> P = prepare_all(data, orders, options.svf, "ivsvf");
  const SvfLayout L = make_layout(orders, tau, options.svf.fixed, "ivsvf");
  Eigen::VectorXd theta = full_theta(L, Eigen::VectorXd::Zero(static_cast<Eigen::Index>(L.free.size())));
  for (std::size_t j = 0; j < L.free.size(); ++j) {
    const int t = L.free[j];
    const int i = L.param_index(t);
    theta(t) = (i < L.n ? -1.0 : 1.0) * r.parameters.values(i);
  }
  internal::LinearSolution sol;
  bool converged = false;
  int it = 0;
  Termination term = Termination::MaxIterations;
  for (it = 1; it <= options.max_iterations; ++it) {
    TransferFunction aux = tf_from_theta(L, theta, 0.0);
    aux = tf_detail::stabilized(aux);
    // Auxiliary-model output driven by the (delayed) input of each record.
    std::vector<Eigen::VectorXd> xhat;
    for (std::size_t e = 0; e < data.size(); ++e) xhat.push_back(lsim(aux, P[e].delayed_u(), data[e].times(), P[e].u_intersample));
    sol = solve_iv(P, L, options.svf.data_filter, xhat);
    if (sol.rank_deficient || !sol.theta.allFinite()) {
      term = sol.rank_deficient ? Termination::RankDeficient : Termination::NumericalFailure;
      break;
    }
    const Eigen::VectorXd next = full_theta(L, sol.theta);
    const double change = (next - theta).norm() / std::max(1e-300, next.norm());
    theta = next;
    if (change < options.tolerance) {
      converged = true;
      term = Termination::Converged;
      break;
    }
  }
  Result<TransferFunction> out = make_result(data, orders, L, sol, options.svf.alpha);
  out.summary.iterations = std::min(it, options.max_iterations);
  if (!converged && out.summary.termination == Termination::Completed) {
    out.summary.termination = term;
    if (term == Termination::MaxIterations)
      out.summary.message = detail::format("the iteration limit ended the IV iterations, not convergence: no relative change below {} in "
                                           "{} iterations; raise max_iterations",
                                           options.tolerance, options.max_iterations);
    else if (out.summary.message.empty())
      out.summary.message = "the instrumental-variable equations became singular or non-finite";
  } else if (converged) {
    out.summary.termination = Termination::Converged;
  }
  if (out.summary.succeeded() && r.model.is_stable() && !out.model.is_stable()) {
    out.summary.termination = Termination::Unstable;
    out.summary.message =
        "the IV iterations moved from a stable LSSVF start to an unstable model; try another tau or a lower order "
        "(the LSSVF estimate may be preferable)";
  }
  tf_detail::check_cancellation(out);
  out.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace

Result<TransferFunction> lssvf(const IdData& data, const TfOrders& orders, const LssvfOptions& options) {
  return lssvf_records(data, orders, options);
}

Result<TransferFunction> lssvf(const std::vector<IdData>& data, const TfOrders& orders, const LssvfOptions& options) {
  return lssvf_records(data, orders, options);
}

Result<TransferFunction> ivsvf(const IdData& data, const TfOrders& orders, const IvsvfOptions& options) {
  return ivsvf_records(data, orders, options);
}

Result<TransferFunction> ivsvf(const std::vector<IdData>& data, const TfOrders& orders, const IvsvfOptions& options) {
  return ivsvf_records(data, orders, options);
}
}  // namespace ctid

namespace ctid::svf_detail {

FitReport simulation_fit(const TransferFunction& model, const internal::RecordRefs& data, int n_free) {
  Eigen::Index total = 0;
  for (const IdData& d : data) total += d.size();
  if (total < 2) {
    FitReport f;
    f.n_samples = static_cast<int>(total);
    f.n_parameters = n_free;
    return f;
  }
  const auto [y, sim] = tf_detail::pooled_outputs(model, data, 0.0);
  return fit_report_or_inf(y, sim, n_free);
}

}  // namespace ctid::svf_detail
