// Kernel Invariance Algorithm (Billings & Li 1999, eqs 15-32).
// See include/ctid/estimate/nonlinear/kia.hpp.
#include "ctid/estimate/nonlinear/kia.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "ctid/core/check.hpp"
#include "ctid/estimate/nonlinear/gfrf.hpp"
#include "ctid/simulate/lsim.hpp"
#include "ctid/validate/metrics.hpp"
#include "data/record_refs.hpp"

namespace ctid {

namespace {
using cd = std::complex<double>;

// Least squares on the real stacking [Re; Im] with unit-norm column scaling (powers of s span decades).
Eigen::VectorXd solve_stacked(const Eigen::MatrixXcd& P, const Eigen::VectorXcd& z) {
  const Eigen::Index n = P.rows(), p = P.cols();
  Eigen::MatrixXd A(2 * n, p);
  Eigen::VectorXd b(2 * n);
  A << P.real(), P.imag();
  b << z.real(), z.imag();
  Eigen::VectorXd scale = A.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < p; ++j)
    if (!(scale(j) > 0)) scale(j) = 1.0;
  const Eigen::VectorXd x = (A * scale.cwiseInverse().asDiagonal()).colPivHouseholderQr().solve(b);
  return x.cwiseQuotient(scale);
}

// ERR (% of b^T b, uncentred) of every column by forward orthogonal selection (BL 28-32), aligned with the columns,
// b the stacked real system [Re z; Im z]. *centring: b^T b / (b^T b - (sum b)^2 / rows), the factor that turns these
// into the paper's centred ERR (BL 32: its denominator is sum z^2 - (1/N)(sum z)^2; the order of selection is the same).
Eigen::VectorXd forward_err(const Eigen::MatrixXcd& P, const Eigen::VectorXcd& z, double* centring) {
  const Eigen::Index n = P.rows(), p = P.cols();
  Eigen::MatrixXd W(2 * n, p);
  Eigen::VectorXd b(2 * n);
  W << P.real(), P.imag();
  b << z.real(), z.imag();
  const double bb = b.squaredNorm();
  *centring = bb / (bb - b.sum() * b.sum() / static_cast<double>(b.size()));
  Eigen::VectorXd err = Eigen::VectorXd::Zero(p);
  std::vector<bool> used(p, false);
  for (Eigen::Index step = 0; step < p; ++step) {
    Eigen::Index best = -1;
    double best_err = -1;
    for (Eigen::Index j = 0; j < p; ++j) {
      if (used[j]) continue;
      const double ww = W.col(j).squaredNorm();
      const double e = ww > 0 ? std::pow(W.col(j).dot(b), 2) / (ww * bb) : 0.0;
      if (std::isfinite(e) && e > best_err) {
        best_err = e;
        best = j;
      }
    }
    if (best < 0) {  // non-finite columns: no ERR for the rest
      for (Eigen::Index j = 0; j < p; ++j)
        if (!used[j]) err(j) = std::numeric_limits<double>::quiet_NaN();
      break;
    }
    used[best] = true;
    err(best) = 100.0 * best_err;
    const Eigen::VectorXd w = W.col(best);
    const double ww = w.squaredNorm();
    if (ww > 0)
      for (Eigen::Index j = 0; j < p; ++j)
        if (!used[j]) W.col(j) -= (w.dot(W.col(j)) / ww) * w;  // modified Gram-Schmidt
  }
  return err;
}

struct Gls {
  Eigen::VectorXd theta, first, err;
  double centring = 1;  // err * centring: the centred ERR (forward_err)
  int iterations = 0, order = 0;
  bool converged = true;
};

// GLS (BL 20-25): LS, then F(v) = 1 + sum f_k (v/vmax)^k fitted to the residual, both sides filtered, repeated.
Gls gls(const Eigen::MatrixXcd& P, const Eigen::VectorXcd& z, const Eigen::VectorXcd& v, int G, int max_iterations,
        double tol) {
  Gls r;
  r.first = r.theta = solve_stacked(P, z);
  const double vmax = v.cwiseAbs().maxCoeff();
  const Eigen::VectorXcd vs = v / vmax;
  auto filter_regressors = [&](const Eigen::VectorXcd& E, int g) {
    Eigen::MatrixXcd R(E.size(), g);
    Eigen::VectorXcd pw = vs;
    for (int k = 0; k < g; ++k) {
      R.col(k) = -pw.cwiseProduct(E);
      pw = pw.cwiseProduct(vs);
    }
    return R;
  };
  r.order = G;
  Eigen::VectorXcd F = Eigen::VectorXcd::Ones(z.size());
  if (G > 0) {
    r.converged = false;
    for (r.iterations = 1; r.iterations <= max_iterations; ++r.iterations) {
      const Eigen::VectorXcd E = z - P * r.theta.cast<cd>();
      const Eigen::VectorXd f = solve_stacked(filter_regressors(E, G), E);
      F.setOnes();
      Eigen::VectorXcd pw = vs;
      for (int k = 0; k < G; ++k) {
        F += f(k) * pw;
        pw = pw.cwiseProduct(vs);
      }
      const Eigen::VectorXd next = solve_stacked(F.asDiagonal() * P, F.cwiseProduct(z));
      const double change = (next - r.theta).cwiseQuotient(next.cwiseAbs().cwiseMax(1e-300)).cwiseAbs().maxCoeff();
      r.theta = next;
      if (change <= tol) {
        r.converged = true;
        break;
      }
    }
    r.iterations = std::min(r.iterations, max_iterations);
  }
  r.err = forward_err(F.asDiagonal() * P, F.cwiseProduct(z), &r.centring);
  return r;
}

void check_points(const KiaPointOptions& p) {
  CTID_REQUIRE(p.count >= 1, "kia: the number of points must be >= 1 (got {})", p.count);
  CTID_REQUIRE(std::isfinite(p.max) && p.max > 0, "kia: the point range must be > 0 rad/s (got {})", p.max);
}

// The point range for a NARX model sampled at T: max = 0 gives default_max_T / T (the paper's range in units of
// its sampling rate: 500 rad/s and 220 rad/s at T = 2.5 ms, BL 33); a range beyond the Nyquist frequency pi/T is
// refused: there e^{sT} aliases and the kernels are not invariant (BL section 4, "fast enough sampling").
KiaPointOptions in_band(KiaPointOptions p, double T, double default_max_T, const char* who, const char* key) {
  CTID_REQUIRE_OPTION(std::isfinite(p.max) && p.max >= 0, "{}: the point range {} must be >= 0 rad/s (0: automatic; "
                      "got {})", who, key, p.max);
  if (p.max == 0) p.max = default_max_T / T;
  CTID_REQUIRE_OPTION(p.max * T <= std::numbers::pi, "{}: the point range {} = {} rad/s lies beyond the Nyquist frequency pi/T = {} "
                      "rad/s of the NARX model (T = {} s), where its kernels are not those of a continuous-time model; "
                      "give {} <= {} or 0 (automatic: {} rad/s)", who, key, p.max, std::numbers::pi / T, T, key, std::numbers::pi / T,
                      default_max_T / T);
  return p;
}
}  // namespace

