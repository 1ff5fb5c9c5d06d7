// ctid internal — see tf_common.hpp.
#include "estimate/transfer_function/tf_common.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cmath>
#include <complex>
#include <string>
#include <utility>
#include <vector>

#include "ctid/core/check.hpp"
#include "ctid/core/types.hpp"
#include "ctid/estimate/svf/lssvf.hpp"
#include "ctid/estimate/transfer_function/srivc.hpp"
#include "ctid/estimate/transfer_function/srivc_auto.hpp"
#include <limits>

#include "ctid/simulate/lsim.hpp"

namespace ctid::tf_detail {

TransferFunction make_tf(const Eigen::VectorXd& a, const Eigen::VectorXd& b, double delay) {
  Eigen::VectorXd den(a.size() + 1);
  den(0) = 1.0;
  den.tail(a.size()) = a;
  return TransferFunction(b, den, delay);
}

Eigen::VectorXd params_of(const TransferFunction& g, const TfOrders& o) {
  Eigen::VectorXd p(o.nf + o.nb);
  for (int i = 1; i <= o.nf; ++i) p(i - 1) = g.den().coefficient_of_power(o.nf - i);
  for (int j = 0; j < o.nb; ++j) p(o.nf + j) = g.num().coefficient_of_power(o.nb - 1 - j);
  return p;
}

TransferFunction tf_of(const Eigen::VectorXd& p, const TfOrders& o, double delay) {
  return make_tf(p.head(o.nf), p.tail(o.nb), delay);
}

double output_error_mse(const TransferFunction& g, const IdData& d) {
  const Eigen::VectorXd yhat = lsim(g, d, 0);
  if (!yhat.allFinite()) return std::numeric_limits<double>::infinity();
  return (d.y().col(0) - yhat).squaredNorm() / double(d.size());
}

std::string poles_text(const TransferFunction& g) {
  std::string s;
  for (const auto& p : g.poles()) {
    char z[64];
    if (p.imag() == 0) std::snprintf(z, sizeof z, "%.6g", p.real());
    else std::snprintf(z, sizeof z, "%.6g%+.6gj", p.real(), p.imag());
    s += (s.empty() ? "" : ", ") + std::string(z);
  }
  return s;
}

double nyquist(const IdData& d) {
  const double h = d.is_uniform() ? d.ts() : d.duration() / std::max(1, d.size() - 1);
  return 3.14159265358979323846 / h;
}

bool pole_beyond_bandwidth(const TransferFunction& g, const IdData& d) {
  const double wn = nyquist(d);
  for (const auto& p : g.poles())
    if (std::abs(p) > 10 * wn) return true;
  return false;
}

Result<TransferFunction> pre_estimate(const IdData& data, int nf, bool equation_error) {
  const IdData d = data.detrend(Detrend::Mean);
  auto good = [](const Result<TransferFunction>& r) { return r.usable() && r.model.is_stable(); };
  // SRIVC first (consistent under output noise); it needs a stable plant and an open loop, so LSSVF (equation
  // error) is the fallback.
  if (!equation_error) try {
    Result<TransferFunction> r;
    if (nf > 0) {
      r = srivc(d, TfOrders{nf, nf, 0});
    } else {
      SrivcAutoOptions o;
      o.try_delay = false;
      r = srivc_auto(d, o);
    }
    if (good(r)) return r;
  } catch (const InvalidArgument&) {
  }
  if (nf > 0 || equation_error) return lssvf(d, TfOrders{nf > 0 ? nf : 2, nf > 0 ? nf : 2, 0});
  Result<TransferFunction> best;
  bool have = false;
  for (int n = 1; n <= 3; ++n) {
    Result<TransferFunction> r = lssvf(d, TfOrders{n, n, 0});
    if (good(r) && std::isfinite(r.fit.bic) && (!have || r.fit.bic < best.fit.bic)) {
      best = std::move(r);
      have = true;
    }
  }
  return have ? best : lssvf(d, TfOrders{2, 2, 0});
}

FitReport frequency_fit(const TransferFunction& g, const Eigen::VectorXd& w, const Eigen::VectorXcd& G, int n_parameters) {
  const Eigen::VectorXcd Gm = g.frequency_response(w);
  const double den = (G.array() - G.mean()).matrix().norm();
  FitReport f;
  f.n_samples = static_cast<int>(G.size());
  f.n_parameters = n_parameters;
  f.mse = (G - Gm).squaredNorm() / static_cast<double>(G.size());
  f.nrmse = den > 0 ? (G - Gm).norm() / den : std::numeric_limits<double>::infinity();
  f.fit_percent = 100.0 * (1.0 - f.nrmse);
  return f;
}

bool warn_poles_beyond_bandwidth(Result<TransferFunction>& r, const IdData& d) {
  const double wn = nyquist(d);
  for (const auto& p : r.model.poles())
    if (std::abs(p) > 10 * wn) {
      r.diagnostics.warnings.push_back(detail::format(
          "a pole at {} rad/s is more than 10 times the Nyquist frequency ({} rad/s): the data cannot resolve it; a "
          "lower order (nf = {}) likely describes them as well",
          std::abs(p), wn, r.model.order() - 1));
      return true;
    }
  return false;
}

// Pooled over the records: RMS of u and y over all samples; w_c from the mean squared derivative of y over every
// record's intervals and the RMS of y about its pooled mean.
TfNormalisation TfNormalisation::of(const internal::RecordRefs& ds) {
  TfNormalisation n;
  double u2 = 0, y2 = 0, ysum = 0, dy2 = 0;
  long long N = 0, intervals = 0;
  for (const IdData& d : ds) {
    const auto y = d.y().col(0), u = d.u().col(0);  // in place
    u2 += u.squaredNorm();
    y2 += y.squaredNorm();
    ysum += y.sum();
    N += y.size();
    for (Eigen::Index k = 1; k < y.size(); ++k) {
      const double dv = (y(k) - y(k - 1)) / (d.time(static_cast<int>(k)) - d.time(static_cast<int>(k - 1)));
      dy2 += dv * dv;
      ++intervals;
    }
  }
  const double ru = std::sqrt(u2 / double(std::max<long long>(1, N))), ry = std::sqrt(y2 / double(std::max<long long>(1, N)));
  if (ru > 0 && std::isfinite(ru)) n.su = ru;
  if (ry > 0 && std::isfinite(ry)) n.sy = ry;
  if (N >= 3 && intervals > 0) {
    const double mean = ysum / double(N);
    double c2 = 0;
    for (const IdData& d : ds) c2 += (d.y().col(0).array() - mean).matrix().squaredNorm();
    const double wc = std::sqrt(dy2 / double(intervals)) / std::sqrt(c2 / double(N));
    if (wc > 0 && std::isfinite(wc)) n.c = 1.0 / wc;
  }
  return n;
}

IdData TfNormalisation::data(const IdData& d) const { return data(d, Eigen::RowVectorXd::Constant(d.nu(), su)); }

IdData TfNormalisation::data(const IdData& d, const Eigen::RowVectorXd& input_scales) const {
  Eigen::MatrixXd u = d.u().array().rowwise() / input_scales.array();
  IdData s = d.is_uniform() ? IdData(std::move(u), d.y() / sy, d.ts() / c, d.t0() / c)
                            : IdData(std::move(u), d.y() / sy, Eigen::VectorXd(d.times() / c));
  for (int i = 0; i < d.nu(); ++i) s.set_intersample(i, d.intersample(i));
  s.set_input_names(d.input_names());
  s.set_output_names(d.output_names());
  return s;
}

double TfNormalisation::factor(const std::string& name, const TfOrders& o) const {
  if (name == "delay") return 1.0 / c;
  if (name.size() < 2 || (name[0] != 'a' && name[0] != 'b')) return 1.0;
  for (size_t i = 1; i < name.size(); ++i)
    if (!std::isdigit(static_cast<unsigned char>(name[i]))) return 1.0;
  const int k = std::stoi(name.substr(1));
  if (name[0] == 'a') return std::pow(c, k);
  return std::pow(c, o.nf - o.nb + 1 + k) * su / sy;
}

TransferFunction TfNormalisation::to_normalised(const TransferFunction& g, const TfOrders& o) const {
  Eigen::VectorXd p = params_of(g, o);
  const std::vector<std::string> names = tf_parameter_names(o);
  for (Eigen::Index i = 0; i < p.size(); ++i) p(i) *= factor(names[static_cast<size_t>(i)], o);
  return tf_of(p, o, g.io_delay() / c);
}

TransferFunction TfNormalisation::from_normalised(const TransferFunction& g, const TfOrders& o) const {
  return TfNormalisation{1.0 / c, 1.0 / su, 1.0 / sy}.to_normalised(g, o);
}

void TfNormalisation::restore(Result<TransferFunction>& r, const TfOrders& o) const {
  Eigen::VectorXd f(r.parameters.size());
  for (int i = 0; i < r.parameters.size(); ++i) f(i) = factor(r.parameters.names[static_cast<size_t>(i)], o);
  restore_common(r.parameters, f, r.fit, r.diagnostics);
  r.model = from_normalised(r.model, o);
}

void TfNormalisation::restore_common(ParameterSet& p, const Eigen::VectorXd& factors, FitReport& fit,
                                     Diagnostics& dg) const {
  const Eigen::VectorXd f = factors.cwiseInverse();
  p.values = p.values.cwiseProduct(f);
  if (p.covariance.rows() == p.size() && p.covariance.cols() == p.size())
    p.covariance = f.asDiagonal() * p.covariance * f.asDiagonal();
  if (p.std.size() == p.size()) p.std = p.std.cwiseProduct(f.cwiseAbs());
  if (dg.has(diagnostic::white_noise_std) && dg.get(diagnostic::white_noise_std).size() == p.size())
    dg.set(diagnostic::white_noise_std, dg.get(diagnostic::white_noise_std).cwiseProduct(f.cwiseAbs()));
  const double v = sy * sy, lv = std::log(v) * fit.n_samples;
  fit.mse *= v;
  fit.fpe *= v;
  fit.aic += lv;
  fit.aicc += lv;
  fit.bic += lv;
  auto scale = [&dg](const auto& key, double factor) {
    if (dg.has(key)) dg.set(key, dg.get(key) * factor);
  };
  scale(diagnostic::delay, c);
  scale(diagnostic::noise_variance, v);
  scale(diagnostic::delay_grid, c);
  scale(diagnostic::delay_grid_mse, v);
  dg.set(diagnostic::time_scale, c);
}

void finish_tf_result(Result<TransferFunction>& r, const IdData& d) {
  if (!r.model.is_stable() && r.summary.succeeded())
    r.diagnostics.warnings.push_back(detail::format("the model is not asymptotically stable (poles {}): its response to "
                                                    "a bounded input can grow without bound",
                                                    poles_text(r.model)));
  check_cancellation(r);
  warn_poles_beyond_bandwidth(r, d);
}

Eigen::Index first_after(const IdData& d, double transient) {
  Eigen::Index k = 0;
  while (k < d.size() && d.time(static_cast<int>(k)) - d.t0() < transient - 1e-12 * std::max(1.0, transient)) ++k;
  return k;
}

std::pair<Eigen::VectorXd, Eigen::VectorXd> pooled_outputs(const TransferFunction& g, const internal::RecordRefs& ds,
                                                           double transient) {
  Eigen::Index total = 0;
  for (const IdData& d : ds) total += d.size() - first_after(d, transient);
  Eigen::VectorXd y(total), sim(total);
  Eigen::Index at = 0;
  for (const IdData& d : ds) {
    const Eigen::Index m = d.size() - first_after(d, transient);
    y.segment(at, m) = d.y().col(0).tail(m);
    if (m == d.size()) lsim_into(g, d, 0, sim.segment(at, m));  // no transient left out: straight into place
    else sim.segment(at, m) = lsim(g, d, 0).tail(m);
    at += m;
  }
  return {std::move(y), std::move(sim)};
}

TransferFunction stabilized(const TransferFunction& tf) {
  if (tf.is_stable()) return tf;
  Eigen::VectorXcd p = tf.poles();
  for (Eigen::Index i = 0; i < p.size(); ++i) {
    if (p(i).real() > 0) p(i) = std::complex<double>(-p(i).real(), p(i).imag());
    else if (p(i).real() == 0) p(i) = std::complex<double>(-1e-6 * std::max(1.0, std::abs(p(i))), p(i).imag());
  }
  return TransferFunction(tf.num(), Polynomial::from_roots(p), tf.io_delay());
}

}  // namespace ctid::tf_detail

