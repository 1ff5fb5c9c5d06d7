#include "ctid/signal/prefilter.hpp"

#include "ctid/core/check.hpp"
#include "ctid/model/state_space.hpp"
#include "ctid/simulate/lsim.hpp"

namespace ctid {

Eigen::MatrixXd filtered_derivatives(const TransferFunction& G, int k_max, const Eigen::Ref<const Eigen::VectorXd>& v,
                                     const Eigen::VectorXd& t, Intersample is, double delay) {
  const int rel = G.order() - (G.num().is_zero() ? 0 : G.num().degree());
  CTID_REQUIRE(k_max >= 0 && k_max <= rel, "filtered_derivatives: s^{} G(s) is improper (relative degree {})", k_max, rel);
  CTID_REQUIRE(v.size() == t.size(), "filtered_derivatives: {} samples but {} times", v.size(), t.size());
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
  const StateSpace bank(ss.A(), ss.B(), C, D);
  LsimOptions o;
  o.input_delay = delay;
  return lsim(bank, Eigen::MatrixXd(v), t, std::vector<Intersample>{is}, o);
}

Eigen::MatrixXd output_sensitivities(const TransferFunction& G, int nb, const IdData& d, bool with_delay) {
  CTID_REQUIRE(d.nu() == 1 && d.ny() >= 1, "output_sensitivities: needs single-input data (has {} inputs)", d.nu());
  const int n = G.order();
  CTID_REQUIRE(nb >= 1 && nb <= n + 1, "output_sensitivities: nb = {} is not in [1, {}]", nb, n + 1);
  const Eigen::VectorXd t = d.times();
  const Eigen::VectorXd u = d.u().col(0);
  const Intersample is = d.intersample(0);
  const double T = G.io_delay();
  const TransferFunction B_over_A2(G.num(), G.den() * G.den());
  const TransferFunction one_over_A(Polynomial{1.0}, G.den());
  Eigen::MatrixXd S(d.size(), n + nb + (with_delay ? 1 : 0));
  if (n > 0) {
    const Eigen::MatrixXd xa = filtered_derivatives(B_over_A2, n - 1, u, t, is, T);
    for (int i = 1; i <= n; ++i) S.col(i - 1) = -xa.col(n - i);
  }
  const Eigen::MatrixXd ub = filtered_derivatives(one_over_A, nb - 1, u, t, is, T);
  for (int j = 0; j < nb; ++j) S.col(n + j) = ub.col(nb - 1 - j);
  if (with_delay) {
    const TransferFunction BA(G.num(), G.den());
    const Eigen::MatrixXd yd = filtered_derivatives(BA, 1, u, t, is, T);
    S.col(n + nb) = -yd.col(1);
  }
  return S;
}

}  // namespace ctid
