// ctid — continuous-time subspace identification (estimate/state_space/subspace.hpp): Johansson, Verhaegen & Chou (1999)
// eqs 6-9 (the lambda-operator model) with PI-MOESP (Verhaegen 1994) on the lambda-filtered signals; PO-MOESP on
// the samples plus logm as the discrete-time comparison route; B, D, x0 by continuous-time least squares.
#include "ctid/estimate/state_space/subspace.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <limits>
#include <optional>

#include <unsupported/Eigen/MatrixFunctions>

#include "ctid/core/check.hpp"
#include "ctid/core/error.hpp"
#include "ctid/signal/svf.hpp"
#include "ctid/simulate/lsim.hpp"
#include "ctid/validate/metrics.hpp"
#include "estimate/state_space/state_space_common.hpp"
#include "internal/least_squares.hpp"

namespace ctid {

template <>
const OptionTable<SubspaceOptions>& option_table<SubspaceOptions>() {
  using O = SubspaceOptions;
  static const OptionTable<O> t =
      OptionTable<O>("subspace")
          .integer("nx", &O::nx, "", or_special(at_least(1), 0, "where the singular values drop most, 1..12"),
                   "state dimension")
          .integer("horizon", &O::horizon, "", or_special(at_least(2), 0, "nx + 2"),
                   "block rows r of the extended observability matrix")
          .choice("route", &O::route, {{"lambda", SubspaceRoute::Lambda}, {"discrete", SubspaceRoute::Discrete}},
                  "lambda: continuous time, lambda = 1/(1 + p tau) (any sampling); discrete: MOESP on the samples, "
                  "then logm (uniform sampling)")
          .real("tau", &O::tau, "s", or_special(above(0), 0, "automatic"),
                "time constant of lambda = 1/(1 + p tau); 0: least BIC, stable first, over 8 values from 2 Ts to "
                "duration/50 (records of 80000 samples or more: searched on their first 10000 samples)")
          .flag("estimate_d", &O::estimate_d, "estimate the direct term D (false: D = 0)")
          .flag("estimate_initial_state", &O::estimate_initial_state,
                "estimate the record's initial state (false: it starts at rest)")
          .flag("stabilize", &O::stabilize,
                "move right-half-plane poles of A to the left half plane (re -> -re) before B, D and x0 are "
                "estimated (false: keep them, e.g. for an unstable plant)");
  return t;
}

void SubspaceOptions::validate() const { option_table<SubspaceOptions>().check(*this); }

namespace {

constexpr int kGramBatch = 256;  // rows gathered before one rank-k update of a Gram matrix

// Pseudo-inverse of a symmetric positive semi-definite matrix (eigenvalues below rel * largest dropped), and the
// same for its inverse square root.
Eigen::MatrixXd spd_pinv(const Eigen::MatrixXd& G, double power, double rel = 1e-12) {
  if (G.rows() == 0) return G;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(G);
  const Eigen::VectorXd& l = es.eigenvalues();
  const double cut = rel * std::max(l.maxCoeff(), 0.0);
  Eigen::VectorXd d(l.size());
  for (Eigen::Index i = 0; i < l.size(); ++i) d(i) = l(i) > cut && l(i) > 0 ? std::pow(l(i), power) : 0.0;
  return es.eigenvectors() * d.asDiagonal() * es.eigenvectors().transpose();
}

// Streams rows into a Gram matrix G = sum z z^T.
class Gram {
 public:
  explicit Gram(int m) : G_(Eigen::MatrixXd::Zero(m, m)), Z_(kGramBatch, m) {}
  void set(int j, double v) { Z_(fill_, j) = v; }
  void commit() {
    if (++fill_ == kGramBatch) flush();
  }
  const Eigen::MatrixXd& done() {
    flush();
    return G_;
  }

