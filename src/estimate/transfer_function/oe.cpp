// Output error and tfest — see include/ctid/estimate/transfer_function/oe.hpp. The criterion and its Gauss-Newton / Levenberg-Marquardt
// search on exact output sensitivities: Ljung (1999) §7.3 and §10.2; the sensitivities are filtered derivatives of the
// input through 1/A and B/A^2, the filters of Young & Jakeman (1980) that SRIVC uses.
#include "ctid/estimate/transfer_function/oe.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>

#include "ctid/core/check.hpp"
#include "ctid/estimate/svf/lssvf.hpp"
#include "ctid/signal/prefilter.hpp"
#include "ctid/simulate/lsim.hpp"
#include "ctid/simulate/simulate.hpp"
#include "ctid/validate/metrics.hpp"
#include "estimate/svf/svf_common.hpp"
#include "estimate/transfer_function/tf_common.hpp"
#include "internal/coloured_covariance.hpp"
#include "internal/least_squares.hpp"
#include "estimate/search.hpp"
#include "internal/levenberg_marquardt.hpp"
#include "signal/filter_bank.hpp"

namespace ctid {

template <>
const OptionTable<OeOptions>& option_table<OeOptions>() {
  using O = OeOptions;
  static const OptionTable<O> t =
      OptionTable<O>("oe")
          .integer("max_iterations", &O::max_iterations, "", at_least(1), "Levenberg-Marquardt iterations")
          .real("tolerance", &O::tolerance, "", above(0), "relative cost decrease / parameter change that stops the search")
          .model("initial", &O::initial, "starting model; none: LSSVF with an automatic filter (oe) or SRIVC (tfest)")
          .named_reals("fixed", &O::fixed, "parameters held at a value, by name (fixed.a1=2, fixed.delay=0.1)")
          .named_bounds("bounds", &O::bounds, "parameter bounds by name (bounds.a1=0,inf); the delay is always >= 0")
          .flag("estimate_delay", &O::estimate_delay, "add the input delay (s) as a parameter named delay")
          .real("delay", &O::delay, "s", at_least(0), "initial or fixed input delay, added to nk Ts")
          .flag("estimate_initial_state", &O::estimate_initial_state,
                "estimate each record's initial condition (its free response, nf coefficients per record; the state "
                "of the model's realisation in diagnostics x0, what simulate and validate start from)")
          .real("transient_time", &O::transient_time, "s", at_least(0),
                "seconds at the start of each record left out of the cost (records not at rest)")
          .include(&O::srivc, option_table<SrivcOptions>(), {"delay_min", "delay_max", "delay_grid"})
          .include(&O::srivc, option_table<SrivcOptions>(), {"max_iterations", "tolerance"},
                   {{"max_iterations", "start_max_iterations"}, {"tolerance", "start_tolerance"}});
  return t;
}

void OeOptions::validate() const {
  option_table<OeOptions>().check(*this);
  srivc.validate();
}

namespace {

using Records = std::vector<IdData>;  // one or several experiments of one system
using tf_detail::first_after;


double shortest_duration(const Records& ds) {
  double s = ds.front().duration();
  for (const IdData& d : ds) s = std::min(s, d.duration());
  return s;
}

// Buffers of the residual evaluations, kept over the iterations so that none allocates what grows with the records.
struct OeWorkspace {
  std::vector<SensitivityWorkspace> sens;  // per record
  Eigen::VectorXd sim;                     // one record's simulated output
  Eigen::MatrixXd s, S;                    // one record's sensitivities; all records' stacked
};

// The output-error residuals y - G u of every record after its transient (each simulated from rest), stacked, and
// (with_sensitivities) their sensitivities to the parameters in ws.S.
bool stacked_residuals(const TransferFunction& g, const Records& ds, double transient, int nb, bool with_delay,
                       Eigen::VectorXd& r, bool with_sensitivities, OeWorkspace& ws) {
  Eigen::Index total = 0;
  for (const IdData& d : ds) total += d.size() - first_after(d, transient);
  if (r.size() != total) r.resize(total);
  ws.sens.resize(ds.size());
  Eigen::Index at = 0;
  for (std::size_t e = 0; e < ds.size(); ++e) {
    const IdData& d = ds[e];
    const Eigen::Index f = first_after(d, transient), m = d.size() - f;
    if (ws.sim.size() != d.size()) ws.sim.resize(d.size());
    lsim_into(g, d, 0, ws.sim);
    r.segment(at, m) = d.y().col(0).tail(m) - ws.sim.tail(m);
    if (with_sensitivities) {
      output_sensitivities_into(g, nb, d, with_delay, ws.sens[e], ws.s);
      if (ws.S.rows() != total || ws.S.cols() != ws.s.cols()) ws.S.resize(total, ws.s.cols());
      ws.S.middleRows(at, m) = ws.s.bottomRows(m);
    }
    at += m;
  }
  return r.allFinite();
}

// The normal equations of OE on a uniformly sampled single-input record from rest, without delay, made sample by
// sample (LmNormalEvaluate's form: cost = 1/2 ||r||^2, A = J^T J, g = J^T r, added to what they hold): the banks 1/A
// of u (its derivatives give the b-sensitivities and, combined by b, the simulated output) and B/A^2 of u (the
// a-sensitivities) advance together — the recursions of output_sensitivities_into and lsim, so the Jacobian is the
// same, but a pass reads u and y and writes nothing that grows with the record. theta = [a1..an, b0..b(nb-1)];
// `free` are the columns of the Jacobian (indices into theta); A null: the cost alone. For the coloured-noise
// covariance, `acov` collects the residuals' autocovariance and `coloured` the filtered Jacobian rows (this record
// one sequence of each).
template <int n>
void oe_stream_n(const Eigen::VectorXd& theta, int nb, const IdData& d, Eigen::Index first, const std::vector<int>& free,
                 double& cost, Eigen::MatrixXd* A, Eigen::VectorXd* g, internal::ResidualAutocovariance* acov = nullptr,
                 internal::ColouredGram* coloured = nullptr) {
  Eigen::VectorXd den(n + 1);
  den(0) = 1.0;
  den.tail(n) = theta.head(n);
  const Polynomial F(den);
  const Eigen::VectorXd b = theta.segment(n, nb);
  const double h = d.ts();
  const Intersample is = d.intersample(0);
  signal_detail::Bank<n> ub(derivative_recursion(TransferFunction(Polynomial{1.0}, F), nb - 1, h, is));
  std::optional<signal_detail::Bank<2 * n>> xb;  // none when B = 0 (the a-sensitivities vanish)
  const bool rows = A || coloured;
  if (rows && b.cwiseAbs().maxCoeff() > 0)
    xb.emplace(derivative_recursion(TransferFunction(Polynomial(b), F * F), n - 1, h, is));
  // Where each free column's sensitivity is read in the banks' rows (those arrays stay in place), with its sign.
  const int p = static_cast<int>(free.size());
  static constexpr double kZero = 0.0;
  std::vector<const double*> src(static_cast<std::size_t>(p));
  std::vector<double> sign(static_cast<std::size_t>(p)), psi(static_cast<std::size_t>(p));
  for (int jj = 0; jj < p; ++jj) {
    const int i = free[static_cast<std::size_t>(jj)];
    const bool a = i < n;  // -s^{n-1-i} B/A^2 u (a_i), s^{nb-1-j}/A u (b_j); J = -S
    src[static_cast<std::size_t>(jj)] = a ? (xb ? &xb->row[n - 1 - i] : &kZero) : &ub.row[nb - 1 - (i - n)];
    sign[static_cast<std::size_t>(jj)] = a ? -1.0 : 1.0;
  }
  const auto u = d.u().col(0);
  const auto y = d.y().col(0);
  const Eigen::Index N = d.size();
  double c = 0.0;
  if (acov) acov->start_sequence();
  if (coloured) coloured->start_sequence();
  for (Eigen::Index k = 0; k < N; ++k) {
    const double* ur = ub.at(u(k));
    if (xb) xb->at(u(k));
    if (k >= first) {
      double yhat = 0.0;
      for (int j = 0; j < nb; ++j) yhat += b(j) * ur[nb - 1 - j];
      const double r = y(k) - yhat;
      c += r * r;
      if (acov) acov->add(r);
      if (rows)
        for (int jj = 0; jj < p; ++jj)
          psi[static_cast<std::size_t>(jj)] = sign[static_cast<std::size_t>(jj)] * *src[static_cast<std::size_t>(jj)];
      if (coloured) coloured->add(psi.data());
      if (A) {
        for (int jj = 0; jj < p; ++jj) {
          const double s = psi[static_cast<std::size_t>(jj)];
          (*g)(jj) -= s * r;
          for (int ll = jj; ll < p; ++ll) (*A)(jj, ll) += s * psi[static_cast<std::size_t>(ll)];
        }
      }
    }
    if (k + 1 == N) break;
    ub.advance(u(k), u(k + 1));
    if (xb) xb->advance(u(k), u(k + 1));
  }
  cost += 0.5 * c;
}

// Whether refine can stream its normal equations (oe_stream_n): every record uniformly sampled with one input, no
// delay, no initial states, an order the banks are compiled for.
bool streamable(const Records& ds, const TfOrders& o, bool delay, int initial_states) {
  if (delay || initial_states > 0 || o.nf < 1 || o.nf > 8) return false;
  for (const IdData& d : ds)
    if (d.nu() != 1 || !d.is_uniform()) return false;
  return true;
}

// The search with the residuals streamed through the compiled filter banks into the normal equations (memory
// O(parameters^2)): x are the free entries of `full` = [a, b].
internal::LmResult streamed_search(const Records& ds, const TfOrders& o, double transient_time, const Eigen::VectorXd& full,
                                   const std::vector<int>& free, const Eigen::VectorXd& v0, const Eigen::VectorXd& lo,
                                   const Eigen::VectorXd& hi, const internal::LmOptions& lmo) {
  const int p = static_cast<int>(free.size()), nt = o.nf + o.nb;
  std::vector<Eigen::Index> first;
  for (const IdData& d : ds) first.push_back(first_after(d, transient_time));
  auto normal = [&](const Eigen::VectorXd& x, double& cost, Eigen::MatrixXd* A, Eigen::VectorXd* g) {
    Eigen::VectorXd f = full;
    for (int j = 0; j < p; ++j) f(free[j]) = x(j);
    const Eigen::VectorXd theta = f.head(nt);
    cost = 0.0;
    if (A) {
      A->setZero(p, p);
      g->setZero(p);
    }
    for (std::size_t e = 0; e < ds.size(); ++e)
      signal_detail::with_order(o.nf, [&]<int n>() { oe_stream_n<n>(theta, o.nb, ds[e], first[e], free, cost, A, g); });
    if (A)
      for (int j = 0; j < p; ++j)
        for (int l = 0; l < j; ++l) (*A)(j, l) = (*A)(l, j);
    return std::isfinite(cost) && (!A || (A->allFinite() && g->allFinite()));
  };
  return internal::levenberg_marquardt(internal::LmNormalEvaluate(normal), v0, lo, hi, lmo);
}

// The coloured-noise covariance at a streamed search's estimate x (internal/coloured_covariance.hpp), by two more
// streamed passes: the residuals' autocovariance, then the Jacobian rows filtered by the residuals' AR model.
internal::ColouredCovariance streamed_coloured(const Records& ds, const TfOrders& o, double transient_time,
                                               const Eigen::VectorXd& full, const std::vector<int>& free,
                                               const internal::LmResult& lm) {
  internal::ColouredCovariance out;
  if (!std::isfinite(lm.cost)) return out;
  const int p = static_cast<int>(free.size()), nt = o.nf + o.nb;
  Eigen::VectorXd f = full;
  for (int j = 0; j < p; ++j) f(free[j]) = lm.x(j);
  const Eigen::VectorXd theta = f.head(nt);
  long long n = 0;
  for (const IdData& d : ds) n += d.size() - first_after(d, transient_time);
  internal::ResidualAutocovariance acov(internal::residual_ar_max_lag(n));
  double cost = 0.0;
  for (const IdData& d : ds)
    signal_detail::with_order(o.nf, [&]<int m>() {
      oe_stream_n<m>(theta, o.nb, d, first_after(d, transient_time), free, cost, nullptr, nullptr, &acov);
    });
  out.noise.push_back(acov.fit(p));
  internal::ColouredGram gram(out.noise.back(), p);
  for (const IdData& d : ds)
    signal_detail::with_order(o.nf, [&]<int m>() {
      oe_stream_n<m>(theta, o.nb, d, first_after(d, transient_time), free, cost, nullptr, nullptr, nullptr, &gram);
    });
  out.score = gram.gram();
  return out;
}

Result<TransferFunction> refine(const Records& ds, const TfOrders& o, const TransferFunction& start, const OeOptions& opt,
                                std::chrono::steady_clock::time_point t0) {
  std::vector<std::string> names = tf_parameter_names(o);
  if (opt.estimate_delay) names.push_back("delay");
  const int np = static_cast<int>(names.size());
  const int nt = o.nf + o.nb;
  Eigen::VectorXd full(np);
  full.head(nt) = tf_detail::params_of(start, o);
  if (opt.estimate_delay) full(nt) = start.io_delay();
  const double fixed_delay = start.io_delay();
  const ParameterConstraints c = resolve_constraints(
      opt.fixed, opt.bounds, names, "oe", "a parameter of this structure (" + options_detail::format_names(names) + ")");
  for (int i = 0; i < np; ++i)
    if (c.held[i]) full(i) = c.value(i);
  const std::vector<int> free = c.free();
  CTID_REQUIRE_OPTION(!free.empty(), "oe: every parameter is fixed; nothing to estimate");
  const int p = static_cast<int>(free.size());
  Eigen::VectorXd lo = Eigen::VectorXd::Constant(p, -INFINITY), hi = Eigen::VectorXd::Constant(p, INFINITY), x0(p);
  // (the initial-condition coefficients are appended below, unbounded, starting at 0: the record from rest)
  // The delay stays in the range the delay search used (delay_min, delay_max; default 10 % of the record).
  const double delay_hi = opt.srivc.delay_max >= 0 ? opt.srivc.delay_max : 0.1 * shortest_duration(ds);
  for (int j = 0; j < p; ++j) {
    x0(j) = full(free[j]);
    if (names[free[j]] == "delay") {
      lo(j) = opt.srivc.delay_min;
      hi(j) = delay_hi;
      x0(j) = std::clamp(x0(j), lo(j), hi(j));
    }
    lo(j) = std::max(lo(j), c.lower(free[j]));
    hi(j) = std::min(hi(j), c.upper(free[j]));
  }
  auto full_of = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd f = full;
    for (int j = 0; j < p; ++j) f(free[j]) = x(j);
    return f;
  };
  auto model_of = [&](const Eigen::VectorXd& x) {
    const Eigen::VectorXd f = full_of(x);
    const double T = opt.estimate_delay ? f(nt) : fixed_delay;
    return tf_detail::tf_of(f.head(nt), o, std::max(0.0, T));
  };
  // Unstable and marginally stable models (an integrator the user fixed, an unstable plant recorded in open
  // loop) are simulated exactly like any other; a step whose simulation overflows is rejected by LM.
  // Initial conditions (estimate_initial_state): record e adds its free response, the impulse response of
  // E_e(s)/F(s) with E_e = c_1 s^{nf-1} + .. + c_nf (any initial state of an order-nf model gives such a response,
  // and every such response comes from one state), so the search vector is [x (p) | c of record 1 (ni) | ..] with
  // exact sensitivities d/dc_k = s^{nf-k}/F and d/da_i = -E s^{nf-i}/F^2 (impulse responses). The delay does not
  // act on the free response.
  const int E = static_cast<int>(ds.size());
  const int ni = opt.estimate_initial_state ? o.nf : 0;
  const int q = p + E * ni;
  std::vector<Eigen::VectorXd> since_start;  // each record's times from its first sample (for the free responses)
  if (ni > 0)
    for (const IdData& d : ds) since_start.push_back(d.times().array() - d.times()(0));
  auto power = [](int k) {  // s^k
    Eigen::VectorXd c = Eigen::VectorXd::Zero(k + 1);
    c(0) = 1.0;
    return Polynomial(c);
  };
  OeWorkspace ws;
  auto evaluate = [&](const Eigen::VectorXd& x, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
    const TransferFunction g = model_of(x.head(p));
    if (!stacked_residuals(g, ds, opt.transient_time, o.nb, opt.estimate_delay, r, J != nullptr, ws)) return false;
    if (J) {
      if (J->rows() != r.size() || J->cols() != q) J->resize(r.size(), q);
      if (q > p) J->rightCols(q - p).setZero();
      for (int j = 0; j < p; ++j) J->col(j) = -ws.S.col(free[j]);
    }
    if (ni == 0) return true;
    const Polynomial& F = g.den();
    Eigen::Index at = 0;
    for (int e = 0; e < E; ++e) {
      const Eigen::VectorXd& tt = since_start[static_cast<size_t>(e)];
      const Eigen::Index m = tt.size();
      const Polynomial Ee(Eigen::VectorXd(x.segment(p + e * ni, ni)));
      r.segment(at, m) -= impulse_response(TransferFunction(Ee, F), tt);
      if (J) {
        for (int k = 0; k < ni; ++k)
          J->block(at, p + e * ni + k, m, 1) = -impulse_response(TransferFunction(power(ni - 1 - k), F), tt);
        for (int j = 0; j < p; ++j) {
          const std::string& name = names[static_cast<size_t>(free[j])];
          if (name[0] != 'a') continue;  // b and the delay do not act on the free response
          const int i = std::stoi(name.substr(1));
          J->block(at, j, m, 1) += impulse_response(TransferFunction(Ee * power(o.nf - i), F * F), tt);
        }
      }
      at += m;
    }
    return r.allFinite() && (!J || J->allFinite());
  };
  internal::LmOptions lmo;
  lmo.max_iterations = opt.max_iterations;
  lmo.ftol = opt.tolerance;
  lmo.xtol = opt.tolerance;
  Eigen::VectorXd v0 = Eigen::VectorXd::Zero(q), v_lo = Eigen::VectorXd::Constant(q, -INFINITY),
                  v_hi = Eigen::VectorXd::Constant(q, INFINITY);
  v0.head(p) = x0;
  v_lo.head(p) = lo;
  v_hi.head(p) = hi;
  internal::LmResult lm;
  internal::ColouredCovariance streamed;  // the streamed search's coloured-noise covariance
  const bool streams = streamable(ds, o, opt.estimate_delay || fixed_delay != 0.0, ni);
  if (streams) {
    lm = streamed_search(ds, o, opt.transient_time, full, free, v0, v_lo, v_hi, lmo);
    streamed = streamed_coloured(ds, o, opt.transient_time, full, free, lm);
  } else {
    lmo.keep_jacobian = true;
    lm = internal::levenberg_marquardt(internal::LmEvaluate(evaluate), v0, v_lo, v_hi, lmo);
  }
  Eigen::VectorXd free_response;  // the estimated free responses, stacked (empty: from rest)
  if (ni > 0 && std::isfinite(lm.cost)) {
    Eigen::VectorXd with, without;
    evaluate(lm.x, with, nullptr);
    Eigen::VectorXd rest = lm.x;
    rest.tail(E * ni).setZero();
    evaluate(rest, without, nullptr);
    free_response = without - with;
    // The information about the model's parameters with the initial conditions eliminated (Schur complement).
    const Eigen::MatrixXd& F = lm.jtj;
    lm.jtj = (F.topLeftCorner(p, p) - F.topRightCorner(p, E * ni) *
                                          F.bottomRightCorner(E * ni, E * ni).ldlt().solve(F.bottomLeftCorner(E * ni, p)))
                 .eval();
  }
  lm.x.conservativeResize(p);

