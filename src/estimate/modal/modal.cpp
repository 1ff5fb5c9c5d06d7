// El-Shafey (1987): modal-parameter estimation (ES-C3, C4, C5), Theorems 4.1/4.2 (ES-C8) and modal_fit.
// Poles from free responses (ES-C9) are in modal_poles.cpp, nonparametric responses (ES-C10..C12) in
// modal_responses.cpp.
#include "ctid/estimate/modal/modal.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <functional>
#include <numbers>

#include "ctid/core/check.hpp"
#include "ctid/model/modal.hpp"
#include "ctid/estimate/svf/lssvf.hpp"
#include "ctid/signal/walsh.hpp"
#include "ctid/simulate/lsim.hpp"
#include "ctid/validate/metrics.hpp"
#include "estimate/transfer_function/tf_common.hpp"
#include "estimate/modal/modal_common.hpp"
#include "internal/least_squares.hpp"

namespace ctid {

using namespace modal_detail;

namespace {


// Regressor r(i) = [y(i - lag_1) .. y(i - lag_n), -x_c(i)^T] (samples before the record are zero).
struct Regressor {
  const Eigen::VectorXd& y;
  const Eigen::MatrixXd& X;
  const Eigen::VectorXi& lag;
  int p() const { return static_cast<int>(lag.size() + X.cols()); }
  double ys(Eigen::Index k) const { return k >= 0 ? y(k) : 0.0; }
  void operator()(Eigen::Index i, double* r, int extra_lag = 0) const {
    for (Eigen::Index k = 0; k < lag.size(); ++k) r[k] = ys(i - lag(k) + extra_lag);
    for (Eigen::Index k = 0; k < X.cols(); ++k) r[lag.size() + k] = -X(i, k);
  }
  Eigen::RowVectorXd row(Eigen::Index i) const {
    Eigen::RowVectorXd r(p());
    (*this)(i, r.data());
    return r;
  }
};


struct SampleWindow {
  int rec = 0, i0 = 0, K = 0;  // record, first sample, number of intervals
};

}  // namespace

template <>
const OptionTable<ModalOptions>& option_table<ModalOptions>() {
  using O = ModalOptions;
  static const OptionTable<O> t = [] {
    OptionTable<O> x("modal");
    x.reals("shifts", &O::shifts, "s", above(0),
            "T_1 < .. < T_n, one per system pole, whole multiples of Ts (the CLI also takes shift_samples); none: "
            "chosen for `order` by the conditioning of a pre-estimate")
        .integer("order", &O::order, "", at_least(0), "system order n when shifts are left automatic")
        .choice("basis", &O::basis,
                {{"automatic", std::optional<ModalBasis>()}, {"fourier", std::optional(ModalBasis::Fourier)},
                 {"walsh", std::optional(ModalBasis::Walsh)}, {"discrete", std::optional(ModalBasis::Discrete)}},
                "modal functions (automatic: Walsh for a piecewise-constant input, Fourier otherwise)")
        .integer("max_order", &O::max_order, "", at_least(0), "estimate p_j, q_j for j = 0..max_order (> 0: Fourier or Walsh)")
        .reals_via("windows", "s", at_least(0),
                   "validity windows START,LENGTH[,START,LENGTH..] (none: automatic)",
                   [](const O& o) {
                     std::vector<double> v;
                     for (const auto& w : o.windows) v.insert(v.end(), {w.start, w.length});
                     return v;
                   },
                   [](O& o, const std::string& method, const std::vector<double>& v) {
                     if (v.size() % 2 != 0)
                       throw InvalidOptions(detail::format("{}: windows are pairs START,LENGTH (got {} values)", method, v.size()));
                     o.windows.clear();
                     for (std::size_t i = 0; i < v.size(); i += 2) o.windows.push_back({v[i], v[i + 1]});
                   })
        .integer("functions", &O::functions, "", at_least(0),
                 "Fourier: 2m functions (even); Walsh: 2^k functions per window; 0: automatic (6 Fourier, 8 Walsh)")
        .choice("quadrature", &O::quadrature, {{"simpson", Quadrature::Simpson}, {"trapezoid", Quadrature::Trapezoid}},
                "integration rule of the Fourier/Walsh integrals (trapezoid reproduces the thesis)")
        .integer("stride", &O::stride, "", at_least(1), "Discrete: every stride-th sample of a window is an equation")
        .real("iv_shift", &O::iv_shift, "s", at_least(0), "Discrete: > 0 uses instruments y(t - T_i + iv_shift)")
        .real("delay", &O::delay, "s", at_least(0), "input delay (a multiple of Ts), fitted on the delayed input");
    return x;
  }();
  return t;
}

ModalOptions ModalOptions::resolved(bool piecewise_constant) const {
  ModalOptions o = *this;
  if (!o.basis) o.basis = piecewise_constant ? ModalBasis::Walsh : ModalBasis::Fourier;
  if (o.functions == 0) o.functions = o.basis == ModalBasis::Walsh ? 8 : 6;
  return o;
}

Eigen::VectorXd shifts_from_samples(const std::string& method, const std::vector<double>& samples, double ts,
                                    const Eigen::VectorXd& given) {
  CTID_REQUIRE_OPTION(given.size() == 0, "{}: give either shifts (seconds) or shift_samples (samples), not both", method);
  Eigen::VectorXd shifts(static_cast<Eigen::Index>(samples.size()));
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const double v = samples[i];
    CTID_REQUIRE_OPTION(std::abs(v - std::round(v)) <= 1e-9 && v >= 0 && v <= 1e9,
                        "{}: shift_samples: {} is not a whole number of samples", method, v);
    shifts(static_cast<Eigen::Index>(i)) = std::round(v) * ts;
  }
  return shifts;
}

