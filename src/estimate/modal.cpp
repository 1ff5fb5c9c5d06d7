// El-Shafey (1987): modal-parameter estimation (ES-C3, C4, C5), Theorems 4.1/4.2 (ES-C8), poles from a
// free-response data matrix and Prony (ES-C9), nonparametric responses (ES-C10, C11, C12) and modal_fit.
#include "ctid/estimate/modal.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <numbers>

#include "ctid/core/check.hpp"
#include "ctid/signal/walsh.hpp"
#include "ctid/simulate/lsim.hpp"
#include "ctid/validate/metrics.hpp"
#include "internal/least_squares.hpp"

namespace ctid {

namespace {

// A whole number of sampling periods, or InvalidArgument naming `what`.
int samples_of(double seconds, double Ts, const std::string& what) {
  const double r = seconds / Ts;
  CTID_REQUIRE(std::isfinite(r) && std::abs(r) <= 1e9 && std::abs(r - std::round(r)) <= 1e-9 * std::max(1.0, std::abs(r)),
               "modal: {} = {} s is not a whole multiple of the sampling period {} s ({} periods)", what, seconds, Ts, r);
  return static_cast<int>(std::lround(r));
}

double condition_2(const Eigen::MatrixXd& M) {
  if (M.size() == 0) return 0.0;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(M);
  const Eigen::VectorXd s = svd.singularValues();
  return s(s.size() - 1) > 0 ? s(0) / s(s.size() - 1) : std::numeric_limits<double>::infinity();
}

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

// Fourier modulating functions f = [sin(w tau) .. sin(m w tau), cos(w tau) .. cos(m w tau)] (ES 3.11 ff.):
// D f = Omega f with Omega = [[0, Omega'], [-Omega', 0]], Omega' = diag(w, 2w, .., m w) (ES 3.25, missing
// in the OCR), and f(0) = f(T_o) = [0 .. 0, 1 .. 1].
struct FourierFunctions {
  int m;
  double w;
  void operator()(double tau, Eigen::VectorXd& f) const {
    for (int h = 1; h <= m; ++h) {
      f(h - 1) = std::sin(h * w * tau);
      f(m + h - 1) = std::cos(h * w * tau);
    }
  }
  Eigen::MatrixXd omega() const {
    Eigen::MatrixXd Om = Eigen::MatrixXd::Zero(2 * m, 2 * m);
    for (int h = 1; h <= m; ++h) {
      Om(h - 1, m + h - 1) = h * w;
      Om(m + h - 1, h - 1) = -h * w;
    }
    return Om;
  }
  Eigen::VectorXd at_zero() const {
    Eigen::VectorXd f0 = Eigen::VectorXd::Zero(2 * m);
    f0.tail(m).setOnes();
    return f0;
  }
};

struct SampleWindow {
  int i0 = 0, K = 0;  // first sample, number of intervals
};

internal::LinearSolution least_squares(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) {
  internal::StreamingLeastSquares ls(static_cast<int>(A.cols()));
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    const Eigen::RowVectorXd row = A.row(i);
    ls.add(row.data(), b(i));
  }
  return ls.solve();
}

}  // namespace

