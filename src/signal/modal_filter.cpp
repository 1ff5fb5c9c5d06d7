// El-Shafey (1987) modal filters and annihilators (ES 2.26-2.45, 3.38-3.47): see
// include/ctid/signal/modal_filter.hpp.
#include "ctid/signal/modal_filter.hpp"

#include <cmath>

#include <unsupported/Eigen/MatrixFunctions>

#include "ctid/core/check.hpp"

namespace ctid {

Eigen::VectorXd quadrature_weights(int intervals, double h, Quadrature rule) {
  CTID_REQUIRE(intervals >= 1, "quadrature_weights: needs at least one interval (got {})", intervals);
  CTID_REQUIRE(std::isfinite(h) && h > 0, "quadrature_weights: step must be > 0 (got {})", h);
  Eigen::VectorXd w = Eigen::VectorXd::Zero(intervals + 1);
  if (rule == Quadrature::Trapezoid || intervals == 1) {
    w.setConstant(h);
    w(0) = w(intervals) = h / 2;
    return w;
  }
  const int simpson = intervals % 2 == 0 ? intervals : intervals - 3;  // even part; 3/8 rule on the rest
  for (int i = 0; i + 2 <= simpson; i += 2) {
    w(i) += h / 3;
    w(i + 1) += 4 * h / 3;
    w(i + 2) += h / 3;
  }
  if (simpson != intervals) {
    const int i = simpson;
    w(i) += 3 * h / 8;
    w(i + 1) += 9 * h / 8;
    w(i + 2) += 9 * h / 8;
    w(i + 3) += 3 * h / 8;
  }
  return w;
}

Eigen::VectorXi shift_lags(const Eigen::VectorXd& shifts, double Ts) {
  CTID_REQUIRE(std::isfinite(Ts) && Ts > 0, "modal filter: the sampling period must be > 0 (got {})", Ts);
  Eigen::VectorXi lags(shifts.size());
  for (Eigen::Index i = 0; i < shifts.size(); ++i) {
    const double r = shifts(i) / Ts;
    CTID_REQUIRE(std::isfinite(r) && std::abs(r) <= 1e9 && std::abs(r - std::round(r)) <= 1e-9 * std::max(1.0, std::abs(r)),
                 "modal filter: shift {} = {} s is not a whole multiple of the sampling period {} s ({} periods)",
                 i + 1, shifts(i), Ts, r);
    lags(i) = static_cast<int>(std::lround(r));
  }
  return lags;
}

Eigen::VectorXd modal_filter(const Eigen::VectorXd& y, double Ts, const Eigen::VectorXd& shifts,
                             const Eigen::VectorXd& weights, double lead) {
  CTID_REQUIRE(shifts.size() == weights.size(), "modal_filter: {} shifts but {} weights", shifts.size(), weights.size());
  CTID_REQUIRE(y.allFinite() && weights.allFinite() && std::isfinite(lead), "modal_filter: non-finite values");
  const Eigen::VectorXi lag = shift_lags(shifts, Ts);
  const Eigen::Index N = y.size();
  Eigen::VectorXd out = lead * y;
  for (Eigen::Index k = 0; k < lag.size(); ++k) {
    const Eigen::Index L = lag(k);
    for (Eigen::Index i = std::max<Eigen::Index>(0, L); i < std::min(N, N + L); ++i) out(i) += weights(k) * y(i - L);
  }
  return out;
}

IdData modal_filter(const IdData& data, const Eigen::VectorXd& shifts, const Eigen::VectorXd& weights, double lead) {
  CTID_REQUIRE(data.is_uniform(), "modal_filter: needs uniformly sampled data");
  Eigen::MatrixXd u(data.size(), data.nu()), y(data.size(), data.ny());
  for (int k = 0; k < data.nu(); ++k) u.col(k) = modal_filter(Eigen::VectorXd(data.u().col(k)), data.ts(), shifts, weights, lead);
  for (int k = 0; k < data.ny(); ++k) y.col(k) = modal_filter(Eigen::VectorXd(data.y().col(k)), data.ts(), shifts, weights, lead);
  IdData out(u, y, data.ts(), data.t0());
  for (int k = 0; k < data.nu(); ++k) out.set_intersample(k, data.intersample(k));
  out.set_input_names(data.input_names());
  out.set_output_names(data.output_names());
  out.set_input_units(data.input_units());
  out.set_output_units(data.output_units());
  return out;
}

InputGenerator modal_filter(const InputGenerator& g, const Eigen::VectorXd& shifts, const Eigen::VectorXd& weights,
                            double lead) {
  CTID_REQUIRE(shifts.size() == weights.size(), "modal_filter: {} shifts but {} weights", shifts.size(), weights.size());
  Eigen::VectorXd c = lead * g.c();
  for (Eigen::Index k = 0; k < shifts.size(); ++k)
    c += weights(k) * (Eigen::MatrixXd(-g.A().transpose() * shifts(k)).exp() * g.c());
  return InputGenerator(g.A(), c, g.x0());
}

Eigen::VectorXd annihilator(const InputGenerator& g, const Eigen::VectorXd& shifts) {
  // ES-C1 applied to the generator: psi_c rows c^T e^{-A T_i}, l = -c^T psi_c^{-1}.
  const int nc = g.order();
  CTID_REQUIRE(shifts.size() == nc, "annihilator: {} shifts for a generator of order {} (one per mode)", shifts.size(), nc);
  const StateSpace s(g.A(), Eigen::MatrixXd::Zero(nc, 1), g.c().transpose(), Eigen::MatrixXd::Zero(1, 1));
  return modal_parameters(s, shifts, 0).P.row(0).transpose();
}

}  // namespace ctid
