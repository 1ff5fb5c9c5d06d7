// Stage 1 of Gawthrop & Wang (2005): FSF compression; see include/ctid/estimate/fsf/fsf.hpp.
#include "ctid/estimate/fsf/fsf.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <complex>
#include <numbers>
#include <vector>

#include <unsupported/Eigen/FFT>

#include "ctid/core/check.hpp"
#include "ctid/model/state_space.hpp"
#include "ctid/model/transfer_function.hpp"
#include "ctid/simulate/lsim.hpp"
#include "ctid/validate/metrics.hpp"
#include "estimate/transfer_function/tf_common.hpp"
#include "internal/least_squares.hpp"

namespace ctid {

using cd = std::complex<double>;

template <>
const OptionTable<FsfOptions>& option_table<FsfOptions>() {
  using O = FsfOptions;
  static const OptionTable<O> t =
      OptionTable<O>("fsf")
          .real("T", &O::T, "s", or_special(above(0), 0, "automatic"),
                "window: settling time of the (shifted) system, rounded to whole sampling periods; 0: a pre-estimate's")
          .integer("n", &O::n, "", or_special(at_least(1), 0, "automatic"),
                   "number of frequency-sampling filters, odd, <= T/Ts; 0: to cover a pre-estimate's bandwidth")
          .real("a", &O::a, "1/s", at_least(0),
                "exponential window e^{-at}; > every unstable pole's real part; 0 and unstable: chosen")
          .real("b", &O::b, "1/s", at_least(0), "residual weighting e^{bt}, <= a (b > 0 is risky, see the method page)")
          .reals("weights", &O::weights, "", at_least(0), "per-sample residual weights; none: 1")
          .flag("unstable", &O::unstable, "the plant is unstable: then the window a must be > 0");
  return t;
}

void FsfOptions::validate() const {
  option_table<FsfOptions>().check(*this);
  CTID_REQUIRE_OPTION(n == 0 || n % 2 == 1, "fsf: the number of filters n must be odd and >= 1, or 0: automatic (got {})", n);
  CTID_REQUIRE_OPTION(b <= a, "fsf: b = {} must not exceed a = {} (e^{(b-a)t} must not grow)", b, a);
}

FsfOptions fsf_settings(const IdData& data, const FsfOptions& given, std::vector<std::string>* choices) {
  given.validate();
  require_io_data(data, "fsf");
  CTID_REQUIRE(data.is_uniform(), "fsf: needs uniformly sampled data");
  FsfOptions o = given;
  const double Ts = data.ts(), duration = data.size() * Ts;
  const int M = data.size();
  auto note = [&](std::string line) {
    if (choices) choices->push_back(std::move(line));
  };
  if (o.T > 0) {  // a given window: whole sampling periods
    const double Nd = o.T / Ts;
    CTID_REQUIRE(Nd <= 1e9, "fsf: T = {} s is more than 1e9 sampling periods of {} s", o.T, Ts);
    const long long N = std::max(1LL, std::llround(Nd));
    if (std::abs(Nd - N) > 1e-9 * std::max(1.0, Nd)) {
      note(detail::format("T = {} s (N = {}): the given {} s rounded to whole sampling periods of {} s", N * Ts, N, o.T, Ts));
      o.T = N * Ts;
    }
  }
  // The pre-estimate, when anything is automatic.
  const bool auto_a = o.a == 0 && o.unstable;
  if (o.T > 0 && o.n > 0 && !auto_a) return o;
  Result<TransferFunction> pre;
  try {
    pre = tf_detail::pre_estimate(data, 0, o.unstable);
  } catch (const InvalidArgument& e) {
    CTID_REQUIRE(false, "fsf: no pre-estimate for the automatic settings ({}); give T, n (and a) with the options",
                 e.what());
  }
  const TransferFunction& g = pre.model;
  const std::string source = detail::format("pre-estimate {}", g.to_string(4));
  double max_re = -INFINITY;
  for (const auto& p : g.poles()) max_re = std::max(max_re, p.real());
  if (o.a == 0 && (o.unstable || max_re >= 0)) {
    o.a = std::max(1.5 * std::max(max_re, 0.0), 20.0 / duration);
    note(detail::format("a = {} 1/s: the window of {}, 1.5 times the largest real part {} of the {}'s poles (at least "
                        "20 / record duration){}",
                        detail::significant(o.a), o.unstable ? "a plant declared unstable" : "an unstable or integrating pre-estimate", detail::significant(max_re),
                        source, max_re < 0 ? "; it has no unstable pole although the plant is declared unstable: check a" : ""));
  }
  if (o.T == 0) {
    double settle = 0;
    try {
      settle = fsf_settling_time(g, o.a, 1e-3, duration);
    } catch (const InvalidArgument&) {
      CTID_REQUIRE(false, "fsf: the window a = {} does not stabilise the pre-estimate (poles {}); give a larger a", o.a,
                   tf_detail::poles_text(g));
    }
    long long N = std::max(3LL, static_cast<long long>(std::ceil(settle / Ts - 1e-9)));
    std::string why = detail::format("settling time (impulse response below 1e-3 of its peak) of the {}{}", source,
                                     o.a > 0 ? ", shifted by a = " + detail::significant(o.a) : std::string());
    if (N > M / 2) {
      N = std::max(3, M / 2);
      why += detail::format("; limited to half the record: the record ({} s) is shorter than twice the settling time "
                            "({} s), so late parts of the response are cut off — a longer record or a window a > 0 helps",
                            detail::significant(duration), detail::significant(settle));
    }
    o.T = N * Ts;
    note(detail::format("T = {} s (N = {}): {}", detail::significant(o.T), N, why));
  }
  if (o.n == 0) {
    const long long N = std::llround(o.T / Ts);
    // The frequency where |G(a + jw)| has fallen to 3 % of its largest value on [0, Nyquist].
    const double w_nyq = std::numbers::pi / Ts, w_1 = 2 * std::numbers::pi / o.T;
    const int K = 400;
    std::vector<double> w(K + 1), mag(K + 1);
    w[0] = 0;
    double peak = 0;
    for (int k = 0; k <= K; ++k) {
      if (k > 0) w[k] = w_1 * 0.1 * std::pow(10 * w_nyq / w_1, double(k - 1) / (K - 1));
      mag[k] = std::abs(g(std::complex<double>(o.a, w[k])));
      peak = std::max(peak, mag[k]);
    }
    double wc = w_nyq;
    for (int k = K; k >= 0; --k)
      if (mag[k] > 0.03 * peak) {
        wc = std::min(w_nyq, k < K ? w[k + 1] : w[K]);
        break;
      }
    const long long m_band = static_cast<long long>(std::ceil(wc / w_1));
    const long long cap = std::min<long long>({101, N % 2 ? N : N - 1, std::max(3, M / 10) | 1});
    o.n = static_cast<int>(std::max<long long>(std::min<long long>(2 * m_band + 1, cap), std::min<long long>(3, cap)));
    note(detail::format("n = {}: filter frequencies up to {} rad/s, where |G(a + jw)| of the {} has fallen to 3 % of "
                        "its peak{}",
                        o.n, detail::significant((o.n - 1) / 2 * w_1), source, 2 * m_band + 1 > cap ? detail::format(" (limited to {})", cap) : std::string()));
  }
  return o;
}

namespace {
// Model, named parameters and covariance of an FSF least-squares solution.
Result<FsfModel> fsf_result(const internal::LinearSolution& sol, double Ts, int N, int n, double a) {
  Result<FsfModel> r;
  r.model = FsfModel(Ts, N, n, sol.theta, sol.covariance, a);
  r.parameters.names.push_back("theta0");
  for (int k = 1; k <= (n - 1) / 2; ++k) {
    r.parameters.names.push_back("re_theta" + std::to_string(k));
    r.parameters.names.push_back("im_theta" + std::to_string(k));
  }
  r.parameters.values = sol.theta;
  r.parameters.set_covariance(sol.covariance);
  r.parameters.fixed.assign(n, false);
  r.diagnostics.condition_number = sol.condition;
  r.diagnostics.set(diagnostic::fsf_N, N);
  r.diagnostics.set(diagnostic::fsf_a, a);
  return r;
}
}  // namespace

Result<FsfModel> fsf(const IdData& data, const FsfOptions& given) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::string> choices;
  const FsfOptions o = fsf_settings(data, given, &choices);
  const double Ts = data.ts();
  const int M = data.size();
  CTID_REQUIRE(o.T / Ts <= M + 0.5, "fsf: T = {} s ({} samples) is longer than the record ({} samples, {} s)", o.T,
               std::llround(o.T / Ts), M, M * Ts);
  const int N = static_cast<int>(std::lround(o.T / Ts));
  CTID_REQUIRE(o.n <= N, "fsf: n = {} filters exceed N = T/Ts = {}", o.n, N);
  CTID_REQUIRE(o.a * o.T <= 300, "fsf: a*T = {} is too large (a = {}, T = {} s): the window e^(-aT) would leave "
               "nothing of the record after the first T seconds; choose a <= {}", o.a * o.T, o.a, o.T, 300 / o.T);
  CTID_REQUIRE(o.weights.size() == 0 || o.weights.size() == M, "fsf: {} weights for {} samples", o.weights.size(), M);
  const int m = (o.n - 1) / 2, p = o.n;
  CTID_REQUIRE(M > p, "fsf: {} samples cannot determine {} parameters", M, p);
  const Eigen::VectorXd u = data.u().col(0), y = data.y().col(0);

