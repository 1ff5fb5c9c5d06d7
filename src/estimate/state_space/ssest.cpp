// ctid — ssest: output-error (and, with an innovation gain, prediction-error) refinement of a MIMO continuous-time
// state-space model (estimate/state_space/ssest.hpp). McKelvey, Helmersson & Ribarits (2004) eqs 9-12 (data-driven local
// coordinates of the full parametrisation); Ljung (1999) §4.3 eq. 4.84 (the innovation form), §7.4, §9.4 (the
// weighted output-error / ML criterion and its covariance); Van Loan (1978) block
// exponentials for the exact sensitivities; the subspace start of estimate/state_space/subspace.hpp (JVC 1999).
#include "ctid/estimate/state_space/ssest.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <limits>
#include <span>
#include <tuple>

#include "ctid/core/check.hpp"
#include "ctid/core/error.hpp"
#include "ctid/simulate/lsim.hpp"
#include "ctid/validate/metrics.hpp"
#include "ctid/validate/uncertainty.hpp"
#include "estimate/state_space/state_space_common.hpp"
#include "estimate/search.hpp"
#include "internal/coloured_covariance.hpp"
#include "internal/levenberg_marquardt.hpp"

namespace ctid {

template <>
const OptionTable<SsestOptions>& option_table<SsestOptions>() {
  using O = SsestOptions;
  static const OptionTable<O> t =
      OptionTable<O>("ssest")
          .integer("nx", &O::nx, "", or_special(at_least(1), 0, "the subspace start's choice"), "state dimension")
          .integer("nx_max", &O::nx_max, "", or_special(at_least(1), 0, "nx only"),
                   "with nx_max > nx: fit every order nx..nx_max and keep the least BIC")
          .integer("max_iterations", &O::max_iterations, "", at_least(1), "Levenberg-Marquardt iterations (all rounds)")
          .real("tolerance", &O::tolerance, "", above(0),
                "decrease of the cost (1/2 sum of squared errors in noise standard deviations) below which a round "
                "ends")
          .flag("estimate_d", &O::estimate_d, "estimate the direct term D (false: D = 0)")
          .flag("estimate_k", &O::estimate_k,
                "prediction-error variant: estimate an innovation gain K (coloured output noise with the plant's "
                "poles; false: output error)")
          .flag("estimate_initial_state", &O::estimate_initial_state,
                "estimate each record's initial state (false: it starts at rest)")
          .flag("enforce_stability", &O::enforce_stability,
                "keep a stable start stable: steps that move a pole into the right half plane are rejected (false: "
                "an unstable plant)")
          .flag("use_variance", &O::use_variance,
                "frequency data: weight by the variances given with them (false: estimate each output's error "
                "variance from the residuals)")
          .integer("integrators", &O::integrators, "", at_least(0),
                   "known pure integrators: poles held at 0 (the first states integrate)")
          .integer("starts", &O::starts, "", at_least(1),
                   "multi-start: the subspace start plus starts-1 with its poles moved within a decade (the usable fit "
                   "of least MSE wins)")
          .integer("seed", &O::seed, "", at_least(0), "seed of the drawn starts")
          .named_reals("fixed", &O::fixed,
                       "entries held at a value by name (fixed.D1_1=0; A, B, C entries with a starting model)")
          .include(&O::start, option_table<SubspaceOptions>(), {"horizon", "route", "tau", "stabilize"},
                   {{"horizon", "start_horizon"}, {"route", "start_route"}, {"tau", "start_tau"},
                    {"stabilize", "start_stabilize"}});
  return t;
}

void SsestOptions::validate() const {
  option_table<SsestOptions>().check(*this);
  start.validate();
  CTID_REQUIRE_OPTION(nx_max == 0 || nx_max >= std::max(nx, 1),
                      "ssest: nx_max = {} must be at least nx = {} (or 0: nx only)", nx_max, nx);
  CTID_REQUIRE_OPTION(nx_max == 0 || nx_max - std::max(nx, 1) <= 20, "ssest: nx_max - nx = {} orders are too many (at most 20)",
                      nx_max - std::max(nx, 1));
}

namespace {

using namespace ss_detail;
using Clock = std::chrono::steady_clock;
constexpr int kBatch = 128;  // samples gathered before one rank-k update of J^T W J
constexpr double kInitialDamping = 1e-6;  // Levenberg-Marquardt's first damping (see search())

// One record as the search sees it: inputs and outputs divided by the channel scales.
struct ScaledRecord {
  Eigen::MatrixXd u, y;
  Eigen::VectorXd t;
  bool uniform = true;
  double h = 0.0;
  std::vector<Intersample> intersample;  // of each input
};

std::vector<ScaledRecord> records_of(std::span<const IdData> ds, const Eigen::VectorXd& su, const Eigen::VectorXd& sy) {
  std::vector<ScaledRecord> out;
  for (const IdData& d : ds) {
    ScaledRecord r;
    r.u = d.u() * su.cwiseInverse().asDiagonal();
    r.y = d.y() * sy.cwiseInverse().asDiagonal();
    r.t = d.times();
    r.uniform = d.is_uniform();
    r.h = r.uniform && d.size() > 1 ? d.ts() : 0.0;
    for (int i = 0; i < d.nu(); ++i) r.intersample.push_back(d.intersample(i));
    out.push_back(std::move(r));
  }
  return out;
}

// The exact one-interval maps of the model and of its sensitivities in P directions (stacked: block d of W1 is
// nx x nx, of W2 and W3 nx x (nu + nk)); the inputs are [u; e], the innovation e held (prediction-error variant,
// nk = ny columns of K; nk = 0 for output error). With K: GK = the innovation's columns of G0 and PhiK = Phi - GK C,
// the predictor's state map.
struct Step {
  double h = -1.0;
  Eigen::MatrixXd Phi, G0, G1, W1, W2, W3, GK, PhiK;
};

// [B, K]: the input matrix of the inputs [u; e] (K empty: B; a direction without K: zeros for it).
Point with_innovation_input(const Point& p, Eigen::Index nk) {
  if (nk == 0) return p;
  Point q = p;
  q.B.conservativeResize(Eigen::NoChange, p.B.cols() + nk);
  q.B.rightCols(nk) = p.K.size() ? p.K : Eigen::MatrixXd::Zero(p.B.rows(), nk);
  return q;
}

// discretize(), without the linear-input block when every input is held (an exponential of size n + m instead of
// n + 2m: the irregular grids compute one per interval and direction).
Discretization exact_step(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, double h, bool any_foh) {
  if (any_foh) return discretize(A, B, h);
  const Eigen::Index n = A.rows(), m = B.cols();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + m, n + m);
  M.topLeftCorner(n, n) = A * h;
  M.topRightCorner(n, m) = B * h;
  const Eigen::MatrixXd E = expm(M);
  return {E.topLeftCorner(n, n), E.topRightCorner(n, m), Eigen::MatrixXd::Zero(n, m), h};
}

Step step_of(const Point& m, const std::vector<Point>& dirs, double h, const std::vector<Intersample>& is) {
  const Eigen::Index nx = m.A.rows(), nu = m.B.cols();
  const Eigen::Index P = static_cast<Eigen::Index>(dirs.size());
  auto foh = [&](Eigen::Index j) { return is[static_cast<size_t>(j)] != Intersample::Zoh; };
  bool any_foh = false;
  for (Eigen::Index j = 0; j < nu; ++j) any_foh = any_foh || foh(j);
  Step s;
  s.h = h;
  const Discretization base = exact_step(m.A, m.B, h, any_foh);
  s.Phi = base.Phi;
  s.G0 = base.Gamma0;
  s.G1 = base.Gamma1;
  for (Eigen::Index j = 0; j < nu; ++j)
    if (!foh(j)) s.G1.col(j).setZero();
  s.W1.setZero(nx * P, nx);
  s.W2.setZero(nx * P, nu);
  s.W3.setZero(nx * P, nu);
  Eigen::MatrixXd Ab = Eigen::MatrixXd::Zero(2 * nx, 2 * nx), Bb(2 * nx, nu);
  Ab.topLeftCorner(nx, nx) = m.A;
  Ab.bottomRightCorner(nx, nx) = m.A;
  Bb.topRows(nx) = m.B;
  for (Eigen::Index d = 0; d < P; ++d) {
    const Point& q = dirs[static_cast<size_t>(d)];
    if (q.A.isZero(0) && q.B.isZero(0)) continue;  // a direction of C, D or x0 only: no forcing of the state
    Ab.bottomLeftCorner(nx, nx) = q.A;
    Bb.bottomRows(nx) = q.B;
    const Discretization a = exact_step(Ab, Bb, h, any_foh);  // Van Loan: the sensitivity blocks of the exponential
    s.W1.middleRows(d * nx, nx) = a.Phi.bottomLeftCorner(nx, nx);
    s.W2.middleRows(d * nx, nx) = a.Gamma0.bottomRows(nx);
    s.W3.middleRows(d * nx, nx) = a.Gamma1.bottomRows(nx);
    for (Eigen::Index j = 0; j < nu; ++j)
      if (!foh(j)) s.W3.block(d * nx, j, nx, 1).setZero();
  }
  return s;
}

// The weighted output-error cost 1/2 sum w_j e_j^2 of every record (sw = sqrt(w)); with JtJ/Jtr the normal equations
// of the directions `dirs` (J = d e / d direction); with yhat each record's simulated outputs. False when a
// simulation overflows. The record is processed kBatch samples at a time: the model's states of a batch first (a
// cheap recursion), then the sensitivities' forcing and output terms of the whole batch as matrix products, the
// sensitivity recursion dX_{k+1} = Phi dX_k + F_k, and one rank-k update of J^T W J.
//
// With an innovation gain K the residuals are the one-step prediction errors e_k = y_k - C x_k - D u_k of the
// predictor x_{k+1} = Phi x_k + Gamma_u u_k + GK e_k (predict() in simulate/lsim.hpp), and the sensitivities follow
// dX_{k+1} = PhiK dX_k + F_k - GK (dC x_k + dD u_k), F_k the forcing by [u; e] (the recursion of the prediction
// error's own sensitivity -(C dX_k + dC x_k + dD u_k)).
// For the coloured-noise covariance (internal/coloured_covariance.hpp), `acov` collects each output's weighted residuals
// and `grams` each output's Jacobian rows (needs JtJ), every record one sequence.
bool evaluate(const Point& m0, const std::vector<Point>* dirs0, const std::vector<ScaledRecord>& recs, const Eigen::VectorXd& sw,
              double& cost, Eigen::MatrixXd* JtJ, Eigen::VectorXd* Jtr, std::vector<Eigen::MatrixXd>* yhat = nullptr,
              std::vector<internal::ResidualAutocovariance>* acov = nullptr,
              std::vector<internal::ColouredGram>* grams = nullptr) {
  const Eigen::Index nx = m0.A.rows(), nu = m0.B.cols(), ny = m0.C.rows(), nk = m0.K.size() ? ny : 0;
  const bool sens = dirs0 && JtJ && Jtr;
  const Eigen::Index P = sens ? static_cast<Eigen::Index>(dirs0->size()) : 0;
  const Point m = with_innovation_input(m0, nk);
  std::vector<Point> augmented;
  if (sens && nk > 0)
    for (const Point& d : *dirs0) augmented.push_back(with_innovation_input(d, nk));
  const std::vector<Point>* dirs = nk > 0 && sens ? &augmented : dirs0;
  const std::vector<Point> none;
  cost = 0.0;
  if (sens) {
    JtJ->setZero(P, P);
    Jtr->setZero(P);
  }
  if (yhat) yhat->clear();
  Eigen::MatrixXd dCs(ny * P, nx), dDs(ny * P, nu);
  for (Eigen::Index d = 0; d < P; ++d) {
    dCs.middleRows(d * ny, ny) = (*dirs)[static_cast<size_t>(d)].C;
    dDs.middleRows(d * ny, ny) = (*dirs)[static_cast<size_t>(d)].D;
  }
  // Per batch: states X, inputs U and their changes dU to the next sample, weighted residuals R, sensitivity states
  // (Dall: the nx x P block of each sample side by side), forcing F, output terms G, J rows.
  Eigen::MatrixXd X(nx, kBatch), U(nu, kBatch), dU(nu, kBatch), R(ny, kBatch), Eps(nk, kBatch), Dall(nx, P * kBatch),
      F(nx * P, kBatch), G(ny * P, kBatch), CD(ny, P * kBatch), Jb(kBatch * ny, P), Delta(nx, P);
  Eigen::VectorXd x(nx), xn(nx), yk(ny);
  for (size_t e = 0; e < recs.size(); ++e) {
    const ScaledRecord& rec = recs[e];
    const Eigen::Index N = rec.u.rows();
    std::vector<Intersample> is = rec.intersample;
    is.resize(static_cast<size_t>(nu + nk), Intersample::Zoh);  // the innovation is held
    std::vector<Step> cache;
    bool predictor_stable = true;
    auto step = [&](double h) -> const Step& {
      for (const Step& s : cache)
        if (std::abs(s.h - h) <= 1e-13 * h) return s;
      if (cache.size() >= 4) cache.erase(cache.begin());
      cache.push_back(step_of(m, sens ? *dirs : none, h, is));
      Step& s = cache.back();
      if (nk > 0) {
        s.GK = s.G0.rightCols(nk);
        s.PhiK = s.Phi - s.GK * m.C;
        // The predictor must be stable: an unstable one amplifies its own errors (the criterion's minimum never has one).
        const Eigen::VectorXcd ev = s.PhiK.eigenvalues();
        predictor_stable = predictor_stable && ev.allFinite() && ev.cwiseAbs().maxCoeff() < 1.0;
      }
      return s;
    };
    auto h_at = [&](Eigen::Index k) { return rec.uniform ? rec.h : rec.t(k + 1) - rec.t(k); };
    x = m.x0[e];
    for (Eigen::Index d = 0; d < P; ++d) Delta.col(d) = (*dirs)[static_cast<size_t>(d)].x0[e];
    if (acov)
      for (auto& a : *acov) a.start_sequence();
    if (grams)
      for (auto& g : *grams) g.start_sequence();
    if (yhat) yhat->emplace_back(N, ny);
    for (Eigen::Index k0 = 0; k0 < N; k0 += kBatch) {
      const Eigen::Index n = std::min<Eigen::Index>(kBatch, N - k0);
      // The model over the batch (x at each sample; x carried to the next batch).
      for (Eigen::Index i = 0; i < n; ++i) {
        const Eigen::Index k = k0 + i;
        X.col(i) = x;
        U.col(i) = rec.u.row(k).transpose();
        yk.noalias() = m.C * x;
        yk.noalias() += m.D * U.col(i);
        if (yhat) yhat->back().row(k) = yk.transpose();
        R.col(i) = rec.y.row(k).transpose() - yk;
        if (nk > 0) Eps.col(i) = R.col(i);
        R.col(i).array() *= sw.array();
        if (acov)
          for (Eigen::Index j = 0; j < ny; ++j) (*acov)[static_cast<size_t>(j)].add(R(j, i));
        if (k + 1 == N) {
          dU.col(i).setZero();
          break;
        }
        const Step& s = step(h_at(k));
        dU.col(i) = rec.u.row(k + 1).transpose() - U.col(i);
        xn.noalias() = s.Phi * x;
        xn.noalias() += s.G0.leftCols(nu) * U.col(i);
        xn.noalias() += s.G1.leftCols(nu) * dU.col(i);
        if (nk > 0) xn.noalias() += s.GK * Eps.col(i);
        x.swap(xn);
      }
      cost += 0.5 * R.leftCols(n).squaredNorm();
      if (!x.allFinite() || !std::isfinite(cost) || !predictor_stable) return false;
      if (!sens) continue;
      // Sensitivities: the output terms dC x + dD u, the forcing of the next sample's sensitivity states.
      G.leftCols(n).noalias() = dCs * X.leftCols(n);
      G.leftCols(n).noalias() += dDs * U.leftCols(n);
      const bool uniform = rec.uniform;
      if (uniform && N > 1) {
        const Step& s = step(rec.h);
        F.leftCols(n).noalias() = s.W1 * X.leftCols(n);
        F.leftCols(n).noalias() += s.W2.leftCols(nu) * U.leftCols(n);
        F.leftCols(n).noalias() += s.W3.leftCols(nu) * dU.leftCols(n);
        if (nk > 0) F.leftCols(n).noalias() += s.W2.rightCols(nk) * Eps.leftCols(n);
      }
      for (Eigen::Index i = 0; i < n; ++i) {
        const Eigen::Index k = k0 + i;
        Dall.middleCols(i * P, P) = Delta;
        if (k + 1 == N) break;
        const Step& s = step(h_at(k));
        if (!uniform) {
          F.col(i).noalias() = s.W1 * X.col(i);
          F.col(i).noalias() += s.W2.leftCols(nu) * U.col(i);
          F.col(i).noalias() += s.W3.leftCols(nu) * dU.col(i);
          if (nk > 0) F.col(i).noalias() += s.W2.rightCols(nk) * Eps.col(i);
        }
        if (nk == 0) {
          Delta.noalias() = s.Phi.lazyProduct(Dall.middleCols(i * P, P));  // small: no GEMM packing
        } else {
          Delta.noalias() = s.PhiK.lazyProduct(Dall.middleCols(i * P, P));
          Delta.noalias() -= s.GK.lazyProduct(Eigen::Map<const Eigen::MatrixXd>(G.col(i).data(), ny, P));
        }
        Delta += Eigen::Map<const Eigen::MatrixXd>(F.col(i).data(), nx, P);
      }
      CD.leftCols(n * P).noalias() = m.C * Dall.leftCols(n * P);
      for (Eigen::Index i = 0; i < n; ++i)
        Jb.middleRows(i * ny, ny).noalias() =
            -(sw.asDiagonal() * (CD.middleCols(i * P, P) + Eigen::Map<const Eigen::MatrixXd>(G.col(i).data(), ny, P)));
      const Eigen::Index rows = n * ny;
      if (grams)
        for (Eigen::Index i = 0; i < n; ++i)
          for (Eigen::Index j = 0; j < ny; ++j) (*grams)[static_cast<size_t>(j)].add(Jb.row(i * ny + j));
      JtJ->selfadjointView<Eigen::Lower>().rankUpdate(Jb.topRows(rows).transpose());
      Jtr->noalias() += Jb.topRows(rows).transpose() * Eigen::Map<const Eigen::VectorXd>(R.data(), rows);
    }
  }
  if (sens) *JtJ = JtJ->selfadjointView<Eigen::Lower>();
  return std::isfinite(cost) && (!sens || (JtJ->allFinite() && Jtr->allFinite()));
}

// Per-output residual variances of a model (scaled units), pooled over the records.
Eigen::VectorXd residual_variances(const Point& m, const std::vector<ScaledRecord>& recs) {
  std::vector<Eigen::MatrixXd> yh;
  double cost = 0.0;
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(m.C.rows());
  Eigen::VectorXd v = Eigen::VectorXd::Zero(m.C.rows());
  if (!evaluate(m, nullptr, recs, ones, cost, nullptr, nullptr, &yh)) return Eigen::VectorXd::Constant(m.C.rows(), NAN);
  Eigen::Index n = 0;
  for (size_t e = 0; e < recs.size(); ++e) {
    v += (recs[e].y - yh[e]).colwise().squaredNorm().transpose();
    n += recs[e].y.rows();
  }
  return v / static_cast<double>(std::max<Eigen::Index>(n, 1));
}

struct Search {
  Eigen::VectorXd theta;
  Eigen::VectorXd weights;  // 1/sigma_j^2 (scaled units)
  int iterations = 0;
  internal::LmResult last;
  bool failed_start = false;
};

// The model in state coordinates of unit covariance along its trajectory over the records (x = L z, L L^T the
// states' second moment): every state of a comparable size, so the search's coordinates are well conditioned.
Point whitened(const Point& m, const std::vector<ScaledRecord>& recs) {
  const Eigen::Index nx = m.A.rows(), nu = m.B.cols();
  Eigen::MatrixXd Sx = Eigen::MatrixXd::Zero(nx, nx);
  Eigen::Index n = 0;
  const StateSpace states(m.A, m.B, Eigen::MatrixXd::Identity(nx, nx), Eigen::MatrixXd::Zero(nx, nu));
  for (size_t e = 0; e < recs.size(); ++e) {
    LsimOptions lo;
    lo.x0 = m.x0[e];
    const Eigen::MatrixXd X = lsim(states, recs[e].u, recs[e].t, recs[e].intersample, lo);
    if (!X.allFinite()) continue;
    Sx += X.transpose() * X;
    n += X.rows();
  }
  Sx /= static_cast<double>(std::max<Eigen::Index>(n, 1));
  Eigen::LLT<Eigen::MatrixXd> llt(Sx + 1e-9 * std::max(Sx.trace(), 1e-300) * Eigen::MatrixXd::Identity(nx, nx));
  if (llt.info() != Eigen::Success || !Sx.allFinite()) return m;
  return transformed(m, llt.matrixL());
}

// Rounds of Levenberg-Marquardt in local coordinates re-centred after each round, then the weights re-estimated and
// the search repeated once (weighted output error = ML for independent Gaussian output noise). `damping` is the
// Levenberg-Marquardt damping to start with, and receives the one reached (a warm-up hands it to the next stage).
Search search_records(const Layout& L, Eigen::VectorXd theta, const std::vector<bool>& held,
                      const std::vector<ScaledRecord>& recs, const SsestOptions& o, bool free_coordinates, double& damping) {
  Search s;
  // enforce_stability keeps a stable start stable (an unstable start is searched freely: it may be an unstable plant).
  const bool check_stability = o.enforce_stability && stable(unpack(L, theta).A, o.integrators);
  s.weights = residual_variances(unpack(L, theta), recs).cwiseMax(1e-12).cwiseInverse();
  if (!s.weights.allFinite()) {
    s.failed_start = true;
    s.theta = theta;
    return s;
  }
  internal::LmOptions lmo;
  lmo.xtol = 1e-10;
  lmo.lambda0 = damping;
  int left = o.max_iterations;
  for (int pass = 0; pass < 2; ++pass) {
    const Eigen::VectorXd sw = s.weights.cwiseSqrt();
    const Rounds r = lm_rounds(
        L, theta, held, check_stability, o.integrators, o.tolerance, left, lmo,
        [&](const Point& m) { return free_coordinates ? whitened(m, recs) : m; },
        [&](const Eigen::MatrixXd& Q) {
          return [&, dirs = directions_of(L, Q)](const Point& m, double& cost, Eigen::MatrixXd* A, Eigen::VectorXd* g) {
            return evaluate(m, A ? &dirs : nullptr, recs, sw, cost, A, g);
          };
        });
    theta = r.theta;
    s.iterations += r.iterations;
    s.last = r.last;
    damping = lmo.lambda0;
    if (r.failed) {
      s.failed_start = s.iterations == 0;
      s.theta = theta;
      return s;
    }
    if (s.last.interrupted || !r.converged) break;
    if (pass == 0) {
      const Eigen::VectorXd w = residual_variances(unpack(L, theta), recs).cwiseMax(1e-12).cwiseInverse();
      if (!w.allFinite()) break;
      const double change = ((w - s.weights).array().abs() / s.weights.array()).maxCoeff();
      s.weights = w;
      // Weights within 10 % of those the search ran with: the optimum moves by a negligible fraction of its standard
      // deviation (the loss of efficiency is second order in the weights' error), so no second search.
      if (change < 0.1) break;
    }
  }
  s.theta = theta;
  return s;
}

// The warm-up's data: the records' beginnings, n samples in all (each record its share).
std::vector<ScaledRecord> beginnings(const std::vector<ScaledRecord>& recs, Eigen::Index total, Eigen::Index n_all) {
  std::vector<ScaledRecord> out;
  for (const ScaledRecord& r : recs) {
    const Eigen::Index n = std::max<Eigen::Index>(2, r.u.rows() * n_all / total);
    out.push_back(ScaledRecord{r.u.topRows(n), r.y.topRows(n), r.t.head(n), r.uniform, r.h, r.intersample});
  }
  return out;
}

// The search on long records (20 000 samples or more) is warmed up on their beginnings, 5 000 samples, then four times
// as many while that is at most a quarter of the records: a poor start (a mode tens of percent off, as subspace
// estimates of well-damped modes often are) costs tens of iterations whose price grows with N, and most of them only
// bring the model near the optimum, which a fraction of the record locates as well; each longer part, and the full
// records at the end, then finish in a few iterations. A warm-up's model is kept only when its cost on the full
// records is below that of the model it started from, so it can make the search faster, never start it from a worse
// point (a beginning too short to determine the slow modes gives a model that is rejected).
Search search(const Layout& L, Eigen::VectorXd theta, const std::vector<bool>& held, const std::vector<ScaledRecord>& recs,
              const SsestOptions& o, bool free_coordinates, int* warm_iterations) {
  Eigen::Index total = 0;
  for (const ScaledRecord& r : recs) total += r.u.rows();
  *warm_iterations = 0;
  Eigen::VectorXd sw;  // the full records' weights, from the start's residuals
  double current = INFINITY;
  // Levenberg-Marquardt damping (relative to diag(J^T W J)) to start with, then carried from stage to stage: the
  // search's directions are badly scaled (slow and fast modes, x0), so a damping of 1e-3 shrinks the step along the
  // weakly determined ones a thousandfold and each stage would spend iterations reducing it again (the full record's
  // stage took 5 Jacobians instead of 3 in the four-mode benchmark of docs/benchmarks.md).
  double damping = kInitialDamping;
  constexpr Eigen::Index kFirstWarmUp = 5000;  // samples of the first warm-up
  for (Eigen::Index n = kFirstWarmUp; 4 * n <= total; n *= 4) {
    double d = damping;
    const Search w = search_records(L, theta, held, beginnings(recs, total, n), o, free_coordinates, d);
    if (w.failed_start || w.last.interrupted) break;
    if (sw.size() == 0) {
      sw = residual_variances(unpack(L, theta), recs).cwiseMax(1e-12).cwiseInverse().cwiseSqrt();
      if (!sw.allFinite() || !evaluate(unpack(L, theta), nullptr, recs, sw, current, nullptr, nullptr)) break;
    }
    double after = INFINITY;
    if (!evaluate(unpack(L, w.theta), nullptr, recs, sw, after, nullptr, nullptr) || !(after < current)) continue;
    theta = w.theta;
    current = after;
    damping = d;
    *warm_iterations += w.iterations;
  }
  return search_records(L, theta, held, recs, o, free_coordinates, damping);
}

void check_records(std::span<const IdData> ds) {
  CTID_REQUIRE(!ds.empty(), "ssest: no records were given");
  const int nu = ds.front().nu(), ny = ds.front().ny();
  CTID_REQUIRE(nu >= 1 && ny >= 1, "ssest: the data need at least one input and one output (got {} and {})", nu, ny);
  for (size_t e = 0; e < ds.size(); ++e) {
    const IdData& d = ds[e];
    CTID_REQUIRE(d.nu() == nu && d.ny() == ny, "ssest: record {} has {} inputs and {} outputs, record 1 has {} and {}",
                 e + 1, d.nu(), d.ny(), nu, ny);
    CTID_REQUIRE(d.u().allFinite() && d.y().allFinite(), "ssest: record {} contains non-finite values", e + 1);
  }
}

// The entries the options hold (set to their held values in p): D (estimate_d false), x0 (records at rest), the
// integrators' columns of A.
void hold_structure(const Layout& L, const SsestOptions& o, Point& p, std::vector<bool>& held) {
  if (!o.estimate_d) {
    p.D.setZero();
    for (int i = 0; i < L.ny; ++i)
      for (int j = 0; j < L.nu; ++j) held[static_cast<size_t>(L.d(i, j))] = true;
  }
  if (!o.estimate_initial_state)
    for (int e = 0; e < L.E; ++e) {
      p.x0[static_cast<size_t>(e)].setZero();
      for (int i = 0; i < L.nx; ++i) held[static_cast<size_t>(L.x0(e, i))] = true;
    }
  for (int j = 0; j < o.integrators; ++j)
    for (int i = 0; i < L.nx; ++i) {
      p.A(i, j) = 0.0;
      held[static_cast<size_t>(L.a(i, j))] = true;
    }
}

// The result at the final model `fin` (user units): the modal form (or the user's coordinates), the parameters and
// their covariance (J^T W J)^-1 with W the inverse noise variances (the residuals' or, for a bound, the given ones),
// fits, initial states, modes and their uncertainty.
void deliver(Result<StateSpace>& res, std::span<const IdData> ds, Point fin, bool user_coordinates,
             const std::vector<bool>& held, int similar, const SsestOptions& o, const Eigen::VectorXd* noise_variance) {
  const int nx = static_cast<int>(fin.A.rows()), nu = ds.front().nu(), ny = ds.front().ny();
  const int E = static_cast<int>(ds.size());
  const Layout L{nx, nu, ny, E, fin.K.size() ? ny : 0};
  const Eigen::VectorXd sy = ss_detail::channel_scales(ds, true);
  Eigen::Index total = 0;
  for (const IdData& d : ds) total += d.size();
  const int n_free_params = static_cast<int>(std::count(held.begin(), held.end(), false)) - similar;
  describe(res, fin, L, held, user_coordinates, o.integrators, o.estimate_d);
  const std::vector<bool>& pfixed = res.parameters.fixed;

  // Covariance: (J^T W J)^-1 over the free parameters (their directions read from their names, the one reading of
  // validate/uncertainty.hpp) and the initial states at the final model, in the user's units (columns scaled before
  // the inversion); the parameters' block of it.
  std::vector<int> slots;
  std::vector<Point> cdirs;
  const std::vector<Eigen::VectorXd> no_x0(static_cast<size_t>(E), Eigen::VectorXd::Zero(nx));
  const std::vector<StateSpaceDirection> pdirs = state_space_directions(res.model, res.parameters);
  for (size_t k = 0; k < pdirs.size(); ++k)
    if (!pfixed[k]) {
      slots.push_back(static_cast<int>(k));
      cdirs.push_back(Point{pdirs[k].dA, pdirs[k].dB, pdirs[k].dC, pdirs[k].dD, no_x0, pdirs[k].dK});
    }
  const int np = static_cast<int>(cdirs.size());
  if (o.estimate_initial_state)
    for (int e = 0; e < E; ++e)
      for (int i = 0; i < nx; ++i) {
        Point d{Eigen::MatrixXd::Zero(nx, nx), Eigen::MatrixXd::Zero(nx, nu), Eigen::MatrixXd::Zero(ny, nx),
                Eigen::MatrixXd::Zero(ny, nu), no_x0, {}};
        d.x0[static_cast<size_t>(e)](i) = 1.0;
        cdirs.push_back(std::move(d));
      }
  const std::vector<ScaledRecord> raw = records_of(ds, Eigen::VectorXd::Ones(nu), Eigen::VectorXd::Ones(ny));
  const Eigen::VectorXd var = noise_variance ? *noise_variance : residual_variances(fin, raw);
  Eigen::MatrixXd JtJ;
  Eigen::VectorXd Jtr;
  double cost = 0;
  std::vector<Eigen::MatrixXd> yhat;
  const Eigen::VectorXd sw = var.cwiseMax(1e-300).cwiseInverse().cwiseSqrt();
  std::vector<internal::ResidualAutocovariance> acov(static_cast<size_t>(ny),
                                                     internal::ResidualAutocovariance(internal::residual_ar_max_lag(total)));
  const bool ok = var.allFinite() && evaluate(fin, &cdirs, raw, sw, cost, &JtJ, &Jtr, &yhat, &acov);
  Eigen::MatrixXd cov;
  if (ok) cov = inverse_normal(JtJ, np);
  res.parameters.set_covariance(cov, slots);
  if (ok && cov.size() && !noise_variance) {
    // The residuals' colour (each output's AR model, the degrees of freedom shared among the outputs): one more pass
    // with the Jacobian rows filtered by it; the white-noise figure stays a diagnostic. (Given noise variances, as
    // ssest_crlb's, declare the noise white.)
    std::vector<internal::ColouredGram> grams;
    int order = 0;
    for (internal::ResidualAutocovariance& a : acov) {
      const internal::ResidualAr ar = a.fit(static_cast<int>(std::lround(double(cdirs.size()) / double(ny))));
      order = std::max(order, ar.order());
      grams.emplace_back(ar, static_cast<int>(cdirs.size()));
    }
    Eigen::MatrixXd JtJ2;
    Eigen::VectorXd Jtr2;
    double cost2 = 0;
    if (evaluate(fin, &cdirs, raw, sw, cost2, &JtJ2, &Jtr2, nullptr, nullptr, &grams)) {
      Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(JtJ.rows(), JtJ.cols());
      for (const internal::ColouredGram& g : grams) Q += g.gram();
      const Eigen::MatrixXd S = internal::sandwich(JtJ, Q);
      if (S.size()) {
        res.diagnostics.set(diagnostic::white_noise_std, res.parameters.std);
        res.diagnostics.set(diagnostic::residual_ar_order, order);
        res.parameters.set_covariance(S.topLeftCorner(np, np), slots);
      }
    }
  }
  if (user_coordinates && similar > 0 && res.summary.succeeded()) {
    res.summary.termination = Termination::Unidentifiable;
    res.summary.message = detail::format(
        "the held entries leave {} direction(s) of a change of state coordinates free: those combinations of the "
        "entries of A, B and C are not determined by the data (the poles and responses are); hold more entries, or "
        "hold none of A, B, C (the modal form)", similar);
  }

  // Fits, noise, initial states, modes.
  if (ok) {
    const int n_fit = n_free_params + (o.estimate_initial_state ? E * nx : 0);
    ss_detail::Fits f = ss_detail::fits_of(ds, yhat, sy, n_fit);
    if (L.nk > 0) {
      // yhat are the one-step predictions; the fit reported is the simulation's, as for every model.
      res.diagnostics.set(diagnostic::prediction_fit_percent, f.per_output);
      Point sim = fin;
      sim.K.resize(0, 0);
      double c = 0;
      if (evaluate(sim, nullptr, raw, Eigen::VectorXd::Ones(ny), c, nullptr, nullptr, &yhat))
        f = ss_detail::fits_of(ds, yhat, sy, n_fit);
      else
        f.all.fit_percent = -INFINITY, f.per_output.setConstant(-INFINITY);
    }
    res.fit = f.all;
    res.diagnostics.set(diagnostic::output_fit_percent, f.per_output);
    res.diagnostics.set(diagnostic::output_noise_variance, var);
    res.diagnostics.set(diagnostic::cost, cost);
  } else {
    res.fit.fit_percent = -INFINITY;
    res.fit.n_samples = static_cast<int>(total * ny);
  }
  for (int e = 0; e < E; ++e) res.diagnostics.set(diagnostic::x0, fin.x0[static_cast<size_t>(e)], e);
  report_modes(res);
  }

Result<StateSpace> fit_from(std::span<const IdData> ds, Point start, bool user_coordinates,
                            const Eigen::VectorXd& singular_values, const SsestOptions& o, Clock::time_point t0) {
  const int nx = static_cast<int>(start.A.rows()), nu = ds.front().nu(), ny = ds.front().ny();
  const int E = static_cast<int>(ds.size());
  const Layout L{nx, nu, ny, E, o.estimate_k ? ny : 0};
  const Eigen::VectorXd su = ss_detail::channel_scales(ds, false), sy = ss_detail::channel_scales(ds, true);
  const std::vector<ScaledRecord> recs = records_of(ds, su, sy);
  if (!o.estimate_k) start.K.resize(0, 0);
  else if (start.K.size() == 0) start.K = Eigen::MatrixXd::Zero(nx, ny);  // the output-error predictor

  // Held entries: D (estimate_d false or fixed.D..), A/B/C (fixed.., with a starting model), x0 (from rest),
  // the integrators' columns of A.
  std::vector<std::string> names;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < nx; ++j) names.push_back(entry_name('A', i, j));
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < nu; ++j) names.push_back(entry_name('B', i, j));
  for (int i = 0; i < ny; ++i)
    for (int j = 0; j < nx; ++j) names.push_back(entry_name('C', i, j));
  for (int i = 0; i < ny; ++i)
    for (int j = 0; j < nu; ++j) names.push_back(entry_name('D', i, j));
  const ParameterConstraints c = resolve_constraints(
      o.fixed, {}, names, "ssest", "an entry of A, B, C or D of this model (" + std::to_string(nx) + " states)");
  std::vector<bool> held(static_cast<size_t>(L.size()), false);
  Eigen::VectorXd v = pack(L, start);
  for (size_t k = 0; k < names.size(); ++k) {
    if (!c.held[k]) continue;
    CTID_REQUIRE_OPTION(user_coordinates || names[k][0] == 'D',
                        "ssest: fixed.{}: entries of A, B and C refer to the coordinates of a starting model; give "
                        "one (ssest(data, initial, options); Python initial=...)", names[k]);
    held[k] = true;
    v(static_cast<Eigen::Index>(k)) = c.value(static_cast<Eigen::Index>(k));
  }
  start = unpack(L, v);
  hold_structure(L, o, start, held);

  // Scaled units; without held A/B/C entries (and integrators) also whitened states, again at each round.
  const bool free_coordinates = !user_coordinates && o.integrators == 0;
  Point s = scaled(start, su, sy);
  if (free_coordinates) s = whitened(s, recs);
  int similar = 0;
  (void)local_directions(L, s, held, &similar);

  Result<StateSpace> res;
  int warm = 0;
  Search sr = search(L, pack(L, s), held, recs, o, free_coordinates, &warm);
  if (warm > 0) res.diagnostics.set(diagnostic::warm_up_iterations, static_cast<double>(warm));
  auto finish = [&] { res.summary.seconds = std::chrono::duration<double>(Clock::now() - t0).count(); };
  if (singular_values.size() > 0) res.diagnostics.set(diagnostic::singular_values, singular_values);
  if (E > 1) res.diagnostics.set(diagnostic::experiments, static_cast<double>(E));
  if (sr.failed_start) {
    res.model = StateSpace(start.A, start.B, start.C, start.D, start.K);
    res.summary.termination = Termination::NumericalFailure;
    res.summary.message = "ssest: the starting model cannot be simulated on the data (its output overflows)";
    finish();
    return res;
  }
  internal::set_termination(res.summary, sr.last);
  res.summary.iterations = sr.iterations;

  deliver(res, ds, unscaled(unpack(L, sr.theta), su, sy), user_coordinates, held, similar, o, nullptr);
  finish();
  return res;
}