void ModalOptions::validate() const {
  CTID_REQUIRE_OPTION(shifts.size() >= 1, "modal: at least one shift is needed (one per system pole)");
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
  if (basis == ModalBasis::Fourier)
    CTID_REQUIRE_OPTION(functions >= 2 && functions % 2 == 0, "modal: the number of Fourier functions must be even and "
                        ">= 2 (got {})", functions);
  if (basis == ModalBasis::Walsh)
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

Result<ModalModel> modal_estimate(const IdData& data, const Eigen::MatrixXd& input_basis, const ModalOptions& o) {
  const auto t_start = std::chrono::steady_clock::now();
  o.validate();
  CTID_REQUIRE(data.ny() == 1, "modal: needs one output (got {})", data.ny());
  CTID_REQUIRE(data.is_uniform(), "modal: needs uniformly sampled data");
  const double Ts = data.ts();
  const int N = data.size(), n = static_cast<int>(o.shifts.size()), nc = static_cast<int>(input_basis.cols());
  CTID_REQUIRE(input_basis.rows() == N, "modal: the input basis has {} rows for {} samples", input_basis.rows(), N);
  CTID_REQUIRE(input_basis.allFinite(), "modal: the input basis has non-finite values");
  const Eigen::VectorXd y = data.y().col(0);
  Eigen::VectorXi lag(n);
  for (int i = 0; i < n; ++i) lag(i) = samples_of(o.shifts(i), Ts, "shift T_" + std::to_string(i + 1));
  const Regressor reg{y, input_basis, lag};
  const int p = n + nc;

  std::vector<ModalWindow> windows = o.windows;
  if (windows.empty()) {
    const double len = (N - 1) * Ts - o.shifts(n - 1);
    CTID_REQUIRE(len > 0, "modal: the record ({} s) is not longer than the largest shift T_n = {} s", (N - 1) * Ts,
                 o.shifts(n - 1));
    windows.push_back({o.shifts(n - 1), len});
  }
  std::vector<SampleWindow> sw;
  for (size_t w = 0; w < windows.size(); ++w) {
    const std::string name = "window " + std::to_string(w + 1);
    SampleWindow s{samples_of(windows[w].start, Ts, name + " start"), samples_of(windows[w].length, Ts, name + " length")};
    CTID_REQUIRE(s.K >= 1 && s.i0 + s.K <= N - 1, "modal: {} [{} s, {} s] is outside the record [0, {} s]", name,
                 windows[w].start, windows[w].start + windows[w].length, (N - 1) * Ts);
    sw.push_back(s);
  }
  const int J = o.max_order, W = static_cast<int>(sw.size());
  Eigen::MatrixXd P(J + 1, n), Q(J + 1, nc);
  Result<ModalModel> res;
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero((J + 1) * p, (J + 1) * p);
  Eigen::VectorXd cond(J + 1);
  auto store = [&](int j, const internal::LinearSolution& sol) {
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

  if (o.basis == ModalBasis::Discrete) {
    const int ivlag = o.iv_shift > 0 ? samples_of(o.iv_shift, Ts, "iv_shift") : 0;
    internal::StreamingLeastSquares ls(p);
    internal::InstrumentalVariables iv(p);
    Eigen::VectorXd r(p), z(p);
    long long rows = 0;
    for (const auto& s : sw)
      for (int i = s.i0; i <= s.i0 + s.K; i += o.stride) {
        reg(i, r.data());
        if (ivlag > 0) {
          if (i - lag(0) + ivlag >= N) continue;  // the instrument y(t - T_1 + iv_shift) is beyond the record
          reg(i, z.data(), ivlag);
          iv.add(z.data(), r.data(), y(i));
        } else {
          ls.add(r.data(), y(i));
        }
        ++rows;
      }
    CTID_REQUIRE(rows >= p, "modal: {} equations in the validity windows for {} unknowns (n = {} shifts + {} input "
                 "modes); lengthen the windows or reduce the stride", rows, p, n, nc);
    // sum p y(t - T_i) - q x_c = -y: the kernel solves r theta' = y with theta' = -theta.
    store(0, ivlag > 0 ? iv.solve() : ls.solve());
  } else if (o.basis == ModalBasis::Fourier) {
    // The functions run on the concatenation of the windows (local time tau continues from one window to
    // the next, T_o = total length; ES Ex. 3.2): for j = 0 the equation holds pointwise in every window.
    // The c_(j-1) recursion integrates by parts, so j > 0 needs one continuous window.
    const int m = o.functions / 2, F = o.functions;
    CTID_REQUIRE(J == 0 || W == 1, "modal: Fourier derivative orders j > 0 (max_order = {}) need one continuous window "
                 "(got {})", J, W);
    CTID_REQUIRE(F >= p + (J > 0 ? 1 : 0), "modal: {} Fourier functions for {} unknowns (n = {} shifts + {} input modes{})",
                 F, p + (J > 0 ? 1 : 0), n, nc, J > 0 ? " + c" : "");
    int total = 0;
    for (const auto& s : sw) total += s.K;
    const FourierFunctions ff{m, 2 * std::numbers::pi / (total * Ts)};
    Eigen::MatrixXd RF = Eigen::MatrixXd::Zero(F, p);
    Eigen::VectorXd zF = Eigen::VectorXd::Zero(F), f(F);
    Eigen::RowVectorXd row(p);
    int offset = 0;
    for (const auto& s : sw) {
      const Eigen::VectorXd wq = quadrature_weights(s.K, Ts, o.quadrature);
      for (int k = 0; k <= s.K; ++k) {
        ff((offset + k) * Ts, f);
        f *= wq(k);
        reg(s.i0 + k, row.data());
        RF.noalias() += f * row;
        zF += f * y(s.i0 + k);
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
  } else {  // Walsh
    const int NW = o.functions;
    CTID_REQUIRE(NW * W >= p, "modal: {} Walsh equations ({} functions x {} windows) for {} unknowns", NW * W, NW, W, p);
    std::vector<Eigen::MatrixXd> RW(W), Rdiff(W);
    Eigen::MatrixXd A(NW * W, p);
    Eigen::VectorXd b(NW * W);
    for (int w = 0; w < W; ++w) {
      const auto& s = sw[w];
      CTID_REQUIRE(s.K % NW == 0, "modal: window {} has {} sampling periods, not a multiple of the {} Walsh blocks (each "
                   "block must span a whole number of samples)", w + 1, s.K, NW);
      const int kb = s.K / NW;
      const Eigen::VectorXd wq = quadrature_weights(kb, Ts, o.quadrature);
      Eigen::MatrixXd RB = Eigen::MatrixXd::Zero(NW, p);
      Eigen::VectorXd zB = Eigen::VectorXd::Zero(NW);
      Rdiff[w].resize(NW, p);
      Eigen::RowVectorXd row(p);
      for (int blk = 0; blk < NW; ++blk) {
        const int first = s.i0 + blk * kb;
        for (int k = 0; k <= kb; ++k) {
          reg(first + k, row.data());
          RB.row(blk) += wq(k) * row;
          zB(blk) += wq(k) * y(first + k);
        }
        Rdiff[w].row(blk) = reg.row(first) - reg.row(first + kb);  // R_d^- - R_d^+ (left minus right edges)
      }
      RW[w] = walsh_transform(RB);
      A.middleRows(w * NW, NW) = RW[w];
      b.segment(w * NW, NW) = walsh_transform(zB);
    }
    store(0, least_squares(A, b));
    for (int j = 1; j <= J; ++j) {
      // ES 3.37: theta_j = -(R_W^T R_W)^{-1} R_W^T Psi (R_d^- - R_d^+) theta_(j-1).
      const Eigen::VectorXd prev = (Eigen::VectorXd(p) << P.row(j - 1).transpose(), Q.row(j - 1).transpose()).finished();
      for (int w = 0; w < W; ++w) b.segment(w * NW, NW) = walsh_transform(Rdiff[w] * prev);
      store(j, least_squares(A, b));
    }
  }

  res.model = ModalModel(o.shifts, P, Q);
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
  res.fit.n_samples = N;
  res.fit.n_parameters = p;
  res.diagnostics.condition_number = cond(0);
  res.diagnostics.vectors["condition_by_order"] = cond;
  res.diagnostics.scalars["windows"] = W;
  if (cond.maxCoeff() > 1e8)
    res.diagnostics.warnings.push_back(detail::format(
        "modal regression condition number {} > 1e8: spread the shifts (conditioning of psi) or lengthen the windows",
        cond.maxCoeff()));
  res.summary.iterations = 1;
  res.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return res;
}

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
  for (int j = 0; j < n; ++j) r.parameters.names.push_back(detail::format("a{}", j));
  for (int j = 0; j < n; ++j) r.parameters.names.push_back(detail::format("b{}", j));
  r.parameters.values.resize(2 * n);
  for (int j = 0; j < n; ++j) {
    r.parameters.values(j) = r.model.den().coefficient_of_power(j);
    r.parameters.values(n + j) = r.model.num().coefficient_of_power(j);
  }
  r.parameters.std = Eigen::VectorXd::Constant(2 * n, std::numeric_limits<double>::quiet_NaN());
  r.parameters.fixed.assign(2 * n, false);
  // Validation by exact simulation from rest with the generated input (the method's input model).
  Eigen::VectorXd t(data.size());
  for (int i = 0; i < data.size(); ++i) t(i) = data.time(i) - data.t0();
  r.fit = fit_report_or_inf(data.y().col(0), lsim(r.model.to_state_space(), input, t), 2 * n);
  return r;
}

Result<TransferFunction> modal_fit(const IdData& data, int nb, ModalOptions o, const InputGenerator* input) {
  const auto t_start = std::chrono::steady_clock::now();
  o.validate();
  const int n = static_cast<int>(o.shifts.size());
  CTID_REQUIRE(nb >= 1 && nb <= n, "modal_fit: nb = {} numerator coefficients must be in [1, n = {}]", nb, n);
  CTID_REQUIRE(data.nu() == 1 && data.ny() == 1, "modal_fit: needs one input and one output (got {}, {})", data.nu(),
               data.ny());
  if (input) {
    CTID_REQUIRE(nb == n, "modal_fit: Theorem 4.2 estimates all n = {} numerator coefficients (nb = {})", n, nb);
    Result<TransferFunction> r = modal_transfer_function(data, *input, o);
    r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    return r;
  }
  if (o.windows.empty()) {
    // Automatic windows: Walsh blocks must tile each window (trim to a multiple of N sampling periods);
    // the Fourier recursion needs one window (the longest).
    const double Ts = data.ts();
    for (ModalWindow w : piecewise_constant_windows(data, o.shifts(n - 1), Ts)) {
      if (o.basis == ModalBasis::Walsh) w.length = std::floor(w.length / Ts / o.functions + 1e-9) * o.functions * Ts;
      if (w.length > 0) o.windows.push_back(w);
    }
    if (o.basis == ModalBasis::Fourier && o.windows.size() > 1) {
      const auto longest = std::max_element(o.windows.begin(), o.windows.end(),
                                            [](const ModalWindow& a, const ModalWindow& b) { return a.length < b.length; });
      o.windows = {*longest};
    }
  }
  CTID_REQUIRE(!o.windows.empty(), "modal_fit: the input never stays constant long enough after a switch (T_n = {} s, "
               "the largest shift, plus the Walsh blocks): no validity windows", o.shifts(n - 1));
  if (o.basis != ModalBasis::Discrete) o.max_order = std::max(o.max_order, n);
  const Result<ModalModel> m = modal_estimate(data, data.u(), o);
  Result<TransferFunction> r;
  r.diagnostics = m.diagnostics;
  r.diagnostics.scalars["windows"] = static_cast<double>(o.windows.size());
  r.summary = m.summary;
  auto failed = [&](const std::string& why) {
    r.summary.termination = Termination::RankDeficient;
    r.summary.message = why;
    r.fit = fit_report_or_inf(data.y().col(0), Eigen::VectorXd::Constant(data.size(), NAN), n + nb);
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
  // Numerator by linear least squares on the exact responses of s^j / A(s) (j < nb) to the data's input.
  Eigen::MatrixXd X(data.size(), nb);
  for (int j = 0; j < nb; ++j) {
    Eigen::VectorXd num = Eigen::VectorXd::Zero(j + 1);
    num(0) = 1.0;
    X.col(j) = lsim(TransferFunction(Polynomial(num), den), data, 0);
  }
  const internal::LinearSolution sol = least_squares(X, data.y().col(0));
  Eigen::VectorXd numc(nb);
  for (int j = 0; j < nb; ++j) numc(j) = sol.theta(nb - 1 - j);
  r.model = TransferFunction(Polynomial(numc), den);
  for (int j = 0; j < n; ++j) r.parameters.names.push_back(detail::format("a{}", j));
  for (int j = 0; j < nb; ++j) r.parameters.names.push_back(detail::format("b{}", j));
  r.parameters.values.resize(n + nb);
  for (int j = 0; j < n; ++j) r.parameters.values(j) = den.coefficient_of_power(j);
  r.parameters.values.tail(nb) = sol.theta;
  r.parameters.std = Eigen::VectorXd::Constant(n + nb, std::numeric_limits<double>::quiet_NaN());
  r.parameters.std.tail(nb) = sol.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();  // given A(s)
  r.parameters.fixed.assign(n + nb, false);
  if (!r.model.is_stable()) r.diagnostics.warnings.push_back("the estimated model is unstable");
  r.fit = fit_report_or_inf(data.y().col(0), lsim(r.model, data, 0), n + nb);
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return r;
}

Polynomial newton_characteristic_polynomial(const Eigen::MatrixXd& M) {
  CTID_REQUIRE(M.rows() == M.cols() && M.rows() >= 1, "newton_characteristic_polynomial: needs a square matrix (got {}x{})",
               M.rows(), M.cols());
  const int n = static_cast<int>(M.rows());
  Eigen::VectorXd T(n + 1);  // T(k) = trace(M^k)
  Eigen::MatrixXd Mk = Eigen::MatrixXd::Identity(n, n);
  for (int k = 1; k <= n; ++k) {
    Mk = Mk * M;
    T(k) = Mk.trace();
  }
  // c(k) = coefficient of s^{n-k} (c(0) = 1): c_k = -(c_{k-1} T_1 + c_{k-2} T_2 + ... + c_1 T_{k-1} + T_k) / k.
  Eigen::VectorXd c = Eigen::VectorXd::Zero(n + 1);
  c(0) = 1.0;
  for (int k = 1; k <= n; ++k) {
    double s = T(k);
    for (int i = 1; i < k; ++i) s += c(k - i) * T(i);
    c(k) = -s / k;
  }
  return Polynomial(c);
}

namespace {
// Deflate the augmented polynomial by the generator's: least squares on the coefficients of
// P_a = P * P_c with P monic of degree deg(P_a) - deg(P_c) (ES 4.56-4.62).
Polynomial deflate(const Polynomial& Pa, const Polynomial& Pc) {
  const int na = Pa.degree(), ncg = Pc.degree(), n = na - ncg;
  const Eigen::VectorXd pc = Pc.monic().coefficients(), pa = Pa.monic().coefficients();
  // pa = conv([1, x_1..x_n], pc): unknowns x (coefficients of s^{n-1} .. s^0).
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(na + 1, n);
  Eigen::VectorXd b = pa;
  for (int i = 0; i <= ncg; ++i) b(i) -= pc(i);  // the leading 1 times pc
  for (int k = 0; k < n; ++k)
    for (int i = 0; i <= ncg; ++i) A(k + 1 + i, k) += pc(i);
  const Eigen::VectorXd x = A.colPivHouseholderQr().solve(b);
  Eigen::VectorXd c(n + 1);
  c << 1.0, x;
  return Polynomial(c);
}
}  // namespace

void FreeResponseOptions::validate() const {
  CTID_REQUIRE_OPTION(shifts.size() >= 1, "free_response_poles: at least one shift is needed");
  for (Eigen::Index i = 0; i < shifts.size(); ++i)
    for (Eigen::Index k = 0; k < i; ++k)
      CTID_REQUIRE_OPTION(shifts(i) != shifts(k), "free_response_poles: shifts {} and {} are equal ({} s)", k + 1, i + 1,
                          shifts(i));
  CTID_REQUIRE_OPTION(std::isfinite(interval) && interval > 0, "free_response_poles: interval must be > 0 (got {} s)",
                      interval);
  CTID_REQUIRE_OPTION(std::isfinite(spacing) && spacing > 0, "free_response_poles: spacing must be > 0 (got {} s)",
                      spacing);
  CTID_REQUIRE_OPTION(pairs >= shifts.size(), "free_response_poles: {} instant pairs for {} shifts (need at least one "
                      "pair per shift)", pairs, shifts.size());
  CTID_REQUIRE_OPTION(generator.degree() < shifts.size(), "free_response_poles: the generator polynomial has degree {} "
                      "but the augmented order is only {}", generator.degree(), shifts.size());
}

PoleEstimate free_response_poles(const Eigen::VectorXd& y, double Ts, const FreeResponseOptions& o) {
  o.validate();
  CTID_REQUIRE(std::isfinite(Ts) && Ts > 0, "free_response_poles: Ts must be > 0 (got {})", Ts);
  CTID_REQUIRE(y.allFinite(), "free_response_poles: the response has non-finite samples");
  const int n = static_cast<int>(o.shifts.size()), N = static_cast<int>(y.size());
  Eigen::VectorXi lag(n);
  for (int i = 0; i < n; ++i) lag(i) = samples_of(o.shifts(i), Ts, "shift T_" + std::to_string(i + 1));
  const int i0 = samples_of(o.start, Ts, "start"), K = samples_of(o.interval, Ts, "interval"),
            step = samples_of(o.spacing, Ts, "spacing");
  const int last = i0 + (o.pairs - 1) * step + K;
  CTID_REQUIRE(i0 - lag.maxCoeff() >= 0 && last - lag.minCoeff() <= N - 1,
               "free_response_poles: the shifted instants span samples [{}, {}] but the record has samples [0, {}]",
               i0 - lag.maxCoeff(), last - lag.minCoeff(), N - 1);
  const Eigen::VectorXd wq = quadrature_weights(K, Ts, o.quadrature);
  Eigen::MatrixXd Y(n, o.pairs), Z(n, o.pairs);
  for (int k = 0; k < o.pairs; ++k) {
    const int a = i0 + k * step;
    for (int i = 0; i < n; ++i) {
      Y(i, k) = y(a + K - lag(i)) - y(a - lag(i));
      Z(i, k) = wq.dot(y.segment(a - lag(i), K + 1));
    }
  }
  PoleEstimate r;
  const Eigen::MatrixXd ZZ = Z * Z.transpose();
  r.condition = condition_2(ZZ);
  r.lambda = ZZ.transpose().colPivHouseholderQr().solve(Z * Y.transpose()).transpose();  // Y Z^T (Z Z^T)^{-1}
  r.all_poles = Eigen::EigenSolver<Eigen::MatrixXd>(r.lambda, false).eigenvalues();
  r.augmented = newton_characteristic_polynomial(r.lambda);
  r.characteristic = o.generator.degree() > 0 ? deflate(r.augmented, o.generator) : r.augmented;
  r.poles = r.characteristic.degree() > 0 ? r.characteristic.roots() : Eigen::VectorXcd(0);
  if (r.condition > 1e12)
    r.warnings.push_back(detail::format("Z Z^T is nearly singular (condition {}): the response does not excite {} modes "
                                        "in the chosen instants, or the shifts are badly placed", r.condition, n));
  return r;
}

PoleEstimate prony(const Eigen::VectorXd& y, double Ts, const PronyOptions& o) {
  CTID_REQUIRE(std::isfinite(Ts) && Ts > 0, "prony: Ts must be > 0 (got {})", Ts);
  CTID_REQUIRE(o.order >= 1 && o.spacing >= 1 && o.equations >= o.order && o.start >= 0,
               "prony: needs order >= 1, spacing >= 1, equations >= order, start >= 0 (got {}, {}, {}, {})", o.order,
               o.spacing, o.equations, o.start);
  const long long last = o.start + static_cast<long long>(o.order + o.equations - 1) * o.spacing;
  CTID_REQUIRE(last < y.size(), "prony: needs samples up to index {} but the record has {}", last, y.size());
  CTID_REQUIRE(y.allFinite(), "prony: the response has non-finite samples");
  const int n = o.order;
  Eigen::MatrixXd R(o.equations, n);
  Eigen::VectorXd b(o.equations);
  for (int e = 0; e < o.equations; ++e) {
    const int m = e + n;  // y(m) + sum_k p_k y(m - k) = 0
    for (int k = 1; k <= n; ++k) R(e, k - 1) = y(o.start + (m - k) * o.spacing);
    b(e) = -y(o.start + m * o.spacing);
  }
  PoleEstimate r;
  r.condition = condition_2(R.transpose() * R);
  const Eigen::VectorXd pk = R.colPivHouseholderQr().solve(b);
  Eigen::VectorXd c(n + 1);
  c << 1.0, pk;
  const Eigen::VectorXcd z = Polynomial(c).roots();
  const double T = o.spacing * Ts;
  r.poles.resize(n);
  for (int k = 0; k < n; ++k) r.poles(k) = std::log(z(k)) / T;
  // prod (s - s_k), real part (the poles come in conjugate pairs up to round-off).
  Eigen::VectorXcd e = Eigen::VectorXcd::Zero(n + 1);
  e(0) = 1.0;
  for (int k = 0; k < n; ++k)
    for (int i = k + 1; i >= 1; --i) e(i) -= r.poles(k) * e(i - 1);
  r.characteristic = Polynomial(Eigen::VectorXd(e.real()));
  r.all_poles = r.poles;
  r.augmented = r.characteristic;
  r.warnings.push_back(detail::format("Prony: imaginary parts are only determined modulo 2 pi / T = {} rad/s; a mode "
                                      "faster than pi / T = {} rad/s aliases into (-{}, {}]",
                                      2 * std::numbers::pi / T, std::numbers::pi / T, std::numbers::pi / T,
                                      std::numbers::pi / T));
  return r;
}

}  // namespace ctid

namespace ctid {

HarmonicResponse modal_frequency_response(const IdData& data, const ModalModel& model, double period,
                                          const std::vector<int>& harmonics, double window_start, Quadrature rule) {
  CTID_REQUIRE(data.nu() == 1 && data.ny() == 1, "modal_frequency_response: needs one input and one output (got {}, {})",
               data.nu(), data.ny());
  CTID_REQUIRE(data.is_uniform(), "modal_frequency_response: needs uniformly sampled data");
  CTID_REQUIRE(!harmonics.empty(), "modal_frequency_response: no harmonics requested");
  const double Ts = data.ts();
  const int N = data.size();
  const Eigen::VectorXd& T = model.shifts();
  CTID_REQUIRE(window_start >= T.maxCoeff() - 1e-9 * Ts, "modal_frequency_response: the window starts at {} s, before "
               "the largest shift T_n = {} s (the modal functions are not valid yet)", window_start, T.maxCoeff());
  const int i0 = samples_of(window_start, Ts, "window start"), K = samples_of(period, Ts, "period");
  CTID_REQUIRE(K >= 2 && i0 + K <= N - 1, "modal_frequency_response: the window [{} s, {} s] is outside the record "
               "[0, {} s]", window_start, window_start + period, (N - 1) * Ts);
  const Eigen::VectorXd p0 = model.P().row(0).transpose();
  const Eigen::VectorXd u0 = modal_filter(Eigen::VectorXd(data.u().col(0)), Ts, T, p0);
  const Eigen::VectorXd y0 = modal_filter(Eigen::VectorXd(data.y().col(0)), Ts, T, p0);
  const bool held = data.intersample(0) == Intersample::Zoh;
  const Eigen::VectorXd wq = quadrature_weights(K, Ts, rule);
  const double wo = 2 * std::numbers::pi / period;
  const int H = static_cast<int>(harmonics.size());
  HarmonicResponse r;
  r.nu.resize(H, 2);
  r.q.resize(H, 2);
  Eigen::VectorXd w(H);
  Eigen::VectorXcd G(H);
  for (int h = 0; h < H; ++h) {
    const int k = harmonics[h];
    CTID_REQUIRE(k >= 1, "modal_frequency_response: harmonic numbers must be >= 1 (got {})", k);
    const double wk = k * wo;
    double n1 = 0, n2 = 0, q1 = 0, q2 = 0;
    for (int i = 0; i <= K; ++i) {
      const double tau = i * Ts;
      q1 += wq(i) * std::sin(wk * tau) * y0(i0 + i);
      q2 += wq(i) * std::cos(wk * tau) * y0(i0 + i);
      if (held) {
        if (i < K) {  // u_0 is constant on [tau_i, tau_{i+1}): integrate the sinusoids exactly
          n1 += u0(i0 + i) * (std::cos(wk * tau) - std::cos(wk * (tau + Ts))) / wk;
          n2 += u0(i0 + i) * (std::sin(wk * (tau + Ts)) - std::sin(wk * tau)) / wk;
        }
      } else {
        n1 += wq(i) * std::sin(wk * tau) * u0(i0 + i);
        n2 += wq(i) * std::cos(wk * tau) * u0(i0 + i);
      }
    }
    const double det = n1 * n1 + n2 * n2;
    CTID_REQUIRE(det > 1e-24 * (1.0 + q1 * q1 + q2 * q2), "modal_frequency_response: harmonic {} ({} rad/s) is not in "
                 "the filtered input (correlations {}, {})", k, wk, n1, n2);
    r.nu.row(h) << n1, n2;
    r.q.row(h) << q1, q2;
    w(h) = wk;
    G(h) = std::complex<double>(q1 * n1 + q2 * n2, q2 * n1 - q1 * n2) / det;  // ES 5.14
  }
  r.response = FrequencyData(w, G);
  return r;
}

Eigen::MatrixXd modal_delta_l(const Eigen::RowVectorXd& p0) {
  const int n = static_cast<int>(p0.size());
  Eigen::MatrixXd L = Eigen::MatrixXd::Zero(n + 1, n + 1), D = Eigen::MatrixXd::Identity(n + 1, n + 1);
  for (int c = 0; c <= n; ++c)
    for (int r = c; r <= n; ++r) L(r, c) = r == c ? 1.0 : p0(r - c - 1);
  for (int r = 1; r <= n; ++r) D(r, r - 1) = -1.0;
  return D * L;
}

TimeResponse modal_step_response(const IdData& data, const ModalModel& model, double level_period, double horizon) {
  CTID_REQUIRE(data.nu() == 1 && data.ny() == 1, "modal_step_response: needs one input and one output (got {}, {})",
               data.nu(), data.ny());
  CTID_REQUIRE(data.is_uniform(), "modal_step_response: needs uniformly sampled data");
  CTID_REQUIRE(std::isfinite(horizon) && horizon >= 0, "modal_step_response: horizon must be >= 0 (got {} s)", horizon);
  const double Ts = data.ts();
  const int N = data.size(), n = model.order();
  const int m = samples_of(level_period, Ts, "level period");
  CTID_REQUIRE(m >= 1, "modal_step_response: the level period must be > 0 (got {} s)", level_period);
  for (int i = 0; i < n; ++i)
    CTID_REQUIRE(std::abs(model.shifts()(i) - (i + 1) * level_period) <= 1e-9 * level_period,
                 "modal_step_response: shift T_{} = {} s must be {} T = {} s (shifts i T, ES 5.15 ff.)", i + 1,
                 model.shifts()(i), i + 1, (i + 1) * level_period);
  const Eigen::VectorXd u = data.u().col(0);
  const int periods = N / m;
  for (int k = 0; k < periods; ++k)
    for (int r = 1; r < m; ++r)
      CTID_REQUIRE(u(k * m + r) == u(k * m), "modal_step_response: the input changes inside level period {} (at t = {} s); "
                   "it must be constant on [kT, (k+1)T) with T = {} s", k, (k * m + r) * Ts, level_period);
  CTID_REQUIRE(periods - n >= n + 1, "modal_step_response: {} level periods give {} equations for {} unknowns per offset",
               periods, periods - n, n + 1);
  const Eigen::VectorXd p0 = model.P().row(0).transpose();
  const Eigen::VectorXd y0 = modal_filter(Eigen::VectorXd(data.y().col(0)), Ts, model.shifts(), p0);
  Eigen::MatrixXd U(periods - n, n + 1);
  for (int k = n; k < periods; ++k)
    for (int i = 0; i <= n; ++i) U(k - n, i) = u((k - i) * m);
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(U);
  CTID_REQUIRE(qr.rank() == n + 1, "modal_step_response: the input level sequences [u(k) .. u(k-{})] span only {} of {} "
               "dimensions; use more distinct levels", n, qr.rank(), n + 1);
  const Eigen::MatrixXd DL = modal_delta_l(p0.transpose());  // lower triangular, unit diagonal
  CTID_REQUIRE(horizon / Ts <= 1e8, "modal_step_response: horizon {} s is more than 1e8 sampling periods", horizon);
  const int steps = static_cast<int>(std::floor(horizon / Ts + 1e-9));
  const int blocks = std::max(n + 1, steps / m + 1);  // g(s + i T), i = 0..blocks-1
  Eigen::MatrixXd G(m, blocks);
  Eigen::VectorXd rhs(periods - n);
  double q00 = 0;
  for (int r = 0; r < m; ++r) {
    for (int k = n; k < periods; ++k) rhs(k - n) = y0(k * m + r);
    const Eigen::VectorXd g = DL.triangularView<Eigen::Lower>().solve(qr.solve(rhs));
    G.row(r).head(n + 1) = g.transpose();
    double c = g(n);
    for (int i = 1; i <= n; ++i) c += p0(i - 1) * g(n - i);
    q00 += c / m;  // y_0 of a unit step: constant q_00 for t >= nT
  }
  for (int r = 0; r < m; ++r)
    for (int b = n + 1; b < blocks; ++b) {  // ES 5.36-5.37
      double v = q00;
      for (int i = 1; i <= n; ++i) v -= p0(i - 1) * G(r, b - i);
      G(r, b) = v;
    }
  TimeResponse out;
  out.t.resize(steps + 1);
  out.value.resize(steps + 1);
  for (int j = 0; j <= steps; ++j) {
    out.t(j) = j * Ts;
    out.value(j) = G(j % m, j / m);
  }
  return out;
}

ImpulseFromStep modal_impulse_from_step(const TimeResponse& step, const Eigen::VectorXd& T, double To, int functions,
                                        Quadrature rule) {
  const Eigen::Index S = step.t.size();
  CTID_REQUIRE(S >= 3 && step.value.size() == S, "modal_impulse_from_step: needs a step response of >= 3 samples with "
               "one value per time (got {} times, {} values)", S, step.value.size());
  const double h = step.t(1) - step.t(0);
  CTID_REQUIRE(step.t(0) == 0.0 && h > 0, "modal_impulse_from_step: the step response grid must start at t = 0 with a "
               "positive spacing (t0 = {}, spacing {})", step.t(0), h);
  for (Eigen::Index i = 1; i < S; ++i)
    CTID_REQUIRE(std::abs(step.t(i) - i * h) <= 1e-9 * std::max(1.0, i * h), "modal_impulse_from_step: the step response "
                 "grid is not uniform (t[{}] = {}, expected {})", i, step.t(i), i * h);
  CTID_REQUIRE(functions >= 2 && functions % 2 == 0, "modal_impulse_from_step: the number of Fourier functions must be "
               "even and >= 2 (got {})", functions);
  const int n = static_cast<int>(T.size());
  CTID_REQUIRE(n >= 1 && functions >= n + 1, "modal_impulse_from_step: {} Fourier functions for {} unknowns (n shifts + "
               "g(T_o))", functions, n + 1);
  Eigen::VectorXi L(n);  // samples ahead
  for (int i = 0; i < n; ++i) {
    CTID_REQUIRE(T(i) < 0, "modal_impulse_from_step: shift T_{} = {} s must be negative (ES 5.38 ff.)", i + 1, T(i));
    L(i) = -samples_of(T(i), h, "shift T_" + std::to_string(i + 1));
  }
  const int K = samples_of(To, h, "T_o");
  CTID_REQUIRE(K >= 2 && K + L.maxCoeff() <= S - 1, "modal_impulse_from_step: T_o = {} s plus the largest shift {} s "
               "needs the step response up to {} s (it ends at {} s)", To, L.maxCoeff() * h, (K + L.maxCoeff()) * h,
               (S - 1) * h);
  const int m = functions / 2;
  const FourierFunctions ff{m, 2 * std::numbers::pi / To};
  const Eigen::VectorXd wq = quadrature_weights(K, h, rule);
  const Eigen::VectorXd& g = step.value;
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(functions, n);
  Eigen::VectorXd zg = Eigen::VectorXd::Zero(functions), f(functions), ints = Eigen::VectorXd::Zero(n);
  for (int k = 0; k <= K; ++k) {
    ff(k * h, f);
    for (int i = 0; i < n; ++i) {
      R.col(i) += wq(k) * g(k + L(i)) * f;
      ints(i) += wq(k) * g(k + L(i));
    }
    zg += wq(k) * g(k) * f;
  }
  const Eigen::MatrixXd Om = ff.omega();
  const Eigen::VectorXd f0 = ff.at_zero();
  // -int g Df + g(T_o) f(T_o) - g(0) f(0) + sum_i p_1i int g(t - T_i) f = q_10 int f = 0.
  Eigen::MatrixXd A(functions, n + 1);
  A << R, f0;
  const Eigen::VectorXd x = least_squares(A, Om * zg + f0 * g(0)).theta;
  ImpulseFromStep r;
  r.p1 = x.head(n);
  r.g_To = x(n);
  r.q10 = (r.g_To - g(0) + r.p1.dot(ints)) / To;  // ES 5.42
  const Eigen::Index count = S - L.maxCoeff();
  r.impulse.t = step.t.head(count);
  r.impulse.value.resize(count);
  for (Eigen::Index k = 0; k < count; ++k) {
    double v = r.q10;
    for (int i = 0; i < n; ++i) v -= r.p1(i) * g(k + L(i));
    r.impulse.value(k) = v;
  }
  return r;
}

}  // namespace ctid