  // Regressors by exact FIR summation with shared partial sums (the van Herk / Gil-Werman sliding
  // window): the record is cut into chunks of N samples; the window (i-N, i] of output i = cN + j is the
  // suffix (j, N) of chunk c-1 plus the prefix [0, j] of chunk c, so every regressor is a sum of two
  // partial sums of its own N terms. Nothing is subtracted or carried from chunk to chunk, so the
  // round-off is that of direct N-term summation (no recursion on the unit circle, GW 2), at O(n) per
  // sample. With p = i - l, the filter weight e^{a l Ts} W^{k l} / N (W = e^{j 2 pi / N}) factors as
  // e^{a Ts (i - chunk start)} W^{k i} / N times e^{-a Ts (p - chunk start)} W^{-k p}, all bounded by e^{2aT}.
  const double aTs = o.a * Ts, cTs = (o.b - o.a) * Ts;
  std::vector<double> E(N), G0(N), G1(N), C(N);
  std::vector<double> twr(static_cast<size_t>(m + 1) * N), twi(twr.size());
  for (int j = 0; j < N; ++j) {
    E[j] = std::exp(-aTs * j);
    G0[j] = std::exp(aTs * j);
    G1[j] = std::exp(aTs * (N + j));
    C[j] = std::exp(cTs * j);
    for (int k = 0; k <= m; ++k) {
      const double phi = 2.0 * std::numbers::pi * static_cast<double>((static_cast<long long>(k) * j) % N) / N;
      twr[static_cast<size_t>(k) * N + j] = std::cos(phi);
      twi[static_cast<size_t>(k) * N + j] = -std::sin(phi);  // W^{-k j}
    }
  }
  const size_t K = static_cast<size_t>(m + 1);
  std::vector<double> xr(K * N), xi(K * N), pre_r(K * N), pre_i(K * N), suf_r(K * (N + 1)), suf_i(K * (N + 1));
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rows(N, p);
  auto pass = [&](auto& kernel) {
    std::fill(suf_r.begin(), suf_r.end(), 0.0);  // zero input before the record
    std::fill(suf_i.begin(), suf_i.end(), 0.0);
    for (int c0 = 0; c0 < M; c0 += N) {
      const int len = std::min(N, M - c0);
      const double cbase = std::exp(cTs * c0) / N;  // e^{(b-a)(t_{c0} - t0)} / N
      for (size_t k = 0; k < K; ++k) {
        double* a_r = &xr[k * N];
        double* a_i = &xi[k * N];
        const double* wr = &twr[k * N];
        const double* wi = &twi[k * N];
        for (int j = 0; j < len; ++j) {
          const double v = E[j] * u(c0 + j);
          a_r[j] = v * wr[j];
          a_i[j] = v * wi[j];
        }
        double* pr = &pre_r[k * N];
        double* pi = &pre_i[k * N];
        double sr = 0, si = 0;
        for (int j = 0; j < len; ++j) {
          sr += a_r[j];
          si += a_i[j];
          pr[j] = sr;
          pi[j] = si;
        }
        const double* qr = &suf_r[k * (N + 1)];
        const double* qi = &suf_i[k * (N + 1)];
        for (int j = 0; j < len; ++j) {
          const double g1 = cbase * C[j] * G1[j], g0 = cbase * C[j] * G0[j];
          const double s_r = g1 * qr[j + 1] + g0 * pr[j], s_i = g1 * qi[j + 1] + g0 * pi[j];
          // out = conj(W^{-k j}) s;  regressors Re(out) (k = 0), 2 Re(out), -2 Im(out)
          const double o_r = wr[j] * s_r + wi[j] * s_i, o_i = wr[j] * s_i - wi[j] * s_r;
          if (k == 0) {
            rows(j, 0) = o_r;
          } else {
            rows(j, 2 * k - 1) = 2.0 * o_r;
            rows(j, 2 * k) = -2.0 * o_i;
          }
        }
      }
      for (int j = 0; j < len; ++j) {
        const int i = c0 + j;
        kernel.add(rows.row(j).data(), cbase * N * C[j] * y(i), o.weights.size() ? o.weights(i) : 1.0);
      }
      // Suffix sums of this chunk for the next one (a partial last chunk is never needed again).
      for (size_t k = 0; k < K; ++k) {
        double* qr = &suf_r[k * (N + 1)];
        double* qi = &suf_i[k * (N + 1)];
        double sr = 0, si = 0;
        for (int j = len - 1; j >= 0; --j) {
          sr += xr[k * N + j];
          si += xi[k * N + j];
          qr[j] = sr;
          qi[j] = si;
        }
      }
    }
  };
  internal::GramLeastSquares gram(p);
  pass(gram);
  internal::LinearSolution sol = gram.solve();
  if (!(sol.condition < internal::kGramConditionLimit)) {
    // Ill-conditioned (e.g. n close to N with little excitation): blocked QR in a second pass.
    internal::StreamingLeastSquares ls(p);
    pass(ls);
    sol = ls.solve();
  }

