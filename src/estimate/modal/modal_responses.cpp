// El-Shafey (1987): nonparametric responses from modal functions — frequency response at the harmonics of a
// periodic input (ES-C10, ES 5.14), step and impulse responses (ES-C11, C12, ES 5.30-5.42).
#include "ctid/estimate/modal/modal.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

#include "ctid/core/check.hpp"
#include "ctid/signal/modal_filter.hpp"
#include "estimate/modal/modal_common.hpp"

namespace ctid {

using namespace modal_detail;

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

template <>
const OptionTable<ModalResponseOptions>& option_table<ModalResponseOptions>() {
  using O = ModalResponseOptions;
  static const OptionTable<O> t =
      OptionTable<O>("modal_response")
          .real("period", &O::period, "s", above(0),
                "level period of a piecewise-constant input (step, impulse) or the input period (frequency); required")
          .real("horizon", &O::horizon, "s", or_special(above(0), 0, "10 period (order + 1)"),
                "step/impulse: length of the response")
          .reals("harmonics", &O::harmonics, "", at_least(1), "frequency: harmonics k of 2 pi / period (none: 1,3,5,7,9)")
          .real("window_start", &O::window_start, "s", or_special(at_least(0), -1, "the largest shift"),
                "frequency: start of the one-period window");
  return t;
}

void ModalResponseOptions::validate() const {
  option_table<ModalResponseOptions>().check(*this);
  for (Eigen::Index i = 0; i < harmonics.size(); ++i)
    CTID_REQUIRE_OPTION(harmonics(i) == std::round(harmonics(i)) && harmonics(i) <= 1e6,
                        "modal_response: harmonic {} is not a whole number (got {})", i + 1, harmonics(i));
}

ModalResponse modal_response(const IdData& d, int order, ResponseKind kind, const ModalResponseOptions& o,
                             const ModalOptions& modal) {
  CTID_REQUIRE_OPTION(o.period > 0, "modal_response: give the period (period=SECONDS: the level period for step and "
                      "impulse responses, the input period for the frequency response)");
  o.validate();
  CTID_REQUIRE_OPTION(order >= 1, "modal_response: the order must be >= 1 (got {})", order);
  CTID_REQUIRE(d.nu() == 1 && d.ny() == 1, "modal_response: one input and one output (got {} and {})", d.nu(), d.ny());
  const double Ts = d.ts();
  ModalResponse r;
  r.kind = kind;
  r.modal = modal;
  ModalOptions& mo = r.modal;
  if (mo.shifts.size() == 0) {
    mo.shifts.resize(order);
    const double base = kind == ResponseKind::Frequency ? std::round(o.period / (order + 1) / Ts) * Ts : o.period;
    for (int i = 0; i < order; ++i) mo.shifts(i) = (i + 1) * base;
  }
  CTID_REQUIRE_OPTION(mo.shifts.size() == order, "modal_response: {} shifts for order {}", mo.shifts.size(), order);
  if (!mo.basis) mo.basis = ModalBasis::Discrete;
  mo.max_order = 0;
  const double Tn = mo.shifts.maxCoeff();
  if (mo.windows.empty()) mo.windows = piecewise_constant_windows(d, Tn, Ts);
  CTID_REQUIRE(!mo.windows.empty(),
               "modal_response: the input never stays constant for longer than T_n = {} s: no validity windows", Tn);
  r.p0 = modal_estimate(d, d.u(), mo);
  if (kind == ResponseKind::Frequency) {
    std::vector<int> h;
    if (o.harmonics.size() == 0) h = {1, 3, 5, 7, 9};
    for (Eigen::Index i = 0; i < o.harmonics.size(); ++i) h.push_back(static_cast<int>(o.harmonics(i)));
    r.frequency = modal_frequency_response(d, r.p0.model, o.period, h, o.window_start >= 0 ? o.window_start : Tn,
                                           mo.quadrature);
    return r;
  }
  const double horizon = o.horizon > 0 ? o.horizon : 10 * o.period * (order + 1);
  r.time = modal_step_response(d, r.p0.model, o.period, horizon);
  if (kind == ResponseKind::Impulse) {
    // Negative shifts -T_i and Fourier functions on the first half of the horizon (ES 5.38-5.42).
    const double To = std::floor((horizon - Tn) / 2 / Ts) * Ts;
    r.time = modal_impulse_from_step(r.time, -mo.shifts, To, std::max(6, 2 * ((order + 2) / 2)), mo.quadrature).impulse;
  }
  return r;
}

}  // namespace ctid
