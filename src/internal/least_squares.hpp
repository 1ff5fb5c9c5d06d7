// ctid internal — shared least-squares kernels used by the estimators.
//
// StreamingLeastSquares: weighted linear least squares min sum w_k (y_k - x_k^T theta)^2
// over rows added one at a time, by blocked Householder QR of [sqrt(w) X, sqrt(w) y]
// (memory O(block * p), never N x p). Solving uses the triangular factor, so the
// accuracy is that of QR, not of the normal equations.
//
// InstrumentalVariables: theta = (sum w z x^T)^{-1} sum w z y with column scaling.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

namespace ctid::internal {

struct LinearSolution {
  Eigen::VectorXd theta;
  Eigen::MatrixXd covariance;   // sigma^2 * (X^T W X)^{-1} (LS) or the IV sandwich
  double sigma2 = 0.0;          // residual variance estimate
  double rss = 0.0;             // weighted residual sum of squares
  double tss = 0.0;             // weighted sum of squares of the targets about their weighted mean (rss's scale)
  double condition = 0.0;       // of the column-scaled problem
  bool rank_deficient = false;
  long long n_rows = 0;
};

/// Weights and targets of the rows added so far: sum w, sum w^2, and the weighted mean and sum of squared
/// deviations of the targets (West 1979), from which the total sum of squares is known without cancellation.
struct TargetMoments {
  double sumw = 0.0, sumw2 = 0.0, mean = 0.0, m2 = 0.0;
  void add(double y, double w) {
    const double wn = sumw + w;
    if (wn > 0) {
      const double delta = y - mean;
      mean += delta * w / wn;
      m2 += w * delta * (y - mean);
    }
    sumw = wn;
    sumw2 += w * w;
  }
};

class StreamingLeastSquares {
 public:
  explicit StreamingLeastSquares(int p, int block = 1024);
  /// Add one row x (p values), target y, weight w >= 0.
  void add(const double* x, double y, double w = 1.0) {
    const double sw = std::sqrt(w);
    for (int j = 0; j < p_; ++j) buf_(fill_, j) = sw * x[j];
    buf_(fill_, p_) = sw * y;
    m_.add(y, w);
    ++rows_;
    if (++fill_ == buf_.rows()) compress();
  }
  long long rows() const { return rows_; }
  LinearSolution solve(double rank_tolerance = 1e-12);

 private:
  void compress();
  int p_;
  Eigen::MatrixXd buf_;   // top p+1 rows: current triangular factor; then pending rows
  Eigen::Index fill_;
  Eigen::HouseholderQR<Eigen::MatrixXd> qr_;
  long long rows_ = 0;
  TargetMoments m_;
};

/// Weighted least squares by accumulating the augmented Gram matrix [X y]^T W [X y]
/// (about (p+1)(p+2)/2 multiply-adds per row, no buffer). Accurate to about
/// eps * cond^2 in the column-scaled condition number; callers re-solve with
/// StreamingLeastSquares when `condition` exceeds kGramConditionLimit.
class GramLeastSquares {
 public:
  explicit GramLeastSquares(int p, int block = 128);
  void add(const double* x, double y, double w = 1.0) {
    // Buffer the weighted augmented row sqrt(w) [x, y]; a block is folded into the Gram
    // matrix by one symmetric rank-k update (vectorised), not row by row.
    const double sw = std::sqrt(w);
    double* r = &buf_(0, fill_);
    for (int j = 0; j < p_; ++j) r[j] = sw * x[j];
    r[p_] = sw * y;
    m_.add(y, w);
    ++rows_;
    if (++fill_ == buf_.cols()) flush();
  }
  long long rows() const { return rows_; }
  LinearSolution solve(double rank_tolerance = 1e-12);

 private:
  void flush();
  int p_;
  Eigen::MatrixXd g_;    // (p+1) x (p+1) Gram matrix of [X y] (lower triangle maintained)
  Eigen::MatrixXd buf_;  // (p+1) x block, one weighted row per column
  Eigen::Index fill_ = 0;
  long long rows_ = 0;
  TargetMoments m_;
};

/// Above this column-scaled condition number the Gram solution loses more than about
/// 8 digits; use the QR kernel instead.
constexpr double kGramConditionLimit = 1e4;

class InstrumentalVariables {
 public:
  /// with_rss = false skips the X^T X terms (then LinearSolution::rss and sigma2 are NaN).
  explicit InstrumentalVariables(int p, bool with_rss = true);
  void add(const double* z, const double* x, double y, double w = 1.0);
  long long rows() const { return rows_; }
  LinearSolution solve(double rank_tolerance = 1e-12) const;
  /// sum w z z^T (upper and lower triangles filled).
  Eigen::MatrixXd zz() const { return zz_.selfadjointView<Eigen::Upper>(); }
  /// sum w z x^T.
  const Eigen::MatrixXd& zx() const { return zx_; }

 private:
  int p_;
  bool with_rss_;
  Eigen::MatrixXd zx_, zz_, xx_;
  Eigen::VectorXd zy_, xy_;
  double yy_ = 0.0, sumw_ = 0.0, sumw2_ = 0.0;
  long long rows_ = 0;
};

/// 2-norm condition number of a square matrix after scaling its columns to unit norm.
double scaled_condition(const Eigen::MatrixXd& M);

/// 2-norm condition number sigma_max / sigma_min of M as it is (infinite when singular, 0 when empty).
double condition_number(const Eigen::MatrixXd& M);

/// The covariance sigma2 M^{-1} of estimated parameters from their information matrix M (J^T J of a search,
/// sum zeta zeta^T of instrumental variables); an empty matrix (unknown, see ParameterSet::set_covariance)
/// when M is empty or sigma2 is not finite.
Eigen::MatrixXd covariance(const Eigen::MatrixXd& information, double sigma2);

/// The condition number of J with its columns scaled to unit norm, from J^T J (the square root of the eigenvalue
/// ratio of the scaled J^T J): what scaled_condition(J) gives without J. Infinite when singular, NaN when empty.
double gram_condition(const Eigen::MatrixXd& jtj);

/// Identifiability at an estimate x of the quantities `names` from their information matrix J^T J (never a +- 0):
/// J^T J scaled to unit diagonal; an eigenvalue below 1e-11 of the largest is a direction the output does not see.
/// Returns "" when every direction is determined, else the message naming the parameters of the weakest direction
/// with their relative changes along it (k/(m s^2 + c s + k): "+1 k, +1 m, +1 c" — scaling all three together
/// leaves the output unchanged), or a parameter without any influence (zero column) by itself. Every output-error
/// search (oe, physical, nde_oe, greybox) makes a result with such a direction Unidentifiable with this message.
std::string unidentifiable(const Eigen::MatrixXd& jtj, const Eigen::VectorXd& x, const std::vector<std::string>& names);

}  // namespace ctid::internal