std::vector<std::complex<double>> kia_points(const KiaPointOptions& o) {
  check_points(o);
  std::mt19937_64 rng(o.seed);
  std::uniform_real_distribution<double> U(0.0, o.max);
  const int n = o.count;
  auto value = [&](int i, int count) { return o.grid ? o.max * (i + 1) / count : std::max(U(rng), 1e-9 * o.max); };
  std::vector<cd> s;
  s.reserve(n);
  switch (o.region) {
    case KiaRegion::Axes: {
      const int nr = n / 2, ni = n - nr;
      for (int i = 0; i < nr; ++i) s.emplace_back(value(i, nr), 0.0);
      for (int i = 0; i < ni; ++i) s.emplace_back(0.0, value(i, ni));
      break;
    }
    case KiaRegion::RealAxis:
      for (int i = 0; i < n; ++i) s.emplace_back(value(i, n), 0.0);
      break;
    case KiaRegion::ImaginaryAxis:
      for (int i = 0; i < n; ++i) s.emplace_back(0.0, value(i, n));
      break;
    case KiaRegion::Complex:
      for (int i = 0; i < n; ++i) {
        const double re = value(i, n), im = o.grid ? o.max * (n - i) / n : U(rng);
        s.emplace_back(re, im);
      }
      break;
  }
  return s;
}