// The subspace start (on the longest record) and each record's initial state for it.
struct Start {
  Point point;
  Eigen::VectorXd sigma;
  double fit = NAN;
  Result<StateSpace> failure;
  bool failed = false;
};

Start subspace_start(std::span<const IdData> ds, int nx, const SsestOptions& o) {
  size_t longest = 0;
  for (size_t e = 1; e < ds.size(); ++e)
    if (ds[e].size() > ds[longest].size()) longest = e;
  SubspaceOptions so = o.start;
  so.nx = nx;
  so.estimate_d = o.estimate_d;
  so.estimate_initial_state = o.estimate_initial_state;
  Start s;
  Result<StateSpace> r = subspace(ds[longest], so);
  if (r.model.nx() == 0) {
    s.failed = true;
    s.failure = std::move(r);
    return s;
  }
  s.sigma = r.diagnostics.get(diagnostic::singular_values);
  s.fit = r.fit.fit_percent;
  const StateSpace& m = r.model;
  s.point = Point{m.A(), m.B(), m.C(), m.D(), {}, {}};
  for (size_t e = 0; e < ds.size(); ++e) {
    if (e == longest) {
      s.point.x0.push_back(r.diagnostics.get(diagnostic::x0));
      continue;
    }
    Eigen::VectorXd x0 = Eigen::VectorXd::Zero(m.nx());
    if (o.estimate_initial_state) (void)subspace_bd(m.A(), m.C(), ds[e], o.estimate_d, true, &x0);
    s.point.x0.push_back(x0);
  }
  return s;
}

