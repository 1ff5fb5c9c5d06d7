#include "ctid/signal/prefilter.hpp"

#include "ctid/core/check.hpp"
#include "ctid/model/state_space.hpp"
#include "ctid/simulate/lsim.hpp"

namespace ctid {

Eigen::MatrixXd filtered_derivatives(const TransferFunction& G, int k_max, const Eigen::Ref<const Eigen::VectorXd>& v,
                                     const Eigen::VectorXd& t, Intersample is, double delay) {
  Eigen::MatrixXd out;
  filtered_derivatives_into(G, k_max, v, t, is, delay, out);
  return out;
}

namespace {
// The realisation of G whose outputs are s^k G, k = 0..k_max: output k is C A^k x + (C A^{k-1} B) v (the direct term
// is non-zero only for k = rel).
StateSpace derivative_bank(const TransferFunction& G, int k_max) {
  const int rel = G.order() - (G.num().is_zero() ? 0 : G.num().degree());
  CTID_REQUIRE(k_max >= 0 && k_max <= rel, "filtered_derivatives: s^{} G(s) is improper (relative degree {})", k_max, rel);
  const StateSpace ss = StateSpace::controllable_canonical(G);
  const int n = ss.nx();
  // Output k: C A^k x + (C A^{k-1} B) v  (the direct term is non-zero only for k = rel).
  Eigen::MatrixXd C(k_max + 1, n), D = Eigen::MatrixXd::Zero(k_max + 1, 1);
  Eigen::RowVectorXd row = ss.C();
  for (int k = 0; k <= k_max; ++k) {
    C.row(k) = row;
    if (k == 0) D(0, 0) = ss.D()(0, 0);
    else D(k, 0) = (C.row(k - 1) * ss.B())(0, 0);
    row = row * ss.A();
  }
  if (n == 0) C.resize(k_max + 1, 0);
  return StateSpace(ss.A(), ss.B(), C, D);
}
}  // namespace

void filtered_derivatives_into(const TransferFunction& G, int k_max, const Eigen::Ref<const Eigen::VectorXd>& v,
                               const Eigen::VectorXd& t, Intersample is, double delay, Eigen::MatrixXd& out) {
  CTID_REQUIRE(v.size() == t.size(), "filtered_derivatives: {} samples but {} times", v.size(), t.size());
  const StateSpace bank = derivative_bank(G, k_max);
  LsimOptions o;
  o.input_delay = delay;
  lsim_into(bank, Eigen::Map<const Eigen::MatrixXd>(v.data(), v.size(), 1), t, std::vector<Intersample>{is}, o, out);
}

DerivativeRecursion derivative_recursion(const TransferFunction& G, int k_max, double h, Intersample is) {
  const StateSpace bank = derivative_bank(G, k_max);
  const int n = bank.nx();
  DerivativeRecursion r;
  r.C = bank.C();
  r.D = bank.D().col(0);
  if (n == 0) {
    r.Phi.resize(0, 0);
    r.G0.resize(0);
    r.G1.resize(0);
    return r;
  }
  const Discretization dz = discretize(bank.A(), bank.B(), h);
  r.Phi = dz.Phi;
  r.G0 = dz.Gamma0.col(0);
  r.G1 = is == Intersample::Zoh ? Eigen::VectorXd::Zero(n) : Eigen::VectorXd(dz.Gamma1.col(0));
  return r;
}

Eigen::MatrixXd output_sensitivities(const TransferFunction& G, int nb, const IdData& d, bool with_delay) {
  SensitivityWorkspace ws;
  Eigen::MatrixXd S;
  output_sensitivities_into(G, nb, d, with_delay, ws, S);
  return S;
}

void output_sensitivities_into(const TransferFunction& G, int nb, const IdData& d, bool with_delay,
                               SensitivityWorkspace& ws, Eigen::MatrixXd& S) {
  CTID_REQUIRE(d.nu() == 1 && d.ny() >= 1, "output_sensitivities: needs single-input data (has {} inputs)", d.nu());
  const int n = G.order();
  CTID_REQUIRE(nb >= 1 && nb <= n + 1, "output_sensitivities: nb = {} is not in [1, {}]", nb, n + 1);
  if (ws.t.size() != d.size()) ws.t = d.times();
  const auto u = d.u().col(0);
  const Intersample is = d.intersample(0);
  const double T = G.io_delay();
  const TransferFunction B_over_A2(G.num(), G.den() * G.den());
  const TransferFunction one_over_A(Polynomial{1.0}, G.den());
  const Eigen::Index cols = n + nb + (with_delay ? 1 : 0);
  if (S.rows() != d.size() || S.cols() != cols) S.resize(d.size(), cols);
  if (n > 0) {
    filtered_derivatives_into(B_over_A2, n - 1, u, ws.t, is, T, ws.xa);
    for (int i = 1; i <= n; ++i) S.col(i - 1) = -ws.xa.col(n - i);
  }
  filtered_derivatives_into(one_over_A, nb - 1, u, ws.t, is, T, ws.ub);
  for (int j = 0; j < nb; ++j) S.col(n + j) = ws.ub.col(nb - 1 - j);
  if (with_delay) {
    const TransferFunction BA(G.num(), G.den());
    filtered_derivatives_into(BA, 1, u, ws.t, is, T, ws.yd);
    S.col(n + nb) = -ws.yd.col(1);
  }
}

}  // namespace ctid