template <>
const OptionTable<KiaPointOptions>& option_table<KiaPointOptions>() {
  using O = KiaPointOptions;
  static const OptionTable<O> t =
      OptionTable<O>("kia")
          .choice("region", &O::region,
                  {{"axes", KiaRegion::Axes}, {"real", KiaRegion::RealAxis}, {"imaginary", KiaRegion::ImaginaryAxis},
                   {"complex", KiaRegion::Complex}},
                  "where the s-points lie (axes: half on each positive axis)")
          .integer("points", &O::count, "", at_least(1), "s-points (linear stage), pairs or triples (higher stages)")
          .real("max", &O::max, "rad/s", or_special(above(0), 0, "automatic: 1.25/T linear, 0.55/T higher stages"),
                "range of the s-points, at most the Nyquist frequency pi/T of the NARX model")
          .flag("grid", &O::grid, "evenly spaced points instead of uniformly random ones")
          .integer("seed", &O::seed, "", at_least(0), "seed of the random points");
  return t;
}

namespace {
// The settings every KIA stage shares, after its own (candidates or orders) and its points.
template <class O>
OptionTable<O>& stage_settings(OptionTable<O>& t) {
  return t.include(&O::points, option_table<KiaPointOptions>())
      .integer("gls_order", &O::gls_order, "", between(-1, 20),
               "GLS filter order; 0: plain least squares; -1 (linear stage): the smallest order explaining 99.99 %")
      .integer("gls_iterations", &O::max_iterations, "", at_least(1), "GLS iterations")
      .real("gls_tolerance", &O::tolerance, "", above(0), "relative change of the coefficients that stops GLS")
      .real("err_threshold", &O::err_threshold, "%", OptionRange{0, 100, false, true, {}, {}},
            "prune terms with a smaller ERR after convergence, then re-estimate (0: keep all)")
      .flag("zoh", &O::zoh, "divide the NARX kernels by the hold factor Z(s) (held input; the CLI takes it from the data)")
      .flag("err_centred", &O::err_centred,
            "ERR over the centred data, sum z^2 - (sum z)^2 / N (the paper's BL 32; default: uncentred, whose ERRs of a "
            "complete model sum to 100 %)");
}
}  // namespace

template <>
const OptionTable<KiaLinearOptions>& option_table<KiaLinearOptions>() {
  using O = KiaLinearOptions;
  static const OptionTable<O> t = [] {
    OptionTable<O> x("kia_linear");
    x.integer("y_order", &O::y_order, "", at_least(1), "output derivatives D^1 y .. D^y_order y")
        .integer("u_order", &O::u_order, "", at_least(0), "input derivatives u .. D^u_order u");
    return stage_settings(x);
  }();
  return t;
}

namespace {
// The table of a higher KIA stage: its candidate terms, then the shared stage settings.
template <class O>
OptionTable<O> candidate_stage_table(const char* method, const char* candidates_doc) {
  OptionTable<O> x(method);
  x.terms("candidates", &O::candidates, candidates_doc);
  return stage_settings(x);
}
}  // namespace

template <>
const OptionTable<KiaQuadraticOptions>& option_table<KiaQuadraticOptions>() {
  static const auto t =
      candidate_stage_table<KiaQuadraticOptions>("kia_quadratic", "degree-2 candidate terms, e.g. y^2,y*Dy,Dy^2,y*u");
  return t;
}

template <>
const OptionTable<KiaCubicOptions>& option_table<KiaCubicOptions>() {
  static const auto t = candidate_stage_table<KiaCubicOptions>("kia_cubic", "degree-3 candidate terms, e.g. y^3,y^2*Dy");
  return t;
}

template <>
const OptionTable<KiaOptions>& option_table<KiaOptions>() {
  using O = KiaOptions;
  static const OptionTable<O> t =
      OptionTable<O>("kia")
          .include(&O::linear, option_table<KiaLinearOptions>())
          .include(&O::quadratic, option_table<KiaQuadraticOptions>(), {}, {{"candidates", "quadratic"}}, "q")
          .include(&O::cubic, option_table<KiaCubicOptions>(), {}, {{"candidates", "cubic"}}, "c")
          .flag("refine", &O::refine, "refine the reconstructed equation by output error on the record")
          .include(&O::refinement, option_table<NdeOeOptions>(), {}, {}, "oe_");
  return t;
}