// Known integrators: the start moved to coordinates whose first k states are the eigenvectors of its k real poles
// nearest 0, those poles set to 0 (A's first k columns zero).
void with_integrators(Point& p, int k) {
  const int nx = static_cast<int>(p.A.rows());
  CTID_REQUIRE_OPTION(k < nx, "ssest: integrators = {} needs a larger state dimension (nx = {})", k, nx);
  Eigen::EigenSolver<Eigen::MatrixXd> es(p.A);
  std::vector<std::pair<double, int>> real;
  for (int i = 0; i < nx; ++i)
    if (es.eigenvalues()(i).imag() == 0.0) real.emplace_back(std::abs(es.eigenvalues()(i)), i);
  CTID_REQUIRE_OPTION(static_cast<int>(real.size()) >= k,
                      "ssest: integrators = {}: the start has only {} real pole(s) to hold at 0", k, real.size());
  std::sort(real.begin(), real.end());
  Eigen::MatrixXd V(nx, k);
  for (int j = 0; j < k; ++j) V.col(j) = es.eigenvectors().col(real[static_cast<size_t>(j)].second).real();
  // T = [V, an orthonormal complement of span(V)].
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(V);
  const Eigen::MatrixXd Qf = qr.householderQ() * Eigen::MatrixXd::Identity(nx, nx);
  Eigen::MatrixXd T(nx, nx);
  T << V, Qf.rightCols(nx - k);
  p = transformed(p, T);
  p.A.leftCols(k).setZero();
}