void ModalOptions::validate() const {
  option_table<ModalOptions>().check(*this);
  CTID_REQUIRE_OPTION(shifts.size() >= 1 || order >= 1,
                      "modal: give the system order (order = n: the shifts are then chosen) or the shifts (one per pole)");
  CTID_REQUIRE_OPTION(shifts.size() == 0 || order == 0 || order == shifts.size(),
                      "modal: order = {} but {} shifts are given (one per pole)", order, shifts.size());
  for (Eigen::Index i = 0; i < shifts.size(); ++i) {
    CTID_REQUIRE_OPTION(std::isfinite(shifts(i)) && shifts(i) > 0, "modal: shift {} must be > 0 (got {} s)", i + 1,
                        shifts(i));
    if (i > 0)
      CTID_REQUIRE_OPTION(shifts(i) > shifts(i - 1), "modal: shifts must be increasing (T_{} = {} s, T_{} = {} s)", i,
                          shifts(i - 1), i + 1, shifts(i));
  }
  CTID_REQUIRE_OPTION(max_order >= 0, "modal: max_order must be >= 0 (got {})", max_order);
  CTID_REQUIRE_OPTION(basis != ModalBasis::Discrete || max_order == 0,
                      "modal: derivative orders j > 0 (max_order = {}) need the Fourier or Walsh basis: derivatives are "
                      "not measured", max_order);
  if (basis == ModalBasis::Fourier && functions != 0)
    CTID_REQUIRE_OPTION(functions >= 2 && functions % 2 == 0, "modal: the number of Fourier functions must be even and "
                        ">= 2 (got {})", functions);
  if (basis == ModalBasis::Walsh && functions != 0)
    CTID_REQUIRE_OPTION(functions >= 1 && (functions & (functions - 1)) == 0,
                        "modal: the number of Walsh functions must be a power of two (got {})", functions);
  CTID_REQUIRE_OPTION(stride >= 1, "modal: stride must be >= 1 (got {})", stride);
  CTID_REQUIRE_OPTION(std::isfinite(iv_shift) && iv_shift >= 0, "modal: iv_shift must be >= 0 (got {} s)", iv_shift);
  for (const auto& w : windows)
    CTID_REQUIRE_OPTION(std::isfinite(w.start) && std::isfinite(w.length) && w.start >= 0 && w.length > 0,
                        "modal: a window must have start >= 0 and length > 0 (got start {} s, length {} s)", w.start,
                        w.length);
}

std::vector<ModalWindow> piecewise_constant_windows(const IdData& data, double settle, double min_length) {
  CTID_REQUIRE(data.nu() == 1, "piecewise_constant_windows: needs one input (got {})", data.nu());
  CTID_REQUIRE(data.is_uniform(), "piecewise_constant_windows: needs uniformly sampled data");
  CTID_REQUIRE(std::isfinite(settle) && settle >= 0, "piecewise_constant_windows: settle must be >= 0 (got {})", settle);
  const Eigen::VectorXd u = data.u().col(0);
  const double Ts = data.ts();
  const int s = static_cast<int>(std::min(std::ceil(settle / Ts - 1e-9), data.size() + 1.0));  // no overflow
  std::vector<ModalWindow> out;
  int begin = 0;  // first sample of the current level
  for (int i = 1; i <= data.size(); ++i) {
    if (i < data.size() && u(i) == u(i - 1)) continue;
    const int first = begin + s, last = i - 1;
    if (last > first && (last - first) * Ts >= min_length) out.push_back({first * Ts, (last - first) * Ts});
    begin = i;
  }
  return out;
}

namespace {
// One record of a modal estimation: its data, the input basis at its samples and its validity windows (seconds
// from its first sample). Several records are several experiments of one system: their equations are pooled.
struct ModalRecord {
  const IdData* data;
  Eigen::MatrixXd basis;
  std::vector<ModalWindow> windows;
};

Result<ModalModel> modal_estimate_records(const std::vector<ModalRecord>& records, const ModalOptions& options);
}  // namespace

