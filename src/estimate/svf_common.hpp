// ctid internal — pieces shared by the Johansson estimators (batch LSSVF/IVSVF and the
// recursive forms): parameter layout with fixed coefficients (RJ 24-25), prepared data
// with criterion weights (RJ 44, 52-53, 59-61) and one streaming pass of the filter bank.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Dense>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/estimate/lssvf.hpp"
#include "ctid/model/transfer_function.hpp"
#include "ctid/signal/svf.hpp"
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

struct PreparedData {
  const IdData* data = nullptr;
  Eigen::VectorXd y, u, w;      // u already delayed by nk samples; w = 0 outside the criterion
  Intersample u_intersample = Intersample::Zoh;
  bool uniform = true;
  double h = 0.0;               // Ts, or the mean interval
  int n_used = 0;
};

/// Index of a parameter name (a1.., b0..) for the orders; InvalidOptions listing the names.
int parameter_index(const TfOrders& o, const std::string& name, const char* who);
SvfLayout make_layout(const TfOrders& o, double tau, const std::map<std::string, double>& fixed, const char* who);
PreparedData prepare(const IdData& data, const TfOrders& o, double transient_time, double alpha, SvfWeights weights,
                     const char* who);
internal::LinearSolution solve_ls(const PreparedData& P, const SvfLayout& L, const std::optional<TransferFunction>& filt);
internal::LinearSolution solve_iv(const PreparedData& P, const SvfLayout& L, const std::optional<TransferFunction>& filt,
                                  const Eigen::VectorXd& aux);
Eigen::VectorXd full_theta(const SvfLayout& L, const Eigen::VectorXd& theta_free);
Eigen::VectorXd svf_transform(const SvfLayout& L, const Eigen::VectorXd& theta);
TransferFunction tf_from_theta(const SvfLayout& L, const Eigen::VectorXd& theta, double delay);
Result<TransferFunction> make_result(const IdData& data, const TfOrders& o, const SvfLayout& L,
                                     const internal::LinearSolution& sol, double alpha);
double choose_tau(const IdData& data, const TfOrders& o, const LssvfOptions& opt, Eigen::VectorXd* grid,
                  Eigen::VectorXd* fits);

/// Mirror unstable poles into the left half plane (auxiliary models must be stable).
TransferFunction stabilized(const TransferFunction& tf);

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

/// Left-hand side y_f - G^T phi - sum over fixed theta_i psi_i.
inline double known_part(const SvfLayout& L, double yf, const double* phi_y, const double* psi) {
  double lhs = yf;
  for (int i = 0; i < L.n; ++i) lhs -= L.g(i) * phi_y[i];
  for (int t = 0; t < 2 * L.n; ++t)
    if (L.fixed[t]) lhs -= L.theta_fixed(t) * psi[t];
  return lhs;
}

/// One pass of the filter bank over the data; f(psi, lhs, zeta_or_null, weight) for every
/// sample with a non-zero weight. zeta is the regressor with the auxiliary signal in
/// place of y (instruments), when aux is given.
template <class F>
void svf_pass(const PreparedData& P, const SvfLayout& L, const std::optional<TransferFunction>& filt,
              const Eigen::VectorXd* aux, F&& f) {
  const IdData& d = *P.data;
  const int N = d.size();
  std::vector<Intersample> is{Intersample::Foh, P.u_intersample};
  if (aux) is.push_back(Intersample::Foh);
  SvfFilterBank bank(L.n, L.tau, is, filt);
  const int S = static_cast<int>(is.size());
  double prev[3], next[3];
  auto load = [&](int k, double* v) {
    v[0] = P.y(k);
    v[1] = P.u(k);
    if (aux) v[2] = (*aux)(k);
  };
  load(0, prev);
  bank.set_current(prev);
  std::vector<double> psi(2 * L.n), zeta(2 * L.n);
  for (int k = 0; k < N; ++k) {
    if (k > 0) {
      load(k, next);
      bank.step(P.uniform ? P.h : d.time(k) - d.time(k - 1), prev, next);
      for (int s = 0; s < S; ++s) prev[s] = next[s];
    }
    const double w = P.w(k);
    if (w == 0.0) continue;
    physical_regressor(L.M, bank.chain(0), bank.chain(1), psi.data());
    const double lhs = known_part(L, bank.filtered(0), bank.chain(0), psi.data());
    if (aux) physical_regressor(L.M, bank.chain(2), bank.chain(1), zeta.data());
    f(psi.data(), lhs, aux ? zeta.data() : nullptr, w);
  }
}

}  // namespace ctid::svf_detail