  Result<FsfModel> r = fsf_result(sol, Ts, N, o.n, o.a);
  r.diagnostics.choices = std::move(choices);
  // fit is the simulation fit on the estimation data, as for every estimator: the FSF model (a finite impulse
  // response) simulated from rest. The regression's own figure, on the windowed and weighted data, has its own
  // name. With a window a > 0 the model is G(s + a), which cannot be simulated as the system: no fit.
  const double regression_nrmse = sol.tss > 0 ? std::sqrt(sol.rss / sol.tss) : std::numeric_limits<double>::infinity();
  r.diagnostics.set(diagnostic::regression_fit_percent, 100.0 * (1.0 - regression_nrmse));
  r.diagnostics.set(diagnostic::fsf_b, o.b);
  r.diagnostics.set(diagnostic::residual_rms, std::sqrt(sol.rss / std::max(1.0, double(sol.n_rows))));
  if (o.a == 0.0) r.fit = fit_report_or_inf(data.y().col(0), r.model.simulate(data.u().col(0)), p);
  if (o.b > 0 && M > N)
    r.diagnostics.warnings.push_back(detail::format(
        "b = {} > 0 with a record ({} s) longer than T = {} s: the weighting amplifies the FSF truncation errors of late "
        "data by up to e^(bT); estimates can be badly biased (docs/methods/gawthrop-wang.md). Prefer b = 0",
        o.b, M * Ts, o.T));
  if (sol.rank_deficient) {
    r.summary.termination = Termination::RankDeficient;
    r.summary.message = detail::format("the FSF regressor is rank deficient (condition {}); the input does not excite the "
                                       "{} filter frequencies (k Omega up to {} rad/s)",
                                       sol.condition, o.n, m * 2.0 * std::numbers::pi / o.T);
  }
  r.summary.iterations = 1;
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

Eigen::VectorXcd one_sided_dft(const Eigen::VectorXd& x, int L) {
  CTID_REQUIRE(L >= 2 && L % 2 == 0 && L >= x.size(), "one_sided_dft: L = {} must be even and >= the length {}", L, x.size());
  std::vector<double> in(L, 0.0);
  for (Eigen::Index i = 0; i < x.size(); ++i) in[i] = x(i);
  std::vector<cd> out;
  Eigen::FFT<double> fft;
  fft.fwd(out, in);
  Eigen::VectorXcd r(L / 2 + 1);
  for (int k = 0; k <= L / 2; ++k) r(k) = out[k];
  return r;
}

Result<FsfModel> fsf_from_spectra(const Eigen::VectorXcd& Uin, const Eigen::VectorXcd& Yin, int L, double Ts,
                                  const FsfOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  o.validate();
  CTID_REQUIRE_OPTION(o.T > 0 && o.n > 0, "fsf_from_spectra: give the window T (s) and the number of filters n (got T = {}, "
                      "n = {}): spectra leave no record to pre-estimate them from", o.T, o.n);
  CTID_REQUIRE_OPTION(!o.unstable || o.a > 0, "fsf_from_spectra: the plant is declared unstable: give a window a > 0");
  CTID_REQUIRE_OPTION(o.b == 0.0, "fsf_from_spectra: b must be 0 in the frequency domain (got {})", o.b);
  CTID_REQUIRE(std::isfinite(Ts) && Ts > 0, "fsf_from_spectra: the sampling period must be > 0 (got {})", Ts);
  CTID_REQUIRE(L >= 2 && L % 2 == 0, "fsf_from_spectra: the DFT length L must be even (got {})", L);
  CTID_REQUIRE(Uin.size() == L / 2 + 1 && Yin.size() == L / 2 + 1,
               "fsf_from_spectra: one-sided spectra of length L/2 + 1 = {} expected (U has {}, Y has {})", L / 2 + 1,
               Uin.size(), Yin.size());
  const double Nd = o.T / Ts;
  CTID_REQUIRE(Nd <= 1e9, "fsf_from_spectra: T = {} s is more than 1e9 sampling periods of {} s", o.T, Ts);
  const int N = static_cast<int>(std::lround(Nd));
  CTID_REQUIRE(std::abs(Nd - N) <= 1e-9 * std::max(1.0, Nd), "fsf_from_spectra: T = {} s is not a whole multiple of Ts = {} s",
               o.T, Ts);
  CTID_REQUIRE(o.n <= N && N <= L, "fsf_from_spectra: need n <= N <= L (n = {}, N = {}, L = {})", o.n, N, L);
  Eigen::VectorXcd U = Uin, Y = Yin;
  if (o.a > 0) {
    // Window in the time domain: inverse FFT of the padded records, e^{-a t}, FFT (GW 28-29).
    Eigen::FFT<double> fft;
    auto window = [&](Eigen::VectorXcd& X) {
      std::vector<cd> full(L);
      for (int k = 0; k <= L / 2; ++k) full[k] = X(k);
      for (int k = 1; k < L / 2; ++k) full[L - k] = std::conj(X(k));
      std::vector<double> x;
      fft.inv(x, full);
      for (int i = 0; i < L; ++i) x[i] *= std::exp(-o.a * i * Ts);
      std::vector<cd> back;
      fft.fwd(back, x);
      for (int k = 0; k <= L / 2; ++k) X(k) = back[k];
    };
    window(U);
    window(Y);
  }
  const int m = (o.n - 1) / 2, p = o.n;
  const FsfModel unit(Ts, N, o.n, Eigen::VectorXd::Zero(o.n));  // only for filter_response
  internal::StreamingLeastSquares ls(p);
  std::vector<double> re(p), im(p);
  for (int i = 0; i <= L / 2; ++i) {
    const double w = 2.0 * std::numbers::pi * i / (L * Ts);
    const double weight = (i == 0 || i == L / 2) ? 1.0 : 2.0;
    // Column for theta_0: H_0 U; Re theta_k: (H_k + H_-k) U; Im theta_k: j (H_k - H_-k) U.
    const cd c0 = unit.filter_response(0, w) * U(i);
    re[0] = c0.real();
    im[0] = c0.imag();
    for (int k = 1; k <= m; ++k) {
      const cd hp = unit.filter_response(k, w), hm = unit.filter_response(-k, w);
      const cd cr = (hp + hm) * U(i), ci = cd(0, 1) * (hp - hm) * U(i);
      re[2 * k - 1] = cr.real();
      im[2 * k - 1] = cr.imag();
      re[2 * k] = ci.real();
      im[2 * k] = ci.imag();
    }
    ls.add(re.data(), Y(i).real(), weight);
    ls.add(im.data(), Y(i).imag(), weight);
  }
  const internal::LinearSolution sol = ls.solve();
  Result<FsfModel> r = fsf_result(sol, Ts, N, o.n, o.a);
  if (sol.rank_deficient) {
    r.summary.termination = Termination::RankDeficient;
    r.summary.message = "the frequency-domain FSF regressor is rank deficient: the input spectrum does not cover the filter "
                        "frequencies";
  }
  r.summary.iterations = 1;
  r.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

double fsf_settling_time(const TransferFunction& g, double a, double tol, double t_max) {
  CTID_REQUIRE(std::isfinite(a) && a >= 0, "fsf_settling_time: a must be >= 0 (got {})", a);
  // Poles of G(s + a) are p - a; the envelope of the impulse response decays with the slowest one.
  const Eigen::VectorXcd p = g.poles();
  double slowest = -INFINITY;
  for (Eigen::Index i = 0; i < p.size(); ++i) slowest = std::max(slowest, p(i).real() - a);
  CTID_REQUIRE(slowest < 0, "fsf_settling_time: G(s + {}) is not stable (slowest pole real part {}); increase a", a,
               slowest + a);
  // Simulate the shifted impulse response on a grid fine enough for the fastest pole.
  double fastest = 0;
  for (Eigen::Index i = 0; i < p.size(); ++i) fastest = std::max(fastest, std::abs(p(i) - a));
  const double h = 0.05 / std::max(fastest, 1e-9);
  const double horizon = std::min(t_max, 20.0 / -slowest);
  const int N = std::max(10, static_cast<int>(horizon / h));
  const StateSpace ss = g.to_state_space();
  const TransferFunction shifted = StateSpace(ss.A() - a * Eigen::MatrixXd::Identity(ss.nx(), ss.nx()), ss.B(), ss.C(), ss.D())
                                       .to_transfer_function();
  const Eigen::VectorXd t = time_grid(horizon / N, N + 1);
  const Eigen::VectorXd imp = impulse_response(shifted, t).cwiseAbs();
  const double peak = imp.maxCoeff();
  for (Eigen::Index i = imp.size() - 1; i >= 0; --i)
    if (imp(i) > tol * peak) return std::min(t_max, t(std::min<Eigen::Index>(i + 1, t.size() - 1)));
  return t(0);
}

}  // namespace ctid