Result<ModalModel> modal_estimate(const IdData& data, const Eigen::MatrixXd& input_basis, const ModalOptions& options) {
  options.validate();
  CTID_REQUIRE(data.is_uniform(), "modal: needs uniformly sampled data");
  std::vector<ModalWindow> windows = options.windows;
  if (windows.empty()) {
    // One window from T_n to the end of the record.
    const double Tn = options.shifts(options.shifts.size() - 1), len = (data.size() - 1) * data.ts() - Tn;
    CTID_REQUIRE(len > 0, "modal: the record ({} s) is not longer than the largest shift T_n = {} s",
                 (data.size() - 1) * data.ts(), Tn);
    windows.push_back({Tn, len});
  }
  return modal_estimate_records({{&data, input_basis, windows}}, options);
}

namespace {
// The modal regressions of a set of records: their regressors, validity windows in samples and sizes. The
// regressors refer to its own outputs and lags: it is built in place and never copied.
struct ModalSystem {
  ModalSystem() = default;
  ModalSystem(const ModalSystem&) = delete;
  ModalSystem& operator=(const ModalSystem&) = delete;
  ModalOptions o;                  // resolved
  double Ts = 0;
  int E = 0, n = 0, nc = 0, p = 0, J = 0, W = 0, total_samples = 0;
  Eigen::VectorXi lag;
  std::vector<Eigen::VectorXd> ys;  // each record's output
  std::vector<Regressor> regs;
  std::vector<SampleWindow> sw;
};

// Stores the order-j solution (the model's rows P_j, Q_j and their covariance).
using StoreOrder = std::function<void(int j, const internal::LinearSolution& sol)>;

void build(ModalSystem& m, const std::vector<ModalRecord>& records, const ModalOptions& options) {
  m.o = options.resolved(false);
  const ModalOptions& o = m.o;
  const int E = m.E = static_cast<int>(records.size()), n = m.n = static_cast<int>(o.shifts.size());
  const IdData& first = *records.front().data;
  CTID_REQUIRE(first.is_uniform(), "modal: needs uniformly sampled data");
  const double Ts = m.Ts = first.ts();
  const int nc = m.nc = static_cast<int>(records.front().basis.cols());
  std::vector<Eigen::VectorXd>& ys = m.ys;
  for (int e = 0; e < E; ++e) {
    const IdData& d = *records[e].data;
    const std::string which = E > 1 ? detail::format(" (record {})", e + 1) : "";
    CTID_REQUIRE(d.ny() == 1, "modal: needs one output{} (got {})", which, d.ny());
    CTID_REQUIRE(d.is_uniform(), "modal: needs uniformly sampled data{}", which);
    CTID_REQUIRE(std::abs(d.ts() - Ts) <= 1e-9 * Ts, "modal: the records are sampled at different periods ({} s and {} s)",
                 Ts, d.ts());
    CTID_REQUIRE(records[e].basis.rows() == d.size(), "modal: the input basis has {} rows for {} samples{}",
                 records[e].basis.rows(), d.size(), which);
    CTID_REQUIRE(records[e].basis.cols() == nc, "modal: the input bases have {} and {} columns", nc,
                 records[e].basis.cols());
    CTID_REQUIRE(records[e].basis.allFinite(), "modal: the input basis has non-finite values{}", which);
    ys.push_back(d.y().col(0));
  }
  m.lag.resize(n);
  for (int i = 0; i < n; ++i) m.lag(i) = samples_of(o.shifts(i), Ts, "shift T_" + std::to_string(i + 1));
  for (int e = 0; e < E; ++e) m.regs.push_back(Regressor{ys[e], records[e].basis, m.lag});
  m.p = n + nc;
  for (int e = 0; e < E; ++e) {
    const int N = records[e].data->size();
    m.total_samples += N;
    const auto& windows = records[e].windows;
    for (size_t w = 0; w < windows.size(); ++w) {
      const std::string name = "window " + std::to_string(w + 1) + (E > 1 ? " of record " + std::to_string(e + 1) : "");
      SampleWindow s{e, samples_of(windows[w].start, Ts, name + " start"), samples_of(windows[w].length, Ts, name + " length")};
      CTID_REQUIRE(s.K >= 1 && s.i0 + s.K <= N - 1, "modal: {} [{} s, {} s] is outside the record [0, {} s]", name,
                   windows[w].start, windows[w].start + windows[w].length, (N - 1) * Ts);
      m.sw.push_back(s);
    }
  }
  CTID_REQUIRE(!m.sw.empty(), "modal: no validity window");
  m.J = o.max_order;
  m.W = static_cast<int>(m.sw.size());
}

// Discrete basis: the equation at every (stride-th) sample of the windows, by least squares or instrumental variables.
void solve_discrete(const ModalSystem& m, const StoreOrder& store) {
  const ModalOptions& o = m.o;
  const int p = m.p;
  const int ivlag = o.iv_shift > 0 ? samples_of(o.iv_shift, m.Ts, "iv_shift") : 0;
  internal::StreamingLeastSquares ls(p);
  internal::InstrumentalVariables iv(p);
  Eigen::VectorXd r(p), z(p);
  long long rows = 0;
  for (const auto& s : m.sw) {
    const Regressor& reg = m.regs[s.rec];
    for (int i = s.i0; i <= s.i0 + s.K; i += o.stride) {
      reg(i, r.data());
      if (ivlag > 0) {
        if (i - m.lag(0) + ivlag >= reg.y.size()) continue;  // the instrument y(t - T_1 + iv_shift) is beyond the record
        reg(i, z.data(), ivlag);
        iv.add(z.data(), r.data(), reg.y(i));
      } else {
        ls.add(r.data(), reg.y(i));
      }
      ++rows;
    }
  }
  CTID_REQUIRE(rows >= p, "modal: {} equations in the validity windows for {} unknowns (n = {} shifts + {} input "
               "modes); lengthen the windows or reduce the stride", rows, p, m.n, m.nc);
  // sum p y(t - T_i) - q x_c = -y: the kernel solves r theta' = y with theta' = -theta.
  store(0, ivlag > 0 ? iv.solve() : ls.solve());
}

// Fourier basis: the functions run on the concatenation of the windows (local time tau continues from one window to
// the next, T_o = total length; ES Ex. 3.2): for j = 0 the equation holds pointwise in every window. The c_(j-1)
// recursion integrates by parts, so j > 0 needs one continuous window.
void solve_fourier(const ModalSystem& m, const StoreOrder& store) {
  const ModalOptions& o = m.o;
  const int p = m.p, J = m.J, F = o.functions, mf = o.functions / 2;
  CTID_REQUIRE(J == 0 || m.W == 1, "modal: Fourier derivative orders j > 0 (max_order = {}) need one continuous window "
               "(got {})", J, m.W);
  CTID_REQUIRE(F >= p + (J > 0 ? 1 : 0), "modal: {} Fourier functions for {} unknowns (n = {} shifts + {} input modes{})",
               F, p + (J > 0 ? 1 : 0), m.n, m.nc, J > 0 ? " + c" : "");
  int total = 0;
  for (const auto& s : m.sw) total += s.K;
  const FourierFunctions ff{mf, 2 * std::numbers::pi / (total * m.Ts)};
  Eigen::MatrixXd RF = Eigen::MatrixXd::Zero(F, p);
  Eigen::VectorXd zF = Eigen::VectorXd::Zero(F), f(F);
  Eigen::RowVectorXd row(p);
  int offset = 0;
  for (const auto& s : m.sw) {
    const Regressor& reg = m.regs[s.rec];
    const Eigen::VectorXd wq = quadrature_weights(s.K, m.Ts, o.quadrature);
    for (int k = 0; k <= s.K; ++k) {
      ff((offset + k) * m.Ts, f);
      f *= wq(k);
      reg(s.i0 + k, row.data());
      RF.noalias() += f * row;
      zF += f * reg.y(s.i0 + k);
    }
    offset += s.K;
  }
  store(0, least_squares(RF, zF));  // R_F theta' = z_F, theta = -theta'
  const Eigen::MatrixXd Om = ff.omega();
  const Eigen::VectorXd f0 = ff.at_zero();
  Eigen::MatrixXd Aj(F, p + 1);
  Aj << -RF, -f0;
  Eigen::VectorXd zhat = zF;
  for (int j = 1; j <= J; ++j) {
    // z_jF = -Omega z_(j-1)F + f(0) c_(j-1), so R_F theta_j + f(0) c = Omega z_(j-1)F; solved for
    // (theta', c') = -(theta_j, c) like the other orders.
    const internal::LinearSolution sol = least_squares(Aj, Om * zhat);
    store(j, sol);
    zhat = -Om * zhat - f0 * sol.theta(p);
  }
}

// Walsh basis: block-pulse integrals over each window; order j from order j - 1 through the edges of the blocks
// (ES 3.37). `P`, `Q`: the rows stored so far.
void solve_walsh(const ModalSystem& m, const StoreOrder& store, const Eigen::MatrixXd& P, const Eigen::MatrixXd& Q) {
  const ModalOptions& o = m.o;
  const int p = m.p, W = m.W, NW = o.functions;
  CTID_REQUIRE(NW * W >= p, "modal: {} Walsh equations ({} functions x {} windows) for {} unknowns", NW * W, NW, W, p);
  std::vector<Eigen::MatrixXd> RW(W), Rdiff(W);
  Eigen::MatrixXd A(NW * W, p);
  Eigen::VectorXd b(NW * W);
  for (int w = 0; w < W; ++w) {
    const auto& s = m.sw[w];
    const Regressor& reg = m.regs[s.rec];
    CTID_REQUIRE(s.K % NW == 0, "modal: window {} has {} sampling periods, not a multiple of the {} Walsh blocks (each "
                 "block must span a whole number of samples)", w + 1, s.K, NW);
    const int kb = s.K / NW;
    const Eigen::VectorXd wq = quadrature_weights(kb, m.Ts, o.quadrature);
    Eigen::MatrixXd RB = Eigen::MatrixXd::Zero(NW, p);
    Eigen::VectorXd zB = Eigen::VectorXd::Zero(NW);
    Rdiff[w].resize(NW, p);
    Eigen::RowVectorXd row(p);
    for (int blk = 0; blk < NW; ++blk) {
      const int first = s.i0 + blk * kb;
      for (int k = 0; k <= kb; ++k) {
        reg(first + k, row.data());
        RB.row(blk) += wq(k) * row;
        zB(blk) += wq(k) * reg.y(first + k);
      }
      Rdiff[w].row(blk) = reg.row(first) - reg.row(first + kb);  // R_d^- - R_d^+ (left minus right edges)
    }
    RW[w] = walsh_transform(RB);
    A.middleRows(w * NW, NW) = RW[w];
    b.segment(w * NW, NW) = walsh_transform(zB);
  }
  store(0, least_squares(A, b));
  for (int j = 1; j <= m.J; ++j) {
    // ES 3.37: theta_j = -(R_W^T R_W)^{-1} R_W^T Psi (R_d^- - R_d^+) theta_(j-1).
    const Eigen::VectorXd prev = (Eigen::VectorXd(p) << P.row(j - 1).transpose(), Q.row(j - 1).transpose()).finished();
    for (int w = 0; w < W; ++w) b.segment(w * NW, NW) = walsh_transform(Rdiff[w] * prev);
    store(j, least_squares(A, b));
  }
}

Result<ModalModel> modal_estimate_records(const std::vector<ModalRecord>& records, const ModalOptions& options) {
  const auto t_start = std::chrono::steady_clock::now();
  options.validate();
  CTID_REQUIRE_OPTION(options.delay == 0.0, "modal: delay = {} s applies to modal_fit (delay the input of the record)",
                      options.delay);
  ModalSystem m;
  build(m, records, options);
  const int J = m.J, n = m.n, nc = m.nc, p = m.p;
  Eigen::MatrixXd P(J + 1, n), Q(J + 1, nc);
  Result<ModalModel> res;
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero((J + 1) * p, (J + 1) * p);
  Eigen::VectorXd cond(J + 1);
  const StoreOrder store = [&](int j, const internal::LinearSolution& sol) {
    const Eigen::VectorXd theta = -sol.theta.head(p);
    P.row(j) = theta.head(n).transpose();
    Q.row(j) = theta.tail(nc).transpose();
    cov.block(j * p, j * p, p, p) = sol.covariance.topLeftCorner(p, p);
    cond(j) = sol.condition;
    if (j == 0) {
      // No simulated output at this stage: the fit is that of the order-0 modal regression.
      res.fit.mse = sol.rss / std::max<long long>(1, sol.n_rows);
      res.fit.nrmse = sol.tss > 0 ? std::sqrt(sol.rss / sol.tss) : std::numeric_limits<double>::infinity();
      res.fit.fit_percent = 100.0 * (1.0 - res.fit.nrmse);
    }
    if (sol.rank_deficient) {
      res.summary.termination = Termination::RankDeficient;
      res.summary.message = detail::format("the order-{} modal regression is rank deficient (condition {}): the input "
                                           "does not excite {} modes in the windows, or the shifts are badly placed",
                                           j, sol.condition, p);
    }
  };

  if (m.o.basis == ModalBasis::Discrete) solve_discrete(m, store);
  else if (m.o.basis == ModalBasis::Fourier) solve_fourier(m, store);
  else solve_walsh(m, store, P, Q);

  res.model = ModalModel(m.o.shifts, P, Q);
  for (int j = 0; j <= J; ++j) {
    for (int i = 1; i <= n; ++i) res.parameters.names.push_back(detail::format("p{}_{}", j, i));
    for (int k = 1; k <= nc; ++k) res.parameters.names.push_back(detail::format("q{}_{}", j, k));
  }
  res.parameters.values.resize((J + 1) * p);
  for (int j = 0; j <= J; ++j) res.parameters.values.segment(j * p, p) << P.row(j).transpose(), Q.row(j).transpose();
  res.parameters.std = cov.diagonal().cwiseMax(0.0).cwiseSqrt();
  if (res.summary.succeeded() && !cov.allFinite()) {
    // As many equations as unknowns (e.g. as many modal functions as parameters): no residual is left to
    // estimate the noise from, so the uncertainty is unknown (not zero, not singular).
    cov.resize(0, 0);
    res.parameters.std.setConstant(std::numeric_limits<double>::quiet_NaN());
    res.diagnostics.warnings.push_back(detail::format(
        "the regressions are exactly determined (no residual degrees of freedom for the {} unknowns per order): "
        "standard deviations are unknown; use more functions, windows or samples to get them",
        p));
  }
  res.parameters.covariance = cov;
  res.parameters.fixed.assign((J + 1) * p, false);
  res.fit.n_samples = m.total_samples;
  res.fit.n_parameters = p;
  res.diagnostics.condition_number = cond(0);
  res.diagnostics.set(diagnostic::condition_by_order, cond);
  res.diagnostics.set(diagnostic::windows, m.W);
  if (m.E > 1) res.diagnostics.set(diagnostic::experiments, m.E);
  if (cond.maxCoeff() > 1e8)
    res.diagnostics.warnings.push_back(detail::format(
        "modal regression condition number {} > 1e8: spread the shifts (conditioning of psi) or lengthen the windows",
        cond.maxCoeff()));
  res.summary.iterations = 1;
  res.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return res;
}
}  // namespace

