// ctid — nonlinear grey-box identification by output error with exact forward sensitivities (see
// include/ctid/estimate/greybox.hpp; Ljung 1999 §7.3; Bohlin 2006).
#include "ctid/estimate/greybox.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include "ctid/core/check.hpp"
#include "ctid/validate/metrics.hpp"
#include "data/record_refs.hpp"
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
// One record as the search sees it.
struct Record {
  Eigen::MatrixXd u;
  Eigen::VectorXd t, y;  // y: the outputs stacked column by column (N ny)
  Intersample hold = Intersample::Zoh;
  Eigen::Index start = 0;  // first row in the stacked residual
  int n = 0;
};

// A multiple-shooting segment of a record: samples first .. first + rows (its inputs and times, one sample beyond
// the rows whose outputs it owns: the next segment's start, where continuity is imposed; the last owns its end).
struct Segment {
  Eigen::MatrixXd u;
  Eigen::VectorXd t;
  int first = 0, rows = 0;
};
}  // namespace

namespace {
// greybox of one record or of several, without copying them.
Result<GreyboxModel> greybox_records(const internal::RecordRefs& records, const GreyboxModel& model, const GreyboxOptions& opt) {
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
    r.hold = greybox_intersample(d);
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
  // Auto: once a simulation has found the model stiff (Dormand-Prince over its budget, BDF ran), the rest of the fit
  // uses BDF directly instead of trying the explicit method first every time.
  GreyboxIntegrator integrator = opt.integrator;
  auto ran = [&](GreyboxIntegrator used) {
    if (used == GreyboxIntegrator::Bdf) integrator = GreyboxIntegrator::Bdf;
  };
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
        const GreyboxSimulation s = m.simulate(d.u, d.t, d.hold, x0, opt.rtol, integrator);
        ran(s.integrator);
        if (!s.ok()) return escape = s.message, false;
        for (int j = 0; j < ny; ++j)
          r.segment(d.start + static_cast<Eigen::Index>(j) * d.n, d.n) = w(j) * s.y.col(j);
        continue;
      }
      const GreyboxSensitivities s = m.sensitivities(d.u, d.t, d.hold, x0, free, free_x0, opt.rtol, true, integrator);
      ran(s.integrator);
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

