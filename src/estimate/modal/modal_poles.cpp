// El-Shafey (1987): poles from a free-response data matrix with Newton's characteristic polynomial and the
// deflation by a known generator (ES-C9, ES 4.50-4.62), and Prony's method for comparison.
#include "ctid/estimate/modal/modal.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <optional>

#include "ctid/core/check.hpp"
#include "estimate/modal/modal_common.hpp"

namespace ctid {

using namespace modal_detail;

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
  r.condition = internal::condition_number(ZZ);
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
  r.condition = internal::condition_number(R.transpose() * R);
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

namespace {
// Shifts of compare_poles left empty: T_i = i d by choose_modal_shifts on Prony's estimate of the augmented order.
// The response's active part is where |y| is still at least 5 % of its peak (a free response decays into noise;
// a forced one is active throughout): Prony's sample spacing is the one of least cond(R^T R) with n' spacings
// within half of it (a geometric grid), and T_n' is at most half of it, so that the instants keep the signal.
Eigen::VectorXd automatic_pole_shifts(const Eigen::VectorXd& y, double Ts, int n, std::vector<std::string>& choices) {
  const int N = static_cast<int>(y.size());
  const double peak = y.cwiseAbs().maxCoeff();
  CTID_REQUIRE(peak > 0, "poles: the response is zero throughout; no pole can be estimated");
  int active = N;
  while (active > 1 && std::abs(y(active - 1)) < 0.05 * peak) --active;
  const int half = active / 2;
  CTID_REQUIRE(half >= 2 * n,
               "poles: no room for {} automatic shifts: the response stays above 5 % of its peak for {} samples only "
               "(need >= {}); give the shifts",
               n, active, 4 * n);
  std::optional<PoleEstimate> best;
  PronyOptions best_options;
  for (int k = 1; k * n <= half; k = std::max(k + 1, static_cast<int>(std::lround(k * 1.25)))) {
    PronyOptions p;
    p.order = n;
    p.spacing = k;
    p.equations = (N - 1) / k - n + 1;
    if (p.equations < 2 * n) break;
    PoleEstimate e = prony(y, Ts, p);
    if (std::isfinite(e.condition) && (!best || e.condition < best->condition)) {
      best = std::move(e);
      best_options = p;
    }
  }
  CTID_REQUIRE(best.has_value(), "poles: Prony's pre-estimate failed at every spacing; give the shifts");
  const TransferFunction prior(Polynomial{1.0}, best->characteristic);
  const ShiftChoice sc = choose_modal_shifts(prior, Ts, half * Ts);
  const double d = sc.shifts(0);
  choices.push_back(detail::format(
      "shifts = i * {} s (i = 1..{}; {} samples apart): the spacing that minimises cond(psi) (= {}) of Prony's "
      "pre-estimate {} (samples {} apart, the best conditioned), T_n at most half the time the response stays above "
      "5 % of its peak ({} s)",
      detail::significant(d), n, std::lround(d / Ts), detail::significant(sc.condition, 3),
      best->characteristic.to_string("s", 4), best_options.spacing, detail::significant(half * Ts)));
  return sc.shifts;
}
}  // namespace

template <>
const OptionTable<PolesOptions>& option_table<PolesOptions>() {
  using O = PolesOptions;
  static const OptionTable<O> t =
      OptionTable<O>("poles")
          .reals("shifts", &O::shifts, "s", above(0),
                 "T_1..T_n', one per pole of the system and of the generator, whole multiples of Ts (the CLI also takes "
                 "shift_samples); empty: uniform shifts chosen on Prony's pre-estimate")
          .real("start", &O::start, "s", or_special(above(0), 0, "the largest shift"), "first instant t_o1")
          .real("interval", &O::interval, "s", or_special(above(0), 0, "the first shift, at least 2 Ts"),
                "integration interval t_fk - t_ok")
          .real("spacing", &O::spacing, "s", or_special(above(0), 0, "the interval"), "t_o(k+1) - t_ok")
          .integer("pairs", &O::pairs, "", or_special(at_least(1), 0, "as many as the record holds"), "instant pairs")
          .choice("quadrature", &O::quadrature, {{"simpson", Quadrature::Simpson}, {"trapezoid", Quadrature::Trapezoid}},
                  "integration rule")
          .reals("generator", &O::generator, "rad/s", at_least(0),
                 "frequencies of a known generated input (0 = constant); the augmented estimate is deflated by them")
          .real("prony_spacing", &O::prony_spacing, "s", or_special(above(0), 0, "the first shift"),
                "spacing of Prony's samples")
          .integer("prony_equations", &O::prony_equations, "", or_special(at_least(1), 0, "as many as the record holds"),
                   "Prony's equations")
          .real("prony_start", &O::prony_start, "s", at_least(0), "time of Prony's first sample");
  return t;
}

void PolesOptions::validate() const { option_table<PolesOptions>().check(*this); }

PolesComparison compare_poles(const Eigen::VectorXd& y, double Ts, int order, const PolesOptions& o) {
  o.validate();
  CTID_REQUIRE(std::isfinite(Ts) && Ts > 0, "poles: Ts must be > 0 (got {})", Ts);
  CTID_REQUIRE_OPTION(order >= 1, "poles: the order must be >= 1 (got {})", order);
  InputGenerator g;
  for (Eigen::Index i = 0; i < o.generator.size(); ++i)
    g = g + (o.generator(i) == 0 ? InputGenerator::constant(1.0) : InputGenerator::sinusoid(o.generator(i), 1.0));
  const int n_aug = order + g.order();
  CTID_REQUIRE_OPTION(o.shifts.size() == 0 || o.shifts.size() == n_aug, "poles: {} shifts; order {}{} needs {}",
                      o.shifts.size(), order, g.order() ? " plus the generator's modes" : "", n_aug);
  CTID_REQUIRE(y.allFinite(), "poles: the response has non-finite samples");
  const int N = static_cast<int>(y.size());
  PolesComparison c;
  const Eigen::VectorXd shifts = o.shifts.size() ? o.shifts : automatic_pole_shifts(y, Ts, n_aug, c.choices);
  auto samples = [&](double seconds, const char* what) { return modal_detail::samples_of(seconds, Ts, what); };
  int max_shift = 0;
  for (int i = 0; i < n_aug; ++i) max_shift = std::max(max_shift, samples(shifts(i), "shift"));
  const int first = samples(shifts(0), "shift");
  const int interval = o.interval > 0 ? samples(o.interval, "interval") : std::max(2, first);
  const int spacing = o.spacing > 0 ? samples(o.spacing, "spacing") : interval;
  const int start = o.start > 0 ? samples(o.start, "start") : max_shift;
  c.free_response.shifts = shifts;
  c.free_response.start = start * Ts;
  c.free_response.interval = interval * Ts;
  c.free_response.spacing = spacing * Ts;
  c.free_response.pairs = o.pairs > 0 ? o.pairs : (N - 1 - start - interval) / spacing + 1;
  c.free_response.quadrature = o.quadrature;
  if (g.order()) c.free_response.generator = g.characteristic_polynomial();
  c.data_matrix = free_response_poles(y, Ts, c.free_response);
  PronyOptions& p = c.prony_options;
  p.order = n_aug;
  p.spacing = o.prony_spacing > 0 ? samples(o.prony_spacing, "prony_spacing") : first;
  p.start = samples(o.prony_start, "prony_start");
  p.equations = o.prony_equations > 0 ? o.prony_equations : (N - 1 - p.start) / std::max(1, p.spacing) - n_aug + 1;
  try {
    c.prony = prony(y, Ts, p);
  } catch (const InvalidArgument& e) {
    c.prony_problem = e.what();
  }
  return c;
}

}  // namespace ctid
