// ctid — continuous-time state space from frequency-response data: subspace(FrequencyData)
// (estimate/state_space/subspace.hpp) and ssest(FrequencyData) (estimate/state_space/ssest.hpp).
//
// Start: McKelvey, Akçay & Ljung (1996), "Subspace-based multivariable system identification from frequency
// response data", IEEE Trans. Autom. Control 41(7), 960-979, Algorithm 2 (arbitrarily spaced frequencies), on the
// unit circle reached by the bilinear map z = (alpha + s)/(alpha - s) (their §V for continuous-time models:
// the map is exact for frequency responses, so G_c(j w_k) = G_d(z_k) with z_k = (alpha + j w_k)/(alpha - j w_k)).
// With the block rows z^i G_k (i < q) and z^i I of the inputs, Y = O X + Gamma U (their eq. 16); the inputs are
// projected out of the real-valued [Re, Im] stacking by an LQ factorisation, the range of O is the dominant left
// singular subspace, A_d follows from shift invariance and C_d is the first block row. Back to continuous time:
// A = alpha (A_d + I)^-1 (A_d - I), C = C_d (A_d + I)^-1 (up to a scale that B absorbs); B, D by linear least
// squares in continuous time, G_k = C (j w_k I - A)^-1 B + D (weighted by the data's variances when given).
//
// Refinement: V = 1/2 sum_k sum_ij 2 |G_ij(j w_k) - Ghat_ij(j w_k)|^2 / var_kij — the Gaussian maximum-likelihood
// criterion for independent circular complex errors of variance var_kij = E|G_hat - G|^2 (Pintelon & Schoukens 2012,
// "System Identification: A Frequency Domain Approach", 2nd ed., §7.2 and §9.11: the nonparametric FRF with its
// sample variance as weight). Without variances the variance of each output's entries is estimated from the
// residuals (and the search repeated once when it moved by more than 10 %, as for time-domain data). The same full
// parametrisation in data-driven local coordinates as time-domain ssest (McKelvey, Helmersson & Ribarits 2004,
// eqs 9-12), re-centred every 5 iterations with the states balanced by the Gramian sum_k Re P_k P_k^H,
// P_k = (j w_k I - A)^-1 B; exact derivatives dG = dC P + C R dA P + C R dB + dD (R = (j w_k I - A)^-1), accumulated
// into the normal equations frequency by frequency (memory O(parameters^2)). Covariance (J^T W J)^-1, multiplied
// by the weighted residual sum of squares per degree of freedom when that exceeds 1 (given variances that miss a
// systematic error: a nonlinear distortion of one realisation, too low an order).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>

#include "ctid/core/check.hpp"
#include "ctid/core/error.hpp"
#include "ctid/estimate/state_space/ssest.hpp"
#include "ctid/estimate/state_space/subspace.hpp"
#include "ctid/validate/metrics.hpp"
#include "ctid/validate/uncertainty.hpp"
#include "estimate/state_space/state_space_common.hpp"
#include "internal/levenberg_marquardt.hpp"

