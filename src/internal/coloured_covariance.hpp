// ctid internal — the covariance of an output-error estimate when the residuals are coloured (Ljung 1999, §9.3: the
// asymptotic covariance of a prediction-error estimate whose model does not describe the noise, Cov = H^-1 Q H^-1
// with H = J^T J and Q = Cov(J^T v), v the output noise).
//
// Q needs the noise's autocovariance over all lags. It is estimated parametrically: an AR model A(q) v = w of each
// output's residuals (Levinson-Durbin on their autocovariance pooled over the records, the order by AIC), so that
// v = A^-1 w and Q = lambda_w J^T A^-1 A^-T J, computed as lambda_w sum_t j~_t j~_t^T with the Jacobian's rows
// filtered by 1/A(q) forward in time from rest in each record (the forward and the backward filter give the same
// stationary autocovariance; they differ by edge terms of relative size order/N). Compared with a lag window on
// the sample cross-products (Newey-West / Bartlett), the AR form has no truncation bias for slowly decaying noise
// (an AR(1) pole at 0.9 needs lags of about 40 to reach 1 %) and is one streaming pass of order N p (order + p).
// With white residuals (order 0) it is sigma^2 (J^T J)^-1 exactly, sigma^2 = RSS/(N - p).
#pragma once

#include <vector>

#include <Eigen/Dense>

namespace ctid::internal {

/// An AR model A(q) = 1 + a_1 q^-1 + .. + a_n q^-n of residuals with innovation variance `variance`
/// (per degree of freedom: RSS-scaled by N/(N - parameters)); order 0: white.
struct ResidualAr {
  Eigen::VectorXd a;        ///< a_1..a_n
  double variance = 0.0;    ///< innovation variance
  int order() const { return static_cast<int>(a.size()); }
};

/// The autocovariance sums s_l = sum_t r_t r_{t-l}, l = 0..max_lag, pooled over sequences (no lag crosses a sequence
/// boundary), added one residual at a time.
class ResidualAutocovariance {
 public:
  explicit ResidualAutocovariance(int max_lag);
  void start_sequence();
  void add(double r);
  long long count() const { return n_; }
  /// The AR model of order 0..max_lag with the least AIC, N ln(sigma_k^2) + 2k (Levinson-Durbin on s_l / N; orders
  /// where the recursion loses positivity end the scan), its innovation variance scaled by N/(N - parameters).
  ResidualAr fit(int parameters) const;

 private:
  int max_lag_;
  Eigen::VectorXd sums_, ring_;
  long long n_ = 0;
  int filled_ = 0, head_ = 0;
};

/// lambda sum_t j~_t j~_t^T with the rows j_t filtered by 1/A(q) from rest in each sequence, added a row at a time.
class ColouredGram {
 public:
  ColouredGram(const ResidualAr& ar, int columns);
  void start_sequence();
  using Row = Eigen::Ref<const Eigen::RowVectorXd, 0, Eigen::InnerStride<>>;  // a row of a column-major J: no copy
  void add(const double* row);
  void add(const Row& row) { add_row(row); }
  /// lambda sum j~ j~^T (both triangles).
  Eigen::MatrixXd gram() const;

 private:
  void add_row(const Row& row);
  ResidualAr ar_;
  Eigen::MatrixXd past_;  // order x columns, the last filtered rows (ring)
  Eigen::MatrixXd sum_;
  Eigen::RowVectorXd now_;
  int filled_ = 0, head_ = 0;
};

/// H^-1 Q H^-1 (column-scaled, symmetrised); empty when H is singular or either is not finite.
Eigen::MatrixXd sandwich(const Eigen::MatrixXd& H, const Eigen::MatrixXd& Q);

/// Rows [start, start + length) of a stacked residual vector form one sequence in time order (one output of one
/// record); `group` is its output (one AR model per group, pooled over the records).
struct ResidualSequence {
  Eigen::Index start = 0, length = 0;
  int group = 0;
};

/// The score covariance Q = Cov(J^T v) of a search's estimate (the sandwich's middle, over J's columns) and the AR
/// models behind it; the covariance is sandwich(J^T J, score) (over a subset of the columns: the same rows and
/// columns of both).
struct ColouredCovariance {
  Eigen::MatrixXd score;         ///< empty when it cannot be formed
  std::vector<ResidualAr> noise; ///< one per group
  int largest_order() const;
};

/// The most AR lags fitted: 40, at most a tenth of the shortest group's residuals.
int residual_ar_max_lag(long long shortest_group);

/// The score covariance from the residuals r and the Jacobian J (rows as r) at the estimate, `parameters` the number
/// of estimated quantities (degrees of freedom of the innovation variances).
ColouredCovariance coloured_covariance(const Eigen::MatrixXd& J, const Eigen::VectorXd& r,
                                       const std::vector<ResidualSequence>& sequences, int parameters);

}  // namespace ctid::internal