  // Multiple shooting (Bock & Plitt 1984, "A multiple shooting algorithm for direct solution of optimal control
  // problems"; Bock 1983 for parameter estimation): each record is cut into segments, segment k > 0 starts from
  // free states s_k, and continuity x_end(k-1) = s_k is imposed by penalty residuals rho_i (x_end,i - s_k,i),
  // rho_i = mu / scale_i, with mu raised over three searches (1, 1e2, 1e4 times the RMS weighted output) so that the
  // last leaves defects at rounding level. An unstable or integrating plant then never runs free over the whole
  // record while the search is far from the optimum. The search vector is [v (p) | the segment states].
  std::vector<std::vector<Segment>> seg(static_cast<size_t>(E));
  std::vector<int> seg_offset(static_cast<size_t>(E), 0);  // each record's first segment state in the vector
  int ns = 0;                                                // segment states in all
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(nx), rho = Eigen::VectorXd::Ones(nx);
  double mu_base = 1.0;
  std::vector<int> all_states(static_cast<size_t>(nx));
  for (int i = 0; i < nx; ++i) all_states[static_cast<size_t>(i)] = i;
  const Eigen::Index Ny = y.size();
  // The residual (and Jacobian) of the segmented problem: weighted output errors, then the continuity residuals.
  // The Jacobian is block sparse (a segment's rows depend on the parameters and its own start only): it is built from
  // triplets and the normal equations are solved sparse (internal/levenberg_marquardt.hpp).
  std::vector<Eigen::Triplet<double>> nz;
  auto put = [&](Eigen::Index row, Eigen::Index col, const Eigen::MatrixXd& block) {
    for (Eigen::Index c = 0; c < block.cols(); ++c)
      for (Eigen::Index i = 0; i < block.rows(); ++i)
        if (block(i, c) != 0.0) nz.emplace_back(static_cast<int>(row + i), static_cast<int>(col + c), block(i, c));
  };
  const internal::LmSparseEvaluate shoot_evaluate = [&](const Eigen::VectorXd& vm, Eigen::VectorXd& r,
                                                        Eigen::SparseMatrix<double>* J) {
    const GreyboxModel m = model_at(vm);
    r.setZero(Ny + ns);
    nz.clear();
    for (int e = 0; e < E; ++e) {
      const Record& d = rec[static_cast<size_t>(e)];
      const auto& sg = seg[static_cast<size_t>(e)];
      const int S = static_cast<int>(sg.size());
      for (int k = 0; k < S; ++k) {
        const Segment& g = sg[static_cast<size_t>(k)];
        const Eigen::Index col_k = p + seg_offset[static_cast<size_t>(e)] + static_cast<Eigen::Index>(k - 1) * nx;
        const Eigen::VectorXd x0 = k == 0 ? x0_of(m, vm, e) : Eigen::VectorXd(vm.segment(col_k, nx));
        Eigen::VectorXd x_end;
        if (!J) {
          const GreyboxSimulation sim = m.simulate(g.u, g.t, d.hold, x0, opt.rtol, integrator);
          ran(sim.integrator);
          if (!sim.ok()) return escape = sim.message, false;
          for (int j = 0; j < ny; ++j)
            r.segment(d.start + static_cast<Eigen::Index>(j) * d.n + g.first, g.rows) = w(j) * sim.y.col(j).head(g.rows);
          x_end = sim.x.row(sim.x.rows() - 1).transpose();
        } else {
          const GreyboxSensitivities sn =
              m.sensitivities(g.u, g.t, d.hold, x0, free, k == 0 ? free_x0 : all_states, opt.rtol, k == 0, integrator);
          ran(sn.integrator);
          if (!sn.ok) return escape = sn.message, false;
          const int nq = k == 0 ? nx0 : nx;
          const Eigen::Index col_s = k == 0 ? pf + e * nx0 : col_k;
          for (int j = 0; j < ny; ++j) {
            const Eigen::Index row = d.start + static_cast<Eigen::Index>(j) * d.n + g.first;
            const Eigen::MatrixXd& dy = sn.dy[static_cast<size_t>(j)];
            r.segment(row, g.rows) = w(j) * sn.y.col(j).head(g.rows);
            put(row, 0, -w(j) * dy.topLeftCorner(g.rows, pf));
            if (nq) put(row, col_s, -w(j) * dy.topRightCorner(g.rows, nq));
          }
          x_end = sn.x_end;
          if (k + 1 < S) {
            const Eigen::Index c = Ny + seg_offset[static_cast<size_t>(e)] + static_cast<Eigen::Index>(k) * nx;
            put(c, 0, rho.asDiagonal() * sn.dx_end.leftCols(pf));
            if (nq) put(c, col_s, rho.asDiagonal() * sn.dx_end.rightCols(nq));
            put(c, col_k + nx, Eigen::MatrixXd((-rho).asDiagonal()));
          }
        }
        if (k + 1 < S) {
          const Eigen::Index c = Ny + seg_offset[static_cast<size_t>(e)] + static_cast<Eigen::Index>(k) * nx;
          r.segment(c, nx) = rho.cwiseProduct(x_end - vm.segment(col_k + nx, nx));
        }
      }
    }
    r.head(Ny) = wy - r.head(Ny);
    if (J) {
      J->resize(Ny + ns, p + ns);
      J->setFromTriplets(nz.begin(), nz.end());
    }
    return true;
  };
  // The segments' starting states, segment by segment (a greedy observer): an output that is a state alone gives
  // that state from the data; the others either continue the previous segment's simulation or restart from the
  // record's initial guess, whichever simulates the segment with the smaller output error. `ok`: every segment
  // simulates from its start.
  auto segment_guess = [&](const Eigen::VectorXd& v, bool& ok) {
    Eigen::VectorXd vm(p + ns);
    vm.head(p) = v;
    ok = true;
    const GreyboxModel m = model_at(v);
    for (int e = 0; e < E; ++e) {
      const Record& d = rec[static_cast<size_t>(e)];
      const auto& sg = seg[static_cast<size_t>(e)];
      const Eigen::VectorXd guess = x0_of(m, v, e);
      Eigen::VectorXd x = guess;
      for (size_t k = 0; k < sg.size(); ++k) {
        const Segment& g = sg[k];
        // The output error of the segment from x (infinite when it escapes), and its end state.
        auto run = [&](Eigen::VectorXd& start, Eigen::VectorXd& end) {
          if (k > 0)
            for (int i = 0; i < nx; ++i)
              if (const int o = model.output_of_state(i); o >= 0) start(i) = d.y(static_cast<Eigen::Index>(o) * d.n + g.first);
          const GreyboxSimulation sim = m.simulate(g.u, g.t, d.hold, start, opt.rtol, integrator);
          ran(sim.integrator);
          if (!sim.ok()) return static_cast<double>(INFINITY);
          end = sim.x.row(sim.x.rows() - 1).transpose();
          double cost = 0;
          for (int j = 0; j < ny; ++j)
            cost += (d.y.segment(static_cast<Eigen::Index>(j) * d.n + g.first, g.rows) - sim.y.col(j).head(g.rows)).squaredNorm();
          return cost;
        };
        Eigen::VectorXd a = x, b = guess, end_a, end_b;
        const double ca = run(a, end_a), cb = k > 0 ? run(b, end_b) : INFINITY;
        if (!std::isfinite(std::min(ca, cb))) ok = false;
        const bool take_b = cb < ca;
        if (k > 0) vm.segment(p + seg_offset[static_cast<size_t>(e)] + static_cast<Eigen::Index>(k - 1) * nx, nx) = take_b ? b : a;
        x = take_b ? end_b : (std::isfinite(ca) ? end_a : guess);
      }
    }
    return vm;
  };
  // One multiple-shooting search from v (the three penalty stages).
  auto shoot = [&](const Eigen::VectorXd& v) {
    bool ok = true;
    Eigen::VectorXd vm = segment_guess(v, ok);
    for (int i = 0; i < nx; ++i) {
      double s2 = 0;
      for (int k = 0; k < ns / std::max(nx, 1); ++k) s2 += vm(p + static_cast<Eigen::Index>(k) * nx + i) * vm(p + static_cast<Eigen::Index>(k) * nx + i);
      scale(i) = ns > 0 && s2 > 0 ? std::sqrt(s2 / (ns / nx)) : 1.0;
    }
    Eigen::VectorXd lo_m = Eigen::VectorXd::Constant(p + ns, -INFINITY), hi_m = Eigen::VectorXd::Constant(p + ns, INFINITY);
    lo_m.head(p) = lo;
    hi_m.head(p) = hi;
    internal::LmResult lm;
    int iterations = 0;
    for (const double f : {1.0, 1e2, 1e4}) {
      rho = (f * mu_base) * scale.cwiseInverse();
      lm = internal::levenberg_marquardt(shoot_evaluate, vm, lo_m, hi_m, lmo);
      iterations += lm.iterations;
      if (!std::isfinite(lm.cost) || lm.interrupted) break;
      vm = lm.x;
    }
    lm.iterations = iterations;
    return lm;
  };
  bool shooting = opt.segments > 1;
  if (opt.segments == 0) {  // automatic: the free run from the start escapes or drifts far from the data
    Eigen::VectorXd r0;
    shooting = !evaluate(v0, r0, nullptr) || !(fit_report_or_inf(wy, wy - r0, p).fit_percent > -900.0);
  }
  // Cuts every record into segments: S each when given, else segments of `length` samples.
  auto make_segments = [&](int S_given, int length) {
    ns = 0;
    for (int e = 0; e < E; ++e) {
      const Record& d = rec[static_cast<size_t>(e)];
      const int S = std::min(S_given > 1 ? S_given : (d.n - 1 + length - 1) / length, d.n - 1);
      seg_offset[static_cast<size_t>(e)] = ns;
      auto& sg = seg[static_cast<size_t>(e)];
      sg.clear();
      for (int k = 0; k < S; ++k) {
        const int b0 = static_cast<int>(std::llround(static_cast<double>(k) * (d.n - 1) / S));
        const int b1 = static_cast<int>(std::llround(static_cast<double>(k + 1) * (d.n - 1) / S));
        Segment g;
        g.first = b0;
        g.rows = k + 1 < S ? b1 - b0 : b1 - b0 + 1;
        g.u = d.u.middleRows(b0, b1 - b0 + 1);
        g.t = d.t.segment(b0, b1 - b0 + 1);
        sg.push_back(std::move(g));
      }
      ns += (S - 1) * nx;
    }
  };
  if (shooting) {
    mu_base = std::sqrt(wy.squaredNorm() / static_cast<double>(std::max<Eigen::Index>(1, wy.size())));
    if (!(mu_base > 0)) mu_base = 1.0;
    if (opt.segments > 1) make_segments(opt.segments, 0);
    else  // automatic: segments of 100 samples, halved (to 4) until every segment simulates from the start
      for (int length = 100;; length /= 2) {
        make_segments(0, length);
        bool ok = true;
        segment_guess(v0, ok);
        if (ok || length <= 4) break;
      }
  }
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
    const internal::LmResult lm = shooting ? shoot(v) : internal::levenberg_marquardt(evaluate, v, lo, hi, lmo);
    start_costs(s) = lm.cost;
    if (s == 0 || lm.cost < best.cost) best = lm;
    if (lm.interrupted) {
      best.interrupted = true;
      best.message = lm.message;
      break;
    }
  }

  // After multiple shooting: the single-shooting search from its estimate where the free run is finite (a stable
  // or integrating plant; it then ends at the output-error optimum itself); its result is taken when its cost is
  // within 5 % of the segments' output cost. Otherwise (an unstable plant: the free run escapes or drifts) the
  // multiple-shooting estimate stands, its information the Schur complement of the segment states' block and its fit
  // that of the segments.
  std::vector<std::string> warnings;
  Eigen::VectorXd segment_fit;  // the segments' weighted outputs when the multiple-shooting estimate stands
  double defect = NAN;
  if (shooting && std::isfinite(best.cost) && !best.interrupted) {
    const Eigen::VectorXd vm = best.x;
    Eigen::VectorXd rm, r1;
    shoot_evaluate(vm, rm, nullptr);
    defect = 0;
    for (Eigen::Index c = 0; c < ns; ++c) defect = std::max(defect, std::abs(rm(Ny + c)) / rho(c % nx) / scale(c % nx));
    const double segment_cost = 0.5 * rm.head(Ny).squaredNorm();
    internal::LmResult single;
    single.cost = INFINITY;
    escape.clear();
    const bool runs = evaluate(vm.head(p), r1, nullptr);
    const std::string free_run = runs ? "its free run drifts away from the data" : escape;
    if (runs) single = internal::levenberg_marquardt(evaluate, vm.head(p), lo, hi, lmo);
    if (std::isfinite(single.cost) && single.cost <= 1.05 * segment_cost) {
      single.iterations += best.iterations;
      best = single;
    } else {
      // The information about v with the segment states eliminated: the Schur complement of their block, the
      // constrained problem's information as the continuity weights grow.
      const Eigen::MatrixXd& F = best.jtj;
      const Eigen::MatrixXd Dinv_Bt = F.bottomRightCorner(ns, ns).ldlt().solve(F.bottomLeftCorner(ns, p));
      segment_fit = wy - rm.head(Ny);
      best.x = vm.head(p);
      best.jtj = F.topLeftCorner(p, p) - F.topRightCorner(p, ns) * Dinv_Bt;
      best.cost = segment_cost;
      warnings.push_back(detail::format(
          "multiple shooting: the fitted model does not run free over the record{} ({}); the fit is that of {} "
          "segments, each from its estimated state (largest continuity defect {} of the state's scale)",
          E > 1 ? "s" : "", free_run, ns / std::max(nx, 1) + E, defect));
    }
  }
  if (best.x.size() > p) {  // an interrupted or failed multiple-shooting search: its parameters only
    best.x.conservativeResize(p);
    if (best.jtj.rows() > p) best.jtj = best.jtj.topLeftCorner(p, p).eval();
  }

  Result<GreyboxModel> r;
  r.diagnostics.warnings = warnings;
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
  if (shooting) {
    r.diagnostics.set(diagnostic::segments, ns / std::max(nx, 1) + E);
    r.diagnostics.set(diagnostic::continuity_defect, defect);
  }
  const std::string failure = "the model cannot be simulated on these data from its start" +
                              std::string(opt.starts > 1 ? "s" : "") + (escape.empty() ? "" : ": " + escape);
  internal::set_termination(r.summary, best, failure, unidentifiable);
  // The fit: all outputs of all records stacked, each weighted (one output: the output itself).
  Eigen::VectorXd rr;
  Eigen::VectorXd yfit = Eigen::VectorXd::Constant(y.size(), NAN);
  if (segment_fit.size()) yfit = segment_fit;
  else if (std::isfinite(best.cost) && evaluate(best.x, rr, nullptr)) yfit = wy - rr;
  else if (r.summary.succeeded()) {
    r.summary.termination = Termination::NumericalFailure;
    r.summary.message = failure;
  }
  r.fit = fit_report_or_inf(wy, yfit, p);
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