  Result<TransferFunction> r;
  r.model = model_of(lm.x);
  r.parameters.names = names;
  r.parameters.values = full;
  for (int j = 0; j < p; ++j) r.parameters.values(free[j]) = lm.x(j);
  r.parameters.fixed = c.held;
  auto [y_all, sim_all] = tf_detail::pooled_outputs(r.model, ds, opt.transient_time);
  if (free_response.size()) sim_all += free_response;
  r.fit = fit_report_or_inf(y_all, sim_all, p + E * ni);
  const double sigma2 = 2.0 * lm.cost / double(std::max<Eigen::Index>(1, y_all.size() - p - E * ni));
  std::vector<internal::ResidualSequence> sequences;  // each record after its transient, in time order
  Eigen::Index row = 0;
  for (const IdData& d : ds) {
    const Eigen::Index m = d.size() - first_after(d, opt.transient_time);
    sequences.push_back({row, m, 0});
    row += m;
  }
  search::UserBounds user{Eigen::VectorXd(p), Eigen::VectorXd(p)};  // bounds.NAME (not the delay's search range)
  for (int j = 0; j < p; ++j) {
    user.lower(j) = c.lower(free[j]);
    user.upper(j) = c.upper(free[j]);
  }
  const search::CovarianceVerdict verdict =
      streams ? search::set_covariance(r.parameters, r.diagnostics, lm, free, sigma2, user, streamed)
              : search::set_covariance(r.parameters, r.diagnostics, lm, free, sigma2, user, sequences);
  r.diagnostics.set(diagnostic::noise_variance, sigma2);
  r.diagnostics.set(diagnostic::delay, r.model.io_delay());
  r.diagnostics.set(diagnostic::evaluations, lm.evaluations);
  r.diagnostics.set(diagnostic::jacobian_evaluations, lm.jacobians);
  if (ds.size() > 1) r.diagnostics.set(diagnostic::experiments, static_cast<double>(ds.size()));
  internal::set_termination(
      r.summary, lm,
      "the simulation of the starting model overflows on this record (its poles are far in the right half plane); "
      "fix or bound the coefficients (--set fixed.NAME=VALUE, bounds.NAME=LOWER,UPPER)",
      verdict.unidentifiable, verdict.at_bound);
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

// The starting model of the refinement: the equation-error (SRIVC) model as it is when it simulates better than
// its stabilised copy (an unstable plant recorded in open loop), else the stabilised copy.
TransferFunction starting_model(const TransferFunction& s, const Records& ds, double transient) {
  if (s.is_stable()) return s;
  const TransferFunction st = tf_detail::stabilized(s);
  Eigen::VectorXd r_raw, r_stab;
  OeWorkspace ws;
  const bool raw_ok = stacked_residuals(s, ds, transient, 1, false, r_raw, false, ws);
  stacked_residuals(st, ds, transient, 1, false, r_stab, false, ws);
  return raw_ok && r_raw.squaredNorm() < r_stab.squaredNorm() ? s : st;
}

void check_record(const IdData& data, const TfOrders& o, const OeOptions& opt, const std::string& who_s, bool several) {
  const char* who = who_s.c_str();
  require_io_data(data, who);
  CTID_REQUIRE(o.nk == 0 || data.is_uniform(), "{}: nk = {} needs uniformly sampled data", who, o.nk);
  CTID_REQUIRE(several || data.size() > o.nf + o.nb + 1, "{}: {} samples cannot determine {} parameters", who, data.size(),
               o.nf + o.nb);
  CTID_REQUIRE(opt.transient_time < data.duration(), "{}: transient_time = {} s is not shorter than the record ({} s)", who,
               opt.transient_time, data.duration());
  CTID_REQUIRE_OPTION(!(opt.estimate_initial_state && opt.transient_time > 0),
                      "{}: estimate_initial_state and transient_time = {} s are alternatives for a record that does not "
                      "start at rest; set one", who, opt.transient_time);
  const double delay = opt.delay + (o.nk > 0 ? o.nk * data.ts() : 0.0);
  CTID_REQUIRE(delay < data.duration(), "{}: the input delay {} s is not shorter than the record ({} s)", who, delay,
               data.duration());
  CTID_REQUIRE_OPTION(!(opt.estimate_delay && o.nb > o.nf), "{}: delay estimation needs a strictly proper model (nb <= nf)",
                      who);
  CTID_REQUIRE(!opt.estimate_delay || opt.srivc.delay_max < data.duration(),
               "{}: delay_max = {} s is not shorter than the record ({} s)", who, opt.srivc.delay_max, data.duration());
  CTID_REQUIRE(!opt.estimate_delay || opt.srivc.delay_min < data.duration(),
               "{}: delay_min = {} s is not shorter than the record ({} s)", who, opt.srivc.delay_min, data.duration());
  CTID_REQUIRE_OPTION(!opt.initial || opt.initial->order() == o.nf, "{}: the initial model has order {} but nf = {}", who,
                      opt.initial ? opt.initial->order() : 0, o.nf);
}

void check_common(const internal::RecordRefs& ds, const TfOrders& o, const OeOptions& opt, const char* who) {
  o.validate(/*allow_biproper=*/true);
  opt.validate();
  CTID_REQUIRE(!ds.empty(), "{}: no records given", who);
  long long total = 0;
  for (std::size_t e = 0; e < ds.size(); ++e) {
    check_record(ds[e], o, opt, ds.size() == 1 ? std::string(who) : detail::format("{} (record {})", who, e + 1), ds.size() > 1);
    CTID_REQUIRE(e == 0 || o.nk == 0 || std::abs(ds[e].ts() - ds[0].ts()) <= 1e-9 * ds[0].ts(),
                 "{} (record {}): nk counts samples, so the records need one sampling period ({} s and {} s)", who, e + 1,
                 ds[0].ts(), ds[e].ts());
    total += ds[e].size();
  }
  CTID_REQUIRE(total > o.nf + o.nb + 1, "{}: {} samples cannot determine {} parameters", who, total, o.nf + o.nb);
}

// The options in the normalised units of n (tf_common.hpp): values, bounds and fixed values by parameter name,
// delays and starting models.
OeOptions normalised(const OeOptions& o, const tf_detail::TfNormalisation& n, const TfOrders& orders) {
  OeOptions s = o;
  if (s.initial) s.initial = n.to_normalised(*s.initial, orders);
  for (auto& [k, v] : s.fixed) v *= n.factor(k, orders);
  for (auto& [k, b] : s.bounds) {
    b.first *= n.factor(k, orders);
    b.second *= n.factor(k, orders);
  }
  s.delay /= n.c;
  if (s.srivc.initial) s.srivc.initial = n.to_normalised(*s.srivc.initial, orders);
  s.srivc.delay /= n.c;
  s.srivc.delay_min /= n.c;
  if (s.srivc.delay_max >= 0) s.srivc.delay_max /= n.c;
  s.transient_time /= n.c;
  s.srivc.transient_time = s.transient_time;  // the SRIVC start leaves out the same transient
  return s;
}

// Runs `fit` (oe or tfest in the units of its record) on the normalised record and maps the result back.
template <class F>
Result<TransferFunction> in_normalised_units(const internal::RecordRefs& data, const TfOrders& orders, const OeOptions& options,
                                             F&& fit) {
  const auto t0 = std::chrono::steady_clock::now();
  const tf_detail::TfNormalisation n = tf_detail::TfNormalisation::of(data);
  Records normalised_records;
  for (const IdData& d : data) normalised_records.push_back(n.data(d));
  Result<TransferFunction> r = fit(normalised_records, normalised(options, n, orders), t0);
  n.restore(r, orders);
  // A parameter left on a bound: named with the bound as the user gave it (the search ran in normalised units).
  if (r.summary.termination == Termination::AtBound) {
    std::vector<search::HeldAtBound> held;
    for (const auto& [name, b] : options.bounds) {
      const int i = r.parameters.index(name);
      if (!std::isnan(r.parameters.std(i))) continue;
      const double v = r.parameters.values(i);
      const bool lower = std::abs(v - b.first) <= 1e-9 * std::max(1.0, std::abs(b.first));
      if (!lower && !(std::abs(v - b.second) <= 1e-9 * std::max(1.0, std::abs(b.second)))) continue;
      held.push_back({name, lower, lower ? b.first : b.second});
      r.parameters.values(i) = held.back().bound;
    }
    if (!held.empty()) r.summary.message = search::at_bound_text(held);
  }
  // The held parameters exactly as given (the round trip through the normalised units can change their last bit).
  if (!options.fixed.empty() && r.parameters.values.size() == static_cast<Eigen::Index>(r.parameters.names.size())) {
    for (const auto& [name, v] : options.fixed) r.parameters.values(r.parameters.index(name)) = v;
    const int nt = orders.nf + orders.nb;
    const double delay = r.parameters.values.size() > nt ? r.parameters.values(nt) : r.model.io_delay();
    if (r.model.den().coefficients().allFinite()) r.model = tf_detail::tf_of(r.parameters.values.head(nt), orders, delay);
  }
  tf_detail::finish_tf_result(r, data.front());
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

double base_delay(const IdData& data, const TfOrders& o, const OeOptions& opt) {
  return opt.delay + (o.nk > 0 ? o.nk * data.ts() : 0.0);
}

Result<TransferFunction> oe_in_units(const Records& data, const TfOrders& orders, const OeOptions& options,
                                     std::chrono::steady_clock::time_point t0) {
  TransferFunction start;
  if (options.estimate_delay) {
    // A delay is only found reliably by a search over its range (the cost has local minima
    // one input period apart): SRIVC's delay search, seeded with the user's dynamics.
    SrivcOptions so = options.srivc;
    so.estimate_delay = true;
    if (options.initial) so.initial = TransferFunction(options.initial->num(), options.initial->den());
    start = starting_model(srivc(data, orders, so).model, data, options.transient_time);
  } else if (options.initial) {
    start = *options.initial;
    if (!options.estimate_delay && start.io_delay() == 0.0) start.set_io_delay(base_delay(data.front(), orders, options));
  } else {
    SrivcOptions so = options.srivc;
    so.delay = options.delay;
    so.max_iterations = 1;  // LSSVF start plus one refinement: a cheap equation-error initial model
    const Result<TransferFunction> s = srivc(data, orders, so);
    start = starting_model(s.model, data, options.transient_time);
  }
  return refine(data, orders, start, options, t0);
}

Result<TransferFunction> tfest_in_units(const Records& data, const TfOrders& orders, const OeOptions& options,
                                        std::chrono::steady_clock::time_point t0) {
  SrivcOptions so = options.srivc;
  so.delay = options.delay;
  so.estimate_delay = options.estimate_delay;
  if (options.initial) so.initial = options.initial;
  const Result<TransferFunction> s = srivc(data, orders, so);
  Result<TransferFunction> r = refine(data, orders, starting_model(s.model, data, options.transient_time), options, t0);
  r.diagnostics.set(diagnostic::srivc_iterations, s.summary.iterations);
  r.diagnostics.set(diagnostic::srivc_fit_percent, s.fit.fit_percent);
  return r;
}

// With estimate_initial_state: each record's initial state in the fitted model's realisation, in the record's units —
// the least-squares state of simulate(Estimated), which spans the same free responses as the fit's E_e(s)/A(s) and
// so reproduces the fit's simulation.
void set_initial_states(Result<TransferFunction>& r, const internal::RecordRefs& data, const OeOptions& options) {
  if (!options.estimate_initial_state || !r.model.den().coefficients().allFinite()) return;
  SimulateOptions so;
  so.initial = InitialCondition::Estimated;
  for (std::size_t e = 0; e < data.size(); ++e)
    r.diagnostics.set(diagnostic::x0, simulate(AnyModel(r.model), data[e], so).x0, static_cast<int>(e));
}

// oe and tfest estimate in normalised time and amplitude units (the result does not depend on the
// units of the record) and map the result back.
Result<TransferFunction> oe_records(const internal::RecordRefs& data, const TfOrders& orders, const OeOptions& options) {
  check_common(data, orders, options, "oe");
  Result<TransferFunction> r = in_normalised_units(data, orders, options, [&](const Records& d, const OeOptions& o, auto t0) {
    return oe_in_units(d, orders, o, t0);
  });
  set_initial_states(r, data, options);
  return r;
}

Result<TransferFunction> tfest_records(const internal::RecordRefs& data, const TfOrders& orders,
                                       const OeOptions& options) {
  check_common(data, orders, options, "tfest");
  Result<TransferFunction> r = in_normalised_units(data, orders, options, [&](const Records& d, const OeOptions& o, auto t0) {
    return tfest_in_units(d, orders, o, t0);
  });
  set_initial_states(r, data, options);
  return r;
}

}  // namespace

Result<TransferFunction> oe(const std::vector<IdData>& data, const TfOrders& orders, const OeOptions& options) {
  return oe_records(data, orders, options);
}

Result<TransferFunction> oe(const IdData& data, const TfOrders& orders, const OeOptions& options) {
  return oe_records(data, orders, options);
}

Result<TransferFunction> tfest(const std::vector<IdData>& data, const TfOrders& orders, const OeOptions& options) {
  return tfest_records(data, orders, options);
}

Result<TransferFunction> tfest(const IdData& data, const TfOrders& orders, const OeOptions& options) {
  return tfest_records(data, orders, options);
}

}  // namespace ctid
