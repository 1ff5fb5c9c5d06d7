// ctid — a continuous-time plant under a known digital linear controller: the sampled-data loop of a digitally
// controlled machine (the closed-loop set-ups of Gawthrop & Wang 2005 §6 and of closed-loop SRIVC), for examples,
// tests and experiment design.
//
// At every sampling instant t_k = k Ts the controller reads the measured output y_k (the plant's output plus
// measurement noise n_k) and the reference r_k and computes, in the RST form (Landau & Zito 2006, "Digital Control
// Systems", ch. 7),
//   P(q^-1) v_k = T(q^-1) r_k - S(q^-1) y_k,    P(q^-1) = p_0 + p_1 q^-1 + ..,  p_0 != 0,
// then holds u_k = clamp(v_k, u_min, u_max) on [t_k, t_k+1) (ZOH). The recursion runs on the controller's own output
// v (no anti-windup: the saturation is the actuator's). The plant is simulated exactly between the instants (its
// state-space form discretised with the hold); a delay of the plant must be a whole number of samples. All past
// signals are zero at k = 0 and the plant starts at rest.
#pragma once

#include <limits>

#include <Eigen/Dense>

#include "ctid/data/iddata.hpp"
#include "ctid/model/transfer_function.hpp"

namespace ctid {

/// P(q^-1) v_k = T(q^-1) r_k - S(q^-1) y_k: coefficients of q^0, q^-1, ... (P(0) != 0; any lengths >= 1).
struct RstController {
  Eigen::VectorXd P{{1.0}}, S{{0.0}}, T{{0.0}};
  double u_min = -std::numeric_limits<double>::infinity();  ///< actuator limits (plant input units)
  double u_max = std::numeric_limits<double>::infinity();

  /// u = R r - S y with constant gains: P = 1, T = r_gain, S = y_gain.
  static RstController gains(double r_gain, double y_gain);
  /// The textbook digital PID of a sampled loop: error e = r - y, integral by the backward rectangle
  /// (I_k = I_k-1 + Ts e_k), derivative of the measurement, filtered: D_k = (tf D_k-1 + kd (y_k - y_k-1)) / (tf + Ts);
  /// u = kp e + ki I - D. Gains in the plant input's units per output unit (ki per second, kd seconds), tf (s) >= 0,
  /// Ts (s) > 0. Throws InvalidArgument for a negative tf, a bad Ts or a non-finite gain.
  static RstController pid(double kp, double ki, double kd, double tf, double Ts);
  /// Throws InvalidArgument naming the problem: an empty or non-finite polynomial, P(0) = 0, u_min > u_max.
  void validate() const;
};

/// The loop run over the reference r (one sample per instant, Ts apart): IdData with the applied input u (ZOH) and
/// the measured output y (plant output + noise), Ts, channel names "u" and "y". noise: measurement noise n_k added
/// to the output the controller reads (empty = none; else one value per sample). Throws InvalidArgument for a plant
/// with a direct term when S(0) != 0 (an algebraic loop), a delay that is not a whole number of samples, a bad Ts, a
/// noise of another length, or a loop whose signals overflow (an unstable loop), naming the sample.
IdData simulate_closed_loop(const TransferFunction& plant, const RstController& controller,
                            const Eigen::VectorXd& reference, double Ts, const Eigen::VectorXd& noise = {});

}  // namespace ctid