Result<ModalModel> modal_estimate(const IdData& data, const InputGenerator& input, const ModalOptions& options) {
  Eigen::VectorXd t(data.size());
  for (int i = 0; i < data.size(); ++i) t(i) = data.time(i) - data.t0();
  return modal_estimate(data, input.basis(t), options);
}

Result<TransferFunction> modal_transfer_function(const IdData& data, const InputGenerator& input, ModalOptions o) {
  const int n = static_cast<int>(o.shifts.size());
  o.max_order = n;
  CTID_REQUIRE(input.order() >= n, "modal_transfer_function: Theorem 4.2 needs at least n = {} input modes (the input "
               "generator has {})", n, input.order());
  const Result<ModalModel> m = modal_estimate(data, input, o);
  Result<TransferFunction> r;
  r.model = m.model.transfer_function(input);
  r.summary = m.summary;
  r.diagnostics = m.diagnostics;
  // Named as every transfer-function estimator names them (tf_parameter_names: a1..an of s^(n-1)..s^0, b0.. from
  // the highest power of the numerator).
  const TfOrders orders{n, n, 0};
  r.parameters.names = tf_parameter_names(orders);
  r.parameters.values = tf_detail::params_of(r.model, orders);
  r.parameters.std = Eigen::VectorXd::Constant(2 * n, std::numeric_limits<double>::quiet_NaN());
  r.parameters.fixed.assign(2 * n, false);
  // Validation by exact simulation from rest with the generated input (the method's input model).
  Eigen::VectorXd t(data.size());
  for (int i = 0; i < data.size(); ++i) t(i) = data.time(i) - data.t0();
  r.fit = fit_report_or_inf(data.y().col(0), lsim(r.model.to_state_space(), input, t), 2 * n);
  return r;
}

