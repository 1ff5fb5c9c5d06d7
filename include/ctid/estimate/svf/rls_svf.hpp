// ctid — recursive estimation with Johansson's operator z = 1/(1 + p tau).
//
// Johansson, R. (1986), Lund TFRT-7318: recursive least squares on the filtered regression
// y = theta_tau^T phi_tau (RJ 11), sampled (RJ 59-60) or continuous-time (RJ 56-58), with
// exponential weighting of rate alpha (RJ 52-53; per sampled update the forgetting factor is
// e^{-2 alpha dt}) or a plain forgetting factor; and the single-unknown-coefficient tracker of a
// partially known system (RJ 74-79, sign of RJ 78 corrected as in RJ 74-79).
//
// The continuous-time recursion dtheta/dt = P phi (y_f - theta^T phi), dP/dt = 2 alpha P - P phi phi^T P
// (RJ 56-57 with the weighting of RJ 53) is integrated exactly between regression instants for a
// regressor and target linear in between: its information form dP^{-1}/dt = -2 alpha P^{-1} + phi phi^T,
// d(P^{-1} theta)/dt = -2 alpha P^{-1} theta + phi y_f gives over a step h
//   P^{-1} <- e^{-2 alpha h} P^{-1} + [phi_k phi_k+1] W [phi_k phi_k+1]^T,
//   W_ij = int_0^h e^{-2 alpha (h - s)} l_i(s) l_j(s) ds   (l_0 = 1 - s/h, l_1 = s/h),
// and the same W on the targets; W's two eigen-directions make it two weighted rank-one updates of P.
// Without noise V = theta~^T P^{-1} theta~ then obeys dV/dt = -2 alpha V - (theta~^T phi)^2 (RJ 58,
// sign and square as in RJ 56-61).
//
// The filters run at every sample given to update(); the regression is updated at every
// sample or at most every `regression_interval` seconds (Johansson's h, which need not be
// the filter's sampling). update() allocates nothing.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "ctid/core/types.hpp"
#include "ctid/data/iddata.hpp"
#include "ctid/estimate/orders.hpp"
#include "ctid/estimate/options.hpp"
#include "ctid/model/transfer_function.hpp"
#include "ctid/signal/svf.hpp"

namespace ctid {

/// The recursion minimising the least-squares criterion: the sampled sum (RJ 59-60) or the time
/// integral (RJ 44/52, recursion RJ 56-57).
enum class RlsRecursion { Sampled, Continuous };

struct RlsSvfOptions {
  double tau = 1.0;                 ///< filter time constant (s), > 0
  double p0 = 1e4;                  ///< P(0) = p0 * I, > 0
  double forgetting = 1.0;          ///< lambda in (0, 1] per regression update
  double alpha = 0.0;               ///< exponential weighting rate (1/s) >= 0; multiplies lambda by e^{-2 alpha dt}
  double regression_interval = 0.0; ///< h (s) between regression updates; 0 = every sample
  /// Sampled: one unit-weight update per regression instant (RJ 59-60). Continuous: RJ 56-57 integrated
  /// exactly between regression instants (information per second, so P(0) = p0 I weighs as p0 * h of the
  /// sampled form); forgetting must then be 1 (alpha weights the past).
  RlsRecursion recursion = RlsRecursion::Sampled;
  Intersample input_intersample = Intersample::Zoh;
  FixedValues fixed;  ///< known coefficients by name (a1.., b0..)
  Eigen::VectorXd theta0;           ///< initial parameter values [a1..an, b0..]; empty = 0
  void validate() const;
};
/// The settings of RlsSvfOptions (name, unit, range, default, doc): validate(), the CLI and Python use it.
template <>
const OptionTable<RlsSvfOptions>& option_table<RlsSvfOptions>();

/// Recursive LSSVF. With no fixed coefficient and nb = nf, the recursion runs on
/// theta_tau exactly as RJ 59-60 (P(0) = p0 I on theta_tau); otherwise on the free
/// physical coefficients (RJ 25).
class RlsSvf {
 public:
  /// Throws InvalidOptions for bad orders/options.
  RlsSvf(const TfOrders& orders, const RlsSvfOptions& options);

  /// Feed one sample (t strictly increasing). Throws InvalidArgument for a
  /// non-increasing t or a non-finite value; allocates nothing.
  void update(double t, double u, double y);
  /// Restart: filters at rest, P = P(0), parameters = theta0.
  void reset();
  /// A new record of the same system follows: the filters restart at rest and its time axis starts anew; the
  /// estimate and P carry on (several experiments).
  void start_record();