 private:
  void flush() {
    if (fill_ == 0) return;
    G_.selfadjointView<Eigen::Lower>().rankUpdate(Z_.topRows(fill_).transpose());
    fill_ = 0;
  }
  Eigen::MatrixXd G_, Z_;
  int fill_ = 0;
};

struct ChannelScales {
  Eigen::VectorXd su, sy;  // standard deviations of the inputs and outputs (1 where constant)
};

ChannelScales scales(const IdData& d) {
  return {ss_detail::channel_scales({&d, 1}, false), ss_detail::channel_scales({&d, 1}, true)};
}

// Gram matrix of z = [U_f; U_p; Y_f] of the lambda route (block row k of U_f: lambda^{r-1-k} u; U_p: lambda^{r+j} u).
Eigen::MatrixXd lambda_gram(const IdData& d, const ChannelScales& s, int r, double tau) {
  const int nu = d.nu(), ny = d.ny(), ns = nu + ny;
  std::vector<Intersample> is;
  for (int i = 0; i < nu; ++i) is.push_back(d.intersample(i));
  for (int j = 0; j < ny; ++j) is.push_back(Intersample::Foh);
  SvfFilterBank bank(2 * r - 1, tau, is);
  Gram g(2 * r * nu + r * ny);
  std::vector<double> prev(static_cast<size_t>(ns)), next(static_cast<size_t>(ns));
  auto sample = [&](int k, std::vector<double>& v) {
    for (int i = 0; i < nu; ++i) v[static_cast<size_t>(i)] = d.u()(k, i) / s.su(i);
    for (int j = 0; j < ny; ++j) v[static_cast<size_t>(nu + j)] = d.y()(k, j) / s.sy(j);
  };
  // lambda^p of signal i at the current time (p = 0: the filtered sample itself).
  auto power = [&](int i, int p) { return p == 0 ? bank.filtered(i) : bank.chain(i)[p - 1]; };
  for (int k = 0; k < d.size(); ++k) {
    sample(k, next);
    if (k == 0)
      bank.set_current(next.data());
    else
      bank.step(d.is_uniform() ? d.ts() : d.time(k) - d.time(k - 1), prev.data(), next.data());
    for (int b = 0; b < r; ++b) {
      for (int i = 0; i < nu; ++i) {
        g.set(b * nu + i, power(i, r - 1 - b));
        g.set(r * nu + b * nu + i, power(i, r + b));
      }
      for (int j = 0; j < ny; ++j) g.set(2 * r * nu + b * ny + j, power(nu + j, r - 1 - b));
    }
    g.commit();
    std::swap(prev, next);
  }
  return g.done();
}

// Gram matrix of z = [U_f; U_p; Y_p; Y_f] on the samples (block row k of U_f: u(t + k); of U_p: u(t - r + k)).
Eigen::MatrixXd discrete_gram(const IdData& d, const ChannelScales& s, int r) {
  const int nu = d.nu(), ny = d.ny();
  Gram g(2 * r * (nu + ny));
  for (int t = r; t + r <= d.size(); ++t) {
    for (int b = 0; b < r; ++b) {
      for (int i = 0; i < nu; ++i) {
        g.set(b * nu + i, d.u()(t + b, i) / s.su(i));
        g.set(r * nu + b * nu + i, d.u()(t - r + b, i) / s.su(i));
      }
      for (int j = 0; j < ny; ++j) {
        g.set(2 * r * nu + b * ny + j, d.y()(t - r + b, j) / s.sy(j));
        g.set(2 * r * nu + r * ny + b * ny + j, d.y()(t + b, j) / s.sy(j));
      }
    }
    g.commit();
  }
  return g.done();
}

struct Range {
  Eigen::MatrixXd U;        // left singular vectors (r ny columns at most)
  Eigen::VectorXd sigma;    // the singular values
  // The extended observability matrix of order nx: U_1 S_1^{1/2}.
  Eigen::MatrixXd O(int nx) const { return U.leftCols(nx) * sigma.head(nx).cwiseSqrt().asDiagonal(); }
};

// MOESP: the range of the output block after projecting out U_f, weighted by the instruments (Verhaegen 1994).
Range moesp(const Eigen::MatrixXd& Glower, int nf, int np, int nyf) {
  const Eigen::MatrixXd G = Glower.selfadjointView<Eigen::Lower>();
  const Eigen::MatrixXd Guu = G.topLeftCorner(nf, nf), Gpu = G.block(nf, 0, np, nf), Gyu = G.block(nf + np, 0, nyf, nf);
  const Eigen::MatrixXd Gpp = G.block(nf, nf, np, np), Gyp = G.block(nf + np, nf, nyf, np);
  const Eigen::MatrixXd Ui = spd_pinv(Guu, -1.0);
  const Eigen::MatrixXd M = Gyp - Gyu * Ui * Gpu.transpose();
  const Eigen::MatrixXd S = Gpp - Gpu * Ui * Gpu.transpose();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(M * spd_pinv(S, -0.5), Eigen::ComputeThinU);
  return {svd.matrixU(), svd.singularValues()};
}

// The order: the one asked for, or where the singular values drop most — the largest ratio s_n / s_(n+1) for
// n = 1 .. 12, as far as the horizon allows and the values are above rounding level.
int chosen_order(const Eigen::VectorXd& sigma, int nx, int ny, int r) {
  const int most = std::min<int>((r - 1) * ny, static_cast<int>(sigma.size()) - 1);
  if (nx > 0) {
    CTID_REQUIRE(nx <= most, "subspace: nx = {} needs (horizon - 1) * outputs >= nx and enough instruments "
                 "(horizon {}, {} outputs); raise horizon", nx, r, ny);
    return nx;
  }
  int best = 0;
  double gap = 0.0;
  for (int n = 1; n <= std::min(most, 12) && sigma(n - 1) > 1e-10 * sigma(0); ++n) {
    const double g = sigma(n - 1) / std::max(sigma(n), 1e-300 * sigma(0));
    if (g > gap) gap = g, best = n;
  }
  CTID_REQUIRE(best > 0, "subspace: the data show no dynamics (all singular values are zero)");
  return best;
}

// Subspace estimates at a given tau (or the discrete route), one per candidate order.
struct Estimate {
  StateSpace model;
  Eigen::VectorXd x0, sigma;
  std::string refusal;  // non-empty: no continuous-time model (discrete route: no real logarithm)
};

Estimate estimate_at(const IdData& d, const ChannelScales& s, const SubspaceOptions& o, int r, double tau) {
  const int nu = d.nu(), ny = d.ny();
  const bool lambda = o.route == SubspaceRoute::Lambda;
  const Range range = lambda ? moesp(lambda_gram(d, s, r, tau), r * nu, r * nu, r * ny)
                             : moesp(discrete_gram(d, s, r), r * nu, r * (nu + ny), r * ny);
  const int n = chosen_order(range.sigma, o.nx, ny, r);
  Estimate e;
  e.sigma = range.sigma;
  const Eigen::MatrixXd O = range.O(n);
  const Eigen::MatrixXd step = ss_detail::shift_invariance(O, ny);
  Eigen::MatrixXd A;
  if (lambda) {
    A = (step - Eigen::MatrixXd::Identity(n, n)) / tau;
  } else {
    const Eigen::VectorXcd ev = step.eigenvalues();
    for (Eigen::Index i = 0; i < ev.size(); ++i)
      if (std::abs(ev(i).imag()) <= 1e-12 * std::abs(ev(i)) && ev(i).real() <= 0.0) {
        e.refusal = detail::format("the discrete-time model of order {} has the pole {} on the negative real axis or "
                                   "at 0: no real continuous-time A has it as exp(A Ts) (use route=lambda)", n,
                                   ev(i).real());
        return e;
      }
    A = step.log() / d.ts();
  }
  if (o.stabilize) A = ss_detail::reflected_into_left_half_plane(A);
  const Eigen::MatrixXd C = s.sy.asDiagonal() * O.topRows(ny);
  try {
    e.model = subspace_bd(A, C, d, o.estimate_d, o.estimate_initial_state, &e.x0);
  } catch (const InvalidArgument& ex) {
    // E.g. a strongly unstable estimate whose responses overflow over the record: not a model of these data.
    CTID_REQUIRE(false, "subspace: the model of order {} at tau = {} s has no finite response over the record ({})", n,
                 tau, ex.what());
  }
  return e;
}

ss_detail::Fits fits_of(const StateSpace& m, const IdData& d, const ChannelScales& s, const Eigen::VectorXd& x0,
                        int n_parameters) {
  LsimOptions lo;
  lo.x0 = x0;
  const Eigen::MatrixXd yhat = lsim(m, d, lo);
  return ss_detail::fits_of({&d, 1}, {&yhat, 1}, s.sy, n_parameters);
}

}  // namespace

StateSpace subspace_bd(const Eigen::MatrixXd& A, const Eigen::MatrixXd& C, const IdData& data, bool estimate_d,
                       bool estimate_initial_state, Eigen::VectorXd* x0_out) {
  const int nx = static_cast<int>(A.rows()), nu = data.nu(), ny = data.ny(), N = data.size();
  CTID_REQUIRE(A.cols() == nx && C.cols() == nx && C.rows() == ny,
               "subspace: A is {}x{} and C {}x{} for {} outputs", A.rows(), A.cols(), C.rows(), C.cols(), ny);
  const int pb = nx * nu, pd = estimate_d ? ny * nu : 0, px = estimate_initial_state ? nx : 0, p = pb + pd + px;
  CTID_REQUIRE(static_cast<long>(N) * ny > p, "subspace: {} samples of {} outputs cannot determine {} values of B, D "
               "and x0", N, ny, p);
  // X = [X_1 .. X_nu] (X_i' = A X_i + I u_i) and P(t) = e^{A (t - t0)}, stepped exactly between samples; each
  // sample's ny regression rows go to a shared least-squares kernel: the normal equations, or the blocked QR when they
  // are poorly conditioned (minimum-norm when the record does not determine every value, e.g. an x0 direction that
  // decays before the second sample).
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(nx, nx);
  auto regress = [&](auto& ls) {
    Eigen::MatrixXd X = Eigen::MatrixXd::Zero(nx, pb), Xn(nx, pb), P = I, Pn(nx, nx);
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> R = Eigen::MatrixXd::Zero(ny, p);
    Discretization disc;
    for (int k = 0; k < N; ++k) {
      if (k > 0) {
        // One exponential if uniform.
        const double h = data.is_uniform() ? data.ts() : data.time(k) - data.time(k - 1);
        if (!(std::abs(disc.h - h) <= 1e-13 * h)) disc = discretize(A, I, h);
        Xn.noalias() = disc.Phi.lazyProduct(X);  // small matrices: coefficient-wise, without GEMM's blocking
        for (int i = 0; i < nu; ++i) {
          const double u0 = data.u()(k - 1, i), u1 = data.u()(k, i);
          Xn.middleCols(static_cast<Eigen::Index>(i) * nx, nx) += disc.Gamma0 * u0;
          if (data.intersample(i) != Intersample::Zoh)
            Xn.middleCols(static_cast<Eigen::Index>(i) * nx, nx) += disc.Gamma1 * (u1 - u0);
        }
        X.swap(Xn);
        Pn.noalias() = disc.Phi.lazyProduct(P);
        P.swap(Pn);
      }
      R.leftCols(pb).noalias() = C.lazyProduct(X);
      if (pd > 0)  // D(j, i) multiplies u_i in row j only (R's other entries there stay 0)
        for (int i = 0; i < nu; ++i)
          for (int j = 0; j < ny; ++j) R(j, pb + i * ny + j) = data.u()(k, i);
      if (px > 0) R.rightCols(px).noalias() = C.lazyProduct(P);
      for (int j = 0; j < ny; ++j) ls.add(R.row(j).data(), data.y()(k, j));
    }
    return ls.solve();
  };
  // The normal equations first (a quarter of the QR's work per row), the QR again when they cannot be solved accurately.
  internal::GramLeastSquares gram(p);
  internal::LinearSolution sol = regress(gram);
  if (!(sol.condition < internal::kGramConditionLimit) || !sol.theta.allFinite()) {
    internal::StreamingLeastSquares qr(p);
    sol = regress(qr);
  }
  const Eigen::VectorXd theta = sol.theta;
  Eigen::MatrixXd B(nx, nu), D = Eigen::MatrixXd::Zero(ny, nu);
  for (int i = 0; i < nu; ++i) B.col(i) = theta.segment(static_cast<Eigen::Index>(i) * nx, nx);
  if (pd > 0)
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < ny; ++j) D(j, i) = theta(pb + i * ny + j);
  if (x0_out) *x0_out = px > 0 ? Eigen::VectorXd(theta.tail(px)) : Eigen::VectorXd::Zero(nx);
  return StateSpace(A, B, C, D);
}