namespace {
Result<TransferFunction> modal_fit_undelayed(const internal::RecordRefs& data, int nb, ModalOptions o,
                                             const InputGenerator* input);
Eigen::VectorXd automatic_shifts(const IdData& d, int n, bool piecewise_constant, std::vector<std::string>& choices);
}  // namespace

namespace {
// modal_fit of one record or of several, without copying them (only a delay makes delayed copies).
Result<TransferFunction> modal_fit_records(const internal::RecordRefs& data, int nb, ModalOptions o,
                                           const InputGenerator* input) {
  o.validate();
  CTID_REQUIRE(!data.empty(), "modal_fit: no records");
  CTID_REQUIRE(!input || data.size() == 1,
               "modal_fit: a generated input belongs to one record (Theorem 4.2's q depend on its generator's state); "
               "{} records are fitted jointly with piecewise-constant inputs, or one at a time", data.size());
  for (std::size_t e = 0; e < data.size(); ++e)
    require_io_data(data[e], data.size() > 1 ? detail::format("modal_fit (record {})", e + 1).c_str() : "modal_fit");
  // The delayed input (zero before each record): the fit sees a delay-free system.
  std::vector<IdData> delayed;
  if (o.delay > 0.0) {
    for (const IdData& d : data) {
      CTID_REQUIRE(d.is_uniform(), "modal_fit: a delay needs uniformly sampled data");
      const double k = o.delay / d.ts();
      CTID_REQUIRE_OPTION(std::abs(k - std::round(k)) <= 1e-9 * std::max(1.0, k),
                          "modal_fit: delay = {} s is not a whole multiple of the sampling period {} s", o.delay, d.ts());
      const int nk = static_cast<int>(std::lround(k));
      CTID_REQUIRE(nk < d.size(), "modal_fit: the delay {} s is not shorter than the record ({} samples)", o.delay, d.size());
      Eigen::MatrixXd u = Eigen::MatrixXd::Zero(d.size(), 1);
      u.bottomRows(d.size() - nk) = d.u().topRows(d.size() - nk);
      delayed.emplace_back(u, d.y(), d.ts(), d.t0());
      delayed.back().set_intersample(0, d.intersample(0));
    }
  }
  const internal::RecordRefs fitted = o.delay > 0.0 ? internal::RecordRefs(delayed) : data;
  std::vector<std::string> choices;
  if (o.shifts.size() == 0) o.shifts = automatic_shifts(fitted.front(), o.order, input == nullptr, choices);
  const double delay = o.delay;
  o.delay = 0.0;
  Result<TransferFunction> r = modal_fit_undelayed(fitted, nb, o.resolved(input == nullptr), input);
  if (delay > 0.0) r.model.set_io_delay(delay);
  r.diagnostics.choices = std::move(choices);
  return r;
}
}  // namespace