void KiaOptions::validate() const {
  linear.validate();
  if (!quadratic.candidates.empty()) quadratic.validate();
  if (!cubic.candidates.empty()) cubic.validate();
  refinement.validate();
}

void KiaLinearOptions::validate() const {
  option_table<KiaLinearOptions>().check(*this);
  CTID_REQUIRE_OPTION(points.count >= y_order + u_order + 1, "kia_linear: {} points for {} coefficients", points.count,
                      y_order + u_order + 1);
}

void KiaQuadraticOptions::validate() const {
  CTID_REQUIRE_OPTION(!candidates.empty(), "kia_quadratic: no candidate terms");
  for (const auto& t : candidates)
    CTID_REQUIRE_OPTION(t.degree() == 2, "kia_quadratic: candidate {} is not of degree 2", t.name());
  option_table<KiaQuadraticOptions>().check(*this);
  CTID_REQUIRE_OPTION(points.count >= static_cast<int>(candidates.size()), "kia_quadratic: {} point pairs for {} "
                      "coefficients", points.count, candidates.size());
}

namespace {
// GLS with the filter order chosen by ERR when G < 0 (BL-D6: the paper's order 10 made the filtered regression
// explain 99.992 %): the smallest order 1..12 whose converged fit explains >= 99.99 % (sum of ERR), otherwise the
// order with the largest sum.
Gls gls_auto(const Eigen::MatrixXcd& P, const Eigen::VectorXcd& z, const Eigen::VectorXcd& v, int G, int iters,
             double tol) {
  if (G >= 0) return gls(P, z, v, G, iters, tol);
  Gls best;
  double best_sum = -1;
  for (int g = 1; g <= 12; ++g) {
    Gls r = gls(P, z, v, g, iters, tol);
    const double sum = r.err.sum();
    if (sum >= 99.99) return r;
    if (sum > best_sum) {
      best_sum = sum;
      best = std::move(r);
    }
  }
  return best;
}

// Run GLS on a candidate set, prune by ERR and re-run; returns the fit (its err centred when asked: the ERR the
// pruning compares with the threshold and the one reported) and the retained column indices.
Gls fit_and_prune(const Eigen::MatrixXcd& P, const Eigen::VectorXcd& z, const Eigen::VectorXcd& v, int G, int iters,
                  double tol, double threshold, bool centred, std::vector<int>& keep) {
  keep.resize(P.cols());
  for (Eigen::Index j = 0; j < P.cols(); ++j) keep[j] = static_cast<int>(j);
  auto fit = [&](const Eigen::MatrixXcd& Pk) {
    Gls g = gls_auto(Pk, z, v, G, iters, tol);
    if (centred) g.err *= g.centring;
    return g;
  };
  Gls r = fit(P);
  if (threshold > 0) {
    std::vector<int> kept;
    for (Eigen::Index j = 0; j < P.cols(); ++j)
      if (r.err(j) >= threshold) kept.push_back(static_cast<int>(j));
    if (!kept.empty() && kept.size() < keep.size()) {
      Eigen::MatrixXcd Pk(P.rows(), static_cast<Eigen::Index>(kept.size()));
      for (size_t j = 0; j < kept.size(); ++j) Pk.col(static_cast<Eigen::Index>(j)) = P.col(kept[j]);
      keep = kept;
      r = fit(Pk);
    }
  }
  return r;
}

template <class R>
void fill_parameters(R& res, const std::vector<std::string>& names, const Eigen::VectorXd& values,
                     const Eigen::VectorXd& first, const Gls& g) {
  res.parameters.names = names;
  res.parameters.values = values;
  res.parameters.std = Eigen::VectorXd::Constant(values.size(), std::numeric_limits<double>::quiet_NaN());
  res.parameters.fixed.assign(values.size(), false);
  res.diagnostics.set(diagnostic::err, g.err);
  res.diagnostics.set(diagnostic::first_iteration, first);
  res.diagnostics.set(diagnostic::gls_iterations, g.iterations);
  res.diagnostics.set(diagnostic::gls_order, g.order);
  res.diagnostics.set(diagnostic::err_sum, g.err.sum());
  res.summary.iterations = g.iterations;
  if (g.order > 0) {
    res.summary.termination = g.converged ? Termination::Converged : Termination::MaxIterations;
    if (!g.converged)
      res.summary.message = detail::format("the iteration limit ended the GLS iterations, not convergence ({} iterations); "
                                           "the last iterate is returned; raise max_iterations", g.iterations);
  }
}
// The model plus the retained candidates with their estimated coefficients (linear, quadratic and cubic stages).
Result<NdeModel> extended(const NdeModel& base, const std::vector<NdeTerm>& candidates, const std::vector<int>& keep,
                          const Gls& g, std::chrono::steady_clock::time_point t_start) {
  std::vector<NdeTerm> terms = base.terms();
  std::vector<double> c(base.coefficients().data(), base.coefficients().data() + base.coefficients().size());
  std::vector<std::string> names;
  Eigen::VectorXd values(keep.size()), first(keep.size());
  for (size_t j = 0; j < keep.size(); ++j) {
    const Eigen::Index k = static_cast<Eigen::Index>(j);
    values(k) = g.theta(k);
    first(k) = g.first(k);
    terms.push_back(candidates[keep[j]]);
    c.push_back(values(k));
    names.push_back(candidates[keep[j]].name());
  }
  Result<NdeModel> res;
  res.model = NdeModel(terms, Eigen::Map<const Eigen::VectorXd>(c.data(), static_cast<Eigen::Index>(c.size())));
  fill_parameters(res, names, values, first, g);
  res.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return res;
}
}  // namespace