  /// Current estimate as parameters [a1..an, b0..b(nb-1)].
  Eigen::VectorXd parameters() const;
  /// Current estimate as a transfer function.
  TransferFunction model() const;
  /// Current theta_tau (length 2 nf).
  Eigen::VectorXd theta_tau() const;
  /// Current covariance-like matrix P (in the recursion's own coordinates).
  const Eigen::MatrixXd& P() const { return P_; }
  long long n_updates() const { return n_updates_; }
  double time() const { return stream_.time(); }

 private:
  TfOrders orders_;
  RlsSvfOptions opt_;
  SvfStream stream_;
  Eigen::MatrixXd M_;
  Eigen::VectorXd g_, theta_fixed_;
  std::vector<bool> fixed_;
  std::vector<int> free_;
  bool theta_tau_mode_ = false;
  Eigen::VectorXd theta_;   // in the recursion's coordinates
  Eigen::MatrixXd P_;
  Eigen::VectorXd Pphi_, row_, psi_;
  Eigen::VectorXd row_prev_, scratch_;  // continuous recursion: the regressor at the last regression instant
  double target_prev_ = 0;
  bool have_prev_ = false;
  long long n_updates_ = 0;
  void weighted_update(const Eigen::VectorXd& phi, double target, double weight);
  void continuous_step(double h, double target);
};

/// The recursion run once over a whole record (one input, one output, nk = 0): the final estimate as a result,
/// with the simulation fit on the record and no standard deviations (P is not a covariance under forgetting or
/// unknown noise). The input's intersample behaviour is the record's. The CLI's `fit --method rls-svf` and Python's ctid.rls_svf. Throws InvalidArgument for data
/// that are not SISO or nk > 0, InvalidOptions for bad options.
Result<TransferFunction> rls_svf(const IdData& data, const TfOrders& orders, const RlsSvfOptions& options = {});
/// Several experiments of one system (the same input intersample behaviour): the recursion runs over the records in
/// turn, the filters restarting at rest at each (start_record), P and the estimate carried on; the fit is pooled.
Result<TransferFunction> rls_svf(const std::vector<IdData>& data, const TfOrders& orders,
                                 const RlsSvfOptions& options = {});

struct CoefficientTrackerOptions {
  double tau = 0.5;                  ///< filter time constant (s)
  double threshold = 0.1;            ///< update only when |psi_j| >= threshold (RJ 79)
  double regression_interval = 0.0;  ///< h (s) between estimates; 0 = every sample
  Intersample input_intersample = Intersample::Zoh;
  void validate() const;
};

/// Tracks one unknown (possibly slowly time-varying) coefficient of an otherwise known
/// model: with psi = F_tau^T phi_tau, theta_j(t) = [y - G^T phi - sum_{i != j} theta_i psi_i] / psi_j
/// whenever |psi_j| >= threshold, else the previous value is kept (RJ 79).
class CoefficientTracker {
 public:
  /// known: the model with every coefficient known (the unknown one's value is the
  /// initial estimate); it must be strictly proper, of order n. unknown: "a1".."a<n>" or
  /// "b0".."b<n-1>", where b0 multiplies s^(n-1) (the numerator is taken with n
  /// coefficients, leading ones zero). Throws InvalidOptions for another name.
  CoefficientTracker(const TransferFunction& known, const std::string& unknown, const CoefficientTrackerOptions& options);
  void update(double t, double u, double y);
  double estimate() const { return estimate_; }
  /// True if the last update() changed the estimate (|psi_j| was above the threshold).
  bool updated() const { return updated_; }
  /// The filtered regressor psi_j at the last update (RJ's phi for a_1).
  double regressor() const { return last_psi_; }
  /// Filter outputs [z^k y] of the last sample (k = 1..n), e.g. for a filtered velocity.
  const double* filtered_output() const { return stream_.bank().chain(0); }

 private:
  SvfStream stream_;
  Eigen::MatrixXd M_;
  Eigen::VectorXd g_, theta_, psi_;
  int n_ = 0, j_ = 0;
  double threshold_, estimate_ = 0, last_psi_ = 0;
  double sign_ = 1.0;
  bool updated_ = false;
};

}  // namespace ctid
