// The sampled-data loop of a continuous plant and a digital RST controller. See include/ctid/simulate/closed_loop.hpp.
#include "ctid/simulate/closed_loop.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "ctid/core/check.hpp"
#include "ctid/model/state_space.hpp"
#include "ctid/simulate/lsim.hpp"

namespace ctid {

RstController RstController::gains(double r_gain, double y_gain) {
  RstController c;
  c.T = Eigen::VectorXd::Constant(1, r_gain);
  c.S = Eigen::VectorXd::Constant(1, y_gain);
  c.validate();
  return c;
}

RstController RstController::pid(double kp, double ki, double kd, double tf, double Ts) {
  CTID_REQUIRE(std::isfinite(Ts) && Ts > 0, "RstController::pid: Ts must be > 0 (got {} s)", Ts);
  CTID_REQUIRE(std::isfinite(tf) && tf >= 0, "RstController::pid: tf must be >= 0 (got {} s)", tf);
  CTID_REQUIRE(std::isfinite(kp) && std::isfinite(ki) && std::isfinite(kd),
               "RstController::pid: gains must be finite (kp {}, ki {}, kd {})", kp, ki, kd);
  // Multiply u = kp e + ki I - D by (1 - q^-1)(1 - beta q^-1), beta = tf / (tf + Ts), gamma = kd / (tf + Ts):
  // (1 - q^-1) I = Ts e and (1 - beta q^-1) D = gamma (1 - q^-1) y.
  const double beta = tf / (tf + Ts), gamma = kd / (tf + Ts);
  const Eigen::Vector3d P(1.0, -1.0 - beta, beta);  // (1 - q^-1)(1 - beta q^-1)
  RstController c;
  c.P = P;
  c.T = kp * P + ki * Ts * Eigen::Vector3d(1.0, -beta, 0.0);
  c.S = c.T + gamma * Eigen::Vector3d(1.0, -2.0, 1.0);
  c.validate();
  return c;
}

void RstController::validate() const {
  for (const auto* p : {&P, &S, &T}) {
    const char* name = p == &P ? "P" : (p == &S ? "S" : "T");
    CTID_REQUIRE(p->size() >= 1 && p->allFinite(), "RstController: {} must have at least one finite coefficient", name);
  }
  CTID_REQUIRE(P(0) != 0.0, "RstController: P(0) must be non-zero (the controller computes u_k from P(0) v_k = ..)");
  CTID_REQUIRE(!(u_min > u_max), "RstController: u_min = {} is above u_max = {}", u_min, u_max);
}

IdData simulate_closed_loop(const TransferFunction& plant, const RstController& c, const Eigen::VectorXd& r, double Ts,
                            const Eigen::VectorXd& noise) {
  c.validate();
  CTID_REQUIRE(std::isfinite(Ts) && Ts > 0, "simulate_closed_loop: Ts must be > 0 (got {} s)", Ts);
  const Eigen::Index N = r.size();
  CTID_REQUIRE(N >= 1 && r.allFinite(), "simulate_closed_loop: the reference must have at least one finite value");
  CTID_REQUIRE(noise.size() == 0 || noise.size() == N,
               "simulate_closed_loop: {} noise values for {} reference samples", noise.size(), N);
  const double lag = plant.io_delay() / Ts;
  const long delay = std::lround(lag);
  CTID_REQUIRE(std::abs(lag - static_cast<double>(delay)) <= 1e-9 * std::max(1.0, lag),
               "simulate_closed_loop: the plant's delay {} s is not a whole number of samples (Ts = {} s)",
               plant.io_delay(), Ts);
  const StateSpace ss = plant.to_state_space();
  const double d = ss.D()(0, 0);
  CTID_REQUIRE(d == 0.0 || c.S(0) == 0.0 || delay > 0,
               "simulate_closed_loop: the plant has a direct term ({}) and S(0) = {}: u_k would depend on itself (an "
               "algebraic loop); use a strictly proper plant or S(0) = 0",
               d, c.S(0));
  const Discretization D = discretize(ss.A(), ss.B(), Ts);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(ss.A().rows());
  Eigen::VectorXd u(N), y(N);
  std::vector<double> v(static_cast<std::size_t>(N));  // the controller's own output, before the limits
  std::vector<double> held(static_cast<std::size_t>(delay), 0.0);  // inputs on their way through the delay
  auto past = [](const Eigen::VectorXd& poly, const auto& sig, Eigen::Index k) {
    double s = 0;
    for (Eigen::Index j = 1; j < poly.size() && j <= k; ++j) s += poly(j) * sig(k - j);
    return s;
  };
  for (Eigen::Index k = 0; k < N; ++k) {
    const double u_plant = delay > 0 ? held[static_cast<std::size_t>(k % delay)] : 0.0;  // u_{k - delay}
    const double y_free = (ss.C() * x)(0);
    double yk = y_free + (delay > 0 ? d * u_plant : 0.0) + (noise.size() ? noise(k) : 0.0);
    // v_k from P(0) v_k = T r - S y - (P's past terms); with a direct term and no delay y_k includes d u_k (S(0) = 0).
    const auto vs = [&](Eigen::Index i) { return v[static_cast<std::size_t>(i)]; };
    const double rhs = c.T(0) * r(k) + past(c.T, r, k) - c.S(0) * yk - past(c.S, y, k) - past(c.P, vs, k);
    const double vk = rhs / c.P(0);
    v[static_cast<std::size_t>(k)] = vk;
    u(k) = std::clamp(vk, c.u_min, c.u_max);
    if (delay == 0) yk += d * u(k);
    y(k) = yk;
    CTID_REQUIRE(std::isfinite(u(k)) && std::isfinite(yk),
                 "simulate_closed_loop: the loop diverged at sample {} (t = {} s): the controller does not stabilise "
                 "the plant", k, static_cast<double>(k) * Ts);
    const double applied = delay > 0 ? u_plant : u(k);
    if (delay > 0) held[static_cast<std::size_t>(k % delay)] = u(k);
    x = D.Phi * x + D.Gamma0 * applied;
  }
  IdData out(u, y, Ts);
  out.set_intersample(Intersample::Zoh);
  out.set_input_names({"u"});
  out.set_output_names({"y"});
  return out;
}

}  // namespace ctid