Result<NdeModel> kia_linear(const NarxModel& narx, const KiaLinearOptions& o) {
  const auto t_start = std::chrono::steady_clock::now();
  o.validate();
  const std::vector<cd> s = kia_points(in_band(o.points, narx.ts(), 1.25, "kia_linear", "max"));
  const Eigen::Index n = static_cast<Eigen::Index>(s.size());
  Eigen::VectorXcd z(n), v(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    z(i) = narx_gfrf_ct(narx, {s[i]}, o.zoh);
    v(i) = s[i];
  }
  CTID_REQUIRE(z.allFinite() && z.cwiseAbs().maxCoeff() > 0, "kia_linear: the NARX model has no linear input-output "
               "kernel (H_1 = 0 or not finite at the points)");
  // H_1 (1 + sum alpha_l s^l) = sum beta_l s^l with the implicit-form coefficients as unknowns: u-terms
  // (coefficient -beta_l) have columns -s^l, y-terms (alpha_l) -s^l H_1.
  std::vector<NdeTerm> terms;
  const int p = o.u_order + 1 + o.y_order;
  Eigen::MatrixXcd P(n, p);
  for (int l = 0; l <= o.u_order; ++l) {
    for (Eigen::Index i = 0; i < n; ++i) P(i, l) = -std::pow(s[i], l);
    terms.push_back({{{true, l}}});
  }
  for (int l = 1; l <= o.y_order; ++l) {
    for (Eigen::Index i = 0; i < n; ++i) P(i, o.u_order + l) = -std::pow(s[i], l) * z(i);
    terms.push_back({{{false, l}}});
  }
  std::vector<int> keep;
  const Gls g = fit_and_prune(P, z, v, o.gls_order, o.max_iterations, o.tolerance, o.err_threshold, o.err_centred, keep);
  return extended(NdeModel({{{{false, 0}}}}, Eigen::VectorXd::Ones(1)), terms, keep, g, t_start);
}