namespace ctid {

namespace {

using namespace ss_detail;
using cd = std::complex<double>;
using Clock = std::chrono::steady_clock;

// The data as the estimators see them: G scaled to G_s = diag(1/sy) G diag(su) (every output and input of
// comparable size) and the square roots of the weights of the real and imaginary parts, sqrt(2 / var) (scaled units).
struct Fd {
  Eigen::VectorXd w;
  std::vector<Eigen::MatrixXcd> G;
  std::vector<Eigen::MatrixXd> sw;
  Eigen::VectorXd sy, su;
  bool given = false;  // the weights come from the data's variances
  int M = 0, ny = 0, nu = 0;
};

Fd scaled_data(const FrequencyData& d, bool use_variance) {
  Fd f;
  f.w = d.w();
  f.M = d.size();
  f.ny = d.outputs();
  f.nu = d.inputs();
  f.sy = Eigen::VectorXd::Ones(f.ny);
  f.su = Eigen::VectorXd::Ones(f.nu);
  auto rms_rows = [&](const std::vector<Eigen::MatrixXcd>& G) {
    Eigen::VectorXd s = Eigen::VectorXd::Zero(f.ny);
    for (const auto& g : G) s += g.cwiseAbs2().rowwise().sum();
    return (s / (f.M * f.nu)).cwiseSqrt().eval();
  };
  const Eigen::VectorXd r = rms_rows(d.matrices());
  for (int i = 0; i < f.ny; ++i) f.sy(i) = r(i) > 0 && std::isfinite(r(i)) ? r(i) : 1.0;
  Eigen::VectorXd c = Eigen::VectorXd::Zero(f.nu);
  for (const auto& g : d.matrices()) c += (f.sy.cwiseInverse().asDiagonal() * g).cwiseAbs2().colwise().sum().transpose();
  c = (c / (f.M * f.ny)).cwiseSqrt();
  for (int j = 0; j < f.nu; ++j) f.su(j) = c(j) > 0 && std::isfinite(c(j)) ? 1.0 / c(j) : 1.0;
  f.given = use_variance && !d.variance().empty();
  for (int k = 0; k < f.M; ++k) {
    const Eigen::MatrixXcd& g = d.matrices()[static_cast<size_t>(k)];
    f.G.push_back(f.sy.cwiseInverse().asDiagonal() * g * f.su.asDiagonal());
    Eigen::MatrixXd s = Eigen::MatrixXd::Ones(f.ny, f.nu);
    if (f.given)
      for (int i = 0; i < f.ny; ++i)
        for (int j = 0; j < f.nu; ++j)
          s(i, j) = std::sqrt(2.0 / (d.variance()[static_cast<size_t>(k)](i, j) * f.su(j) * f.su(j) / (f.sy(i) * f.sy(i))));
    f.sw.push_back(s);
  }
  return f;
}

// The same data in the user's units (scales 1), the weights carried over.
Fd user_units(const Fd& f) {
  Fd u = f;
  for (int k = 0; k < f.M; ++k) {
    u.G[static_cast<size_t>(k)] = f.sy.asDiagonal() * f.G[static_cast<size_t>(k)] * f.su.cwiseInverse().asDiagonal();
    for (int i = 0; i < f.ny; ++i)
      for (int j = 0; j < f.nu; ++j) u.sw[static_cast<size_t>(k)](i, j) *= f.su(j) / f.sy(i);
  }
  u.sy.setOnes();
  u.su.setOnes();
  return u;
}

// Per-output weights sqrt(2 / var_i), var_i the mean |e|^2 of output i's entries.
void estimate_weights(Fd& f, const std::vector<Eigen::MatrixXcd>& E) {
  Eigen::VectorXd v = Eigen::VectorXd::Zero(f.ny);
  for (const auto& e : E) v += e.cwiseAbs2().rowwise().sum();
  v /= static_cast<double>(f.M * f.nu);
  const double floor = 1e-24 * std::max(v.maxCoeff(), 1e-300);
  for (auto& s : f.sw)
    for (int i = 0; i < f.ny; ++i) s.row(i).setConstant(std::sqrt(2.0 / std::max(v(i), floor)));
}

// R B, C R and G = C R B + D at one frequency (R = (j w I - A)^-1). False when j w I - A is singular.
struct Response {
  Eigen::MatrixXcd P, Q, G;
};
bool response(const Point& m, double w, Response& out) {
  const Eigen::Index n = m.A.rows();
  Eigen::MatrixXcd S = -m.A.cast<cd>();
  S.diagonal().array() += cd(0.0, w);
  const Eigen::PartialPivLU<Eigen::MatrixXcd> lu(S);
  const Eigen::MatrixXcd R = lu.inverse();
  if (!R.allFinite() || n == 0) return n == 0;
  out.P = R * m.B.cast<cd>();
  out.Q = m.C.cast<cd>() * R;
  out.G = m.C.cast<cd>() * out.P + m.D.cast<cd>();
  return out.G.allFinite();
}

// The errors G_k - Ghat_k of a model (false when a response is not finite).
bool errors(const Point& m, const Fd& f, std::vector<Eigen::MatrixXcd>& E) {
  E.clear();
  Response r;
  for (int k = 0; k < f.M; ++k) {
    if (!response(m, f.w(k), r)) return false;
    E.push_back(f.G[static_cast<size_t>(k)] - r.G);
  }
  return true;
}

// The weighted cost 1/2 sum r^2 (r = sw Re e, sw Im e) and, with JtJ/Jtr, the normal equations in the directions
// `dirs` (columns in pack's layout of the entries of A, B, C, D). The derivative in direction d is
// dG = dC P + Q dA P + Q dB + dD (P = R B, Q = C R): with the directions' blocks stacked (dA_d one below the other,
// and so on) the whole Jacobian of a frequency is three matrix products.
bool evaluate(const Point& m, const Fd& f, const Layout& L, const Eigen::MatrixXd* dirs, double& cost,
              Eigen::MatrixXd* JtJ, Eigen::VectorXd* Jtr) {
  const int ny = f.ny, nu = f.nu, nx = L.nx;
  const bool sens = dirs && JtJ && Jtr;
  const Eigen::Index p = sens ? dirs->cols() : 0, rows = 2 * ny * nu;
  cost = 0.0;
  Eigen::MatrixXcd SA, SC;
  Eigen::MatrixXd SB, SD;
  if (sens) {
    JtJ->setZero(p, p);
    Jtr->setZero(p);
    SA.resize(nx * p, nx);
    SB.resize(nx * p, nu);
    SC.resize(ny * p, nx);
    SD.resize(ny * p, nu);
    for (Eigen::Index d = 0; d < p; ++d) {
      const Point q = unpack(L, dirs->col(d));
      SA.middleRows(d * nx, nx) = q.A.cast<cd>();
      SB.middleRows(d * nx, nx) = q.B;
      SC.middleRows(d * ny, ny) = q.C.cast<cd>();
      SD.middleRows(d * ny, ny) = q.D;
    }
  }
  Eigen::MatrixXd Jk(rows, p);
  Eigen::MatrixXcd W, V, dG;
  Eigen::VectorXd rk(rows);
  Response r;
  for (int k = 0; k < f.M; ++k) {
    if (!response(m, f.w(k), r)) return false;
    const Eigen::MatrixXd& sw = f.sw[static_cast<size_t>(k)];
    const Eigen::MatrixXcd e = f.G[static_cast<size_t>(k)] - r.G;
    for (int i = 0; i < ny; ++i)
      for (int j = 0; j < nu; ++j) {
        const Eigen::Index row = 2 * (i * nu + j);
        rk(row) = sw(i, j) * e(i, j).real();
        rk(row + 1) = sw(i, j) * e(i, j).imag();
      }
    cost += 0.5 * rk.squaredNorm();
    if (!sens) continue;
    W.noalias() = SA * r.P;  // dA_d P, stacked
    W += SB.cast<cd>();
    V.noalias() = SC * r.P;  // dC_d P, stacked
    for (int j = 0; j < nu; ++j) {
      dG.noalias() = r.Q * Eigen::Map<const Eigen::MatrixXcd>(W.col(j).data(), nx, p);
      dG += Eigen::Map<const Eigen::MatrixXcd>(V.col(j).data(), ny, p);
      dG += Eigen::Map<const Eigen::MatrixXd>(SD.col(j).data(), ny, p).cast<cd>();
      for (int i = 0; i < ny; ++i) {
        const Eigen::Index row = 2 * (i * nu + j);
        Jk.row(row) = -sw(i, j) * dG.row(i).real();
        Jk.row(row + 1) = -sw(i, j) * dG.row(i).imag();
      }
    }
    JtJ->selfadjointView<Eigen::Lower>().rankUpdate(Jk.transpose());
    Jtr->noalias() += Jk.transpose() * rk;
  }
  if (sens) *JtJ = JtJ->selfadjointView<Eigen::Lower>();
  return std::isfinite(cost) && (!sens || (JtJ->allFinite() && Jtr->allFinite()));
}

// The model in state coordinates balanced over the data's frequencies: x = L z with L L^T = sum_k Re P_k P_k^H / M.
Point balanced(const Point& m, const Fd& f) {
  const Eigen::Index nx = m.A.rows();
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(nx, nx);
  Response r;
  for (int k = 0; k < f.M; ++k) {
    if (!response(m, f.w(k), r)) return m;
    W += (r.P * r.P.adjoint()).real();
  }
  W /= f.M;
  Eigen::LLT<Eigen::MatrixXd> llt(W + 1e-12 * std::max(W.trace(), 1e-300) * Eigen::MatrixXd::Identity(nx, nx));
  if (llt.info() != Eigen::Success || !W.allFinite()) return m;
  return transformed(m, llt.matrixL());
}

void check_data(const FrequencyData& d, const char* who) {
  CTID_REQUIRE(d.size() >= 1 && d.outputs() >= 1 && d.inputs() >= 1, "{}: the frequency data are empty", who);
}

// B and D for given A, C: min sum_k sum_ij w_kij |G_kij - (C R_k B + D)_ij|^2, column by column of (B; D).
bool fit_bd(const Eigen::MatrixXd& A, const Eigen::MatrixXd& C, const Fd& f, bool estimate_d, Point& out) {
  const Eigen::Index nx = A.rows(), ny = f.ny, nu = f.nu, p = nx + (estimate_d ? ny : 0);
  CTID_REQUIRE(2 * f.M * ny > p, "subspace: {} frequencies of {} outputs cannot determine the {} values of each column "
               "of B and D", f.M, ny, p);
  std::vector<Eigen::MatrixXcd> Phi;
  for (int k = 0; k < f.M; ++k) {
    Eigen::MatrixXcd S = -A.cast<cd>();
    S.diagonal().array() += cd(0.0, f.w(k));
    Phi.push_back(C.cast<cd>() * Eigen::PartialPivLU<Eigen::MatrixXcd>(S).inverse());
    if (!Phi.back().allFinite()) return false;
  }
  out = Point{A, Eigen::MatrixXd(nx, nu), C, Eigen::MatrixXd::Zero(ny, nu), {}, {}};
  Eigen::MatrixXd X(2 * f.M * ny, p);
  Eigen::VectorXd y(2 * f.M * ny);
  for (Eigen::Index j = 0; j < nu; ++j) {
    X.setZero();
    for (int k = 0; k < f.M; ++k)
      for (Eigen::Index i = 0; i < ny; ++i) {
        const double s = f.sw[static_cast<size_t>(k)](i, j);
        const Eigen::Index row = 2 * (k * ny + i);
        X.row(row).head(nx) = s * Phi[static_cast<size_t>(k)].row(i).real();
        X.row(row + 1).head(nx) = s * Phi[static_cast<size_t>(k)].row(i).imag();
        if (estimate_d) X(row, nx + i) = s;
        y(row) = s * f.G[static_cast<size_t>(k)](i, j).real();
        y(row + 1) = s * f.G[static_cast<size_t>(k)](i, j).imag();
      }
    const Eigen::VectorXd theta = X.colPivHouseholderQr().solve(y);
    out.B.col(j) = theta.head(nx);
    if (estimate_d) out.D.col(j) = theta.tail(ny);
  }
  return out.B.allFinite() && out.D.allFinite();
}

// The fits of a model (user units): each output 100 (1 - ||G_i - Ghat_i|| / ||G_i||) over its entries and
// frequencies; all outputs together in the scaled units.
ss_detail::Fits frequency_fits(const Point& m_user, const Fd& f, int n_parameters) {
  ss_detail::Fits out;
  out.per_output = Eigen::VectorXd::Constant(f.ny, -INFINITY);
  out.all.fit_percent = -INFINITY;
  out.all.n_samples = 2 * f.M * f.ny * f.nu;
  out.all.n_parameters = n_parameters;
  std::vector<Eigen::MatrixXcd> E;
  const Point ms = scaled(m_user, f.su, f.sy);
  if (!errors(ms, f, E)) return out;
  Eigen::VectorXd en = Eigen::VectorXd::Zero(f.ny), gn = Eigen::VectorXd::Zero(f.ny);
  for (int k = 0; k < f.M; ++k) {
    en += E[static_cast<size_t>(k)].cwiseAbs2().rowwise().sum();
    gn += f.G[static_cast<size_t>(k)].cwiseAbs2().rowwise().sum();
  }
  // Scaling a row by 1/sy_i and the columns by su_j: each output's ratio changes only through the column scales.
  for (int i = 0; i < f.ny; ++i) {
    double e2 = 0.0, g2 = 0.0;
    for (int k = 0; k < f.M; ++k)
      for (int j = 0; j < f.nu; ++j) {
        const double c = 1.0 / (f.su(j) * f.su(j));
        e2 += c * std::norm(E[static_cast<size_t>(k)](i, j));
        g2 += c * std::norm(f.G[static_cast<size_t>(k)](i, j));
      }
    out.per_output(i) = g2 > 0 ? 100.0 * (1.0 - std::sqrt(e2 / g2)) : -INFINITY;
  }
  const int N = out.all.n_samples;
  out.all.mse = en.sum() / N;
  out.all.nrmse = std::sqrt(en.sum() / std::max(gn.sum(), 1e-300));
  out.all.fit_percent = 100.0 * (1.0 - out.all.nrmse);
  out.all.fpe = fpe(out.all.mse, N, n_parameters);
  out.all.aic = aic(out.all.mse, N, n_parameters);
  out.all.aicc = aicc(out.all.mse, N, n_parameters);
  out.all.bic = bic(out.all.mse, N, n_parameters);
  return out;
}

// The subspace estimate of A and C (continuous time) at order nx (0: the largest gap of the singular values).
struct FdStart {
  Point point;
  Eigen::VectorXd sigma;
  double alpha = 0.0;
  std::string refusal;
};

FdStart frequency_subspace(const Fd& f, const SubspaceOptions& o) {
  const int ny = f.ny, nu = f.nu, M = f.M;
  FdStart s;
  s.alpha = o.tau > 0 ? 1.0 / o.tau : std::sqrt(f.w(0) * f.w(M - 1));
  const int q = o.horizon > 0 ? o.horizon : o.nx > 0 ? std::max(2 * o.nx, o.nx + 2) : 20;
  CTID_REQUIRE(o.nx == 0 || (q - 1) * ny >= o.nx,
               "subspace: nx = {} needs (horizon - 1) * outputs >= nx (horizon {}, {} outputs)", o.nx, q, ny);
  const Eigen::Index cols = 2 * static_cast<Eigen::Index>(M) * nu, ru = q * nu, ryr = q * ny;
  CTID_REQUIRE(cols >= ru + ryr,
               "subspace: {} frequencies with {} input(s) are too few for horizon {} with {} outputs (at least {} "
               "frequencies)", M, nu, q, ny, (ru + ryr + 2 * nu - 1) / (2 * nu));
  // [U; Y] real-valued: block column k = [z_k^i I; z_k^i G_k] (i < q), real parts then imaginary parts.
  Eigen::MatrixXd H(ru + ryr, cols);
  for (int k = 0; k < M; ++k) {
    const cd z = (cd(s.alpha, f.w(k))) / (cd(s.alpha, -f.w(k)));
    cd zi = 1.0;
    for (int i = 0; i < q; ++i) {
      const Eigen::MatrixXcd Ub = zi * Eigen::MatrixXcd::Identity(nu, nu), Yb = zi * f.G[static_cast<size_t>(k)];
      H.block(i * nu, k * nu, nu, nu) = Ub.real();
      H.block(i * nu, (M + k) * nu, nu, nu) = Ub.imag();
      H.block(ru + i * ny, k * nu, ny, nu) = Yb.real();
      H.block(ru + i * ny, (M + k) * nu, ny, nu) = Yb.imag();
      zi *= z;
    }
  }
  // LQ: H = L Q^T; the inputs projected out of Y leave L22 (Y's rows, the columns after U's).
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(H.transpose());
  const Eigen::MatrixXd R = qr.matrixQR().topRows(ru + ryr).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd L22 = R.bottomRightCorner(ryr, ryr).transpose();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(L22, Eigen::ComputeThinU);
  s.sigma = svd.singularValues();
  int nx = o.nx;
  if (nx == 0) {
    double best = 0.0;
    for (int n = 1; n < std::min<int>(static_cast<int>(s.sigma.size()) - 1, (q - 1) * ny); ++n) {
      const double ratio = s.sigma(n - 1) / std::max(s.sigma(n), 1e-300 * s.sigma(0));
      if (ratio > best) best = ratio, nx = n;
    }
    nx = std::max(nx, 1);
  }
  const Eigen::MatrixXd O = svd.matrixU().leftCols(nx);
  const Eigen::MatrixXd Ad = shift_invariance(O, ny), Cd = O.topRows(ny);
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(nx, nx);
  const Eigen::PartialPivLU<Eigen::MatrixXd> plus(Ad + I);
  const Eigen::VectorXcd ld = Ad.eigenvalues();
  for (Eigen::Index i = 0; i < ld.size(); ++i)
    if (std::abs(ld(i) + 1.0) < 1e-10) {
      s.refusal = "the discrete estimate has a pole at z = -1 (an infinite continuous-time frequency); try another tau";
      return s;
    }
  Eigen::MatrixXd A = s.alpha * plus.solve(Ad - I);
  const Eigen::MatrixXd C = (Ad + I).transpose().partialPivLu().solve(Cd.transpose()).transpose();  // Cd (Ad + I)^-1
  if (o.stabilize) A = reflected_into_left_half_plane(A);
  if (!fit_bd(A, C, f, o.estimate_d, s.point)) s.refusal = "B and D could not be estimated (a pole on the imaginary axis "
                                                           "at a data frequency)";
  return s;
}

int free_count(int nx, int nu, int ny, bool d) { return nx * (nu + ny) + (d ? ny * nu : 0); }

}  // namespace

Result<StateSpace> subspace(const FrequencyData& data, const SubspaceOptions& options) {
  const auto t0 = Clock::now();
  options.validate();
  check_data(data, "subspace");
  CTID_REQUIRE_OPTION(options.route == SubspaceRoute::Lambda,
                      "subspace: route=discrete applies to time-domain records; frequency data use the bilinear map "
                      "(route=lambda, tau = 1/alpha)");
  const Fd f = scaled_data(data, true);
  const FdStart s = frequency_subspace(f, options);
  Result<StateSpace> res;
  res.diagnostics.set(diagnostic::singular_values, s.sigma);
  res.diagnostics.set(diagnostic::frequency_scale, s.alpha);
  auto finish = [&] { res.summary.seconds = std::chrono::duration<double>(Clock::now() - t0).count(); };
  if (!s.refusal.empty()) {
    res.summary.termination = Termination::NumericalFailure;
    res.summary.message = "subspace: " + s.refusal;
    finish();
    return res;
  }
  const Point m = unscaled(s.point, f.su, f.sy);
  const int nx = static_cast<int>(m.A.rows());
  res.model = StateSpace(m.A, m.B, m.C, m.D);
  std::vector<double> v;
  auto add = [&](char name, const Eigen::MatrixXd& X) {
    for (int i = 0; i < X.rows(); ++i)
      for (int j = 0; j < X.cols(); ++j) {
        res.parameters.names.push_back(entry_name(name, i, j));
        res.parameters.fixed.push_back(false);
        v.push_back(X(i, j));
      }
  };
  add('A', m.A);
  add('B', m.B);
  add('C', m.C);
  if (options.estimate_d) add('D', m.D);
  res.parameters.values = Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
  res.parameters.std = Eigen::VectorXd::Constant(res.parameters.values.size(), NAN);
  const ss_detail::Fits fits = frequency_fits(m, f, free_count(nx, f.nu, f.ny, options.estimate_d));
  res.fit = fits.all;
  res.diagnostics.set(diagnostic::output_fit_percent, fits.per_output);
  int unstable = 0;
  for (const auto& p : res.model.poles()) unstable += p.real() >= 0.0;
  if (unstable > 0)
    res.diagnostics.warnings.push_back(detail::format("the model has {} pole(s) in the right half plane (a subspace "
                                                      "estimate is not constrained to be stable)", unstable));
  res.summary.termination = Termination::Completed;
  res.summary.iterations = 1;
  finish();
  return res;
}

namespace {

Result<StateSpace> fit_frequency_from(const Fd& f0, Point start, const Eigen::VectorXd& sigma,
                                      double alpha, double start_fit, const SsestOptions& o, Clock::time_point t0) {
  const int nx = static_cast<int>(start.A.rows()), nu = f0.nu, ny = f0.ny;
  const Layout L{nx, nu, ny, 0};
  Fd f = f0;
  std::vector<bool> held(static_cast<size_t>(L.size()), false);
  std::vector<std::string> names;
  for (int i = 0; i < ny; ++i)
    for (int j = 0; j < nu; ++j) names.push_back(entry_name('D', i, j));
  const ParameterConstraints c = resolve_constraints(
      o.fixed, {}, names, "ssest", "an entry of D of this model (with frequency data the modal form is returned)");
  if (!o.estimate_d) start.D.setZero();
  for (int i = 0; i < ny; ++i)
    for (int j = 0; j < nu; ++j) {
      const size_t k = static_cast<size_t>(i * nu + j);
      if (!o.estimate_d || c.held[k]) {
        held[static_cast<size_t>(L.d(i, j))] = true;
        if (c.held[k]) start.D(i, j) = c.value(static_cast<Eigen::Index>(k));
      }
    }
  Point s = balanced(scaled(start, f.su, f.sy), f);
  int similar = 0;
  (void)local_directions(L, s, held, &similar);
  std::vector<Eigen::MatrixXcd> E;
  Result<StateSpace> res;
  auto finish = [&] { res.summary.seconds = std::chrono::duration<double>(Clock::now() - t0).count(); };
  if (sigma.size() > 0) res.diagnostics.set(diagnostic::singular_values, sigma);
  if (alpha > 0) res.diagnostics.set(diagnostic::frequency_scale, alpha);
  if (std::isfinite(start_fit)) res.diagnostics.set(diagnostic::start_fit_percent, start_fit);
  if (!errors(s, f, E)) {
    res.model = StateSpace(start.A, start.B, start.C, start.D);
    res.summary.termination = Termination::NumericalFailure;
    res.summary.message = "ssest: the starting model has a pole on the imaginary axis at a data frequency";
    finish();
    return res;
  }
  if (!f.given) estimate_weights(f, E);

  // Rounds of LM in local coordinates re-centred (and balanced) after each round; without given variances the
  // weights re-estimated at the optimum and the search repeated once when they moved by more than 10 %.
  const bool check_stability = o.enforce_stability && stable(s.A, 0);
  internal::LmOptions lmo;
  lmo.xtol = 1e-10;
  int left = o.max_iterations, iterations = 0;
  internal::LmResult last;
  Eigen::VectorXd theta = pack(L, s);
  for (int pass = 0; pass < 2; ++pass) {
    const Rounds r = lm_rounds(
        L, theta, held, check_stability, 0, o.tolerance, left, lmo, [&](const Point& m) { return balanced(m, f); },
        [&](const Eigen::MatrixXd& Q) {
          return [&f, &L, &Q](const Point& m, double& v, Eigen::MatrixXd* A, Eigen::VectorXd* g) {
            return evaluate(m, f, L, A ? &Q : nullptr, v, A, g);
          };
        });
    theta = r.theta;
    iterations += r.iterations;
    last = r.last;
    if (f.given || last.interrupted || !r.converged || pass == 1) break;
    const std::vector<Eigen::MatrixXd> before = f.sw;
    if (!errors(unpack(L, theta), f, E)) break;
    estimate_weights(f, E);
    double change = 0.0;
    for (int i = 0; i < ny; ++i) {
      const double a = before.front()(i, 0), b = f.sw.front()(i, 0);
      change = std::max(change, std::abs(b * b - a * a) / (a * a));
    }
    if (change < 0.1) break;
  }
  internal::set_termination(res.summary, last);
  res.summary.iterations = iterations;

  // The result in the user's units: modal form, covariance, fits, modes.
  Point fin = unscaled(unpack(L, theta), f.su, f.sy);
  describe(res, fin, L, held, false, 0, o.estimate_d);
  const Fd fu = user_units(f);
  const std::vector<StateSpaceDirection> pdirs = state_space_directions(res.model, res.parameters);
  std::vector<int> slots;
  const Layout Lu{nx, nu, ny, 0};
  for (size_t k = 0; k < pdirs.size(); ++k)
    if (!res.parameters.fixed[k]) slots.push_back(static_cast<int>(k));
  const int np = static_cast<int>(slots.size());
  Eigen::MatrixXd dirs(Lu.size(), np);
  for (int k = 0; k < np; ++k) {
    const StateSpaceDirection& d = pdirs[static_cast<size_t>(slots[static_cast<size_t>(k)])];
    dirs.col(k) = pack(Lu, Point{d.dA, d.dB, d.dC, d.dD, {}, {}});
  }
  Eigen::MatrixXd JtJ;
  Eigen::VectorXd Jtr;
  double cost = 0.0;
  const bool ok = evaluate(fin, fu, Lu, &dirs, cost, &JtJ, &Jtr);
  const int n_free = static_cast<int>(std::count(held.begin(), held.end(), false)) - similar;
  const double dof = 2.0 * f.M * ny * nu - n_free;
  const double chi2 = dof > 0 ? 2.0 * cost / dof : INFINITY;
  Eigen::MatrixXd cov;
  if (ok) cov = inverse_normal(JtJ, np);
  const double inflate = f.given ? std::max(1.0, chi2) : chi2;
  if (cov.size() > 0 && std::isfinite(inflate)) cov *= inflate;
  res.parameters.set_covariance(cov, slots);
  const ss_detail::Fits fits = frequency_fits(fin, f, n_free);
  res.fit = fits.all;
  res.diagnostics.set(diagnostic::output_fit_percent, fits.per_output);
  res.diagnostics.set(diagnostic::cost, cost);
  res.diagnostics.set(diagnostic::chi2_per_dof, chi2);
  if (f.given && chi2 > 2.0)
    res.diagnostics.warnings.push_back(detail::format(
        "the weighted residuals are {} times the variances given with the data: a systematic error (nonlinear "
        "distortion, too low an order) dominates; the covariance is multiplied by that factor (use_variance=false "
        "weights by the residuals instead)", chi2));
  report_modes(res);
  finish();
  return res;
}

void check_frequency_options(const SsestOptions& o) {
  CTID_REQUIRE_OPTION(o.integrators == 0, "ssest: integrators = {} with frequency data: hold the pole at 0 by fitting "
                                          "s G(jw) instead, or use time-domain records", o.integrators);
  CTID_REQUIRE_OPTION(o.starts == 1, "ssest: starts = {} with frequency data: multi-start searches records only",
                      o.starts);
  CTID_REQUIRE_OPTION(!o.estimate_k, "ssest: estimate_k with frequency data: an FRF carries no noise sequence to "
                                     "predict (use time-domain records for the prediction-error variant)");
  for (const auto& [name, v] : o.fixed)
    CTID_REQUIRE_OPTION(!name.empty() && name[0] == 'D',
                        "ssest: fixed.{}: with frequency data only entries of D can be held", name);
}

Result<StateSpace> frequency_order(const Fd& f, int nx, const SsestOptions& o,
                                   Clock::time_point t0) {
  SubspaceOptions so = o.start;
  so.nx = nx;
  so.estimate_d = o.estimate_d;
  const FdStart s = frequency_subspace(f, so);
  if (!s.refusal.empty()) {
    Result<StateSpace> r;
    r.summary.termination = Termination::NumericalFailure;
    r.summary.message = "ssest: the subspace start failed: " + s.refusal;
    r.diagnostics.set(diagnostic::singular_values, s.sigma);
    return r;
  }
  const Point start = unscaled(s.point, f.su, f.sy);
  const double start_fit = frequency_fits(start, f, 0).all.fit_percent;
  return fit_frequency_from(f, start, s.sigma, s.alpha, start_fit, o, t0);
}

}  // namespace

Result<StateSpace> ssest(const FrequencyData& data, const SsestOptions& options) {
  const auto t0 = Clock::now();
  options.validate();
  check_data(data, "ssest");
  check_frequency_options(options);
  const Fd f = scaled_data(data, options.use_variance);
  if (options.nx_max <= options.nx || options.nx_max == 0) return frequency_order(f, options.nx, options, t0);
  Result<StateSpace> best = order_search(std::max(options.nx, 1), options.nx_max,
                                         [&](int n) { return frequency_order(f, n, options, t0); });
  best.summary.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return best;
}

Result<StateSpace> ssest(const FrequencyData& data, const StateSpace& initial, const SsestOptions& options) {
  const auto t0 = Clock::now();
  options.validate();
  check_data(data, "ssest");
  check_frequency_options(options);
  CTID_REQUIRE_OPTION(options.nx == 0 || options.nx == initial.nx(),
                      "ssest: nx = {} differs from the starting model's {} states", options.nx, initial.nx());
  CTID_REQUIRE_OPTION(options.nx_max == 0, "ssest: nx_max needs the subspace start (a starting model has one order)");
  CTID_REQUIRE(initial.nu() == data.inputs() && initial.ny() == data.outputs(),
               "ssest: the starting model has {} inputs and {} outputs, the data {} and {}", initial.nu(), initial.ny(),
               data.inputs(), data.outputs());
  CTID_REQUIRE(initial.nx() >= 1, "ssest: the starting model has no states");
  const Fd f = scaled_data(data, options.use_variance);
  const Point p{initial.A(), initial.B(), initial.C(), initial.D(), {}, {}};
  return fit_frequency_from(f, p, Eigen::VectorXd(), 0.0, frequency_fits(p, f, 0).all.fit_percent, options, t0);
}

}  // namespace ctid