// The start with each pole p moved to p exp(f_i) (f from the multi-start draws; a complex pair by one factor, so its
// damping is kept): A = V diag(p exp(f)) V^-1 in the start's coordinates, B, C, D and the initial states kept.
// Returns false when A's eigenvectors are too ill-conditioned to move the poles one by one.
bool with_poles_moved(Point& p, const Eigen::VectorXd& f) {
  Eigen::EigenSolver<Eigen::MatrixXd> es(p.A);
  if (es.info() != Eigen::Success) return false;
  const Eigen::VectorXcd lambda = es.eigenvalues();
  const Eigen::MatrixXcd V = es.eigenvectors();
  Eigen::JacobiSVD<Eigen::MatrixXcd> svd(V);
  const Eigen::VectorXd sv = svd.singularValues();
  if (!(sv(sv.size() - 1) > 1e-8 * sv(0))) return false;
  Eigen::VectorXcd moved = lambda;
  for (Eigen::Index i = 0; i < lambda.size(); ++i) {
    Eigen::Index k = i;  // a pair's member of positive imaginary part gives the pair's factor
    if (lambda(i).imag() < 0)
      for (Eigen::Index j = 0; j < lambda.size(); ++j)
        if (lambda(j).imag() > 0 && std::abs(lambda(j) - std::conj(lambda(i))) <= 1e-9 * std::abs(lambda(i))) k = j;
    moved(i) = lambda(i) * std::exp(f(k));
  }
  p.A = (V * moved.asDiagonal() * V.inverse()).real();
  return true;
}