Result<NdeModel> kia_quadratic(const NarxModel& narx, const NdeModel& linear_in, const KiaQuadraticOptions& o) {
  const auto t_start = std::chrono::steady_clock::now();
  o.validate();
  const NdeModel linear = linear_in.normalized();
  for (const auto& t : linear.terms())
    CTID_REQUIRE(t.degree() == 1, "kia_quadratic: the linear model has a nonlinear term {}", t.name());
  const KiaPointOptions first = in_band(o.points, narx.ts(), 0.55, "kia_quadratic", "qmax");
  KiaPointOptions second = first;
  second.seed = first.seed + 7919;
  const std::vector<cd> s1 = kia_points(first), s2 = kia_points(second);
  const Eigen::Index n = static_cast<Eigen::Index>(s1.size());
  const Polynomial A = linear.a();
  Eigen::VectorXcd z(n), v(n);
  const int p = static_cast<int>(o.candidates.size());
  Eigen::MatrixXcd P(n, p);
  for (Eigen::Index i = 0; i < n; ++i) {
    const cd S[2] = {s1[i], s2[i]}, H1[2] = {linear.h1(s1[i]), linear.h1(s2[i])};
    z(i) = 2.0 * A(S[0] + S[1]) * narx_gfrf_ct(narx, {S[0], S[1]}, o.zoh);
    v(i) = S[0] + S[1];
    auto X = [&](const NdeFactor& f, int k) { return std::pow(S[k], f.derivative) * (f.input ? 1.0 : H1[k]); };
    for (int j = 0; j < p; ++j) {
      const auto& f = o.candidates[j].factors;
      P(i, j) = -(X(f[0], 0) * X(f[1], 1) + X(f[0], 1) * X(f[1], 0));
    }
  }
  CTID_REQUIRE(z.allFinite(), "kia_quadratic: the NARX second-order kernel is not finite at the points");
  CTID_REQUIRE(P.allFinite(), "kia_quadratic: the linear model's H_1 is not finite at the points (a pole on an axis?)");
  std::vector<int> keep;
  const Gls g = fit_and_prune(P, z, v, o.gls_order, o.max_iterations, o.tolerance, o.err_threshold, o.err_centred, keep);
  return extended(linear, o.candidates, keep, g, t_start);
}

void KiaCubicOptions::validate() const {
  CTID_REQUIRE_OPTION(!candidates.empty(), "kia_cubic: no candidate terms");
  for (const auto& t : candidates)
    CTID_REQUIRE_OPTION(t.degree() == 3, "kia_cubic: candidate {} is not of degree 3", t.name());
  option_table<KiaCubicOptions>().check(*this);
  CTID_REQUIRE_OPTION(points.count >= static_cast<int>(candidates.size()), "kia_cubic: {} point triples for {} "
                      "coefficients", points.count, candidates.size());
}

Result<NdeModel> kia_cubic(const NarxModel& narx, const NdeModel& model_in, const KiaCubicOptions& o) {
  const auto t_start = std::chrono::steady_clock::now();
  o.validate();
  const NdeModel model = model_in.normalized();
  for (const auto& t : model.terms())
    CTID_REQUIRE(t.degree() <= 2, "kia_cubic: the model already has a term of degree {} ({})", t.degree(), t.name());
  std::vector<cd> S[3];
  const KiaPointOptions points = in_band(o.points, narx.ts(), 0.55, "kia_cubic", "qmax");
  for (int k = 0; k < 3; ++k) {
    KiaPointOptions p = points;
    p.seed = o.points.seed + 7919u * static_cast<unsigned>(k);
    S[k] = kia_points(p);
  }
  const Eigen::Index n = static_cast<Eigen::Index>(S[0].size());
  const int p = static_cast<int>(o.candidates.size());
  const Polynomial A = model.a();
  Eigen::VectorXcd z(n), v(n);
  Eigen::MatrixXcd P(n, p);
  for (Eigen::Index i = 0; i < n; ++i) {
    const cd s[3] = {S[0][i], S[1][i], S[2][i]};
    const cd H1[3] = {model.h1(s[0]), model.h1(s[1]), model.h1(s[2])};
    v(i) = s[0] + s[1] + s[2];
    // 6 A H3 = -Q - sum gamma C' with Q the known quadratic part: model.h3 of the quadratic model is -Q/(6A).
    z(i) = 6.0 * A(v(i)) * (narx_gfrf_ct(narx, {s[0], s[1], s[2]}, o.zoh) - model.h3(s[0], s[1], s[2]));
    auto X1 = [&](const NdeFactor& f, int k) { return std::pow(s[k], f.derivative) * (f.input ? 1.0 : H1[k]); };
    for (int j = 0; j < p; ++j) {
      const auto& f = o.candidates[j].factors;
      int q[3] = {0, 1, 2};
      cd c = 0.0;
      do c -= X1(f[0], q[0]) * X1(f[1], q[1]) * X1(f[2], q[2]);
      while (std::next_permutation(q, q + 3));
      P(i, j) = c;
    }
  }
  CTID_REQUIRE(z.allFinite(), "kia_cubic: the NARX third-order kernel is not finite at the points");
  CTID_REQUIRE(P.allFinite(), "kia_cubic: the model's kernels are not finite at the points (a pole on an axis?)");
  std::vector<int> keep;
  const Gls g = fit_and_prune(P, z, v, o.gls_order, o.max_iterations, o.tolerance, o.err_threshold, o.err_centred, keep);
  return extended(model, o.candidates, keep, g, t_start);
}