namespace ctid::tf_detail {

namespace {
// d root / d coefficient k (descending, leading coefficient index 0) of polynomial c at a simple root x.
Eigen::VectorXcd root_gradient(const Eigen::VectorXd& c, std::complex<double> x) {
  const Eigen::Index n = c.size() - 1;
  std::complex<double> dp = 0;  // P'(x)
  for (Eigen::Index k = 0; k < n; ++k) dp += c(k) * static_cast<double>(n - k) * std::pow(x, static_cast<double>(n - k - 1));
  Eigen::VectorXcd g(c.size());
  for (Eigen::Index k = 0; k <= n; ++k) g(k) = -std::pow(x, static_cast<double>(n - k)) / dp;
  return g;
}
}  // namespace

template <class R>
void check_cancellation(R& r) {
  if (!r.summary.succeeded()) return;
  const ParameterSet& p = r.parameters;
  const Eigen::VectorXd den = r.model.den().coefficients(), num = r.model.num().coefficients();
  const Eigen::Index P = p.size();
  if (P == 0 || p.covariance.rows() != P || !p.covariance.allFinite() || num.size() < 2) return;
  const std::vector<TfCoefficient> map = tf_coefficients(r.model, p);
  if (map.empty()) return;  // another parameterisation
  // Parameter index of each coefficient (-1: not estimated).
  std::vector<int> ia(static_cast<size_t>(den.size()), -1), ib(static_cast<size_t>(num.size()), -1);
  for (size_t i = 0; i < map.size(); ++i)
    if (map[i].poly) (map[i].poly == 'a' ? ia : ib)[static_cast<size_t>(map[i].index)] = static_cast<int>(i);
  const Eigen::VectorXcd poles = r.model.poles(), zeros = r.model.zeros();
  const double fastest = poles.size() ? poles.cwiseAbs().maxCoeff() : 0.0;
  for (const auto& pole : poles)
    for (const auto& zero : zeros) {
      const std::complex<double> d = pole - zero;
      // Only pairs that are close on the model's own scale can cancel (a far, poorly known zero is a
      // coefficient near 0, not a cancellation).
      if (std::abs(d) > 0.5 * std::max({std::abs(pole), std::abs(zero), 0.05 * fastest})) continue;
      // Gradient of d over the parameters, then the 2 x 2 covariance of (Re d, Im d).
      Eigen::MatrixXd J = Eigen::MatrixXd::Zero(2, P);
      const Eigen::VectorXcd gp = root_gradient(den, pole), gz = root_gradient(num, zero);
      for (Eigen::Index k = 0; k < den.size(); ++k)
        if (ia[static_cast<size_t>(k)] >= 0) {
          J(0, ia[static_cast<size_t>(k)]) += gp(k).real();
          J(1, ia[static_cast<size_t>(k)]) += gp(k).imag();
        }
      for (Eigen::Index k = 0; k < num.size(); ++k)
        if (ib[static_cast<size_t>(k)] >= 0) {
          J(0, ib[static_cast<size_t>(k)]) -= gz(k).real();
          J(1, ib[static_cast<size_t>(k)]) -= gz(k).imag();
        }
      const Eigen::Matrix2d S = J * p.covariance * J.transpose();
      double m2;  // squared Mahalanobis distance of d from 0
      const bool real_pair = std::abs(pole.imag()) < 1e-12 && std::abs(zero.imag()) < 1e-12;
      if (real_pair) m2 = S(0, 0) > 0 ? d.real() * d.real() / S(0, 0) : INFINITY;
      else {
        const Eigen::Vector2d v(d.real(), d.imag());
        m2 = S.determinant() > 0 ? v.dot(S.ldlt().solve(v)) : INFINITY;
      }
      const double limit = real_pair ? 6.63 : 9.21;  // chi^2 99 % with 1 or 2 degrees of freedom
      if (m2 < limit) {
        r.summary.termination = Termination::Unidentifiable;
        r.summary.message = detail::format(
            "the pole {} and the zero {} cancel (their distance {} is within its 99 % confidence region): the model "
            "order is higher than the data support; reduce nf and nb",
            pole, zero, std::abs(d));
        return;
      }
    }
}

template void check_cancellation(Result<TransferFunction>&);

}  // namespace ctid::tf_detail