// Whether fit a is better than fit b: usable before not usable, then the lower MSE.
bool better(const Result<StateSpace>& a, const Result<StateSpace>& b) {
  if (a.usable() != b.usable()) return a.usable();
  return a.fit.mse < b.fit.mse;
}

Result<StateSpace> ssest_order(std::span<const IdData> ds, int nx, const SsestOptions& o, Clock::time_point t0) {
  Start s = subspace_start(ds, nx, o);
  if (s.failed) {
    Result<StateSpace> r = std::move(s.failure);
    r.summary.message = "ssest: the subspace start failed: " + r.summary.message;
    return r;
  }
  const Eigen::Index n = s.point.A.rows();
  search::StartDraws draws(Eigen::VectorXd::Zero(n), Eigen::VectorXd::Constant(n, -std::log(10.0)),
                           Eigen::VectorXd::Constant(n, std::log(10.0)),
                           {o.starts, static_cast<std::uint64_t>(o.seed), static_cast<int>(n)});
  Result<StateSpace> best;
  Eigen::VectorXd costs = Eigen::VectorXd::Constant(o.starts, NAN);
  int chosen = 0;
  for (int k = 0; k < o.starts; ++k) {
    Point p = s.point;
    if (k > 0 && !with_poles_moved(p, draws.next())) continue;
    if (o.integrators > 0) with_integrators(p, o.integrators);
    Result<StateSpace> r = fit_from(ds, p, false, s.sigma, o, t0);
    costs(k) = r.fit.mse;
    const bool interrupted = r.summary.termination == Termination::Interrupted;
    if (k == 0 || better(r, best)) {
      best = std::move(r);
      chosen = k;
    }
    if (interrupted) {
      best.summary.termination = Termination::Interrupted;
      break;
    }
  }
  best.diagnostics.set(diagnostic::start_fit_percent, s.fit);
  if (o.starts > 1) {
    best.diagnostics.set(diagnostic::starts_cost, costs);
    best.diagnostics.choices.push_back(detail::format(
        "start {} of {} fitted best ({}: poles moved within a decade, seed {})", chosen + 1, o.starts,
        chosen == 0 ? "the subspace start itself" : "the subspace start", o.seed));
  }
  best.summary.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return best;
}