Result<TransferFunction> modal_fit(const IdData& data, int nb, ModalOptions o, const InputGenerator* input) {
  return modal_fit_records(data, nb, std::move(o), input);
}

Result<TransferFunction> modal_fit(const std::vector<IdData>& data, int nb, ModalOptions o, const InputGenerator* input) {
  return modal_fit_records(data, nb, std::move(o), input);
}

namespace {
// The shifts of modal_fit left automatic: see modal.hpp.
Eigen::VectorXd automatic_shifts(const IdData& d, int n, bool piecewise_constant, std::vector<std::string>& choices) {
  CTID_REQUIRE(d.is_uniform(), "modal_fit: automatic shifts need uniformly sampled data");
  const double Ts = d.ts(), duration = d.size() * Ts;
  double max_shift = duration / 4;
  std::string limit = "a quarter of the record";
  if (piecewise_constant) {
    std::vector<int> runs;
    int run = 1;
    for (int i = 1; i < d.size(); ++i) {
      if (d.u()(i, 0) == d.u()(i - 1, 0)) {
        ++run;
      } else {
        runs.push_back(run);
        run = 1;
      }
    }
    runs.push_back(run);
    std::nth_element(runs.begin(), runs.begin() + static_cast<std::ptrdiff_t>(runs.size() / 2), runs.end());
    const double half_level = 0.5 * runs[runs.size() / 2] * Ts;
    if (half_level < max_shift) {
      max_shift = half_level;
      limit = "half the median level duration";
    }
  }
  CTID_REQUIRE(max_shift >= n * Ts,
               "modal_fit: no room for {} automatic shifts: {} is {} s, less than n Ts = {} s; give the shifts", n, limit,
               max_shift, n * Ts);
  const Result<TransferFunction> pre = tf_detail::pre_estimate(d, n);
  const ShiftChoice c = choose_modal_shifts(pre.model, Ts, max_shift);
  const double spacing = c.shifts(0);
  choices.push_back(detail::format("shifts = i * {} s (i = 1..{}; {} samples apart): the spacing that minimises cond(psi) "
                                   "(= {}) of the pre-estimate {}, T_n at most {} ({} s)",
                                   detail::significant(spacing), n, std::lround(spacing / Ts),
                                   detail::significant(c.condition, 3), pre.model.to_string(4), limit,
                                   detail::significant(max_shift)));
  return c.shifts;
}

Result<TransferFunction> modal_fit_undelayed(const internal::RecordRefs& data, int nb, ModalOptions o,
                                             const InputGenerator* input) {
  const auto t_start = std::chrono::steady_clock::now();
  const int n = static_cast<int>(o.shifts.size());
  CTID_REQUIRE(nb >= 1 && nb <= n, "modal_fit: nb = {} numerator coefficients must be in [1, n = {}]", nb, n);
  if (input) {
    CTID_REQUIRE(nb == n, "modal_fit: Theorem 4.2 estimates all n = {} numerator coefficients (nb = {})", n, nb);
    Result<TransferFunction> r = modal_transfer_function(data.front(), *input, o);
    r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    return r;
  }
  const int E = static_cast<int>(data.size());
  CTID_REQUIRE(o.windows.empty() || E == 1,
               "modal_fit: windows are times of one record; with {} records they are found from each record's level "
               "switches (leave windows empty)", E);
  std::vector<ModalRecord> records;
  for (const IdData& d : data) records.push_back({&d, d.u(), o.windows});
  if (o.windows.empty()) {
    // Automatic windows in every record: Walsh blocks must tile each window (trim to a multiple of N sampling
    // periods); the Fourier recursion needs one window (the longest of all records).
    for (ModalRecord& rec : records) {
      const double Ts = rec.data->ts();
      for (ModalWindow w : piecewise_constant_windows(*rec.data, o.shifts(n - 1), Ts)) {
        if (o.basis == ModalBasis::Walsh) w.length = std::floor(w.length / Ts / o.functions + 1e-9) * o.functions * Ts;
        if (w.length > 0) rec.windows.push_back(w);
      }
    }
    if (o.basis == ModalBasis::Fourier) {
      std::size_t best = 0, best_w = 0;
      double longest = -1;
      for (std::size_t e = 0; e < records.size(); ++e)
        for (std::size_t w = 0; w < records[e].windows.size(); ++w)
          if (records[e].windows[w].length > longest) longest = records[e].windows[w].length, best = e, best_w = w;
      for (std::size_t e = 0; e < records.size(); ++e)
        records[e].windows = e == best && longest > 0 ? std::vector<ModalWindow>{records[e].windows[best_w]}
                                                      : std::vector<ModalWindow>{};
    }
  }
  int windows = 0;
  for (const ModalRecord& rec : records) windows += static_cast<int>(rec.windows.size());
  CTID_REQUIRE(windows > 0, "modal_fit: the input never stays constant long enough after a switch (T_n = {} s, "
               "the largest shift, plus the Walsh blocks): no validity windows", o.shifts(n - 1));
  if (o.basis != ModalBasis::Discrete) o.max_order = std::max(o.max_order, n);
  o.windows.clear();
  const Result<ModalModel> m = modal_estimate_records(records, o);
  Result<TransferFunction> r;
  r.diagnostics = m.diagnostics;
  r.summary = m.summary;
  Eigen::Index total = 0;
  for (const IdData& d : data) total += d.size();
  Eigen::VectorXd y(total);
  for (Eigen::Index e = 0, at = 0; e < E; at += data[e].size(), ++e) y.segment(at, data[e].size()) = data[e].y().col(0);
  auto failed = [&](const std::string& why) {
    r.summary.termination = Termination::RankDeficient;
    r.summary.message = why;
    r.fit = fit_report_or_inf(y, Eigen::VectorXd::Constant(total, NAN), n + nb);
    r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    return r;
  };
  if (m.summary.termination == Termination::RankDeficient) return failed(m.summary.message);
  Polynomial den;
  if (m.model.max_order() >= n) {
    den = m.model.characteristic_polynomial();  // Theorem 4.1
  } else {
    const double T = o.shifts(0);
    for (int i = 0; i < n; ++i)
      CTID_REQUIRE(std::abs(o.shifts(i) - (i + 1) * T) <= 1e-9 * T, "modal_fit: the Discrete route needs uniform shifts "
                   "T_i = i T (T_{} = {} s, T_1 = {} s); or use the Fourier/Walsh basis", i + 1, o.shifts(i), T);
    Eigen::VectorXd zc(n + 1);
    zc << 1.0, m.model.P().row(0).transpose();
    const Eigen::VectorXcd z = Polynomial(zc).roots();
    for (int k = 0; k < n; ++k)
      if (!(std::abs(z(k)) > 1e-300))
        return failed("a root of z^n + p_01 z^(n-1) + .. + p_0n is at z = 0: no finite pole (p_0n = 0)");
    Eigen::VectorXcd e = Eigen::VectorXcd::Zero(n + 1);
    e(0) = 1.0;
    for (int k = 0; k < n; ++k) {
      const std::complex<double> sk = std::log(z(k)) / T;
      for (int i = k + 1; i >= 1; --i) e(i) -= sk * e(i - 1);
    }
    den = Polynomial(Eigen::VectorXd(e.real()));
  }
  // Numerator by linear least squares on the exact responses of s^j / A(s) (j < nb) to each record's input, from
  // rest, stacked over the records.
  Eigen::MatrixXd X(total, nb);
  Eigen::Index at = 0;
  for (const IdData& d : data) {
    for (int j = 0; j < nb; ++j) {
      Eigen::VectorXd num = Eigen::VectorXd::Zero(j + 1);
      num(0) = 1.0;
      X.col(j).segment(at, d.size()) = lsim(TransferFunction(Polynomial(num), den), d, 0);
    }
    at += d.size();
  }
  const internal::LinearSolution sol = least_squares(X, y);
  Eigen::VectorXd numc(nb);
  for (int j = 0; j < nb; ++j) numc(j) = sol.theta(nb - 1 - j);
  r.model = TransferFunction(Polynomial(numc), den);
  // Named as every transfer-function estimator names them (tf_parameter_names); b0 is the numerator's highest power.
  const TfOrders orders{nb, n, 0};
  r.parameters.names = tf_parameter_names(orders);
  r.parameters.values = tf_detail::params_of(r.model, orders);
  r.parameters.std = Eigen::VectorXd::Constant(n + nb, std::numeric_limits<double>::quiet_NaN());
  r.parameters.std.tail(nb) = sol.covariance.diagonal().cwiseMax(0.0).cwiseSqrt().reverse();  // given A(s)
  r.parameters.fixed.assign(n + nb, false);
  if (!r.model.is_stable()) r.diagnostics.warnings.push_back("the estimated model is unstable");
  const auto [measured, simulated] = tf_detail::pooled_outputs(r.model, data, 0.0);
  r.fit = fit_report_or_inf(measured, simulated, n + nb);
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return r;
}
}  // namespace

InputGenerator generator_fitted_to_input(const std::vector<double>& frequencies, const IdData& d) {
  CTID_REQUIRE(d.nu() == 1, "generator_fitted_to_input: needs one input (got {})", d.nu());
  CTID_REQUIRE(!frequencies.empty(), "generator_fitted_to_input: no frequencies given");
  InputGenerator g;
  for (double w : frequencies) {
    CTID_REQUIRE(std::isfinite(w) && w >= 0, "generator_fitted_to_input: frequency {} rad/s is not >= 0", w);
    g = g + (w == 0 ? InputGenerator::constant(1.0) : InputGenerator::sinusoid(w, 1.0, 0.0));
  }
  Eigen::VectorXd t(d.size());
  for (int i = 0; i < d.size(); ++i) t(i) = d.time(i) - d.t0();
  const Eigen::MatrixXd X = g.basis(t);
  const Eigen::VectorXd c = X.colPivHouseholderQr().solve(d.u().col(0));  // amplitudes from the measured input
  return InputGenerator(g.A(), c, g.x0());
}

}  // namespace ctid
