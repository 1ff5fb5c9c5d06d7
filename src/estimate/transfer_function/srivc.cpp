// SRIVC — Young & Jakeman (1980); Garnier & Wang (2008) ch. 4. See include/ctid/estimate/transfer_function/srivc.hpp.
#include "ctid/estimate/transfer_function/srivc.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <optional>

#include "ctid/core/check.hpp"
#include "ctid/core/progress.hpp"
#include "ctid/estimate/svf/lssvf.hpp"
#include "ctid/signal/prefilter.hpp"
#include "ctid/simulate/lsim.hpp"
#include "ctid/validate/metrics.hpp"
#include "ctid/validate/residuals.hpp"
#include "estimate/svf/svf_common.hpp"
#include "estimate/transfer_function/tf_common.hpp"
#include "internal/least_squares.hpp"
#include "signal/filter_bank.hpp"

namespace ctid {

template <>
const OptionTable<SrivcOptions>& option_table<SrivcOptions>() {
  using O = SrivcOptions;
  static const OptionTable<O> t =
      OptionTable<O>("srivc")
          .integer("max_iterations", &O::max_iterations, "", at_least(1), "IV iterations")
          .real("tolerance", &O::tolerance, "", above(0),
                "stop when max_i |change of theta_i| / max(|theta_i|, 1e-8) is below")
          .model("initial", &O::initial, "starting model of the same orders; none: LSSVF with an automatic filter")
          .real("delay", &O::delay, "s", at_least(0), "input delay added to nk Ts (the start of the search when estimated)")
          .flag("estimate_delay", &O::estimate_delay,
                "estimate a non-integer input delay: grid search over [delay_min, delay_max], then refinement")
          .real("delay_min", &O::delay_min, "s", at_least(0), "lower end of the delay search")
          .real("delay_max", &O::delay_max, "s", or_special(at_least(0), -1, "10 % of the record"),
                "upper end of the delay search")
          .integer("delay_grid", &O::delay_grid, "", or_special(between(1, O::kMaxDelayGrid), 0, "one per sample period, at most 200"),
                   "grid points of the delay search")
          .real("transient_time", &O::transient_time, "s", at_least(0),
                "seconds at the start of each record left out of the IV equations and the fit (records not at rest)");
  return t;
}

void SrivcOptions::validate() const {
  option_table<SrivcOptions>().check(*this);
  CTID_REQUIRE_OPTION(delay_max < 0 || delay_max >= delay_min, "srivc: the delay range [{}, {}] s is empty", delay_min,
                      delay_max);
}


using namespace tf_detail;

namespace srivc_detail {
struct IvChannel {
  Eigen::VectorXd u;
  Intersample intersample;
  double delay;
  int nb;
};
// Closed-loop instruments (CLSRIVC): the noise-free loop driven by the reference r with the
// known controller C; the reference enters at the plant input (u = r - C y) or as a setpoint
// (u = C (r - y)).
struct ClosedLoopInstruments {
  Eigen::VectorXd r;
  Intersample intersample = Intersample::Zoh;
  TransferFunction controller;
  bool at_plant_input = true;
};
}  // namespace srivc_detail

namespace {

struct SrivcRun {
  Eigen::VectorXd theta;        // [a1..an, b(1)..., b(K)...]
  internal::LinearSolution sol; // of the last IV step
  Eigen::MatrixXd zz;           // sum zeta zeta^T of the last step
  Eigen::MatrixXd zx;           // sum zeta phi^T of the last step
  int iterations = 0;
  bool converged = false;
  bool rank_deficient = false;
  bool interrupted = false;
};

double relative_change(const Eigen::VectorXd& next, const Eigen::VectorXd& prev) {
  double change = 0;
  for (Eigen::Index i = 0; i < next.size(); ++i)
    change = std::max(change, std::abs(next(i) - prev(i)) / std::max(std::abs(next(i)), 1e-8));
  return change;
}

// How an IV iteration ended, shared by the SRIVC variants.
template <class M>
void set_termination(Result<M>& r, bool rank_deficient, bool converged, double tolerance, int max_iterations,
                     const std::string& singular_message) {
  if (rank_deficient) {
    r.summary.termination = Termination::RankDeficient;
    r.summary.message = singular_message;
  } else if (!converged) {
    r.summary.termination = Termination::MaxIterations;
    r.summary.message = detail::format("the iteration limit ended the IV iterations, not convergence: no relative change "
                                       "below {} in {} iterations; raise max_iterations", tolerance, max_iterations);
  } else {
    r.summary.termination = Termination::Converged;
  }
  if (r.summary.succeeded() && !r.model.is_stable()) {
    r.summary.termination = Termination::Unstable;
    r.summary.message = "SRIVC converged to an unstable model (its prefilter is kept stable, so its estimate of an "
                        "unstable plant is not consistent); for a plant that is unstable in open loop use tfest or oe, "
                        "which fit unstable models by output error";
  }
}

}  // namespace

namespace srivc_detail {

// The filtered signals of one record's IV step, kept from one iteration to the next so that no iteration
// allocates (or page-faults) buffers that grow with the record.
struct IvWorkspace {
  Eigen::MatrixXd yf, xf, tmp;
  std::vector<Eigen::MatrixXd> uf, uz;  // per input channel
};

// One record of an IV step (several records: several experiments, each filtered from rest).
struct IvRecord {
  const Eigen::VectorXd* y;
  const Eigen::VectorXd* t;
  const std::vector<IvChannel>* ch;
  Eigen::Index first = 0;                   // rows before it (the record's transient) are left out
  const ClosedLoopInstruments* cl = nullptr;  // closed loop: instruments from this record's reference
  IvWorkspace* ws = nullptr;                  // its buffers (null: fresh ones each step)
  double h = 0;                               // > 0: uniformly sampled at this interval (the streaming pass)
};

// The rows of an open-loop, single-input, delay-free IV step on uniform samples, made and added sample by sample:
// the banks 1/A of y (FOH) and of u, and B/A^2 of u (the instruments) advance together, so that the step reads y
// and u once and writes nothing that grows with the record (the same recursions as filtered_derivatives).
template <int n>
void iv_stream_n(internal::InstrumentalVariables& iv, const Polynomial& A, const Eigen::VectorXd& y, const IvChannel& c,
                 int p, const Eigen::VectorXd& theta, Eigen::Index first, double h) {
  const TransferFunction F(Polynomial{1.0}, A);
  const Eigen::VectorXd b = theta.segment(n, c.nb);
  const bool aux = b.cwiseAbs().maxCoeff() > 0;
  signal_detail::Bank<n> yb(derivative_recursion(F, n, h, Intersample::Foh));
  signal_detail::Bank<n> ub(derivative_recursion(F, c.nb - 1, h, c.intersample));
  std::optional<signal_detail::Bank<2 * n>> xb;
  if (aux) xb.emplace(derivative_recursion(TransferFunction(Polynomial(b), A * A), n - 1, h, c.intersample));
  std::vector<double> phi(p), zeta(p, 0.0);
  const int m = c.nb - 1;
  const Eigen::Index N = y.size();
  for (Eigen::Index k = 0; k < N; ++k) {
    const double* yr = yb.at(y(k));
    const double* ur = ub.at(c.u(k));
    const double* xr = aux ? xb->at(c.u(k)) : nullptr;
    if (k >= first) {
      for (int i = 1; i <= n; ++i) {
        phi[i - 1] = -yr[n - i];
        zeta[i - 1] = aux ? -xr[n - i] : 0.0;
      }
      for (int j = 0; j <= m; ++j) phi[n + j] = zeta[n + j] = ur[m - j];
      iv.add(zeta.data(), phi.data(), yr[n], 1.0);
    }
    if (k + 1 == N) break;
    yb.advance(y(k), y(k + 1));
    ub.advance(c.u(k), c.u(k + 1));
    if (aux) xb->advance(c.u(k), c.u(k + 1));
  }
}

// iv_stream_n for the model order n (1..8); false for another order (the caller uses the matrices).
bool iv_stream(internal::InstrumentalVariables& iv, const Polynomial& A, const Eigen::VectorXd& y, const IvChannel& c,
               int n, int p, const Eigen::VectorXd& theta, Eigen::Index first, double h) {
  return signal_detail::with_order(n, [&]<int N>() { iv_stream_n<N>(iv, A, y, c, p, theta, first, h); });
}

// Adds one record's rows of an SRIVC instrumental-variable step to iv (see iv_step).
void iv_accumulate(internal::InstrumentalVariables& iv, const Polynomial& A, const Eigen::VectorXd& y, const Eigen::VectorXd& t,
                   const std::vector<IvChannel>& ch, int n, int p, const Eigen::VectorXd& theta,
                   const ClosedLoopInstruments* cl, Eigen::Index first, IvWorkspace& ws, double h) {
  const TransferFunction F(Polynomial{1.0}, A);
  if (h > 0 && !cl && ch.size() == 1 && ch.front().delay == 0.0 && n >= 1 && n <= 8 &&
      iv_stream(iv, A, y, ch.front(), n, p, theta, first, h))
    return;
  filtered_derivatives_into(F, n, y, t, Intersample::Foh, 0.0, ws.yf);
  const Eigen::MatrixXd& yf = ws.yf;
  Eigen::MatrixXd& xf = ws.xf;
  xf.setZero(t.size(), n);
  std::vector<Eigen::MatrixXd>& uf = ws.uf;  // regressors and instruments of the input part
  std::vector<Eigen::MatrixXd>& uz = ws.uz;
  uf.resize(ch.size());
  if (cl) uz.resize(ch.size());
  int off = n;
  for (std::size_t ci = 0; ci < ch.size(); ++ci) {
    const IvChannel& c = ch[ci];
    const Eigen::VectorXd b = theta.segment(off, c.nb);
    off += c.nb;
    filtered_derivatives_into(F, c.nb - 1, c.u, t, c.intersample, c.delay, uf[ci]);
    if (cl) {
      // Noise-free loop: u^ = S r (or C S r), x^ = B/A u^, S = A Dc / (A Dc + B Nc); prefiltered by 1/A.
      const Polynomial& Nc = cl->controller.num();
      const Polynomial& Dc = cl->controller.den();
      const Polynomial B(b);
      const Polynomial Pcl = stabilized(TransferFunction(Polynomial{1.0}, A * Dc + B * Nc)).den();
      const Polynomial Su = cl->at_plant_input ? A * Dc : A * Nc;  // u^ = Su / Pcl r
      const Polynomial Sx = cl->at_plant_input ? B * Dc : B * Nc;  // x^ = Sx / Pcl r
      filtered_derivatives_into(TransferFunction(Su, Pcl * A), c.nb - 1, cl->r, t, cl->intersample, 0.0, uz[ci]);
      filtered_derivatives_into(TransferFunction(Sx, Pcl * A), n - 1, cl->r, t, cl->intersample, 0.0, xf);
    } else if (b.cwiseAbs().maxCoeff() > 0) {
      filtered_derivatives_into(TransferFunction(Polynomial(b), A * A), n - 1, c.u, t, c.intersample, c.delay, ws.tmp);
      xf += ws.tmp;
    }
  }
  std::vector<double> phi(p), zeta(p);
  for (Eigen::Index k = first; k < t.size(); ++k) {
    for (int i = 1; i <= n; ++i) {
      phi[i - 1] = -yf(k, n - i);
      zeta[i - 1] = -xf(k, n - i);
    }
    int o = n;
    for (std::size_t c = 0; c < ch.size(); ++c) {
      const int m = ch[c].nb - 1;
      for (int j = 0; j <= m; ++j) {
        phi[o + j] = uf[c](k, m - j);
        zeta[o + j] = cl ? uz[c](k, m - j) : phi[o + j];
      }
      o += ch[c].nb;
    }
    iv.add(zeta.data(), phi.data(), yf(k, n), 1.0);
  }
}

// One SRIVC instrumental-variable step for y = sum_i B_i/A u_i (common denominator):
// prefilter 1/A (A stabilised), regressors from the measured y and inputs, instruments from
// the auxiliary-model output sum_i B_i/A u_i. theta = [a (n), b_1 (nb_1), ..., b_K (nb_K)]. The normal equations
// are summed over the records (each record's filters start at rest).
SrivcRun iv_step(const std::vector<IvRecord>& records, int n, const Eigen::VectorXd& theta) {
  int p = n;
  for (const auto& c : *records.front().ch) p += c.nb;
  Eigen::VectorXd den(n + 1);
  den(0) = 1.0;
  den.tail(n) = theta.head(n);
  const Polynomial A = stabilized(TransferFunction(Polynomial{1.0}, Polynomial(den))).den();
  internal::InstrumentalVariables iv(p, /*with_rss=*/false);
  for (const auto& rec : records) {
    IvWorkspace fresh;
    iv_accumulate(iv, A, *rec.y, *rec.t, *rec.ch, n, p, theta, rec.cl, rec.first, rec.ws ? *rec.ws : fresh, rec.h);
  }
  SrivcRun run;
  run.sol = iv.solve();
  run.zz = iv.zz();
  run.zx = iv.zx();
  run.theta = run.sol.theta;
  run.rank_deficient = run.sol.rank_deficient || !run.sol.theta.allFinite();
  return run;
}

}  // namespace srivc_detail

using srivc_detail::IvChannel;

namespace {

using Records = std::vector<IdData>;  // one or several experiments of one system


// SRIVC iterations at a fixed total delay (SISO), the IV equations summed over the records.
SrivcRun srivc_fixed_delay(const Records& ds, const TfOrders& o, double delay, Eigen::VectorXd theta, const SrivcOptions& opt,
                           int max_iterations) {
  std::vector<Eigen::VectorXd> ts, ys;
  std::vector<std::vector<IvChannel>> chs;
  for (const IdData& d : ds) {
    ts.push_back(d.times());
    ys.push_back(d.y().col(0));
    chs.emplace_back().push_back({d.u().col(0), d.intersample(0), delay, o.nb});  // one copy of u (a braced list would copy it twice)
  }
  std::vector<srivc_detail::IvWorkspace> ws(ds.size());
  std::vector<srivc_detail::IvRecord> recs;
  for (std::size_t e = 0; e < ds.size(); ++e)
    recs.push_back({&ys[e], &ts[e], &chs[e], first_after(ds[e], opt.transient_time), nullptr, &ws[e],
                    ds[e].is_uniform() ? ds[e].ts() : 0.0});
  SrivcRun run;
  run.theta = theta;
  for (int it = 1; it <= max_iterations; ++it) {
    if (!report_progress("srivc", it, NAN)) {
      run.interrupted = true;
      return run;
    }
    SrivcRun step = srivc_detail::iv_step(recs, o.nf, run.theta);
    step.iterations = it;
    if (step.rank_deficient) {
      step.theta = run.theta;
      return step;
    }
    const double change = relative_change(step.theta, run.theta);
    run = step;
    if (change < opt.tolerance) {
      run.converged = true;
      return run;
    }
  }
  return run;
}

// The mean squared output error over all records after their transients (+Inf when a simulation diverges).
double pooled_mse(const TransferFunction& g, const Records& ds, double transient) {
  const auto [y, sim] = pooled_outputs(g, ds, transient);
  if (!sim.allFinite()) return std::numeric_limits<double>::infinity();
  return (y - sim).squaredNorm() / double(std::max<Eigen::Index>(1, y.size()));
}

Eigen::VectorXd initial_theta(const Records& ds, const TfOrders& o, double delay, const SrivcOptions& opt) {
  if (opt.initial) {
    CTID_REQUIRE_OPTION(opt.initial->order() == o.nf, "srivc: the initial model has order {} but nf = {}", opt.initial->order(),
                        o.nf);
    return params_of(*opt.initial, o);
  }
  // LSSVF with an automatic filter on the delay-shifted input (nk = 0, strictly proper), on the longest record.
  const IdData& d = *std::max_element(ds.begin(), ds.end(), [](const IdData& a, const IdData& b) { return a.size() < b.size(); });
  std::optional<IdData> shifted;  // only a delay makes a new record; otherwise the record itself
  if (delay > 0) {
    const Eigen::VectorXd ud = filtered_derivatives(TransferFunction(Polynomial{1.0}, Polynomial{1.0}), 0, d.u().col(0),
                                                    d.times(), d.intersample(0), delay);
    Eigen::MatrixXd u = ud;
    shifted = d.is_uniform() ? IdData(u, d.y(), d.ts(), d.t0()) : IdData(u, d.y(), d.times());
    shifted->set_intersample(0, d.intersample(0));
  }
  const TfOrders lo{std::min(o.nb, o.nf), o.nf, 0};
  LssvfOptions lso;
  lso.tau_grid_size = 3;  // a rough start is enough: SRIVC's own iterations do the rest
  const Result<TransferFunction> ls = lssvf(shifted ? *shifted : d, lo, lso);
  Eigen::VectorXd th = Eigen::VectorXd::Zero(o.nf + o.nb);
  th.head(o.nf) = ls.parameters.values.head(o.nf);
  th.tail(lo.nb) = ls.parameters.values.tail(lo.nb);
  return th;
}

}  // namespace

namespace {
// The checks of srivc()'s inputs, in the user's units (messages name seconds), for each record.
void check_srivc_inputs(const internal::RecordRefs& ds, const TfOrders& orders, const SrivcOptions& options) {
  CTID_REQUIRE(!ds.empty(), "srivc: no records given");
  for (std::size_t e = 0; e < ds.size(); ++e) {
    const IdData& data = ds[e];
    const std::string who = ds.size() == 1 ? "srivc" : detail::format("srivc (record {})", e + 1);
    require_io_data(data, who.c_str());
    CTID_REQUIRE(orders.nk == 0 || data.is_uniform(), "{}: nk = {} needs uniformly sampled data", who, orders.nk);
    const int p = orders.nf + orders.nb;
    CTID_REQUIRE(ds.size() > 1 || data.size() > p, "srivc: {} samples cannot determine {} parameters", data.size(), p);
    const double base_delay = options.delay + (orders.nk > 0 ? orders.nk * data.ts() : 0.0);
    CTID_REQUIRE(base_delay < data.duration(), "{}: the input delay {} s is not shorter than the record ({} s)", who,
                 base_delay, data.duration());
    CTID_REQUIRE(!options.estimate_delay || options.delay_max < data.duration(),
                 "{}: delay_max = {} s is not shorter than the record ({} s)", who, options.delay_max, data.duration());
    CTID_REQUIRE(options.transient_time < data.duration(), "{}: transient_time = {} s is not shorter than the record ({} s)",
                 who, options.transient_time, data.duration());
    CTID_REQUIRE(!options.estimate_delay || options.delay_min < data.duration(),
                 "{}: delay_min = {} s is not shorter than the record ({} s)", who, options.delay_min, data.duration());
    CTID_REQUIRE(e == 0 || (orders.nk == 0 || std::abs(data.ts() - ds[0].ts()) <= 1e-9 * ds[0].ts()),
                 "{}: nk counts samples, so the records need one sampling period (record 1: {} s, this one: {} s)", who,
                 ds[0].ts(), data.ts());
  }
  long long total = 0;
  for (const IdData& d : ds) total += d.size();
  CTID_REQUIRE(total > orders.nf + orders.nb, "srivc: {} samples cannot determine {} parameters", total,
               orders.nf + orders.nb);
  CTID_REQUIRE_OPTION(!options.initial || options.initial->order() == orders.nf,
                      "srivc: the initial model has order {} but nf = {}", options.initial ? options.initial->order() : 0,
                      orders.nf);
}

// SISO SRIVC in the units of the records (srivc() calls it on the normalised records).
Result<TransferFunction> srivc_in_units(const Records& ds, const TfOrders& orders, const SrivcOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const IdData& data = ds.front();
  const int p = orders.nf + orders.nb;
  const double base_delay = options.delay + (orders.nk > 0 ? orders.nk * data.ts() : 0.0);
  double shortest = data.duration();
  for (const IdData& d : ds) shortest = std::min(shortest, d.duration());

  double delay = base_delay;
  Eigen::VectorXd theta;
  Eigen::VectorXd grid, grid_cost;
  if (options.estimate_delay) {
    const double dmax = options.delay_max >= 0 ? options.delay_max : 0.1 * shortest;
    const double h = data.is_uniform() ? data.ts() : data.duration() / std::max(1, data.size() - 1);
    int G = options.delay_grid > 0 ? options.delay_grid
                                   : static_cast<int>(std::min(200.0, std::floor((dmax - options.delay_min) / h) + 1));
    G = std::max(G, 2);
    grid.resize(G);
    grid_cost.resize(G);
    double best = std::numeric_limits<double>::infinity();
    Eigen::VectorXd warm;
    for (int i = 0; i < G; ++i) {
      if (!report_progress("delay_grid", i + 1, best)) {  // interrupted: keep the points done so far
        grid.conservativeResize(i);
        grid_cost.conservativeResize(i);
        break;
      }
      const double dl = options.delay_min + (dmax - options.delay_min) * i / double(G - 1);
      grid(i) = dl;
      // The first grid point starts from the user's model or LSSVF; the others from their
      // neighbour's estimate (the dynamics change little between neighbouring delays).
      const Eigen::VectorXd th0 = i == 0 ? initial_theta(ds, orders, dl, options) : warm;
      const SrivcRun r = srivc_fixed_delay(ds, orders, dl, th0, options, 3);
      warm = r.rank_deficient || !r.theta.allFinite() ? th0 : r.theta;
      grid_cost(i) = r.rank_deficient ? INFINITY : pooled_mse(tf_of(r.theta, orders, dl), ds, options.transient_time);
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
    if (theta.size() == 0) theta = initial_theta(ds, orders, delay, options);  // interrupted before the first point
    for (int outer = 0; outer < 40 && !interrupt_requested(); ++outer) {
      theta = srivc_fixed_delay(ds, orders, delay, theta, options, options.max_iterations).theta;
      auto cost = [&](double dl) { return pooled_mse(tf_of(theta, orders, dl), ds, options.transient_time); };
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
    theta = initial_theta(ds, orders, delay, options);
  }

  const SrivcRun run = srivc_fixed_delay(ds, orders, delay, theta, options, options.max_iterations);
  Result<TransferFunction> r;
  r.model = tf_of(run.theta, orders, delay);
  r.parameters.names = tf_parameter_names(orders);
  r.parameters.values = run.theta;
  r.parameters.fixed.assign(p, false);
  // The simulation fit over all records (each from rest, after its transient), as one concatenated output.
  const auto [y_all, sim_all] = pooled_outputs(r.model, ds, options.transient_time);
  const Eigen::Index total = y_all.size();
  r.fit = fit_report_or_inf(y_all, sim_all, p + (options.estimate_delay ? 1 : 0));
  // Covariance sigma^2 (sum zeta zeta^T)^{-1}, sigma^2 from the output error.
  const double sigma2 = r.fit.mse * double(total) / double(std::max<Eigen::Index>(1, total - p));
  // (no zz when interrupted before a step)
  r.parameters.set_covariance(run.rank_deficient ? Eigen::MatrixXd() : internal::covariance(run.zz, sigma2));
  r.diagnostics.condition_number = run.sol.condition;
  r.diagnostics.set(diagnostic::delay, delay);
  r.diagnostics.set(diagnostic::noise_variance, sigma2);
  if (ds.size() > 1) r.diagnostics.set(diagnostic::experiments, static_cast<double>(ds.size()));
  if (grid.size() > 0) {
    r.diagnostics.set(diagnostic::delay_grid, grid);
    r.diagnostics.set(diagnostic::delay_grid_mse, grid_cost);
  }
  r.summary.iterations = run.iterations;
  set_termination(r, run.rank_deficient, run.converged, options.tolerance, options.max_iterations,
                  detail::format("the instrumental-variable matrix is singular (condition {}); the input does not excite {} "
                                 "parameters",
                                 run.sol.condition, p));
  if (run.interrupted) {
    r.summary.termination = Termination::Interrupted;
    r.summary.message = detail::format("interrupted after {} iterations", run.iterations);
  }
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

Result<TransferFunction> srivc_records(const internal::RecordRefs& data, const TfOrders& orders,
                                       const SrivcOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  orders.validate(/*allow_biproper=*/true);
  options.validate();
  check_srivc_inputs(data, orders, options);
  // The estimation runs in normalised time and amplitude units, so that its result does not depend on the
  // units of the records; the result is mapped back. One normalisation for all records.
  const tf_detail::TfNormalisation n = tf_detail::TfNormalisation::of(data);
  SrivcOptions o = options;
  if (o.initial) o.initial = n.to_normalised(*o.initial, orders);
  o.delay /= n.c;
  o.delay_min /= n.c;
  if (o.delay_max >= 0) o.delay_max /= n.c;
  o.transient_time /= n.c;
  Records normalised;
  for (const IdData& d : data) normalised.push_back(n.data(d));
  Result<TransferFunction> r = srivc_in_units(normalised, orders, o);
  n.restore(r, orders);
  tf_detail::finish_tf_result(r, data.front());
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

}  // namespace

Result<TransferFunction> srivc(const std::vector<IdData>& data, const TfOrders& orders, const SrivcOptions& options) {
  return srivc_records(data, orders, options);
}

Result<TransferFunction> srivc(const IdData& data, const TfOrders& orders, const SrivcOptions& options) {
  return srivc_records(data, orders, options);
}

template <>
const OptionTable<SrivcMisoOptions>& option_table<SrivcMisoOptions>() {
  using O = SrivcMisoOptions;
  static const OptionTable<O> t =
      OptionTable<O>("srivc_miso")
          .integer("max_iterations", &O::max_iterations, "", at_least(1), "sweeps over all channels")
          .real("tolerance", &O::tolerance, "", above(0), "stop when the relative change of every parameter is below")
          .flag("common_denominator", &O::common_denominator,
                "1: y = (sum_i B_i u_i)/A with one A; 0: y = sum_i B_i/A_i u_i (backfitting)")
          .reals("delays", &O::delays, "s", at_least(0), "per-input delays added to nk Ts (none: zero)");
  return t;
}

void SrivcMisoOptions::validate() const { option_table<SrivcMisoOptions>().check(*this); }

namespace {
// Start, input by input: SISO SRIVC of y minus the outputs of the channels fitted before (the later inputs
// act as noise). Fitting every channel on y alone instead gives starts biased by all other inputs (at
// equal input powers a 0 dB "noise"), from which the iterations can end rank-deficient.
// th: each channel's parameters; xhat[e][i]: channel i's simulated output on record e.
void miso_start(const Records& ds, const std::vector<TfOrders>& orders, const std::vector<std::vector<IvChannel>>& chs,
                const std::vector<Eigen::VectorXd>& ys, const std::vector<Eigen::VectorXd>& ts,
                std::vector<Eigen::VectorXd>& th, std::vector<std::vector<Eigen::VectorXd>>& xhat) {
  const int K = ds.front().nu(), E = static_cast<int>(ds.size());
  auto channel_model = [&](int i, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    return tf_detail::make_tf(a, b, chs[0][i].delay);
  };
  std::vector<Eigen::VectorXd> rest = ys;
  for (int i = 0; i < K; ++i) {
    Records rk;
    for (int e = 0; e < E; ++e) {
      const IdData& d = ds[e];
      const Eigen::MatrixXd ui = d.u().col(i);
      rk.push_back(d.is_uniform() ? IdData(ui, rest[e], d.ts(), d.t0()) : IdData(ui, rest[e], ts[e]));
      rk.back().set_intersample(d.intersample(i));
    }
    SrivcOptions so;
    so.delay = chs[0][i].delay;
    so.max_iterations = 20;
    const Result<TransferFunction> s = srivc(rk, {orders[i].nb, orders[i].nf, 0}, so);
    const TransferFunction gi =
        tf_detail::stabilized(channel_model(i, s.parameters.values.head(orders[i].nf), s.parameters.values.tail(orders[i].nb)));
    th[i] = tf_detail::params_of(gi, {orders[i].nb, orders[i].nf, 0});
    for (int e = 0; e < E; ++e) {
      xhat[e][i] = lsim(gi, ds[e], i);
      rest[e] -= xhat[e][i];
    }
  }
}

// MISO SRIVC on one or several records (experiments of one system), each record's filters from rest; the IV
// equations of every step are summed over the records.
Result<MisoModel> srivc_miso_in_units(const Records& ds, const std::vector<TfOrders>& orders, const SrivcMisoOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  opt.validate();
  const int K = ds.front().nu(), E = static_cast<int>(ds.size());
  CTID_REQUIRE_OPTION(opt.delays.empty() || static_cast<int>(opt.delays.size()) == K,
                      "srivc_miso: {} delays for {} inputs", opt.delays.size(), K);
  int p = 0, total = 0;
  for (const auto& d : ds) total += d.size();
  for (int i = 0; i < K; ++i) {
    orders[i].validate(/*allow_biproper=*/true);
    for (const auto& d : ds) CTID_REQUIRE(orders[i].nk == 0 || d.is_uniform(), "srivc_miso: nk needs uniformly sampled data");
    CTID_REQUIRE_OPTION(!opt.common_denominator || orders[i].nf == orders[0].nf,
                        "srivc_miso: a common denominator needs equal nf for every input (input 1 has {}, input {} has {})",
                        orders[0].nf, i + 1, orders[i].nf);
    p += orders[i].nb + (opt.common_denominator ? 0 : orders[i].nf);
  }
  if (opt.common_denominator) p += orders[0].nf;
  CTID_REQUIRE(total > p, "srivc_miso: {} samples cannot determine {} parameters", total, p);

  // Per record: times, output and the channels (input, intersample, total delay, nb).
  std::vector<Eigen::VectorXd> ts(E), ys(E);
  std::vector<std::vector<IvChannel>> chs(E);
  for (int e = 0; e < E; ++e) {
    const IdData& d = ds[e];
    ts[e] = d.times();
    ys[e] = d.y().col(0);
    for (int i = 0; i < K; ++i)
      chs[e].push_back({d.u().col(i), d.intersample(i),
                        (opt.delays.empty() ? 0.0 : opt.delays[i]) + (orders[i].nk > 0 ? orders[i].nk * d.ts() : 0.0),
                        orders[i].nb});
  }
  // The delay of channel i (nk counted in the first record's sampling period, as every record shares the model).
  auto channel_model = [&](int i, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    return tf_detail::make_tf(a, b, chs[0][i].delay);
  };
  std::vector<Eigen::VectorXd> th(K);                                       // channel parameters
  std::vector<std::vector<Eigen::VectorXd>> xhat(E, std::vector<Eigen::VectorXd>(K));  // simulated channel outputs
  miso_start(ds, orders, chs, ys, ts, th, xhat);
  auto records_of = [&](const std::vector<Eigen::VectorXd>& y, const std::vector<std::vector<IvChannel>>& ch) {
    std::vector<srivc_detail::IvRecord> rec;
    for (int e = 0; e < E; ++e) rec.push_back({&y[e], &ts[e], &ch[e]});
    return rec;
  };
  Result<MisoModel> r;
  SrivcRun last;
  Eigen::MatrixXd information;  // sum zeta zeta^T of the estimated parameters
  bool converged = false, failed = false;
  int it = 0;
  if (opt.common_denominator) {
    const int n = orders[0].nf;
    Eigen::VectorXd theta(p);
    theta.head(n) = th[0].head(n);
    int off = n;
    for (int i = 0; i < K; ++i) {
      theta.segment(off, orders[i].nb) = th[i].tail(orders[i].nb);
      off += orders[i].nb;
    }
    for (it = 1; it <= opt.max_iterations; ++it) {
      last = srivc_detail::iv_step(records_of(ys, chs), n, theta);
      if (last.rank_deficient) { failed = true; break; }
      const double change = relative_change(last.theta, theta);
      theta = last.theta;
      if (change < opt.tolerance) { converged = true; break; }
    }
    off = n;
    for (int i = 0; i < K; ++i) {
      r.model.channels.push_back(channel_model(i, theta.head(n), theta.segment(off, orders[i].nb)));
      off += orders[i].nb;
    }
    r.parameters.values = theta;
    for (int k = 1; k <= n; ++k) r.parameters.names.push_back("a" + std::to_string(k));
    for (int i = 0; i < K; ++i)
      for (int j = 0; j < orders[i].nb; ++j) r.parameters.names.push_back("u" + std::to_string(i + 1) + ".b" + std::to_string(j));
    information = last.zz;  // sum zeta zeta^T
  } else {
    // Backfitting: channel i is refitted on y minus the other channels' model outputs, in every record.
    Eigen::MatrixXd zz_blocks = Eigen::MatrixXd::Zero(p, p);
    std::vector<Eigen::VectorXd> yi(E);
    std::vector<std::vector<IvChannel>> chi(E);
    for (it = 1; it <= opt.max_iterations; ++it) {
      double change = 0;
      int off = 0;
      for (int i = 0; i < K; ++i) {
        for (int e = 0; e < E; ++e) {
          yi[e] = ys[e];
          for (int k = 0; k < K; ++k)
            if (k != i) yi[e] -= xhat[e][k];
          chi[e] = {chs[e][i]};
        }
        SrivcRun s = srivc_detail::iv_step(records_of(yi, chi), orders[i].nf, th[i]);
        if (s.rank_deficient) { failed = true; break; }
        change = std::max(change, relative_change(s.theta, th[i]));
        th[i] = s.theta;
        // The other channels see this one through its simulated output: an unstable intermediate estimate
        // would swamp them, so it is simulated with its poles mirrored into the left half plane.
        const TransferFunction gi = tf_detail::stabilized(channel_model(i, th[i].head(orders[i].nf), th[i].tail(orders[i].nb)));
        for (int e = 0; e < E; ++e) xhat[e][i] = lsim(gi, ds[e], i);
        const int pi = orders[i].nf + orders[i].nb;
        zz_blocks.block(off, off, pi, pi) = s.zz;
        off += pi;
        last = s;
      }
      if (failed) break;
      if (change < opt.tolerance) { converged = true; break; }
    }
    r.parameters.values.resize(p);
    int off = 0;
    for (int i = 0; i < K; ++i) {
      const int pi = orders[i].nf + orders[i].nb;
      r.parameters.values.segment(off, pi) = th[i];
      off += pi;
      r.model.channels.push_back(channel_model(i, th[i].head(orders[i].nf), th[i].tail(orders[i].nb)));
      const std::string u = "u" + std::to_string(i + 1) + ".";
      for (int k = 1; k <= orders[i].nf; ++k) r.parameters.names.push_back(u + "a" + std::to_string(k));
      for (int j = 0; j < orders[i].nb; ++j) r.parameters.names.push_back(u + "b" + std::to_string(j));
    }
    information = zz_blocks;  // block-diagonal approximation across channels
  }
  r.parameters.fixed.assign(p, false);
  // The simulation fit over all records (each from rest), as one concatenated output.
  Eigen::VectorXd yall(total), sall(total);
  for (int e = 0, at = 0; e < E; at += ds[e].size(), ++e) {
    yall.segment(at, ds[e].size()) = ys[e];
    sall.segment(at, ds[e].size()) = lsim(r.model, ds[e]);
  }
  r.fit = fit_report_or_inf(yall, sall, p);
  const double sigma2 = r.fit.mse * total / std::max(1, total - p);
  r.parameters.set_covariance(failed ? Eigen::MatrixXd() : internal::covariance(information, sigma2));
  r.diagnostics.condition_number = last.sol.condition;
  r.diagnostics.set(diagnostic::noise_variance, sigma2);
  if (E > 1) r.diagnostics.set(diagnostic::experiments, E);
  r.summary.iterations = std::min(it, opt.max_iterations);
  set_termination(r, failed, converged, opt.tolerance, opt.max_iterations,
                  "the instrumental-variable matrix is singular; the inputs do not excite every parameter");
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

// g(s'/c) * gain as a transfer function in s' (a known controller in normalised units).
TransferFunction time_scaled(const TransferFunction& g, double c, double gain) {
  const int n = g.den().degree();
  auto scaled = [&](const Polynomial& p, double k) {
    Eigen::VectorXd q = p.coefficients();
    const int m = p.degree();
    for (int i = 0; i <= m; ++i) q(i) *= k * std::pow(c, n - (m - i));
    return q;
  };
  return TransferFunction(scaled(g.num(), gain), scaled(g.den(), 1.0), g.io_delay() / c);
}
}  // namespace

namespace {
// srivc_miso of one record or of several, without copying them.
Result<MisoModel> srivc_miso_records(const internal::RecordRefs& ds, const std::vector<TfOrders>& orders, const SrivcMisoOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  CTID_REQUIRE(!ds.empty(), "srivc_miso: no records");
  const int K = ds.front().nu();
  for (std::size_t e = 0; e < ds.size(); ++e) {
    const std::string who = ds.size() > 1 ? "srivc_miso (record " + std::to_string(e + 1) + ")" : "srivc_miso";
    require_io_data(ds[e], who.c_str(), -1, 1);
    CTID_REQUIRE(ds[e].nu() == K, "{}: {} inputs; record 1 has {}", who, ds[e].nu(), K);
  }
  CTID_REQUIRE(K >= 1 && static_cast<int>(orders.size()) == K, "srivc_miso: {} inputs but {} sets of orders", K,
               orders.size());
  // As srivc: estimated in normalised units (time / c, each input by its RMS, y by its RMS; pooled over the
  // records), mapped back.
  const tf_detail::TfNormalisation n = tf_detail::TfNormalisation::of(ds);
  std::vector<tf_detail::TfNormalisation> per_input;  // c, the input's RMS, sy
  Eigen::RowVectorXd su(K);
  for (int i = 0; i < K; ++i) {
    double ss = 0;
    int count = 0;
    for (const auto& d : ds) {
      ss += d.u().col(i).squaredNorm();
      count += d.size();
    }
    const double rms = std::sqrt(ss / std::max(1, count));
    su(i) = rms > 0 && std::isfinite(rms) ? rms : 1.0;
    per_input.push_back({n.c, su(i), n.sy});
  }
  SrivcMisoOptions o = opt;
  for (double& dl : o.delays) dl /= n.c;
  Records normalised;
  for (const auto& d : ds) normalised.push_back(n.data(d, su));
  Result<MisoModel> r = srivc_miso_in_units(normalised, orders, o);
  // Parameters "a<k>" (common denominator), "u<i>.a<k>", "u<i>.b<j>".
  Eigen::VectorXd f(r.parameters.size());
  for (int k = 0; k < r.parameters.size(); ++k) {
    const std::string& name = r.parameters.names[static_cast<size_t>(k)];
    const size_t dot = name.find('.');
    const int i = dot == std::string::npos ? 0 : std::stoi(name.substr(1, dot - 1)) - 1;
    f(k) = per_input[static_cast<size_t>(i)].factor(dot == std::string::npos ? name : name.substr(dot + 1), orders[i]);
  }
  n.restore_common(r.parameters, f, r.fit, r.diagnostics);
  for (int i = 0; i < r.model.nu(); ++i)
    r.model.channels[i] = per_input[static_cast<size_t>(i)].from_normalised(r.model.channels[i], orders[i]);
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}
}  // namespace

Result<MisoModel> srivc_miso(const IdData& data, const std::vector<TfOrders>& orders, const SrivcMisoOptions& opt) {
  return srivc_miso_records(data, orders, opt);
}

Result<MisoModel> srivc_miso(const std::vector<IdData>& ds, const std::vector<TfOrders>& orders, const SrivcMisoOptions& opt) {
  return srivc_miso_records(ds, orders, opt);
}

template <>
const OptionTable<ClosedLoopOptions>& option_table<ClosedLoopOptions>() {
  using O = ClosedLoopOptions;
  static const OptionTable<O> t =
      OptionTable<O>("srivc_closed_loop")
          .model("controller", &O::controller, "the known controller C(s) (proper, no delay)")
          .flag("reference_at_plant_input", &O::reference_at_plant_input,
                "1: u = r - C y (reference added at the plant input); 0: u = C (r - y) (a setpoint)")
          .choice("reference_intersample", &O::reference_intersample,
                  {{"zoh", Intersample::Zoh}, {"foh", Intersample::Foh}, {"bl", Intersample::BandLimited}},
                  "intersample behaviour of the reference")
          .integer("max_iterations", &O::max_iterations, "", at_least(1), "IV iterations")
          .real("tolerance", &O::tolerance, "", above(0), "stop when the relative parameter change is below")
          .real("transient_time", &O::transient_time, "s", at_least(0),
                "seconds at the start of each record left out of the IV equations and the fit (loops not at rest)");
  return t;
}

void ClosedLoopOptions::validate() const {
  option_table<ClosedLoopOptions>().check(*this);
  CTID_REQUIRE_OPTION(controller.io_delay() == 0.0, "srivc_closed_loop: the controller must have no delay (got {} s)",
                      controller.io_delay());
}

namespace {
Result<TransferFunction> srivc_closed_loop_in_units(const std::vector<IdData>& ds, const std::vector<Eigen::VectorXd>& refs,
                                                    const TfOrders& orders, const ClosedLoopOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  const int p = orders.nf + orders.nb;
  const std::size_t E = ds.size();
  std::vector<srivc_detail::ClosedLoopInstruments> cl;
  std::vector<Eigen::VectorXd> ys, ts;
  std::vector<std::vector<IvChannel>> chs;
  for (std::size_t e = 0; e < E; ++e) {
    cl.push_back({refs[e], opt.reference_intersample, opt.controller, opt.reference_at_plant_input});
    ys.push_back(ds[e].y().col(0));
    ts.push_back(ds[e].times());
    chs.emplace_back().push_back({ds[e].u().col(0), ds[e].intersample(0), 0.0, orders.nb});
  }
  std::vector<srivc_detail::IvRecord> recs;
  for (std::size_t e = 0; e < E; ++e) recs.push_back({&ys[e], &ts[e], &chs[e], first_after(ds[e], opt.transient_time), &cl[e]});
  // Start: open-loop SRIVC (biased in closed loop, but a stable model near the truth).
  SrivcOptions so;
  so.max_iterations = 10;
  so.transient_time = opt.transient_time;
  Eigen::VectorXd theta = srivc(ds, orders, so).parameters.values;
  SrivcRun run;
  bool converged = false;
  int it = 0;
  for (it = 1; it <= opt.max_iterations; ++it) {
    SrivcRun step = srivc_detail::iv_step(recs, orders.nf, theta);
    if (step.rank_deficient) {
      run = step;
      break;
    }
    const double change = relative_change(step.theta, theta);
    theta = step.theta;
    run = step;
    if (change < opt.tolerance) {
      converged = true;
      break;
    }
  }
  Result<TransferFunction> r;
  r.model = tf_of(theta, orders, 0.0);
  r.parameters.names = tf_parameter_names(orders);
  r.parameters.values = theta;
  r.parameters.fixed.assign(p, false);
  // The simulation fit over all records (each from rest, after its transient), as one concatenated output.
  const auto [y_all, sim_all] = pooled_outputs(r.model, ds, opt.transient_time);
  r.fit = fit_report_or_inf(y_all, sim_all, p);
  // Covariance sigma^2 (Z^T Phi)^{-1} (Z^T Z) (Phi^T Z)^{-1} (IV sandwich: the instruments differ
  // from the regressors in closed loop), the sums over all records.
  const Eigen::Index total = y_all.size();
  const double sigma2 = r.fit.mse * double(total) / double(std::max<Eigen::Index>(1, total - p));
  if (!run.rank_deficient && run.zx.size() == p * p) {
    const Eigen::MatrixXd inv = run.zx.fullPivLu().inverse();
    r.parameters.set_covariance(sigma2 * inv * run.zz * inv.transpose());
  } else {
    r.parameters.set_covariance({});
  }
  r.diagnostics.condition_number = run.sol.condition;
  r.diagnostics.set(diagnostic::noise_variance, sigma2);
  if (E > 1) r.diagnostics.set(diagnostic::experiments, static_cast<double>(E));
  // The sandwich assumes white noise. Coloured noise (why CLSRIVC is used) makes it too small, by about
  // sqrt((1 + rho)/(1 - rho)) for AR(1) noise of lag-1 correlation rho: say so when that exceeds 1.5.
  const Eigen::VectorXd err = y_all - sim_all;
  const double e0 = err.squaredNorm();
  const double rho = err.size() > 1 && std::isfinite(e0) && e0 > 0 ? residual_autocorrelation(err, 1).values(1) : 0.0;
  r.diagnostics.set(diagnostic::output_error_lag1_correlation, rho);
  if (rho > 0.4)
    r.diagnostics.warnings.push_back(detail::format(
        "the output error is correlated (lag-1 correlation {}): the standard deviations assume white noise and may be "
        "too small by a factor of about {}",
        std::round(rho * 1000) / 1000, std::round(std::sqrt((1 + rho) / (1 - rho)) * 10) / 10));
  r.summary.iterations = std::min(it, opt.max_iterations);
  set_termination(r, run.rank_deficient, converged, opt.tolerance, opt.max_iterations,
                  "the closed-loop instrument matrix is singular; the reference does not excite every parameter");
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}
}  // namespace

Result<TransferFunction> srivc_closed_loop(const std::vector<IdData>& data, const std::vector<Eigen::VectorXd>& references,
                                           const TfOrders& orders, const ClosedLoopOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  orders.validate(/*allow_biproper=*/false);
  opt.validate();
  CTID_REQUIRE(!data.empty(), "srivc_closed_loop: no records");
  CTID_REQUIRE(references.size() == data.size(), "srivc_closed_loop: {} references for {} records", references.size(),
               data.size());
  CTID_REQUIRE_OPTION(orders.nk == 0, "srivc_closed_loop: nk must be 0 (got {})", orders.nk);
  const int p = orders.nf + orders.nb;
  Eigen::Index total = 0;
  for (std::size_t e = 0; e < data.size(); ++e) {
    const std::string who = data.size() > 1 ? "srivc_closed_loop (record " + std::to_string(e + 1) + ")" : "srivc_closed_loop";
    require_io_data(data[e], who.c_str());
    CTID_REQUIRE(references[e].size() == data[e].size(), "{}: the reference has {} samples but the data have {}", who,
                 references[e].size(), data[e].size());
    CTID_REQUIRE(references[e].allFinite(), "{}: the reference contains NaN or Inf", who);
    CTID_REQUIRE(opt.transient_time < data[e].duration(), "{}: transient_time = {} s is not shorter than the record ({} s)",
                 who, opt.transient_time, data[e].duration());
    total += data[e].size();
  }
  CTID_REQUIRE(total > p, "srivc_closed_loop: {} samples cannot determine {} parameters", total, p);
  // As srivc: estimated in normalised units (pooled over the records) and mapped back. The controller maps y to
  // u: C'(s') = (sy/su) C(s'/c); the reference has the units of u (added at the plant input) or of y (a setpoint).
  const tf_detail::TfNormalisation n = tf_detail::TfNormalisation::of(data);
  ClosedLoopOptions o = opt;
  o.controller = time_scaled(opt.controller, n.c, n.sy / n.su);
  o.transient_time /= n.c;
  std::vector<IdData> scaled;
  std::vector<Eigen::VectorXd> refs;
  for (std::size_t e = 0; e < data.size(); ++e) {
    scaled.push_back(n.data(data[e]));
    refs.push_back(references[e] / (opt.reference_at_plant_input ? n.su : n.sy));
  }
  Result<TransferFunction> r = srivc_closed_loop_in_units(scaled, refs, orders, o);
  n.restore(r, orders);
  tf_detail::check_cancellation(r);
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

Result<TransferFunction> srivc_closed_loop(const IdData& data, const Eigen::VectorXd& reference, const TfOrders& orders,
                                           const ClosedLoopOptions& opt) {
  return srivc_closed_loop(std::vector<IdData>{data}, std::vector<Eigen::VectorXd>{reference}, orders, opt);
}

}  // namespace ctid