// ssest of one record (a span of one, not copied) or of several.
Result<StateSpace> ssest_records(std::span<const IdData> data, const SsestOptions& options) {
  const auto t0 = Clock::now();
  options.validate();
  check_records(data);
  if (options.nx_max <= options.nx || options.nx_max == 0) return ssest_order(data, options.nx, options, t0);
  Result<StateSpace> best = order_search(std::max(options.nx, 1), options.nx_max,
                                         [&](int n) { return ssest_order(data, n, options, t0); });
  best.summary.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return best;
}

}  // namespace

Result<StateSpace> ssest(const IdData& data, const SsestOptions& options) {
  return ssest_records(std::span<const IdData>(&data, 1), options);
}

Result<StateSpace> ssest(const std::vector<IdData>& data, const SsestOptions& options) { return ssest_records(data, options); }

Result<StateSpace> ssest(const std::vector<IdData>& data, const StateSpace& initial, const SsestOptions& options) {
  const auto t0 = Clock::now();
  options.validate();
  check_records(data);
  CTID_REQUIRE_OPTION(options.nx == 0 || options.nx == initial.nx(),
                      "ssest: nx = {} differs from the starting model's {} states", options.nx, initial.nx());
  CTID_REQUIRE_OPTION(options.nx_max == 0, "ssest: nx_max needs the subspace start (a starting model has one order)");
  CTID_REQUIRE_OPTION(options.starts == 1, "ssest: starts = {} draws around the subspace start; a starting model is "
                                           "searched from itself alone", options.starts);
  CTID_REQUIRE(initial.nu() == data.front().nu() && initial.ny() == data.front().ny(),
               "ssest: the starting model has {} inputs and {} outputs, the data {} and {}", initial.nu(), initial.ny(),
               data.front().nu(), data.front().ny());
  CTID_REQUIRE(initial.nx() >= 1, "ssest: the starting model has no states");
  bool user = false;
  for (const auto& [name, v] : options.fixed) user = user || name[0] != 'D';
  Point p{initial.A(), initial.B(), initial.C(), initial.D(), {}, initial.K()};
  for (const IdData& d : data) {
    Eigen::VectorXd x0 = Eigen::VectorXd::Zero(initial.nx());
    if (options.estimate_initial_state) (void)subspace_bd(initial.A(), initial.C(), d, options.estimate_d, true, &x0);
    p.x0.push_back(x0);
  }
  if (options.integrators > 0) {
    CTID_REQUIRE_OPTION(!user, "ssest: integrators with held A/B/C entries: hold the integrators' columns of A at 0 "
                               "instead (fixed.A1_1=0 ..)");
    with_integrators(p, options.integrators);
  }
  return fit_from(data, p, user, Eigen::VectorXd(), options, t0);
}