Result<StateSpace> subspace(const IdData& data, const SubspaceOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  options.validate();
  const int nu = data.nu(), ny = data.ny(), N = data.size();
  CTID_REQUIRE(nu >= 1 && ny >= 1, "subspace: the data need at least one input and one output (got {} and {})", nu, ny);
  CTID_REQUIRE(data.u().allFinite() && data.y().allFinite(), "subspace: the data contain non-finite values");
  CTID_REQUIRE(options.route != SubspaceRoute::Discrete || data.is_uniform(),
               "subspace: route=discrete needs uniformly sampled data (these are irregular); use route=lambda");
  const int r = options.horizon > 0 ? options.horizon : options.nx > 0 ? options.nx + 2 : 10;
  CTID_REQUIRE(N >= 4 * r * (nu + ny), "subspace: {} samples are too few for horizon {} with {} inputs and {} outputs "
               "(at least {})", N, r, nu, ny, 4 * r * (nu + ny));
  CTID_REQUIRE(options.nx == 0 || (r - 1) * ny >= options.nx,
               "subspace: nx = {} needs (horizon - 1) * outputs >= nx (horizon {}, {} outputs)", options.nx, r, ny);

  Result<StateSpace> res;
  const ChannelScales scale = scales(data);  // every output and input to unit standard deviation
  // The free parameters of a minimal realisation (A, B, C, D up to a change of basis) and the initial state.
  auto n_free = [&](int nx) {
    return nx * (nu + ny) + (options.estimate_d ? ny * nu : 0) + (options.estimate_initial_state ? nx : 0);
  };
  // Among the taus tried (each with its order), the least BIC of the simulation error (every output scaled alike;
  // with one order that is the best fit), stable models first.
  Estimate best;
  ss_detail::Fits best_fit;
  best_fit.all.fit_percent = -INFINITY;
  best_fit.all.bic = INFINITY;
  double best_tau = 0.0;
  bool best_stable = false;
  // On long records (eight times kTauSearchSamples or more) the tau search runs on the record's beginning and only the
  // chosen tau on the whole record: the choice needs the lambda chain's transient (about 2 r tau) to be a small part
  // of the searched samples, not all of them. Measured on six 1e5-sample records of the 2x2 test system at 10 and
  // 20 dB: the whole record's fit at the tau chosen so is within 0.08 % of the best of the whole record's grid.
  constexpr int kTauSearchSamples = 10000;
  std::vector<double> grid;
  const bool search_beginning = options.route == SubspaceRoute::Lambda && options.tau <= 0 &&
                                N >= 8 * kTauSearchSamples;
  std::optional<IdData> beginning;  // the searched part when it is not the whole record (no copy of the record)
  if (search_beginning) beginning = data.slice(0, kTauSearchSamples);
  const IdData& searched = beginning ? *beginning : data;
  if (options.route == SubspaceRoute::Lambda) {
    if (options.tau > 0) {
      grid = {options.tau};
    } else {
      const double ts = searched.duration() / std::max(searched.size() - 1, 1);
      const double lo = 2.0 * ts, hi = std::max(searched.duration() / 50.0, 4.0 * ts);
      for (int i = 0; i < 8; ++i) grid.push_back(lo * std::pow(hi / lo, i / 7.0));
    }
  } else {
    grid = {0.0};
  }
  Eigen::VectorXd grid_fit = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(grid.size()), -INFINITY);
  std::string last_problem;
  for (size_t g = 0; g < grid.size(); ++g) {
    Estimate e;
    try {
      e = estimate_at(searched, scale, options, r, grid[g]);
    } catch (const InvalidArgument& ex) {
      last_problem = ex.what();
      if (grid.size() == 1) throw;
      continue;
    }
    ss_detail::Fits f;
    f.all.fit_percent = -INFINITY;
    f.all.bic = INFINITY;
    if (e.refusal.empty()) f = fits_of(e.model, searched, scale, e.x0, n_free(e.model.nx()));
    grid_fit(static_cast<Eigen::Index>(g)) = f.all.fit_percent;
    // A stable model before an unstable one, then the BIC.
    const bool stable = e.refusal.empty() && e.model.is_stable();
    const bool better = std::isfinite(f.all.bic)
                            ? (stable && !best_stable) || (stable == best_stable && !(f.all.bic >= best_fit.all.bic))
                            : best.model.nx() == 0 && best.refusal.empty();
    if (better) {
      best_stable = stable;
      best = std::move(e);
      best_fit = f;
      best_tau = grid[g];
    }
  }
  CTID_REQUIRE(best.model.nx() > 0 || !best.refusal.empty(), "subspace: no tau of the grid gave a model ({})",
               last_problem);
  if (search_beginning) {  // the chosen tau on the whole record
    best = estimate_at(data, scale, options, r, best_tau);
    if (best.refusal.empty()) best_fit = fits_of(best.model, data, scale, best.x0, n_free(best.model.nx()));
  }

  if (!best.refusal.empty()) {
    res.summary.termination = Termination::NumericalFailure;
    res.summary.message = "subspace: " + best.refusal;
    res.diagnostics.set(diagnostic::singular_values, best.sigma);
    res.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return res;
  }
  const StateSpace& m = best.model;
  const ss_detail::Fits& f = best_fit;
  res.model = m;
  auto add = [&](const std::string& name, const Eigen::MatrixXd& M) {
    for (Eigen::Index i = 0; i < M.rows(); ++i)
      for (Eigen::Index j = 0; j < M.cols(); ++j) {
        res.parameters.names.push_back(name + std::to_string(i + 1) + "_" + std::to_string(j + 1));
        res.parameters.fixed.push_back(false);
      }
  };
  add("A", m.A());
  add("B", m.B());
  add("C", m.C());
  if (options.estimate_d) add("D", m.D());
  std::vector<double> v;
  for (const Eigen::MatrixXd* M : {&m.A(), &m.B(), &m.C()})
    for (Eigen::Index i = 0; i < M->rows(); ++i)
      for (Eigen::Index j = 0; j < M->cols(); ++j) v.push_back((*M)(i, j));
  if (options.estimate_d)
    for (Eigen::Index i = 0; i < ny; ++i)
      for (Eigen::Index j = 0; j < nu; ++j) v.push_back(m.D()(i, j));
  res.parameters.values = Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
  res.parameters.std = Eigen::VectorXd::Constant(res.parameters.values.size(), std::numeric_limits<double>::quiet_NaN());
  res.fit = f.all;
  res.diagnostics.set(diagnostic::singular_values, best.sigma);
  res.diagnostics.set(diagnostic::output_fit_percent, f.per_output);
  res.diagnostics.set(diagnostic::x0, best.x0);
  if (options.route == SubspaceRoute::Lambda) {
    res.diagnostics.set(diagnostic::tau, best_tau);
    if (grid.size() > 1) {
      res.diagnostics.set(diagnostic::tau_grid, Eigen::Map<const Eigen::VectorXd>(grid.data(), static_cast<Eigen::Index>(grid.size())));
      res.diagnostics.set(diagnostic::tau_grid_fit_percent, grid_fit);
    }
  }
  int unstable = 0;
  for (const auto& p : m.poles()) unstable += p.real() >= 0.0;
  if (unstable > 0)
    res.diagnostics.warnings.push_back(detail::format("the model has {} pole(s) in the right half plane (a subspace "
                                                      "estimate is not constrained to be stable)", unstable));
  res.summary.termination = Termination::Completed;
  res.summary.iterations = 1;
  res.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return res;
}

}  // namespace ctid