std::vector<NdeTerm> kia_product_candidates(int degree, int y_order, int u_order) {
  CTID_REQUIRE(degree >= 1 && y_order >= 0 && u_order >= 0, "kia_product_candidates: degree {} >= 1, orders {} and {} >= 0",
               degree, y_order, u_order);
  std::vector<NdeFactor> factors;
  for (int l = 0; l < y_order; ++l) factors.push_back({false, l});  // D^{y_order} y appears once, linearly
  for (int l = 0; l <= u_order; ++l) factors.push_back({true, l});
  std::vector<NdeTerm> out;
  std::vector<int> idx(static_cast<size_t>(degree), 0);  // non-decreasing indices: unordered products
  const int F = static_cast<int>(factors.size());
  while (true) {
    NdeTerm t;
    for (int i : idx) t.factors.push_back(factors[static_cast<size_t>(i)]);
    out.push_back(t);
    int k = degree - 1;
    while (k >= 0 && idx[static_cast<size_t>(k)] == F - 1) --k;
    if (k < 0) break;
    ++idx[static_cast<size_t>(k)];
    for (int j = k + 1; j < degree; ++j) idx[static_cast<size_t>(j)] = idx[static_cast<size_t>(k)];
  }
  return out;
}

namespace {
// kia of one record or of several, without copying them; `refine` is nde_oe of the same records as the caller gave
// them (nde_oe's public calls, which do not copy either).
template <class Refine>
KiaRun kia_records(const internal::RecordRefs& ds, const NarxModel& narx, const KiaOptions& o, const Refine& refine) {
  CTID_REQUIRE(!ds.empty(), "kia: no records");
  const int E = static_cast<int>(ds.size());
  for (int e = 0; e < E; ++e) {
    const std::string who = E > 1 ? detail::format("kia (record {})", e + 1) : "kia";
    require_io_data(ds[e], who.c_str());
    CTID_REQUIRE(std::abs(narx.ts() - ds[e].ts()) <= 1e-9 * ds[e].ts(),
                 "{}: the NARX model was identified at Ts = {} s, the data have {} s", who, narx.ts(), ds[e].ts());
  }
  o.validate();
  KiaRun run;
  Result<NdeModel>& r = run.reconstructed;
  r = kia_linear(narx, o.linear);
  // Each higher stage returns its own coefficients; the earlier stages' are prepended to its table.
  auto stack = [](const Result<NdeModel>& before, Result<NdeModel> next) {
    next.parameters.names.insert(next.parameters.names.begin(), before.parameters.names.begin(),
                                 before.parameters.names.end());
    Eigen::VectorXd v(before.parameters.size() + next.parameters.values.size());
    v << before.parameters.values, next.parameters.values;
    next.parameters.values = v;
    next.parameters.std = Eigen::VectorXd::Constant(v.size(), NAN);
    next.parameters.fixed.assign(static_cast<size_t>(v.size()), false);
    Eigen::VectorXd e(v.size());
    e << before.diagnostics.get(diagnostic::err), next.diagnostics.get(diagnostic::err);
    next.diagnostics.set(diagnostic::err, e);
    return next;
  };
  // Stages of degree 2 and 3: the given candidates, or every product (when the NARX model has such terms).
  std::vector<std::string> choices;
  auto stage = [&](auto options, int degree) {
    bool narx_has = false;
    for (const NarxTerm& t : narx.terms()) narx_has = narx_has || t.degree() == degree;
    if (options.candidates.empty() && narx_has) {
      options.candidates = kia_product_candidates(degree, o.linear.y_order, o.linear.u_order);
      if (options.err_threshold == 0.0) options.err_threshold = 0.01;
      options.points.count = std::max(options.points.count, 2 * static_cast<int>(options.candidates.size()));
      choices.push_back(detail::format(
          "{} candidates: all {} products of y..D^{}y, u..D^{}u ({} point {}), pruned below ERR {} % after convergence "
          "(the NARX model has terms of degree {})",
          degree == 2 ? "quadratic" : "cubic", options.candidates.size(), o.linear.y_order - 1, o.linear.u_order,
          options.points.count, degree == 2 ? "pairs" : "triples", options.err_threshold, degree));
    }
    return options;
  };
  const KiaQuadraticOptions quadratic = stage(o.quadratic, 2);
  const KiaCubicOptions cubic = stage(o.cubic, 3);
  if (!quadratic.candidates.empty()) r = stack(r, kia_quadratic(narx, r.model, quadratic));
  if (!cubic.candidates.empty()) r = stack(r, kia_cubic(narx, r.model, cubic));
  r.diagnostics.choices = choices;
  // The equation's simulated output on each record (from rest), pooled.
  Eigen::Index total = 0;
  for (const IdData& d : ds) total += d.size();
  Eigen::VectorXd y(total), ysim(total);
  bool sim_ok = true;
  for (Eigen::Index e = 0, at = 0; e < E; at += ds[e].size(), ++e) {
    const IdData& d = ds[e];
    y.segment(at, d.size()) = d.y().col(0);
    const NdeSimulation sim = r.model.simulate(d.u().col(0), (d.times().array() - d.t0()).matrix(), d.intersample(0));
    if (sim.ok()) {
      ysim.segment(at, d.size()) = sim.y;
    } else if (sim_ok) {
      sim_ok = false;
      r.summary.termination = sim.termination;
      r.summary.message = "the NDE simulation failed" + (E > 1 ? detail::format(" on record {}", e + 1) : "") + ": " +
                          sim.message;
    }
  }
  r.fit = fit_report_or_inf(y, sim_ok ? ysim : Eigen::VectorXd::Constant(total, NAN), r.parameters.size());
  if (E > 1) r.diagnostics.set(diagnostic::experiments, E);
  // Kernel invariance means the equation reproduces its NARX model: its free run on each record after the first
  // max_lag samples, pooled.
  const int L = narx.max_lag();
  std::vector<double> measured, free_run;
  bool escaped = false;
  for (const IdData& d : ds) {
    if (d.size() <= L + 2) continue;
    const Eigen::VectorXd yn = narx.simulate(d.u().col(0), d.y().col(0).head(L), &escaped);
    if (escaped) break;
    measured.insert(measured.end(), d.y().col(0).data() + L, d.y().col(0).data() + d.size());
    free_run.insert(free_run.end(), yn.data() + L, yn.data() + d.size());
  }
  if (!escaped && !measured.empty())
    run.narx_fit_percent = fit_report_or_inf(Eigen::Map<const Eigen::VectorXd>(measured.data(), Eigen::Index(measured.size())),
                                             Eigen::Map<const Eigen::VectorXd>(free_run.data(), Eigen::Index(free_run.size())), 0)
                               .fit_percent;
  if (sim_ok && run.narx_fit_percent > 0 && r.fit.fit_percent < 0.5 * run.narx_fit_percent) {
    r.summary.termination = Termination::Unidentifiable;
    r.summary.message = detail::format(
        "the continuous-time equation does not reproduce its NARX model (simulated fit {} % against the NARX "
        "model's {} %): its candidate terms cannot express the NARX kernels (y_order, u_order, quadratic, cubic), "
        "or the sampling is too slow for kernel invariance",
        std::round(r.fit.fit_percent * 100) / 100, std::round(run.narx_fit_percent * 100) / 100);
  }
  const bool narx_fit_known = std::isfinite(run.narx_fit_percent);
  if (narx_fit_known) r.diagnostics.set(diagnostic::narx_fit_percent, run.narx_fit_percent);
  if (o.refine) {
    run.refined = refine(r.model);
    if (narx_fit_known) run.refined->diagnostics.set(diagnostic::narx_fit_percent, run.narx_fit_percent);
    run.refined->diagnostics.choices.insert(run.refined->diagnostics.choices.begin(), choices.begin(), choices.end());
  }
  return run;
}
}  // namespace

KiaRun kia(const IdData& d, const NarxModel& narx, const KiaOptions& o) {
  return kia_records(d, narx, o, [&](const NdeModel& m) { return nde_oe(d, m, o.refinement); });
}

KiaRun kia(const std::vector<IdData>& ds, const NarxModel& narx, const KiaOptions& o) {
  return kia_records(ds, narx, o, [&](const NdeModel& m) { return nde_oe(ds, m, o.refinement); });
}

}  // namespace ctid