Result<StateSpace> ssest_crlb(const StateSpace& truth, const std::vector<IdData>& data,
                              const Eigen::VectorXd& noise_variance, const SsestOptions& options) {
  const auto t0 = Clock::now();
  options.validate();
  check_records(data);
  const int nx = truth.nx(), nu = data.front().nu(), ny = data.front().ny();
  CTID_REQUIRE(truth.nu() == nu && truth.ny() == ny, "ssest_crlb: the model has {} inputs and {} outputs, the data {} "
               "and {}", truth.nu(), truth.ny(), nu, ny);
  CTID_REQUIRE(noise_variance.size() == ny && (noise_variance.array() > 0).all() && noise_variance.allFinite(),
               "ssest_crlb: give one positive noise variance per output ({} outputs, {} values)", ny,
               noise_variance.size());
  const Layout L{nx, nu, ny, static_cast<int>(data.size()), options.estimate_k ? ny : 0};
  Point p{truth.A(), truth.B(), truth.C(), truth.D(),
          std::vector<Eigen::VectorXd>(data.size(), Eigen::VectorXd::Zero(nx)),
          options.estimate_k ? (truth.has_innovation_gain() ? truth.K() : Eigen::MatrixXd::Zero(nx, ny))
                             : Eigen::MatrixXd()};
  std::vector<bool> held(static_cast<size_t>(L.size()), false);
  hold_structure(L, options, p, held);
  int similar = 0;
  (void)local_directions(L, p, held, &similar);
  Result<StateSpace> res;
  res.summary.termination = Termination::Completed;
  deliver(res, data, p, false, held, similar, options, &noise_variance);
  res.summary.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return res;
}

}  // namespace ctid
