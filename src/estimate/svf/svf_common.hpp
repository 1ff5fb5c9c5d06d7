// ctid internal — pieces shared by the Johansson estimators (batch LSSVF/IVSVF and the
// recursive forms): parameter layout with fixed coefficients (RJ 24-25), prepared data
// with criterion weights (RJ 44, 52-53, 59-61) and one streaming pass of the filter bank.
#pragma once

#include <cmath>
#include <optional>
#include <vector>

#include <Eigen/Dense>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/estimate/svf/lssvf.hpp"
#include "ctid/model/transfer_function.hpp"
#include "ctid/signal/svf.hpp"
#include "data/record_refs.hpp"
#include "internal/least_squares.hpp"

namespace ctid::svf_detail {

/// theta = [-a_1..-a_n, b_1..b_n] (Johansson's order); parameters = [a1..an, b0..b(nb-1)].
struct SvfLayout {
  int n = 0, nb = 0;
  double tau = 0.0;
  Eigen::MatrixXd M;            // M_tau
  Eigen::VectorXd g;            // first half of G_tau
  std::vector<bool> fixed;      // per theta entry
  Eigen::VectorXd theta_fixed;  // values of fixed theta entries (others 0)
  std::vector<int> free;        // theta indices estimated
  /// theta index of parameter i (a1..an, b0..).
  int theta_index(int i) const { return i < n ? i : n + (n - nb) + (i - n); }
  /// parameter index of theta index t (or -1 for an implicit zero leading b).
  int param_index(int t) const { return t < n ? t : (t - n < n - nb ? -1 : n + (t - n) - (n - nb)); }
};

/// The experiment seen by the criterion: output, input delayed by nk samples (zero
/// before the record) and the weight of each sample (zero before transient_time).
struct PreparedData {
  const IdData* data = nullptr;
  int nk = 0, first = 0, n_used = 0;
  Intersample u_intersample = Intersample::Zoh;
  bool uniform = true;
  double h = 0.0;               // Ts, or the mean interval
  double alpha = 0.0, t_end = 0.0;
  SvfWeights weights = SvfWeights::Riemann;
  const double* ys = nullptr;  // output column 0 and input column 0 of *data
  const double* us = nullptr;
  double y(int k) const { return ys[k]; }
  double u(int k) const { return k >= nk ? us[k - nk] : 0.0; }
  /// Criterion weight of sample k (RJ 44, 52-53, 59-61), relative to the mean interval.
  double weight(int k) const {
    if (k < first) return 0.0;
    const int N = data->size();
    double w = 1.0;
    if (!uniform || weights == SvfWeights::Trapezoidal) {
      const double hb = k > first ? data->time(k) - data->time(k - 1) : (k + 1 < N ? data->time(k + 1) - data->time(k) : h);
      const double ha = k + 1 < N ? data->time(k + 1) - data->time(k) : hb;
      if (weights == SvfWeights::Riemann) w = hb / h;
      else w = (k == first ? ha / 2 : (k == N - 1 ? hb / 2 : (ha + hb) / 2)) / h;
    }
    if (alpha > 0) w *= std::exp(2.0 * alpha * (data->time(k) - t_end));
    return w;
  }
  /// The delayed input as a vector (for auxiliary-model simulation).
  Eigen::VectorXd delayed_u() const {
    Eigen::VectorXd v(data->size());
    for (int k = 0; k < data->size(); ++k) v(k) = u(k);
    return v;
  }
};

/// Index of a parameter name (a1.., b0..) for the orders; InvalidOptions listing the names.
int parameter_index(const TfOrders& o, const std::string& name, const char* who);
SvfLayout make_layout(const TfOrders& o, double tau, const FixedValues& fixed, const char* who);
PreparedData prepare(const IdData& data, const TfOrders& o, double transient_time, double alpha, SvfWeights weights,
                     const char* who);
/// Least squares (and instrumental variables, aux: the auxiliary model's output per record) with the normal
/// equations summed over one or several prepared records (several experiments of one system).
internal::LinearSolution solve_ls(const std::vector<PreparedData>& P, const SvfLayout& L,
                                  const std::optional<TransferFunction>& filt);
internal::LinearSolution solve_iv(const std::vector<PreparedData>& P, const SvfLayout& L,
                                  const std::optional<TransferFunction>& filt, const std::vector<Eigen::VectorXd>& aux);
Eigen::VectorXd full_theta(const SvfLayout& L, const Eigen::VectorXd& theta_free);
Eigen::VectorXd svf_transform(const SvfLayout& L, const Eigen::VectorXd& theta);
TransferFunction tf_from_theta(const SvfLayout& L, const Eigen::VectorXd& theta, double delay);
/// The result of a solved regression: parameters and covariance, model, diagnostics and warnings (RJ-A4, A5, RJ 55);
/// make_result adds the simulation fit on the records, make_model_result leaves the fit to the caller.
Result<TransferFunction> make_result(const internal::RecordRefs& data, const TfOrders& o, const SvfLayout& L,
                                     const internal::LinearSolution& sol, double alpha);
Result<TransferFunction> make_model_result(const TfOrders& o, const SvfLayout& L, const internal::LinearSolution& sol,
                                           double alpha, double delay);
double choose_tau(const internal::RecordRefs& data, const TfOrders& o, const LssvfOptions& opt, Eigen::VectorXd* grid,
                  Eigen::VectorXd* fits);

/// Output-error fit of a model on the records (each simulated from rest, concatenated); -Inf fit when a
/// simulation diverges.
FitReport simulation_fit(const TransferFunction& model, const internal::RecordRefs& data, int n_free);


/// psi = F_tau^T phi (physical-coefficient regressor, RJ 25) from the chain outputs;
/// M is M_tau (n x n lower triangular), psi has 2n entries.
inline void physical_regressor(const Eigen::MatrixXd& M, const double* phi_y, const double* phi_u, double* psi) {
  const Eigen::Index n = M.rows();
  for (Eigen::Index j = 0; j < n; ++j) {
    double sy = 0, su = 0;
    for (Eigen::Index i = j; i < n; ++i) {
      sy += M(i, j) * phi_y[i];
      su += M(i, j) * phi_u[i];
    }
    psi[j] = sy;
    psi[n + j] = su;
  }
}

/// The regression at one instant as a linear map of phi = [z^k y, z^k u] (2n values):
/// row = T phi (the free entries of psi = F_tau^T phi, RJ 25) and
/// lhs = y_f - c^T phi (c = [g; 0] plus the fixed coefficients' share, RJ 24).
struct RowMap {
  int p = 0, m = 0;        // free parameters, 2n
  std::vector<double> T;   // p x m, row-major
  std::vector<double> c;   // m
  explicit RowMap(const SvfLayout& L) : p(static_cast<int>(L.free.size())), m(2 * L.n) {
    T.assign(static_cast<std::size_t>(p) * m, 0.0);
    c.assign(m, 0.0);
    std::vector<double> phi(m, 0.0), psi(m);
    for (int k = 0; k < m; ++k) {  // column k of the map: phi = e_k
      std::fill(phi.begin(), phi.end(), 0.0);
      phi[k] = 1.0;
      physical_regressor(L.M, phi.data(), phi.data() + L.n, psi.data());
      for (int j = 0; j < p; ++j) T[static_cast<std::size_t>(j) * m + k] = psi[L.free[j]];
      double ck = k < L.n ? L.g(k) : 0.0;
      for (int t = 0; t < m; ++t)
        if (L.fixed[t]) ck += L.theta_fixed(t) * psi[t];
      c[k] = ck;
    }
  }
  /// row (p values) and the returned lhs from phi_y, phi_u (n values each) and y_f.
  double apply(const double* phy, const double* phu, double yf, double* row) const {
    const int n = m / 2;
    double lhs = yf;
    for (int k = 0; k < n; ++k) lhs -= c[k] * phy[k] + c[n + k] * phu[k];
    for (int j = 0; j < p; ++j) {
      const double* t = &T[static_cast<std::size_t>(j) * m];
      double acc = 0;
      for (int k = 0; k < n; ++k) acc += t[k] * phy[k] + t[n + k] * phu[k];
      row[j] = acc;
    }
    return lhs;
  }
};

/// svf_pass for the plain chain with a compile-time order (n <= 4): the same arithmetic as
/// SvfFilterBank::step and RowMap::apply with fully unrolled loops (the LSSVF hot path).
template <int n, class F>
void svf_pass_fixed(const PreparedData& P, const SvfLayout& L, const Eigen::VectorXd* aux, F&& f) {
  const IdData& d = *P.data;
  const int N = d.size();
  const RowMap map(L);
  const int p = map.p;
  const bool foh_u = P.u_intersample != Intersample::Zoh;
  SvfChainCoefficients cf;
  double e[n], g0[n], g1[n];
  double hcur = -1.0;
  double xy[n] = {}, xu[n] = {}, xa[n] = {};
  double T[2 * n * 2 * n] = {}, c[2 * n] = {};
  for (int j = 0; j < p; ++j)
    for (int k = 0; k < 2 * n; ++k) T[j * 2 * n + k] = map.T[static_cast<std::size_t>(j) * 2 * n + k];
  for (int k = 0; k < 2 * n; ++k) c[k] = map.c[k];
  auto chain = [&](double* x, double s0, double ds) {
    for (int k = n - 1; k >= 0; --k) {
      double acc = g0[k] * s0 + g1[k] * ds;
      for (int m = 0; m <= k; ++m) acc += e[k - m] * x[m];
      x[k] = acc;
    }
  };
  auto apply = [&](const double* phy, const double* phu, double* row) {
    for (int j = 0; j < p; ++j) {
      const double* t = &T[j * 2 * n];
      double acc = 0;
      for (int k = 0; k < n; ++k) acc += t[k] * phy[k] + t[n + k] * phu[k];
      row[j] = acc;
    }
  };
  double row[2 * n] = {}, zrow[2 * n] = {};
  double yp = P.y(0), up = P.u(0), ap = aux ? (*aux)(0) : 0.0;
  for (int k = 0; k < N; ++k) {
    if (k > 0) {
      const double h = P.uniform ? P.h : d.time(k) - d.time(k - 1);
      if (h != hcur) {
        cf.compute(n, h, L.tau);
        for (int j = 0; j < n; ++j) { e[j] = cf.e[j]; g0[j] = cf.g0[j]; g1[j] = cf.g1[j]; }
        hcur = h;
      }
      const double yn = P.y(k), un = P.u(k);
      chain(xy, yp, yn - yp);
      chain(xu, up, foh_u ? un - up : 0.0);
      if (aux) {
        const double an = (*aux)(k);
        chain(xa, ap, an - ap);
        ap = an;
      }
      yp = yn;
      up = un;
    }
    const double w = P.weight(k);
    if (w == 0.0) continue;
    double lhs = yp;
    for (int q = 0; q < n; ++q) lhs -= c[q] * xy[q] + c[n + q] * xu[q];
    apply(xy, xu, row);
    if (aux) apply(xa, xu, zrow);
    f(static_cast<const double*>(row), lhs, aux ? static_cast<const double*>(zrow) : nullptr, w);
  }
}

/// One pass of the filter bank over the data; f(row, lhs, zrow_or_null, weight) for every
/// sample with a non-zero weight, where row holds the free regressors. zrow is the same
/// row with the auxiliary signal in place of y (instruments), when aux is given.
template <class F>
void svf_pass(const PreparedData& P, const SvfLayout& L, const std::optional<TransferFunction>& filt,
              const Eigen::VectorXd* aux, F&& f) {
  if (!filt) {
    switch (L.n) {
      case 1: return svf_pass_fixed<1>(P, L, aux, f);
      case 2: return svf_pass_fixed<2>(P, L, aux, f);
      case 3: return svf_pass_fixed<3>(P, L, aux, f);
      case 4: return svf_pass_fixed<4>(P, L, aux, f);
      default: break;
    }
  }
  const IdData& d = *P.data;
  const int N = d.size();
  std::vector<Intersample> is{Intersample::Foh, P.u_intersample};
  if (aux) is.push_back(Intersample::Foh);
  SvfFilterBank bank(L.n, L.tau, is, filt);
  const RowMap map(L);
  const int S = static_cast<int>(is.size());
  double prev[3], next[3];
  auto load = [&](int k, double* v) {
    v[0] = P.y(k);
    v[1] = P.u(k);
    if (aux) v[2] = (*aux)(k);
  };
  load(0, prev);
  bank.set_current(prev);
  std::vector<double> row(map.p), zrow(map.p);
  for (int k = 0; k < N; ++k) {
    if (k > 0) {
      load(k, next);
      bank.step(P.uniform ? P.h : d.time(k) - d.time(k - 1), prev, next);
      for (int s = 0; s < S; ++s) prev[s] = next[s];
    }
    const double w = P.weight(k);
    if (w == 0.0) continue;
    const double lhs = map.apply(bank.chain(0), bank.chain(1), bank.filtered(0), row.data());
    if (aux) map.apply(bank.chain(2), bank.chain(1), 0.0, zrow.data());
    f(row.data(), lhs, aux ? zrow.data() : nullptr, w);
  }
}

}  // namespace ctid::svf_detail
